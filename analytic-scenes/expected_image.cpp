#include "analytic-scenes/expected_image.h"

#include "core/parallel.h"

namespace pathlab {
namespace {

struct PixelIntegral {
  dvec3 mean;
  dvec3 footprint_variance;
};

// Filter-weighted mean of the radiance over pixel (px, py)'s support, on an
// n x n midpoint grid per pixel unit.
PixelIntegral integrate_pixel(const AnalyticModel& model, const Camera& camera, const FilmDesc& film, int px, int py, int n) {
  const bool box = film.filter == FilterKind::Box;
  // Support in film coordinates, clipped to the image.
  const double x0 = box ? px : std::max(0.0, px - 0.5), x1 = box ? px + 1.0 : std::min<double>(film.width, px + 1.5);
  const double y0 = box ? py : std::max(0.0, py - 0.5), y1 = box ? py + 1.0 : std::min<double>(film.height, py + 1.5);
  const int nx = static_cast<int>(std::lround((x1 - x0) * n)), ny = static_cast<int>(std::lround((y1 - y0) * n));
  const double cx = px + 0.5, cy = py + 0.5;
  dvec3 sum(0.0), sum_w2L(0.0), sum_w2L2(0.0);
  double sum_w = 0.0, sum_w2 = 0.0;
  for (int j = 0; j < ny; ++j) {
    const double y = y0 + (j + 0.5) * (y1 - y0) / ny;
    const double wy = box ? 1.0 : 1.0 - std::abs(y - cy);
    for (int i = 0; i < nx; ++i) {
      const double x = x0 + (i + 0.5) * (x1 - x0) / nx;
      const double w = wy * (box ? 1.0 : 1.0 - std::abs(x - cx));
      const Ray ray = camera.generate_ray(vec2(static_cast<float>(x), static_cast<float>(y)), vec2(0.5f));
      const dvec3 L(model.radiance(ray));
      sum += w * L;
      sum_w += w;
      sum_w2 += w * w;
      sum_w2L += w * w * L;
      sum_w2L2 += w * w * L * L;
    }
  }
  // Cell areas cancel in the ratio below, except one: Int w^2 (L - m)^2 dA
  // carries one cell area, (Int w dA)^2 two.
  const double cell = ((x1 - x0) / nx) * ((y1 - y0) / ny);
  const dvec3 m = sum / sum_w;
  const dvec3 spread = glm::max(sum_w2L2 - 2.0 * m * sum_w2L + m * m * sum_w2, dvec3(0.0));
  return {m, spread / (cell * sum_w * sum_w)};
}

}  // namespace

ExpectedImage expected_image(const AnalyticModel& model, const Camera& camera, const FilmDesc& film) {
  ExpectedImage out{Image(film.width, film.height), Image(film.width, film.height), Image(film.width, film.height)};
  parallel_for(0, static_cast<std::size_t>(film.height), 1, [&](std::size_t y0, std::size_t y1) {
    for (int y = static_cast<int>(y0); y < static_cast<int>(y1); ++y)
      for (int x = 0; x < film.width; ++x) {
        PixelIntegral prev = integrate_pixel(model, camera, film, x, y, 4), cur = prev;
        for (int n = 8; n <= 128; n *= 2) {
          cur = integrate_pixel(model, camera, film, x, y, n);
          const dvec3 diff = glm::abs(cur.mean - prev.mean);
          prev = cur;
          if (glm::all(glm::lessThanEqual(diff, 1e-5 * glm::abs(cur.mean) + 1e-12))) {
            // Converged: the last difference bounds the remaining error.
            out.quadrature_error.at(x, y) = vec3(diff);
            break;
          }
          out.quadrature_error.at(x, y) = vec3(diff);
        }
        out.mean.at(x, y) = vec3(cur.mean);
        out.footprint_variance.at(x, y) = vec3(cur.footprint_variance);
      }
  });
  return out;
}

}  // namespace pathlab
