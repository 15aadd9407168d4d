#pragma once
// Small text helpers the io readers share (private to io; part of io_base).

#include <string>
#include <string_view>

namespace robomach::io {

/// `s` without leading and trailing white space (std::isspace).
std::string Trim(std::string_view s);
/// `s` in lower case (ASCII).
std::string Lower(std::string s);

}  // namespace robomach::io
