#pragma once
// The one name-keyed registry idiom (issue #36 "one vocabulary"): the
// effects, the drilling controller kinds, the polishing path patterns and the
// machine kinematics are each a NamedRegistry of their entries, kept in the
// order they were added; an enum's names are the same idiom over a fixed
// array (ParseByName, enum_names.h). Both refuse a name with one message:
// "<what> '<name>': expected a, b or c" (ThrowUnknownName).

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace robomach {

/// "a", "a or b", "a, b or c": the names for a message ("" for none).
inline std::string NameListOf(const std::vector<std::string>& names) {
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i) {
    list += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + names[i];
  }
  return list;
}

/// @throws std::invalid_argument "<what> '<name>': expected <expected>", the
/// refusal of every registry and enum parser (`expected` is a NameListOf).
[[noreturn]] inline void ThrowUnknownName(const std::string& what, const std::string& name,
                                          const std::string& expected) {
  throw std::invalid_argument(what + " '" + name + "': expected " + expected);
}

/// Entries of type T (a factory, a pointer to a singleton, a value) by name,
/// in the order of Add. Not thread-safe while being filled; fill it once
/// (a function-local static) and only read it afterwards.
template <class T>
class NamedRegistry {
 public:
  /// `what` starts the message of an unknown name: "unknown path pattern".
  explicit NamedRegistry(std::string what) : what_(std::move(what)) {}

  /// Adds `value` under `name`. @throws std::logic_error when the name is
  /// taken (two entries of one name are a robomach bug, not bad input).
  NamedRegistry& Add(std::string name, T value) {
    if (Contains(name)) throw std::logic_error(what_ + ": '" + name + "' added twice");
    entries_.emplace_back(std::move(name), std::move(value));
    return *this;
  }

  bool Contains(const std::string& name) const { return Get(name) != nullptr; }

  /// The entry of `name`, or nullptr (for a caller that tries more, such as
  /// EffectRegistry's families).
  const T* Get(const std::string& name) const {
    for (const auto& [n, v] : entries_) {
      if (n == name) return &v;
    }
    return nullptr;
  }

  /// The entry of `name`. @throws std::invalid_argument
  /// "<what> '<name>': expected a, b or c".
  const T& Find(const std::string& name) const {
    if (const T* v = Get(name)) return *v;
    ThrowUnknownName(what_, name, NameList());
  }

  /// The names in the order of Add.
  std::vector<std::string> Names() const {
    std::vector<std::string> names;
    names.reserve(entries_.size());
    for (const auto& [n, v] : entries_) names.push_back(n);
    return names;
  }

  /// "a, b or c".
  std::string NameList() const { return NameListOf(Names()); }

  /// The entries in the order of Add (for a caller that lists them all).
  std::vector<T> Values() const {
    std::vector<T> values;
    values.reserve(entries_.size());
    for (const auto& [n, v] : entries_) values.push_back(v);
    return values;
  }

  /// The (name, entry) pairs in the order of Add.
  const std::vector<std::pair<std::string, T>>& entries() const { return entries_; }
  std::size_t size() const { return entries_.size(); }
  const std::string& what() const { return what_; }

 private:
  std::string what_;
  std::vector<std::pair<std::string, T>> entries_;
};

}  // namespace robomach
