#pragma once
// The one idiom of an enum's words (issue #36 "one vocabulary"): each enum a
// file, a summary, a message or a tool's option names has one printer
// `ToString(E)` and one parser `ParseE(name)` in its module's header. The
// parsers are written with ParseByName below, so they accept exactly the
// printer's spellings and name them all when they refuse one. It is the
// enum case of the name-keyed registry (named_registry.h): the same refusal,
// "<what> '<name>': expected a, b or c" (ThrowUnknownName).

#include <cstddef>
#include <string>
#include <vector>

#include "robomach/common/named_registry.h"

namespace robomach {

/// The value of `all` whose ToString (found by argument-dependent lookup in
/// E's namespace) is `name`. @throws std::invalid_argument
/// "<what> '<name>': expected a, b or c" for anything else.
template <typename E, std::size_t N>
E ParseByName(const std::string& what, const std::string& name, const E (&all)[N]) {
  for (E e : all) {
    if (name == ToString(e)) return e;
  }
  std::vector<std::string> names;
  for (E e : all) names.emplace_back(ToString(e));
  ThrowUnknownName(what, name, NameListOf(names));
}

}  // namespace robomach
