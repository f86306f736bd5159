#pragma once
// Errors raised while loading or validating configuration.
//
// A FieldError names the dotted field path, the offending value and the
// reason, e.g. `agent.inter_distance_m = -4: must be > 0`. The loader adds
// the file and line, so users see one line they can act on.
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ddswarm {

/// A configuration field holds a bad value. what() is "field = value: reason".
class FieldError : public std::runtime_error {
 public:
  FieldError(std::string field, const std::string& value, const std::string& reason)
      : std::runtime_error(field + " = " + value + ": " + reason), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

/// `text` with control characters escaped (\n, \t, \xNN), so a message
/// that quotes a key or value from a file stays on one line.
inline std::string one_line(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (unsigned char c : text) {
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

/// A configuration file could not be used. what() is "file:line: message",
/// always one line (control characters quoted from the file are escaped).
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(const std::string& what) : std::runtime_error(one_line(what)) {}
};

template <class T>
std::string to_text(const T& v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

/// Throws FieldError unless lo <= v <= hi.
template <class T>
void check_range(const std::string& field, T v, T lo, T hi) {
  if (!(v >= lo && v <= hi))
    throw FieldError(field, to_text(v), "must be in [" + to_text(lo) + ", " + to_text(hi) + "]");
}

/// Throws FieldError unless v > 0 (and finite).
template <class T>
void check_positive(const std::string& field, T v) {
  if (!(v > 0) || v != v || v > std::numeric_limits<T>::max())
    throw FieldError(field, to_text(v), "must be > 0");
}

/// Throws FieldError unless v >= 0 (and finite).
template <class T>
void check_non_negative(const std::string& field, T v) {
  if (!(v >= 0) || v > std::numeric_limits<T>::max())
    throw FieldError(field, to_text(v), "must be >= 0");
}

/// Validates a configuration that command-line options changed after its file
/// was loaded: a FieldError then names the file too ("file: field = value:
/// reason"), with no line, since the value may be the command line's.
template <class Validate>
void validate_with_overrides(const std::string& file, Validate&& validate) {
  try {
    validate();
  } catch (const FieldError& e) {
    throw ConfigError(file + ": " + e.what() + " (this file with the command line's options)");
  }
}

}  // namespace ddswarm
