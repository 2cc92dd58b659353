// The scene loader's internals, shared by scene_loader.cpp and
// scene_loader_shapes.cpp (not for other code): the cursor on the JSON that
// reports bad input with its place, and the readers the two files share.
#pragma once

#include "core/json_document.h"
#include "core/messages.h"
#include "core/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pathlab::scene_detail {

using json = nlohmann::json;
using Pointer = json::json_pointer;

// Why positions have a limit, for messages (core/geometry.h).
inline const std::string kRangeRule = "1e16 (docs/scene-format.md: every ray must stay within Embree's 1.8e18)";

// A name from the file, quoted for a one-line message: control characters
// become '?' and very long names are cut.
inline std::string in_quotes(std::string_view name) { return quote_input(name); }

// " (did you mean 'x'?)" if one of `candidates` is close to `name`, else "".
inline std::string suggestion(std::string_view name, std::span<const std::string_view> candidates) {
  const std::string near = nearest_name(name, candidates);
  return near.empty() ? std::string() : " (did you mean " + in_quotes(near) + "?)";
}

// What a value is, for "expected X, found Y": the value itself when short.
inline std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::object: return "an object";
    case json::value_t::array: return "an array of " + std::to_string(v.size());
    case json::value_t::string: {
      const std::string& s = v.get_ref<const std::string&>();
      if (s.size() <= 60) return "the string " + v.dump();
      return "the string \"" + shorten_input(s).insert(60, "\"");
    }
    case json::value_t::null: return "null";
    case json::value_t::boolean: return v.get<bool>() ? "true" : "false";
    case json::value_t::discarded: return "nothing";
    default: return "the number " + (v.is_number_float() ? format_number(v.get<double>()) : v.dump());
  }
}

// The value at `ptr`, or null if there is none (a const json's operator[]
// on a missing key is undefined behaviour).
inline const json& resolve(const JsonDocument& doc, const Pointer& ptr) {
  static const json missing;
  return doc.root().contains(ptr) ? doc.root()[ptr] : missing;
}

// A cursor on one JSON object of the scene: typed accessors that report
// their own location, and a check that no key is misspelt.
class Node {
 public:
  Node(const JsonDocument& doc, Pointer ptr) : doc_(doc), ptr_(std::move(ptr)), value_(resolve(doc, ptr_)) {}

  const json& value() const { return value_; }
  const Pointer& pointer() const { return ptr_; }
  bool has(const std::string& key) const { return value_.is_object() && value_.contains(key); }
  Node child(const std::string& key) const { return Node(doc_, ptr_ / key); }
  Node child(std::size_t index) const { return Node(doc_, ptr_ / index); }

  // "<file>:<line>:<col>: <pointer>: <problem>". A value that is not in the
  // file (a default) is placed at its nearest enclosing value that is.
  std::string message(const std::string& problem) const {
    Pointer located = ptr_;
    while (!located.empty() && doc_.position(located).line == 0) located = located.parent_pointer();
    const std::string path = ptr_.empty() ? std::string("(top level)") : shorten_input(ptr_.to_string());
    return doc_.where(located) + ": " + path + ": " + problem;
  }
  [[noreturn]] void fail(const std::string& problem) const { throw InputError(message(problem)); }

  void expect_object() const {
    if (!value_.is_object()) fail("expected an object, found " + describe(value_));
  }

  void allow_only(std::initializer_list<std::string_view> keys) const {
    expect_object();
    const std::vector<std::string_view> allowed(keys);
    for (const auto& [key, unused] : value_.items()) {
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      child(key).fail("unknown key " + in_quotes(key) + suggestion(key, allowed));
    }
  }

