#pragma once
// The text of an option that is a list (issue #36: one parser, used by the
// tools and the workflows alike). Errors are OptionError naming the field
// (or the option, when a tool passes its option's name).

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace robomach::workflows {

/// "1,2.5,3" -> numbers; @throws OptionError(field, "FIELD: expected
/// numbers separated by commas, got \"TEXT\"").
std::vector<double> ParseNumberList(const std::string& field, const std::string& text);

/// "x,y,z" in millimetres -> metres, or nullopt for "tcp" (or empty);
/// @throws OptionError(field, "FIELD: expected x,y,z in mm or 'tcp', ...").
std::optional<Eigen::Vector3d> ParsePointMm(const std::string& field, const std::string& text);

}  // namespace robomach::workflows
