#include "robomach/io/acquired_path_file.h"

#include <algorithm>
#include <charconv>

#include "machine_text.h"
#include "robomach/common/units.h"
#include "robomach/io/format17.h"
#include "robomach/io/parallel_rows.h"

namespace robomach::io {

using machine::AxisScale;
using machine_text::FromSi;
using machine_text::UnitSuffix;

namespace {
constexpr size_t kMaxAxes = 8;                       // 16-bit capture words (formats.md §8.2)
constexpr size_t kMaxRowNumbers = 1 + kMaxAxes + 9;  // t_s, axes, tip, axis, 3 contour columns
}  // namespace

AcquiredPathWriter::AcquiredPathWriter(std::ostream& out, const std::vector<AxisScale>& axes, bool contour)
    : out_(out), axes_(axes) {
  if (axes_.size() > kMaxAxes) throw std::invalid_argument("AcquiredPathWriter: more than 8 axes");
  out_ << "t_s";
  for (const auto& a : axes_) out_ << "," << a.name << UnitSuffix(a);
  out_ << ",x_mm,y_mm,z_mm,i,j,k";
  if (contour) out_ << ",contour_error_mm,axis_error_deg,path_s_mm";
  out_ << "\n";
}

void AcquiredPathWriter::Row(double t_s, const machine::AcquiredSample& s, const machine::ContourError* c) {
  buffer_.clear();
  AppendRow(&buffer_, t_s, s, c);
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
}

void AcquiredPathWriter::AppendRow(std::string* buffer, double t_s, const machine::AcquiredSample& s,
                                   const machine::ContourError* c) const {
  // The row is built in a stack buffer and appended once (this runs 480,000
  // times for a 60 s, 8 kHz record).
  char row[kMaxRowNumbers * (kMaxChars17 + 1) + 1];
  char* p = row;
  p = std::to_chars(p, p + kMaxChars17, t_s).ptr;  // t_s copied from the counts: shortest exact text
  auto put = [&](double v) {
    *p++ = ',';
    p = WriteDouble17(v, p);  // "%.17g", fast
  };
  for (size_t a = 0; a < axes_.size(); ++a) put(FromSi(axes_[a], s.real[a]));
  for (int i = 0; i < 3; ++i) put(MToMm(s.pose.p_W(i)));
  for (int i = 0; i < 3; ++i) put(s.pose.k_W(i));
  if (c != nullptr) {
    put(MToMm(c->distance));
    put(RadToDeg(c->axis_angle));
    put(MToMm(c->s));
  }
  *p++ = '\n';
  buffer->append(row, p);
}

std::vector<machine::ContourError> WriteAcquiredPath(std::ostream& out, const machine::CountsRecord& record,
                                                     const std::vector<AxisScale>& axes,
                                                     machine::Acquisition* acquisition,
                                                     machine::ContourTracker* tracker, int threads) {
  const AcquiredPathWriter w(out, axes, tracker != nullptr);
  const long rows = record.rows();
  const size_t n = axes.size();
  std::vector<machine::ContourError> contour(tracker != nullptr ? static_cast<size_t>(rows) : 0);
  // 4096 rows are ~1.1 MB of text: small enough for the pipeline to start
  // formatting early, large enough that the hand-offs cost nothing.
  constexpr long kChunk = 4096;
  const int slots = 2 * std::max(1, threads) + 2;
  std::vector<std::vector<machine::AcquiredSample>> samples(static_cast<size_t>(slots),
                                                             std::vector<machine::AcquiredSample>(kChunk));
  WritePipelined(
      out, rows, kChunk, slots,
      [&](long first, long last, int slot) {
        auto& s = samples[static_cast<size_t>(slot)];
        for (long r = first; r < last; ++r) {
          s[static_cast<size_t>(r - first)] = acquisition->Process(record.t_s[r], record.counts.data() + r * n);
          if (tracker != nullptr) contour[static_cast<size_t>(r)] = tracker->Next(s[static_cast<size_t>(r - first)].pose);
        }
      },
      [&](long first, long last, int slot, std::string* text) {
        const auto& s = samples[static_cast<size_t>(slot)];
        text->reserve(static_cast<size_t>(last - first) * 320);
        for (long r = first; r < last; ++r) {
          w.AppendRow(text, record.t_s[r], s[static_cast<size_t>(r - first)],
                      tracker != nullptr ? &contour[static_cast<size_t>(r)] : nullptr);
        }
      },
      threads);
  return contour;
}

namespace {

nlohmann::json StatsJson(const machine::SeriesStats& s) {
  return {{"max", s.max_abs}, {"mean", s.mean}, {"rms", s.rms}, {"std", s.std_dev}};
}

}  // namespace

nlohmann::json ContourSummaryJson(const std::vector<machine::ContourError>& contour,
                                  const machine::ProgrammedPath& path) {
  std::vector<double> d_um(contour.size()), a_deg(contour.size()), s_mm(contour.size());
  for (size_t i = 0; i < contour.size(); ++i) {
    d_um[i] = contour[i].distance * 1e6;
    a_deg[i] = RadToDeg(contour[i].axis_angle);
    s_mm[i] = MToMm(contour[i].s);
  }
  nlohmann::json j;
  j["contour_error_um"] = StatsJson(machine::Stats(d_um));
  j["axis_error_deg"] = StatsJson(machine::Stats(a_deg));
  j["path_length_mm"] = MToMm(path.length());
  j["covered_mm"] = {s_mm.empty() ? 0.0 : *std::min_element(s_mm.begin(), s_mm.end()),
                     s_mm.empty() ? 0.0 : *std::max_element(s_mm.begin(), s_mm.end())};
  return j;
}

}  // namespace robomach::io
