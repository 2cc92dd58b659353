#include "core/camera.h"

#include "core/sampling.h"

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
  // Film position -> point on the image plane at distance 1 along forward.
  const float sx = (2.0f * film.x * inv_width_ - 1.0f) * tan_half_fov_ * aspect_;
  const float sy = (1.0f - 2.0f * film.y * inv_height_) * tan_half_fov_;
  const vec3 d = glm::normalize(forward_ + sx * right_ + sy * up_);
  if (desc_.aperture_radius <= 0.0f) return Ray{desc_.position, d};

  // Thin lens: every ray through this film point meets at the same point of
  // the plane in focus, whatever point of the aperture it leaves from.
  const vec3 focus = desc_.position + d * (desc_.focus_distance / glm::dot(d, forward_));
  const vec2 lens = desc_.aperture_radius * square_to_concentric_disk(u_lens);
  const vec3 origin = desc_.position + lens.x * right_ + lens.y * up_;
  return Ray{origin, glm::normalize(focus - origin)};
}

}  // namespace pathlab
