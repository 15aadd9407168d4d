#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/dynamics/uncertainty.h"

namespace robomach::io {

inline constexpr char kUncertaintyFileFormat[] =
    "a parameter-uncertainty YAML (docs/formats.md §12, as kq-identify --uncertainty-out writes)";

/// The YAML of docs/formats.md §12: `parameter_uncertainty:` with `source`,
/// `parameters` (name, value, scale) and `covariance` (rows in the order of
/// the parameters), numbers to full precision; each parameter's standard
/// deviation and the correlations as comments for a reader.
std::string ParameterUncertaintyYaml(const dynamics::ParameterUncertainty& u);

/// Writes ParameterUncertaintyYaml atomically (nothing half-written).
void WriteParameterUncertainty(const std::string& path, const dynamics::ParameterUncertainty& u);

/// Reads one file. @throws MissingFileError; InputError at file:line:col for
///   another kind of file, a missing or unknown key, a scale that is not
///   linear/log/inverse, a row of the wrong length, or a covariance that is
///   not symmetric positive semi-definite (dynamics::CheckValid's words).
dynamics::ParameterUncertainty ReadParameterUncertainty(const std::string& path);

/// Reads several files and combines them as independent campaigns
/// (dynamics::CombineIndependent). @throws InputError naming both files when
///   one parameter is in two of them.
dynamics::ParameterUncertainty ReadParameterUncertainties(const std::vector<std::string>& paths);

/// For JSON summaries: [{name, value, scale, std_dev_theta}], the
/// covariance's rows under "covariance" and the source.
nlohmann::json ParameterUncertaintyToJson(const dynamics::ParameterUncertainty& u);

/// A posture's mode intervals: {method, reason, evaluations, modes: [{mode,
/// freq_hz, freq_hz_lower, freq_hz_upper, damping_ratio(_lower/_upper),
/// peak_receptance_m_per_N(_lower/_upper)}]}.
nlohmann::json ModeIntervalsToJson(const dynamics::PostureModeIntervals& intervals);

}  // namespace robomach::io
