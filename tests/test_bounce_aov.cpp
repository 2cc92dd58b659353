// The per-bounce layers (render --aov bounces, debugtools/bounce_aov.h) and
// the wavefront's stage buffers (render --dump-stage-buffers,
// debugtools/stage_buffers.h).
//
//   - closed form: in a furnace under BSDF sampling every sample's layer d
//     is exactly Le rho^d (the Lambert weight is rho, every ray finds Le);
//   - every sample's layers sum to its radiance, and a box film's pixel to
//     the sum of the layers' means (both tracers, NEE and delta lights);
//   - the CLI writes the layers as named EXR channels and refuses --clamp;
//   - the stage buffers: the camera rays' throughput is 1, the paths that
//     survive bounce K are exactly those that reach K + 1, and recording
//     leaves the samples' bits alone.
#include "apps/cli/cli.h"
#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/render.h"
#include "debugtools/bounce_aov.h"
#include "debugtools/compare.h"
#include "debugtools/stage_buffers.h"
#include "debugtools/tracers.h"
#include "reference/reference_tracer.h"
#include "tests/temp_dir.h"
#include "tests/test_scenes.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <sstream>

namespace pathlab {
namespace {

const char* const kTracers[] = {"reference", "wavefront"};

TEST(BounceLayers, FurnaceLayerDIsLeTimesRhoToTheD) {
  constexpr float Le = 0.5f, rho = 0.7f;
  constexpr int max_depth = 10;  // depths 0..10: 8, 9 and 10 in the rest layer
  Scene scene = test::furnace_scene(Le, rho, max_depth, 100, Strategy::Bsdf, 4);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  for (const char* name : kTracers) {
    const auto tracer = make_tracer(name, compiled, settings);
    for (std::uint32_t s = 0; s < 4; ++s) {
      BounceObserver obs;
      tracer->trace_sample(1, 2, s, &obs);
      double rest = 0.0;
      for (int d = 0; d <= max_depth; ++d) {
        const double want = Le * std::pow(static_cast<double>(rho), d);
        if (d >= kBounceDepths) {
          rest += want;
          continue;
        }
        const Spectrum& got = obs.layers.L[static_cast<std::size_t>(d)][0];
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want, 1e-6 * want) << name << " L" << d;
        EXPECT_EQ(obs.layers.L[static_cast<std::size_t>(d)][1], Spectrum(0.0f)) << name << " L" << d << ".nee";
      }
      EXPECT_NEAR(obs.layers.L[kBounceDepths][0].x, rest, 1e-6 * rest) << name << " rest";
    }
  }
}

// A box film of the samples BounceTracer rendered, and their layers.
struct BounceRender {
  BounceRender(Scene scene, const char* tracer_name)
      : compiled(std::move(scene)),
        tracer(make_tracer(tracer_name, compiled, compiled.scene().render)),
        bounces(compiled.scene().film.width, compiled.scene().film.height),
        film(compiled.scene().film.width, compiled.scene().film.height, FilterKind::Box) {
    render(BounceTracer(*tracer, bounces), film);
  }
  const CompiledScene compiled;
  const std::unique_ptr<Tracer> tracer;
  BounceAccumulator bounces;
  Film film;
};

TEST(BounceLayers, SumToTheSampleAndToThePixel) {
  for (const bool delta : {false, true})
    for (const char* name : kTracers) {
      Scene scene = delta ? test::cornell_with_delta_lights() : builtin_cornell_box();
      scene.film.width = 12;
      scene.film.height = 10;
      scene.film.filter = FilterKind::Box;
      scene.render.spp = 6;
      scene.render.strategy = delta ? Strategy::LightBsdf : Strategy::Mis;
      const BounceRender r(std::move(scene), name);
      const std::string what = std::string(name) + (delta ? " delta lights" : " cornell");
      // Per sample: the layers against the radiance the tracer returned.
      int nonzero_nee = 0, deep = 0;
      for (std::uint32_t y = 0; y < 10; ++y)
        for (std::uint32_t x = 0; x < 12; ++x)
          for (std::uint32_t s = 0; s < 6; ++s) {
            BounceObserver obs;
            const FilmSample fs = r.tracer->trace_sample(x, y, s, &obs);
            const Spectrum sum = obs.layers.total();
            for (int c = 0; c < 3; ++c)
              ASSERT_NEAR(sum[c], fs.L[c], 1e-5f * std::max(1.0f, std::abs(fs.L[c])))
                  << what << " pixel " << x << "," << y << " sample " << s;
            nonzero_nee += is_black(obs.layers.L[1][1]) ? 0 : 1;
            deep += is_black(obs.layers.L[3][0] + obs.layers.L[3][1]) ? 0 : 1;
          }
      EXPECT_GT(nonzero_nee, 0) << what;  // the test sees both techniques and several depths
      EXPECT_GT(deep, 0) << what;
      // Per pixel: the film's mean against the sum of the layers' means.
      Image sum(12, 10);
      for (int d = 0; d < kBounceLayers; ++d)
        for (Technique t : {Technique::Bsdf, Technique::Nee}) {
          const Image m = r.bounces.mean(d, t);
          for (std::size_t i = 0; i < sum.pixels.size(); ++i) sum.pixels[i] += m.pixels[i];
        }
      for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 12; ++x)
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(sum.at(x, y)[c], r.film.mean(x, y)[c], 1e-5f * std::max(1.0f, r.film.mean(x, y)[c]))
                << what << " pixel " << x << "," << y;
    }
}

using BounceCli = test::TempDirTest;

