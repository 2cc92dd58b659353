// glTF 2.0 files (.gltf with embedded or external buffers, .glb) read into
// triangle meshes (world-space copies, or groups placed by instances for a
// mesh several nodes use), Disney materials, cameras and point lights.
// The mapping and what is ignored: docs/scene-format.md ("gltf" shapes).
#pragma once

#include "core/camera.h"
#include "core/material.h"
#include "core/mesh.h"
#include "core/scene.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace pathlab {

// One glTF material mapped onto pathlab's Disney model.
struct GltfMaterial {
  std::string gltf_name;  // the file's name for it; empty if unnamed (and for the default material)
  Material material;      // MaterialType::Disney; name "<file name>/<glTF name>", "#<index>" if unnamed
  // glTF's doubleSided, which the material follows: false makes it one-sided
  // (Material::one_sided) and its emission one-sided.
  bool double_sided = false;
};

// One primitive of one mesh: placed by one node (GltfContent::primitives),
// or in mesh space as a member of a group (GltfGroup::primitives).
struct GltfPrimitive {
  std::string description;  // "<file>: /meshes/0/primitives/1 (node 3)", "... (mesh space)"
  TriangleMesh mesh;        // world space: node transforms, then the caller's transform; or mesh space
  std::uint32_t material;   // into GltfContent::materials
};

// A mesh that several nodes place: its primitives once, in mesh space.
struct GltfGroup {
  std::string name;  // "<file name>/mesh <glTF name>", "mesh #<index>" if unnamed; unique in the file
  std::vector<GltfPrimitive> primitives;
};

struct GltfCamera {
  CameraDesc desc;                     // placed by its node; yfov as fov_y
  std::optional<float> aspect_ratio;   // width / height, if the file gives it
};

struct GltfContent {
  // The file's materials in file order, then glTF's default material if a
  // primitive has none.
  std::vector<GltfMaterial> materials;
  std::vector<GltfPrimitive> primitives;   // world space
  std::vector<GltfGroup> groups;
  // One per node placement of a group: Instance::group indexes `groups`,
  // to_world = the caller's transform x the node's world matrix.
  std::vector<Instance> instances;
  std::vector<GltfCamera> cameras;         // perspective cameras, in node order
  std::vector<DeltaLight> delta_lights;    // KHR_lights_punctual point, spot and directional lights
  // The images the materials' textures read (TextureRef::image indexes
  // this list): external files where the glTF names them, embedded ones
  // (data URIs, buffer views) written to a temporary folder removed at exit.
  std::vector<TextureImage> images;
  std::vector<std::string> warnings;       // one line each, naming the file
};

struct GltfOptions {
  mat4 transform{1.0f};  // applied after the node transforms
  // Every mesh as world-space copies, none instanced: for a file that is
  // itself a member of a scene group (Embree instances one level deep).
  bool flatten = false;
  // Whether a primitive of this material would be sampled as a light, once
  // the caller's material overrides apply; empty: the glTF material's own
  // emission. A mesh with such a primitive is always copied, since the light
  // sampler does not sample emitters in groups.
  std::function<bool(const GltfMaterial&)> is_light;
};

// Reads the default scene (`scene`, else scene 0, else every root node) of a
// glTF 2.0 file. A mesh that one node places (counting every path through
// the node graph) becomes one world-space mesh per primitive; a mesh placed
// two or more times becomes a group, placed by one instance per placement,
// unless `options` or an emitting material says otherwise, or the placement
// is singular (that placement is then a copy, losing its now degenerate
// triangles with a warning). Images are not read.
// Throws InputError "<file>: <JSON pointer>: <problem>" for a malformed or
// truncated file, a missing or escaping buffer URI, a buffer larger than its
// data, a view or accessor past its data, an index out of range, a non-finite
// attribute, mismatched attribute counts, a cycle in the node graph, a
// reference to a missing object, and an unsupported required extension.
GltfContent load_gltf(const std::filesystem::path& file, const GltfOptions& options = {});

// Appends `content` to `scene`: each primitive as a Triangles shape, its
// material `material_for[i]` (a scene material) where set, else glTF
// material i added to the scene once (named uniquely); each group as a
// ShapeGroup (named uniquely) of shapes marked in_group, and its instances;
// and the point lights. `material_for` is empty or has one entry per content
// material. Throws InputError if a group's shape would be a sampled light
// (`GltfOptions::is_light` disagreed with `material_for`).
void append_gltf(Scene& scene, const GltfContent& content,
                 const std::vector<std::optional<std::uint32_t>>& material_for = {});

// True if `file` names a glTF file (.gltf or .glb, any case).
bool is_gltf_file(const std::filesystem::path& file);

// A whole scene from a glTF file, for `pathlab render model.glb`: its first
// camera (else one framing the bounds), its lights (else a white
// environment of radiance 1 when nothing emits), a 640x480 film.
Scene load_gltf_scene(const std::filesystem::path& file);

}  // namespace pathlab
