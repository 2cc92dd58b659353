// Pinhole and thin-lens perspective cameras.
//
// Scene-file parameters (object "camera"; see docs/scene-format.md):
//   position        [x,y,z]  eye point                          required
//   look_at         [x,y,z]  point the view is centred on         required
//   up              [x,y,z]  approximate up vector               default [0,1,0]
//   fov_y           degrees  vertical field of view, (0, 180)     default 40
//   aperture_radius world    thin-lens radius; 0 = pinhole        default 0
//   focus_distance  world    distance of the plane in focus > 0   default |look_at - position|
#pragma once

#include "core/math.h"
#include "core/ray.h"

#include <utility>

namespace pathlab {

struct CameraDesc {
  vec3 position{0.0f, 0.0f, 5.0f};
  vec3 look_at{0.0f};
  vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y_degrees = 40.0f;
  float aperture_radius = 0.0f;
  float focus_distance = 5.0f;
};

class Camera {
 public:
  Camera(const CameraDesc& desc, int width, int height);

  // The primary ray through film position `film` (in pixels: x to the right,
  // y down, (0,0) the top-left corner of the image) and aperture sample
  // `u_lens` in [0,1)^2 (ignored by a pinhole).
  Ray generate_ray(vec2 film, vec2 u_lens) const;
  // The same with the aperture sample drawn by u_lens() (the tracers' lens
  // pair, Dim::LensX) only where it is read: for a thin lens (under zsobol
  // a draw costs a permutation of the Sobol' index).
  template <class DrawLens, class = decltype(std::declval<const DrawLens&>()())>
  Ray generate_ray(vec2 film, const DrawLens& u_lens) const {
    return generate_ray(film, has_lens() ? vec2(u_lens()) : vec2(0.0f));
  }
  // Whether generate_ray reads u_lens (a thin lens).
  bool has_lens() const { return desc_.aperture_radius > 0.0f; }

  const CameraDesc& desc() const { return desc_; }
  // The image plane as generate_ray() computes it, for code that makes rays
  // in bulk and must make the same ones (the wavefront's vectorised camera).
  struct Plane {
    vec3 forward, right, up;
    float tan_half_fov, aspect, inv_width, inv_height;
  };
  Plane plane() const { return {forward_, right_, up_, tan_half_fov_, aspect_, inv_width_, inv_height_}; }
  vec3 forward() const { return forward_; }

 private:
  CameraDesc desc_;
  vec3 forward_, right_, up_;
  float tan_half_fov_ = 0.0f;
  float aspect_ = 1.0f;
  float inv_width_ = 1.0f, inv_height_ = 1.0f;
};

}  // namespace pathlab
