// CLI11 validators shared by every subcommand: numbers are checked and
// printed the same way everywhere (finite, in range, %g-style).
#pragma once

#include "core/messages.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

namespace pathlab::cli {

// A floating-point option within [lo, hi]; the message prints the bounds
// %g-style (CLI::Range prints 3.4e38 as 39 digits and 1e-12 as 0.000000).
inline CLI::Validator number_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return {};  // the option's own conversion reports it
        if (!std::isfinite(v)) return "expected a finite number, found " + quote_input(text);
        if (!(v >= lo && v <= hi))
          return "the value " + quote_input(text) + " is not in [" + format_number(lo) + ", " + format_number(hi) + "]";
        return {};
      },
      "[" + format_number(lo) + ", " + format_number(hi) + "]", "number_range");
}

// A number > 0 (CLI::PositiveNumber prints the double range's 309 digits).
inline CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return {};
        if (!std::isfinite(v)) return "expected a finite number, found " + quote_input(text);
        if (!(v > 0.0)) return "the value " + quote_input(text) + " must be positive";
        return {};
      },
      "POSITIVE", "positive_number");
}

// Every floating-point option must be a finite number that a float holds:
// CLI11 parses "nan" and "inf", and every comparison with NaN is false, so a
// range check alone lets NaN through. cli.cpp adds this to every option
// CLI11 types as FLOAT (float, double, their optionals and lists) of every
// subcommand, so that none can forget it.
inline const CLI::Validator& finite_number() {
  static const CLI::Validator finite(
      [](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return {};
        if (!std::isfinite(v)) return "expected a finite number, found " + quote_input(text);
        if (std::abs(v) > 3.4e38) return "the number " + quote_input(text) + " is too large (the limit is 3.4e38)";
        return {};
      },
      "", "finite");
  return finite;
}

}  // namespace pathlab::cli
