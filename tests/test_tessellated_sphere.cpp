// Tessellated spheres (label "stat"): a UV sphere of n rings x 2n segments
// with smooth (exact unit) vertex normals, put in place of the analytic
// sphere of a "sphere-in-uniform-light" scene, agrees with the closed form
// within an allowance the test derives from the tessellation.
//
// Notation: sphere centre c, radius R; Lambert albedo a; surroundings of
// uniform radiance L (the environment, or the emissive room's walls); the
// analytic sphere shows on = a L (0 with depth cap 0) and everything else
// off = L. Both come from the scene's own model.
//
// 1. The tessellation angle. A face F (unit normal g) has its three vertices
//    on the circle where its plane meets the sphere, of angular radius rho_F
//    seen from c: the plane lies at distance R cos rho_F from c, and the exact
//    normal of each vertex makes the angle rho_F with g. Let
//        theta_max = max over faces and their vertices of angle(g, p - c),
//    computed from the mesh's positions in double precision with the exact
//    radial normals - not the mesh's normal array, so that wrong normals
//    cannot widen their own allowance. (About pi / (sqrt 2 n), the half-
//    diagonal of the quads next to the equator: 0.2742 for n = 8, 0.06936
//    for 32, 0.017354 for 128.) Then
//    (a) the mesh, the convex hull of its vertices, lies between the balls
//        of radii R cos theta_max and R;
//    (b) the interpolated shading normal ns, a normalised convex combination
//        of F's vertex normals, stays in their convex cone of half-angle
//        rho_F about g: angle(ns, g) <= theta_max (shading_normal() snapping
//        to g within 0.08 degrees only brings it nearer);
//    (c) a point x of F is R cos rho_F g + t from c with |t| <= R sin rho_F:
//        angle(x - c, g) <= theta_max.
//    ((a) and (b) on the mesh itself: test_tessellation_bound.cpp.)
//
// 2. A hit's radiance. At a hit with wo.ns > 0 and angle(ns, g) = theta, the
//    Lambert lobe (in the shading frame, cosine to ns) reflects, by the
//    geometric-side policy, only directions with wi.ns > 0 and wi.g > 0; the
//    mesh is convex, so each of them leaves it and sees L, and a depth cap
//    >= 1 adds nothing else. Lost: the cosine-weighted (about ns) measure of
//    {wi.ns > 0 > wi.g}, over pi. Projected onto the disc normal to ns
//    (Nusselt), the hemisphere is the unit disc and g's horizon the half
//    ellipse of semi-axes cos theta and 1, so the lost set has area
//    (pi - pi cos theta) / 2:
//        P(theta) = (1 - cos theta) / 2           (test_tessellation_bound.cpp)
//    and the hit carries on (1 - P(theta)) in [on (1 - delta), on] with
//        delta = (1 - cos theta_max) / 2 ~ theta_max^2 / 4.
//    If instead wo.ns < 0 < wo.g (a view grazing the face by less than
//    theta), the two-sided lobe turns its frame to -ns and keeps only the
//    wedge between the two planes: on P(theta), nearly black. That happens
//    only near the silhouette:
//
// 3. Which rays. A camera ray whose line passes at distance b from c
//    - b > R: misses the ball, so the mesh: off, exactly;
//    - b < b_in = R cos theta_max cos 2 theta_max: hits the mesh (b < R cos
//      theta_max, (a)) and does not turn: with s = |x - c| >= R cos theta_max
//      and sin alpha = b / s, the hit is on the near side of the closest
//      approach (beyond it wo.g > 0 would need b > s cos theta_max >= R cos^2
//      theta_max > b_in), so angle(wo, x - c) = alpha and, by (b) and (c),
//      angle(wo, ns) <= alpha + 2 theta_max < pi / 2;
//    - the band b_in <= b <= R: anything in [0, max(on, off)].
//    The band is about 2.5 theta_max^2 R wide: the silhouette's sag
//    R (1 - cos theta_max) (twice the sagitta of half the segment angle,
//    because a silhouette can cross a face's middle, deeper than any edge's)
//    plus 2 theta_max^2 R where a hit may turn. band_pixels() gives it on the
//    film; the bilinear filter's footprint adds one pixel.
//
// 4. The test. lo and hi are the film-filter-weighted integrals
//    (expected_image) of the ray-wise lower and upper bounds. Each
//    pixel-channel is z-tested by check_against_expected against the point of
//    [lo, hi] nearest its rendered value (sigma as in `pathlab check`: 3x3
//    variance, quadrature error, float floor; Sidak over all 3 W H tests,
//    alpha 1e-4): the true value lies in the interval, so |z| can only be
//    smaller than against it. The interior pixels (whole footprint inside
//    b_in) also take a mean test per channel against [on (1 - delta), on]
//    with the standard error sqrt(sum sigma^2) / N, x3 for the bilinear filter
//    (Sidak over the three channels).
#include "tests/check_util.h"
#include "tests/stat_util.h"
#include "tests/test_scenes.h"

