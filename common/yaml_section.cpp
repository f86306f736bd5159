#include "common/yaml_section.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace ddswarm {
namespace {

std::string scalar_text(const YAML::Node& n) {
  if (n.IsScalar()) return n.Scalar();
  std::ostringstream os;
  os << YAML::Dump(n);
  std::string s = os.str();
  for (auto& c : s)
    if (c == '\n') c = ' ';
  return s;
}

std::string join(const std::string& a, const std::string& b) { return a.empty() ? b : a + "." + b; }

}  // namespace

YamlSection::YamlSection(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    throw ConfigError(file_ + ":" + std::to_string(node_.Mark().line + 1) + ": " + path_ +
                      ": must be a mapping of key: value");
  }
}

bool YamlSection::has(const std::string& key) const { return node_ && node_.IsMap() && node_[key]; }

YAML::Node YamlSection::take(const std::string& key) {
  consumed_.insert(key);
  if (!node_ || !node_.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  YAML::Node n = node_[key];
  if (!n || n.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
  return n;
}

int YamlSection::line_of(const std::string& key) const {
  if (node_ && node_.IsMap()) {
    for (auto it = node_.begin(); it != node_.end(); ++it)
      if (it->first.Scalar() == key) return it->first.Mark().line + 1;
  }
  return node_ ? node_.Mark().line + 1 : 0;
}

void YamlSection::fail(const YAML::Node& at, const std::string& key, const std::string& value,
                       const std::string& reason) const {
  int line = (at && at.Mark().line >= 0) ? at.Mark().line + 1 : line_of(key);
  throw ConfigError(file_ + ":" + std::to_string(line) + ": " + join(path_, key) + " = " + value +
                    ": " + reason);
}

template <class T>
T YamlSection::convert(const YAML::Node& n, const std::string& key) const {
  try {
    if constexpr (std::is_same_v<T, double> || std::is_same_v<T, float>) {
      if (!n.IsScalar()) fail(n, key, scalar_text(n), "must be a number");
      std::string s = n.Scalar();
      // yaml-cpp accepts .nan/.inf; a config never wants them.
      T v = n.as<T>();
      if (!std::isfinite(v)) fail(n, key, s, "must be a finite number");
      return v;
    } else if constexpr (std::is_same_v<T, bool>) {
      return n.as<bool>();
    } else if constexpr (std::is_integral_v<T>) {
      if (!n.IsScalar()) fail(n, key, scalar_text(n), "must be an integer");
      return n.as<T>();
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (!n.IsScalar()) fail(n, key, scalar_text(n), "must be a string");
      return n.Scalar();
    } else if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
      if (!n.IsSequence() || n.size() != 3) fail(n, key, scalar_text(n), "must be [x, y, z]");
      Eigen::Vector3d v;
      for (int i = 0; i < 3; ++i) v[i] = convert<double>(n[i], key);
      return v;
    } else if constexpr (std::is_same_v<T, Eigen::Vector2d>) {
      if (!n.IsSequence() || n.size() != 2) fail(n, key, scalar_text(n), "must be [x, y]");
      return Eigen::Vector2d(convert<double>(n[0], key), convert<double>(n[1], key));
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      if (!n.IsSequence()) fail(n, key, scalar_text(n), "must be a list of numbers");
      std::vector<double> v;
      for (const auto& e : n) v.push_back(convert<double>(e, key));
      return v;
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      if (!n.IsSequence()) fail(n, key, scalar_text(n), "must be a list of strings");
      std::vector<std::string> v;
      for (const auto& e : n) v.push_back(convert<std::string>(e, key));
      return v;
    } else if constexpr (std::is_same_v<T, std::vector<Eigen::Vector2d>>) {
      if (!n.IsSequence()) fail(n, key, scalar_text(n), "must be a list of [x, y] points");
      std::vector<Eigen::Vector2d> v;
      for (const auto& e : n) v.push_back(convert<Eigen::Vector2d>(e, key));
      return v;
    } else if constexpr (std::is_same_v<T, std::vector<Eigen::Vector3d>>) {
      if (!n.IsSequence()) fail(n, key, scalar_text(n), "must be a list of [x, y, z] points");
      std::vector<Eigen::Vector3d> v;
      for (const auto& e : n) v.push_back(convert<Eigen::Vector3d>(e, key));
      return v;
    } else {
      static_assert(sizeof(T) == 0, "unsupported config field type");
    }
  } catch (const YAML::Exception&) {
    const char* what = std::is_same_v<T, bool>       ? "must be true or false"
                       : std::is_integral_v<T>       ? "must be an integer"
                       : std::is_floating_point_v<T> ? "must be a number"
                                                     : "has the wrong type";
    fail(n, key, scalar_text(n), what);
  }
}

template double YamlSection::convert<double>(const YAML::Node&, const std::string&) const;
template float YamlSection::convert<float>(const YAML::Node&, const std::string&) const;
template bool YamlSection::convert<bool>(const YAML::Node&, const std::string&) const;
template int YamlSection::convert<int>(const YAML::Node&, const std::string&) const;
template unsigned YamlSection::convert<unsigned>(const YAML::Node&, const std::string&) const;
template long YamlSection::convert<long>(const YAML::Node&, const std::string&) const;
template unsigned long YamlSection::convert<unsigned long>(const YAML::Node&,
                                                           const std::string&) const;
template std::uint16_t YamlSection::convert<std::uint16_t>(const YAML::Node&,
                                                           const std::string&) const;
template std::string YamlSection::convert<std::string>(const YAML::Node&, const std::string&) const;
template Eigen::Vector3d YamlSection::convert<Eigen::Vector3d>(const YAML::Node&,
                                                               const std::string&) const;
template Eigen::Vector2d YamlSection::convert<Eigen::Vector2d>(const YAML::Node&,
                                                               const std::string&) const;
template std::vector<double> YamlSection::convert<std::vector<double>>(const YAML::Node&,
                                                                       const std::string&) const;
template std::vector<std::string> YamlSection::convert<std::vector<std::string>>(
    const YAML::Node&, const std::string&) const;
template std::vector<Eigen::Vector2d> YamlSection::convert<std::vector<Eigen::Vector2d>>(
    const YAML::Node&, const std::string&) const;
template std::vector<Eigen::Vector3d> YamlSection::convert<std::vector<Eigen::Vector3d>>(
    const YAML::Node&, const std::string&) const;

YamlSection YamlSection::child(const std::string& key) {
  YAML::Node n = take(key);
  return YamlSection(n ? n : YAML::Node(YAML::NodeType::Null), file_, join(path_, key));
}

std::vector<YamlSection> YamlSection::children(const std::string& key) {
  YAML::Node n = take(key);
  std::vector<YamlSection> out;
  if (!n) return out;
  if (!n.IsSequence()) fail(n, key, scalar_text(n), "must be a list");
  for (std::size_t i = 0; i < n.size(); ++i)
    out.emplace_back(n[i], file_, join(path_, key) + "[" + std::to_string(i) + "]");
  return out;
}

void YamlSection::finish() const {
  if (!node_ || !node_.IsMap()) return;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string k = it->first.Scalar();
    if (!consumed_.count(k)) {
      throw ConfigError(file_ + ":" + std::to_string(it->first.Mark().line + 1) + ": " +
                        join(path_, k) + ": unknown key");
    }
  }
}

