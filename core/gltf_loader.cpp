// glTF 2.0 through tinygltf. The JSON is checked first (gltf_validate.cpp) so
// that tinygltf reads only files the checks approved and never allocates a
// size the file does not back; then the default scene is put into the world
// here: world-space copies of the meshes, or groups and instances.
#include "core/gltf_loader.h"

#include "core/error.h"
#include "core/geometry.h"
#include "core/messages.h"
#include "core/gltf_validate.h"
#include "core/scene_limits.h"

// No image decoding (textures are not supported yet), no default file system
// access (the callbacks below read only approved buffers), no external image
// read at all. tiny_gltf.h lies in a system include folder, so its own
// warnings stay out of the project's -Werror build.
#include <fstream>  // tiny_gltf.h needs it but includes it only with its default file access

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_NO_FS
#include <tiny_gltf.h>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include <unistd.h>

namespace pathlab {
namespace {

namespace fs = std::filesystem;
using gltf::fail;

// --------------------------------------------------------------- file access

struct Approved {
  std::set<fs::path> files;
};

bool file_exists(const std::string& path, void* user) {
  return static_cast<Approved*>(user)->files.count(fs::path(path).lexically_normal()) > 0;
}
std::string expand_path(const std::string& path, void*) { return path; }
bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  if (!file_exists(path, user)) {
    *err = "not read";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return static_cast<bool>(in) || in.eof();
}
bool write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  *err = "pathlab does not write glTF files";
  return false;
}
// Images are not decoded here: an embedded image's bytes (a data URI or a
// buffer view) are kept as they are, for OpenImageIO to read from a file
// (Flattener::texture); an external one keeps its uri.
bool keep_image_bytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  return true;
}

// The folder embedded images are written to, one per process, removed at
// exit (the scene's textures name these files).
const fs::path& embedded_image_dir() {
  struct Dir {
    fs::path path;
    Dir() {
      path = fs::temp_directory_path() / ("pathlab-gltf-images-" + std::to_string(::getpid()));
      std::error_code ec;
      fs::create_directories(path, ec);
      if (ec) throw SystemError("cannot create " + path.string() + " for glTF's embedded images: " + ec.message());
    }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

tinygltf::Model parse(const fs::path& file, std::vector<fs::path>* external_files) {
  const gltf::Container container = gltf::read_container(file);
  // tinygltf reads "extras" and "extensions" recursively: a file nested
  // deeper than any real one is refused before it can exhaust the stack.
  constexpr int kMaxDepth = 64;
  const auto depth_limit = [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth > kMaxDepth) fail(file, "", "JSON nested more than " + std::to_string(kMaxDepth) + " levels deep");
    return true;
  };
  const nlohmann::json doc = nlohmann::json::parse(container.json_text, depth_limit, false);
  if (doc.is_discarded()) fail(file, "", "not valid JSON");
  Approved approved{gltf::validate(doc, file, container)};
  external_files->assign(approved.files.begin(), approved.files.end());

  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&file_exists, &expand_path, &read_whole_file, &write_whole_file, &approved});
  loader.SetImageLoader(&keep_image_bytes, nullptr);
  tinygltf::Model model;
  std::string err, warn;  // tinygltf's warnings repeat what pathlab reports itself
  const std::string base = file.parent_path().string();
  const bool ok =
      container.binary
          ? loader.LoadBinaryFromMemory(&model, &err, &warn, container.bytes.data(),
                                        static_cast<unsigned int>(container.bytes.size()), base)
          : loader.LoadASCIIFromString(&model, &err, &warn, container.json_text.data(),
                                       static_cast<unsigned int>(container.json_text.size()), base);
  if (!ok || !err.empty()) {
    while (!err.empty() && err.back() == '\n') err.pop_back();
    std::replace(err.begin(), err.end(), '\n', ';');
    throw InputError(file.string() + ": " + (err.empty() ? std::string("tinygltf could not read it") : err));
  }
  return model;
}

// ------------------------------------------------------------------ accessors

const char* component_name(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "byte";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "unsigned byte";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "short";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "unsigned short";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "unsigned int";
    default: return "float";
  }
}

template <typename T>
T load(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// One component as a float: floats as they are, normalized integers mapped
// to [0, 1] or [-1, 1] as glTF defines, other integers by value.
float component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return load<float>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0f : p[0];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const auto v = load<std::uint16_t>(p);
      return normalized ? v / 65535.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = load<std::int8_t>(p);
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const auto v = load<std::int16_t>(p);
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    default: return static_cast<float>(load<std::uint32_t>(p));
  }
}

class Flattener {
 public:
  Flattener(const tinygltf::Model& model, const fs::path& file, const GltfOptions& options)
      : model_(model), file_(file), options_(options) {}

  GltfContent run();

