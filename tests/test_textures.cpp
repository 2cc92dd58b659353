// Textures: lookups against closed forms (texel values, wrap modes, the sRGB
// decode, filtering in linear space), the ray cone's footprint at a hit,
// normal maps, textured emission as a light and as a plain surface, and the
// same paths and bits in both tracers.
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/film.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "core/tangents.h"
#include "debugtools/aov.h"
#include "reference/reference_tracer.h"
#include "tests/stat_util.h"
#include "tests/temp_dir.h"
#include "tests/texture_util.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <sstream>
#include <tuple>

namespace pathlab {
namespace {

using test::write_image;

// The four texels of the 2x2 test image, row by row from the top.
const std::vector<float> kTexels = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f,   // row 0 (top): x = 0, 1
                                    0.7f, 0.8f, 0.9f, 1.0f, 0.0f, 0.5f};  // row 1
Spectrum texel(int x, int y) {
  const std::size_t i = static_cast<std::size_t>(3 * (2 * y + x));
  return Spectrum(kTexels[i], kTexels[i + 1], kTexels[i + 2]);
}
// The uv of texel (x, y)'s centre in a 2x2 image (v up, y from the top).
vec2 centre(int x, int y) { return vec2((x + 0.5f) / 2.0f, 1.0f - (y + 0.5f) / 2.0f); }

void expect_near(const Spectrum& a, const Spectrum& b, float tol, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << what << " channel " << c;
}

// A 256x256 RGB image of uniform noise (seeded), so that every MIP level
// reads a different value at a point: a footprint off by a factor shows.
void write_noise(const std::filesystem::path& path, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<float> noise(256 * 256 * 3);
  for (float& v : noise) v = uniform(gen);
  write_image(path, 256, 256, 3, noise);
}

class TexturesTest : public test::TempDirTest {};

TEST_F(TexturesTest, PointLookupsReadTheTexelsAndWrapAsAsked) {
  write_image(dir_ / "t.exr", 2, 2, 3, kTexels);
  const std::vector<TextureImage> images{{dir_ / "t.exr", TextureColorSpace::Linear, "test"}};
  const Textures tx(images, 16.0f);
  TextureRef ref;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) expect_near(tx.color(ref, {centre(x, y), 0.0f}), texel(x, y), 1e-6f, "centre");
  // Half way between the two texels of row 0: the mean of both (bilinear).
  expect_near(tx.color(ref, {vec2(0.5f, 0.75f), 0.0f}), 0.5f * (texel(0, 0) + texel(1, 0)), 1e-6f, "between");
  // u = -0.25 is the centre of texel -1 of row 0.
  const vec2 outside(-0.25f, 0.75f);
  ref.wrap = TextureWrap::Repeat;
  expect_near(tx.color(ref, {outside, 0.0f}), texel(1, 0), 1e-6f, "repeat");
  expect_near(tx.color(ref, {centre(1, 1) + vec2(3.0f, -2.0f), 0.0f}), texel(1, 1), 1e-5f, "repeat far");
  ref.wrap = TextureWrap::Clamp;
  expect_near(tx.color(ref, {outside, 0.0f}), texel(0, 0), 1e-6f, "clamp");
  ref.wrap = TextureWrap::Black;
  expect_near(tx.color(ref, {outside, 0.0f}), Spectrum(0.0f), 1e-6f, "black");
  ref.wrap = TextureWrap::Mirror;
  expect_near(tx.color(ref, {outside, 0.0f}), texel(0, 0), 1e-6f, "mirror");
  expect_near(tx.color(ref, {vec2(1.25f, 0.75f), 0.0f}), texel(1, 0), 1e-6f, "mirror past 1");
  // One channel as a number; scale and offset after decoding.
  ref = TextureRef{};
  ref.channel = 1;
  ref.scale = Spectrum(2.0f);
  ref.offset = Spectrum(0.25f);
  EXPECT_NEAR(tx.number(ref, {centre(1, 0), 0.0f}), 2.0f * 0.5f + 0.25f, 1e-6f);
  // The mean of every texel.
  EXPECT_NEAR(tx.mean(0, 0), (0.1f + 0.4f + 0.7f + 1.0f) / 4.0f, 1e-6f);
}

