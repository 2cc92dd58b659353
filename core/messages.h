// Quoting user input and numbers in messages: one way everywhere, so that
// no message echoes a 5 MB key or prints a double with 309 digits.
#pragma once

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <string>
#include <string_view>
#include <system_error>

namespace pathlab {

// User text (a key, a name, an option value, a token) quoted for a one-line
// message: control characters become '?', and text longer than 60 bytes is
// cut: 'first 60 bytes...' (N bytes). Every message that echoes input goes
// through this, so that a 5 MB key is not printed whole.
inline std::string quote_input(std::string_view text) {
  constexpr std::size_t kShown = 60;
  std::string out(text.substr(0, kShown));
  std::replace_if(out.begin(), out.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; }, '?');
  if (text.size() <= kShown) return "'" + out + "'";
  return "'" + out + "...' (" + std::to_string(text.size()) + " bytes)";
}

// The same cut without the quotes, for text that is printed bare (a JSON
// pointer made of keys): "first 60 bytes... (N bytes)".
inline std::string shorten_input(std::string_view text) {
  const std::string quoted = quote_input(text);
  const std::size_t close = quoted.rfind('\'');
  return quoted.substr(1, close - 1) + quoted.substr(close + 1);
}

// A number for a message, %g-style: "1e+308", not std::to_string's 309 digits.
inline std::string format_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.7g", v);
  return text;
}

// A number for a message with as many digits as tell it apart: 179.999999,
// which format_number rounds to 180 (beside a limit of 180, misleading).
inline std::string exact_number(double v) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  return ec == std::errc() ? std::string(text, end) : format_number(v);
}

}  // namespace pathlab
