#include "core/gltf_validate.h"

#include "core/error.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <system_error>
#include <vector>

namespace pathlab::gltf {

using json = nlohmann::json;

void fail(const std::filesystem::path& file, const std::string& pointer, const std::string& problem) {
  throw InputError(file.string() + ": " + (pointer.empty() ? std::string("(top level)") : pointer) + ": " + problem);
}

namespace {

std::uint32_t read_u32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}

// A short quoted string for messages (URIs may be long data URIs).
std::string quoted(const std::string& s) { return "'" + (s.size() > 60 ? s.substr(0, 60) + "..." : s) + "'"; }

// %xx escapes of a URI decoded (glTF URIs are RFC 3986 references).
std::string percent_decode(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

// Decoded size of a base64 payload, or -1 if it is not base64.
std::int64_t base64_size(std::string_view s) {
  if (s.size() % 4 != 0) return -1;
  std::size_t pad = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/';
    if (c == '=' && i + 2 >= s.size()) { ++pad; continue; }
    if (!ok || pad > 0) return -1;
  }
  return static_cast<std::int64_t>(s.size() / 4 * 3 - pad);
}

// The checks share the file name and the document.
class Checker {
 public:
  Checker(const json& doc, const std::filesystem::path& file) : doc_(doc), file_(file) {}

  [[noreturn]] void fail_at(const std::string& ptr, const std::string& problem) const { fail(file_, ptr, problem); }

  // The array `key` of the root (empty if absent); an array if present.
  const json& array(const std::string& key) const {
    static const json empty = json::array();
    if (!doc_.contains(key)) return empty;
    if (!doc_[key].is_array()) fail_at("/" + key, "expected an array");
    return doc_[key];
  }
  std::size_t count(const std::string& key) const { return array(key).size(); }

  // A non-negative integer member, or `fallback` when absent.
  std::uint64_t uint(const json& o, const std::string& ptr, const std::string& key, std::uint64_t fallback,
                     bool required = false) const {
    if (!o.is_object()) fail_at(ptr, "expected an object");
    if (!o.contains(key)) {
      if (required) fail_at(ptr, "missing required '" + key + "'");
      return fallback;
    }
    const json& v = o[key];
    if (!v.is_number_integer() || (v.is_number_integer() && !v.is_number_unsigned() && v.get<std::int64_t>() < 0))
      fail_at(ptr + "/" + key, "expected a non-negative integer, found " + v.dump().substr(0, 40));
    return v.get<std::uint64_t>();
  }
  // An index member that must name one of `n` objects of kind `what`.
  std::int64_t index(const json& o, const std::string& ptr, const std::string& key, std::size_t n,
                     const char* what, bool required = false) const {
    if (!o.contains(key) && !required) return -1;
    const std::uint64_t i = uint(o, ptr, key, 0, required);
    if (i >= n)
      fail_at(ptr + "/" + key, "no " + std::string(what) + " " + std::to_string(i) + " (the file has " +
                                   std::to_string(n) + ")");
    return static_cast<std::int64_t>(i);
  }

  // An array member of exactly n finite numbers (absent: empty).
  std::vector<double> numbers(const json& o, const std::string& ptr, const std::string& key, std::size_t n) const {
    if (!o.contains(key)) return {};
    const json& v = o[key];
    if (!v.is_array() || v.size() != n)
      fail_at(ptr + "/" + key, "expected an array of " + std::to_string(n) + " numbers, found " + v.dump().substr(0, 60));
    std::vector<double> out;
    for (std::size_t k = 0; k < n; ++k) {
      if (!v[k].is_number() || !std::isfinite(v[k].get<double>()))
        fail_at(ptr + "/" + key + "/" + std::to_string(k), "expected a finite number, found " + v[k].dump().substr(0, 40));
      out.push_back(v[k].get<double>());
    }
    return out;
  }
  // A node's transform: a 16-number affine `matrix` (column-major, last row
  // 0 0 0 1) or any of `translation` (3), `rotation` (a quaternion x y z w
  // of non-zero length) and `scale` (3), never both kinds (glTF 2.0, 5.25).
  // A malformed one would otherwise be dropped and the mesh placed as if
  // it had none.
  void node_transform(const json& node, const std::string& ptr) const {
    if (!node.is_object()) fail_at(ptr, "expected an object");
    const std::vector<double> matrix = numbers(node, ptr, "matrix", 16);
    const std::vector<double> rotation = numbers(node, ptr, "rotation", 4);
    const bool translation = !numbers(node, ptr, "translation", 3).empty();
    const bool scale = !numbers(node, ptr, "scale", 3).empty();
    const bool trs = translation || !rotation.empty() || scale;
    if (!matrix.empty() && trs) fail_at(ptr, "a node has either 'matrix' or 'translation', 'rotation' and 'scale', not both");
    if (!matrix.empty() && (matrix[3] != 0.0 || matrix[7] != 0.0 || matrix[11] != 0.0 || matrix[15] != 1.0))
      fail_at(ptr + "/matrix", "not an affine transform: its last row (elements 3, 7, 11, 15) must be 0, 0, 0, 1");
    if (!rotation.empty()) {
      const double length = std::sqrt(rotation[0] * rotation[0] + rotation[1] * rotation[1] +
                                      rotation[2] * rotation[2] + rotation[3] * rotation[3]);
      if (!(length > 0.0) || !std::isfinite(length))
        fail_at(ptr + "/rotation", "a rotation is a unit quaternion; this one has no direction: " +
                                       node["rotation"].dump().substr(0, 60));
    }
  }

