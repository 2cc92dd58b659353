#include "core/scene_loader.h"

#include "core/data_dir.h"
#include "core/environment_map.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/gltf_loader.h"
#include "core/json_document.h"
#include "core/scene_limits.h"
#include "core/scene_loader_internal.h"
#include "core/tangents.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pathlab {
namespace {

using namespace scene_detail;

CameraDesc read_camera(const Node& node) {
  node.allow_only({"position", "look_at", "up", "fov_y", "aperture_radius", "focus_distance"});
  CameraDesc c;
  c.position = node.required("position").vector3();
  if (!within_scene_range(c.position)) node.child("position").fail("the camera lies beyond the scene coordinate limit " + kRangeRule);
  c.look_at = node.required("look_at").vector3();
  if (!within_scene_range(c.look_at)) node.child("look_at").fail("look_at lies beyond the scene coordinate limit " + kRangeRule);
  if (node.has("up")) c.up = node.child("up").vector3();
  const vec3 view = c.look_at - c.position;
  if (!is_finite(view) || !std::isfinite(glm::length(view)))
    node.child("look_at").fail("look_at is too far from position (beyond the float range)");
  if (glm::length(view) <= 0.0f) node.child("look_at").fail("look_at must differ from position");
  if (!(glm::length(glm::cross(view, c.up)) > 0.0f)) {
    if (!node.has("up"))
      node.fail("the view is straight up or down, so the default up [0, 1, 0] is parallel to it; give 'up'");
    node.child("up").fail("up must not be zero or parallel to the viewing direction");
  }
  // Checked before it becomes a float: 179.9999999 is 180 as one.
  const double fov_y = node.number_or("fov_y", 40.0);
  c.fov_y_degrees = static_cast<float>(fov_y);
  if (!(fov_y > 0.0 && fov_y <= kMaxFovYDegrees) || !(c.fov_y_degrees > 0.0f))
    node.child("fov_y").fail("fov_y " + exact_number(fov_y) + " is outside (0, " + format_number(kMaxFovYDegrees) +
                             "] degrees" + (fov_y > 0.0 && c.fov_y_degrees == 0.0f ? " (it is 0 as a float)" : "") +
                             " (docs/scene-format.md: towards 180 the camera's float arithmetic fails)");
  c.aperture_radius = static_cast<float>(node.number_or("aperture_radius", 0.0));
  if (c.aperture_radius < 0.0f) node.child("aperture_radius").fail("aperture_radius must not be negative");
  if (!within_scene_range(glm::abs(c.position) + vec3(c.aperture_radius)))
    node.child("aperture_radius").fail("the aperture reaches beyond the scene coordinate limit " + kRangeRule);
  c.focus_distance = static_cast<float>(node.number_or("focus_distance", glm::length(c.look_at - c.position)));
  if (!(c.focus_distance > 0.0f)) node.child("focus_distance").fail("focus_distance must be positive");
  if (!(c.focus_distance <= kMaxSceneCoordinate)) {
    // Not given, it is the distance to look_at: that is what to change.
    if (!node.has("focus_distance"))
      node.child("look_at").fail("look_at lies " + format_number(c.focus_distance) +
                                 " from position, and focus_distance (not given) is that distance, beyond the scene "
                                 "coordinate limit " + kRangeRule + "; move look_at nearer, or give focus_distance");
    node.child("focus_distance").fail("focus_distance exceeds the scene coordinate limit " + kRangeRule);
  }
  return c;
}

FilmDesc read_film(const Node& node) {
  node.allow_only({"resolution", "filter"});
  FilmDesc f;
  if (node.has("resolution")) {
    const Node r = node.child("resolution");
    if (!r.value().is_array() || r.value().size() != 2) r.fail("expected [width, height]");
    const std::int64_t w = r.child(0).integer(), h = r.child(1).integer();
    if (w < 1 || h < 1 || w > 65536 || h > 65536) r.fail("width and height must lie in [1, 65536]");
    f.width = static_cast<int>(w);
    f.height = static_cast<int>(h);
  }
  if (node.has("filter")) {
    const std::string name = node.child("filter").string();
    if (name == "box") f.filter = FilterKind::Box;
    else if (name == "bilinear") f.filter = FilterKind::Bilinear;
    else node.child("filter").fail("unknown filter " + in_quotes(name) + " (expected box or bilinear)");
  }
  return f;
}

// A string that names one of `names`, parsed by `parse`: an unknown one
// fails naming `what` and the nearest name, or else every name ("(expected a,
// b or c)").
template <typename Parse>
auto read_choice(const Node& value, const char* what, std::span<const std::string_view> names, Parse parse) {
  const std::string name = value.string();
  const auto parsed = parse(name);
  if (!parsed) {
    std::string near = suggestion(name, names);
    if (near.empty()) {
      near = " (expected ";
      for (std::size_t i = 0; i < names.size(); ++i)
        near += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + std::string(names[i]);
      near += ")";
    }
    value.fail(std::string("unknown ") + what + " " + in_quotes(name) + near);
  }
  return *parsed;
}

RenderSettings read_render(const Node& node) {
  node.allow_only({"spp", "max_depth", "rr_depth", "strategy", "seed", "bsdf_sampling", "clamp", "min_pdf", "bvh",
                   "intersection", "texture_filter", "texture_cache_mb", "light_sampling", "light_sampler", "sampler"});
  RenderSettings r;
  if (node.has("spp")) {
    const std::int64_t spp = node.child("spp").integer();
    if (spp < 1 || spp > (1 << 24)) node.child("spp").fail("spp must lie in [1, 16777216]");
    r.spp = static_cast<int>(spp);
  }
  if (node.has("max_depth")) {
    const std::int64_t d = node.child("max_depth").integer();
    if (d < -1 || d > kMaxVerticesUncapped) node.child("max_depth").fail("max_depth must be -1 (no cap) or lie in [0, 1000]");
    r.max_depth = static_cast<int>(d);
  }
  if (node.has("rr_depth")) {
    const std::int64_t d = node.child("rr_depth").integer();
    if (d < 0 || d > kMaxVerticesUncapped) node.child("rr_depth").fail("rr_depth must lie in [0, 1000]");
    r.rr_depth = static_cast<int>(d);
  }
  if (node.has("strategy")) r.strategy = read_choice(node.child("strategy"), "strategy", strategy_names(), parse_strategy);
  if (node.has("seed")) {
    // Any 64-bit unsigned value, as --seed takes.
    const Node s = node.child("seed");
    if (s.value().is_number_unsigned()) {
      r.seed = s.value().get<std::uint64_t>();
    } else {
      const std::int64_t seed = s.integer();
      if (seed < 0) s.fail("seed must not be negative");
      r.seed = static_cast<std::uint64_t>(seed);
    }
  }
  if (node.has("bsdf_sampling")) {
    constexpr std::array<std::string_view, 2> names{"vndf", "cospow"};
    r.bsdf_sampling = read_choice(node.child("bsdf_sampling"), "BSDF sampling", names, parse_bsdf_sampling);
  }
  if (node.has("light_sampling")) {
    constexpr std::array<std::string_view, 2> names{"area", "solid_angle"};
    r.light_sampling = read_choice(node.child("light_sampling"), "light sampling", names, parse_light_sampling);
  }
  if (node.has("light_sampler")) {
    constexpr std::array<std::string_view, 2> names{"power", "bvh"};
    r.light_sampler = read_choice(node.child("light_sampler"), "light sampler", names, parse_light_sampler);
  }
  if (node.has("intersection")) {
    constexpr std::array<std::string_view, 2> names{"robust", "fast"};
    r.intersection = read_choice(node.child("intersection"), "intersection", names, parse_intersection);
  }
  if (node.has("bvh")) {
    const std::string name = node.child("bvh").string();
    if (name != "fast" && name != "compact") node.child("bvh").fail("unknown bvh " + in_quotes(name) + " (expected fast or compact)");
    r.compact_bvh = name == "compact";
  }
  if (node.has("texture_filter")) {
    const std::string name = node.child("texture_filter").string();
    const auto f = parse_texture_filter(name);
    if (!f) node.child("texture_filter").fail("unknown texture_filter " + in_quotes(name) + " (expected cone or point)");
    r.texture_filter = *f;
  }
  if (node.has("sampler")) {
    constexpr std::array<std::string_view, 2> names{"independent", "zsobol"};
    r.sampler = read_choice(node.child("sampler"), "sampler", names, parse_sampler);
  }
  if (node.has("texture_cache_mb")) {
    r.texture_cache_mb = static_cast<float>(node.child("texture_cache_mb").number());
    if (!(r.texture_cache_mb >= 1.0f && r.texture_cache_mb <= 1.0e6f))
      node.child("texture_cache_mb").fail("texture_cache_mb must lie in [1, 1e6] (megabytes), as --texture-cache-mb");
  }
  if (node.has("clamp")) {
    r.clamp = static_cast<float>(node.child("clamp").number());
    if (r.clamp < 0.0f) node.child("clamp").fail("clamp must not be negative (0 turns clamping off)");
  }
  if (node.has("min_pdf")) {
    r.min_pdf = static_cast<float>(node.child("min_pdf").number());
    if (r.min_pdf < 0.0f) node.child("min_pdf").fail("min_pdf must not be negative (0 turns it off)");
  }
  return r;
}

// A number in [lo, hi] (the message names the range).
float unit_number(const Node& node, const char* key, float fallback, float lo = 0.0f, float hi = 1.0f) {
  if (!node.has(key)) return fallback;
  const float v = static_cast<float>(node.child(key).number());
  if (!(v >= lo && v <= hi)) {
    std::ostringstream range;
    range << key << " must lie in [" << lo << ", " << hi << "], found " << v;
    node.child(key).fail(range.str());
  }
  return v;
}

// "alpha": the material's coverage (core/alpha.h), a number in [0, 1] or a
// texture (one channel, linear by default, read at the nearest texel). A
// light may not have it: the light sampler would aim at points that its
// shadow rays may pass through.
void read_alpha(const Node& node, Material& m, Scene& scene) {
  if (!node.has("alpha")) return;
  const Node a = node.child("alpha");
  const bool textured = is_texture(a);
  if (textured) m.alpha_texture = read_texture(a, scene, TextureUse::Number, TextureColorSpace::Linear);
  else if (!a.value().is_number()) a.fail("alpha must be a number in [0, 1] or a texture {\"texture\": \"file.png\", ...}, found " + describe(a.value()));
  else m.alpha = unit_number(node, "alpha", 1.0f);
  if (m.has_alpha() && m.emits() && m.sampled_as_light)
    a.fail(std::string(textured ? "an alpha texture" : "alpha") +
           " on a light: light sampling does not model coverage; give the material \"light\": false, or make it "
           "opaque");
}

// A key that belongs to another material type gets a pointed message, not
// only "unknown key": {key used, what to say}.
void reject_misplaced(const Node& node, const std::string& type,
                      std::initializer_list<std::pair<const char*, const char*>> keys) {
  for (const auto& [key, advice] : keys)
    if (node.has(key))
      node.child(key).fail((type == "emissive" ? "an " : "a ") + type + " material has no '" + key + "'; " + advice);
}

// A material's textured parameters, read before the constants are (a
// Disney material is rebuilt from its parameters, so they are applied last).
struct MaterialTextures {
  const Node& node;
  Scene& scene;
  std::vector<TexturedParam> found;
  // True (and the texture noted) if `key` holds a texture.
  bool take(const char* key, MaterialParam param, TextureUse use) {
    if (!node.has(key) || !is_texture(node.child(key))) return false;
    found.push_back({param, read_texture(node.child(key), scene,
                                         use, use == TextureUse::Color ? TextureColorSpace::Srgb : TextureColorSpace::Linear)});
    return true;
  }
};

Material read_material(const Node& node, const std::string& name, Scene& scene) {
  node.expect_object();
  const std::string type = node.required("type").string();
  Material m;
  m.name = name;
  MaterialTextures tex{node, scene, {}};
  // A colour or number, or a texture in its place (then the constant keeps its default).
  auto colour = [&](const char* key, MaterialParam param, bool max_one, Spectrum fallback) {
    if (tex.take(key, param, TextureUse::Color) || !node.has(key)) return fallback;
    return node.child(key).color(max_one);
  };
  auto number = [&](const char* key, MaterialParam param, float fallback) {
    if (tex.take(key, param, TextureUse::Number)) return fallback;
    return unit_number(node, key, fallback);
  };
  if (type == "diffuse" || type == "mirror") {
    const char* refl = type == "diffuse" ? "albedo" : "reflectance";
    reject_misplaced(node, type,
                     {{type == "diffuse" ? "reflectance" : "albedo",
                       type == "diffuse" ? "its colour is 'albedo'" : "its colour is 'reflectance'"},
                      {"radiance", "emitted light is 'emission'"}});
    node.allow_only({"type", refl, "emission", "two_sided", "light", "one_sided", "normal_map", "alpha"});
    m.type = type == "diffuse" ? MaterialType::Diffuse : MaterialType::Mirror;
    m.albedo = colour(refl, MaterialParam::Albedo, true, Spectrum(type == "diffuse" ? 0.5f : 1.0f));
    m.emission = colour("emission", MaterialParam::Emission, false, Spectrum(0.0f));
  } else if (type == "emissive") {
    reject_misplaced(node, type,
                     {{"emission", "its emitted light is 'radiance'"},
                      {"albedo", "it reflects nothing (use type diffuse with 'emission' for a surface that does both)"},
                      {"reflectance", "it reflects nothing"},
                      {"one_sided", "it reflects nothing; the sides it emits from are set by 'two_sided'"}});
    node.allow_only({"type", "radiance", "two_sided", "light", "alpha"});
    m.type = MaterialType::Emissive;
    m.albedo = Spectrum(0.0f);
    node.required("radiance");
    m.emission = colour("radiance", MaterialParam::Emission, false, Spectrum(0.0f));
  } else if (type == "disney") {
    reject_misplaced(node, type,
                     {{"albedo", "its colour is 'base_color'"},
                      {"baseColor", "parameters are snake_case: 'base_color'"},
                      {"radiance", "emitted light is 'emission'"}});
    node.allow_only({"type", "base_color", "metallic", "subsurface", "specular", "specular_tint", "roughness",
                     "anisotropic", "sheen", "sheen_tint", "clearcoat", "clearcoat_gloss", "energy_compensation", "emission",
                     "two_sided", "light", "one_sided", "normal_map", "alpha"});
    DisneyParams p;
    p.base_color = colour("base_color", MaterialParam::BaseColor, true, p.base_color);
    p.metallic = number("metallic", MaterialParam::Metallic, p.metallic);
    p.subsurface = number("subsurface", MaterialParam::Subsurface, p.subsurface);
    p.specular = number("specular", MaterialParam::Specular, p.specular);
    p.specular_tint = number("specular_tint", MaterialParam::SpecularTint, p.specular_tint);
    p.roughness = number("roughness", MaterialParam::Roughness, p.roughness);
    // 0.9 * 1 would leave an aspect of sqrt(0.1); the range stops at 1.
    p.anisotropic = number("anisotropic", MaterialParam::Anisotropic, p.anisotropic);
    p.sheen = number("sheen", MaterialParam::Sheen, p.sheen);
    p.sheen_tint = number("sheen_tint", MaterialParam::SheenTint, p.sheen_tint);
    p.clearcoat = number("clearcoat", MaterialParam::Clearcoat, p.clearcoat);
    p.clearcoat_gloss = number("clearcoat_gloss", MaterialParam::ClearcoatGloss, p.clearcoat_gloss);
    p.energy_compensation = node.boolean_or("energy_compensation", false);
    const bool textured_lobes =
        std::any_of(tex.found.begin(), tex.found.end(), [](const TexturedParam& t) { return t.param != MaterialParam::Emission; });
    if (p.energy_compensation && textured_lobes)
      node.child("energy_compensation")
          .fail("energy_compensation cannot be combined with textured parameters (its tables are built once per material)");
    const std::string keep = m.name;
    m = disney_material(p);
    m.name = keep;
    m.emission = colour("emission", MaterialParam::Emission, false, Spectrum(0.0f));
  } else if (type == "dielectric") {
    reject_misplaced(node, type,
                     {{"albedo", "its tints are 'reflectance' and 'transmittance'"},
                      {"eta", "the index of refraction is 'ior'"},
                      {"emission", "glass does not emit"},
                      {"one_sided", "glass has an inside and an outside: both sides scatter"}});
    node.allow_only({"type", "ior", "reflectance", "transmittance", "normal_map", "alpha"});
    DielectricParams p;
    p.ior = unit_number(node, "ior", p.ior, 1.0f, 10.0f);
    p.reflectance = colour("reflectance", MaterialParam::GlassReflectance, true, p.reflectance);
    p.transmittance = colour("transmittance", MaterialParam::GlassTransmittance, true, p.transmittance);
    const std::string keep = m.name;
    m = dielectric_material(p);
    m.name = keep;
    m.albedo = Spectrum(0.0f);
  } else {
    const std::array<std::string_view, 5> types{"diffuse", "mirror", "emissive", "disney", "dielectric"};
    const std::string near = suggestion(type, types);
    node.child("type").fail("unknown material type " + in_quotes(type) +
                            (near.empty() ? " (expected diffuse, mirror, emissive, disney or dielectric)" : near));
  }
  for (const TexturedParam& t : tex.found) m.set_texture(t.param, t.texture);
  if (node.has("normal_map")) {
    const Node nm = node.child("normal_map");
    if (!is_texture(nm)) nm.fail("expected a texture: {\"texture\": \"file.png\", ...}, found " + describe(nm.value()));
    NormalMap map{read_texture(nm, scene, TextureUse::NormalMap, TextureColorSpace::Linear), 1.0f};
    map.scale = map.texture.scale.x;
    map.texture.scale = Spectrum(1.0f);
    m.normal_map = map;
  }
  m.two_sided_emission = node.boolean_or("two_sided", false);
  m.sampled_as_light = node.boolean_or("light", true);
  m.one_sided = node.boolean_or("one_sided", false);
  read_alpha(node, m, scene);
  return m;
}

}  // namespace

