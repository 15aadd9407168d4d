#include "robomach/io/prediction_files.h"

#include <algorithm>
#include <stdexcept>

#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

DirectionPairs AllDirectionPairs() {
  DirectionPairs p;
  for (int r = 0; r < 3; ++r) {
    for (int e = 0; e < 3; ++e) p.emplace_back(r, e);
  }
  return p;
}

DirectionPairs ParseDirectionPairs(const std::string& text) {
  if (text == "all") return AllDirectionPairs();
  DirectionPairs out;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t comma = text.find(',', pos);
    if (comma == std::string::npos) comma = text.size();
    const std::string item = text.substr(pos, comma - pos);
    auto axis = [&](char c) {
      if (c < 'x' || c > 'z') {
        throw std::invalid_argument("direction pair '" + item +
                                    "': expected two of x, y, z such as xx or xy");
      }
      return c - 'x';
    };
    if (item.size() != 2) {
      throw std::invalid_argument("direction pair '" + item +
                                  "': expected two of x, y, z such as xx or xy");
    }
    const std::pair<int, int> pair(axis(item[0]), axis(item[1]));
    if (std::find(out.begin(), out.end(), pair) != out.end()) {
      throw std::invalid_argument("direction pair '" + item + "' is given twice");
    }
    out.push_back(pair);
    pos = comma + 1;
  }
  return out;
}

void WritePredictedFrfCsv(const std::string& path, const std::vector<PosturePrediction>& predictions,
                          const DirectionPairs& pairs) {
  WriteFileAtomically(path, [&](std::ostream& os) { WritePredictedFrfCsv(os, predictions, pairs); });
}

void WritePredictedFrfCsv(std::ostream& os, const std::vector<PosturePrediction>& predictions,
                          const DirectionPairs& pairs) {
  {
    os << "# quantity: receptance\n";
    os << "# written by robomach frf-predict; receptance in m/N, directions in the robot base frame\n";
    os << "pose_id,response,excitation,freq_hz,re,im\n";
    for (const auto& p : predictions) {
      for (const auto& [r, e] : pairs) {
        for (Eigen::Index i = 0; i < p.freq_hz.size(); ++i) {
          const std::complex<double> h = p.H[i](r, e);
          os << p.pose_id << ',' << "xyz"[r] << ',' << "xyz"[e] << ',' << FormatDouble(p.freq_hz(i))
             << ',' << FormatDouble(h.real()) << ',' << FormatDouble(h.imag()) << '\n';
        }
      }
    }
  }
}

void WriteModalTableCsv(const std::string& path, const std::vector<std::string>& pose_ids,
                        const std::vector<std::vector<dynamics::Mode>>& modes) {
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << "pose_id,mode,freq_hz,damping_ratio,modal_mass_kg,ux,uy,uz\n";
    for (size_t p = 0; p < pose_ids.size(); ++p) {
      for (size_t k = 0; k < modes[p].size(); ++k) {
        const dynamics::Mode& m = modes[p][k];
        os << pose_ids[p] << ',' << k + 1 << ',' << FormatDouble(m.freq_hz) << ','
           << FormatDouble(m.damping_ratio) << ',' << FormatDouble(m.modal_mass_kg) << ','
           << FormatDouble(m.shape_T(0)) << ',' << FormatDouble(m.shape_T(1)) << ','
           << FormatDouble(m.shape_T(2)) << '\n';
      }
    }
  });
}

}  // namespace robomach::io
