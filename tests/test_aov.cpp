// render --aov: the AOVs come out as named EXR layers whose values follow
// from the scene (albedo of the wall a pixel sees, unit normals, positive
// depths), the film (variance) and the tracer's FilmSamples (path length).
#include "apps/cli/cli.h"
#include "debugtools/tracers.h"
#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/image_io.h"
#include "core/render.h"
#include "debugtools/aov.h"
#include "debugtools/material_override.h"
#include "debugtools/path_recorder.h"
#include "tests/temp_dir.h"
#include "tests/test_scenes.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <map>
#include <sstream>

namespace pathlab {
namespace {

using AovTest = test::TempDirTest;

// Every channel of an EXR, by name.
std::map<std::string, std::vector<float>> read_channels(const std::filesystem::path& file, int* w, int* h) {
  auto in = OIIO::ImageInput::open(file.string());
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  const OIIO::ImageSpec spec = in->spec();
  *w = spec.width;
  *h = spec.height;
  std::vector<float> all(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeFloat, all.data()));
  std::map<std::string, std::vector<float>> out;
  for (int c = 0; c < spec.nchannels; ++c) {
    auto& v = out[spec.channelnames[static_cast<std::size_t>(c)]];
    for (std::size_t i = 0; i < all.size() / spec.nchannels; ++i) v.push_back(all[i * spec.nchannels + c]);
  }
  return out;
}

TEST_F(AovTest, RenderWritesNamedLayers) {
  const std::string exr = (dir_ / "aov.exr").string(), plain = (dir_ / "plain.exr").string();
  const char* with[] = {"pathlab", "render", "--resolution", "32x32", "--spp", "4", "-q", "-o", exr.c_str(),
                        "--aov", "albedo,normal,depth,variance,pathlength,material"};
  const char* without[] = {"pathlab", "render", "--resolution", "32x32", "--spp", "4", "-q", "-o", plain.c_str()};
  std::ostringstream out, err;
  ASSERT_EQ(cli::run(static_cast<int>(std::size(with)), with, out, err), 0) << err.str();
  ASSERT_EQ(cli::run(static_cast<int>(std::size(without)), without, out, err), 0) << err.str();

  int w = 0, h = 0;
  auto ch = read_channels(exr, &w, &h);
  ASSERT_EQ(w, 32);
  for (const char* name : {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z",
                           "depth.Z", "variance.R", "variance.G", "variance.B", "pathlength.Y", "material.Y"})
    EXPECT_EQ(ch.count(name), 1u) << name;
  EXPECT_EQ(ch.size(), 15u);

  // The beauty channels equal the plain render, and read_image (diff, check)
  // still finds them first.
  const Image beauty = read_image(plain), layered = read_image(exr);
  for (std::size_t i = 0; i < beauty.pixels.size(); ++i) {
    ASSERT_EQ(beauty.pixels[i], layered.pixels[i]) << i;
    ASSERT_EQ(ch["R"][i], beauty.pixels[i].x);
  }

  // Pixel (1, 16) sees only the red wall, straight on from the side.
  const std::size_t red = 16 * 32 + 1;
  EXPECT_FLOAT_EQ(ch["albedo.R"][red], 0.63f);
  EXPECT_FLOAT_EQ(ch["albedo.G"][red], 0.065f);
  EXPECT_NEAR(ch["normal.X"][red], 1.0f, 1e-5f);  // the red wall faces +x
  EXPECT_GT(ch["depth.Z"][red], 3.0f);
  EXPECT_LT(ch["depth.Z"][red], 5.0f);
  EXPECT_EQ(ch["material.Y"][red], 2.0f);  // white, red, green, light
  for (std::size_t i = 0; i < ch["pathlength.Y"].size(); ++i) {
    EXPECT_GE(ch["pathlength.Y"][i], 1.0f) << i;  // the box is closed behind the camera's view
    EXPECT_LE(ch["pathlength.Y"][i], 17.0f) << i;
    EXPECT_GE(ch["variance.R"][i], 0.0f);
  }
}

// A small Cornell box rendered by the render driver through AovTracer.
struct AovRender {
  AovRender(int res, int spp, FilterKind filter, const std::string& tracer_name)
      : compiled(test::small_cornell(res, spp, filter)),
        tracer(make_tracer(tracer_name, compiled, compiled.scene().render)),
        aovs(compiled, compiled.scene().render),
        film(res, res, filter) {
    render(AovTracer(*tracer, aovs), film);
  }
  const CompiledScene compiled;
  const std::unique_ptr<Tracer> tracer;
  AovAccumulator aovs;
  Film film;
};

TEST(Aov, PathLengthIsTheMeanOfTheSamplesHitsAndVarianceIsTheFilms) {
  AovRender r(12, 3, FilterKind::Box, "wavefront");
  const auto& [compiled, tracer, aovs, film] = r;

  std::vector<FilmSample> direct(12 * 12 * 3);
  tracer->render_batch(0, 3, direct);
  const Image pl = aovs.path_length();
  for (int p = 0; p < 12 * 12; ++p) {
    const float mean = static_cast<float>(direct[p * 3].hits + direct[p * 3 + 1].hits + direct[p * 3 + 2].hits) / 3.0f;
    EXPECT_FLOAT_EQ(pl.pixels[static_cast<std::size_t>(p)].x, mean) << p;
  }
  const std::vector<ExrChannel> ch = aov_channels(film, aovs, std::vector<Aov>{Aov::Variance});
  ASSERT_EQ(ch.size(), 6u);
  EXPECT_EQ(ch[3].name, "variance.R");
  EXPECT_EQ(ch[3].values[40], film.variance_of_mean(4, 3).x);
}

// The AOV pass casts the tracer's own camera rays: its depth and material
// buffers agree with the first hits recorded by replaying every sample.
TEST(Aov, FirstSurfaceBuffersFollowTheTracersCameraRays) {
  AovRender r(8, 3, FilterKind::Bilinear, "reference");
  const auto& [compiled, tracer, aovs, film] = r;
  const Image depth = aovs.depth(), material = aovs.material();
  for (std::uint32_t y = 0; y < 8; ++y) {
    for (std::uint32_t x = 0; x < 8; ++x) {
      double sum = 0.0;
      int hits = 0, first_material = -1;
      for (std::uint32_t s = 0; s < 3; ++s) {
        PathRecorder rec;
        tracer->trace_sample(x, y, s, &rec);
        const auto& cam = std::get<CameraEvent>(rec.events().at(0));
        if (const auto* h = std::get_if<HitEvent>(&rec.events().at(1))) {
          sum += glm::length(h->p - cam.origin);
          ++hits;
          if (s == 0) first_material = static_cast<int>(h->material);
        }
      }
      const float want = hits ? static_cast<float>(sum / hits) : 0.0f;
      EXPECT_NEAR(depth.at(static_cast<int>(x), static_cast<int>(y)).x, want, 1e-4f * (1.0f + want)) << x << "," << y;
      EXPECT_EQ(material.at(static_cast<int>(x), static_cast<int>(y)).x, static_cast<float>(first_material));
    }
  }
}

TEST(MaterialOverride, KeepsEmissionAndReplacesScattering) {
  const Scene cornell = builtin_cornell_box();
  const Scene white = override_materials(cornell, MaterialOverride::WhiteLambert);
  const Scene mirror = override_materials(cornell, MaterialOverride::Mirror);
  ASSERT_EQ(white.materials.size(), cornell.materials.size());
  for (std::size_t i = 0; i < cornell.materials.size(); ++i) {
    const Material& m = cornell.materials[i];
    EXPECT_EQ(white.materials[i].emission, m.emission);
    EXPECT_EQ(mirror.materials[i].emission, m.emission);
    EXPECT_EQ(white.materials[i].name, m.name);
    if (m.type == MaterialType::Emissive) {
      EXPECT_EQ(white.materials[i].type, MaterialType::Emissive);
      continue;
    }
    EXPECT_EQ(white.materials[i].type, MaterialType::Diffuse);
    EXPECT_EQ(white.materials[i].albedo, Spectrum(1.0f));
    EXPECT_EQ(mirror.materials[i].type, MaterialType::Mirror);
  }
  EXPECT_EQ(parse_material_override("mirror"), MaterialOverride::Mirror);
  EXPECT_FALSE(parse_material_override("chrome"));
}

}  // namespace
}  // namespace pathlab
