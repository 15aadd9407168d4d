#include "robomach/io/frf_quantity.h"

#include <map>
#include <set>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "frf_text.h"

#include "text.h"

namespace robomach::io {


std::string QuantityUnit(FrfQuantity q) {
  switch (q) {
    case FrfQuantity::kReceptance: return "m/N";
    case FrfQuantity::kMobility: return "(m/s)/N";
    case FrfQuantity::kAccelerance: return "(m/s^2)/N";
  }
  return "?";
}

std::string ToString(FrfQuantity q) {
  switch (q) {
    case FrfQuantity::kReceptance: return "receptance";
    case FrfQuantity::kMobility: return "mobility";
    case FrfQuantity::kAccelerance: return "accelerance";
  }
  return "?";
}

std::string QuantityWithArticle(FrfQuantity q) {
  return (q == FrfQuantity::kAccelerance ? "an " : "a ") + ToString(q);
}

FrfQuantity ParseFrfQuantity(const std::string& name) {
  const std::string n = Lower(Trim(name));
  for (FrfQuantity q : {FrfQuantity::kReceptance, FrfQuantity::kMobility, FrfQuantity::kAccelerance}) {
    if (n == ToString(q)) return q;
  }
  throw std::invalid_argument("quantity '" + name +
                              "': expected receptance, mobility or accelerance");
}

std::complex<double> ToReceptance(FrfQuantity quantity, double freq_hz, std::complex<double> value) {
  const double w = HzToRadPerSec(freq_hz);
  switch (quantity) {
    case FrfQuantity::kReceptance: return value;
    case FrfQuantity::kMobility: return value / std::complex<double>(0.0, w);  // Y = iω H
    case FrfQuantity::kAccelerance: return -value / (w * w);                  // A = −ω² H
  }
  return value;
}

std::complex<double> FromReceptance(FrfQuantity quantity, double freq_hz, std::complex<double> h) {
  const double w = HzToRadPerSec(freq_hz);
  switch (quantity) {
    case FrfQuantity::kReceptance: return h;
    case FrfQuantity::kMobility: return h * std::complex<double>(0.0, w);
    case FrfQuantity::kAccelerance: return -h * (w * w);
  }
  return h;
}

void DropPointNumbers(const std::string& path, FrfReadResult* r) {
  std::map<std::string, std::set<std::pair<int, int>>> pairs;
  for (const auto& [k, f] : r->frfs) pairs[k.pose_id].insert({k.response_point, k.excitation_point});
  bool any = false;
  for (const auto& [pose, set] : pairs) {
    if (set.size() > 1) {
      std::string list;
      int shown = 0;
      for (const auto& [a, b] : set) {
        if (shown++ == 4) {
          list += ", ...";
          break;
        }
        list += (list.empty() ? "" : ", ") + std::to_string(a) + "->" + std::to_string(b);
      }
      throw InputError({path, 0, 0},
                       (pose.empty() ? std::string("the FRFs") : "posture " + pose) + " hold " +
                           std::to_string(set.size()) + " measurement-point pairs (response->excitation " + list +
                           "): a roving test. The tool-tip tools read one point per posture: give frf-modes this "
                           "file for the modes and shapes of every point, or split the export (one driving point "
                           "per file), or name the postures with pose=ID");
    }
    const auto [a, b] = *set.begin();
    any = any || a != 0 || b != 0;
    if (a != b) {
      r->warnings.push_back(path + ": " + (pose.empty() ? std::string() : "posture " + pose + ": ") +
                            "a transfer FRF between two points (response point " + std::to_string(a) +
                            ", excitation point " + std::to_string(b) +
                            "); a tool-tip FRF is a driving-point FRF (hammer and sensor at the tool tip), so it is "
                            "read as one only if the export numbered one point twice");
    }
  }
  if (!any) return;
  dynamics::FrfSet stripped;
  for (const auto& [k, f] : r->frfs) {
    dynamics::FrfKey k2 = k;
    k2.response_point = k2.excitation_point = 0;
    stripped.Insert(k2, f);
  }
  r->frfs = std::move(stripped);
}

}  // namespace robomach::io