// A grey image (one channel, or grey and alpha) reads as R = G = B = grey,
// as glTF reads it (a grey metallic-roughness JPEG's G and B), and alpha 1
// where it has none; never a channel past the image's (which Debian's OIIO
// answers with an assertion that aborts the process).
TEST_F(TexturesTest, GreyImagesReadAsRgbWithAlphaOne) {
  write_image(dir_ / "grey.exr", 2, 1, 1, {0.25f, 0.75f});
  write_image(dir_ / "grey-alpha.exr", 2, 1, 2, {0.25f, 0.5f, 0.75f, 1.0f});
  write_image(dir_ / "rgb.exr", 2, 1, 3, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
  const std::vector<TextureImage> images{{dir_ / "grey.exr", TextureColorSpace::Linear, "test"},
                                         {dir_ / "grey-alpha.exr", TextureColorSpace::Linear, "test"},
                                         {dir_ / "rgb.exr", TextureColorSpace::Linear, "test"}};
  const Textures tx(images, 16.0f);
  const TextureFootprint left{vec2(0.25f, 0.5f), 0.0f};
  TextureRef ref;
  for (std::uint8_t c = 0; c < 3; ++c) {
    ref.channel = c;
    ref.image = 0;
    EXPECT_EQ(tx.number(ref, left), 0.25f) << int(c);
    ref.image = 1;
    EXPECT_EQ(tx.number(ref, left), 0.25f) << int(c);
  }
  ref.channel = 3;  // alpha
  ref.image = 0;
  EXPECT_EQ(tx.number(ref, left), 1.0f);
  ref.image = 1;
  EXPECT_EQ(tx.number(ref, left), 0.5f);
  ref.image = 2;
  EXPECT_EQ(tx.number(ref, left), 1.0f);
  ref.channel = 0;
  ref.image = 1;
  expect_near(tx.color(ref, left), Spectrum(0.25f), 0.0f, "grey+alpha as a colour");
}

// The sRGB curve (IEC 61966-2-1), in double.
double srgb(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

TEST_F(TexturesTest, SrgbDecodesEightBitCodesAndFiltersInLinearSpace) {
  const std::vector<int> codes = {0, 1, 10, 11, 64, 128, 200, 254, 255, 33, 77, 190};
  std::vector<float> texels;
  for (int c : codes) texels.push_back(static_cast<float>(c) / 255.0f);
  write_image(dir_ / "codes.png", 4, 1, 3, texels, OIIO::TypeDesc::UINT8);
  write_image(dir_ / "bw.png", 2, 1, 1, {0.0f, 1.0f}, OIIO::TypeDesc::UINT8);
  const std::vector<TextureImage> images{{dir_ / "codes.png", TextureColorSpace::Srgb, "test"},
                                         {dir_ / "codes.png", TextureColorSpace::Linear, "test"},
                                         {dir_ / "bw.png", TextureColorSpace::Srgb, "test"}};
  const Textures tx(images, 16.0f);
  for (int x = 0; x < 4; ++x) {
    const vec2 uv((x + 0.5f) / 4.0f, 0.5f);
    TextureRef ref;
    const Spectrum decoded = tx.color(ref, {uv, 0.0f});
    ref.image = 1;
    const Spectrum stored = tx.color(ref, {uv, 0.0f});
    for (int c = 0; c < 3; ++c) {
      const double code = codes[static_cast<std::size_t>(3 * x + c)] / 255.0;
      EXPECT_NEAR(decoded[c], srgb(code), 1e-6 * std::max(1.0, srgb(code) * 10.0)) << "code " << code * 255;
      EXPECT_NEAR(stored[c], code, 1e-6) << "code " << code * 255;
    }
  }
  // Black and white, half way: 0.5 in linear space (filtering the encoded
  // values would give 0.5 encoded, 0.214 linear).
  TextureRef bw;
  bw.image = 2;
  EXPECT_NEAR(tx.color(bw, {vec2(0.5f, 0.5f), 0.0f}).x, 0.5f, 1e-6f);
  // A grey image gives its one channel to all three.
  expect_near(tx.color(bw, {vec2(0.75f, 0.5f), 0.0f}), Spectrum(1.0f), 1e-6f, "grey");
}

TEST_F(TexturesTest, RefusesNonFiniteTexelsNamingThem) {
  std::vector<float> texels(2 * 2 * 3, 0.5f);
  texels[3 * 1 + 2] = std::numeric_limits<float>::quiet_NaN();  // texel (1, 0), channel 2
  write_image(dir_ / "nan.exr", 2, 2, 3, texels);
  texels[3 * 1 + 2] = 0.5f;
  texels[3 * 2 + 0] = std::numeric_limits<float>::infinity();  // texel (0, 1), channel 0
  write_image(dir_ / "inf.exr", 2, 2, 3, texels);
  for (const auto& [file, says] : {std::pair{"nan.exr", "texel (1, 0) channel 2 is NaN"},
                                   std::pair{"inf.exr", "texel (0, 1) channel 0 is infinite"}}) {
    const std::vector<TextureImage> images{{dir_ / file, TextureColorSpace::Linear, "scene.json:3:4: /materials/m/albedo"}};
    try {
      const Textures tx(images, 16.0f);
      ADD_FAILURE() << file << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("scene.json:3:4: /materials/m/albedo"), std::string::npos) << e.what();
    }
  }
}

// ------------------------------------------------------------ ray cones

// A textured rectangle (half-size `half`, tilted by `tilt_deg` about x) at
// distance `d` in front of a camera with `fov` over `res` pixels.
std::string plane_scene(const std::string& texture, float d, float tilt_deg, float half, int res,
                        const std::string& filter, const std::string& extra_material = "") {
  std::ostringstream s;
  s << R"({"pathlab_scene": 1,
  "camera": {"position": [0, 0, )" << d << R"(], "look_at": [0, 0, 0], "fov_y": 40},
  "film": {"resolution": [)" << res << ", " << res << R"(]},
  "render": {"texture_filter": ")" << filter << R"(", "max_depth": 1},
  "materials": {"m": {"type": "diffuse", "albedo": {"texture": ")" << texture << R"(", "colorspace": "linear"})"
    << extra_material << R"(},
                "lamp": {"type": "emissive", "radiance": 1}},
  "shapes": [{"type": "rectangle", "material": "m", "transform": [{"scale": )" << half
    << R"(}, {"rotate": {"axis": [1, 0, 0], "angle": )" << tilt_deg << R"(}}]},
             {"type": "sphere", "material": "lamp", "center": [0, 0, 50], "radius": 1}]})";
  return s.str();
}

TEST(RayCone, CameraSpreadIsOnePixelsAngle) {
  EXPECT_NEAR(pixel_spread_angle(40.0f, 64), std::atan(2.0 * std::tan(20.0 * kPi / 180.0) / 64.0), 1e-7);
  const RayCone c{0.0f, 0.01f};
  EXPECT_FLOAT_EQ(c.width_at(4.0f), 0.04f);
  // An impulse keeps the spread, a diffuse bounce widens it to the lobe's.
  EXPECT_FLOAT_EQ(scattered_cone(c, 4.0f, true, 1.0f, TextureFilter::Cone).spread, 0.01f);
  EXPECT_FLOAT_EQ(scattered_cone(c, 4.0f, true, 1.0f, TextureFilter::Cone).width, 0.04f);
  EXPECT_NEAR(scattered_cone(c, 4.0f, false, 1.0f / kPi, TextureFilter::Cone).spread, 2.0f, 1e-6f);
  // The point filter carries no cone past a scatter either: the finest level
  // at every bounce, as at the camera (a diffuse bounce widened it to 2 rad).
  for (const bool impulse : {false, true}) {
    const RayCone p = scattered_cone(c, 4.0f, impulse, 1.0f / kPi, TextureFilter::Point);
    EXPECT_EQ(p.width, 0.0f);
    EXPECT_EQ(p.spread, 0.0f);
  }
}

// A sphere's texture coordinates (pbrt's phi and theta about z) against
// closed forms: the axes and the quarter turns exactly, u in [0, 1) across
// the seam (just below the +x axis it is just below 1, never 1 itself), v
// by theta near the poles, where acos(z) would round (z = 1 - 1e-8 is 1 in
// float, theta 1e-4 is not 0), and on random directions within a few ulp of
// libm's double atan2; sin theta too (the footprint's).
TEST(SphereUv, ClosedFormsAtAxesSeamAndPoles) {
  const auto at = [](vec3 d) {
    float sin_theta = -1.0f;
    const vec2 uv = sphere_uv(d, &sin_theta);
    return std::tuple{uv.x, uv.y, sin_theta};
  };
  const struct {
    vec3 d;
    float u, v;
  } axes[] = {{{1, 0, 0}, 0.0f, 0.5f},  {{0, 1, 0}, 0.25f, 0.5f}, {{-1, 0, 0}, 0.5f, 0.5f},
              {{0, -1, 0}, 0.75f, 0.5f}, {{0, 0, 1}, 0.0f, 1.0f},  {{0, 0, -1}, 0.0f, 0.0f}};
  for (const auto& a : axes) {
    const auto [u, v, sin_theta] = at(a.d);
    const std::string where = "at (" + std::to_string(a.d.x) + ", " + std::to_string(a.d.y) + ", " + std::to_string(a.d.z) + ")";
    EXPECT_FLOAT_EQ(u, a.u) << where;
    EXPECT_FLOAT_EQ(v, a.v) << where;
    EXPECT_FLOAT_EQ(sin_theta, std::abs(a.d.z) == 1.0f ? 0.0f : 1.0f) << where;
  }
  // The seam: just below +x, u is just below 1 (or 0 once it rounds to 1).
  const auto [u_seam, v_seam, s_seam] = at(vec3(1.0f, -1e-6f, 0.0f));
  EXPECT_LT(u_seam, 1.0f);
  EXPECT_GT(u_seam, 0.999999f);
  EXPECT_EQ(std::get<0>(at(vec3(1.0f, -1e-30f, 0.0f))), 0.0f);  // phi = -1e-30 rounds to a full turn
  // Near the pole: theta = 1e-4 gives v = 1 - 1e-4 / pi.
  const float th = 1e-4f;
  const auto [u_pole, v_pole, s_pole] = at(vec3(std::sin(th), 0.0f, std::cos(th)));
  EXPECT_NEAR(v_pole, 1.0 - 1e-4 / kPi, 1e-7);
  EXPECT_NEAR(s_pole, std::sin(th), 1e-10);
  EXPECT_LT(v_pole, 1.0f) << "theta by acos(z) in float would be 0 here";
  std::mt19937 gen(11);
  std::normal_distribution<float> normal;
  double worst_u = 0.0, worst_v = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const vec3 d = glm::normalize(vec3(normal(gen), normal(gen), normal(gen)));
    const auto [u, v, sin_theta] = at(d);
    double phi = std::atan2(double(d.y), double(d.x));
    if (phi < 0.0) phi += 2.0 * 3.14159265358979323846;
    const double u_true = phi / (2.0 * 3.14159265358979323846);
    // theta of d as it is (a float-normalised d is 1 +- 1e-7 long, which acos(z) would read as an angle).
    const double v_true = 1.0 - std::atan2(std::hypot(double(d.x), double(d.y)), double(d.z)) / 3.14159265358979323846;
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    if (u_true < 1.0 - 1e-6) worst_u = std::max(worst_u, std::abs(u - u_true));
    worst_v = std::max(worst_v, std::abs(v - v_true));
    ASSERT_NEAR(sin_theta, std::sqrt(double(d.x) * d.x + double(d.y) * d.y), 2e-7);
  }
  // A few ulp of numbers below 1 (float's ulp at 0.5..1 is 6e-8).
  EXPECT_LT(worst_u, 4e-7);
  EXPECT_LT(worst_v, 4e-7);
}

