#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "robomach/common/errors.h"
#include "robomach/io/file_kind.h"

namespace robomach::io {

/// A YAML node that knows its file and position, so every error names
/// `file:line:col` (yaml-cpp marks are 0-based; we add 1, style.md §3).
/// Maps remember which keys were read; RejectUnknownKeys() reports the rest.
class YamlDoc {
 public:
  /// @throws MissingFileError if the file is missing or cannot be read;
  ///   InputError if it is recognised as another kind of file (a CSV table,
  ///   UFF58, a picture; the message names `expected`, see io/file_kind.h)
  ///   or is not valid YAML.
  static YamlDoc LoadFile(const std::string& path, const std::string& expected = kYamlFileFormat);
  static YamlDoc LoadString(const std::string& text, const std::string& path);

  const std::string& path() const { return *path_; }
  SourceLocation location() const;
  /// Dotted key path from the document root, for messages ("robot.urdf").
  const std::string& key_path() const { return key_path_; }
  /// An InputError at this node: "file:line:col: key.path: message".
  InputError Error(const std::string& message) const;
  /// Runs `f` and returns what it returns; an exception of type E it throws
  /// (std::invalid_argument by default: a check that knows no file) becomes
  /// Error(e.what()), at this node with its key path. AtLocation's form for
  /// a YAML node (common/errors.h), instead of a try/catch at each site:
  ///
  ///   p.hole_axis = axis.Checked([&] { return drilling::ParseHoleAxis(a); });
  template <class E = std::invalid_argument, class F>
  decltype(auto) Checked(F&& f) const {
    try {
      return std::forward<F>(f)();
    } catch (const E& e) {
      throw Error(e.what());
    }
  }

  bool IsMap() const { return node_.IsMap(); }
  bool IsSequence() const { return node_.IsSequence(); }
  bool IsNull() const { return !node_ || node_.IsNull(); }
  bool Has(const std::string& key) const;
  /// @throws InputError "file:line:col: missing key 'x' in 'parent'".
  YamlDoc operator[](const std::string& key) const;
  /// Keys of a map in file order.
  /// "; the file's keys are those of a robot config (...): the file for
  /// another option?" when this map's keys are those of one of robomach's
  /// YAML files and `missing` is not a key of that kind; "" otherwise.
  /// Added to a missing top-level key.
  std::string OtherYamlKind(const std::string& missing) const;
  std::vector<std::string> Keys() const;
  int size() const;               // sequence length
  YamlDoc at(int index) const;    // sequence element

  double Number() const;
  double PositiveNumber() const;
  double NumberInRange(double lo, double hi, bool include_lo = true, bool include_hi = true) const;
  int Int() const;
  int IntInRange(int lo, int hi) const;
  bool Bool() const;
  std::string String() const;
  /// A sequence of numbers; `expected_size` < 0 accepts any length.
  std::vector<double> Numbers(int expected_size = -1) const;
  std::vector<std::string> Strings() const;

  /// Marks `key` as known without reading it.
  void MarkUsed(const std::string& key) const;
  /// @throws InputError at the first key of this map never read or marked.
  void RejectUnknownKeys() const;

 private:
  YamlDoc(YAML::Node node, std::shared_ptr<const std::string> path, std::string key_path);
  YAML::Node node_;
  std::shared_ptr<const std::string> path_;
  std::string key_path_;
  std::shared_ptr<std::vector<std::string>> used_keys_;
};

/// Resolves a path given inside a config file relative to that file's folder.
std::string ResolveRelative(const std::string& config_path, const std::string& relative);

/// A path given inside the config at `config_path`, rewritten for a copy of
/// that config written to `output_path`: a relative path is re-based onto the
/// copy's folder so that ResolveRelative(output_path, result) names the file
/// ResolveRelative(config_path, path) names; an absolute path is returned
/// unchanged. Lexical, as ResolveRelative is: the '..' of a path through a
/// symbolic link undoes the link's name, not the folder it points to.
std::string RebaseRelative(const std::string& config_path, const std::string& path,
                           const std::string& output_path);

}  // namespace robomach::io