#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>

namespace pathlab {
namespace {

constexpr double kAlpha = 1e-4;

// The sphere of a sphere-in-uniform-light scene, its model's two radiances
// and the bounds of the header for one tessellation.
struct Bounds {
  dvec3 c;
  double R = 0.0;
  Spectrum on, off;
  double theta_max = 0.0;
  double delta() const { return 0.5 * (1.0 - std::cos(theta_max)); }
  double b_in() const { return R * std::cos(theta_max) * std::cos(2.0 * theta_max); }
};

// Ray-wise lower (upper = false) or upper bound of the mesh's radiance.
class BoundModel final : public AnalyticModel {
 public:
  BoundModel(const Bounds& b, bool upper) : b_(b), upper_(upper) {}
  std::string_view name() const override { return upper_ ? "tessellated sphere, upper" : "tessellated sphere, lower"; }
  std::string describe() const override { return std::string(name()); }
  // The bounds jump where the impact parameter is b_in or R: two cones of
  // rays about the direction to the centre.
  void edges(EdgeList& out) const override {
    const dvec3 to_c = b_.c - out.eye();
    const double D = glm::length(to_c);
    for (const double b : {b_.b_in(), b_.R * (1.0 + 1e-6)})
      if (b < D) out.cone(to_c, std::sqrt(1.0 - (b / D) * (b / D)));
  }
  Spectrum radiance(const Ray& ray) const override {
    const dvec3 oc = b_.c - dvec3(ray.origin), d(ray.dir);
    const double along = glm::dot(oc, d);
    const double b = std::sqrt(std::max(0.0, glm::dot(oc, oc) - along * along));
    // The float vertices lie on the sphere to a few ulps: 1e-6 R is outside.
    if (along <= 0.0 || b > b_.R * (1.0 + 1e-6)) return b_.off;
    if (b < b_.b_in()) return upper_ ? b_.on : b_.on * static_cast<float>(1.0 - b_.delta());
    return upper_ ? glm::max(b_.on, b_.off) : Spectrum(0.0f);
  }

