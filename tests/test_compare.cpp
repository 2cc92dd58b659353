// pathlab compare (debugtools/compare.h, apps/cli/cmd_compare.cpp): the
// verdict and exit code between two tracers and between two builds
// (--with, here the same binary, or a wrapper that changes the seed so
// that every sample differs), the report of the first disagreeing sample,
// the per-bounce test's false-alarm side at two seeds, and bad input.
// The detection side (a planted fault found to its sample, event and
// depth) is in tests/test_faults.cpp, where faults can be planted.
#include "apps/cli/cli.h"
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/scene_loader.h"
#include "debugtools/compare.h"
#include "debugtools/tracers.h"
#include "tests/temp_dir.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

namespace pathlab {
namespace {

using CompareCli = test::TempDirTest;

int run(std::vector<std::string> args, std::string* out, std::string* err) {
  args.insert(args.begin(), "pathlab");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream o, e;
  const int rc = cli::run(static_cast<int>(argv.size()), argv.data(), o, e);
  *out = o.str();
  *err = e.str();
  return rc;
}

TEST_F(CompareCli, TracersAgreeAndTwoBuildsOfOneCodeAgree) {
  std::string out, err;
  ASSERT_EQ(run({"compare", "--resolution", "16x12", "--spp", "4"}, &out, &err), 0) << out << err;
  EXPECT_NE(out.find("AGREE"), std::string::npos) << out;
  EXPECT_NE(out.find("every layer agrees"), std::string::npos) << out;

  ASSERT_EQ(run({"compare", "--resolution", "16x12", "--spp", "4", "--json", "--with", PATHLAB_BINARY}, &out, &err), 0)
      << out << err;
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["format"], "pathlab-compare");
  EXPECT_TRUE(j["agree"].get<bool>());
  EXPECT_EQ(j["samples"]["equal"], 16 * 12 * 4);
  EXPECT_TRUE(j["first_disagreement"].is_null());
  EXPECT_TRUE(j["bounces"]["first_depth"].is_null());
}

// A stand-in for another build: this binary with `extra` appended to its arguments.
std::string wrapper(const std::filesystem::path& dir, const std::string& extra) {
  const std::filesystem::path script = dir / "other-pathlab";
  {
    std::ofstream s(script);
    s << "#!/bin/sh\nexec '" << PATHLAB_BINARY << "' \"$@\" " << extra << "\n";
  }
  std::filesystem::permissions(script, std::filesystem::perms::owner_all);
  return script.string();
}

// Another "build" whose tracer samples only the BSDF: two thirds of the
// samples differ. Pixels 0,0 and 1,0 see the ceiling, in the light's plane,
// where no light sample is taken (f = 0), so their first samples agree in
// radiance and the first that differs in row-major order is pixel 2,0 sample
// 0. Its first vertex is on the ceiling too, where this build reports its
// rejected light sample as an event and the other build samples no light, so
// the event lists part there (event 2, vertex 1). Both replay commands are given, and the per-bounce test names L1 (NEE
// is missing from B).
TEST_F(CompareCli, AnotherBuildThatPartsDisagreesFromTheFirstSample) {
  const std::string other = wrapper(dir_, "--strategy bsdf");
  std::string out, err;
  ASSERT_EQ(run({"compare", "--resolution", "16x12", "--spp", "4", "--with", other}, &out, &err), 1) << out << err;
  EXPECT_NE(out.find("DISAGREE"), std::string::npos) << out;
  EXPECT_NE(out.find("first disagreeing sample (row-major pixel, then sample): pixel 2,0 sample 0:"),
            std::string::npos)
      << out;
  // Next-event estimation skipped (strategy bsdf): a change, not rounding.
  EXPECT_NE(out.find("first divergence: event 2: different events, a light sample at vertex 1 and a scatter at "
                     "vertex 1 (not a rounding difference)"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("replay: pathlab trace-pixel --pixel 2,0 --sample 0 --seed 0 --tracer wavefront"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("replay: " + other + " trace-pixel --pixel 2,0 --sample 0"), std::string::npos) << out;
  EXPECT_NE(out.find("first depth that disagrees: L1"), std::string::npos) << out;
}

TEST_F(CompareCli, BadInputExitsTwoWithOneMessage) {
  std::string out, err;
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"compare", "--tracers", "reference"}, "--tracers reference: give two"},
      {{"compare", "--tracer", "wavefront"}, "not --tracer"},
      {{"compare", "--with", (dir_ / "nope").string()}, "no such file"},
      {{"compare", "--resolution", "4x4", "--spp", "1", "--with", "/bin/false"}, "failed (exit 1)"},
      {{"compare", "--export", (dir_ / "x").string(), "--with", PATHLAB_BINARY}, "cannot go with --with"},
      {{"compare", "--resolution", "4x4", "--spp", "1", "--with", wrapper(dir_, "--seed 7")}, "seed 7, not"},
  };
  for (const auto& [args, message] : cases) {
    EXPECT_EQ(run(args, &out, &err), 2) << args.back();
    EXPECT_NE(err.find(message), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
}

TEST_F(CompareCli, ExportFileRoundTripsAndRefusesATruncatedOne) {
  const std::string file = (dir_ / "ref.samples").string();
  std::string out, err;
  ASSERT_EQ(run({"compare", "--resolution", "6x4", "--spp", "3", "--tracers", "reference", "--export", file}, &out, &err),
            0)
      << err;
  const SampleExport e = read_sample_export(file);
  EXPECT_EQ(e.tracer, "reference");
  ASSERT_EQ(e.samples.size(), 6u * 4u * 3u);
  EXPECT_EQ(e.bounces.samples(5), 3u);
  const std::uintmax_t size = std::filesystem::file_size(file);
  std::filesystem::resize_file(file, size - 5);
  try {
    read_sample_export(file);
    FAIL() << "a truncated file was read";
  } catch (const InputError& ex) {
    EXPECT_NE(std::string(ex.what()).find(file + ": truncated"), std::string::npos) << ex.what();
  }
}

// The first disagreeing sample is the first in row-major pixel, then sample
// order, whatever batch it came in: here the second batch holds pixel 1,0
// sample 2, which comes before pixel 0,1 sample 1 of the first.
TEST(CompareSamples, FirstDisagreementIsRowMajorThenSampleAcrossBatches) {
  constexpr int width = 2, height = 2;
  constexpr std::uint32_t per_batch = 2;
  SampleComparer c(width, width * height * 4);
  std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>> replayed;
  for (std::uint32_t first : {0u, 2u}) {
    std::vector<FilmSample> a(width * height * per_batch), b(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) a[i].L = b[i].L = Spectrum(0.5f);
    if (first == 0) b[2 * per_batch + 1].L.x = 0.6f;  // pixel 0,1 (index 2), sample 1
    else b[1 * per_batch + 0].L.y = 0.4f;            // pixel 1,0 (index 1), sample 2
    c.add_batch(a, b, per_batch, first);
  }
  const SampleComparison r = c.finish([&](std::uint32_t x, std::uint32_t y, std::uint32_t s) {
    replayed.emplace_back(x, y, s);
    return PathDivergence{};
  });
  EXPECT_EQ(r.samples, 16u);
  EXPECT_EQ(r.equal, 14u);
  ASSERT_EQ(r.replayed.size(), 1u);  // 2 of 16 differ: too many to agree, so only the first is replayed
  EXPECT_EQ(r.replayed[0].x, 1u);
  EXPECT_EQ(r.replayed[0].y, 0u);
  EXPECT_EQ(r.replayed[0].sample, 2u);
  EXPECT_EQ(replayed.size(), 1u);
}

// Two renders at independent seeds estimate the same layers: the per-bounce
// test, at its family-wise false-alarm rate of 1e-4, passes them (fixed
// seeds). The per-sample rule, of course, does not.
TEST(CompareBounces, IndependentSeedsOfOneTracerAgreeStatistically) {
  Scene scene = builtin_cornell_box();
  scene.film.width = 16;
  scene.film.height = 12;
  RenderSettings s0 = scene.render, s1 = scene.render;
  s1.seed = 12345;
  const CompiledScene compiled(std::move(scene));
  const auto a = make_tracer("reference", compiled, s0), b = make_tracer("wavefront", compiled, s1);
  const BounceComparison r = compare_bounces(render_bounces(*a, 32), render_bounces(*b, 32));
  EXPECT_TRUE(r.agree()) << "first depth " << r.first_depth;
  EXPECT_FALSE(compare_tracers(*a, *b, 2).agree());
}

}  // namespace
}  // namespace pathlab
