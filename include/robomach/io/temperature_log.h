#pragma once
// Temperature log of the compensation (formats.md §8.4).
// Units are converted here, once: mm -> m, deg -> rad.

#include <string>
#include <vector>

#include "robomach/io/machine_file.h"
#include "robomach/machine/compensation.h"

namespace robomach::io {

// Plausible ranges of the log's numbers (docs/plausibility.md). The log is
// seed eq. 5, dTemp = K0 + tan(beta) (P - P0): K0 is the thermal offset of
// the axis, tan(beta) its thermal growth per unit of position, P0 the
// position where the growth is zero. Thermal drifts of machine tools are
// tens of um (tested by ISO 230-3; the review of Mayr et al., "Thermal
// issues in machine tools", CIRP Annals 61/2 (2012)), so an offset over 1 mm
// is um typed for mm (x1000).
inline constexpr double kMaxPlausibleThermalOffsetMm = 1.0;
/// Refused (exit 65): no axis drifts by 10 cm.
inline constexpr double kMaxThermalOffsetMm = 100.0;
/// |tan_beta|: the expansion coefficient times the warming. Steel and cast
/// iron 10 - 12e-6 /K, aluminium 23e-6 /K; 40 K of warming gives at most
/// 1e-3 (real logs: 1e-6 - 1e-4). Above: the slope in um/m (ppm, x1e6),
/// mm/m (x1000) or percent (x100).
inline constexpr double kMaxPlausibleThermalSlope = 1e-3;
/// Refused (exit 65): a growth of 10 % of the position (4000 K of warming
/// for aluminium) is no thermal slope.
inline constexpr double kMaxThermalSlope = 0.1;
/// t_s: a row later than a day after the counts' clock started is a time in
/// ms (records of a machining test last seconds to hours; 8 kHz counts over
/// a day are 7e8 rows).
inline constexpr double kMaxPlausibleLogTimeS = 86400.0;

/// Temperature log `t_s,axis,K0_mm,tan_beta,P0_mm` (formats.md §8.4).
/// @throws InputError "file:line: column NAME: ..." for an unknown or rotary
///   axis, t_s not increasing per axis, |K0_mm| over kMaxThermalOffsetMm,
///   |tan_beta| over kMaxThermalSlope, |P0_mm| over kMaxMachineLengthMm.
/// Values outside the plausible ranges (K0_mm, tan_beta, P0_mm within
/// kMaxPlausibleMachineLengthMm, t_s up to kMaxPlausibleLogTimeS) give one
/// "implausible (unit mistake?): file:line: column NAME: ..." per column in
/// *implausible (the largest value; not collected when null); the axis
/// tools print them and flag their result (exit 3).
std::vector<machine::TemperatureCompensation> ReadTemperatureLog(const std::string& path,
                                                                 const MachineFile& machine,
                                                                 std::vector<std::string>* implausible = nullptr);

}  // namespace robomach::io