 private:
  // Every component of every element of accessor `index`, element after
  // element. `what` names the attribute; `types` are the component types
  // glTF allows for it (the first one float).
  std::vector<float> floats(int index, int type, std::initializer_list<int> types, bool need_normalized,
                            const std::string& where) const;
  std::vector<std::uint32_t> indices(int index, const std::string& where) const;
  TriangleMesh primitive_mesh(std::size_t mesh, std::size_t prim);
  std::optional<GltfPrimitive> transformed_primitive(std::size_t mesh, std::size_t prim, const mat4& xf,
                                                     const std::string& label, const std::string& node_at);
  std::vector<int> roots() const;
  template <typename Visit>
  void walk(const std::vector<int>& roots, Visit&& visit) const;
  bool may_instance(std::size_t mesh);
  std::optional<std::uint32_t> group(std::size_t mesh);
  bool place_instance(std::size_t mesh, const mat4& xf, std::size_t node);
  void place_mesh(std::size_t mesh, const mat4& world, std::size_t node);
  void place_node(std::size_t node, const mat4& world);
  std::uint32_t material(int index);
  // The TextureRef of a material's textureInfo (its image added to
  // out_.images once per colour space), or nothing (with a warning) for a
  // texture pathlab cannot read as the file means it.
  std::optional<TextureRef> texture(int texture, int tex_coord, const tinygltf::ExtensionMap& extensions,
                                    TextureColorSpace space, const std::string& at);
  void warn_once(const std::string& key, const std::string& text) {
    if (warned_.insert(key).second) out_.warnings.push_back(file_.string() + ": " + text);
  }

  const tinygltf::Model& model_;
  const fs::path& file_;
  const GltfOptions& options_;
  GltfContent out_;
  std::map<int, std::uint32_t> materials_;  // glTF material (-1: default) -> out_.materials
  std::map<std::pair<int, TextureColorSpace>, std::uint32_t> images_;  // (glTF image, colour space) -> out_.images
  std::map<std::pair<std::size_t, std::size_t>, TriangleMesh> meshes_;  // primitives read once, copied per node
  std::vector<bool> instanced_;  // per glTF mesh: placed by instances of a group
  std::map<std::size_t, std::optional<std::uint32_t>> groups_;  // glTF mesh -> out_.groups (none: no triangles)
  std::vector<Box> group_boxes_;                                  // per out_.groups entry, mesh space
  std::set<std::string> ignored_, warned_;
};

