#include "core/compiled_scene.h"

#include "core/geometry.h"
#include "core/parallel.h"

namespace pathlab {

CompiledScene::CompiledScene(Scene scene)
    : scene_(std::move(scene)), camera_(scene_.camera, scene_.film.width, scene_.film.height) {
  configure_shading(scene_);  // materials: shading path for the scene's lobes, sampling flavour, min pdf
  vec3 lo(kInfinity), hi(-kInfinity);
  for (const Shape& shape : scene_.shapes) {
    if (shape.kind == Shape::Kind::Sphere) {
      lo = glm::min(lo, shape.center - shape.radius);
      hi = glm::max(hi, shape.center + shape.radius);
    } else {
      for (const vec3& p : shape.mesh.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
    }
    lobes_ |= scene_.materials[shape.material].lobes();
  }
  if (lo.x <= hi.x) {
    bounds_center_ = 0.5f * (lo + hi);
    bounds_radius_ = std::max(0.5f * glm::length(hi - lo), 1e-3f);
  }
  accel_ = std::make_unique<EmbreeAccel>(scene_.shapes);
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
  lights_ = std::make_unique<LightSampler>(scene_, bounds_radius_);
}

bool CompiledScene::intersect(const Ray& ray, Surfel* s) const {
  RayHit hit;
  if (!accel_->intersect(ray, &hit)) return false;
  resolve(ray, hit, s);
  return true;
}

void CompiledScene::resolve(const Ray& ray, const RayHit& hit, Surfel* s) const {
  const Shape& shape = scene_.shapes[hit.shape];
  const SurfacePoint sp = shape.kind == Shape::Kind::Sphere
                              ? sphere_point(shape, ray.origin + hit.t * ray.dir)
                              : triangle_point(triangles_[first_triangle_[hit.shape] + hit.prim], hit.uv);
  s->p = sp.p;
  s->p_error = sp.p_error;
  s->n = sp.n;
  s->uv = hit.uv;
  vec3 ns = sp.n;
  if (shape.kind == Shape::Kind::Triangles && (shape.mesh.has_normals() || shape.mesh.has_uvs())) {
    const glm::uvec3 v = shape.mesh.triangles[hit.prim];
    const float b0 = 1.0f - hit.uv.x - hit.uv.y;
    if (shape.mesh.has_uvs())
      s->uv = b0 * shape.mesh.uvs[v.x] + hit.uv.x * shape.mesh.uvs[v.y] + hit.uv.y * shape.mesh.uvs[v.z];
    if (shape.mesh.has_normals()) {
      const std::vector<vec3>& n = shape.mesh.normals;
      ns = shading_normal(sp.n, b0 * n[v.x] + hit.uv.x * n[v.y] + hit.uv.y * n[v.z]);
    }
  }
  s->shading_normal = ns != sp.n;
  s->frame = Frame(ns);
  s->material = &scene_.materials[shape.material];
  s->shape = hit.shape;
  s->prim = hit.prim;
}

}  // namespace pathlab
