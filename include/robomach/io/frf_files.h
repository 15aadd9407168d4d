#pragma once

// Measured FRF files: the long CSV of formats.md §3 and Universal File Format
// dataset 58 (ASCII). Readers convert mobility and accelerance to receptance
// once, here, so the library sees one quantity (style.md §2.5).

#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "robomach/dynamics/measured_frf.h"

namespace robomach::io {

/// The physical quantity stored in a file. With H the receptance [m/N] and
/// the e^{iωt} convention: mobility Y = iω H [(m/s)/N], accelerance
/// A = −ω² H [(m/s²)/N].
enum class FrfQuantity { kReceptance, kMobility, kAccelerance };

/// "receptance", "mobility", "accelerance".
std::string QuantityName(FrfQuantity q);
/// @throws std::invalid_argument for anything else.
FrfQuantity ParseQuantity(const std::string& name);

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
  std::vector<std::string> warnings;     // "path:line: ..." each
};

/// Reads the long CSV format of formats.md §3: columns pose_id, response,
/// excitation, freq_hz, re, im, optional coherence; `# quantity:` metadata.
/// Rows of one FRF must be contiguous, with strictly increasing frequencies
/// on one grid. Lines at 0 Hz of mobility or accelerance files (where the
/// conversion to receptance is undefined) are dropped with a warning.
/// A warning is also given when a file declared as receptance rises like f²
/// (accelerance) or like f (mobility) at its lowest lines, below the first
/// resonance, where a receptance tends to the static compliance.
/// @throws InputError "file:line: column X: expected ..., got ..." for bad
///   cells, a non-increasing frequency, mixed grids inside one FRF (the rows
///   of one FRF split into blocks, or an even grid whose step changes),
///   a duplicate FRF, an unknown quantity.
FrfReadResult ReadFrfCsv(const std::string& path);

/// Writes `frfs` in the format of formats.md §3 as `quantity`, with a
/// coherence column if every FRF has coherence, and `# averages: N` if
/// `averages` > 0. Numbers are written so that they read back exactly.
/// Atomic (formats.md §4).
void WriteFrfCsv(const std::string& path, const dynamics::FrfSet& frfs,
                 FrfQuantity quantity = FrfQuantity::kReceptance, int averages = 0);
void WriteFrfCsv(std::ostream& os, const dynamics::FrfSet& frfs,
                 FrfQuantity quantity = FrfQuantity::kReceptance, int averages = 0);

/// Reads a Universal File Format file of ASCII dataset 58 records (one
/// function per record; [SDRC 1993], record layout below). Supported:
/// function type 4 (frequency response function) with complex ordinates
/// (data types 5 and 6), and function type 6 (coherence, real ordinates
/// 2 and 4) attached to the FRF with the same directions; even (record 7
/// field 3 = 1) or uneven abscissa spacing. The ordinate's specific data type
/// (record 9 field 1: 8 displacement, 11 velocity, 12 acceleration) gives
/// the quantity; 0 or 1 (unknown, general) is read as receptance with a
/// warning. Direction codes 1/−1 = x, 2/−2 = y, 3/−3 = z; a negative code
/// means the transducer points along −axis, so the value is negated once per
/// negative code. Values are taken as SI (m, m/s, m/s² per N); an ordinate
/// or abscissa unit label that says otherwise ("mm", "g", "lbf", "in", "rpm")
/// is an error. Dataset 151 (a header without data) is skipped; any other
/// dataset number, binary 58b, rotational direction codes, and other
/// function types are rejected with a message naming the record's line.
///
/// The posture is `pose=ID` in ID line 1 of the record; otherwise
/// `default_pose_id` (from `--pose ID=file.uff`); neither is an error.
///
/// - [SDRC 1993] Structural Dynamics Research Corporation, I-DEAS Universal
///   File Format, dataset 58 "Function at Nodal DOF" (records 1–12).
FrfReadResult ReadUff58(const std::string& path, const std::string& default_pose_id = "");

/// Writes one dataset 58 record per FRF (complex double, format 4E20.12;
/// even spacing when the grid is even, else E13.5,2E20.12), `pose=ID` in
/// ID line 1, and a coherence record (function type 6) per FRF that has
/// coherence. Atomic. The abscissa is written in E13.5 as the format
/// prescribes; this keeps 6 significant digits of f_min and Δf.
void WriteUff58(const std::string& path, const dynamics::FrfSet& frfs,
                FrfQuantity quantity = FrfQuantity::kReceptance);
void WriteUff58(std::ostream& os, const dynamics::FrfSet& frfs,
                FrfQuantity quantity = FrfQuantity::kReceptance);

/// Reads a measured-FRF file by its extension: `.uff`, `.unv` or `.uf` as
/// UFF58, anything else as CSV. `default_pose_id` applies to UFF only.
FrfReadResult ReadFrfFile(const std::string& path, const std::string& default_pose_id = "");

/// Rounds to 13 significant digits, the precision of UFF58's E20.12 field.
/// Data rounded so carry identical values in a CSV and a UFF58 copy.
double RoundToUffPrecision(double v);

}  // namespace robomach::io
