#include "core/json_document.h"

#include "core/error.h"
#include "core/limits.h"
#include "core/messages.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

namespace pathlab {
namespace {

// Deeper nesting than this is rejected so that the recursive scanner below
// cannot overflow the stack on a hostile file. No scene needs even 20.
constexpr int kMaxDepth = 1000;

std::string located(const std::string& file, SourcePosition p, const std::string& problem) {
  return file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column) + ": " + problem;
}

// 1-based line and byte column of `offset` (0-based) in `text`; `offset` may
// be text.size(), which is the place just after the last byte.
SourcePosition position_at(std::string_view text, std::size_t offset) {
  offset = std::min(offset, text.size());
  const std::string_view before = text.substr(0, offset);
  const auto newline = before.rfind('\n');
  const std::size_t line_start = newline == std::string_view::npos ? 0 : newline + 1;
  return {static_cast<int>(std::count(before.begin(), before.end(), '\n')) + 1,
          static_cast<int>(offset - line_start) + 1};
}

// nlohmann 3.11.2 says e.g. "[json.exception.parse_error.101] parse error at
// line 1, column 10: syntax error while parsing object - unexpected string
// literal; expected '}'". Keep only "unexpected string literal; expected '}'":
// the position is ours to print, and "last read: '...'" echoes raw input.
std::string parse_error_reason(const std::string& what) {
  std::string reason = what;
  if (const auto p = reason.find("parse error"); p != std::string::npos) {
    if (const auto colon = reason.find(": ", p); colon != std::string::npos) reason.erase(0, colon + 2);
  }
  if (reason.starts_with("syntax error")) {
    if (const auto dash = reason.find("- "); dash != std::string::npos) reason.erase(0, dash + 2);
  }
  if (const auto last = reason.find("; last read: '"); last != std::string::npos) {
    const auto expected = reason.rfind("'; expected ");
    reason.erase(last, expected != std::string::npos && expected > last ? expected + 1 - last
                                                                       : std::string::npos);
  }
  return reason;
}

// Keys are quoted in messages; keep control characters out of the one line.
std::string printable(std::string_view key) { return shorten_input(key); }

// If the token at or just before `offset` (where nlohmann gave up) is NaN or
// an infinity as other languages write them (NaN, nan, Infinity, -inf, ...,
// in any case), the offset where that token starts.
std::optional<std::size_t> non_finite_literal(std::string_view text, std::size_t offset) {
  const auto is_letter = [](char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; };
  const auto is_sign = [](char c) { return c == '-' || c == '+'; };
  std::size_t start = std::min(offset, text.size());
  while (start > 0 && is_letter(text[start - 1])) --start;
  if (start > 0 && is_sign(text[start - 1])) --start;
  std::size_t end = start < text.size() && is_sign(text[start]) ? start + 1 : start;
  std::string word;
  for (; end < text.size() && is_letter(text[end]); ++end)
    word += static_cast<char>(std::tolower(static_cast<unsigned char>(text[end])));
  if (word == "nan" || word == "inf" || word == "infinity") return start;
  return std::nullopt;
}

// nlohmann 3.11 reports a number beyond the double range (1e999, the only
// way to write an infinity in JSON) as out_of_range 406, without a position:
// "[json.exception.out_of_range.406] number overflow parsing '1e999'". Give
// it the "<file>:<line>:<column>: malformed JSON: ..." form of any syntax error.
std::string number_out_of_range(std::string_view text, const std::string& file, const std::string& what) {
  const auto open = what.find("parsing '");
  const auto close = open == std::string::npos ? std::string::npos : what.find('\'', open + 9);
  if (close == std::string::npos) {  // not the message we know: keep it, without the "[json.exception...]"
    return file + ": malformed JSON: " + what.substr(what.starts_with("[") ? what.find("] ") + 2 : 0);
  }
  const std::string literal = what.substr(open + 9, close - open - 9);
  const std::string problem = "malformed JSON: number '" + printable(literal.substr(0, 40)) +
                              (literal.size() > 40 ? "..." : "") + "' is out of range (numbers must be finite)";
  // nlohmann stopped at this number, so the text before it is valid JSON:
  // the first number token outside strings that equals the literal is it.
  constexpr std::string_view kNumberChars = "+-.0123456789eE";
  for (std::size_t i = 0; i < text.size();) {
    if (text[i] == '"') {
      for (++i; i < text.size() && text[i] != '"'; ++i) i += text[i] == '\\' ? 1 : 0;
      ++i;
    } else if (text[i] == '-' || (text[i] >= '0' && text[i] <= '9')) {
      const std::size_t start = i;
      while (i < text.size() && kNumberChars.find(text[i]) != std::string_view::npos) ++i;
      if (text.substr(start, i - start) == literal) return located(file, position_at(text, start), problem);
    } else {
      ++i;
    }
  }
  return file + ": " + problem;
}

// JSON pointer reference token: "~" -> "~0", "/" -> "~1" (RFC 6901).
std::string pointer_token(std::string_view key) {
  std::string out;
  for (const char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

void append_utf8(std::string& out, unsigned cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
    return;
  }
  const int extra = cp < 0x800 ? 1 : cp < 0x10000 ? 2 : 3;  // continuation bytes
  out += static_cast<char>((0xFFu << (7 - extra)) | (cp >> (6 * extra)));
  for (int i = extra - 1; i >= 0; --i) out += static_cast<char>(0x80 | ((cp >> (6 * i)) & 0x3F));
}

// Walks text that nlohmann has already accepted and records where each value
// starts. Because the text is valid, it checks structure only where it must
// (duplicate keys, depth, bytes after a NUL that nlohmann takes as the end).
class PositionScanner {
 public:
  PositionScanner(std::string_view text, const std::string& file,
                  std::map<std::string, SourcePosition>& out)
      : text_(text), file_(file), out_(out) {}

  void run() {
    if (text_.starts_with("\xEF\xBB\xBF")) pos_ = 3;  // nlohmann skips a UTF-8 BOM too
    skip_whitespace();
    out_[""] = here();
    value("", 0);
    skip_whitespace();
    if (pos_ < text_.size()) {
      throw InputError(located(file_, here(), "malformed JSON: unexpected NUL byte"));
    }
  }

 private:
  SourcePosition here() const { return {line_, static_cast<int>(pos_ - line_start_) + 1}; }

  // Raw newlines can only occur between tokens, so lines are counted here.
  void skip_whitespace() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
        line_start_ = pos_ + 1;
      } else if (c != ' ' && c != '\t' && c != '\r') {
        return;
      }
      ++pos_;
    }
  }

  // After an element: whitespace, then an optional ',' and more whitespace.
  void skip_separator() {
    skip_whitespace();
    if (pos_ < text_.size() && text_[pos_] == ',') {
      ++pos_;
      skip_whitespace();
    }
  }

  void value(const std::string& pointer, int depth) {
    if (depth > kMaxDepth) {
      throw InputError(located(file_, here(), "JSON nested deeper than " +
                                                  std::to_string(kMaxDepth) + " levels"));
    }
    const char c = text_[pos_];
    if (c == '{') {
      object(pointer, depth);
    } else if (c == '[') {
      array(pointer, depth);
    } else if (c == '"') {
      string();
    } else {  // number, true, false or null: runs up to a delimiter
      constexpr std::string_view kDelimiters(",]} \t\r\n\0", 8);
      while (pos_ < text_.size() && kDelimiters.find(text_[pos_]) == std::string_view::npos) ++pos_;
    }
  }

  void object(const std::string& pointer, int depth) {
    ++pos_;  // '{'
    skip_whitespace();
    while (text_[pos_] != '}') {
      const SourcePosition key_pos = here();
      const std::string key = string();
      const std::string child = pointer + "/" + pointer_token(key);
      // A second member with the same key maps to the same pointer.
      if (const auto first = out_.find(child); first != out_.end()) {
        throw InputError(located(file_, key_pos,
                                 "duplicate key '" + printable(key) + "' (first at line " +
                                     std::to_string(first->second.line) + ")"));
      }
      out_[child] = key_pos;
      skip_whitespace();
      ++pos_;  // ':'
      skip_whitespace();
      value(child, depth + 1);
      skip_separator();
    }
    ++pos_;  // '}'
  }

  void array(const std::string& pointer, int depth) {
    ++pos_;  // '['
    skip_whitespace();
    for (std::size_t index = 0; text_[pos_] != ']'; ++index) {
      const std::string child = pointer + "/" + std::to_string(index);
      out_[child] = here();
      value(child, depth + 1);
      skip_separator();
    }
    ++pos_;  // ']'
  }

  // At the opening quote; returns the decoded string (needed for pointers
  // and so that "a" and "\u0061" count as the same key).
  std::string string() {
    std::string out;
    ++pos_;  // opening '"'
    while (text_[pos_] != '"') {
      if (text_[pos_] != '\\') {
        out += text_[pos_++];
        continue;
      }
      const char escape = text_[pos_ + 1];
      pos_ += 2;
      switch (escape) {
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          unsigned cp = hex4();
          if (cp >= 0xD800 && cp < 0xDC00) {  // high surrogate; nlohmann checked the pair
            pos_ += 2;                        // "\u"
            cp = 0x10000 + ((cp - 0xD800) << 10) + (hex4() - 0xDC00);
          }
          append_utf8(out, cp);
          break;
        }
        default: out += escape; break;  // '"', '\\', '/'
      }
    }
    ++pos_;  // closing '"'
    return out;
  }

  unsigned hex4() {
    const std::string digits(text_.substr(pos_, 4));
    pos_ += 4;
    return static_cast<unsigned>(std::stoul(digits, nullptr, 16));
  }

  std::string_view text_;
  const std::string& file_;
  std::map<std::string, SourcePosition>& out_;
  std::size_t pos_ = 0;
  std::size_t line_start_ = 0;
  int line_ = 1;
};

}  // namespace

