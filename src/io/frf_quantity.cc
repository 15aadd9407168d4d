#include "robomach/io/frf_quantity.h"

#include "robomach/common/units.h"
#include "frf_text.h"

#include "text.h"

namespace robomach::io {


std::string QuantityName(FrfQuantity q) {
  switch (q) {
    case FrfQuantity::kReceptance: return "receptance";
    case FrfQuantity::kMobility: return "mobility";
    case FrfQuantity::kAccelerance: return "accelerance";
  }
  return "?";
}

FrfQuantity ParseQuantity(const std::string& name) {
  const std::string n = Lower(Trim(name));
  if (n == "receptance") return FrfQuantity::kReceptance;
  if (n == "mobility") return FrfQuantity::kMobility;
  if (n == "accelerance") return FrfQuantity::kAccelerance;
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

}  // namespace robomach::io
