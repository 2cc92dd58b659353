// World -> film projection for the scene camera (the inverse of
// Camera::generate_ray for a pinhole): where a path vertex appears on the
// image. A thin-lens camera is projected through the centre of its lens.
#pragma once

#include "core/camera.h"
#include "core/math.h"

#include <optional>

namespace pathlab {

class FilmProjection {
 public:
  FilmProjection(const CameraDesc& desc, int width, int height);
  // Film position in pixels (x right, y down, (0,0) the top-left corner),
  // or nothing for a point behind (or on) the camera's plane.
  std::optional<vec2> project(const vec3& world) const;

 private:
  vec3 position_, forward_, right_, up_;
  float tan_half_fov_, aspect_;
  int width_, height_;
};

}  // namespace pathlab