JsonDocument JsonDocument::parse(std::string_view text, const std::filesystem::path& file) {
  JsonDocument doc;
  doc.file_ = file;
  const std::string name = file.string();
  try {
    doc.root_ = nlohmann::json::parse(text, /*cb=*/nullptr, /*allow_exceptions=*/true,
                                      /*ignore_comments=*/false);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the 1-based index of the last byte read (text.size() + 1 at
    // the end of input); 0 would mean "no position", so use the start.
    std::size_t offset = e.byte == 0 ? 0 : e.byte - 1;
    std::string problem = "malformed JSON: " + parse_error_reason(e.what());
    // Writers that emit NaN or Infinity (JavaScript, Python) make this common.
    if (const auto start = non_finite_literal(text, offset);
        start && (problem.find("invalid literal") != std::string::npos ||
                  problem.find("invalid number") != std::string::npos)) {
      offset = *start;
      problem += " (JSON has no NaN or infinity)";
    }
    throw InputError(located(name, position_at(text, offset), problem));
  } catch (const nlohmann::json::out_of_range& e) {
    throw InputError(number_out_of_range(text, name, e.what()));
  }
  PositionScanner(text, name, doc.positions_).run();
  return doc;
}

JsonDocument JsonDocument::load(const std::filesystem::path& file) {
  const auto fail = [&file](int error) {
    throw InputError(file.string() + ": cannot read scene: " +
                     (error != 0 ? std::strerror(error) : "unknown error"));
  };
  // A device or a FIFO would be read for ever or block; a folder says so.
  if (const std::string kind = special_file_kind(file); !kind.empty())
    throw InputError(file.string() + ": cannot read scene: it is " + kind + ", not a regular file");
  std::error_code size_error;
  if (const std::uintmax_t bytes = std::filesystem::file_size(file, size_error); !size_error)
    check_memory(bytes, file.string() + ": the scene file");
  errno = 0;
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(file.c_str(), "rb"),
                                                           &std::fclose);
  if (!in) fail(errno);
  std::string text;
  char buffer[1 << 14];
  while (const std::size_t got = std::fread(buffer, 1, sizeof buffer, in.get())) text.append(buffer, got);
  if (std::ferror(in.get())) fail(errno);  // e.g. EISDIR for a directory
  return parse(text, file);
}