  // Every number ends up a float: reject what a float cannot hold.
  double number() const {
    if (!value_.is_number()) fail("expected a number, found " + describe(value_));
    const double v = value_.get<double>();
    if (!std::isfinite(v)) fail("number is not finite");
    if (std::abs(v) > std::numeric_limits<float>::max())
      fail("number " + format_number(v) + " is too large (the limit is 3.4e38)");
    return v;
  }
  std::int64_t integer() const {
    if (!value_.is_number_integer()) fail("expected an integer, found " + describe(value_));
    if (value_.is_number_unsigned() && value_.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX))
      fail("integer " + quote_input(value_.dump()) + " is too large");
    return value_.get<std::int64_t>();
  }
  std::string string() const {
    if (!value_.is_string()) fail("expected a string, found " + describe(value_));
    return value_.get<std::string>();
  }
  bool boolean() const {
    if (!value_.is_boolean()) fail("expected true or false, found " + describe(value_));
    return value_.get<bool>();
  }
  vec3 vector3() const {
    if (!value_.is_array() || value_.size() != 3) fail("expected an array of 3 numbers, found " + describe(value_));
    return vec3(static_cast<float>(child(0).number()), static_cast<float>(child(1).number()),
                static_cast<float>(child(2).number()));
  }
  // A colour: [r,g,b] or one number for grey; each component >= 0 (and <= 1
  // if `max_one`).
  Spectrum color(bool max_one) const {
    if (!value_.is_number() && !(value_.is_array() && value_.size() == 3))
      fail("expected a colour: one number or an array of 3 numbers, found " + describe(value_));
    const Spectrum c = value_.is_number() ? Spectrum(static_cast<float>(number())) : vector3();
    for (int i = 0; i < 3; ++i) {
      if (c[i] < 0.0f) fail("components must not be negative");
      if (max_one && c[i] > 1.0f) fail("components must lie in [0, 1] (a reflectance above 1 creates energy)");
    }
    return c;
  }

  double number_or(const std::string& key, double fallback) const { return has(key) ? child(key).number() : fallback; }
  bool boolean_or(const std::string& key, bool fallback) const { return has(key) ? child(key).boolean() : fallback; }
  // The member `key`, which must be there. If it is missing but a key close
  // to it is present, the message says which (a misspelt required key would
  // otherwise only be reported as missing).
  Node required(const std::string& key) const {
    expect_object();
    if (!has(key)) {
      std::string hint;
      const std::array<std::string_view, 1> wanted{key};
      for (const auto& [present, unused] : value_.items())
        if (!nearest_name(present, wanted).empty()) hint = " (is " + in_quotes(present) + " a misspelling of it?)";
      fail("missing required key " + in_quotes(key) + hint);
    }
    return child(key);
  }

 private:
  const JsonDocument& doc_;
  Pointer ptr_;
  const json& value_;
};

// Fails at `at` if `path` exists and is a device, a FIFO or a folder, which
// would be read for ever or block ("<what> <path> must be a regular file").
void require_regular(const Node& at, const std::filesystem::path& path, const std::string& what);

// One transform step, or a list applied in order (the first listed is
// applied to the shape first).
mat4 read_transform(const Node& node);

// The scene material `node` names, with "did you mean" when there is none.
std::uint32_t material_index(const Node& node, const std::map<std::string, std::uint32_t>& materials);

// A mesh, sphere, rectangle or box entry, appended to scene.shapes: one
// shape, or for an OBJ file with `usemtl` one per material its faces use.
// `label` names the entry in messages: "shapes[3]", "groups/tree[0]".
void read_shape(const Node& node, Scene& scene, const std::filesystem::path& folder,
                const std::map<std::string, std::uint32_t>& materials, const std::string& label);

// Textured parameters (scene_loader_textures.cpp). A value is a texture
// when it is an object with a "texture" key.
enum class TextureUse : std::uint8_t { Color, Number, NormalMap };
bool is_texture(const Node& node);
// The texture entry at `node`, its image added to scene.textures (once per
// file and colour space; files are relative to the scene's folder). The
// header is read here, so a missing or unreadable file, or a channel out of
// range, is reported at the key; the texels are scanned when the scene is
// compiled (core/texture.h). For a NormalMap, `scale` is glTF's normal scale
// (any sign) and comes back in TextureRef::scale.x.
TextureRef read_texture(const Node& node, Scene& scene, TextureUse use, TextureColorSpace default_space);

}  // namespace pathlab::scene_detail