  std::set<std::filesystem::path> buffers(const Container& c);
  void views();
  void accessors();
  void meshes();
  void nodes_and_scenes();

 private:
  const json& doc_;
  const std::filesystem::path& file_;
  std::vector<std::uint64_t> buffer_length_, view_length_, view_stride_;
};

std::set<std::filesystem::path> Checker::buffers(const Container& c) {
  std::set<std::filesystem::path> external;
  const json& buffers = array("buffers");
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    const std::string ptr = "/buffers/" + std::to_string(i);
    const std::uint64_t length = uint(buffers[i], ptr, "byteLength", 0, true);
    buffer_length_.push_back(length);
    const auto mismatch = [&](const std::string& holder, std::uint64_t size) {
      if (length != size)
        fail_at(ptr + "/byteLength", "byteLength is " + std::to_string(length) + " but " + holder + " has " +
                                         std::to_string(size) + " bytes");
    };
    if (!buffers[i].contains("uri")) {
      if (!c.binary || i != 0) fail_at(ptr, "a buffer without 'uri' must be the first buffer of a .glb file");
      if (length > c.bin_size) mismatch("the BIN chunk", c.bin_size);
      continue;
    }
    if (!buffers[i]["uri"].is_string()) fail_at(ptr + "/uri", "expected a string");
    const std::string uri = buffers[i]["uri"].get<std::string>();
    if (uri.rfind("data:", 0) == 0) {
      const std::string_view view(uri);
      std::int64_t size = -1;
      for (const std::string_view head : {"data:application/octet-stream;base64,", "data:application/gltf-buffer;base64,"})
        if (view.substr(0, head.size()) == head) size = base64_size(view.substr(head.size()));
      if (size < 0)
        fail_at(ptr + "/uri", "unsupported data URI (expected data:application/octet-stream;base64, or "
                              "data:application/gltf-buffer;base64, followed by base64)");
      mismatch("the data URI", static_cast<std::uint64_t>(size));
      continue;
    }
    const std::string decoded = percent_decode(uri);
    const std::filesystem::path rel(decoded);
    if (decoded.empty()) fail_at(ptr + "/uri", "the buffer URI is empty");
    if (decoded.find("://") != std::string::npos || rel.is_absolute() || rel.has_root_name() ||
        rel.has_root_directory())
      fail_at(ptr + "/uri", "buffer URI " + quoted(uri) +
                                " refused: only paths relative to the glTF file's folder and data URIs are read");
    const std::filesystem::path normal = rel.lexically_normal();
    if (!normal.empty() && *normal.begin() == "..")
      fail_at(ptr + "/uri", "buffer URI " + quoted(uri) + " refused: it leaves the glTF file's folder");
    const std::filesystem::path path = (file_.parent_path() / normal).lexically_normal();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
      fail_at(ptr + "/uri", "buffer file " + path.string() + " does not exist");
    mismatch(path.filename().string(), std::filesystem::file_size(path, ec));
    external.insert(path);
  }
  return external;
}

