#include "robomach/report/heat_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <cstdio>
#include <string_view>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/io/atomic_file.h"
#include "robomach/report/plot.h"

namespace robomach::report {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kBlack(0, 0, 0);

std::string Label(double v) { return FormatNumber(std::abs(v) < 1e-12 ? 0.0 : v, 6); }

void Text(cv::Mat& img, const std::string& s, cv::Point p, double scale = 0.45, int align = 0) {
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, kFont, scale, 1, &base);
  if (align == 1) p.x -= sz.width / 2;
  if (align == 2) p.x -= sz.width;
  cv::putText(img, s, p, kFont, scale, kBlack, 1, cv::LINE_AA);
}

// Viridis through OpenCV's colour map (BGR).
cv::Vec3b Colour(double t) {
  cv::Mat one(1, 1, CV_8UC1, cv::Scalar(std::clamp(static_cast<int>(std::lround(255 * t)), 0, 255)));
  cv::Mat out;
  cv::applyColorMap(one, out, cv::COLORMAP_VIRIDIS);
  return out.at<cv::Vec3b>(0, 0);
}

// @throws std::invalid_argument naming the field of a map that cannot be
// drawn (it would divide by a zero extent or index outside `values`).
void CheckDrawable(const HeatMap& m, int pw, int ph) {
  const auto bad = [&](const std::string& what) {
    throw std::invalid_argument("heat map '" + m.title + "': " + what);
  };
  if (m.nx < 1 || m.ny < 1) bad("nx and ny must be >= 1");
  if (!std::isfinite(m.dx) || !std::isfinite(m.dy) || m.dx == 0.0 || m.dy == 0.0) {
    bad("dx and dy must be finite and non-zero");
  }
  if (m.values.size() != static_cast<size_t>(m.nx) * static_cast<size_t>(m.ny)) bad("values must hold nx * ny cells");
  if (!m.marks.empty() && m.marks.size() != m.values.size()) bad("marks must be empty or hold nx * ny cells");
  if (pw < 2 || ph < 2) bad("width_px / height_px leave no room for the plot");
}

