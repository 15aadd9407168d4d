#pragma once

// The long FRF CSV of formats.md §3. The reader converts mobility and
// accelerance to receptance once, here (style.md §2.5).

#include <ostream>
#include <string>

#include "robomach/io/frf_quantity.h"

namespace robomach::io {

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
FrfReadResult ReadFrfCsv(const std::string& path, bool keep_points = false);

/// Writes `frfs` in the format of formats.md §3 as `quantity`, with a
/// coherence column if every FRF has coherence, and `# averages: N` if
/// `averages` > 0. Numbers are written so that they read back exactly.
/// Atomic (formats.md §4).
void WriteFrfCsv(const std::string& path, const dynamics::FrfSet& frfs,
                 FrfQuantity quantity = FrfQuantity::kReceptance, int averages = 0);
void WriteFrfCsv(std::ostream& os, const dynamics::FrfSet& frfs,
                 FrfQuantity quantity = FrfQuantity::kReceptance, int averages = 0);

}  // namespace robomach::io