mat4 scene_detail::read_transform(const Node& node) {
  if (node.value().is_array()) {
    mat4 m(1.0f);
    for (std::size_t i = 0; i < node.value().size(); ++i) m = read_transform(node.child(i)) * m;
    return m;
  }
  if (!node.value().is_object())
    node.fail("expected a transform step such as {\"translate\": [x, y, z]}, or a list of them; found " +
              describe(node.value()));
  if (node.value().size() != 1) node.fail("a transform step has exactly one of translate, scale, rotate, matrix");
  if (node.has("translate")) return glm::translate(mat4(1.0f), node.child("translate").vector3());
  if (node.has("scale")) {
    const Node s = node.child("scale");
    const vec3 v = s.value().is_number() ? vec3(static_cast<float>(s.number())) : s.vector3();
    if (v.x == 0.0f || v.y == 0.0f || v.z == 0.0f) s.fail("scale must not be zero");
    return glm::scale(mat4(1.0f), v);
  }
  if (node.has("rotate")) {
    const Node r = node.child("rotate");
    r.allow_only({"axis", "angle"});
    const vec3 axis = r.required("axis").vector3();
    if (glm::length(axis) <= 0.0f) r.child("axis").fail("axis must not be zero");
    return glm::rotate(mat4(1.0f), glm::radians(static_cast<float>(r.required("angle").number())), glm::normalize(axis));
  }
  if (node.has("matrix")) {
    const Node mn = node.child("matrix");
    if (!mn.value().is_array() || mn.value().size() != 16) mn.fail("expected 16 numbers, row by row");
    mat4 m;
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) m[col][row] = static_cast<float>(mn.child(row * 4 + col).number());
    if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
      mn.fail("the last row must be [0, 0, 0, 1] (no projective transforms)");
    if (glm::determinant(mat3(m)) == 0.0f) mn.fail("matrix is singular");
    return m;
  }
  const auto key = node.value().begin().key();
  const std::array<std::string_view, 4> steps{"translate", "scale", "rotate", "matrix"};
  const std::string near = suggestion(key, steps);
  node.child(key).fail("unknown transform step " + in_quotes(key) +
                       (near.empty() ? " (expected translate, scale, rotate or matrix)" : near));
}