std::vector<float> Flattener::floats(int index, int type, std::initializer_list<int> types, bool need_normalized,
                                     const std::string& where) const {
  const tinygltf::Accessor& a = model_.accessors[static_cast<std::size_t>(index)];
  const std::string at = "/accessors/" + std::to_string(index);
  const int n = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(type));
  const bool allowed = std::find(types.begin(), types.end(), a.componentType) != types.end();
  const bool float_type = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
  if (a.type != type || !allowed || (need_normalized && !float_type && !a.normalized))
    fail(file_, where, "expected " + std::to_string(n) + "-component " +
                           (types.size() > 1 ? "float or normalized integer" : std::string("float")) + " data, found " +
                           std::to_string(tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type))) +
                           "-component " + component_name(a.componentType) + " (" + at + ")");
  std::vector<float> values(a.count * static_cast<std::size_t>(n), 0.0f);
  if (a.bufferView < 0) return values;  // glTF: no bufferView means zeros
  // Bounds were checked against the JSON (gltf_validate.cpp), whose sizes
  // tinygltf has loaded exactly.
  const tinygltf::BufferView& v = model_.bufferViews[static_cast<std::size_t>(a.bufferView)];
  const unsigned char* base = model_.buffers[static_cast<std::size_t>(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
  const int size = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
  const std::size_t stride = v.byteStride != 0 ? v.byteStride : static_cast<std::size_t>(size * n);
  for (std::size_t i = 0; i < a.count; ++i)
    for (int c = 0; c < n; ++c)
      values[i * static_cast<std::size_t>(n) + static_cast<std::size_t>(c)] =
          component(base + i * stride + static_cast<std::size_t>(c * size), a.componentType, a.normalized);
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      fail(file_, where, "element " + std::to_string(i / static_cast<std::size_t>(n)) + " is not finite (" + at + ")");
  return values;
}

std::vector<std::uint32_t> Flattener::indices(int index, const std::string& where) const {
  const tinygltf::Accessor& a = model_.accessors[static_cast<std::size_t>(index)];
  if (a.type != TINYGLTF_TYPE_SCALAR ||
      (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
       a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
    fail(file_, where, "indices must be scalar unsigned byte, short or int, found " +
                           std::string(component_name(a.componentType)) + " (/accessors/" + std::to_string(index) + ")");
  std::vector<std::uint32_t> out(a.count, 0);
  if (a.bufferView < 0) return out;
  const tinygltf::BufferView& v = model_.bufferViews[static_cast<std::size_t>(a.bufferView)];
  const unsigned char* base = model_.buffers[static_cast<std::size_t>(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
  const auto size = static_cast<std::size_t>(tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType)));
  const std::size_t stride = v.byteStride != 0 ? v.byteStride : size;
  for (std::size_t i = 0; i < a.count; ++i) {
    const unsigned char* p = base + i * stride;
    out[i] = size == 1 ? p[0] : size == 2 ? load<std::uint16_t>(p) : load<std::uint32_t>(p);
  }
  return out;
}

TriangleMesh Flattener::primitive_mesh(std::size_t mesh, std::size_t prim) {
  const tinygltf::Primitive& p = model_.meshes[mesh].primitives[prim];
  const std::string ptr = "/meshes/" + std::to_string(mesh) + "/primitives/" + std::to_string(prim);
  TriangleMesh m;
  const std::string pos_at = ptr + "/attributes/POSITION";
  const std::vector<float> pos = floats(p.attributes.at("POSITION"), TINYGLTF_TYPE_VEC3,
                                        {TINYGLTF_COMPONENT_TYPE_FLOAT}, false, pos_at);
  const std::size_t count = pos.size() / 3;
  for (std::size_t i = 0; i < count; ++i) m.positions.emplace_back(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
  const auto attribute = [&](const char* name, int type, std::initializer_list<int> types) {
    const auto it = p.attributes.find(name);
    if (it == p.attributes.end()) return std::vector<float>();
    const std::string at = ptr + "/attributes/" + name;
    std::vector<float> v = floats(it->second, type, types, types.size() > 1, at);
    const std::size_t n = v.size() / static_cast<std::size_t>(tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(type)));
    if (n != count)
      fail(file_, at, std::to_string(n) + " elements, but POSITION has " + std::to_string(count));
    return v;
  };
  const std::vector<float> normals = attribute("NORMAL", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
  for (std::size_t i = 0; i < normals.size() / 3; ++i) {
    const vec3 n(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    if (!(glm::length(n) > 0.0f)) fail(file_, ptr + "/attributes/NORMAL", "element " + std::to_string(i) + " has zero length");
    m.normals.push_back(glm::normalize(n));
  }
  // glTF's UV origin is the image's top-left corner (v down); pathlab keeps
  // the OBJ / PLY / pbrt convention (origin bottom-left, v up): v -> 1 - v.
  const std::vector<float> uvs = attribute("TEXCOORD_0", TINYGLTF_TYPE_VEC2,
                                           {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                            TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
  for (std::size_t i = 0; i < uvs.size() / 2; ++i) m.uvs.emplace_back(uvs[2 * i], 1.0f - uvs[2 * i + 1]);
  const std::vector<float> tangents = attribute("TANGENT", TINYGLTF_TYPE_VEC4, {TINYGLTF_COMPONENT_TYPE_FLOAT});
  for (std::size_t i = 0; i < tangents.size() / 4; ++i) {
    const vec3 t(tangents[4 * i], tangents[4 * i + 1], tangents[4 * i + 2]);
    if (!(glm::length(t) > 0.0f)) fail(file_, ptr + "/attributes/TANGENT", "element " + std::to_string(i) + " has zero length");
    m.tangents.emplace_back(glm::normalize(t), tangents[4 * i + 3] < 0.0f ? -1.0f : 1.0f);
  }
  for (const auto& [name, unused] : p.attributes)
    if (name != "POSITION" && name != "NORMAL" && name != "TEXCOORD_0" && name != "TANGENT")
      ignored_.insert("attribute " + name);
  if (!p.targets.empty()) ignored_.insert("morph targets");

  std::vector<std::uint32_t> idx;
  if (p.indices >= 0) {
    idx = indices(p.indices, ptr + "/indices");
    for (const std::uint32_t i : idx)
      if (i >= count)
        fail(file_, ptr + "/indices", "index " + std::to_string(i) + " out of range (" + std::to_string(count) + " vertices)");
  } else {
    idx.resize(count);
    for (std::size_t i = 0; i < count; ++i) idx[i] = static_cast<std::uint32_t>(i);
  }
  // Strips and fans as glTF defines them, keeping each triangle's winding.
  const std::size_t n = idx.size();
  if (p.mode == TINYGLTF_MODE_TRIANGLES || p.mode == -1) {
    for (std::size_t i = 0; i + 2 < n; i += 3) m.triangles.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
  } else if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (std::size_t i = 0; i + 2 < n; ++i)
      m.triangles.push_back(i % 2 == 0 ? glm::uvec3(idx[i], idx[i + 1], idx[i + 2]) : glm::uvec3(idx[i], idx[i + 2], idx[i + 1]));
  } else if (p.mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (std::size_t i = 1; i + 1 < n; ++i) m.triangles.emplace_back(idx[i], idx[i + 1], idx[0]);
  }
  return m;
}

// The local transform of a node: its matrix, or T * R * S.
mat4 local_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    mat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = static_cast<float>(node.matrix[static_cast<std::size_t>(4 * c + r)]);
    return m;
  }
  mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, vec3(static_cast<float>(node.translation[0]), static_cast<float>(node.translation[1]),
                               static_cast<float>(node.translation[2])));
  if (node.rotation.size() == 4)  // normalised in double: a long finite quaternion overflows a float's length
    m = m * glm::mat4_cast(glm::quat(glm::normalize(
                glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]))));
  if (node.scale.size() == 3)
    m = glm::scale(m, vec3(static_cast<float>(node.scale[0]), static_cast<float>(node.scale[1]), static_cast<float>(node.scale[2])));
  return m;
}

// Primitive `prim` of `mesh` moved by `xf`, without the triangles that are
// degenerate after it (a warning says how many); none for points and lines
// or when no triangle is left. `node_at` is the JSON pointer blamed for a
// transform that leaves the float range.
std::optional<GltfPrimitive> Flattener::transformed_primitive(std::size_t mesh, std::size_t prim, const mat4& xf,
                                                              const std::string& label, const std::string& node_at) {
  const tinygltf::Primitive& p = model_.meshes[mesh].primitives[prim];
  if (p.mode >= 0 && p.mode < TINYGLTF_MODE_TRIANGLES) {
    warn_once("points", "primitives of points or lines skipped");
    return std::nullopt;
  }
  const auto key = std::make_pair(mesh, prim);
  if (meshes_.count(key) == 0) meshes_[key] = primitive_mesh(mesh, prim);
  GltfPrimitive out{file_.string() + ": /meshes/" + std::to_string(mesh) + "/primitives/" + std::to_string(prim) + " (" +
                        label + ")",
                    meshes_[key], material(p.material)};
  const std::size_t before = out.mesh.triangles.size();
  const std::size_t dropped = transform_mesh(&out.mesh, xf);
  for (const vec3& v : out.mesh.positions)
    if (!within_scene_range(v)) fail(file_, node_at, "the transform moves vertices beyond the scene coordinate limit 1e16");
  if (dropped > 0)
    out_.warnings.push_back(out.description + ": dropped " + std::to_string(dropped) + " degenerate triangle(s) of " +
                            std::to_string(before));
  if (out.mesh.triangles.empty()) return std::nullopt;
  return out;
}

// Whether `mesh` may be a group: not if one of its primitives would be
// sampled as a light, since the light sampler does not sample emitters in
// groups (an instanced emitter would need a light per placement); such a
// mesh stays copies, which stay lights.
bool Flattener::may_instance(std::size_t mesh) {
  for (const tinygltf::Primitive& p : model_.meshes[mesh].primitives) {
    if (p.mode >= 0 && p.mode < TINYGLTF_MODE_TRIANGLES) continue;
    const GltfMaterial& m = out_.materials[material(p.material)];
    if (options_.is_light ? options_.is_light(m) : m.material.emits() && m.material.sampled_as_light) return false;
  }
  return true;
}

// The group of `mesh`, made when first placed: its primitives in mesh space.
// None if no triangle is left (points and lines only, or all degenerate).
std::optional<std::uint32_t> Flattener::group(std::size_t mesh) {
  if (const auto it = groups_.find(mesh); it != groups_.end()) return it->second;
  const std::string& gltf_name = model_.meshes[mesh].name;
  GltfGroup g;
  g.name = file_.filename().string() + "/mesh " + (gltf_name.empty() ? "#" + std::to_string(mesh) : gltf_name);
  for (const GltfGroup& other : out_.groups)
    if (other.name == g.name) g.name += " #" + std::to_string(mesh);  // two glTF meshes of one name stay apart
  Box box;
  for (std::size_t prim = 0; prim < model_.meshes[mesh].primitives.size(); ++prim) {
    std::optional<GltfPrimitive> p = transformed_primitive(mesh, prim, mat4(1.0f), "mesh space", "/meshes/" + std::to_string(mesh));
    if (!p) continue;
    for (const vec3& v : p->mesh.positions) box.add(v);
    g.primitives.push_back(std::move(*p));
  }
  std::optional<std::uint32_t> index;
  if (!g.primitives.empty()) {
    index = static_cast<std::uint32_t>(out_.groups.size());
    out_.groups.push_back(std::move(g));
    group_boxes_.push_back(box);
  }
  groups_[mesh] = index;
  return index;
}

// Places `mesh` by an instance of its group at `xf`, or returns false if
// that placement cannot be an instance: Embree and the normals need its
// inverse, and the placed group must stay within the float range. The
// caller copies such a placement instead, as for a mesh placed once: a
// singular one loses its (now degenerate) triangles with a warning naming
// the node, one beyond the float range is refused there.
bool Flattener::place_instance(std::size_t mesh, const mat4& xf, std::size_t node) {
  if (!invertible_placement(xf)) return false;
  const std::optional<std::uint32_t> g = group(mesh);
  if (!g) return true;  // nothing to place
  if (!placed_in_range(group_boxes_[*g], xf)) return false;
  out_.instances.push_back(
      {*g, xf, file_.string() + ": /nodes/" + std::to_string(node) + " (mesh " + std::to_string(mesh) + ")"});
  return true;
}

// The one place a mesh is put into the world: an instance of its group if
// several nodes place it, else (or if that placement cannot be an instance)
// a world-space copy of each primitive.
void Flattener::place_mesh(std::size_t mesh, const mat4& world, std::size_t node) {
  const mat4 xf = options_.transform * world;
  if (instanced_[mesh] && place_instance(mesh, xf, node)) return;
  for (std::size_t prim = 0; prim < model_.meshes[mesh].primitives.size(); ++prim)
    if (std::optional<GltfPrimitive> p =
            transformed_primitive(mesh, prim, xf, "node " + std::to_string(node), "/nodes/" + std::to_string(node)))
      out_.primitives.push_back(std::move(*p));
}

void Flattener::place_node(std::size_t index, const mat4& world) {
  const tinygltf::Node& node = model_.nodes[index];
  if (node.mesh >= 0) place_mesh(static_cast<std::size_t>(node.mesh), world, index);
  if (node.skin >= 0) ignored_.insert("skins");
  const mat4 xf = options_.transform * world;
  if (node.camera >= 0) {
    const tinygltf::Camera& cam = model_.cameras[static_cast<std::size_t>(node.camera)];
    const std::string at = "/cameras/" + std::to_string(node.camera);
    if (cam.type == "perspective") {
      const double yfov = cam.perspective.yfov;
      // As the scene's fov_y (core/scene_limits.h): just below pi is 180 degrees as a float.
      const double max_yfov = kMaxFovYDegrees * M_PI / 180.0;
      if (!(yfov > 0.0 && yfov <= max_yfov && static_cast<float>(yfov * 180.0 / M_PI) > 0.0f))
        fail(file_, at + "/perspective/yfov",
             "yfov " + exact_number(yfov) + " is outside (0, " + format_number(max_yfov) + "] radians (0 to " +
                 format_number(kMaxFovYDegrees) + " degrees; docs/scene-format.md)");
      GltfCamera c;
      // A glTF camera looks down its -z axis with +y up.
      c.desc.position = vec3(xf * vec4(0, 0, 0, 1));
      const vec3 forward = glm::normalize(vec3(xf * vec4(0, 0, -1, 0)));
      c.desc.look_at = c.desc.position + forward;
      c.desc.up = glm::normalize(vec3(xf * vec4(0, 1, 0, 0)));
      c.desc.fov_y_degrees = static_cast<float>(yfov * 180.0 / M_PI);
      c.desc.focus_distance = 1.0f;
      if (!is_finite(c.desc.position) || !is_finite(forward) || !is_finite(c.desc.up) ||
          !(glm::length(glm::cross(forward, c.desc.up)) > 0.0f))
        fail(file_, "/nodes/" + std::to_string(index), "the camera's transform is degenerate");
      if (cam.perspective.aspectRatio > 0.0) c.aspect_ratio = static_cast<float>(cam.perspective.aspectRatio);
      out_.cameras.push_back(c);
    } else {
      warn_once("ortho", "orthographic cameras ignored");
    }
  }
  const auto light = node.extensions.find("KHR_lights_punctual");
  if (light != node.extensions.end() && light->second.Has("light")) {
    const int l = light->second.Get("light").GetNumberAsInt();
    const tinygltf::Light& src = model_.lights[static_cast<std::size_t>(l)];
    const std::string where = "/extensions/KHR_lights_punctual/lights/" + std::to_string(l);
    Spectrum color(1.0f);
    if (src.color.size() == 3) color = Spectrum(static_cast<float>(src.color[0]), static_cast<float>(src.color[1]),
                                                 static_cast<float>(src.color[2]));
    // Candela taken as W/sr, lux as W/m^2, per channel (docs/scene-format.md).
    const Spectrum intensity = color * static_cast<float>(src.intensity);
    if (!is_finite(intensity) || intensity.x < 0.0f || intensity.y < 0.0f || intensity.z < 0.0f)
      fail(file_, where, "colour and intensity must be finite and not negative");
    DeltaLight out;
    out.position = vec3(xf * vec4(0, 0, 0, 1));
    out.intensity = intensity;
    if (src.type == "spot" || src.type == "directional") {
      // Both shine down the node's -z axis.
      const vec3 axis = vec3(xf * vec4(0, 0, -1, 0));
      if (!is_finite(axis) || !(glm::length(axis) > 0.0f))
        fail(file_, "/nodes/" + std::to_string(index), "the light's transform is degenerate");
      out.direction = glm::normalize(axis);
    }
    if (src.type == "point") {
      out_.delta_lights.push_back(out);
    } else if (src.type == "spot") {
      const double inner = src.spot.innerConeAngle, outer = src.spot.outerConeAngle;
      if (!(inner >= 0.0 && inner < outer && outer <= M_PI / 2))
        fail(file_, where, "spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
      out.kind = DeltaLight::Kind::Spot;
      out.cos_outer = static_cast<float>(std::cos(outer));
      out.cos_inner = static_cast<float>(std::cos(inner));
      out_.delta_lights.push_back(out);
    } else if (src.type == "directional") {
      out.kind = DeltaLight::Kind::Directional;
      out_.delta_lights.push_back(out);
    } else {
      warn_once("lights", "lights of a type other than point, spot and directional ignored");
    }
  }
}

// glTF metallic-roughness onto Disney (table in docs/scene-format.md).
std::uint32_t Flattener::material(int index) {
  if (const auto it = materials_.find(index); it != materials_.end()) return it->second;
  const std::string label = file_.filename().string() + "/";
  GltfMaterial out;
  DisneyParams p;
  p.specular = 0.5f;  // F0 = 0.08 * 0.5 = 0.04, glTF's dielectric F0
  p.specular_tint = 0.0f;
  p.sheen = 0.0f;
  Spectrum emission(0.0f);
  float coverage = 1.0f;  // Material::alpha
  float cutoff = -1.0f;   // Material::alpha_cutoff
  std::optional<TextureRef> coverage_texture;  // Material::alpha_texture
  std::vector<TexturedParam> textures;
  std::optional<NormalMap> normal_map;
  std::optional<TextureRef> emission_texture;
  if (index < 0) {
    // glTF's default material: base colour 1, metallic 1, roughness 1.
    p.base_color = Spectrum(1.0f);
    p.metallic = 1.0f;
    p.roughness = 1.0f;
    out.material.name = label + "(default)";
  } else {
    const tinygltf::Material& m = model_.materials[static_cast<std::size_t>(index)];
    const std::string at = "/materials/" + std::to_string(index);
    const auto unit = [&](double v, const std::string& key) {
      if (!(v >= 0.0 && v <= 1.0)) fail(file_, at + key, "must lie in [0, 1], found " + format_number(v));
      return static_cast<float>(v);
    };
    const auto& pbr = m.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() != 4) fail(file_, at + "/pbrMetallicRoughness/baseColorFactor", "expected 4 numbers");
    for (int c = 0; c < 3; ++c)
      p.base_color[c] = unit(pbr.baseColorFactor[static_cast<std::size_t>(c)], "/pbrMetallicRoughness/baseColorFactor");
    const float alpha = unit(pbr.baseColorFactor[3], "/pbrMetallicRoughness/baseColorFactor");
    p.metallic = unit(pbr.metallicFactor, "/pbrMetallicRoughness/metallicFactor");
    p.roughness = unit(pbr.roughnessFactor, "/pbrMetallicRoughness/roughnessFactor");
    if (m.emissiveFactor.size() == 3) {
      for (int c = 0; c < 3; ++c) emission[c] = unit(m.emissiveFactor[static_cast<std::size_t>(c)], "/emissiveFactor");
    }
    for (const auto& [name, value] : m.extensions) {
      if (name == "KHR_materials_emissive_strength" && value.Has("emissiveStrength")) {
        const double s = value.Get("emissiveStrength").GetNumberAsDouble();
        if (!(s >= 0.0 && std::isfinite(s)))
          fail(file_, at + "/extensions/" + name + "/emissiveStrength", "must be finite and not negative");
        emission *= static_cast<float>(s);
      } else if (name != "KHR_materials_emissive_strength") {
        ignored_.insert("extension " + name);
      }
    }
    // alphaMode (glTF 2.0, 3.9.4) onto the material's coverage: OPAQUE
    // ignores alpha, MASK keeps the surface where alpha >= alphaCutoff and
    // cuts it elsewhere, BLEND is stochastic coverage. Alpha is the factor's
    // times the base colour texture's (its fourth channel, always linear;
    // 1 for an image without one).
    if (m.alphaMode == "MASK") {
      if (!(m.alphaCutoff >= 0.0)) fail(file_, at + "/alphaCutoff", "must not be negative");
      cutoff = static_cast<float>(m.alphaCutoff);
      coverage = alpha >= cutoff ? 1.0f : 0.0f;
    } else if (m.alphaMode == "BLEND") {
      coverage = alpha;
    }
    // Textures multiply their factors (glTF 2.0, 3.9): the factor is the
    // TextureRef's scale.
    if (pbr.baseColorTexture.index >= 0)
      if (auto t = texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
                           TextureColorSpace::Srgb, at + "/pbrMetallicRoughness/baseColorTexture")) {
        t->scale = p.base_color;
        textures.push_back({MaterialParam::BaseColor, *t});
        if (m.alphaMode == "MASK" || m.alphaMode == "BLEND") {
          t->channel = 3;
          t->scale = Spectrum(alpha);
          coverage_texture = t;
        }
      }
    if (pbr.metallicRoughnessTexture.index >= 0)
      if (auto t = texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                           pbr.metallicRoughnessTexture.extensions, TextureColorSpace::Linear,
                           at + "/pbrMetallicRoughness/metallicRoughnessTexture")) {
        // Blue is metallic, green roughness.
        t->channel = 2;
        t->scale = Spectrum(p.metallic);
        textures.push_back({MaterialParam::Metallic, *t});
        t->channel = 1;
        t->scale = Spectrum(p.roughness);
        textures.push_back({MaterialParam::Roughness, *t});
      }
    if (m.normalTexture.index >= 0)
      if (auto t = texture(m.normalTexture.index, m.normalTexture.texCoord, m.normalTexture.extensions,
                           TextureColorSpace::Linear, at + "/normalTexture"))
      {
        if (!(std::abs(m.normalTexture.scale) <= double(kMaxNormalMapScale)))
          fail(file_, at + "/normalTexture/scale",
               "a normal map's scale must lie in [-1e6, 1e6] (beyond, the tilted normal's length overflows)");
        normal_map = NormalMap{*t, static_cast<float>(m.normalTexture.scale)};
      }
    if (m.emissiveTexture.index >= 0)
      if (auto t = texture(m.emissiveTexture.index, m.emissiveTexture.texCoord, m.emissiveTexture.extensions,
                           TextureColorSpace::Srgb, at + "/emissiveTexture"))
        emission_texture = t;
    if (m.occlusionTexture.index >= 0) ignored_.insert("occlusionTexture");
    out.gltf_name = m.name;
    out.double_sided = m.doubleSided;
    out.material.name = label + (m.name.empty() ? "#" + std::to_string(index) : m.name);
  }
  const std::string name = out.material.name;
  out.material = disney_material(p);
  out.material.name = name;
  out.material.emission = emission;
  out.material.alpha = coverage;
  out.material.alpha_cutoff = cutoff;
  out.material.alpha_texture = coverage_texture;
  for (const TexturedParam& t : textures) out.material.set_texture(t.param, t.texture);
  if (emission_texture && !is_black(emission)) {
    emission_texture->scale = emission;
    out.material.set_texture(MaterialParam::Emission, *emission_texture);
  }
  out.material.normal_map = normal_map;
  // Single-sided: the back neither reflects nor emits (Material::one_sided).
  // glTF's back-face culling, which makes the back invisible in a
  // rasteriser, is not modelled: the back still occludes.
  out.material.two_sided_emission = out.double_sided;
  out.material.one_sided = !out.double_sided;
  // Two glTF materials of one name stay apart.
  for (const GltfMaterial& other : out_.materials)
    if (other.material.name == out.material.name) out.material.name += "#" + std::to_string(index);
  const auto at = static_cast<std::uint32_t>(out_.materials.size());
  out_.materials.push_back(std::move(out));
  materials_[index] = at;
  return at;
}

