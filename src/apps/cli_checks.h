#pragma once
// Range checks of the command-line tools. CLI11's own NonNegativeNumber and PositiveNumber
// print their range up to DBL_MAX written out (300 digits) and let "nan" through.

#include <cmath>
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>

namespace panmap {
namespace cli {

/// A finite number at or above `min` (strictly above when `strict`).
inline CLI::Validator atLeast(double min, bool strict, const std::string& what) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        const bool ok = end != text.c_str() && *end == '\0' && std::isfinite(v) &&
                        (strict ? v > min : v >= min);
        return ok ? "" : what + ", not " + text;
      },
      what);
}

/// A finite number >= 0.
inline CLI::Validator nonNegative() { return atLeast(0.0, false, "a number >= 0"); }
/// A finite number > 0.
inline CLI::Validator positive() { return atLeast(0.0, true, "a number > 0"); }

}  // namespace cli
}  // namespace panmap