YamlDocument YamlDocument::load_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw ConfigError(path + ": is a directory, not a scenario file");
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse(ss.str(), path);
}

YamlDocument YamlDocument::parse(const std::string& text, const std::string& file) {
  YamlDocument d;
  d.file_ = file;
  try {
    d.root_ = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(file + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
  if (d.root_ && !d.root_.IsNull() && !d.root_.IsMap())
    throw ConfigError(file + ":1: the document must be a mapping of sections");
  d.index(d.root_, "", 0);
  return d;
}

void YamlDocument::index(const YAML::Node& n, const std::string& prefix, int depth) {
  // An alias that refers to itself makes an endless tree; no config nests this deep.
  if (depth > 32)
    throw ConfigError(file_ + ":" + std::to_string(n.Mark().line + 1) + ": " +
                      prefix.substr(0, 80) +
                      "...: nested more than 32 levels (a recursive alias?)");
  if (n.IsMap()) {
    for (auto it = n.begin(); it != n.end(); ++it) {
      std::string p = join(prefix, it->first.Scalar());
      // yaml-cpp keeps both entries of a repeated key and reads the first:
      // a silent surprise, so it is an error.
      if (lines_.count(p))
        throw ConfigError(file_ + ":" + std::to_string(it->first.Mark().line + 1) + ": " + p +
                          ": duplicate key (first at line " + std::to_string(lines_[p]) + ")");
      lines_[p] = it->first.Mark().line + 1;
      index(it->second, p, depth + 1);
    }
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) {
      std::string p = prefix + "[" + std::to_string(i) + "]";
      lines_[p] = n[i].Mark().line + 1;
      index(n[i], p, depth + 1);
    }
  }
}

YamlSection YamlDocument::section(const std::string& key) const {
  YAML::Node n = root_ && root_.IsMap() ? root_[key] : YAML::Node();
  return YamlSection(n ? n : YAML::Node(YAML::NodeType::Null), file_, key);
}

void YamlDocument::guard(const std::function<void()>& fn) const {
  try {
    fn();
  } catch (const FieldError& e) {
    std::string p = e.field();
    int line = 0;
    while (!p.empty()) {
      auto it = lines_.find(p);
      if (it != lines_.end()) {
        line = it->second;
        break;
      }
      auto cut = p.find_last_of(".[");
      p = cut == std::string::npos ? "" : p.substr(0, cut);
    }
    throw ConfigError(file_ + ":" + (line ? std::to_string(line) + ":" : "") + " " + e.what());
  }
}

}  // namespace ddswarm
