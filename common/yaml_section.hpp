#pragma once
// Reading YAML into config structs, strictly.
//
// Every component has one config struct. Its loader reads one YAML mapping
// through a YamlSection: each get() consumes a key; finish() rejects every
// key that nobody consumed, naming file, line and key. Type errors name the
// file, line, key and value. YAML is parsed only into config structs.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <array>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/config_error.hpp"

namespace ddswarm {

class YamlSection {
 public:
  /// node: a mapping (or null: an absent section reads as empty).
  /// file: path shown in errors; path: dotted prefix, e.g. "agent".
  YamlSection(YAML::Node node, std::string file, std::string path);

  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  bool has(const std::string& key) const;

  /// Reads key into out if present; leaves out unchanged otherwise.
  template <class T>
  void get(const std::string& key, T& out) {
    YAML::Node n = take(key);
    if (n) out = convert<T>(n, key);
  }

  /// Reads a string key through a name->value table (enums).
  template <class E>
  void get_enum(const std::string& key, E& out, const std::map<std::string, E>& names) {
    YAML::Node n = take(key);
    if (!n) return;
    std::string s = convert<std::string>(n, key);
    auto it = names.find(s);
    if (it == names.end()) {
      std::string allowed;
      for (auto& [k, v] : names) allowed += (allowed.empty() ? "" : "|") + k;
      fail(n, key, s, "must be one of " + allowed);
    }
    out = it->second;
  }

  /// A nested mapping; an absent key yields an empty section.
  YamlSection child(const std::string& key);

  /// A sequence of mappings (e.g. obstacles); absent yields empty.
  std::vector<YamlSection> children(const std::string& key);

  /// Throws ConfigError naming every key that was not consumed.
  void finish() const;

  /// Throws ConfigError "file:line: path.key = value: reason".
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& value,
                         const std::string& reason) const;

  /// Line (1-based) of key, or of this section when key is absent; 0 if unknown.
  int line_of(const std::string& key) const;

  /// The whole node (for copying sections verbatim, e.g. experiment overrides).
  const YAML::Node& node() const { return node_; }

 private:
  YAML::Node take(const std::string& key);
  template <class T>
  T convert(const YAML::Node& n, const std::string& key) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> consumed_;
};

/// A loaded YAML document that remembers the line of every dotted key path,
/// so errors found later (validate()) can still point at the file and line.
class YamlDocument {
 public:
  /// Loads path; throws ConfigError on a missing file or a syntax error.
  static YamlDocument load_file(const std::string& path);
  /// Parses text (file is only used in messages).
  static YamlDocument parse(const std::string& text, const std::string& file);

  YamlSection section(const std::string& key) const;
  const YAML::Node& root() const { return root_; }
  const std::string& file() const { return file_; }

  /// Runs fn (load + validate); turns a FieldError into a ConfigError with
  /// the file and the line of the field (or its nearest known parent).
  void guard(const std::function<void()>& fn) const;

 private:
  void index(const YAML::Node& n, const std::string& prefix, int depth);
  YAML::Node root_;
  std::string file_;
  std::map<std::string, int> lines_;
};

}  // namespace ddswarm
