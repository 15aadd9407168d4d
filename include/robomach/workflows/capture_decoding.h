#pragma once
// axis-decode's run (issue #21): a raw quadrature capture (formats.md §8.2,
// 16-bit little-endian words, two bits per axis) decoded to counts at every
// `every`-th sample.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/common/progress.h"
#include "robomach/common/run_status.h"
#include "robomach/io/machine_file.h"

namespace robomach::workflows {

/// Flagged (its `verdict`; axis-decode's exit 3) when any axis has error
/// events: each leaves its position uncertain by 2 counts.
struct CaptureDecoding {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  std::int64_t samples{0};
  std::vector<std::int64_t> error_events;  // per axis: both channels changed in one sample
  std::vector<std::int64_t> final_counts;  // per axis
};

/// Decodes the capture for the machine file's axes (QuadratureDecoder with
/// `glitch_filter` samples), calling `on_row(t_s, counts)` at samples 0,
/// every, 2 every, ... (t_s = sample / rate_hz; counts in axes order).
/// @throws InputError naming the capture for an odd size (a truncated
///   16-bit word), an empty capture or a read error.
CaptureDecoding DecodeCaptureFile(const std::string& capture_path, const io::MachineFile& machine, double rate_hz,
                                  long every, int glitch_filter,
                                  const std::function<void(double, const std::int64_t*)>& on_row,
                                  const ProgressCallback& progress = {});

/// axis-decode's summary (docs/formats.md §8.2): samples, the decoding
/// settings, and per axis (by name) the error events and the final count.
nlohmann::json CaptureDecodingSummaryJson(const CaptureDecoding& decoding, const std::vector<machine::AxisScale>& axes,
                                          double rate_hz, long every, int glitch_filter);

}  // namespace robomach::workflows
