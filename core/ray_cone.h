// Ray cones: the texture footprint a path carries (Akenine-Möller et al.,
// "Texture Level of Detail Strategies for Real-Time Ray Tracing", Ray
// Tracing Gems 2019, ch. 20, and its 2021 follow-up). A cone has a width at
// the ray's origin and a spread angle; along a segment of length t its width
// becomes width + spread * t (the small-angle form the paper uses).
//
// The camera gives each primary ray a cone of width 0 and the spread of one
// pixel, atan(2 tan(fov_y / 2) / height) (the angle a pixel subtends at the
// image centre; a thin lens keeps the pinhole's cone). At a hit the cone's
// width w is projected onto the surface (w / |cos theta|, theta between the
// ray and the geometric normal) and converted to texture space by the square
// root of the triangle's uv-to-world area ratio: the footprint's width in uv,
// which OIIO receives as the derivatives ds/dx = dt/dy (an isotropic
// footprint: along the surface's steepest direction it is the projected
// width, across it wider than the truth; the paper's choice, conservative).
//
// After a scatter the cone goes on from the hit with the width it had there:
// - an impulse (mirror, glass) keeps the spread (the paper's flat-surface
//   case; the curvature term is left out, so a curved mirror's reflection is
//   filtered a little too sharply);
// - any other lobe widens the spread to at least the angle of a cone whose
//   solid angle is 1/pdf of the sampled direction, 2 sqrt(1 / (pi pdf)),
//   capped at pi (the solid angle one sample stands for; Suykens and Willems'
//   path differentials argue the same way). A diffuse bounce therefore reads
//   the next surface's textures heavily filtered, which is what the
//   integral over that lobe does anyway.
// With the point filter there is no cone to carry: every lookup reads the
// finest level, after a scatter as at the camera.
// Both tracers carry the same cone, computed by these functions, so they
// read the same texels; a scene without textures carries none (the tracers
// skip this arithmetic).
#pragma once

#include "core/math.h"
#include "core/texture.h"

#include <algorithm>
#include <cmath>

namespace pathlab {

struct RayCone {
  float width = 0.0f;   // at the ray's origin
  float spread = 0.0f;  // full angle, radians
  float width_at(float t) const { return width + spread * t; }
};

// The spread of a camera ray: the angle one pixel subtends at the image
// centre for a vertical field of view `fov_y_degrees` over `height` pixels.
inline float pixel_spread_angle(float fov_y_degrees, int height) {
  return std::atan(2.0f * std::tan(0.5f * fov_y_degrees * kPi / 180.0f) / static_cast<float>(height));
}

// The cone leaving a hit at distance `t` along `in` after a scatter (none
// with the point filter): the width there, and the spread of the sampled
// lobe where it is wider (not after an impulse). Generic code
// (core/simd/lanes-inl.h scattered_cone) that the wavefront's lanes call too.
RayCone scattered_cone(const RayCone& in, float t, bool impulse, float pdf, TextureFilter filter);

// The footprint's width in texture space at a hit (the cone's width there,
// projected onto the surface and scaled by sqrt(uv area / world area)) is
// footprint_width in core/simd/lanes-inl.h: CompiledScene::read_textures
// and the wavefront's lanes compute it by that one source.

}  // namespace pathlab