TEST_F(BounceCli, RenderWritesTheLayersAndRefusesClamp) {
  const std::string exr = (dir_ / "b.exr").string();
  const char* args[] = {"pathlab", "render", "--resolution", "8x6", "--spp", "2", "-q", "-o", exr.c_str(), "--aov", "bounces"};
  std::ostringstream out, err;
  ASSERT_EQ(cli::run(static_cast<int>(std::size(args)), args, out, err), 0) << err.str();
  auto in = OIIO::ImageInput::open(exr);
  ASSERT_TRUE(in);
  const auto& names = in->spec().channelnames;
  ASSERT_EQ(names.size(), 3u + 3u * kTechniques * kBounceLayers);
  EXPECT_EQ(names[0], "R");
  for (const char* want : {"L0.bsdf.R", "L0.nee.B", "L7.nee.G", "Lrest.bsdf.R", "Lrest.nee.B"})
    EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;

  const char* clamp[] = {"pathlab", "render", "--resolution", "8x6", "--spp", "2", "-q", "-o", exr.c_str(), "--aov",
                         "bounces", "--clamp", "4"};
  std::ostringstream out2, err2;
  EXPECT_EQ(cli::run(static_cast<int>(std::size(clamp)), clamp, out2, err2), 2);
  EXPECT_NE(err2.str().find("--aov bounces"), std::string::npos) << err2.str();
}

TEST(StageBuffers, ArraysAtBounceKAndTheirHandOverToKPlus1) {
  Scene scene = builtin_cornell_box();
  scene.film.width = 10;
  scene.film.height = 8;
  scene.render.rr_depth = 1;  // roulette from vertex 2 on: survival < 1
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const WavefrontTracer wavefront(compiled, settings, 256);
  constexpr std::uint32_t spp = 8;
  const std::size_t n = 10 * 8 * spp;
  std::vector<FilmSample> plain(n);
  wavefront.render_batch(0, spp, plain);
  std::vector<std::vector<StageRecord>> records(4, std::vector<StageRecord>(n));
  for (int k = 1; k <= 3; ++k) {
    std::vector<FilmSample> out(n);
    wavefront.render_batch_recording(0, spp, out, k, records[static_cast<std::size_t>(k)]);
    for (std::size_t i = 0; i < n; ++i) ASSERT_TRUE(out[i].L == plain[i].L && out[i].rays == plain[i].rays) << i;
  }
  int light_samples = 0, died = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const StageRecord& cam = records[1][i];
    ASSERT_TRUE(cam.reached);
    EXPECT_EQ(cam.throughput, Spectrum(1.0f));
    EXPECT_NEAR(glm::length(cam.dir), 1.0f, 1e-5f);
    for (int k = 1; k <= 2; ++k) {
      const StageRecord& r = records[static_cast<std::size_t>(k)][i];
      const StageRecord& next = records[static_cast<std::size_t>(k) + 1][i];
      EXPECT_EQ(r.survived, next.reached) << "sample " << i << " bounce " << k;
      if (r.reached && !r.survived) ++died;
      if (r.light_sampled) {
        ++light_samples;
        EXPECT_GT(r.light_pdf, 0.0f);
      }
      if (r.reached && std::isfinite(r.distance)) {
        EXPECT_GT(r.distance, 0.0f);
      }
    }
  }
  EXPECT_GT(light_samples, 0);
  EXPECT_GT(died, 0);

  // Splatted: reached(K + 1) = reached(K) x survival(K), pixel by pixel.
  StageBuffers b2(10, 8, 2), b3(10, 8, 3);
  b2.add_batch(spp, records[2]);
  b3.add_batch(spp, records[3]);
  const Image r2 = b2.reached(), s2 = b2.survival(), r3 = b3.reached();
  for (std::size_t p = 0; p < r2.pixels.size(); ++p)
    EXPECT_NEAR(r3.pixels[p].x, r2.pixels[p].x * s2.pixels[p].x, 1e-6f) << p;
}

using StageCli = test::TempDirTest;

TEST_F(StageCli, DumpWritesOneExrPerArrayAndRefusesTheReference) {
  const std::string exr = (dir_ / "s.exr").string(), folder = (dir_ / "stages").string();
  const char* args[] = {"pathlab", "render", "--resolution", "8x6", "--spp", "2", "-q", "-o", exr.c_str(),
                        "--tracer", "wavefront", "--dump-stage-buffers", "2", folder.c_str()};
  std::ostringstream out, err;
  ASSERT_EQ(cli::run(static_cast<int>(std::size(args)), args, out, err), 0) << err.str();
  for (const char* name : {"reached", "throughput", "direction", "distance", "survival", "light_pdf"})
    EXPECT_TRUE(std::filesystem::exists(dir_ / "stages" / (std::string("bounce2-") + name + ".exr"))) << name;

  const char* reference[] = {"pathlab", "render", "--resolution", "8x6", "--spp", "2", "-q", "-o", exr.c_str(),
                             "--dump-stage-buffers", "2", folder.c_str()};
  std::ostringstream out2, err2;
  EXPECT_EQ(cli::run(static_cast<int>(std::size(reference)), reference, out2, err2), 2);
  EXPECT_NE(err2.str().find("--tracer wavefront"), std::string::npos) << err2.str();
  const char* zero[] = {"pathlab", "render", "--resolution", "8x6", "--spp", "2", "-q", "-o", exr.c_str(),
                        "--tracer", "wavefront", "--dump-stage-buffers", "0", folder.c_str()};
  std::ostringstream out3, err3;
  EXPECT_EQ(cli::run(static_cast<int>(std::size(zero)), zero, out3, err3), 2);
  EXPECT_NE(err3.str().find("--dump-stage-buffers 0: K must be"), std::string::npos) << err3.str();
}

}  // namespace
}  // namespace pathlab
