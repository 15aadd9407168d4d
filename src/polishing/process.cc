#include "robomach/polishing/process.h"

#include <cmath>
#include <sstream>

#include "robomach/polishing/hertz_contact.h"

namespace robomach::polishing {
namespace {
void Require(bool ok, const char* field, double value, const char* bound) {
  if (!ok) {
    std::ostringstream m;
    m << field << ": expected " << bound << ", got " << value;
    throw std::invalid_argument(m.str());
  }
}
}  // namespace

void CheckValid(const PolishingProcess& p) {
  Require(p.wheel_radius > 0 && std::isfinite(p.wheel_radius), "wheel_radius", p.wheel_radius, "> 0");
  Require(p.crown_radius > 0 && std::isfinite(p.crown_radius), "crown_radius", p.crown_radius, "> 0");
  Require(p.belt_width > 0 && std::isfinite(p.belt_width), "belt_width", p.belt_width, "> 0");
  Require(p.pad_modulus > 0 && std::isfinite(p.pad_modulus), "pad_modulus", p.pad_modulus, "> 0");
  Require(p.pad_poisson >= 0 && p.pad_poisson < 0.5, "pad_poisson", p.pad_poisson, "in [0, 0.5)");
  Require(p.belt_speed > 0 && std::isfinite(p.belt_speed), "belt_speed", p.belt_speed, "> 0");
  Require(p.work_modulus > 0 && std::isfinite(p.work_modulus), "work_modulus", p.work_modulus, "> 0");
  Require(p.work_poisson >= 0 && p.work_poisson < 0.5, "work_poisson", p.work_poisson, "in [0, 0.5)");
  Require(p.preston_coefficient > 0 && std::isfinite(p.preston_coefficient), "preston_coefficient",
          p.preston_coefficient, "> 0");
  Require(p.force > 0 && std::isfinite(p.force), "force", p.force, "> 0");
  Require(p.margin >= 0 && std::isfinite(p.margin), "margin", p.margin, ">= 0");
  Require(p.max_speed > 0 && std::isfinite(p.max_speed), "max_speed", p.max_speed, "> 0");
}

double EffectiveModulus(const PolishingProcess& p) {
  return EffectiveModulus(p.pad_modulus, p.pad_poisson, p.work_modulus, p.work_poisson);
}

}  // namespace robomach::polishing