std::optional<TextureRef> Flattener::texture(int index, int tex_coord, const tinygltf::ExtensionMap& extensions,
                                             TextureColorSpace space, const std::string& at) {
  if (tex_coord != 0) {
    warn_once("texcoord", "textures read through TEXCOORD_1 or later ignored (only TEXCOORD_0 is read), first at " + at);
    return std::nullopt;
  }
  if (extensions.count("KHR_texture_transform") > 0)
    warn_once("transform", "KHR_texture_transform ignored (textures read untransformed), first at " + at);
  if (index < 0 || static_cast<std::size_t>(index) >= model_.textures.size())
    fail(file_, at + "/index", "no texture " + std::to_string(index));
  const tinygltf::Texture& tex = model_.textures[static_cast<std::size_t>(index)];
  if (tex.source < 0 || static_cast<std::size_t>(tex.source) >= model_.images.size()) {
    warn_once("nosource", "a texture without an image (or with only an extension's image) ignored, first at " + at);
    return std::nullopt;
  }
  TextureRef ref;
  if (tex.sampler >= 0 && static_cast<std::size_t>(tex.sampler) < model_.samplers.size()) {
    const tinygltf::Sampler& sm = model_.samplers[static_cast<std::size_t>(tex.sampler)];
    const auto wrap = [](int mode) {
      return mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? TextureWrap::Clamp
             : mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? TextureWrap::Mirror
                                                             : TextureWrap::Repeat;
    };
    ref.wrap = wrap(sm.wrapS);
    if (sm.wrapT != sm.wrapS)
      warn_once("wrap", "a sampler whose wrapT differs from wrapS reads both with wrapS's mode, first at " + at);
  }
  const auto key = std::make_pair(tex.source, space);
  if (const auto it = images_.find(key); it != images_.end()) {
    ref.image = it->second;
    return ref;
  }
  const tinygltf::Image& image = model_.images[static_cast<std::size_t>(tex.source)];
  const std::string image_at = "/images/" + std::to_string(tex.source);
  fs::path path;
  if (!image.image.empty()) {
    // Embedded: written out once per image for OpenImageIO to read.
    static std::atomic<unsigned> counter{0};
    const std::string ext = image.mimeType == "image/jpeg" ? ".jpg" : image.mimeType == "image/png" ? ".png" : ".img";
    path = embedded_image_dir() / (file_.stem().string() + "-" + std::to_string(counter++) + ext);
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(image.image.data()), static_cast<std::streamsize>(image.image.size()));
    if (!out) throw SystemError(path.string() + ": cannot write glTF's embedded image " + image_at);
  } else if (!image.uri.empty()) {
    path = (file_.parent_path() / image.uri).lexically_normal();
    if (!fs::is_regular_file(path)) fail(file_, image_at + "/uri", "the image " + path.string() + " does not exist");
  } else {
    fail(file_, image_at, "the image has neither data nor a uri");
  }
  ref.image = static_cast<std::uint32_t>(out_.images.size());
  out_.images.push_back({path, space, file_.string() + ": " + image_at});
  images_[key] = ref.image;
  return ref;
}

