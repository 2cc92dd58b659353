#include "core/compiled_scene.h"

#include "core/error.h"
#include "core/geometry.h"
#include "core/parallel.h"
#include "core/scene_limits.h"
#include "core/simd/width1.h"

#include <algorithm>
#include <cmath>

namespace pathlab {
namespace {

// The texture coordinates at a hit: a mesh's blended by TriangleMesh::uv_at
// where it has them, else the barycentrics (a sphere's: its hit's).
vec2 hit_uv(const Shape& shape, const RayHit& hit) {
  return shape.kind == Shape::Kind::Triangles && shape.mesh.has_uvs() ? shape.mesh.uv_at(hit.prim, hit.uv) : hit.uv;
}

// An instance's placement as the generic texture inputs and shading frame
// read it (core/simd/texture_inputs-inl.h, shading_frame-inl.h): its
// columns and whether it mirrors, at width 1 (null in world space, where
// none is asked for).
// Asked off the mask (m false), each gives what a masked gather gives: 0.
struct PlacementColumns {
  const CompiledScene::Placement* place;
  void linear(lane1::M m, width1::F3 (&c)[3]) const {
    for (int k = 0; k < 3; ++k) c[k] = width1::lanes(m.raw ? vec3(place->to_world[k]) : vec3(0.0f));
  }
  void to_local(lane1::M m, width1::F3 (&c)[4]) const {
    for (int k = 0; k < 4; ++k) c[k] = width1::lanes(m.raw ? vec3(place->to_local[k]) : vec3(0.0f));
  }
  void to_world(lane1::M m, width1::F3 (&c)[4]) const {
    for (int k = 0; k < 4; ++k) c[k] = width1::lanes(m.raw ? vec3(place->to_world[k]) : vec3(0.0f));
  }
  void to_normal(lane1::M m, width1::F3 (&c)[3]) const {
    for (int k = 0; k < 3; ++k) c[k] = width1::lanes(m.raw ? place->to_normal[k] : vec3(0.0f));
  }
  lane1::M mirrors(lane1::M m) const { return {m.raw && place->mirrors}; }
};

// A hit as the generic surface_point reads it (core/simd/lanes-inl.h), at
// width 1: the traced ray, the hit's triangle (`triangles`: its shape's
// first in CompiledScene's table) or sphere, and the instance's placement.
// Asked only where the hit needs them (the mask true).
struct HitColumns : PlacementColumns {
  const Ray& traced;
  const RayHit& hit;
  const Shape& shape;
  const Triangle* triangles;
  void ray(lane1::M, width1::F3& o, width1::F3& dir, width1::F& t) const {
    o = width1::lanes(traced.origin);
    dir = width1::lanes(traced.dir);
    t = width1::F{hit.t};
  }
  void triangle(lane1::M, width1::F3& p0, width1::F3& p1, width1::F3& p2, width1::F3& n) const {
    const Triangle& tri = triangles[hit.prim];
    p0 = width1::lanes(tri.p0);
    p1 = width1::lanes(tri.p1);
    p2 = width1::lanes(tri.p2);
    n = width1::lanes(tri.n);
  }
  lane1::M sphere(lane1::M, width1::F3& center, width1::F& radius) const {
    center = width1::lanes(shape.center);
    radius = width1::F{shape.radius};
    return {shape.flip_normals};
  }
};

// The loaders check what a file says; a scene built in code gets the same
// guarantees here: groups name existing shapes marked in_group, instances
// existing groups, and every placement is finite and invertible.
void check_instancing(const Scene& scene) {
  for (const ShapeGroup& group : scene.groups)
    for (const std::uint32_t s : group.shapes)
      if (s >= scene.shapes.size() || !scene.shapes[s].in_group)
        throw InputError("group '" + group.name + "': shape " + std::to_string(s) +
                         (s >= scene.shapes.size() ? " does not exist" : " is not marked in_group"));
  for (const Instance& inst : scene.instances) {
    if (inst.group >= scene.groups.size())
      throw InputError(inst.description + ": no group " + std::to_string(inst.group));
    if (!invertible_placement(inst.to_world))
      throw InputError(inst.description + ": the placement is singular or not finite");
  }
}

// The loaders refuse alpha on a light; a scene built in code gets the same
// check: the light sampler would aim at points that rays may pass through.
void check_alpha(const Scene& scene) {
  for (const Shape& shape : scene.shapes) {
    const Material& m = scene.materials[shape.material];
    if (m.has_alpha() && m.emits() && m.sampled_as_light)
      throw InputError(shape.description + ": material '" + m.name +
                       "' has alpha on a light (light sampling does not model coverage; give it \"light\": false)");
  }
}

}  // namespace

CompiledScene::CompiledScene(Scene scene)
    : scene_(std::move(scene)), camera_(scene_.camera, scene_.film.width, scene_.film.height) {
  check_instancing(scene_);
  check_scene_range(scene_);  // no ray Embree would abort on (core/geometry.h)
  check_alpha(scene_);
  configure_shading(scene_);  // materials: shading path for the scene's lobes, sampling flavour, min pdf
  Box box;
  for (const Shape& shape : scene_.shapes) {
    if (!shape.in_group) box.add(bounds(shape));
    lobes_ |= scene_.materials[shape.material].lobes();
    has_alpha_ = has_alpha_ || scene_.materials[shape.material].has_alpha();
  }
  // An instance's bounds: the corners of its group's box, placed.
  std::vector<Box> group_boxes;
  for (const ShapeGroup& group : scene_.groups) {
    Box& g = group_boxes.emplace_back();
    for (const std::uint32_t s : group.shapes) g.add(bounds(scene_.shapes[s]));
  }
  for (const Instance& inst : scene_.instances) {
    box.add(placed(group_boxes[inst.group], inst.to_world));
    placements_.push_back({inst.to_world, glm::inverse(inst.to_world), glm::transpose(glm::inverse(mat3(inst.to_world))),
                           glm::determinant(mat3(inst.to_world)) < 0.0f});
  }
  if (!box.empty()) {
    bounds_center_ = 0.5f * (box.lo + box.hi);
    bounds_radius_ = std::max(0.5f * glm::length(box.hi - box.lo), 1e-3f);
  }
  // Room for Embree's 16-byte loads past the last vertex, so that it reads
  // the positions in place instead of copying them (EmbreeAccel).
  // (Written once, as zeros, so that nothing reads uninitialised bytes.)
  for (Shape& shape : scene_.shapes) {
    std::vector<vec3>& p = shape.mesh.positions;
    if (p.empty()) continue;
    p.reserve(p.size() + 1);
    p.emplace_back(0.0f);
    p.pop_back();
  }
  // The images first: alpha textures are read during traversal.
  if (!scene_.textures.empty()) textures_ = std::make_unique<Textures>(scene_.textures, scene_.render.texture_cache_mb);
  accel_ = std::make_unique<EmbreeAccel>(scene_.shapes, scene_.groups, scene_.instances,
                                         BvhOptions{scene_.render.compact_bvh, scene_.render.intersection},
                                         scene_.materials, textures_.get());
  first_triangle_.resize(scene_.shapes.size() + 1, 0);
  for (std::size_t i = 0; i < scene_.shapes.size(); ++i) {
    const Shape& shape = scene_.shapes[i];
    first_triangle_[i + 1] =
        first_triangle_[i] + (shape.kind == Shape::Kind::Triangles ? shape.mesh.triangles.size() : std::size_t{0});
  }
  triangles_.resize(first_triangle_.back());
  for (std::size_t i = 0; i < scene_.shapes.size(); ++i) {
    const Shape& shape = scene_.shapes[i];
    Triangle* out = triangles_.data() + first_triangle_[i];
    parallel_for(0, first_triangle_[i + 1] - first_triangle_[i], 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) out[t] = make_triangle(shape, static_cast<std::uint32_t>(t));
    });
  }
  lights_ = std::make_unique<LightSampler>(scene_, bounds_radius_, textures_.get());
}

