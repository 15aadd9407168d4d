#include "robomach/io/acquired_path_file.h"

#include <charconv>

#include "machine_text.h"
#include "robomach/common/units.h"
#include "robomach/io/format17.h"

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

namespace {

nlohmann::json StatsJson(const machine::SeriesStats& s) {
  return {{"max", s.max_abs}, {"mean", s.mean}, {"rms", s.rms}, {"std", s.std_dev}};
}

}  // namespace

nlohmann::json ContourSummaryJson(const ContourFigures& f) {
  nlohmann::json j;
  j["contour_error_um"] = StatsJson(f.contour_error_um);
  j["axis_error_deg"] = StatsJson(f.axis_error_deg);
  j["path_length_mm"] = f.path_length_mm;
  j["covered_mm"] = {f.covered_min_mm, f.covered_max_mm};
  return j;
}

}  // namespace robomach::io