// The footprint resolve() passes to OIIO at a camera ray's hit is the
// closed form: d * spread / cos(theta) in world units, times
// sqrt(uv area / world area) = 1 / (2 half) for the rectangle. The texture
// is noise, so that every MIP level reads a different value there, and the
// test sees a footprint off by a factor of two.
TEST_F(TexturesTest, ConeFootprintAtAPlaneIsTheClosedForm) {
  write_noise(dir_ / "noise.exr", 7);
  const float d = 4.0f, tilt = 60.0f, half = 1.0f;
  const int res = 64;
  for (const std::string filter : {"cone", "point"}) {
    const Scene scene = parse_scene(plane_scene("noise.exr", d, tilt, half, res, filter), dir_ / "scene.json");
    const CompiledScene compiled{Scene(scene)};
    const RayCone cone = compiled.camera_cone(scene.render.texture_filter);
    // Slightly off the centre, so that the hit is not on the diagonal.
    const Ray ray = compiled.camera().generate_ray(vec2(0.5f * res + 0.3f, 0.5f * res - 0.2f), vec2(0.5f));
    Surfel s;
    SurfaceParams params;
    ASSERT_TRUE(compiled.intersect(ray, &s, cone, &params));
    ASSERT_EQ(s.params, &params);
    const double t = glm::length(s.p - ray.origin);
    const double cos_theta = std::abs(glm::dot(ray.dir, s.n));
    const double spread = filter == "cone" ? pixel_spread_angle(40.0f, res) : 0.0;
    const float width = static_cast<float>(t * spread / cos_theta / (2.0 * half));
    const TextureRef& ref = compiled.scene().materials[compiled.scene().shapes[0].material].textured.at(0).texture;
    const Spectrum expected = compiled.textures()->color(ref, {s.uv, width});
    expect_near(params.albedo, expected, 2e-5f, filter);
    if (filter == "cone") {
      const Spectrum doubled = compiled.textures()->color(ref, {s.uv, 2.0f * width});
      EXPECT_GT(glm::length(doubled - expected), 1e-3f) << "the test cannot tell a doubled footprint";
      EXPECT_GT(glm::length(compiled.textures()->color(ref, {s.uv, 0.0f}) - expected), 1e-3f);
    }
  }
}

