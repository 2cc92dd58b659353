// A glTF file as a whole scene (`pathlab render model.glb`), and glTF content
// appended to a scene (the "gltf" shape of scene_loader.cpp).
#include "core/gltf_loader.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pathlab {

namespace {

// `base`, or `base (2)`, `base (3)`, ... the first that `taken` says is free
// (the same file used twice).
template <typename Taken>
std::string unique_name(const std::string& base, Taken&& taken) {
  std::string name = base;
  for (int n = 2; taken(name); ++n) name = base + " (" + std::to_string(n) + ")";
  return name;
}

}  // namespace

void append_gltf(Scene& scene, const GltfContent& content, const std::vector<std::optional<std::uint32_t>>& material_for) {
  std::vector<std::optional<std::uint32_t>> index = material_for;
  index.resize(content.materials.size());
  // The scene material of glTF material `i`, added when first used.
  const auto scene_material = [&](std::uint32_t i) {
    std::optional<std::uint32_t>& m = index[i];
    if (!m) {
      Material added = content.materials[i].material;
      // Its textures' images into the scene's list (once per file and colour space).
      const auto image = [&](TextureRef& ref) {
        const TextureImage& im = content.images[ref.image];
        for (std::uint32_t k = 0; k < scene.textures.size(); ++k)
          if (scene.textures[k].file == im.file && scene.textures[k].colorspace == im.colorspace) {
            ref.image = k;
            return;
          }
        ref.image = static_cast<std::uint32_t>(scene.textures.size());
        scene.textures.push_back(im);
      };
      for (TexturedParam& t : added.textured) image(t.texture);
      if (added.normal_map) image(added.normal_map->texture);
      if (added.alpha_texture) image(*added.alpha_texture);
      added.name = unique_name(added.name, [&](const std::string& name) {
        return std::any_of(scene.materials.begin(), scene.materials.end(), [&](const Material& x) { return x.name == name; });
      });
      m = static_cast<std::uint32_t>(scene.materials.size());
      scene.materials.push_back(std::move(added));
    }
    return *m;
  };
  const auto add_shape = [&](const GltfPrimitive& prim, bool in_group) {
    Shape shape;
    shape.kind = Shape::Kind::Triangles;
    shape.description = prim.description;
    shape.material = scene_material(prim.material);
    shape.mesh = prim.mesh;
    shape.in_group = in_group;
    scene.shapes.push_back(std::move(shape));
    return static_cast<std::uint32_t>(scene.shapes.size() - 1);
  };
  for (const GltfPrimitive& prim : content.primitives) add_shape(prim, false);
  const auto first_group = static_cast<std::uint32_t>(scene.groups.size());
  for (const GltfGroup& group : content.groups) {
    ShapeGroup added{unique_name(group.name,
                                 [&](const std::string& name) {
                                   return std::any_of(scene.groups.begin(), scene.groups.end(),
                                                      [&](const ShapeGroup& g) { return g.name == name; });
                                 }),
                     {}};
    for (const GltfPrimitive& prim : group.primitives) {
      const std::uint32_t s = add_shape(prim, true);
      // The loader copies a mesh with a light's material instead of grouping
      // it (GltfOptions::is_light); the light sampler would miss it here.
      const Material& m = scene.materials[scene.shapes[s].material];
      if (m.emits() && m.sampled_as_light)
        throw InputError(prim.description + ": material '" + m.name +
                         "' emits, but the mesh was loaded as a group, whose emitters are not sampled as lights");
      added.shapes.push_back(s);
    }
    scene.groups.push_back(std::move(added));
  }
  for (const Instance& inst : content.instances)
    scene.instances.push_back({first_group + inst.group, inst.to_world, inst.description});
  scene.delta_lights.insert(scene.delta_lights.end(), content.delta_lights.begin(), content.delta_lights.end());
}

Scene load_gltf_scene(const std::filesystem::path& file) {
  const GltfContent content = load_gltf(file);
  Scene scene;
  scene.file = file;
  scene.name = file.stem().string();
  scene.film = FilmDesc{640, 480, FilterKind::Box};
  scene.warnings = content.warnings;
  scene.input_files = content.external_files;
  append_gltf(scene, content);
  if (!content.cameras.empty()) {
    scene.camera = content.cameras.front().desc;
    if (const auto aspect = content.cameras.front().aspect_ratio)
      scene.film.width = std::clamp(static_cast<int>(std::lround(480.0f * *aspect)), 1, 65536);
  } else {
    // Framing the bounds: the bounding sphere fits the 40 degree vertical
    // field of view, seen from the +z side and a little above.
    // A group's vertices count where its instances place them.
    vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    const auto grow = [&](const vec3& p) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    };
    for (const Shape& s : scene.shapes)
      if (!s.in_group)
        for (const vec3& p : s.mesh.positions) grow(p);
    for (const Instance& inst : scene.instances)
      for (const std::uint32_t s : scene.groups[inst.group].shapes)
        for (const vec3& p : scene.shapes[s].mesh.positions) grow(vec3(inst.to_world * vec4(p, 1.0f)));
    const bool empty = !(lo.x <= hi.x);
    const vec3 center = empty ? vec3(0.0f) : 0.5f * (lo + hi);
    float radius = empty ? 1.0f : 0.5f * glm::length(hi - lo);
    if (!(radius > 0.0f)) radius = 1.0f;
    const float distance = radius / std::sin(glm::radians(20.0f));
    scene.camera.fov_y_degrees = 40.0f;
    scene.camera.position = center + distance * glm::normalize(vec3(0.0f, 0.25f, 1.0f));
    scene.camera.look_at = center;
    scene.camera.up = vec3(0.0f, 1.0f, 0.0f);
    scene.camera.focus_distance = distance;
  }
  bool emits = !scene.delta_lights.empty();
  for (const Shape& s : scene.shapes) emits = emits || scene.materials[s.material].emits();
  if (!emits) scene.environment = Spectrum(1.0f);  // so that any model is visible
  return scene;
}

}  // namespace pathlab
