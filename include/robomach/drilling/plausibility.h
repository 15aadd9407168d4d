#pragma once
// Unit plausibility of drilling inputs and results (issue #22 item 1): values
// far outside twist-drilling practice are almost always a unit mistake (m in
// an _mm field, mm/min in a mm/rev column, N·mm in a N·m column). Each check
// returns findings, one sentence each naming the value, the range and the
// likely mistake; the tools print them and flag the result (exit 3).

#include <string>
#include <vector>

#include "robomach/drilling/drill_forces.h"
#include "robomach/drilling/drilling_process.h"
#include "robomach/drilling/force_fit.h"

namespace robomach::drilling {

// Twist-drill diameters [m]: micro drills start near 0.1 mm, solid and
// indexable drills end near 80-100 mm (Sandvik Coromant, Drilling: Technical
// guide (2017), "Drilling tool range" 0.3-84 mm; micro drills to 0.1 mm,
// Machinery's Handbook 30th ed., "Twist drill sizes").
inline constexpr double kMinPlausibleDrillDiameter = 0.1e-3;
inline constexpr double kMaxPlausibleDrillDiameter = 100e-3;
// Feed per revolution [m/rev]: 0.005 mm/rev (micro drills) to 1 mm/rev
// (large drills in soft material); Machinery's Handbook 30th ed., "Feeds for
// drilling" (0.001-0.040 in/rev = 0.025-1.0 mm/rev for 1/16-2 in drills),
// Sandvik Coromant Drilling guide (fn 0.05-0.8 mm/rev for solid drills).
inline constexpr double kMinPlausibleFeedPerRev = 0.005e-3;
inline constexpr double kMaxPlausibleFeedPerRev = 1.0e-3;
// Cutting speed at the drill's periphery v_c = pi D n [m/s]: 1 m/min (HSS in
// hardened or high-temperature alloys, at the low end of Machinery's
// Handbook 30th ed. Tables "Cutting speeds for drilling") to 1000 m/min
// (carbide in aluminium alloys, Sandvik Coromant guide: up to ~600 m/min).
inline constexpr double kMinPlausibleCuttingSpeed = 1.0 / 60.0;
inline constexpr double kMaxPlausibleCuttingSpeed = 1000.0 / 60.0;
// Spindle speed [rpm] of drilling spindles: 10 rpm to 100 000 rpm (high-speed
// PCB and micro-drilling spindles reach 60 000-300 000 rpm; a robot or machine
// spindle stays under 40 000 rpm; the range only catches rad/s or rev/s typed).
inline constexpr double kMinPlausibleSpindleSpeedRpm = 10.0;
inline constexpr double kMaxPlausibleSpindleSpeedRpm = 100000.0;
// Torque over (thrust x diameter), T / (F D), of a twist drill: the lips'
// cutting force acts at about D/4 and the thrust is of the order of the
// cutting force (Shaw and Oxford, "On the drilling of metals 2 - The torque
// and thrust in drilling", Trans. ASME 79 (1957) 139-148: T ~ f^0.8 D^1.8,
// F ~ f^0.8 D^0.8 + chisel term); measured tables give 0.1-0.5 (0.30 for the
// shipped Q235/HSS table). A factor of ~10 either side is allowed; N·mm
// under torque_Nm gives ~300, kN under thrust_N ~300, N under torque_Nm with
// thrust in kN ~3e-4.
inline constexpr double kMinPlausibleTorqueThrustRatio = 0.02;
inline constexpr double kMaxPlausibleTorqueThrustRatio = 3.0;
// Shear-stress coefficients K_TH, K_TQ [Pa]: the shear flow stress of metals
// in cutting runs from ~100 MPa (pure aluminium, copper) to ~1.5 GPa
// (hardened steel, nickel alloys); Altintas, Manufacturing Automation, 2nd
// ed. (2012), Table 2.1 (Al 7075 297 MPa, AISI 1045 ~600 MPa, Ti6Al4V
// 613 MPa); the coefficients of the force model are this stress times
// factors of order one, so 30 MPa to 10 GPa is allowed.
inline constexpr double kMinPlausibleShearStress = 30e6;
inline constexpr double kMaxPlausibleShearStress = 10e9;

/// Diameter, feed per revolution, spindle speed and cutting speed against
/// tooling practice (`process` may be null: the drill alone).
std::vector<std::string> ToolingFindings(const DrillGeometry& drill, const DrillingProcess* process);

/// The median T / (F D) of the rows against its plausible range (the
/// torque and thrust columns' units), then K_TH and K_TQ of `material`
/// against the shear stresses of metals.
std::vector<std::string> ForceTableFindings(const std::vector<ForceTableRow>& rows);
std::vector<std::string> MaterialFindings(const DrillingMaterial& material);

}  // namespace robomach::drilling
