#pragma once
// Acquired path (formats.md §8.5): the header and one row at a time (the
// acquisition that computes the rows is workflows::WriteAcquiredPath), and
// axis-acquire's contour summary. The writer converts back for the file: m
// -> mm, rad -> deg.

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/machine/acquisition.h"

namespace robomach::io {

/// Acquired path rows (formats.md §8.5), 17 significant digits: the
/// constructor writes the header (with the contour columns if
/// `contour_columns`), Row one row; all or nothing is the caller's stream
/// (io::WriteFileAtomically).
class AcquiredPathWriter {
 public:
  AcquiredPathWriter(std::ostream& out, const std::vector<machine::AxisScale>& axes,
                     bool contour_columns);
  void Row(double t_s, const machine::AcquiredSample& s, const machine::ContourError* contour);
  /// The text of one row (with its newline) appended to `buffer`; safe to
  /// call from several threads.
  void AppendRow(std::string* buffer, double t_s, const machine::AcquiredSample& s,
                 const machine::ContourError* contour) const;

 private:
  std::ostream& out_;
  std::vector<machine::AxisScale> axes_;
  std::string buffer_;
};

/// The contour figures of axis-acquire's summary, computed by the caller
/// (workflows::ContourFiguresOf; issue #36: io writes them).
struct ContourFigures {
  machine::SeriesStats contour_error_um;  // of the contour error [um]
  machine::SeriesStats axis_error_deg;    // of the tool axis error [deg]
  double path_length_mm{0.0};             // the programmed path's length
  double covered_min_mm{0.0}, covered_max_mm{0.0};  // the part of it the run covered (0, 0 without rows)
};

/// The contour part of axis-acquire's summary (docs/formats.md §4.1): the
/// statistics (max, mean, rms, std) of the contour error [um] and of the
/// tool axis error [deg], the programmed path's length and the part of it
/// the run covered [mm].
nlohmann::json ContourSummaryJson(const ContourFigures& figures);

}  // namespace robomach::io
