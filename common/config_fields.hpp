#pragma once
// One declaration per config field. A config struct keeps each default in its
// initialiser and lists its fields once, with unit, bounds and a doc line:
//
//   template <class Self, class V>
//   static void fields(Self& c, V& v) {
//     v.field("inter_distance_m", c.inter_distance_m, {"m", positive(), "D_int"});
//     v.choice("source", c.source, kSources, {"", any(), "where peers come from"});
//     v.section("start", [&](auto& w) { w.field("spacing_m", c.start.spacing_m, {...}); });
//     v.list("cylinders", c.cylinders, "pillars");  // each element lists its own fields
//   }
//
// The visitors below turn that list into the loader (FieldLoader: YAML keys
// into members), the checks (FieldChecker: a FieldError naming the dotted
// field and the bound), and the reference (FieldLister: the rows of
// docs/configuration.md, which a test compares with the doc). Checks that
// relate two fields stay in the struct's validate(), after the list's.
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/config_error.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm {

/// The values a numeric field may take.
struct Bounds {
  enum class Kind { kAny, kPositive, kNonNegative, kRange, kZeroOrRange, kAtMost };
  Kind kind = Kind::kAny;
  double lo = 0, hi = 0;

  /// As the reference writes it: "> 0", ">= 0", "[0, 1]", "0 or [2, 3600]", "(0, 1000]".
  std::string text() const {
    switch (kind) {
      case Kind::kAny:
        return "";
      case Kind::kPositive:
        return "> 0";
      case Kind::kNonNegative:
        return ">= 0";
      case Kind::kRange:
        return "[" + to_text(lo) + ", " + to_text(hi) + "]";
      case Kind::kZeroOrRange:
        return "0 or [" + to_text(lo) + ", " + to_text(hi) + "]";
      case Kind::kAtMost:
        return "(0, " + to_text(hi) + "]";
    }
    return "";
  }

  /// Throws FieldError(field, v, "must be ...") when v is out of bounds.
  template <class T>
  void check(const std::string& field, T v) const {
    switch (kind) {
      case Kind::kAny:
        return;
      case Kind::kPositive:
        return check_positive(field, v);
      case Kind::kNonNegative:
        return check_non_negative(field, v);
      case Kind::kRange:
        return check_range(field, v, static_cast<T>(lo), static_cast<T>(hi));
      case Kind::kZeroOrRange:
        if (v != 0) check_range(field, v, static_cast<T>(lo), static_cast<T>(hi));
        return;
      case Kind::kAtMost:
        check_positive(field, v);
        if (v > static_cast<T>(hi))
          throw FieldError(field, to_text(v), "must be <= " + to_text(hi));
        return;
    }
  }
};

inline Bounds any() { return {}; }
inline Bounds positive() { return {Bounds::Kind::kPositive}; }
inline Bounds non_negative() { return {Bounds::Kind::kNonNegative}; }
inline Bounds in(double lo, double hi) { return {Bounds::Kind::kRange, lo, hi}; }
inline Bounds zero_or(double lo, double hi) { return {Bounds::Kind::kZeroOrRange, lo, hi}; }
/// (0, hi].
inline Bounds up_to(double hi) { return {Bounds::Kind::kAtMost, 0, hi}; }

/// What a field's declaration says besides its name and member.
struct FieldSpec {
  const char* unit = "";  ///< "m", "m/s", "s (wall)", ...; empty when unitless
  Bounds bounds;
  const char* doc = "";  ///< one line: what the field does
};

/// An enum field's names, in the order the reference lists them.
template <class E>
using Choices = std::vector<std::pair<std::string, E>>;

/// Reads the listed fields from a YAML section (a key absent keeps the default).
class FieldLoader {
 public:
  explicit FieldLoader(YamlSection& s) : s_(s) {}
  template <class T>
  void field(const char* key, T& v, const FieldSpec&) {
    s_.get(key, v);
  }
  template <class E>
  void choice(const char* key, E& v, const Choices<E>& names, const FieldSpec&) {
    s_.get_enum(key, v, std::map<std::string, E>(names.begin(), names.end()));
  }
  /// A nested mapping whose fields list(w) declares.
  template <class List>
  void section(const char* key, List&& list) {
    YamlSection child = s_.child(key);
    FieldLoader w(child);
    list(w);
    child.finish();
  }
  /// A sequence of mappings, each an element whose fields E::fields declares.
  template <class E>
  void list(const char* key, std::vector<E>& v, const char*) {
    for (auto child : s_.children(key)) {
      E e;
      FieldLoader w(child);
      E::fields(e, w);
      child.finish();
      v.push_back(std::move(e));
    }
  }

 private:
  YamlSection& s_;
};

/// Checks every listed field against its bounds; prefix: "agent", "comm", ...
class FieldChecker {
 public:
  explicit FieldChecker(std::string prefix) : prefix_(std::move(prefix)) {}
  template <class T>
  void field(const char* key, const T& v, const FieldSpec& spec) {
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
      spec.bounds.check(prefix_ + "." + key, v);
  }
  template <class E>
  void choice(const char*, const E&, const Choices<E>&, const FieldSpec&) {}
  template <class List>
  void section(const char* key, List&& list) {
    FieldChecker w(prefix_ + "." + key);
    list(w);
  }
  template <class E>
  void list(const char* key, const std::vector<E>& v, const char*) {
    for (std::size_t k = 0; k < v.size(); ++k) {
      FieldChecker w(prefix_ + "." + key + "[" + std::to_string(k) + "]");
      E::fields(v[k], w);
    }
  }

 private:
  std::string prefix_;
};

/// One row of the configuration reference.
struct FieldRow {
  std::string key;
  std::string type;          ///< "real", "integer", "bool", "text", "list", or "a | b | c"
  std::string default_text;  ///< as YAML would write it
  std::string unit;
  std::string bounds;  ///< Bounds::text()
  std::string doc;
};

/// Lists the fields of a default-constructed struct: the reference's rows.
class FieldLister {
 public:
  template <class T>
  void field(const char* key, const T& v, const FieldSpec& spec) {
    std::string type = "text", def;
    if constexpr (std::is_same_v<T, bool>) {
      type = "bool";
      def = v ? "true" : "false";
    } else if constexpr (std::is_integral_v<T>) {
      type = "integer";
      def = std::to_string(v);
    } else if constexpr (std::is_floating_point_v<T>) {
      type = "real";
      def = exact(v);
    } else if constexpr (std::is_same_v<T, std::string>) {
      def = v;
    } else if constexpr (requires {
                           v.rows();
                           v.cols();
                         }) {  // an Eigen vector
      type = v.size() == 2 ? "[x, y]" : "[x, y, z]";
      for (int k = 0; k < v.size(); ++k) def += (k ? ", " : "[") + exact(v[k]);
      def += "]";
    } else {  // a list
      type = "list";
      def = v.empty() ? "[]" : "[...]";
    }
    rows.push_back({prefix + key, type, def, spec.unit, spec.bounds.text(), spec.doc});
  }
  template <class E>
  void choice(const char* key, const E& v, const Choices<E>& names, const FieldSpec& spec) {
    std::string type, def;
    for (const auto& [name, value] : names) {
      type += (type.empty() ? "" : " | ") + name;
      if (value == v) def = name;
    }
    rows.push_back({prefix + key, type, def, spec.unit, "", spec.doc});
  }
  /// A section's fields are rows "key.field".
  template <class List>
  void section(const char* key, List&& list) {
    FieldLister w;
    w.prefix = prefix + key + ".";
    list(w);
    rows.insert(rows.end(), w.rows.begin(), w.rows.end());
  }
  /// A list is one row; its elements' fields are the reference's prose.
  template <class E>
  void list(const char* key, const std::vector<E>&, const char* doc) {
    rows.push_back({prefix + key, "list", "[]", "", "", doc});
  }

  std::string prefix;  ///< "" or "section."
  std::vector<FieldRow> rows;

 private:
  /// A default as written in the code (to_text keeps 6 digits: 6396.667 would read 6396.67).
  static std::string exact(double v) {
    std::ostringstream os;
    os.precision(10);
    os << v;
    return os.str();
  }
};

/// The reference rows of config struct C (C::fields on a default C).
template <class C>
std::vector<FieldRow> field_rows() {
  C c;
  FieldLister l;
  C::fields(c, l);
  return l.rows;
}

}  // namespace ddswarm
