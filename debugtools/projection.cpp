#include "debugtools/projection.h"

namespace pathlab {

FilmProjection::FilmProjection(const CameraDesc& desc, int width, int height)
    : position_(desc.position),
      tan_half_fov_(std::tan(glm::radians(desc.fov_y_degrees) * 0.5f)),
      aspect_(static_cast<float>(width) / static_cast<float>(height)),
      width_(width),
      height_(height) {
  // The same frame as Camera's constructor.
  forward_ = glm::normalize(desc.look_at - desc.position);
  right_ = glm::normalize(glm::cross(forward_, desc.up));
  up_ = glm::cross(right_, forward_);
}

std::optional<vec2> FilmProjection::project(const vec3& world) const {
  const vec3 d = world - position_;
  const float z = glm::dot(d, forward_);
  if (!(z > 1e-6f)) return std::nullopt;
  const float sx = glm::dot(d, right_) / z, sy = glm::dot(d, up_) / z;
  // generate_ray: sx = (2 fx / w - 1) tan aspect,  sy = (1 - 2 fy / h) tan.
  return vec2((sx / (tan_half_fov_ * aspect_) + 1.0f) * 0.5f * static_cast<float>(width_),
              (1.0f - sy / tan_half_fov_) * 0.5f * static_cast<float>(height_));
}

}  // namespace pathlab