bool CompiledScene::intersect(const Ray& ray, Surfel* s, const RayCone& cone, SurfaceParams* params) const {
  RayHit hit;
  if (!accel_->intersect(ray, &hit)) return false;
  resolve(ray, hit, s, cone, params);
  return true;
}

void CompiledScene::resolve(const Ray& ray, const RayHit& hit, Surfel* s, const RayCone& cone,
                            SurfaceParams* params) const {
  // The point, its error bound and the front normal in world space by the
  // generic surface_point at width 1, which the wavefront's lanes run too:
  // an instance's hit was found in its group's space (at the same distance
  // along the world ray), resolved there and placed.
  using namespace width1;
  const Shape& shape = scene_.shapes[hit.shape];
  const bool sphere = shape.kind == Shape::Kind::Sphere;
  const bool placed = hit.instance != kNoInstance;
  // The vertex normals shading_frame blends, asked for first: on a large
  // mesh each is a cache miss, which then overlaps the triangle's below
  // (issued after surface_point, the reference's resolve took 1.05x the
  // time on dragons-100).
  if (!sphere && shape.mesh.has_normals()) {
    const glm::uvec3 v = shape.mesh.triangles[hit.prim];
    for (int k = 0; k < 3; ++k) __builtin_prefetch(&shape.mesh.normals[v[k]]);
  }
  const HitColumns at{
      {placed ? &placements_[hit.instance] : nullptr}, ray, hit, shape, triangles_.data() + first_triangle_[hit.shape]};
  F3 p, error, n, to_normal[3];
  generic::surface_point(kScalar, lane1::M{!sphere}, lane1::M{sphere}, lane1::M{placed}, F{hit.uv.x}, F{hit.uv.y}, at,
                         p, error, n, to_normal);
  s->p = scalars(p);
  s->p_error = scalars(error);
  s->n = scalars(n);
  s->uv = hit_uv(shape, hit);
  shading_frame(shape, hit, s);
  if (textures_ && s->material->reads_textures_at_hits()) read_textures(shape, ray, hit, cone, params, s);
}