// The hits through the camera at `pixels` of a textured surface placed in
// world space and of the same surface placed by an instance: the same uv and
// the same filtered texel (the footprint, of the placed geometry, large
// enough that the finest level would read something else).
void expect_placed_reads_as_world(const CompiledScene& world, const CompiledScene& placed,
                                  std::initializer_list<vec2> pixels) {
  const TextureRef& ref = world.scene().materials[0].textured.at(0).texture;
  for (const vec2 pixel : pixels) {
    const Ray ray = world.camera().generate_ray(pixel, vec2(0.5f));
    Surfel a, b;
    SurfaceParams pa, pb;
    ASSERT_TRUE(world.intersect(ray, &a, world.camera_cone(TextureFilter::Cone), &pa));
    ASSERT_TRUE(placed.intersect(ray, &b, placed.camera_cone(TextureFilter::Cone), &pb));
    ASSERT_NE(b.instance, kNoInstance);
    EXPECT_NEAR(a.uv.x, b.uv.x, 1e-5f);
    EXPECT_NEAR(a.uv.y, b.uv.y, 1e-5f);
    expect_near(pb.albedo, pa.albedo, 2e-4f, "placed against world");
    EXPECT_GT(glm::length(world.textures()->color(ref, {a.uv, 0.0f}) - pa.albedo), 1e-2f)
        << "the footprint is too small to test";
  }
}