 private:
  Bounds b_;
  bool upper_;
};

// The distance on the film, in pixels, between the images of the rays of
// impact parameters b_in and R (the sphere centred in a pinhole view).
double band_pixels(const Bounds& b, const Scene& scene) {
  const double D = glm::length(dvec3(scene.camera.position) - b.c);
  const double f = 0.5 * scene.film.height / std::tan(glm::radians(double(scene.camera.fov_y_degrees)) / 2.0);
  const auto image_radius = [&](double impact) { return f * std::tan(std::asin(impact / D)); };
  return image_radius(b.R) - image_radius(b.b_in());
}

struct MeshScene {
  Scene scene;  // the analytic sphere replaced by the mesh
  Bounds bounds;
};

// `normals` rewrites the mesh's vertex normals (the planted bugs); the
// bounds stay those of the correct mesh.
MeshScene tessellated(const std::string& file, int rings,
                      const std::function<void(TriangleMesh&)>& normals = {}) {
  Scene scene = load_scene(test::analytic_scene(file));
  scene.render.spp *= test::stat_scale();
  const auto model = make_analytic_model(scene);
  Shape* sphere = nullptr;
  for (Shape& s : scene.shapes)
    if (s.kind == Shape::Kind::Sphere && !scene.materials[s.material].emits()) sphere = &s;
  EXPECT_NE(sphere, nullptr);
  Bounds b;
  b.c = dvec3(sphere->center);
  b.R = sphere->radius;
  const vec3 to_centre = glm::normalize(sphere->center - scene.camera.position);
  b.on = model->radiance(Ray{scene.camera.position, to_centre});
  b.off = model->radiance(Ray{scene.camera.position, -to_centre});
  sphere->kind = Shape::Kind::Triangles;
  sphere->description = "UV sphere, " + std::to_string(rings) + " rings";
  sphere->mesh = test::uv_sphere(sphere->center, sphere->radius, rings);
  b.theta_max = test::tessellation_angle(sphere->mesh, b.c);
  if (normals) normals(sphere->mesh);
  return {std::move(scene), b};
}

// The rays at the corners of pixel (x, y)'s filter support all pass within
// b_in of the centre; the set of such rays meets the film in an ellipse
// (a cone cut by a plane), convex, so then the whole support does.
bool interior_pixel(const Bounds& b, const Camera& camera, const FilmDesc& film, int x, int y) {
  const double r = film.filter == FilterKind::Box ? 0.0 : 0.5;
  const double x0 = std::max(0.0, x - r), x1 = std::min<double>(film.width, x + 1.0 + r);
  const double y0 = std::max(0.0, y - r), y1 = std::min<double>(film.height, y + 1.0 + r);
  for (const double fx : {x0, x1})
    for (const double fy : {y0, y1}) {
      const Ray ray = camera.generate_ray(vec2(static_cast<float>(fx), static_cast<float>(fy)), vec2(0.5f));
      const dvec3 oc = b.c - dvec3(ray.origin), d(ray.dir);
      const double along = glm::dot(oc, d);
      if (along <= 0.0 || glm::dot(oc, oc) - along * along >= b.b_in() * b.b_in()) return false;
    }
  return true;
}

struct Verdict {
  CheckResult pixels;        // against the nearest point of [lo, hi]
  bool mean_pass = false;    // interior pixels' mean, every channel
  double worst_mean_z = 0.0;
  int interior = 0;
  double mean_loss = 0.0;    // interior pixels: mean of (on - rendered) / on over channels
};

struct Intervals {
  ExpectedImage lo, hi;
};

Intervals intervals(const Bounds& b, const Scene& scene) {
  const Camera camera(scene.camera, scene.film.width, scene.film.height);
  return {expected_image(BoundModel(b, false), camera, scene.film), expected_image(BoundModel(b, true), camera, scene.film)};
}

template <typename TracerT>
Verdict render_and_judge(const MeshScene& ms, const Intervals& iv, Strategy strategy) {
  Scene scene = ms.scene;
  scene.render.strategy = strategy;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const TracerT tracer(compiled, settings);
  const FilmDesc& fd = compiled.scene().film;
  Film film(fd.width, fd.height, fd.filter);
  render(tracer, film);

  const Bounds& b = ms.bounds;
  ExpectedImage nearest{Image(fd.width, fd.height), Image(fd.width, fd.height), Image(fd.width, fd.height)};
  const CheckOptions options{kAlpha};
  dvec3 sum(0.0), sum_var(0.0);
  Verdict v;
  for (int y = 0; y < fd.height; ++y)
    for (int x = 0; x < fd.width; ++x) {
      const Spectrum m = film.mean(x, y), var = film.variance_of_mean(x, y);
      for (int ch = 0; ch < 3; ++ch) {
        nearest.mean.at(x, y)[ch] = std::clamp(m[ch], iv.lo.mean.at(x, y)[ch], iv.hi.mean.at(x, y)[ch]);
        nearest.quadrature_error.at(x, y)[ch] =
            std::max(iv.lo.quadrature_error.at(x, y)[ch], iv.hi.quadrature_error.at(x, y)[ch]);
      }
      if (!interior_pixel(b, compiled.camera(), fd, x, y)) continue;
      ++v.interior;
      const dvec3 floor = options.rel_floor * dvec3(b.on) + options.abs_floor;
      sum += dvec3(m);
      sum_var += dvec3(var) + floor * floor;
    }
  v.pixels = check_against_expected(film, nearest, options);
  v.mean_pass = v.interior > 0;
  const double inflate = fd.filter == FilterKind::Bilinear ? 3.0 : 1.0;
  const double threshold = test::sidak_z(kAlpha, 3.0);
  for (int ch = 0; ch < 3; ++ch) {
    const double n = std::max(1, v.interior), mean = sum[ch] / n, se = std::sqrt(sum_var[ch]) / n * inflate;
    const double lo = b.on[ch] * (1.0 - b.delta()), hi = b.on[ch];
    const double z = (mean - std::clamp(mean, lo, hi)) / se;
    if (std::abs(z) > std::abs(v.worst_mean_z)) v.worst_mean_z = z;
    if (std::abs(z) > threshold) v.mean_pass = false;
    v.mean_loss += (1.0 - mean / b.on[ch]) / 3.0;
  }
  return v;
}

std::string describe(const Verdict& v) {
  std::string s = std::to_string(v.pixels.failing) + " pixel-channels beyond |z| " +
                  std::to_string(v.pixels.z_threshold) + ", interior mean z " + std::to_string(v.worst_mean_z);
  if (!v.pixels.worst.empty()) {
    const PixelDeviation& w = v.pixels.worst.front();
    s += "; worst pixel (" + std::to_string(w.x) + ", " + std::to_string(w.y) + ") z " + std::to_string(w.z) +
         " rendered " + std::to_string(w.rendered) + " nearest bound " + std::to_string(w.expected);
  }
  return s;
}

struct Case {
  std::string file;
  int rings;
};

class TessellatedSphere : public testing::TestWithParam<Case> {};

// Every tracer and strategy passes against the derived interval; the bound
// and the silhouette band shrink as the rings grow.
TEST_P(TessellatedSphere, AgreesWithTheAnalyticSphereWithinTheDerivedBound) {
  const MeshScene ms = tessellated(GetParam().file, GetParam().rings);
  const Intervals iv = intervals(ms.bounds, ms.scene);
  std::printf("[ bound    ] %s, %d rings: theta_max %.5f, delta %.3g, band %.3g px\n", GetParam().file.c_str(),
              GetParam().rings, ms.bounds.theta_max, ms.bounds.delta(), band_pixels(ms.bounds, ms.scene));
  for (const Strategy strategy : {Strategy::Bsdf, Strategy::Mis})
    for (const bool wavefront : {false, true}) {
      const Verdict v = wavefront ? render_and_judge<WavefrontTracer>(ms, iv, strategy)
                                  : render_and_judge<ReferenceTracer>(ms, iv, strategy);
      const std::string what = std::string(strategy_name(strategy)) + (wavefront ? " wavefront" : " reference");
      std::printf("[ measured ] %-14s %d interior pixels, mean loss %.3g (bound %.3g), mean z %.2f\n", what.c_str(),
                  v.interior, v.mean_loss, ms.bounds.delta(), v.worst_mean_z);
      EXPECT_TRUE(v.pixels.pixels_pass) << what << ": " << describe(v);
      EXPECT_TRUE(v.mean_pass) << what << ": " << describe(v);
      EXPECT_GT(v.interior, 400) << what;  // most of the sphere's image is tested
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes, TessellatedSphere,
                         testing::Values(Case{"sphere-in-environment.json", 8}, Case{"sphere-in-environment.json", 32},
                                         Case{"sphere-in-environment.json", 128},
                                         Case{"white-sphere-emissive-room.json", 8},
                                         Case{"white-sphere-emissive-room.json", 32},
                                         Case{"white-sphere-emissive-room.json", 128}),
                         [](const testing::TestParamInfo<Case>& p) {
                           return (p.param.file[0] == 's' ? std::string("environment_") : std::string("room_")) +
                                  std::to_string(p.param.rings);
                         });

// Planted bugs, judged against the correct mesh's bound: each must fail.
// Renders at 4x the scene's samples, for a margin.
Verdict planted(const std::function<void(TriangleMesh&)>& bug, Strategy strategy, bool wavefront, const char* what) {
  MeshScene ms = tessellated("sphere-in-environment.json", 32, bug);
  ms.scene.render.spp *= 4;
  const Intervals iv = intervals(ms.bounds, ms.scene);
  const Verdict v = wavefront ? render_and_judge<WavefrontTracer>(ms, iv, strategy)
                              : render_and_judge<ReferenceTracer>(ms, iv, strategy);
  std::printf("[ fault    ] %s, %s %s: mean loss %.3g (bound %.3g); %s\n", what, strategy_name(strategy),
              wavefront ? "wavefront" : "reference", v.mean_loss, ms.bounds.delta(), describe(v).c_str());
  return v;
}

// A 32-ring mesh carrying the vertex normals of an 8-ring sphere (each vertex
// takes the exact normal of the nearest coarse vertex, up to 0.14 rad off):
// about 4x the bound's loss on average. The BSDF strategy's estimate is
// exact but for the lost samples, so its mean test resolves the difference;
// MIS's environment samples are too noisy at this sample count (its
// standard error is about the excess itself), so it is not asked to.
TEST(TessellatedSphereFault, NormalsOfACoarserSphereFail) {
  constexpr int kRings = 32, kStep = 4;
  const auto coarse = [](TriangleMesh& mesh) {
    for (int i = 0; i <= kRings; ++i)
      for (int j = 0; j <= 2 * kRings; ++j) {
        const double theta = std::numbers::pi * std::round(double(i) / kStep) * kStep / kRings;
        const double phi = std::numbers::pi * std::round(double(j) / kStep) * kStep / kRings;
        mesh.normals[static_cast<std::size_t>(i * (2 * kRings + 1) + j)] =
            vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      }
  };
  for (const bool wavefront : {false, true}) {
    const Verdict v = planted(coarse, Strategy::Bsdf, wavefront, "8-ring normals on 32 rings");
    EXPECT_FALSE(v.pixels.pixels_pass && v.mean_pass) << (wavefront ? "wavefront" : "reference");
  }
}

// Normals by the wrong transform: the mesh placed turned by 20 degrees about
// x, its normals left as they were (equivalently: the normals turned by 20
// degrees against the positions). Every tracer and strategy must fail.
TEST(TessellatedSphereFault, NormalsByTheWrongTransformFail) {
  const auto turned = [](TriangleMesh& mesh) {
    const mat3 r(glm::rotate(mat4(1.0f), glm::radians(20.0f), vec3(1.0f, 0.0f, 0.0f)));
    for (vec3& n : mesh.normals) n = r * n;
  };
  for (const Strategy strategy : {Strategy::Bsdf, Strategy::Mis})
    for (const bool wavefront : {false, true}) {
      const Verdict v = planted(turned, strategy, wavefront, "normals turned 20 degrees");
      EXPECT_FALSE(v.pixels.pixels_pass && v.mean_pass) << strategy_name(strategy) << (wavefront ? " wavefront" : "");
    }
}

}  // namespace
}  // namespace pathlab