void CompiledScene::resolve_shading(const RayHit& hit, Surfel* s) const {
  const Shape& shape = scene_.shapes[hit.shape];
  s->uv = hit_uv(shape, hit);
  shading_frame(shape, hit, s);
}

void CompiledScene::shading_frame(const Shape& shape, const RayHit& hit, Surfel* s) const {
  // The generic steps at width 1 (core/simd/shading_frame-inl.h's
  // surface_frame), which the wavefront's lanes take too: the vertex normals
  // (placed by the instance first) blended into the shading normal, the
  // frame about it of Frame(ns) or of the mesh's tangents.
  using namespace width1;
  const TriangleMesh& mesh = shape.mesh;
  const bool triangles = shape.kind == Shape::Kind::Triangles;
  const bool placed = hit.instance != kNoInstance;
  const PlacementColumns place{placed ? &placements_[hit.instance] : nullptr};
  const auto normals = [&](lane1::M, F3 (&n)[3]) {
    const glm::uvec3 v = mesh.triangles[hit.prim];
    for (int k = 0; k < 3; ++k) n[k] = lanes(mesh.normals[v[k]]);
  };
  const auto tangents = [&](lane1::M, F3 (&t)[3], F (&w)[3]) {
    const glm::uvec3 v = mesh.triangles[hit.prim];
    for (int k = 0; k < 3; ++k) {
      const vec4& tk = mesh.tangents[v[k]];
      t[k] = lanes(vec3(tk));
      w[k] = F{tk.w};
    }
  };
  const auto flipped = [&](lane1::M) { return lane1::M{shape.flip_normals}; };
  F3 fs, ft, ns;
  s->shading_normal = generic::surface_frame(kScalar, F{hit.uv.x}, F{hit.uv.y}, lanes(s->n),
                                             lane1::M{triangles && mesh.has_normals()}, normals,
                                             lane1::M{triangles && !mesh.tangents.empty()}, tangents, flipped,
                                             lane1::M{placed}, place, fs, ft, ns)
                          .raw;
  s->frame.s = scalars(fs);
  s->frame.t = scalars(ft);
  s->frame.n = scalars(ns);
  s->material = &scene_.materials[shape.material];
  s->params = nullptr;
  s->shape = hit.shape;
  s->prim = hit.prim;
  s->instance = hit.instance;
}

void CompiledScene::read_textures(const Shape& shape, const Ray& ray, const RayHit& hit, const RayCone& cone,
                                  SurfaceParams* params, Surfel* s) const {
  using namespace width1;  // the generic steps at width 1 (core/simd/texture_inputs-inl.h)
  const Material& m = *s->material;
  // Texture coordinates and the uv-to-world area ratio that turns the cone's
  // width into a footprint in uv (core/ray_cone.h).
  const bool placed = hit.instance != kNoInstance;
  const PlacementColumns place{placed ? &placements_[hit.instance] : nullptr};
  generic::TextureInputs<F> in;
  if (shape.kind == Shape::Kind::Sphere) {
    in = generic::sphere_texture_inputs(kScalar, lanes(s->p), lanes(shape.center), F{shape.radius}, lane1::M{placed},
                                        place);
  } else {
    const Triangle& t = triangles_[first_triangle_[hit.shape] + hit.prim];
    const auto corners = [&](lane1::M) { return corner_uvs(shape.mesh, hit.prim); };
    in = generic::triangle_texture_inputs(kScalar, F{hit.uv.x}, F{hit.uv.y}, lanes(t.p0), lanes(t.p1), lanes(t.p2),
                                          lane1::M{shape.mesh.has_uvs()}, corners, lane1::M{placed}, place);
  }
  s->uv = vec2(in.u.raw, in.v.raw);
  const float width = generic::footprint_width(kScalar, F{cone.width}, F{cone.spread}, lanes(ray.origin),
                                               lanes(ray.dir), lanes(s->p), lanes(s->n), in.uv_per_area)
                          .raw;
  const TextureFootprint at{s->uv, width};
  if (m.normal_map) {
    // Tangent space as glTF has it: x along the tangent (dP/du), y along the
    // bitangent (dP/dv, "+y up"), z the shading normal (generic code, which
    // the wavefront's lanes run too: shading_frame-inl.h normal_mapped_frame).
    const vec3 c = vec3(textures_->color(m.normal_map->texture, at));
    F3 fs = lanes(s->frame.s), ft = lanes(s->frame.t), fn = lanes(s->frame.n);
    lane1::M shading;
    if (generic::normal_mapped_frame(kScalar, lanes(c), F{m.normal_map->scale}, lanes(s->n), fs, ft, fn, shading).raw) {
      s->frame.s = scalars(fs);
      s->frame.t = scalars(ft);
      s->frame.n = scalars(fn);
      s->shading_normal = shading.raw;
    }
  }
  if (m.is_textured() && params != nullptr) {
    evaluate_textured(m, *textures_, at, params);
    s->params = params;
  }
}

}  // namespace pathlab