namespace {

void read_gltf_shape(const Node& node, Scene& scene, const std::filesystem::path& folder,
                     const std::map<std::string, std::uint32_t>& materials, bool in_group);

// "groups": {"name": [shape, ...], ...}: shapes in the group's own space,
// appended to scene.shapes and marked in_group.
void read_groups(const Node& node, Scene& scene, const std::filesystem::path& folder,
                 const std::map<std::string, std::uint32_t>& materials) {
  node.expect_object();
  for (const auto& [name, unused] : node.value().items()) {
    const Node list = node.child(name);
    if (!list.value().is_array() || list.value().empty()) list.fail("expected a non-empty array of shapes");
    // A glTF file in "shapes" may have added groups already (its meshes that
    // several nodes place).
    if (std::any_of(scene.groups.begin(), scene.groups.end(), [&name = name](const ShapeGroup& g) { return g.name == name; }))
      list.fail("the group name " + in_quotes(name) + " is taken by a glTF mesh's group; choose another");
    ShapeGroup group{name, {}};
    for (std::size_t i = 0; i < list.value().size(); ++i) {
      const Node item = list.child(i);
      if (item.value().is_object() && item.has("type") && item.child("type").value() == "instance")
        item.child("type").fail("a group holds shapes, not instances (instances of instances are not supported)");
      const std::size_t first = scene.shapes.size(), delta_lights = scene.delta_lights.size();
      if (item.value().is_object() && item.has("type") && item.child("type").value() == "gltf")
        read_gltf_shape(item, scene, folder, materials, true);
      else
        read_shape(item, scene, folder, materials, "groups/" + name + "[" + std::to_string(i) + "]");
      if (scene.delta_lights.size() != delta_lights)
        item.child("file").fail("the glTF file has lights (KHR_lights_punctual), which instances do not place; put it in 'shapes'");
      for (std::size_t k = first; k < scene.shapes.size(); ++k) {
        Shape& shape = scene.shapes[k];
        const Material& m = scene.materials[shape.material];
        // As in pbrt-v4: an instanced emitter would need a light per placement.
        if (m.emits() && m.sampled_as_light)
          (item.has("material") ? item.child("material") : item)
              .fail("material " + in_quotes(m.name) +
                    " emits: emitters in a group are not sampled as lights; place the shape in 'shapes', or give "
                    "the material \"light\": false");
        shape.in_group = true;
        group.shapes.push_back(static_cast<std::uint32_t>(k));
      }
    }
    scene.groups.push_back(std::move(group));
  }
}

// "instances": [{"group": name, "transform": T} or {"group": name,
// "transforms": [T, ...]}, ...].
void read_instances(const Node& node, Scene* scene) {
  if (!node.value().is_array()) node.fail("expected an array of instances");
  for (std::size_t i = 0; i < node.value().size(); ++i) {
    const Node item = node.child(i);
    item.expect_object();
    item.allow_only({"group", "transform", "transforms"});
    const Node group = item.required("group");
    const std::string name = group.string();
    const auto found = std::find_if(scene->groups.begin(), scene->groups.end(),
                                    [&name = name](const ShapeGroup& g) { return g.name == name; });
    if (found == scene->groups.end()) {
      std::vector<std::string_view> names;
      for (const ShapeGroup& g : scene->groups) names.push_back(g.name);
      group.fail("no group named " + in_quotes(name) +
                 (names.empty() ? std::string(" (the scene has no \"groups\")") : suggestion(name, names)));
    }
    const auto index = static_cast<std::uint32_t>(found - scene->groups.begin());
    const std::string label = "instances[" + std::to_string(i) + "]";
    // The group's bounding box, whose placed corners must stay finite.
    Box box;
    for (const std::uint32_t id : found->shapes) box.add(bounds(scene->shapes[id]));
    // Every placement must be invertible (Embree and the normals need its
    // inverse) and keep the group within the float range.
    const auto place = [&](const Node& where, const std::string& description) {
      const mat4 xf = read_transform(where);
      if (!invertible_placement(xf))
        where.fail("the transform is singular or not finite (determinant " +
                   format_number(glm::determinant(mat3(xf))) + ")");
      if (!placed_in_range(box, xf)) where.fail("the transform moves the group beyond the scene coordinate limit " + kRangeRule);
      scene->instances.push_back({index, xf, description});
    };
    if (item.has("transform") == item.has("transforms"))
      item.fail("an instance needs exactly one of 'transform' (one placement) and 'transforms' (a list)");
    if (item.has("transform")) {
      place(item.child("transform"), label + " (" + name + ")");
    } else {
      const Node list = item.child("transforms");
      if (!list.value().is_array() || list.value().empty()) list.fail("expected a non-empty array of transforms");
      for (std::size_t k = 0; k < list.value().size(); ++k)
        place(list.child(k), label + "[" + std::to_string(k) + "] (" + name + ")");
    }
  }
}

// A "gltf" shape: every primitive of the file's default scene, with the
// file's materials unless "material" (all) or "materials" (by glTF name)
// says otherwise, and the file's point lights. A mesh several nodes place
// becomes a group and instances, unless the file is itself a member of a
// group (`in_group`): Embree's instancing is one level deep.
void read_gltf_shape(const Node& node, Scene& scene, const std::filesystem::path& folder,
                     const std::map<std::string, std::uint32_t>& materials, bool in_group) {
  node.allow_only({"type", "file", "transform", "material", "materials"});
  if (node.has("material") && node.has("materials"))
    node.child("materials").fail("give either 'material' (for every primitive) or 'materials' (by glTF name)");
  const Node file = node.required("file");
  if (file.string().empty()) file.fail("the glTF file name is empty");
  const std::filesystem::path path = resolve_scene_path(folder, file.string());
  if (names_data_file(file.string()) && !std::filesystem::exists(path))
    file.fail(file.string() + ": " + path.string() + " does not exist; " + data_directory_hint());
  require_regular(file, path, "glTF file");
  // The overrides are read before the file, so that the loader knows which
  // materials will be lights (meshes with one are never grouped).
  std::optional<std::uint32_t> all;
  std::map<std::string, std::uint32_t> by_name;
  if (node.has("material")) {
    all = material_index(node.child("material"), materials);
  } else if (node.has("materials")) {
    const Node map = node.child("materials");
    map.expect_object();
    for (const auto& [gltf_name, unused] : map.value().items())
      by_name[gltf_name] = material_index(map.child(gltf_name), materials);
  }
  const auto override_of = [&](const GltfMaterial& m) -> std::optional<std::uint32_t> {
    if (all) return all;
    const auto it = by_name.find(m.gltf_name);
    return it == by_name.end() ? std::nullopt : std::optional<std::uint32_t>(it->second);
  };
  GltfOptions options;
  options.transform = node.has("transform") ? read_transform(node.child("transform")) : mat4(1.0f);
  options.flatten = in_group;
  options.is_light = [&](const GltfMaterial& m) {
    const std::optional<std::uint32_t> o = override_of(m);
    const Material& used = o ? scene.materials[*o] : m.material;
    return used.emits() && used.sampled_as_light;
  };
  GltfContent content;
  try {
    content = load_gltf(path, options);
    scene.input_files.push_back(path);
    scene.input_files.insert(scene.input_files.end(), content.external_files.begin(), content.external_files.end());
  } catch (const InputError& e) {
    file.fail(e.what());
  }
  std::vector<std::optional<std::uint32_t>> material_for;
  std::vector<std::string_view> gltf_names;
  for (const GltfMaterial& m : content.materials) {
    material_for.push_back(override_of(m));
    if (!m.gltf_name.empty()) gltf_names.push_back(m.gltf_name);
  }
  for (const auto& [gltf_name, unused] : by_name)
    if (std::none_of(content.materials.begin(), content.materials.end(),
                     [&gltf_name = gltf_name](const GltfMaterial& m) { return m.gltf_name == gltf_name; }))
      node.child("materials").child(gltf_name).fail(path.filename().string() + " has no material named " +
                                                    in_quotes(gltf_name) + suggestion(gltf_name, gltf_names));
  for (const std::string& w : content.warnings) scene.warnings.push_back(file.message(w));
  const std::size_t before = scene.shapes.size();
  try {
    append_gltf(scene, content, material_for);
  } catch (const InputError& e) {
    file.fail(e.what());
  }
  if (scene.shapes.size() == before) file.fail(path.string() + ": the file's scene holds no triangles");
  for (std::size_t k = before; k < scene.shapes.size(); ++k) {
    const Material& m = scene.materials[scene.shapes[k].material];
    if (m.has_alpha() && m.emits() && m.sampled_as_light)
      file.fail(scene.shapes[k].description + ": material " + in_quotes(m.name) +
                " has alpha (alphaMode MASK or BLEND) on a light: light sampling does not model coverage; override "
                "it with a scene material in 'materials'");
  }
}

// {"type": "environment", "file": ..., "scale": s, "transform": rotations,
//  "clamp_negative": bool}.
std::shared_ptr<const EnvironmentMap> read_environment_map(const Node& l, const std::filesystem::path& folder,
                                                           Scene* scene) {
  const Node file = l.required("file");
  if (file.string().empty()) file.fail("the image file name is empty");
  const std::filesystem::path path = resolve_scene_path(folder, file.string());
  if (names_data_file(file.string()) && !std::filesystem::exists(path))
    file.fail(file.string() + ": " + path.string() + " does not exist; " + data_directory_hint());
  require_regular(file, path, "environment image");
  float scale = 1.0f;
  if (l.has("scale")) {
    scale = static_cast<float>(l.child("scale").number());
    if (!(scale >= 0.0f)) l.child("scale").fail("scale must be >= 0, found " + format_number(scale));
  }
  // Directions only: a rotation (a mirror too) keeps solid angles, so the
  // map's density stays a density; a scale or shear would not, and a
  // translation means nothing at infinity.
  mat3 to_world(1.0f);
  if (l.has("transform")) {
    const Node t = l.child("transform");
    const mat4 m = read_transform(t);
    to_world = mat3(m);
    const mat3 gram = glm::transpose(to_world) * to_world;
    float off = 0.0f;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) off = std::max(off, std::abs(gram[i][j] - (i == j ? 1.0f : 0.0f)));
    if (!(off <= 1e-4f)) t.fail("an environment's transform may only rotate (no scale or shear)");
    if (m[3][0] != 0.0f || m[3][1] != 0.0f || m[3][2] != 0.0f)
      t.fail("an environment's transform may only rotate (a translation means nothing at infinity)");
  }
  const bool clamp_negative = l.boolean_or("clamp_negative", true);
  std::string warning;
  try {
    auto map = std::make_shared<const EnvironmentMap>(load_environment_map(path, scale, to_world, clamp_negative, &warning));
    if (!warning.empty()) scene->warnings.push_back(file.message(warning));
    scene->input_files.push_back(path);
    return map;
  } catch (const InputError& e) {
    file.fail(e.what());
  }
}