// A textured sphere placed by an instance reads the texture over the same
// footprint as the sphere it becomes in world space: a unit sphere scaled
// 2.5 times against a sphere of radius 2.5, seen from the side (on the
// equator, away from the seam), the cone filter over a noise texture whose
// every MIP level differs. A footprint in the group's units (2.5 times too
// wide in uv) reads another level.
TEST_F(TexturesTest, PlacedSphereFiltersAsTheSphereItBecomes) {
  write_noise(dir_ / "noise.exr", 5);
  const auto scene = [&](const std::string& shapes) {
    return parse_scene(R"({"pathlab_scene": 1,
      "camera": {"position": [0, -10, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_y": 40},
      "film": {"resolution": [64, 64]},
      "render": {"max_depth": 1},
      "materials": {"m": {"type": "diffuse", "albedo": {"texture": "noise.exr", "colorspace": "linear"}}},
      )" + shapes + "}",
                       dir_ / "scene.json");
  };
  const CompiledScene world{scene(R"("shapes": [{"type": "sphere", "material": "m", "center": [0, 0, 0], "radius": 2.5}])")};
  const CompiledScene placed{scene(R"("shapes": [],
      "groups": {"ball": [{"type": "sphere", "material": "m", "center": [0, 0, 0], "radius": 1}]},
      "instances": [{"group": "ball", "transform": [{"scale": 2.5}]}])")};
  expect_placed_reads_as_world(world, placed, {vec2(32.3f, 31.8f), vec2(27.5f, 36.2f), vec2(40.1f, 30.4f)});
}

// The same for a textured rectangle (a mesh with texture coordinates)
// placed by an instance that stretches it 3 times along x and 1.5 times
// along y, then tilts it: the footprint's uv area per world area is of the
// triangle's edges placed (texture_inputs-inl.h triangle_texture_inputs),
// so it reads as the rectangle it becomes in world space does. Edges in the
// group's units, or only one of them placed, read another level.
TEST_F(TexturesTest, PlacedMeshFiltersAsTheMeshItBecomes) {
  write_noise(dir_ / "noise.exr", 9);
  const auto scene = [&](const std::string& shapes) {
    return parse_scene(R"({"pathlab_scene": 1,
      "camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "fov_y": 40},
      "film": {"resolution": [64, 64]},
      "render": {"max_depth": 1},
      "materials": {"m": {"type": "diffuse", "albedo": {"texture": "noise.exr", "colorspace": "linear"}}},
      )" + shapes + "}",
                       dir_ / "scene.json");
  };
  const std::string place = R"([{"scale": [3, 1.5, 1]}, {"rotate": {"axis": [1, 0, 0], "angle": 30}}])";
  const CompiledScene world{scene(R"("shapes": [{"type": "rectangle", "material": "m", "transform": )" + place + "}]")};
  const CompiledScene placed{scene(R"("shapes": [],
      "groups": {"quad": [{"type": "rectangle", "material": "m"}]},
      "instances": [{"group": "quad", "transform": )" + place + "}]")};
  expect_placed_reads_as_world(world, placed, {vec2(32.3f, 31.8f), vec2(24.5f, 36.2f), vec2(40.1f, 28.4f)});
}