cv::Mat Render(const HeatMap& m) {
  const int W = m.width_px, H = m.height_px, right = 180, top = 60, bottom = 90;
  // Categorical row labels (posture ids) may be wider than numeric ticks.
  int left = 90;
  for (const std::string& l : m.y_tick_labels) {
    int base = 0;
    left = std::max(left, 50 + cv::getTextSize(l, kFont, 0.42, 1, &base).width);
  }
  const int pw = W - left - right, ph = H - top - bottom;
  CheckDrawable(m, pw, ph);
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  Text(img, m.title, {W / 2, 30}, 0.6, 1);
  double vmin = INFINITY, vmax = -INFINITY;
  for (double v : m.values) {
    if (std::isfinite(v)) {
      vmin = std::min(vmin, v);
      vmax = std::max(vmax, v);
    }
  }
  if (std::isfinite(m.range_min) && std::isfinite(m.range_max)) vmin = m.range_min, vmax = m.range_max;
  if (!std::isfinite(vmin)) vmin = 0.0, vmax = 1.0;
  if (!(vmax > vmin)) vmax = vmin + (vmin == 0.0 ? 1.0 : std::abs(vmin) * 0.1);
  // Data extent: cell edges.
  const double xa = m.x0 - 0.5 * m.dx, xb = m.x0 + (m.nx - 0.5) * m.dx;
  const double ya = m.y0 - 0.5 * m.dy, yb = m.y0 + (m.ny - 0.5) * m.dy;
  auto px = [&](double x) { return left + static_cast<int>(std::lround((x - xa) / (xb - xa) * pw)); };
  auto py = [&](double y) {
    const int from_bottom = static_cast<int>(std::lround((y - ya) / (yb - ya) * ph));
    return m.first_row_at_top ? top + from_bottom : top + ph - from_bottom;
  };
  if (m.symmetric_range) {
    const double a = std::max(std::abs(vmin), std::abs(vmax));
    vmin = -a;
    vmax = a;
  }
  for (int r = 0; r < m.ny; ++r) {
    for (int c = 0; c < m.nx; ++c) {
      const size_t i = static_cast<size_t>(r) * m.nx + c;
      const double v = i < m.values.size() ? m.values[i] : NAN;
      const cv::Point a(px(m.x0 + (c - 0.5) * m.dx), py(m.y0 + (r + 0.5) * m.dy));
      const cv::Point b(px(m.x0 + (c + 0.5) * m.dx), py(m.y0 + (r - 0.5) * m.dy));
      const cv::Rect cell(cv::Point(std::min(a.x, b.x), std::min(a.y, b.y)),
                          cv::Point(std::max(a.x, b.x), std::max(a.y, b.y)));
      if (std::isfinite(v)) {
        const cv::Vec3b col = Colour((v - vmin) / (vmax - vmin));
        cv::rectangle(img, cell, cv::Scalar(col[0], col[1], col[2]), cv::FILLED);
      } else {
        cv::rectangle(img, cell, cv::Scalar(200, 200, 200), cv::FILLED);
      }
      if (i < m.marks.size() && m.marks[i] == 1) {
        cv::rectangle(img, cell, cv::Scalar(235, 235, 235), cv::FILLED);
        cv::line(img, cell.tl(), cell.br(), cv::Scalar(40, 40, 200), 1, cv::LINE_AA);
        cv::line(img, {cell.x, cell.y + cell.height}, {cell.x + cell.width, cell.y}, cv::Scalar(40, 40, 200), 1,
                 cv::LINE_AA);
      }
      if (m.annotate && std::isfinite(v)) {
        const std::string buf = FormatNumber(v, 3);
        // Dark text on the light (yellow) end of viridis, light text on the dark end.
        const bool light = (v - vmin) / (vmax - vmin) > 0.6;
        int base = 0;
        const cv::Size sz = cv::getTextSize(buf, kFont, 0.45, 1, &base);
        cv::putText(img, buf, {cell.x + (cell.width - sz.width) / 2, cell.y + (cell.height + sz.height) / 2}, kFont,
                    0.45, light ? kBlack : cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
      }
    }
  }
  cv::rectangle(img, cv::Rect(left, top, pw, ph), kBlack, 1);
  if (!m.x_tick_labels.empty()) {
    for (int c = 0; c < m.nx && c < static_cast<int>(m.x_tick_labels.size()); ++c) {
      const int x = px(m.x0 + c * m.dx);
      cv::line(img, {x, top + ph}, {x, top + ph + 5}, kBlack);
      Text(img, m.x_tick_labels[c], {x, top + ph + 20}, 0.42, 1);
    }
  } else {
    for (double t : LinearTicks(xa, xb, 7)) {
      if (t < xa || t > xb) continue;
      cv::line(img, {px(t), top + ph}, {px(t), top + ph + 5}, kBlack);
      Text(img, Label(t), {px(t), top + ph + 20}, 0.42, 1);
    }
  }
  if (!m.y_tick_labels.empty()) {
    for (int r = 0; r < m.ny && r < static_cast<int>(m.y_tick_labels.size()); ++r) {
      const int y = py(m.y0 + r * m.dy);
      cv::line(img, {left - 5, y}, {left, y}, kBlack);
      Text(img, m.y_tick_labels[r], {left - 8, y + 5}, 0.42, 2);
    }
  } else {
    for (double t : LinearTicks(ya, yb, 7)) {
      if (t < ya || t > yb) continue;
      cv::line(img, {left - 5, py(t)}, {left, py(t)}, kBlack);
      Text(img, Label(t), {left - 8, py(t) + 5}, 0.42, 2);
    }
  }
  Text(img, m.x_label, {left + pw / 2, top + ph + 45}, 0.5, 1);
  {
    // Rotated y label.
    int base = 0;
    const cv::Size sz = cv::getTextSize(m.y_label, kFont, 0.5, 1, &base);
    cv::Mat t(sz.height + base + 4, sz.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(t, m.y_label, {2, sz.height + 1}, kFont, 0.5, kBlack, 1, cv::LINE_AA);
    cv::Mat r;
    cv::rotate(t, r, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x = 12, y = std::max(0, top + ph / 2 - r.rows / 2);
    if (y + r.rows <= H && x + r.cols <= W) r.copyTo(img(cv::Rect(x, y, r.cols, r.rows)));
  }
  // Colour bar.
  const int bx = left + pw + 40, bw = 22;
  for (int y = 0; y < ph; ++y) {
    const cv::Vec3b col = Colour(1.0 - static_cast<double>(y) / (ph - 1));
    cv::line(img, {bx, top + y}, {bx + bw, top + y}, cv::Scalar(col[0], col[1], col[2]));
  }
  cv::rectangle(img, cv::Rect(bx, top, bw, ph), kBlack, 1);
  for (double t : LinearTicks(vmin, vmax, 6)) {
    if (t < vmin || t > vmax) continue;
    const int y = top + ph - static_cast<int>(std::lround((t - vmin) / (vmax - vmin) * ph));
    cv::line(img, {bx + bw, y}, {bx + bw + 5, y}, kBlack);
    Text(img, Label(t), {bx + bw + 8, y + 5}, 0.42);
  }
  Text(img, m.colorbar_label, {bx - 10, top - 10}, 0.45);
  // Legend for cells without colour.
  const int ly = top + ph + 70;
  cv::rectangle(img, cv::Rect(left, ly - 12, 16, 16), cv::Scalar(200, 200, 200), cv::FILLED);
  Text(img, m.nan_label, {left + 22, ly + 1}, 0.45);
  if (!m.mark_label.empty()) {
    const cv::Rect cell(left + 260, ly - 12, 16, 16);
    cv::rectangle(img, cell, cv::Scalar(235, 235, 235), cv::FILLED);
    cv::line(img, cell.tl(), cell.br(), cv::Scalar(40, 40, 200), 1, cv::LINE_AA);
    cv::line(img, {cell.x, cell.y + cell.height}, {cell.x + cell.width, cell.y}, cv::Scalar(40, 40, 200), 1, cv::LINE_AA);
    Text(img, m.mark_label, {left + 282, ly + 1}, 0.45);
  }
  return img;
}

std::vector<unsigned char> Encode(const cv::Mat& img) {
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", img, png)) throw OutputError("PNG encoding failed");
  return png;
}

}  // namespace

std::vector<unsigned char> EncodeHeatMapPng(const HeatMap& map) { return Encode(Render(map)); }

void SaveHeatMapPng(const HeatMap& map, const std::string& path) {
  const std::vector<unsigned char> png = EncodeHeatMapPng(map);
  io::WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

std::vector<unsigned char> EncodeHeatMapsPng(const std::vector<HeatMap>& maps) {
  std::vector<cv::Mat> images;
  int width = 1;
  for (const HeatMap& m : maps) {
    images.push_back(Render(m));
    width = std::max(width, images.back().cols);
  }
  if (images.empty()) images.emplace_back(1, 1, CV_8UC3, cv::Scalar(255, 255, 255));
  for (cv::Mat& im : images) {
    if (im.cols < width) cv::copyMakeBorder(im, im, 0, 0, 0, width - im.cols, cv::BORDER_CONSTANT, cv::Scalar(255, 255, 255));
  }
  cv::Mat all;
  cv::vconcat(images, all);
  return Encode(all);
}

void SaveHeatMapsPng(const std::vector<HeatMap>& maps, const std::string& path) {
  const std::vector<unsigned char> png = EncodeHeatMapsPng(maps);
  io::WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace robomach::report
