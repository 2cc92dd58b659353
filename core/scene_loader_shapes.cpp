// The shape entries of a scene file other than "gltf": mesh, sphere,
// rectangle and box (format: docs/scene-format.md, "Shapes"). A mesh whose
// OBJ file names materials (`usemtl`) becomes one shape per material.
#include "core/data_dir.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/limits.h"
#include "core/mesh.h"
#include "core/scene_limits.h"
#include "core/scene_loader_internal.h"

#include <optional>

namespace pathlab::scene_detail {
namespace {

// `uvs`: texture coordinates (each face's square onto [0, 1]^2), given only
// to a shape whose material reads textures.
TriangleMesh unit_rectangle(bool uvs) {
  TriangleMesh m;
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  if (uvs) m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  return m;
}

TriangleMesh unit_box(bool uvs) {
  TriangleMesh m;
  // Six faces, each with its own four corners, wound counter-clockwise seen
  // from outside.
  const vec3 n[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const vec3& normal : n) {
    const Frame f(normal);
    const auto base = static_cast<unsigned>(m.positions.size());
    for (const vec2 c : {vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, 1)}) {
      m.positions.push_back(normal + c.x * f.s + c.y * f.t);
      if (uvs) m.uvs.push_back(0.5f * (c + 1.0f));
    }
    // (s, t, n) is right-handed, so s -> t is counter-clockwise about n.
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
  }
  return m;
}

// A mesh file's triangles with the scene material each part gets, before
// the shape's transform.
struct MeshPart {
  TriangleMesh mesh;
  std::optional<std::uint32_t> material;  // none until resolved: every returned part has one
  std::string description;
};

// The triangles of a "mesh" entry, one part per OBJ material its faces use
// (one part for a file without `usemtl`). A part's scene material is, in
// this order: the one "materials" maps its OBJ name to, the scene material
// of the same name, the shape's "material" (also for faces before the first
// `usemtl`).
std::vector<MeshPart> read_mesh_parts(const Node& node, Scene& scene, const std::filesystem::path& folder,
                                      const std::map<std::string, std::uint32_t>& materials,
                                      const std::string& label) {
  const Node file = node.required("file");
  if (file.string().empty()) file.fail("the mesh file name is empty");
  const std::filesystem::path path = resolve_scene_path(folder, file.string());
  const std::string description = label + " (mesh " + file.string();
  if (names_data_file(file.string()) && !std::filesystem::exists(path))
    file.fail(file.string() + ": " + path.string() + " does not exist; " + data_directory_hint());
  const std::string normals = node.has("normals") ? node.child("normals").string() : "file";
  if (normals != "file" && normals != "flat" && normals != "smooth")
    node.child("normals").fail("unknown normals " + in_quotes(normals) + " (expected file, flat or smooth)");
  // The mapping is read before the file, so that a misnamed scene material
  // is reported before the file's problems.
  std::map<std::string, std::uint32_t> by_name;
  if (node.has("materials")) {
    const Node map = node.child("materials");
    map.expect_object();
    for (const auto& [obj_name, unused] : map.value().items())
      by_name[obj_name] = material_index(map.child(obj_name), materials);
  }
  MeshLoadReport report;
  MeshLoadOptions options;
  options.smoothing_groups = normals == "file";
  TriangleMesh mesh;
  try {
    mesh = load_mesh(path, &report, options);
    scene.input_files.push_back(path);
  } catch (const InputError& e) {
    file.fail(e.what());
  }
  if (!report.ignored.empty()) {
    std::string list;
    for (const std::string& what : report.ignored) list += (list.empty() ? "" : "; ") + what;
    scene.warnings.push_back(file.message(path.string() + ": ignored " + list));
  }
  // "file": the file's normals where it has them, else its smoothing
  // groups' (flat otherwise); "flat": none; "smooth": angle-weighted vertex
  // normals, computed over the whole mesh (across material boundaries too).
  if (normals == "flat") {
    mesh.normals.clear();
  } else if (normals == "smooth") {
    mesh.normals = smooth_vertex_normals(mesh);
  }
  if (report.degenerate_dropped > 0)
    scene.warnings.push_back(file.message(
        path.string() + ": dropped " + std::to_string(report.degenerate_dropped) + " degenerate triangle(s) of " +
        std::to_string(report.degenerate_dropped + report.triangles_loaded) + " (zero area or a repeated vertex)"));

  const std::vector<std::string> obj_names = mesh.material_names;
  const std::vector<std::string_view> obj_views(obj_names.begin(), obj_names.end());
  for (const auto& [obj_name, unused] : by_name)
    if (std::find(obj_names.begin(), obj_names.end(), obj_name) == obj_names.end())
      node.child("materials").child(obj_name).fail(
          path.filename().string() + " has no material named " + in_quotes(obj_name) +
          (obj_names.empty() ? std::string(" (it has no 'usemtl')") : suggestion(obj_name, obj_views)));

  std::vector<MeshPart> parts;
  std::vector<std::string> unmatched;  // used OBJ names without a scene material, with "did you mean"
  bool before_usemtl = false;          // faces before the first `usemtl` (in a file that has one)
  std::vector<std::string_view> scene_names;
  for (const auto& [known, unused] : materials) scene_names.push_back(known);
  for (auto& [slot, part] : split_by_face_material(std::move(mesh))) {
    MeshPart& added = parts.emplace_back();
    added.mesh = std::move(part);
    if (slot == TriangleMesh::kNoFileMaterial) {
      added.description = description + (obj_names.empty() ? ")" : ", faces before 'usemtl')");
      before_usemtl = !obj_names.empty();
      continue;
    }
    const std::string& name = obj_names[slot];
    added.description = description + ", material " + in_quotes(name) + ")";
    if (const auto mapped = by_name.find(name); mapped != by_name.end()) {
      added.material = mapped->second;
    } else if (const auto same = materials.find(name); same != materials.end()) {
      added.material = same->second;
    } else {
      unmatched.push_back(in_quotes(name) + suggestion(name, scene_names));
    }
  }
  const bool fallback_needed = std::any_of(parts.begin(), parts.end(), [](const MeshPart& p) { return !p.material; });
  if (!fallback_needed) return parts;
  if (obj_names.empty() || node.has("material")) {
    const std::uint32_t fallback = material_index(node.required("material"), materials);
    for (MeshPart& p : parts)
      if (!p.material) p.material = fallback;
    return parts;
  }
  std::string problem = "missing required key 'material': " + path.filename().string();
  if (!unmatched.empty()) {
    std::string list;
    for (const std::string& u : unmatched) list += (list.empty() ? "" : ", ") + u;
    problem += " uses " + std::string(unmatched.size() == 1 ? "a material" : "materials") +
               " that no scene material matches: " + list;
  }
  if (before_usemtl) problem += std::string(unmatched.empty() ? "" : ", and") + " has faces before its first 'usemtl'";
  const bool one = unmatched.size() + (before_usemtl ? 1 : 0) == 1;
  node.fail(problem + "; give 'material' for " + (one ? "it" : "them") +
            ", or map OBJ names to scene materials in 'materials'");
}


// Moves a triangle shape by the entry's transform, which must leave it in the
// float range and with some area.
void place(const Node& node, Scene& scene, const mat4& xf, Shape& shape) {
  const Node where = node.has("transform") ? node.child("transform") : node;
  const std::size_t dropped = transform_mesh(&shape.mesh, xf);
  for (const vec3& p : shape.mesh.positions)
    if (!within_scene_range(p))
      where.fail(node.has("transform") ? "the transform moves vertices beyond the scene coordinate limit " + kRangeRule
                                       : "a vertex lies beyond the scene coordinate limit " + kRangeRule);
  if (dropped > 0 && !shape.mesh.triangles.empty())
    scene.warnings.push_back(where.message(shape.description + ": the transform made " + std::to_string(dropped) +
                                           " triangle(s) degenerate; dropped"));
  if (shape.mesh.triangles.empty()) {
    const bool emits = scene.materials[shape.material].emits();
    where.fail(emits ? "zero-area light: the shape has no area left after its transform"
                     : "the shape has no area left after its transform");
  }
}

}  // namespace

