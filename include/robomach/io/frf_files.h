#pragma once

// Measured FRF files: the long CSV of formats.md §3 and Universal File Format
// dataset 58 (formats.md §4), one format per header (frf_csv.h, frf_uff58.h,
// the quantities they share in frf_quantity.h). Readers convert mobility and
// accelerance to receptance once, here, so the library sees one quantity
// (style.md §2.5). This header includes them all and picks the reader.

#include <string>
#include <vector>

#include "robomach/io/frf_csv.h"
#include "robomach/io/frf_quantity.h"
#include "robomach/io/frf_uff58.h"

namespace robomach::io {

/// Reads a measured-FRF file: UFF for the extensions `.uff`, `.unv`, `.uf`,
/// `.ufb` or a file that starts with the UFF delimiter "-1", else CSV.
/// `default_pose_id` applies to UFF only.
///
/// Point numbers (formats.md §3 `response_point`/`excitation_point`, UFF
/// nodes): with `keep_points` they stay in the keys (a roving test for mode
/// shapes, frf-modes). Without it (the tool-tip tools) a posture must hold
/// one point pair, whose numbers are dropped (0); a transfer FRF between two
/// points is read with a warning; several pairs are an InputError that says
/// which pairs the posture holds and what to do.
FrfReadResult ReadFrfFile(const std::string& path, const std::string& default_pose_id = "",
                          bool keep_points = false);

/// The frequency axis judged (docs/plausibility.md): the highest line of
/// all FRFs of a file below 25 Hz (dynamics::kMinPlausibleMeasuredTopHz) is
/// a frequency axis in kHz (a hammer test's lines reach 0.1 - 10 kHz; the robot's modes
/// are 5 - 2000 Hz). One finding, "path: ...", without the "implausible
/// (unit mistake?): " prefix, naming where the file keeps its frequencies;
/// empty when plausible.
std::vector<std::string> FrequencyUnitFindings(const FrfReadResult& read, const std::string& path);

}  // namespace robomach::io
