// Small glTF 2.0 files assembled by tests: one binary buffer, views and
// accessors appended to it, the JSON edited freely, written as .gltf with
// an embedded base64 buffer, as .glb, or as .gltf + external .bin.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace pathlab::test {

inline constexpr int kGltfByte = 5121, kGltfShort = 5123, kGltfUint = 5125, kGltfFloat = 5126;

class GltfWriter {
 public:
  GltfWriter() {
    doc["asset"] = {{"version", "2.0"}};
  }

  nlohmann::json doc;
  std::vector<unsigned char> bin;

  // Appends `bytes` (padded to 4) as a buffer view; its index.
  int view(const void* data, std::size_t bytes, int stride = 0) {
    const std::size_t offset = bin.size();
    bin.resize(offset + bytes);
    std::memcpy(bin.data() + offset, data, bytes);
    while (bin.size() % 4 != 0) bin.push_back(0);
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (stride != 0) v["byteStride"] = stride;
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size() - 1);
  }
  int accessor(int view_index, int component, std::size_t count, const char* type, std::size_t offset = 0,
               bool normalized = false) {
    nlohmann::json a = {{"bufferView", view_index}, {"componentType", component}, {"count", count}, {"type", type}};
    if (offset != 0) a["byteOffset"] = offset;
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size() - 1);
  }
  // A tightly packed accessor of `values` (n components per element).
  template <typename T>
  int add(const std::vector<T>& values, int component, const char* type, int n, bool normalized = false) {
    return accessor(view(values.data(), values.size() * sizeof(T)), component, values.size() / static_cast<std::size_t>(n),
                    type, 0, normalized);
  }
  // A mesh of one primitive per entry: {attribute name: accessor} (+ indices, material).
  int mesh(const std::vector<nlohmann::json>& primitives) {
    doc["meshes"].push_back({{"primitives", primitives}});
    return static_cast<int>(doc["meshes"].size() - 1);
  }
  int node(const nlohmann::json& n) {
    doc["nodes"].push_back(n);
    return static_cast<int>(doc["nodes"].size() - 1);
  }

  static std::string base64(const std::vector<unsigned char>& data) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < data.size(); i += 3) {
      const std::uint32_t b = std::uint32_t{data[i]} << 16 | (i + 1 < data.size() ? std::uint32_t{data[i + 1]} << 8 : 0u) |
                              (i + 2 < data.size() ? std::uint32_t{data[i + 2]} : 0u);
      out += t[b >> 18 & 63];
      out += t[b >> 12 & 63];
      out += i + 1 < data.size() ? t[b >> 6 & 63] : '=';
      out += i + 2 < data.size() ? t[b & 63] : '=';
    }
    return out;
  }

  // The JSON with the buffer as a data URI.
  std::string embedded() const {
    nlohmann::json d = doc;
    d["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
    return d.dump(1);
  }
  // The JSON naming an external `bin_name` (write `bin` there).
  std::string external(const std::string& bin_name) const {
    nlohmann::json d = doc;
    d["buffers"] = {{{"byteLength", bin.size()}, {"uri", bin_name}}};
    return d.dump(1);
  }
  // A .glb: header, JSON chunk, BIN chunk.
  std::string glb() const {
    nlohmann::json d = doc;
    d["buffers"] = {{{"byteLength", bin.size()}}};
    std::string json = d.dump();
    while (json.size() % 4 != 0) json += ' ';
    std::string out = "glTF";
    const auto u32 = [&](std::size_t v) {
      for (int k = 0; k < 4; ++k) out += static_cast<char>(v >> (8 * k) & 0xff);
    };
    u32(2);
    u32(12 + 8 + json.size() + 8 + bin.size());
    u32(json.size());
    out += "JSON" + json;
    u32(bin.size());
    out += std::string("BIN\0", 4);
    out.append(reinterpret_cast<const char*>(bin.data()), bin.size());
    return out;
  }

  static void write(const std::filesystem::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  void write_external(const std::filesystem::path& gltf, const std::string& bin_name) const {
    write(gltf, external(bin_name));
    write(gltf.parent_path() / bin_name, std::string(bin.begin(), bin.end()));
  }
};

// A unit quad in z = 0, counter-clockwise seen from +z, with normals +z:
// positions and normals as floats, indices 0 1 2, 0 2 3.
inline const std::vector<float> kQuadPositions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
inline const std::vector<float> kQuadNormals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};

}  // namespace pathlab::test