void Checker::views() {
  const json& views = array("bufferViews");
  for (std::size_t i = 0; i < views.size(); ++i) {
    const std::string ptr = "/bufferViews/" + std::to_string(i);
    const auto b = static_cast<std::size_t>(index(views[i], ptr, "buffer", buffer_length_.size(), "buffer", true));
    const std::uint64_t offset = uint(views[i], ptr, "byteOffset", 0);
    const std::uint64_t length = uint(views[i], ptr, "byteLength", 0, true);
    if (offset > buffer_length_[b] || length > buffer_length_[b] - offset)
      fail_at(ptr, "bytes [" + std::to_string(offset) + ", " + std::to_string(offset + length) +
                       ") lie past the end of buffer " + std::to_string(b) + " (" +
                       std::to_string(buffer_length_[b]) + " bytes)");
    const std::uint64_t stride = uint(views[i], ptr, "byteStride", 0);
    if (views[i].contains("byteStride") && (stride < 4 || stride > 252 || stride % 4 != 0))
      fail_at(ptr + "/byteStride", "byteStride must be a multiple of 4 in [4, 252], found " + std::to_string(stride));
    view_length_.push_back(length);
    view_stride_.push_back(stride);
  }
}

std::uint64_t component_size(std::uint64_t type) {
  switch (type) {
    case 5120: case 5121: return 1;  // BYTE, UNSIGNED_BYTE
    case 5122: case 5123: return 2;  // SHORT, UNSIGNED_SHORT
    case 5125: case 5126: return 4;  // UNSIGNED_INT, FLOAT
    default: return 0;
  }
}

