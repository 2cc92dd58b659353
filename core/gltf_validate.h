// The checks a glTF file passes before tinygltf reads it (core/gltf_loader.cpp
// uses them): the .glb container, and everything in the JSON that decides
// what is read or allocated (buffer URIs and sizes, views, accessors) or
// could make the loader loop (a cycle of nodes). Internal to the loader.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab::gltf {

// A glTF file split into its JSON text and (for .glb) its BIN chunk.
struct Container {
  std::vector<unsigned char> bytes;  // the whole file
  bool binary = false;               // .glb
  std::string_view json_text;        // into `bytes`
  std::size_t bin_size = 0;          // length of the BIN chunk, 0 if none
};

// Reads `file`; a .glb (recognised by its magic) must be complete and
// well-formed. Throws InputError "<file>: <problem>".
Container read_container(const std::filesystem::path& file);

// Checks the parsed JSON of `file`. Returns the external buffer files (paths
// as tinygltf will ask for them, lexically normal) that may be read: each lies
// in the folder of `file`, exists, and has exactly its byteLength. Throws
// InputError "<file>: <JSON pointer>: <problem>".
std::set<std::filesystem::path> validate(const nlohmann::json& doc, const std::filesystem::path& file,
                                         const Container& container);

// Extensions pathlab reads; any other listed in extensionsRequired is refused.
inline constexpr std::string_view kSupportedExtensions[] = {"KHR_lights_punctual",
                                                            "KHR_materials_emissive_strength"};

// "<file>: <pointer>: <problem>", thrown as InputError.
[[noreturn]] void fail(const std::filesystem::path& file, const std::string& pointer, const std::string& problem);

}  // namespace pathlab::gltf