// The default scene's root nodes (`scene`, else scene 0, else every node
// that is no node's child).
std::vector<int> Flattener::roots() const {
  const int scene = model_.defaultScene >= 0 ? model_.defaultScene : model_.scenes.empty() ? -1 : 0;
  if (scene >= 0) return model_.scenes[static_cast<std::size_t>(scene)].nodes;
  std::vector<int> out;
  std::vector<bool> child(model_.nodes.size(), false);
  for (const tinygltf::Node& n : model_.nodes)
    for (const int c : n.children) child[static_cast<std::size_t>(c)] = true;
  for (std::size_t i = 0; i < model_.nodes.size(); ++i)
    if (!child[i]) out.push_back(static_cast<int>(i));
  return out;
}

// visit(node, world matrix) for every node under the roots, parents first,
// depth first without recursion (the validator refused cycles and second
// parents, so each node is visited once).
template <typename Visit>
void Flattener::walk(const std::vector<int>& roots, Visit&& visit) const {
  std::vector<std::pair<std::size_t, mat4>> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(static_cast<std::size_t>(*it), mat4(1.0f));
  while (!stack.empty()) {
    const auto [node, parent] = stack.back();
    stack.pop_back();
    const mat4 world = parent * local_transform(model_.nodes[node]);
    visit(node, world);
    const std::vector<int>& children = model_.nodes[node].children;
    for (auto it = children.rbegin(); it != children.rend(); ++it) stack.emplace_back(static_cast<std::size_t>(*it), world);
  }
}