void read_lights(const Node& node, Scene* scene, const std::filesystem::path& folder) {
  if (!node.value().is_array()) node.fail("expected an array of lights");
  for (std::size_t i = 0; i < node.value().size(); ++i) {
    const Node l = node.child(i);
    l.expect_object();
    const std::string type = l.required("type").string();
    if (type == "point") {
      l.allow_only({"type", "position", "intensity"});
      scene->delta_lights.push_back({l.required("position").vector3(), l.required("intensity").color(false)});
      if (!within_scene_range(scene->delta_lights.back().position))
        l.child("position").fail("the light lies beyond the scene coordinate limit " + kRangeRule);
    } else if (type == "spot") {
      l.allow_only({"type", "position", "direction", "look_at", "intensity", "cone_angle", "falloff_start"});
      DeltaLight spot;
      spot.kind = DeltaLight::Kind::Spot;
      spot.position = l.required("position").vector3();
      if (!within_scene_range(spot.position))
        l.child("position").fail("the light lies beyond the scene coordinate limit " + kRangeRule);
      spot.intensity = l.required("intensity").color(false);
      if (l.has("direction") == l.has("look_at")) l.fail("a spot light needs exactly one of 'direction' and 'look_at'");
      const Node aim = l.has("direction") ? l.child("direction") : l.child("look_at");
      const vec3 axis = l.has("direction") ? aim.vector3() : aim.vector3() - spot.position;
      if (!(glm::length(axis) > 0.0f) || !is_finite(axis))
        aim.fail(l.has("direction") ? "direction must not be zero" : "look_at must differ from position");
      spot.direction = glm::normalize(axis);
      const float outer = static_cast<float>(l.required("cone_angle").number());
      if (!(outer > 0.0f && outer <= 90.0f)) {
        std::ostringstream m;
        m << "cone_angle (the half-angle of the cone, degrees) must lie in (0, 90], found " << outer;
        l.child("cone_angle").fail(m.str());
      }
      const float inner = unit_number(l, "falloff_start", outer, 0.0f, outer);
      spot.cos_outer = std::cos(glm::radians(outer));
      spot.cos_inner = std::cos(glm::radians(inner));
      scene->delta_lights.push_back(spot);
    } else if (type == "directional") {
      l.allow_only({"type", "direction", "irradiance", "angular_diameter"});
      DeltaLight sun;
      sun.kind = DeltaLight::Kind::Directional;
      sun.intensity = l.required("irradiance").color(false);
      const vec3 d = l.required("direction").vector3();
      if (!(glm::length(d) > 0.0f) || !is_finite(d)) l.child("direction").fail("direction must not be zero");
      sun.direction = glm::normalize(d);
      // A sun disk (0.53 for the sun seen from the earth); 0 keeps a delta light.
      sun.angular_radius = glm::radians(0.5f * unit_number(l, "angular_diameter", 0.0f, 0.0f, 90.0f));
      if (sun.angular_radius > 0.0f) {
        // The disk's radiance E / (pi sin^2 alpha) and its cone's density
        // 1 / (2 pi (1 - cos alpha)) must be floats (LightSampler keeps them
        // so): a disk far smaller than any sun would be black, every sample
        // of it counted bad.
        const double alpha = sun.angular_radius, sin2 = std::sin(alpha) * std::sin(alpha);
        const double one_minus_cos = 2.0 * std::sin(0.5 * alpha) * std::sin(0.5 * alpha);
        const double radiance = double(max_component(sun.intensity)) / (kPi * sin2);
        if (!(radiance <= double(FLT_MAX)) || !(1.0 / (2.0 * kPi * one_minus_cos) <= double(FLT_MAX)))
          l.child("angular_diameter")
              .fail("a sun disk this small has a radiance (" + format_number(radiance) +
                    " from the irradiance over pi sin^2 of its radius) or a density beyond the float range; give 0 "
                    "for a delta directional light");
      }
      scene->delta_lights.push_back(sun);
    } else if (type == "environment") {
      l.allow_only({"type", "radiance", "file", "scale", "transform", "clamp_negative"});
      if (scene->environment || scene->environment_map) l.fail("only one environment light is allowed");
      if (l.has("radiance") == l.has("file"))
        l.fail("an environment needs exactly one of 'radiance' (uniform) and 'file' (a lat-long image)");
      if (l.has("radiance")) {
        for (const char* key : {"scale", "transform", "clamp_negative"})
          if (l.has(key)) l.child(key).fail(std::string(key) + " applies to an environment image ('file') only");
        scene->environment = l.required("radiance").color(false);
      } else {
        scene->environment_map = read_environment_map(l, folder, scene);
      }
    } else {
      const std::array<std::string_view, 4> types{"point", "spot", "directional", "environment"};
      const std::string near = suggestion(type, types);
      l.child("type").fail("unknown light type " + in_quotes(type) +
                           (near.empty() ? " (expected point, spot, directional or environment)" : near));
    }
  }
}

