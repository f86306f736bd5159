#pragma once
// Command-line number checks that refuse NaN. CLI11's Range and
// PositiveNumber compare with < and >, which are false for NaN, so
// `--north nan` passed them; these name the option's bounds and exit 2 like
// any other bad usage.
#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

namespace ddswarm {

/// A finite number in [lo, hi].
inline CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v)) return "Value " + text + " is not a number";
        if (!std::isfinite(v) || v < lo || v > hi)
          return "Value " + text + " not a finite number in [" + CLI::detail::to_string(lo) + ", " +
                 CLI::detail::to_string(hi) + "]";
        return {};
      },
      "FINITE in [" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]");
}

/// A finite number > 0.
inline CLI::Validator finite_positive() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v)) return "Value " + text + " is not a number";
        if (!std::isfinite(v) || !(v > 0)) return "Value " + text + " is not a finite number > 0";
        return {};
      },
      "FINITE > 0");
}

}  // namespace ddswarm
