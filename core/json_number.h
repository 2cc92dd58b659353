// Checked conversions of JSON numbers for the files pathlab reads back (its
// partial films, trace-pixel --json). nlohmann's get<int>() of 8.9e68 is
// undefined behaviour, and get<std::uint32_t>() of -1 or 2^40 wraps without a
// word; these answer "no" instead, and the caller names the file and the key.
// (The scene loader has its own, JsonValue, which also knows line and column.)
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <optional>

namespace pathlab {

// `v` as a T if it is a JSON integer (not 3.0, not "3") that T can hold.
template <std::integral T>
std::optional<T> json_integer(const nlohmann::json& v) {
  if (v.is_number_unsigned()) {
    const std::uint64_t u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<T>::max())) return std::nullopt;
    return static_cast<T>(u);
  }
  if (v.is_number_integer()) {  // a negative one: nlohmann keeps non-negative integers unsigned
    const std::int64_t s = v.get<std::int64_t>();
    if constexpr (std::is_unsigned_v<T>) {
      return std::nullopt;
    } else {
      if (s < static_cast<std::int64_t>(std::numeric_limits<T>::min())) return std::nullopt;
      return static_cast<T>(s);
    }
  }
  return std::nullopt;
}

// `v` as a float if it is a JSON number a float can hold (finite, |v| at most
// FLT_MAX; smaller ones round, as a float's own text would).
inline std::optional<float> json_float(const nlohmann::json& v) {
  if (!v.is_number()) return std::nullopt;
  const double d = v.get<double>();
  if (!std::isfinite(d) || std::abs(d) > static_cast<double>(std::numeric_limits<float>::max())) return std::nullopt;
  return static_cast<float>(d);
}

}  // namespace pathlab
