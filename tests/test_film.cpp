// The film: gathering, variance, NaN handling, and thread-count independence.
#include "apps/cli/cli.h"
#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "core/render.h"
#include "reference/reference_tracer.h"
#include "tests/temp_dir.h"
#include "tests/test_scenes.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace pathlab {
namespace {

TEST(Film, BoxFilterMeanAndVarianceOfMean) {
  Film film(2, 1, FilterKind::Box);
  // Pixel 0 gets 1, 2, 3, 6; pixel 1 gets 5 four times.
  const float values[4] = {1, 2, 3, 6};
  std::vector<FilmSample> s(2 * 4);
  for (int j = 0; j < 4; ++j) {
    s[j] = {vec2(0.3f, 0.5f), Spectrum(values[j]), 1};
    s[4 + j] = {vec2(1.7f, 0.2f), Spectrum(5.0f), 1};
  }
  film.add_batch(0, 4, s);
  EXPECT_FLOAT_EQ(film.mean(0, 0).x, 3.0f);
  // Sample variance (n - 1 denominator) 14/3, divided by n = 4.
  EXPECT_NEAR(film.variance_of_mean(0, 0).x, (14.0 / 3.0) / 4.0, 1e-6);
  EXPECT_FLOAT_EQ(film.mean(1, 0).y, 5.0f);
  EXPECT_EQ(film.variance_of_mean(1, 0).y, 0.0f);
  EXPECT_EQ(film.sample_count(0, 0), 4u);
}

TEST(Film, SumsTheRaysOfEverySampleItIsGiven) {
  // A NaN sample is left out of the image, but its rays were cast all the
  // same; with a splatting filter each sample counts once, not once per
  // pixel it lands in.
  for (FilterKind filter : {FilterKind::Box, FilterKind::Bilinear}) {
    Film film(2, 2, filter);
    std::vector<FilmSample> s(4 * 2);
    for (std::uint32_t i = 0; i < s.size(); ++i)
      s[i] = {vec2(float(i / 2 % 2) + 0.5f, float(i / 4) + 0.5f), Spectrum(1.0f), i + 1};
    s[5].L = Spectrum(std::nanf(""));
    film.add_batch(0, 2, s);
    EXPECT_EQ(film.rays_cast(), 36u);  // 1 + 2 + ... + 8
    film.add_batch(2, 2, s);
    EXPECT_EQ(film.rays_cast(), 72u);
    EXPECT_EQ(film.bad_sample_count(), 2u);
  }
}

// A film that keeps only the mean gives the same image bits as one that
// keeps the variance too, for either filter and with a NaN among the
// samples; asked for a variance, it says it has none.
TEST(Film, MeanOnlyFilmHasTheSameImage) {
  for (FilterKind filter : {FilterKind::Box, FilterKind::Bilinear}) {
    std::vector<FilmSample> s(9 * 3);
    for (std::uint32_t i = 0; i < s.size(); ++i) {
      const float k = static_cast<float>(i) * 0.77f;
      s[i] = {vec2(float(i / 3 % 3) + std::fmod(k * 0.37f, 1.0f), float(i / 9) + std::fmod(k * 0.61f, 1.0f)),
              Spectrum(k, 1.0f / (k + 1.0f), std::sqrt(k)), 2};
    }
    s[4].L.y = std::nanf("");
    Film full(3, 3, filter), mean(3, 3, filter, FilmMoments::Mean);
    full.add_batch(0, 3, s);
    mean.add_batch(0, 3, s);
    const Image a = full.image(), b = mean.image();
    EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(vec3)), 0);
    EXPECT_EQ(mean.sample_count(1, 1), full.sample_count(1, 1));
    EXPECT_EQ(mean.bad_sample_count(), 1u);
    EXPECT_TRUE(full.keeps_variance());
    EXPECT_FALSE(mean.keeps_variance());
    EXPECT_THROW(mean.variance_of_mean(), std::logic_error);
    EXPECT_THROW(mean.variance_of_mean(0, 0), std::logic_error);
  }
}

TEST(Film, BatchesAddUpToOneBigBatch) {
  // Two batches of 2 give the same bits as one batch of 4.
  auto make = [](std::uint32_t first, std::uint32_t count) {
    std::vector<FilmSample> s(9 * count);
    for (std::uint32_t p = 0; p < 9; ++p)
      for (std::uint32_t j = 0; j < count; ++j) {
        const float k = static_cast<float>(p * 7 + (first + j) * 3);
        s[p * count + j] = {vec2(float(p % 3) + std::fmod(k * 0.37f, 1.0f), float(p / 3) + std::fmod(k * 0.61f, 1.0f)),
                            Spectrum(k, 1.0f / (k + 1.0f), std::sqrt(k)), 1};
      }
    return s;
  };
  Film a(3, 3, FilterKind::Bilinear), b(3, 3, FilterKind::Bilinear);
  a.add_batch(0, 4, make(0, 4));
  b.add_batch(0, 2, make(0, 2));
  b.add_batch(2, 2, make(2, 2));
  const Image ia = a.image(), ib = b.image();
  EXPECT_EQ(std::memcmp(ia.pixels.data(), ib.pixels.data(), ia.pixels.size() * sizeof(vec3)), 0);
}

