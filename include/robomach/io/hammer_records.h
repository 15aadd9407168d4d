#pragma once

// Raw impact-hammer time records (issue #18, item 4; docs/frf-estimate.md):
// CSV with a header row and
//   time_s            time [s], strictly increasing, evenly spaced per hit
//   force_N           hammer force [N]
//   <name>_m          a displacement response [m]           (receptance)
//   <name>_m_per_s    a velocity response [m/s]             (mobility)
//   <name>_m_per_s2   an acceleration response [m/s²]       (accelerance)
//   hit               optional: hit id; the rows of one hit are contiguous
// One or more response columns. Without a `hit` column a file is one hit,
// named by the file's stem. `#` lines are comments. Several files may be
// read together; they must have the same response columns. The sample rate
// is 1/(mean time step), snapped to a whole number of hertz when that is
// within the rounding of the written times.
//
// Or a UFF file (docs/formats.md §10.1; issue #34 item 7) of dataset 58
// time records (function type 1), as acquisition systems export them: per
// hit its force record (record 9 specific data type 13 or 9, or a force
// unit) followed by its response records (8, 11, 12, or a length, m/s or
// m/s² unit), all on one even time grid per hit. A hit starts at each force
// record; its id is its load case when every hit has its own, else its
// number in the file. A response channel is named n<node>_<axis> from
// record 6 (a negative direction read with its sign flipped), its column
// n<node>_<axis>_m_per_s2 (or _m, _m_per_s). Units as the label of record 9
// says ("g", "mm/s^2", "lbf"), else dataset 164, else SI.

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/common/frames.h"

#include "robomach/calibration/frf_estimate.h"
#include "robomach/calibration/impact_record.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/io/frf_files.h"

namespace robomach::io {

struct HammerRecords {
  std::vector<calibration::ResponseChannel> channels;  // in the first file's column order
  std::vector<calibration::ImpactRecord> hits;         // in file and row order
  /// Column names of the channels as in the files ("acc_x_m_per_s2").
  std::vector<std::string> channel_columns;
};

/// The response quantity of a column name by its unit suffix, and the
/// channel name without it; false for a name without such a suffix.
bool ParseResponseColumn(const std::string& column, calibration::ResponseQuantity* quantity, std::string* name);

/// Reads hammer records from one or more files (format above). Hit ids are
/// the `hit` cells, or the file stem; with several files the stem is put in
/// front of a hit cell ("run2#3") so that ids stay unique.
/// A file that starts with the UFF delimiter is read as UFF58 time records
/// (above), any other as CSV; the two may be mixed if their responses agree.
/// @throws InputError "file:line:column: ..." for a UFF record that is not
///   a time record or cannot be told force or response, hits whose time
///   grids or responses differ, a missing or unknown
///   column, a bad number (with a hint for a decimal comma, nan, inf), a
///   time that does not increase or is not evenly spaced (a step more than
///   1 % off the hit's median step), a hit whose rows are split, fewer than 16 samples in a
///   hit, sample rates that differ between hits by more than 1e-4 (relative), files
///   with different response columns, or a duplicate hit id.
HammerRecords ReadHammerRecords(const std::vector<std::string>& paths);

/// The FRF key of every response channel, in channel order: (pose_id, the
/// channel's direction, excitation). A channel's direction is
/// `directions[name]` ("x", "y" or "z") when given, else its name's: a name
/// that is x, y or z or ends in _x, _y or _z (a capital too, as ParseAxis).
/// @throws std::invalid_argument, a message that names the channel (and
///   reads after "--direction "): a direction for no channel ("acc=z: no
///   response channel 'acc'"), one that is not x, y or z, a channel without
///   a direction, two channels with the same key.
std::vector<dynamics::FrfKey> ChannelKeys(const HammerRecords& records, const std::string& pose_id, Axis excitation,
                                          const std::map<std::string, std::string>& directions = {});

/// FrfEstimateOptions::response_range from ranges given by channel name, in
/// each channel's SI unit (m, m/s, m/s²; 0 = unknown): one entry per
/// channel in channel order, 0 where no range is given; empty when `ranges`
/// is.
/// @throws std::invalid_argument naming the entry ("acc=50: no response
///   channel 'acc'", a range that is negative or not finite).
std::vector<double> ResponseRanges(const HammerRecords& records, const std::map<std::string, double>& ranges);

/// Writes estimated FRFs as the CSV of formats.md §3 (WriteFrfCsv, with
/// `# averages: N`), preceded by `# key: value` lines that record how they
/// were estimated (estimator, hits, windows). ReadFrfCsv reads such a file
/// back (it ignores metadata keys it does not know). Atomic.
/// @throws std::invalid_argument for a key that is empty, contains ':' or a
///   space, or is `quantity`/`averages` (written by WriteFrfCsv), or a value
///   with a line break.
void WriteEstimatedFrfCsv(const std::string& path, const dynamics::FrfSet& frfs, FrfQuantity quantity,
                          int averages, const std::vector<std::pair<std::string, std::string>>& metadata);

/// The file quantity of a response channel's quantity (displacement:
/// receptance, velocity: mobility, acceleration: accelerance).
FrfQuantity QuantityOf(calibration::ResponseQuantity q);

/// The estimated FRFs of hammer records as receptance, keyed by `keys` (one
/// per channel, in channel order), and what frf-estimate writes with them.
struct EstimatedFrfs {
  dynamics::FrfSet frfs;            // receptance [m/N] with the coherence
  std::vector<std::string> labels;  // "acc_x (Hxz)", in key order
  std::vector<int> channel_of;      // the channel of each FRF, in key order
  /// `# key: value` lines: estimator, hits averaged and rejected, windows.
  std::vector<std::pair<std::string, std::string>> metadata;
};

/// H1 (or H2 with `h2`) of every channel converted from its quantity to
/// receptance. Requires result.status kOk.
/// @throws std::invalid_argument for a result without an estimate or keys
///   that do not match the channels.
EstimatedFrfs ToEstimatedFrfs(const calibration::FrfEstimateResult& result, const HammerRecords& records,
                              const std::vector<dynamics::FrfKey>& keys, bool h2);

/// frf-estimate's summary JSON, its result part (docs/formats.md §4.1):
/// sample rate, block, line spacing, averages, windows, leakage, the
/// estimator's warnings, every hit (status, time, peak force, pulse,
/// notes) and every channel (name, column, quantity, direction and, for
/// an estimate, its coherence: lines, lines above 0.9, minimum).
nlohmann::json FrfEstimateSummaryJson(const calibration::FrfEstimateResult& result, const HammerRecords& records,
                                      const std::vector<dynamics::FrfKey>& keys);

}  // namespace robomach::io
