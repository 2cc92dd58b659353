#include "core/camera.h"

#include "core/sampling.h"
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
  const F3 d = generic::camera_direction(kScalar, plane, F{film.x}, F{film.y});
  if (desc_.aperture_radius <= 0.0f) return Ray{desc_.position, scalars(d)};
  const vec2 lens = desc_.aperture_radius * square_to_concentric_disk(u_lens);
  F3 origin, dir;
  generic::thin_lens(kScalar, plane, F{desc_.focus_distance}, d, F{lens.x}, F{lens.y}, origin, dir);
  return Ray{scalars(origin), scalars(dir)};
}

}  // namespace pathlab
