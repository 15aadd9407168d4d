#include "robomach/drilling/plausibility.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "robomach/common/number_format.h"

namespace robomach::drilling {
std::vector<std::string> ToolingFindings(const DrillGeometry& drill, const DrillingProcess* process) {
  std::vector<std::string> out;
  const double d_mm = MToMm(drill.diameter);
  if (drill.diameter < kMinPlausibleDrillDiameter || drill.diameter > kMaxPlausibleDrillDiameter) {
    out.push_back("drill diameter_mm " + FormatNumber(d_mm) + " mm is outside the " + FormatNumber(MToMm(kMinPlausibleDrillDiameter)) +
                  " to " + FormatNumber(MToMm(kMaxPlausibleDrillDiameter)) + " mm of twist drills: " +
                  (drill.diameter < kMinPlausibleDrillDiameter ? "a diameter in m typed in the mm field?"
                                                               : "a diameter in um typed in the mm field?"));
  }
  if (!process) return out;
  const double f_mm = MToMm(process->feed_per_rev);
  if (process->feed_per_rev < kMinPlausibleFeedPerRev || process->feed_per_rev > kMaxPlausibleFeedPerRev) {
    out.push_back("feed_mm_per_rev " + FormatNumber(f_mm) + " mm/rev is outside the " + FormatNumber(MToMm(kMinPlausibleFeedPerRev)) +
                  " to " + FormatNumber(MToMm(kMaxPlausibleFeedPerRev)) + " mm/rev of drilling practice: " +
                  (process->feed_per_rev > kMaxPlausibleFeedPerRev ? "a feed in mm/min (feed per rev x rpm)?"
                                                                   : "a feed in m/rev typed in the mm field?"));
  }
  const double rpm = RadPerSecToRpm(process->spindle_speed_rad_s);
  if (rpm < kMinPlausibleSpindleSpeedRpm || rpm > kMaxPlausibleSpindleSpeedRpm) {
    out.push_back("speed_rpm " + FormatNumber(rpm) + " rpm is outside the " + FormatNumber(kMinPlausibleSpindleSpeedRpm) + " to " +
                  FormatNumber(kMaxPlausibleSpindleSpeedRpm) + " rpm of drilling spindles: " +
                  (rpm < kMinPlausibleSpindleSpeedRpm ? "a speed in rev/s?" : "a speed in rad/min or a cutting speed?"));
  }
  const double vc = drill.diameter * 0.5 * process->spindle_speed_rad_s;  // pi D n
  if (vc < kMinPlausibleCuttingSpeed || vc > kMaxPlausibleCuttingSpeed) {
    out.push_back("the cutting speed pi D n = " + FormatNumber(vc * 60.0) + " m/min (D " + FormatNumber(d_mm) + " mm, " + FormatNumber(rpm) +
                  " rpm) is outside the " + FormatNumber(kMinPlausibleCuttingSpeed * 60.0) + " to " +
                  FormatNumber(kMaxPlausibleCuttingSpeed * 60.0) +
                  " m/min of drilling metals: check the units of diameter_mm and speed_rpm");
  }
  return out;
}

std::vector<std::string> ForceTableFindings(const std::vector<ForceTableRow>& rows) {
  std::vector<std::string> out;
  std::vector<double> ratio;
  for (const ForceTableRow& r : rows) {
    if (r.thrust > 0 && r.diameter > 0 && r.torque > 0) ratio.push_back(r.torque / (r.thrust * r.diameter));
  }
  if (ratio.empty()) return out;
  std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
  const double med = ratio[ratio.size() / 2];
  if (med < kMinPlausibleTorqueThrustRatio || med > kMaxPlausibleTorqueThrustRatio) {
    out.push_back("the median torque / (thrust x diameter) of the table is " + FormatNumber(med) + ", outside the " +
                  FormatNumber(kMinPlausibleTorqueThrustRatio) + " to " + FormatNumber(kMaxPlausibleTorqueThrustRatio) +
                  " of twist drills (the lips' force acts near D/4): " +
                  (med > kMaxPlausibleTorqueThrustRatio
                       ? "the torque is probably in N·mm under torque_Nm (or the thrust in kN under thrust_N)"
                       : "the torque is probably in kN·m under torque_Nm (or the thrust in mN under thrust_N)"));
  }
  return out;
}

std::vector<std::string> MaterialFindings(const DrillingMaterial& material) {
  std::vector<std::string> out;
  const auto check = [&](double k, const char* name) {
    if (k < kMinPlausibleShearStress || k > kMaxPlausibleShearStress) {
      out.push_back(std::string(name) + " = " + FormatNumber(k * 1e-6) + " MPa is outside the " +
                    FormatNumber(kMinPlausibleShearStress * 1e-6) + " to " + FormatNumber(kMaxPlausibleShearStress * 1e-6) +
                    " MPa of the shear stresses of metals in cutting: a unit mistake in the table (torque in N·mm, "
                    "thrust in kN, diameter or feed in m) or a material that is not a metal");
    }
  };
  check(material.shear_stress_thrust, "shear_stress_thrust (K_TH)");
  check(material.shear_stress_torque, "shear_stress_torque (K_TQ)");
  return out;
}

}  // namespace robomach::drilling
