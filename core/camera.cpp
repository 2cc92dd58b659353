#include "core/camera.h"

#include "core/simd/width1.h"

namespace pathlab {

Camera::Camera(const CameraDesc& desc, int width, int height)
    : desc_(desc),
      tan_half_fov_(std::tan(glm::radians(desc.fov_y_degrees) * 0.5f)),
      aspect_(static_cast<float>(width) / static_cast<float>(height)),
      inv_width_(1.0f / static_cast<float>(width)),
      inv_height_(1.0f / static_cast<float>(height)) {
  forward_ = glm::normalize(desc.look_at - desc.position);
  right_ = glm::normalize(glm::cross(forward_, desc.up));
  up_ = glm::cross(right_, forward_);
}

Ray Camera::generate_ray(vec2 film, vec2 u_lens) const {
  using namespace width1;
  const generic::CameraPlane<F> plane{lanes(desc_.position), lanes(forward_), lanes(right_), lanes(up_),
                                      F{tan_half_fov_}, F{aspect_}, F{inv_width_}, F{inv_height_}};
  const auto lens_u = [&](F& lu, F& lv) {
    lu = F{u_lens.x};
    lv = F{u_lens.y};
  };
  F3 origin, dir;
  generic::camera_ray(kScalar, plane, desc_.aperture_radius, desc_.focus_distance, F{film.x}, F{film.y}, lens_u, origin,
                      dir);
  return Ray{scalars(origin), scalars(dir)};
}

}  // namespace pathlab