GltfContent Flattener::run() {
  for (const std::string& ext : model_.extensionsUsed)
    if (std::find(std::begin(gltf::kSupportedExtensions), std::end(gltf::kSupportedExtensions), ext) ==
        std::end(gltf::kSupportedExtensions))
      ignored_.insert("extension " + ext);
  if (!model_.animations.empty()) ignored_.insert("animations");
  // The file's materials in file order, used or not, so that names can be
  // overridden whatever the scene shows.
  for (std::size_t m = 0; m < model_.materials.size(); ++m) material(static_cast<int>(m));

  const std::vector<int> from = roots();
  // A mesh is a group if two or more nodes place it.
  std::vector<std::size_t> uses(model_.meshes.size(), 0);
  walk(from, [&](std::size_t node, const mat4&) {
    if (model_.nodes[node].mesh >= 0) ++uses[static_cast<std::size_t>(model_.nodes[node].mesh)];
  });
  instanced_.assign(model_.meshes.size(), false);
  for (std::size_t m = 0; m < model_.meshes.size(); ++m)
    instanced_[m] = !options_.flatten && uses[m] >= 2 && may_instance(m);
  walk(from, [&](std::size_t node, const mat4& world) { place_node(node, world); });
  if (out_.primitives.empty() && out_.groups.empty() && out_.delta_lights.empty())
    out_.warnings.push_back(file_.string() + ": the scene holds no triangles");
  if (!ignored_.empty()) {
    std::string list;
    for (const std::string& what : ignored_) list += (list.empty() ? "" : ", ") + what;
    out_.warnings.push_back(file_.string() + ": ignored (not supported yet): " + list);
  }
  return std::move(out_);
}

}  // namespace

bool is_gltf_file(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".gltf" || ext == ".glb";
}

GltfContent load_gltf(const fs::path& file, const GltfOptions& options) {
  std::vector<fs::path> external_files;
  const tinygltf::Model model = parse(file, &external_files);
  GltfContent content = Flattener(model, file, options).run();
  content.external_files = std::move(external_files);
  return content;
}

}  // namespace pathlab
