// glTF 2.0 files (.gltf with embedded or external buffers, .glb) read into
// world-space triangle meshes, Disney materials, cameras and point lights.
// The mapping and what is ignored: docs/scene-format.md ("gltf" shapes).
#pragma once

#include "core/camera.h"
#include "core/material.h"
#include "core/mesh.h"
#include "core/scene.h"

#include <filesystem>
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

// One primitive of one mesh placed by one node.
struct GltfPrimitive {
  std::string description;  // "<file>: /meshes/0/primitives/1 (node 3)"
  TriangleMesh mesh;        // world space: node transforms, then the caller's transform
  std::uint32_t material;   // into GltfContent::materials
};

struct GltfCamera {
  CameraDesc desc;                     // placed by its node; yfov as fov_y
  std::optional<float> aspect_ratio;   // width / height, if the file gives it
};

struct GltfContent {
  // The file's materials in file order, then glTF's default material if a
  // primitive has none.
  std::vector<GltfMaterial> materials;
  std::vector<GltfPrimitive> primitives;
  std::vector<GltfCamera> cameras;         // perspective cameras, in node order
  std::vector<PointLight> point_lights;    // KHR_lights_punctual point lights
  std::vector<std::string> warnings;       // one line each, naming the file
};

// Reads the default scene (`scene`, else scene 0, else every root node) of a
// glTF 2.0 file and flattens it: each primitive becomes one mesh in world
// space, `transform` applied after the node transforms. Images are not read.
// Throws InputError "<file>: <JSON pointer>: <problem>" for a malformed or
// truncated file, a missing or escaping buffer URI, a buffer larger than its
// data, a view or accessor past its data, an index out of range, a non-finite
// attribute, mismatched attribute counts, a cycle in the node graph, a
// reference to a missing object, and an unsupported required extension.
GltfContent load_gltf(const std::filesystem::path& file, const mat4& transform = mat4(1.0f));

// Appends `content` to `scene`: each primitive as a Triangles shape, its
// material `material_for[i]` (a scene material) where set, else glTF
// material i added to the scene once (named uniquely); and the point lights.
// `material_for` is empty or has one entry per content material.
void append_gltf(Scene& scene, const GltfContent& content,
                 const std::vector<std::optional<std::uint32_t>>& material_for = {});

// True if `file` names a glTF file (.gltf or .glb, any case).
bool is_gltf_file(const std::filesystem::path& file);

// A whole scene from a glTF file, for `pathlab render model.glb`: its first
// camera (else one framing the bounds), its lights (else a white
// environment of radiance 1 when nothing emits), a 640x480 film.
Scene load_gltf_scene(const std::filesystem::path& file);

}  // namespace pathlab
