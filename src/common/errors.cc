#include "robomach/common/errors.h"

namespace robomach {

std::string SourceLocation::ToString() const {
  std::string s = path.empty() ? std::string("<input>") : path;
  if (line > 0) {
    s += ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
  }
  return s;
}

InputError::InputError(SourceLocation where, const std::string& message)
    : std::runtime_error(where.ToString() + ": " + message),
      where_(std::move(where)),
      message_(message) {}

}  // namespace robomach