// ------------------------------------------------------------ normal maps

TEST_F(TexturesTest, ConstantNormalMapTiltsTheShadingNormalByItsAngle) {
  write_image(dir_ / "one.exr", 1, 1, 3, {0.5f, 0.5f, 0.5f});
  for (const float alpha_deg : {10.0f, 35.0f, 70.0f}) {
    const float a = alpha_deg * kPi / 180.0f;
    for (const float scale : {1.0f, 0.5f}) {
      write_image(dir_ / "n.exr", 1, 1, 3, {0.5f + 0.5f * std::sin(a), 0.5f, 0.5f + 0.5f * std::cos(a)});
      std::ostringstream nm;
      nm << R"(, "normal_map": {"texture": "n.exr", "scale": )" << scale << "}";
      // The rectangle faces +z; its u runs along +x, v along +y.
      const Scene scene = parse_scene(plane_scene("one.exr", 4.0f, 0.0f, 1.0f, 16, "cone", nm.str()), dir_ / "s.json");
      const CompiledScene compiled{Scene(scene)};
      Surfel s;
      SurfaceParams params;
      const Ray ray = compiled.camera().generate_ray(vec2(8.3f, 7.6f), vec2(0.5f));
      ASSERT_TRUE(compiled.intersect(ray, &s, compiled.camera_cone(TextureFilter::Cone), &params));
      const vec3 expected = glm::normalize(vec3(scale * std::sin(a), 0.0f, std::cos(a)));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.frame.n[c], expected[c], 1e-5f) << alpha_deg << " deg, scale " << scale;
      EXPECT_TRUE(s.shading_normal);
      EXPECT_NEAR(glm::dot(s.frame.s, s.frame.n), 0.0f, 1e-6f);
      EXPECT_NEAR(glm::length(s.frame.s), 1.0f, 1e-6f);
      EXPECT_NEAR(std::abs(glm::dot(glm::cross(s.frame.s, s.frame.t), s.frame.n)), 1.0f, 1e-5f);
    }
  }
}