SourcePosition JsonDocument::position(const nlohmann::json::json_pointer& pointer) const {
  const auto it = positions_.find(pointer.to_string());
  return it == positions_.end() ? SourcePosition{} : it->second;
}

std::string JsonDocument::where(const nlohmann::json::json_pointer& pointer) const {
  const SourcePosition p = position(pointer);
  if (p.line == 0) return file_.string();
  return file_.string() + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

std::string nearest_name(std::string_view key, std::span<const std::string_view> candidates) {
  // Optimal string alignment distance: Levenshtein plus the swap of two
  // adjacent characters as one edit ("tpye" -> "type"), with no substring
  // edited twice. Three rolling rows: the swap looks two rows back.
  const auto distance = [key](std::string_view other) {
    std::vector<std::size_t> before(other.size() + 1), prev(other.size() + 1), cur(other.size() + 1);
    for (std::size_t j = 0; j <= other.size(); ++j) prev[j] = j;
    for (std::size_t i = 1; i <= key.size(); ++i) {
      cur[0] = i;
      for (std::size_t j = 1; j <= other.size(); ++j) {
        const std::size_t substitute = prev[j - 1] + (key[i - 1] == other[j - 1] ? 0 : 1);
        cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, substitute});
        if (i > 1 && j > 1 && key[i - 1] == other[j - 2] && key[i - 2] == other[j - 1])
          cur[j] = std::min(cur[j], before[j - 2] + 1);
      }
      std::swap(before, prev);
      std::swap(prev, cur);
    }
    return prev[other.size()];
  };
  const std::size_t limit = std::max<std::size_t>(1, key.size() / 3);
  std::string_view best;
  std::size_t best_distance = limit + 1;
  for (const std::string_view candidate : candidates) {
    const std::size_t d = distance(candidate);
    if (d < best_distance) {  // strict: ties keep the first candidate
      best = candidate;
      best_distance = d;
    }
  }
  return std::string(best);
}

}  // namespace pathlab
