#include "robomach/workflows/capture_decoding.h"

#include <algorithm>
#include <bit>
#include <filesystem>
#include <fstream>

#include "robomach/common/errors.h"
#include "robomach/io/file_kind.h"
#include "robomach/machine/quadrature_decoder.h"

namespace robomach::workflows {

CaptureDecoding DecodeCaptureFile(const std::string& capture_path, const io::MachineFile& mf, double rate_hz, long every,
                                  int filter, const std::function<void(double, const std::int64_t*)>& on_row,
                                  const ProgressCallback& progress) {
  if (!(rate_hz > 0.0) || every < 1 || filter < 0) {
    throw std::invalid_argument("DecodeCaptureFile: expected a rate > 0, every >= 1, a filter >= 0");
  }
  const auto& axes = mf.machine.axes;
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(capture_path, ec);
  if (ec) throw InputError({capture_path, 0, 0}, "cannot open file for reading");
  // Text (a counts CSV given as the capture) or a PNG decodes to millions
  // of error events; name what the file is instead (file_kind.h).
  io::RequireBinaryFile(capture_path, io::kCaptureFileFormat);
  if (bytes % 2 != 0) {
    throw InputError({capture_path, 0, 0}, "size " + std::to_string(bytes) +
                                               " bytes is not a whole number of 16-bit words (truncated capture?)");
  }
  if (bytes == 0) throw InputError({capture_path, 0, 0}, "the capture is empty");
  const long long total = static_cast<long long>(bytes / 2);
  machine::QuadratureDecoder decoder({.num_axes = static_cast<int>(axes.size()), .glitch_filter_samples = filter});
  std::ifstream in(capture_path, std::ios::binary);
  if (!in) throw InputError({capture_path, 0, 0}, "cannot open file for reading");
  std::vector<std::uint16_t> block(1 << 16);
  long long pos = 0, next_out = 0;
  while (pos < total) {
    const long long want = std::min<long long>(static_cast<long long>(block.size()), total - pos);
    in.read(reinterpret_cast<char*>(block.data()), want * 2);
    if (in.gcount() != want * 2) throw InputError({capture_path, 0, 0}, "read error");
    if constexpr (std::endian::native == std::endian::big) {
      for (auto& w : block) w = static_cast<std::uint16_t>((w >> 8) | (w << 8));
    }
    long long at = 0;
    while (at < want) {
      // Decode up to and including the next output sample.
      const long long len = std::min(want - at, next_out - (pos + at) + 1);
      decoder.Decode(block.data() + at, static_cast<std::size_t>(len));
      at += len;
      if (pos + at - 1 == next_out) {
        on_row(static_cast<double>(next_out) / rate_hz, decoder.counts().data());
        next_out += every;
      }
    }
    pos += want;
    if (progress) progress(static_cast<long>(pos), static_cast<long>(total));
  }
  CaptureDecoding out;
  out.samples = decoder.samples();
  out.error_events.assign(decoder.error_events().begin(), decoder.error_events().end());
  out.final_counts.assign(decoder.counts().begin(), decoder.counts().end());
  std::int64_t events = 0;
  std::string per;
  for (size_t a = 0; a < out.error_events.size(); ++a) {
    events += out.error_events[a];
    if (out.error_events[a] > 0) per += " " + mf.machine.axes[a].name + ": " + std::to_string(out.error_events[a]);
  }
  if (events > 0) {
    out.verdict.Flag(std::to_string(events) + " error events (A and B changed in one sample; each leaves the position "
             "uncertain by 2 counts):" + per + ". Raise the sample rate or use --glitch-filter.");
  }
  return out;
}

nlohmann::json CaptureDecodingSummaryJson(const CaptureDecoding& d, const std::vector<machine::AxisScale>& axes,
                                          double rate_hz, long every, int glitch_filter) {
  nlohmann::json j;
  j["samples"] = d.samples;
  j["sample_rate_hz"] = rate_hz;
  j["every"] = every;
  j["glitch_filter"] = glitch_filter;
  j["error_events"] = nlohmann::json::object();
  j["final_counts"] = nlohmann::json::object();
  for (size_t a = 0; a < axes.size(); ++a) {
    j["error_events"][axes[a].name] = d.error_events.at(a);
    j["final_counts"][axes[a].name] = d.final_counts.at(a);
  }
  return j;
}

}  // namespace robomach::workflows