// A flat map, (0.5, 0.5, 1) exactly, renders the bits of no map on the same
// mesh (with the same tangents).
TEST_F(TexturesTest, FlatNormalMapRendersTheBitsOfNoMap) {
  write_image(dir_ / "one.exr", 1, 1, 3, {0.5f, 0.5f, 0.5f});
  write_image(dir_ / "flat.exr", 1, 1, 3, {0.5f, 0.5f, 1.0f});
  auto image = [&](bool map) {
    Scene scene = parse_scene(plane_scene("one.exr", 4.0f, 30.0f, 1.0f, 12, "cone",
                                          map ? R"(, "normal_map": {"texture": "flat.exr"})" : ""),
                              dir_ / "s.json");
    scene.render.max_depth = 3;
    scene.render.spp = 4;
    if (!map) scene.shapes[0].mesh.tangents = compute_tangents(scene.shapes[0].mesh);
    const CompiledScene compiled(std::move(scene));
    const ReferenceTracer tracer(compiled, compiled.scene().render);
    Film film(12, 12, FilterKind::Box);
    render(tracer, film);
    return film.image();
  };
  const Image a = image(true), b = image(false);
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(vec3)), 0);
}

// Textures larger than the cache render correctly: OpenImageIO's cache
// evicts and reloads tiles, and the image is the same, bit for bit, as with a
// cache that holds everything. 24 MB of float texels and a 1024^2 sRGB image
// against a 1 MB cache, through both filters.
TEST_F(TexturesTest, TexturesLargerThanTheCacheRenderTheSameBits) {
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> big(1024 * 1024 * 3);
  for (float& v : big) v = u(gen);
  write_image(dir_ / "big.exr", 1024, 1024, 3, big);
  for (float& v : big) v = u(gen);
  write_image(dir_ / "big2.exr", 1024, 1024, 3, big);
  write_image(dir_ / "big.png", 1024, 1024, 3, big, OIIO::TypeDesc::UINT8);
  for (const char* filter : {"cone", "point"}) {
    auto image = [&](int cache_mb) {
      std::string text = plane_scene("big.exr", 1.5f, 50.0f, 1.0f, 48, filter,
                                     R"(, "normal_map": {"texture": "big2.exr", "scale": 0.3})");
      const auto swap = [&](const std::string& from, const std::string& to) {
        ASSERT_NE(text.find(from), std::string::npos) << from;
        text.replace(text.find(from), from.size(), to);
      };
      swap(R"("max_depth": 1)", R"("max_depth": 2, "texture_cache_mb": )" + std::to_string(cache_mb));
      swap(R"("lamp": {"type": "emissive", "radiance": 1})",
           R"("lamp": {"type": "emissive", "radiance": {"texture": "big.png"}})");
      Scene scene = parse_scene(text, dir_ / "s.json");
      scene.render.spp = 4;
      const CompiledScene compiled(std::move(scene));
      const ReferenceTracer tracer(compiled, compiled.scene().render);
      Film film(48, 48, FilterKind::Box);
      render(tracer, film);
      return film.image();
    };
    const Image small = image(1), large = image(512);
    EXPECT_EQ(std::memcmp(small.pixels.data(), large.pixels.data(), small.pixels.size() * sizeof(vec3)), 0) << filter;
  }
}

// The albedo AOV shows what a textured surface's hits read, not the
// material's constant.
TEST_F(TexturesTest, AlbedoAovReadsTheTexture) {
  write_image(dir_ / "c.exr", 1, 1, 3, {0.3f, 0.6f, 0.9f});
  // A large rectangle filling the view.
  const CompiledScene compiled(parse_scene(plane_scene("c.exr", 2.0f, 0.0f, 5.0f, 8, "cone"), dir_ / "s.json"));
  const ReferenceTracer tracer(compiled, compiled.scene().render);
  AovAccumulator aovs(compiled, compiled.scene().render);
  Film film(8, 8, FilterKind::Box);
  render(AovTracer(tracer, aovs), film);
  const Image albedo = aovs.albedo();
  for (const vec3& p : albedo.pixels) expect_near(p, Spectrum(0.3f, 0.6f, 0.9f), 1e-6f, "albedo AOV");
}

