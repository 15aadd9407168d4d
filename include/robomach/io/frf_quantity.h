#pragma once

// The quantity a measured FRF file stores, its conversion to receptance, and
// what an FRF reader returns (formats.md §3, §4).

#include <complex>
#include <string>
#include <vector>

#include "robomach/dynamics/measured_frf.h"

namespace robomach::io {

/// The physical quantity stored in a file. With H the receptance [m/N] and
/// the e^{iωt} convention: mobility Y = iω H [(m/s)/N], accelerance
/// A = −ω² H [(m/s²)/N].
enum class FrfQuantity { kReceptance, kMobility, kAccelerance };

/// "receptance", "mobility", "accelerance".
std::string ToString(FrfQuantity q);
/// Its SI unit: "m/N", "(m/s)/N", "(m/s^2)/N".
std::string QuantityUnit(FrfQuantity q);
/// The name with its article, for messages: "a receptance", "a mobility",
/// "an accelerance".
std::string QuantityWithArticle(FrfQuantity q);
/// @throws std::invalid_argument for anything else.
FrfQuantity ParseFrfQuantity(const std::string& name);

/// Converts one line of `quantity` to receptance and back.
/// ω = 2π f must be > 0 for mobility and accelerance.
std::complex<double> ToReceptance(FrfQuantity quantity, double freq_hz, std::complex<double> value);
std::complex<double> FromReceptance(FrfQuantity quantity, double freq_hz, std::complex<double> h);

/// What a reader found, plus warnings for the caller to print (the library
/// never prints).
struct FrfReadResult {
  dynamics::FrfSet frfs;                 // receptance [m/N]
  FrfQuantity file_quantity{FrfQuantity::kReceptance};
  /// Number of averages behind the coherence (`# averages: N`); 0 if not given.
  int averages{0};
  /// Something the caller should hear about: a reading that may be wrong
  /// (a quantity assumed, nonzero values past the announced count).
  std::vector<std::string> warnings;     // "path:line: ..." each
  /// What the reader inferred or skipped, for the record: directions from
  /// entity names, a quantity from unit labels, padding, datasets and
  /// records that are not FRFs. Tools print them as notes, not warnings.
  std::vector<std::string> notes;
  /// The file's format (set by io::ReadFrfFile), for messages that say
  /// where its units are: CSV column names or UFF58 records 8-10.
  dynamics::FrfFileFormat file_format{dynamics::FrfFileFormat::kUnknown};
};

/// What the readers do without `keep_points` (io::ReadFrfFile): a posture
/// must hold one measurement-point pair, whose numbers are dropped (the tool
/// tip); a transfer pair is kept with a warning. @throws InputError naming
/// the pairs of a posture that holds several (a roving test) and what to do.
void DropPointNumbers(const std::string& path, FrfReadResult* r);

}  // namespace robomach::io
