#pragma once

#include <string>

namespace robomach::report {

/// Text for an HTML page, in element content or in a quoted attribute:
/// & < > " ' become entities.
std::string HtmlEscape(const std::string& text);

}  // namespace robomach::report
