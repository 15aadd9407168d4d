#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace robomach {

/// `text` with every byte that is not part of valid UTF-8 written as \xHH
/// (e.g. a Latin-1 "é" from a file header as \xE9), for messages: a raw
/// byte would garble the terminal and make a JSON summary invalid. Valid
/// UTF-8 (ASCII, "²", "µ") is kept as it is.
std::string EscapeInvalidUtf8(std::string_view text);

/// Where in a user's file something was found. Lines and columns are 1-based;
/// 0 means unknown.
struct SourceLocation {
  std::string path;
  int line{0};
  int column{0};
  /// "path", "path:line" or "path:line:column".
  std::string ToString() const;
};

/// Malformed or out-of-range user data. what() == "path:line[:col]: message".
/// Bytes of the path or message that are not UTF-8 are escaped
/// (EscapeInvalidUtf8): the message quotes text from the user's file.
class InputError : public std::runtime_error {
 public:
  InputError(SourceLocation where, const std::string& message);
  const SourceLocation& where() const { return where_; }
  /// The message without the location prefix.
  const std::string& message() const { return message_; }

 private:
  SourceLocation where_;
  std::string message_;
};

/// An output file could not be created, written or renamed into place.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A numerical method failed at the values it was given: a factorisation or
/// an eigensolver did not succeed (a mass matrix that is not positive
/// definite at an extreme parameter value), a result is not finite. Code that
/// tries many values (a fit's trial points, an audit's candidates) catches
/// this type, and only this type, and treats the value as infeasible; any
/// other exception there is bad input or a bug and propagates.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An option of a workflow (a field of an options struct) out of its
/// bounds, or one the data cannot meet (issue #36: the validators name the
/// field, its value and the bound). what() is the message; field() the
/// struct's field, which a tool maps to its option (exit 64) and Python
/// to its keyword argument (ValueError).
class OptionError : public std::invalid_argument {
 public:
  OptionError(std::string field, const std::string& message)
      : std::invalid_argument(message), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

/// Runs `f` and returns what it returns; an exception of type E it throws
/// (std::invalid_argument by default: a check that knows no file) becomes an
/// InputError at `where` whose message is `prefix` followed by the
/// exception's. The one way to attach a file location to an error (issue
/// #36), instead of a try/catch that rethrows at each site:
///
///   const Axis axis = AtLocation({path, line, column}, "feed_direction: ",
///                                [&] { return ParseAxis(text); });
template <class E = std::invalid_argument, class F>
decltype(auto) AtLocation(const SourceLocation& where, const std::string& prefix, F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const E& e) {
    throw InputError(where, prefix + e.what());
  }
}

}  // namespace robomach

/// Debug-only check of an internal invariant (a robomach bug, not bad input).
#ifdef NDEBUG
#define ROBOMACH_ASSERT(cond) ((void)0)
#else
#include <cassert>
#define ROBOMACH_ASSERT(cond) assert(cond)
#endif
