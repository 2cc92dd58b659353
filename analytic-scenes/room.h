// Helpers shared by the models: closed "rooms" (a sphere or a watertight
// triangle mesh), whether a point is inside one, which way its emission
// faces, and exact ray-sphere intersection in double precision.
#pragma once

#include "core/scene.h"

#include <optional>
#include <string>

namespace pathlab::analytic {

// Throws InputError "<scene>: <model>: <problem>".
[[noreturn]] void refuse(const Scene& scene, std::string_view model, const std::string& problem);

// True if `shape` is a sphere or a watertight mesh (every edge shared by
// exactly two triangles, matching vertices by position).
bool is_closed(const Shape& shape);
// True if `p` is strictly inside the closed `shape` (ray parity for meshes).
bool contains(const Shape& shape, const vec3& p);
// True if the closed `shape`'s front side faces its inside (normals flipped
// for a sphere; inward winding for a mesh).
bool front_faces_inwards(const Shape& shape);
// True if the closed `shape`'s emission reaches its inside: its front side
// faces inwards or the material emits from both sides.
bool emits_inwards(const Shape& shape, const Material& material);
// The Lambert albedo the closed `shape` reflects with towards its inside:
// the material's, or black for a one-sided material whose front faces out.
Spectrum reflectance_inside(const Shape& shape, const Material& material);

// Distance t > 0 at which the ray from `o` along `d` crosses the triangle
// (Möller-Trumbore in double precision), if it does.
std::optional<double> hit_triangle(const dvec3& o, const dvec3& d, const dvec3& p0, const dvec3& p1, const dvec3& p2);

// Distance along the ray to the first intersection with the sphere in front
// of the origin, computed in double precision.
std::optional<double> hit_sphere(const vec3& center, float radius, const Ray& ray);

}  // namespace pathlab::analytic
