// A glTF file as a whole scene (`pathlab render model.glb`), and glTF content
// appended to a scene (the "gltf" shape of scene_loader.cpp).
#include "core/gltf_loader.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pathlab {

void append_gltf(Scene& scene, const GltfContent& content, const std::vector<std::optional<std::uint32_t>>& material_for) {
  std::vector<std::optional<std::uint32_t>> index = material_for;
  index.resize(content.materials.size());
  for (const GltfPrimitive& prim : content.primitives) {
    std::optional<std::uint32_t>& m = index[prim.material];
    if (!m) {
      // Added when first used; a name already in the scene (the same file
      // twice) gets a suffix.
      Material added = content.materials[prim.material].material;
      const std::string base = added.name;
      for (int n = 2; std::any_of(scene.materials.begin(), scene.materials.end(),
                                  [&](const Material& x) { return x.name == added.name; });
           ++n)
        added.name = base + " (" + std::to_string(n) + ")";
      m = static_cast<std::uint32_t>(scene.materials.size());
      scene.materials.push_back(std::move(added));
    }
    Shape shape;
    shape.kind = Shape::Kind::Triangles;
    shape.description = prim.description;
    shape.material = *m;
    shape.mesh = prim.mesh;
    scene.shapes.push_back(std::move(shape));
  }
  scene.point_lights.insert(scene.point_lights.end(), content.point_lights.begin(), content.point_lights.end());
}

Scene load_gltf_scene(const std::filesystem::path& file) {
  const GltfContent content = load_gltf(file);
  Scene scene;
  scene.file = file;
  scene.name = file.stem().string();
  scene.film = FilmDesc{640, 480, FilterKind::Box};
  scene.warnings = content.warnings;
  append_gltf(scene, content);
  if (!content.cameras.empty()) {
    scene.camera = content.cameras.front().desc;
    if (const auto aspect = content.cameras.front().aspect_ratio)
      scene.film.width = std::clamp(static_cast<int>(std::lround(480.0f * *aspect)), 1, 65536);
  } else {
    // Framing the bounds: the bounding sphere fits the 40 degree vertical
    // field of view, seen from the +z side and a little above.
    vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const Shape& s : scene.shapes)
      for (const vec3& p : s.mesh.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
    const vec3 center = scene.shapes.empty() ? vec3(0.0f) : 0.5f * (lo + hi);
    float radius = scene.shapes.empty() ? 1.0f : 0.5f * glm::length(hi - lo);
    if (!(radius > 0.0f)) radius = 1.0f;
    const float distance = radius / std::sin(glm::radians(20.0f));
    scene.camera.fov_y_degrees = 40.0f;
    scene.camera.position = center + distance * glm::normalize(vec3(0.0f, 0.25f, 1.0f));
    scene.camera.look_at = center;
    scene.camera.up = vec3(0.0f, 1.0f, 0.0f);
    scene.camera.focus_distance = distance;
  }
  bool emits = !scene.point_lights.empty();
  for (const Shape& s : scene.shapes) emits = emits || scene.materials[s.material].emits();
  if (!emits) scene.environment = Spectrum(1.0f);  // so that any model is visible
  return scene;
}

}  // namespace pathlab