TEST(Film, BilinearSplatsWithTentWeights) {
  Film film(2, 1, FilterKind::Bilinear);
  // A sample at x = 0.75 lies a quarter pixel right of pixel 0's centre:
  // weight 0.75 to pixel 0, 0.25 to pixel 1. Pixel 1's own sample at its
  // centre has weight 1 for it and 0 for pixel 0.
  std::vector<FilmSample> s = {{vec2(0.75f, 0.5f), Spectrum(4.0f), 1}, {vec2(1.5f, 0.5f), Spectrum(0.0f), 1}};
  film.add_batch(0, 1, s);
  EXPECT_FLOAT_EQ(film.mean(0, 0).x, 4.0f);
  EXPECT_FLOAT_EQ(film.mean(1, 0).x, 0.25f * 4.0f / 1.25f);
}

TEST(Film, NanAndInfSamplesAreLeftOutCountedAndLocated) {
  Film film(2, 2, FilterKind::Box);
  std::vector<FilmSample> s(4 * 2, FilmSample{vec2(0.5f), Spectrum(1.0f), 1});
  for (int p = 0; p < 4; ++p)
    for (int j = 0; j < 2; ++j) s[p * 2 + j].film = vec2(float(p % 2) + 0.5f, float(p / 2) + 0.5f);
  s[3 * 2 + 1].L = Spectrum(std::nanf(""), 0.0f, 0.0f);  // pixel (1,1), sample 5 + 1
  s[1 * 2 + 0].L.y = kInfinity;                           // pixel (1,0), sample 5
  film.add_batch(5, 2, s);
  EXPECT_EQ(film.bad_sample_count(), 2u);
  ASSERT_EQ(film.bad_samples().size(), 2u);
  EXPECT_EQ(film.bad_samples()[0].x, 1u);
  EXPECT_EQ(film.bad_samples()[0].y, 0u);
  EXPECT_EQ(film.bad_samples()[0].sample, 5u);
  EXPECT_EQ(film.bad_samples()[1].x, 1u);
  EXPECT_EQ(film.bad_samples()[1].y, 1u);
  EXPECT_EQ(film.bad_samples()[1].sample, 6u);
  const Image img = film.image();
  for (const vec3& p : img.pixels) EXPECT_EQ(p, vec3(1.0f));
  EXPECT_EQ(film.sample_count(1, 1), 1u);
}

TEST(Film, BilinearLeavesANanOutOfItsNeighboursToo) {
  // Pixel 1's NaN sample lies 0.3 px from pixel 0's centre line, inside its
  // tent: pixel 0 must neither take it in nor count it.
  Film film(2, 1, FilterKind::Bilinear);
  std::vector<FilmSample> s = {{vec2(0.5f, 0.5f), Spectrum(2.0f), 1},
                               {vec2(1.2f, 0.5f), Spectrum(std::nanf(""), 1.0f, 1.0f), 1}};
  film.add_batch(0, 1, s);
  EXPECT_EQ(film.bad_sample_count(), 1u);
  EXPECT_EQ(film.mean(0, 0), Spectrum(2.0f));
  EXPECT_EQ(film.mean(1, 0), Spectrum(0.0f));  // its only sample was bad; pixel 0's lies outside its tent
  EXPECT_EQ(film.sample_count(0, 0), 1u);
  EXPECT_EQ(film.sample_count(1, 0), 0u);
  EXPECT_EQ(film.variance_of_mean(0, 0), Spectrum(0.0f));
}

Image render_with_threads(const Scene& scene_in, int threads) {
  const ThreadLimit limit(threads);
  Scene scene = scene_in;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  Film film(compiled.scene().film.width, compiled.scene().film.height, compiled.scene().film.filter);
  render(tracer, film);
  return film.image();
}

TEST(Film, SameBitsForOneAndTwoThreads) {
  for (FilterKind filter : {FilterKind::Box, FilterKind::Bilinear}) {
    const Scene scene = test::small_cornell(24, 8, filter);
    const Image a = render_with_threads(scene, 1), b = render_with_threads(scene, 2);
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(vec3)), 0);
  }
}

// tools/run-tsan.sh's proof that its ThreadSanitizer run can fail: with
// PATHLAB_TSAN_PLANTED_RACE=1 the chunks of a parallel_for on two threads
// add to one plain counter, and the run must report a data race. Skipped
// otherwise (in every ordinary run).
TEST(Parallel, PlantedRaceForThreadSanitizer) {
  if (std::getenv("PATHLAB_TSAN_PLANTED_RACE") == nullptr) GTEST_SKIP() << "only for tools/run-tsan.sh";
  const ThreadLimit two(2);
  long counter = 0;
  parallel_for(0, 64, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      counter = counter + 1;
      std::this_thread::yield();
    }
  });
  EXPECT_GT(counter, 0);
}

// The user-facing promise: `pathlab render --threads 1` and `--threads 2`
// write identical pixels.
TEST(Film, CliThreadsOneAndTwoWriteIdenticalExr) {
  const test::ScopedTempDir folder("threads");
  const std::filesystem::path& dir = folder.path();
  std::vector<Image> images;
  for (const char* threads : {"1", "2"}) {
    const std::string out = (dir / (std::string("t") + threads + ".exr")).string();
    const char* argv[] = {"pathlab", "render", "-o", out.c_str(), "--spp", "4", "--resolution", "32x24",
                          "--threads", threads, "--quiet"};
    std::ostringstream o, e;
    ASSERT_EQ(cli::run(static_cast<int>(std::size(argv)), argv, o, e), 0) << e.str();
    images.push_back(read_image(out));
  }
  ASSERT_EQ(images[0].pixels.size(), images[1].pixels.size());
  EXPECT_EQ(std::memcmp(images[0].pixels.data(), images[1].pixels.data(), images[0].pixels.size() * sizeof(vec3)), 0);
}

}  // namespace
}  // namespace pathlab
