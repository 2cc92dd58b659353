// A parsed JSON document that remembers where each value came from, so that
// every scene error can say "file:line:column" and not just "somewhere".
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>

namespace pathlab {

struct SourcePosition {
  int line = 0;    // 1-based; 0 = unknown
  int column = 0;  // 1-based, in bytes
};

class JsonDocument {
 public:
  // Parses `text` read from `file`. Throws InputError
  // "<file>:<line>:<column>: <problem>" for malformed JSON and for duplicate
  // keys in one object (which nlohmann::json would silently merge).
  static JsonDocument parse(std::string_view text, const std::filesystem::path& file);
  // Reads and parses a file. Throws InputError if it cannot be read.
  static JsonDocument load(const std::filesystem::path& file);

  const nlohmann::json& root() const { return root_; }
  const std::filesystem::path& file() const { return file_; }

  // Position of the value at `pointer` (for an object member: of its key).
  SourcePosition position(const nlohmann::json::json_pointer& pointer) const;
  // "<file>:<line>:<column>" for `pointer`, or "<file>" if it is unknown.
  std::string where(const nlohmann::json::json_pointer& pointer) const;

 private:
  nlohmann::json root_;
  std::filesystem::path file_;
  std::map<std::string, SourcePosition> positions_;  // keyed by JSON pointer string
};

// The candidate closest to `key` by edit distance, if it is close enough to
// be a plausible typo (distance <= max(1, key.size() / 3)); empty otherwise.
std::string nearest_name(std::string_view key, std::span<const std::string_view> candidates);

}  // namespace pathlab