void require_regular(const Node& at, const std::filesystem::path& path, const std::string& what) {
  if (const std::string kind = special_file_kind(path); !kind.empty())
    at.fail(what + " " + path.string() + " must be a regular file, not " + kind);
}

std::uint32_t material_index(const Node& node, const std::map<std::string, std::uint32_t>& materials) {
  const std::string name = node.string();
  const auto found = materials.find(name);
  if (found == materials.end()) {
    std::vector<std::string_view> names;
    for (const auto& [known, unused] : materials) names.push_back(known);
    node.fail("no material named " + in_quotes(name) + suggestion(name, names));
  }
  return found->second;
}

void read_shape(const Node& node, Scene& scene, const std::filesystem::path& folder,
                const std::map<std::string, std::uint32_t>& materials, const std::string& label) {
  node.expect_object();
  const std::string type = node.required("type").string();
  if (type == "mesh") {
    node.allow_only({"type", "file", "material", "materials", "transform", "flip_normals", "normals"});
  } else if (type == "sphere") {
    node.allow_only({"type", "center", "radius", "material", "transform", "flip_normals"});
  } else if (type == "rectangle" || type == "box") {
    node.allow_only({"type", "material", "transform", "flip_normals"});
  } else {
    const std::array<std::string_view, 5> types{"mesh", "sphere", "rectangle", "box", "gltf"};
    const std::string near = suggestion(type, types);
    node.child("type").fail("unknown shape type " + in_quotes(type) +
                            (near.empty() ? " (expected mesh, sphere, rectangle, box or gltf)" : near));
  }
  // A mesh's "material" may be needed only for some of its parts (or none).
  Shape shape;
  shape.description = label + " (" + type + ")";
  if (type != "mesh" || node.has("material")) shape.material = material_index(node.required("material"), materials);
  shape.flip_normals = node.boolean_or("flip_normals", false);
  const mat4 xf = node.has("transform") ? read_transform(node.child("transform")) : mat4(1.0f);

  if (type == "sphere") {
    shape.kind = Shape::Kind::Sphere;
    if (scene.materials[shape.material].has_alpha())
      node.child("material").fail("material " + in_quotes(scene.materials[shape.material].name) +
                                  " has alpha, which spheres do not support (a ray crosses a sphere twice at one "
                                  "primitive, and both crossings would share one decision); use a mesh");
    shape.center = node.has("center") ? node.child("center").vector3() : vec3(0.0f);
    shape.radius = static_cast<float>(node.number_or("radius", 1.0));
    if (!(shape.radius > 0.0f)) node.child("radius").fail("radius must be positive");
    if (!(shape.radius >= kMinSphereRadius && shape.radius <= kMaxSceneCoordinate))
      node.child("radius").fail("radius must lie in [1e-18, 1e16] (a smaller one squares to a denormal or zero)");
    // A sphere stays a sphere only under rotation, uniform scale, translation.
    const mat3 l(xf);
    const float sx = glm::length(l[0]), sy = glm::length(l[1]), sz = glm::length(l[2]);
    const float tol = 1e-5f * std::max(sx, std::max(sy, sz));
    if (std::abs(sx - sy) > tol || std::abs(sx - sz) > tol || std::abs(glm::dot(l[0], l[1])) > tol * sx ||
        std::abs(glm::dot(l[0], l[2])) > tol * sx || std::abs(glm::dot(l[1], l[2])) > tol * sx)
      node.child("transform").fail("a sphere's transform may only rotate, translate and scale uniformly");
    shape.center = vec3(xf * vec4(shape.center, 1.0f));
    shape.radius *= sx;
    const Node where = node.has("transform") ? node.child("transform") : node.child("radius");
    if (!(shape.radius > 0.0f))
      where.fail(std::string(scene.materials[shape.material].emits() ? "zero-area light: " : "") +
                 "the sphere's radius is zero after its transform");
    if (!(shape.radius >= kMinSphereRadius && shape.radius <= kMaxSceneCoordinate))
      where.fail("the sphere's radius after its transform must lie in [1e-18, 1e16]");
    if (!within_scene_range(glm::abs(shape.center) + vec3(shape.radius)))
      where.fail("the sphere reaches beyond the scene coordinate limit " + kRangeRule);
    scene.shapes.push_back(std::move(shape));
    return;
  }

  shape.kind = Shape::Kind::Triangles;
  std::vector<MeshPart> parts;
  if (type == "mesh") {
    parts = read_mesh_parts(node, scene, folder, materials, label);
  } else {
    const Material& m = scene.materials[shape.material];
    const bool uvs = m.is_textured() || m.normal_map.has_value() || m.alpha_texture.has_value();
    parts.push_back({type == "rectangle" ? unit_rectangle(uvs) : unit_box(uvs), shape.material, shape.description});
  }
  for (MeshPart& part : parts) {
    Shape added = shape;
    added.mesh = std::move(part.mesh);
    added.material = *part.material;
    added.description = std::move(part.description);
    place(node, scene, xf, added);
    scene.shapes.push_back(std::move(added));
  }
}

}  // namespace pathlab::scene_detail