std::uint64_t component_count(const std::string& type) {
  static const std::pair<const char*, std::uint64_t> types[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                                                {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
  for (const auto& [name, n] : types)
    if (type == name) return n;
  return 0;
}

void Checker::accessors() {
  const json& accessors = array("accessors");
  for (std::size_t i = 0; i < accessors.size(); ++i) {
    const json& a = accessors[i];
    const std::string ptr = "/accessors/" + std::to_string(i);
    if (a.is_object() && a.contains("sparse"))
      fail_at(ptr + "/sparse", "sparse accessors are not supported");
    const std::uint64_t size = component_size(uint(a, ptr, "componentType", 0, true));
    if (size == 0) fail_at(ptr + "/componentType", "unknown componentType " + a["componentType"].dump());
    const std::uint64_t n = a.contains("type") && a["type"].is_string() ? component_count(a["type"].get<std::string>()) : 0;
    if (n == 0) fail_at(ptr + "/type", "expected SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4");
    const std::uint64_t count = uint(a, ptr, "count", 0, true);
    if (count == 0) fail_at(ptr + "/count", "count must be at least 1");
    const std::int64_t view = index(a, ptr, "bufferView", view_length_.size(), "bufferView");
    const std::uint64_t offset = uint(a, ptr, "byteOffset", 0);
    // Without a bufferView the data is all zeros, and nothing bounds the
    // count but this (pathlab would allocate it).
    if (view < 0 && count > (std::uint64_t{1} << 24))
      fail_at(ptr + "/count", "count " + std::to_string(count) + " without a bufferView: more than 2^24 zeros");
    if (view < 0) continue;  // all zeros
    // Matrices' columns are padded to 4 bytes; pathlab reads no matrices,
    // so their element size only needs to bound the read.
    const std::uint64_t element = size * n;
    const auto v = static_cast<std::size_t>(view);
    const std::uint64_t stride = view_stride_[v] != 0 ? view_stride_[v] : element;
    if (offset % size != 0) fail_at(ptr + "/byteOffset", "byteOffset must be a multiple of the component size");
    const std::uint64_t limit = view_length_[v];
    // count <= limit keeps the products below 2^64.
    const bool past = count > limit || offset > limit || stride * (count - 1) > limit ||
                      offset + stride * (count - 1) + element > limit;
    if (past)
      fail_at(ptr, std::to_string(count) + " elements of " + std::to_string(element) + " bytes (stride " +
                       std::to_string(stride) + ") from byte " + std::to_string(offset) + " read past the end of bufferView " +
                       std::to_string(view) + " (" + std::to_string(limit) + " bytes)");
  }
}

void Checker::meshes() {
  const json& meshes = array("meshes");
  const std::size_t accessors = count("accessors"), materials = count("materials");
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const std::string mptr = "/meshes/" + std::to_string(m);
    if (!meshes[m].is_object() || !meshes[m].contains("primitives") || !meshes[m]["primitives"].is_array())
      fail_at(mptr, "expected an object with an array 'primitives'");
    const json& prims = meshes[m]["primitives"];
    for (std::size_t p = 0; p < prims.size(); ++p) {
      const std::string ptr = mptr + "/primitives/" + std::to_string(p);
      if (!prims[p].is_object() || !prims[p].contains("attributes") || !prims[p]["attributes"].is_object())
        fail_at(ptr, "expected an object with an object 'attributes'");
      for (const auto& [name, unused] : prims[p]["attributes"].items())
        index(prims[p]["attributes"], ptr + "/attributes", name, accessors, "accessor", true);
      if (!prims[p]["attributes"].contains("POSITION")) fail_at(ptr + "/attributes", "missing POSITION");
      index(prims[p], ptr, "indices", accessors, "accessor");
      index(prims[p], ptr, "material", materials, "material");
      if (uint(prims[p], ptr, "mode", 4) > 6) fail_at(ptr + "/mode", "mode must lie in [0, 6]");
    }
  }
}

void Checker::nodes_and_scenes() {
  const json& nodes = array("nodes");
  std::size_t lights = 0;
  if (doc_.contains("extensions") && doc_["extensions"].contains("KHR_lights_punctual") &&
      doc_["extensions"]["KHR_lights_punctual"].contains("lights") &&
      doc_["extensions"]["KHR_lights_punctual"]["lights"].is_array())
    lights = doc_["extensions"]["KHR_lights_punctual"]["lights"].size();
  // glTF gives a node one parent at most: with more, every path through the
  // graph would be a placement, 2^n of them for a chain of n doubled links.
  std::vector<std::int64_t> parent(nodes.size(), -1);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::string ptr = "/nodes/" + std::to_string(i);
    index(nodes[i], ptr, "mesh", count("meshes"), "mesh");
    index(nodes[i], ptr, "camera", count("cameras"), "camera");
    node_transform(nodes[i], ptr);
    if (nodes[i].contains("extensions") && nodes[i]["extensions"].contains("KHR_lights_punctual"))
      index(nodes[i]["extensions"]["KHR_lights_punctual"], ptr + "/extensions/KHR_lights_punctual", "light", lights,
            "light", true);
    if (nodes[i].contains("children")) {
      const json& children = nodes[i]["children"];
      if (!children.is_array()) fail_at(ptr + "/children", "expected an array");
      for (std::size_t k = 0; k < children.size(); ++k) {
        if (!children[k].is_number_unsigned() || children[k].get<std::uint64_t>() >= nodes.size())
          fail_at(ptr + "/children/" + std::to_string(k), "no node " + children[k].dump().substr(0, 20) +
                                                              " (the file has " + std::to_string(nodes.size()) + ")");
        const auto child = children[k].get<std::size_t>();
        if (parent[child] >= 0)
          fail_at(ptr + "/children/" + std::to_string(k),
                  "node " + std::to_string(child) + " already has parent node " + std::to_string(parent[child]) +
                      " (glTF allows one parent per node)");
        parent[child] = static_cast<std::int64_t>(i);
      }
    }
  }
  // A cycle would make the traversal endless: depth-first search without
  // recursion (a deep chain must not overflow the stack), colouring nodes
  // on the current path.
  enum : std::uint8_t { kUnseen, kOnPath, kDone };
  std::vector<std::uint8_t> state(nodes.size(), kUnseen);
  for (std::size_t root = 0; root < nodes.size(); ++root) {
    if (state[root] != kUnseen) continue;
    std::vector<std::pair<std::size_t, std::size_t>> stack{{root, 0}};  // node, next child
    state[root] = kOnPath;
    while (!stack.empty()) {
      auto& [node, next] = stack.back();
      const json* children = nodes[node].contains("children") ? &nodes[node]["children"] : nullptr;
      if (children == nullptr || next == children->size()) {
        state[node] = kDone;
        stack.pop_back();
        continue;
      }
      const std::size_t k = next++;
      const auto child = (*children)[k].get<std::size_t>();
      if (state[child] == kOnPath)
        fail_at("/nodes/" + std::to_string(node) + "/children/" + std::to_string(k),
                "node " + std::to_string(child) + " is its own descendant (a cycle in the node graph)");
      if (state[child] == kUnseen) {
        state[child] = kOnPath;
        stack.emplace_back(child, 0);
      }
    }
  }
  const json& scenes = array("scenes");
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    const std::string ptr = "/scenes/" + std::to_string(s);
    if (!scenes[s].is_object()) fail_at(ptr, "expected an object");
    if (!scenes[s].contains("nodes")) continue;
    if (!scenes[s]["nodes"].is_array()) fail_at(ptr + "/nodes", "expected an array");
    for (std::size_t k = 0; k < scenes[s]["nodes"].size(); ++k)
      if (!scenes[s]["nodes"][k].is_number_unsigned() || scenes[s]["nodes"][k].get<std::uint64_t>() >= nodes.size())
        fail_at(ptr + "/nodes/" + std::to_string(k), "no node " + scenes[s]["nodes"][k].dump().substr(0, 20) +
                                                         " (the file has " + std::to_string(nodes.size()) + ")");
      else if (const auto root = scenes[s]["nodes"][k].get<std::size_t>(); parent[root] >= 0)
        fail_at(ptr + "/nodes/" + std::to_string(k), "node " + std::to_string(root) + " is a child of node " +
                                                         std::to_string(parent[root]) + ", not a root");
  }
  index(doc_, "", "scene", scenes.size(), "scene");
}

}  // namespace