Scene read_scene(const JsonDocument& doc) {
  const Node root(doc, Pointer());
  root.expect_object();
  // The version first: a file of another version may well have other keys.
  if (!root.has("pathlab_scene"))
    root.fail("missing 'pathlab_scene' (the format version; this pathlab reads version " +
              std::to_string(kSceneFormatVersion) + ")");
  const Node version = root.child("pathlab_scene");
  if (const std::int64_t v = version.integer(); v != kSceneFormatVersion)
    version.fail("unsupported scene format version " + std::to_string(v) + " (this pathlab reads version " +
                 std::to_string(kSceneFormatVersion) + ")");
  root.allow_only({"pathlab_scene", "camera", "film", "render", "materials", "shapes", "groups", "instances", "lights",
                   "analytic"});
  Scene scene;
  scene.file = doc.file();
  scene.name = doc.file().stem().string();
  if (root.has("analytic")) {
    scene.analytic = root.child("analytic").string();
    if (scene.analytic.empty()) root.child("analytic").fail("expected the name of an analytic model");
  }
  scene.camera = read_camera(root.required("camera"));
  if (root.has("film")) scene.film = read_film(root.child("film"));
  if (root.has("render")) scene.render = read_render(root.child("render"));

  std::map<std::string, std::uint32_t> materials;
  const Node mats = root.required("materials");
  mats.expect_object();
  for (const auto& [name, unused] : mats.value().items()) {
    materials[name] = static_cast<std::uint32_t>(scene.materials.size());
    scene.materials.push_back(read_material(mats.child(name), name, scene));
  }

  const Node shapes = root.required("shapes");
  if (!shapes.value().is_array()) shapes.fail("expected an array of shapes");
  const std::filesystem::path folder = doc.file().parent_path();
  for (std::size_t i = 0; i < shapes.value().size(); ++i) {
    const Node shape = shapes.child(i);
    if (shape.value().is_object() && shape.has("type") && shape.child("type").value() == "gltf")
      read_gltf_shape(shape, scene, folder, materials, false);
    else
      read_shape(shape, scene, folder, materials, "shapes[" + std::to_string(i) + "]");
  }
  if (root.has("groups")) read_groups(root.child("groups"), scene, folder, materials);
  if (root.has("instances")) read_instances(root.child("instances"), &scene);
  for (std::uint32_t g = 0; g < scene.groups.size(); ++g)
    if (std::none_of(scene.instances.begin(), scene.instances.end(), [g](const Instance& i) { return i.group == g; }))
      scene.warnings.push_back(root.child("groups").child(scene.groups[g].name).message(
          "group " + in_quotes(scene.groups[g].name) + " is never placed (no instance names it)"));

  if (root.has("lights")) read_lights(root.child("lights"), &scene, folder);
  // Tangents for the meshes whose material needs them (core/tangents.h).
  add_needed_tangents(&scene);

  bool any_light = (scene.environment && !is_black(*scene.environment)) ||
                   (scene.environment_map && !scene.environment_map->is_black());
  for (const DeltaLight& p : scene.delta_lights) any_light = any_light || !is_black(p.intensity);
  for (const Shape& s : scene.shapes) any_light = any_light || scene.materials[s.material].emits();
  if (!any_light) scene.warnings.push_back(doc.file().string() + ": the scene has no light; it will render black");
  return scene;
}

}  // namespace

Scene parse_scene(std::string_view text, const std::filesystem::path& file) {
  return read_scene(JsonDocument::parse(text, file));
}

Scene load_scene(const std::filesystem::path& file) {
  if (is_gltf_file(file)) return load_gltf_scene(file);
  return read_scene(JsonDocument::load(file));
}

Scene builtin_cornell_box() {
  Scene scene = parse_scene(builtin_cornell_box_text(), "<built-in cornell-box>");
  scene.file.clear();
  scene.name = "cornell";
  return scene;
}

}  // namespace pathlab