// ------------------------------------------------------------ textured emission

// A textured emitter over a floor, sampled as a light ("light": true: MIS
// with light sampling) and found only by rays ("light": false): both
// estimate the same image, in both tracers, for a rectangle (the light
// sample's texel at the triangle's barycentrics, a hit's at its uv) and a
// sphere (sphere_uv of the light sample's point from the centre, and the
// hit's, in the wavefront's lanes). Compared on the four quadrants of the
// image, each channel, by a z-test Šidák-corrected for the 48 comparisons
// at alpha = 1e-3 (fixed seeds; the variances are the films' own estimates).
TEST_F(TexturesTest, TexturedEmitterAsLightAndAsSurfaceAgree) {
  // 4x4 emission texels from 0 to ~3 (linear), very non-uniform.
  std::vector<float> texels;
  for (int i = 0; i < 16; ++i) texels.insert(texels.end(), {0.2f * i, 0.05f * (15 - i), (i % 3) * 0.8f});
  write_image(dir_ / "emit.exr", 4, 4, 3, texels);
  const double z_max = test::sidak_z(1e-3, 48);
  for (const bool sphere : {false, true})
    for (const bool wavefront : {false, true}) {
      SCOPED_TRACE(std::string(sphere ? "sphere" : "rectangle") + (wavefront ? ", wavefront" : ", reference"));
      auto render_image = [&](bool light) {
        const std::string lamp =
            sphere ? R"({"type": "sphere", "material": "lamp", "center": [0.3, 1.0, 0], "radius": 0.45})"
                   : R"({"type": "rectangle", "material": "lamp", "transform": [{"scale": 0.8}, {"rotate": {"axis": [1, 0, 0], "angle": 90}}, {"translate": [0.3, 1.2, 0]}]})";
        const std::string text = std::string(R"({"pathlab_scene": 1,
          "camera": {"position": [0, 3, 3], "look_at": [0, 0, 0], "fov_y": 50},
          "film": {"resolution": [16, 16]},
          "render": {"spp": 256, "max_depth": 1, "strategy": "mis", "seed": 5},
          "materials": {"floor": {"type": "diffuse", "albedo": 0.8},
                        "lamp": {"type": "emissive", "radiance": {"texture": "emit.exr", "colorspace": "linear", "scale": 4}, "light": )") +
                                 (light ? "true" : "false") + R"(}},
          "shapes": [{"type": "rectangle", "material": "floor", "transform": [{"scale": 3}, {"rotate": {"axis": [1, 0, 0], "angle": -90}}]},
                     )" + lamp + "]}";
        const CompiledScene compiled(parse_scene(text, dir_ / "s.json"));
        EXPECT_EQ(compiled.lights().area_light_count(), light ? (sphere ? 1u : 2u) : 0u);
        Film film(16, 16, FilterKind::Box, FilmMoments::MeanAndVariance);
        if (wavefront)
          render(WavefrontTracer(compiled, compiled.scene().render), film);
        else
          render(ReferenceTracer(compiled, compiled.scene().render), film);
        return film;
      };
      const Film a = render_image(true), b = render_image(false);
      for (int q = 0; q < 4; ++q)
        for (int c = 0; c < 3; ++c) {
          double ma = 0, mb = 0, va = 0, vb = 0;
          for (int y = (q / 2) * 8; y < (q / 2) * 8 + 8; ++y)
            for (int x = (q % 2) * 8; x < (q % 2) * 8 + 8; ++x) {
              ma += a.mean(x, y)[c], mb += b.mean(x, y)[c];
              va += a.variance_of_mean(x, y)[c], vb += b.variance_of_mean(x, y)[c];
            }
          const double z = (ma - mb) / std::sqrt(va + vb);
          EXPECT_LT(std::abs(z), z_max) << "quadrant " << q << " channel " << c << ": " << ma / 64 << " vs " << mb / 64;
        }
    }
}

}  // namespace
}  // namespace pathlab