Container read_container(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw InputError(file.string() + ": is a folder, not a glTF file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open: " + std::strerror(errno));
  Container c;
  c.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  const std::size_t size = c.bytes.size();
  c.binary = size >= 4 && std::memcmp(c.bytes.data(), "glTF", 4) == 0;
  if (!c.binary) {
    c.json_text = std::string_view(reinterpret_cast<const char*>(c.bytes.data()), size);
    return c;
  }
  // 12-byte header (magic, version, length), then chunks of (length, type,
  // data): JSON first, BIN optionally second.
  const auto bad = [&](const std::string& problem) { throw InputError(file.string() + ": " + problem); };
  if (size < 20) bad("truncated .glb: " + std::to_string(size) + " bytes, less than a header and one chunk");
  if (read_u32(&c.bytes[4]) != 2) bad("unsupported .glb version " + std::to_string(read_u32(&c.bytes[4])) + " (expected 2)");
  const std::uint64_t length = read_u32(&c.bytes[8]);
  if (length > size) bad("truncated .glb: the header says " + std::to_string(length) + " bytes, the file has " + std::to_string(size));
  if (length < size) bad("the .glb header says " + std::to_string(length) + " bytes but the file has " + std::to_string(size));
  const std::uint64_t json_length = read_u32(&c.bytes[12]);
  if (std::memcmp(&c.bytes[16], "JSON", 4) != 0) bad("the first .glb chunk is not JSON");
  if (20 + json_length > length) bad("truncated .glb: the JSON chunk runs past the end of the file");
  c.json_text = std::string_view(reinterpret_cast<const char*>(&c.bytes[20]), json_length);
  const std::uint64_t next = 20 + json_length;
  if (next + 8 <= length && std::memcmp(&c.bytes[next + 4], "BIN\0", 4) == 0) {
    c.bin_size = read_u32(&c.bytes[next]);
    if (next + 8 + c.bin_size > length) bad("truncated .glb: the BIN chunk runs past the end of the file");
  } else if (next != length && next + 8 > length) {
    bad("truncated .glb: a chunk header is cut off");
  }
  return c;
}

std::set<std::filesystem::path> validate(const json& doc, const std::filesystem::path& file, const Container& container) {
  if (!doc.is_object()) fail(file, "", "expected a JSON object");
  if (!doc.contains("asset") || !doc["asset"].is_object() || !doc["asset"].contains("version") ||
      !doc["asset"]["version"].is_string())
    fail(file, "/asset", "missing asset.version (is this a glTF file?)");
  if (const std::string v = doc["asset"]["version"].get<std::string>(); v.rfind("2.", 0) != 0)
    fail(file, "/asset/version", "unsupported glTF version '" + v.substr(0, 20) + "' (pathlab reads 2.x)");
  if (doc.contains("extensionsRequired")) {
    const json& req = doc["extensionsRequired"];
    if (!req.is_array()) fail(file, "/extensionsRequired", "expected an array");
    for (std::size_t i = 0; i < req.size(); ++i) {
      const std::string name = req[i].is_string() ? req[i].get<std::string>() : req[i].dump();
      if (std::find(std::begin(kSupportedExtensions), std::end(kSupportedExtensions), name) == std::end(kSupportedExtensions))
        fail(file, "/extensionsRequired/" + std::to_string(i),
             "required extension " + quoted(name) +
                 " is not supported (pathlab reads KHR_lights_punctual and KHR_materials_emissive_strength)");
    }
  }
  Checker check(doc, file);
  std::set<std::filesystem::path> external = check.buffers(container);
  check.views();
  check.accessors();
  check.meshes();
  check.nodes_and_scenes();
  return external;
}

}  // namespace pathlab::gltf
