// Partial films: exact sums, the file, merging, resuming (docs/overnight.md).
// The claim under test everywhere: a render made in pieces has the bits of
// one made in one go.
#include "apps/cli/interrupt.h"
#include "core/error.h"
#include "core/film.h"
#include "core/fixed_sum.h"
#include "core/image_io.h"
#include "core/partial_film.h"
#include "core/rng.h"
#include "tests/cli_util.h"
#include "tests/process_util.h"
#include "tests/temp_dir.h"

#include <gtest/gtest.h>
#include <xxhash.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <numeric>
#include <random>
#include <thread>

namespace pathlab {
namespace {

using test::run_cli;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- FixedSum

TEST(FixedSum, RoundsToTheNearestUnitHalvesAwayFromZero) {
  const double unit = std::ldexp(1.0, -64);
  EXPECT_EQ(Sum1::round(1.0), static_cast<int128_t>(1) << 64);
  EXPECT_EQ(Sum1::round(-3.0), -(static_cast<int128_t>(3) << 64));
  EXPECT_EQ(Sum1::round(0.75 * unit), 1);
  EXPECT_EQ(Sum1::round(0.5 * unit), 1);
  EXPECT_EQ(Sum1::round(-0.5 * unit), -1);
  EXPECT_EQ(Sum1::round(0.25 * unit), 0);
  EXPECT_EQ(Sum1::round(1.5 * unit), 2);
  EXPECT_EQ(Sum1::round(std::ldexp(1.0, -80)), 0);
  EXPECT_EQ(Sum1::round(0.0), 0);
  EXPECT_EQ(Sum1::round(-0.0), 0);
  EXPECT_EQ(Sum1::round(std::numeric_limits<double>::denorm_min()), 0);
  // The largest term allowed, exactly.
  EXPECT_EQ(Sum1::round(std::nextafter(Sum1::kLimit, 0.0)),
            static_cast<int128_t>(std::nextafter(Sum1::kLimit, 0.0) * std::ldexp(1.0, 32)) << 32);
  EXPECT_EQ(Sum2::round(1.0), static_cast<int128_t>(1) << 32);
}

TEST(FixedSum, TheSumIsTheSameInAnyOrderAndWithinHalfAUnitPerTerm) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-40, 30);
  std::vector<double> terms(20000);
  for (double& t : terms) t = std::ldexp(mantissa(rng), exponent(rng));
  Sum1 forward, shuffled, halves_a, halves_b;
  for (double t : terms) forward.add(t);
  std::vector<double> other = terms;
  std::shuffle(other.begin(), other.end(), rng);
  for (double t : other) shuffled.add(t);
  for (std::size_t i = 0; i < terms.size(); ++i) (i % 3 == 0 ? halves_a : halves_b).add(terms[i]);
  halves_b += halves_a;
  EXPECT_EQ(forward, shuffled);
  EXPECT_EQ(forward, halves_b);
  // Against the exactly rounded sum of the same terms (long double is
  // not exact here either, so the bound allows its error too).
  long double exact = 0.0L;
  for (double t : terms) exact += t;
  const double bound = terms.size() * std::ldexp(1.0, -65) + 1e-12 * std::abs(static_cast<double>(exact)) + 1e-15;
  EXPECT_NEAR(forward.value(), static_cast<double>(exact), bound);
}

// -------------------------------------------------------------------- Film

// Random samples of a width x height film, with a few bad ones.
std::vector<FilmSample> random_batch(int width, int height, std::uint32_t count, std::uint64_t seed) {
  std::vector<FilmSample> samples(static_cast<std::size_t>(width) * height * count);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const std::size_t pixel = i / count;
    FilmSample& s = samples[i];
    s.film = vec2(static_cast<float>(pixel % width) + u(rng), static_cast<float>(pixel / width) + u(rng));
    s.L = Spectrum(u(rng), 10.0f * u(rng) * u(rng), std::exp(20.0f * u(rng) - 10.0f));
    s.rays = 3;
    if (rng() % 97 == 0) s.L.y = std::numeric_limits<float>::quiet_NaN();
    if (rng() % 113 == 0) s.L.x = 1e10f;  // beyond the film's range
  }
  return samples;
}

bool same_state(const Film& a, const Film& b) {
  const Film::ConstWords x = a.words(), y = b.words();
  const auto eq = [](std::span<const std::uint64_t> p, std::span<const std::uint64_t> q) {
    return p.size() == q.size() && std::equal(p.begin(), p.end(), q.begin());
  };
  if (!eq(x.pixels, y.pixels) || !eq(x.moments, y.moments) || !eq(x.splat, y.splat)) return false;
  if (a.bad_sample_count() != b.bad_sample_count() || a.rays_cast() != b.rays_cast()) return false;
  if (a.bad_samples().size() != b.bad_samples().size()) return false;
  for (std::size_t i = 0; i < a.bad_samples().size(); ++i) {
    const BadSample &p = a.bad_samples()[i], &q = b.bad_samples()[i];
    if (p.x != q.x || p.y != q.y || p.sample != q.sample) return false;
  }
  return true;
}

class FilmAdd : public ::testing::TestWithParam<std::tuple<FilterKind, FilmMoments>> {};

TEST_P(FilmAdd, FilmsOfSplitSamplesAddUpToTheFilmOfAll) {
  const auto [filter, moments] = GetParam();
  constexpr int W = 9, H = 7;
  // Samples 0..11 in one batch; then as 0..4 + 5..11 into two films added
  // in either order; then as twelve films of one sample each.
  const std::vector<FilmSample> all = random_batch(W, H, 12, 1);
  const auto slice = [&](std::uint32_t first, std::uint32_t count) {
    std::vector<FilmSample> out;
    for (std::size_t p = 0; p < static_cast<std::size_t>(W) * H; ++p)
      for (std::uint32_t j = 0; j < count; ++j) out.push_back(all[p * 12 + first + j]);
    return out;
  };
  Film one(W, H, filter, moments);
  one.add_batch(0, 12, all);
  ASSERT_GT(one.bad_sample_count(), 0u);
  Film a(W, H, filter, moments), b(W, H, filter, moments);
  a.add_batch(0, 5, slice(0, 5));
  b.add_batch(5, 7, slice(5, 7));
  Film ab(W, H, filter, moments), ba(W, H, filter, moments);
  ab.add(a);
  ab.add(b);
  ba.add(b);
  ba.add(a);
  EXPECT_TRUE(same_state(one, ab));
  EXPECT_TRUE(same_state(one, ba));
  Film singles(W, H, filter, moments);
  for (std::uint32_t k = 12; k-- > 0;) {
    Film f(W, H, filter, moments);
    f.add_batch(k, 1, slice(k, 1));
    singles.add(f);
  }
  EXPECT_TRUE(same_state(one, singles));
  // And the image itself, the thing users compare.
  const Image x = one.image(), y = singles.image();
  EXPECT_EQ(0, std::memcmp(x.pixels.data(), y.pixels.data(), x.pixels.size() * sizeof(Spectrum)));
}

INSTANTIATE_TEST_SUITE_P(AllFilms, FilmAdd,
                         ::testing::Combine(::testing::Values(FilterKind::Box, FilterKind::Bilinear),
                                            ::testing::Values(FilmMoments::Mean, FilmMoments::MeanAndVariance)));

TEST(FilmRange, SamplesBeyondTheFilmsRangeAreBadNotSummed) {
  Film film(1, 1, FilterKind::Box);
  std::vector<FilmSample> s(3);
  s[0].L = Spectrum(1.0f);
  s[1].L = Spectrum(1.0f, static_cast<float>(kFilmRadianceLimit), 1.0f);
  s[2].L = Spectrum(3.0f);
  film.add_batch(0, 3, s);
  EXPECT_EQ(film.bad_sample_count(), 1u);
  ASSERT_EQ(film.bad_samples().size(), 1u);
  EXPECT_EQ(film.bad_samples()[0].sample, 1u);
  EXPECT_EQ(film.mean(0, 0), Spectrum(2.0f));
}

// -------------------------------------------------------------- The file

class PartialFilmFile : public test::TempDirTest {
 protected:
  PartialFilm make(FilterKind filter, FilmMoments moments, PassRange passes) {
    PartialFilm pf{Film(5, 4, filter, moments), {}};
    pf.film.add_batch(passes.begin, passes.count(), random_batch(5, 4, passes.count(), passes.begin));
    pf.info.passes = passes;
    pf.info.target_spp = 16;
    pf.info.fingerprint = {{"pathlab test", "setting seed 1"}, "00112233445566778899aabbccddeeff"};
    pf.info.stats.samples = 20u * passes.count();
    pf.info.stats.energy_total.add(12.5);
    return pf;
  }
  std::string error_reading(const fs::path& p) {
    try {
      read_partial_film(p);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  // The bytes of a small good film written to good.pfilm.
  std::string good_bytes() {
    const PartialFilm pf = make(FilterKind::Box, FilmMoments::MeanAndVariance, {0, 4});
    const fs::path good = dir_ / "good.pfilm";
    write_partial_film(pf.film, pf.info, good);
    std::ifstream in(good, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
};

TEST_F(PartialFilmFile, WhatIsWrittenIsReadBackBitForBit) {
  for (const FilterKind filter : {FilterKind::Box, FilterKind::Bilinear})
    for (const FilmMoments moments : {FilmMoments::Mean, FilmMoments::MeanAndVariance}) {
      const PartialFilm pf = make(filter, moments, {3, 9});
      const fs::path file = dir_ / "a.pfilm";
      write_partial_film(pf.film, pf.info, file);
      const PartialFilm back = read_partial_film(file);
      EXPECT_TRUE(same_state(pf.film, back.film));
      EXPECT_EQ(back.info.passes.begin, 3u);
      EXPECT_EQ(back.info.passes.end, 9u);
      EXPECT_EQ(back.info.fingerprint.lines, pf.info.fingerprint.lines);
      EXPECT_EQ(back.info.fingerprint.digest, pf.info.fingerprint.digest);
      EXPECT_EQ(back.info.stats.samples, pf.info.stats.samples);
      EXPECT_EQ(back.info.stats.energy_total, pf.info.stats.energy_total);
      EXPECT_FALSE(fs::exists(dir_ / ("a.pfilm.tmp-" + std::to_string(::getpid()))));
    }
}

TEST_F(PartialFilmFile, DamagedFilesAreRefusedNamingTheFileAndTheProblem) {
  const std::string bytes = good_bytes();
  const auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(dir_ / name, std::ios::binary) << content;
    return dir_ / name;
  };
  std::string flipped = bytes;
  flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 0x10);
  // The header's text edited, its length kept right: a number no field's
  // integer holds (8.9e68 as the width, once undefined behaviour found by the
  // fuzzer; -1 as the target) is refused before anything is made of it.
  const auto with_header = [&](const std::string& from, const std::string& to) {
    std::uint64_t n = 0;
    std::memcpy(&n, bytes.data() + 8, 8);
    std::string header = bytes.substr(16, n);
    const std::size_t at = header.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) header.replace(at, from.size(), to);
    const std::uint64_t m = header.size();
    return bytes.substr(0, 8) + std::string(reinterpret_cast<const char*>(&m), 8) + header + bytes.substr(16 + n);
  };
  std::string header_flipped = bytes;
  header_flipped[40] = static_cast<char>(header_flipped[40] ^ 0x01);
  const struct {
    fs::path file;
    const char* problem;
  } cases[] = {
      {write("empty.pfilm", ""), "empty"},
      {write("short.pfilm", bytes.substr(0, 20)), "too short"},
      {write("truncated.pfilm", bytes.substr(0, bytes.size() - 100)), "truncated"},
      {write("flipped.pfilm", flipped), "checksum"},
      {write("header.pfilm", header_flipped), "header"},
      {write("foreign.pfilm", std::string("\x89PNG\r\n\x1a\n") + std::string(100, 'x')), "not a pathlab partial film"},
      {write("longer.pfilm", bytes + "x"), "after its checksum"},
      {dir_ / "missing.pfilm", "does not exist"},
      {fs::create_directories(dir_ / "folder.pfilm") ? dir_ / "folder.pfilm" : dir_, "it is a folder, not a file"},
      {write("width.pfilm", with_header("\"width\": 5", "\"width\": 8.88889e+68")),
       "its width is 8.88889e+68, not an integer from 0 to 4294967295"},
      {write("target.pfilm", with_header("\"target_spp\": 16", "\"target_spp\": -1")),
       "target_spp is -1, not an integer"},
      {write("version.pfilm", with_header("\"format_version\": 1", "\"format_version\": 1.0")), "format version 1.0"},
  };
  for (const auto& c : cases) {
    const std::string message = error_reading(c.file);
    EXPECT_NE(message.find(c.file.string()), std::string::npos) << message;
    EXPECT_NE(message.find(c.problem), std::string::npos) << c.file << ": " << message;
  }
}

// A flipped bit in the header (its length field or its text) is damage,
// not a truncated file: the length's high bits once read as "truncated (it
// ends inside its header)", a resolution's digit as "truncated: a 7x4 film
// needs ...". A header the checksum vouches for is another version's.
TEST_F(PartialFilmFile, AFlippedBitInTheHeaderIsReportedAsACorruptHeader) {
  const std::string bytes = good_bytes();
  std::uint64_t header_size = 0;
  std::memcpy(&header_size, bytes.data() + 8, 8);
  const fs::path file = dir_ / "flipped.pfilm";
  std::size_t corrupt_header = 0;
  // Every bit of the length field and of the header's text.
  for (std::size_t at = 8; at < 16 + header_size; ++at)
    for (int bit = 0; bit < 8; ++bit) {
      std::string damaged = bytes;
      damaged[at] = static_cast<char>(damaged[at] ^ (1 << bit));
      std::ofstream(file, std::ios::binary | std::ios::trunc) << damaged;
      const std::string message = error_reading(file);
      ASSERT_NE(message.find(file.string()), std::string::npos) << "byte " << at << " bit " << bit << ": " << message;
      EXPECT_EQ(message.find("truncated"), std::string::npos) << "byte " << at << " bit " << bit << ": " << message;
      const bool header = message.find("its header is corrupt: ") != std::string::npos;
      EXPECT_TRUE(header || message.find("its checksum does not match its content") != std::string::npos)
          << "byte " << at << " bit " << bit << ": " << message;
      corrupt_header += header;
      if (at >= 10 && at < 16) {
        EXPECT_NE(message.find("its header is corrupt: its length field says"), std::string::npos) << message;
      }
    }
  EXPECT_GT(corrupt_header, 8u * header_size / 2);

  // The width 5 read as 7: the arrays' sizes in the header tell the damage.
  std::string seven = bytes;
  const std::size_t width = seven.find("\"width\": 5");
  ASSERT_NE(width, std::string::npos);
  seven[width + 9] = '7';
  std::ofstream(file, std::ios::binary | std::ios::trunc) << seven;
  std::string message = error_reading(file);
  EXPECT_NE(message.find("its header is corrupt: its array sizes [140,120,0] do not match its resolution 7x4"),
            std::string::npos)
      << message;

  // Another format version, its checksum right: not damage, another version.
  std::string other = bytes.substr(0, bytes.size() - 16);
  const std::size_t version = other.find("\"format_version\": 1");
  ASSERT_NE(version, std::string::npos);
  other[version + 18] = '2';
  const XXH128_hash_t h = XXH3_128bits(other.data(), other.size());
  for (int i = 0; i < 8; ++i) other.push_back(static_cast<char>(h.low64 >> (8 * i)));
  for (int i = 0; i < 8; ++i) other.push_back(static_cast<char>(h.high64 >> (8 * i)));
  std::ofstream(file, std::ios::binary | std::ios::trunc) << other;
  message = error_reading(file);
  EXPECT_NE(message.find("format version 2, this pathlab reads 1: not a partial film of this pathlab version"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find("(format version"), std::string::npos) << message;  // the version named once
}

TEST_F(PartialFilmFile, MergeRefusesOverlapsGapsAndOtherRenders) {
  const auto merge = [&](std::vector<PartialFilm> parts) -> std::string {
    std::vector<fs::path> names;
    for (std::size_t i = 0; i < parts.size(); ++i) names.push_back("part" + std::to_string(i));
    try {
      merge_partial_films(std::move(parts), names);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const auto parts = [&](std::initializer_list<PassRange> ranges) {
    std::vector<PartialFilm> v;
    for (const PassRange& r : ranges) v.push_back(make(FilterKind::Box, FilmMoments::Mean, r));
    return v;
  };
  EXPECT_EQ(merge(parts({{4, 8}, {0, 4}})), "");
  EXPECT_NE(merge(parts({{0, 5}, {4, 8}})).find("overlaps"), std::string::npos);
  EXPECT_NE(merge(parts({{0, 3}, {4, 8}})).find("passes 3..4 are missing"), std::string::npos);
  std::vector<PartialFilm> other = parts({{0, 4}, {4, 8}});
  other[1].info.fingerprint = {{"pathlab test", "setting seed 2"}, "ffeeddccbbaa99887766554433221100"};
  const std::string message = merge(std::move(other));
  EXPECT_NE(message.find("not a part of the same render"), std::string::npos) << message;
  EXPECT_NE(message.find("setting seed 2"), std::string::npos) << message;
}

// ---------------------------------------------------------------- The CLI

class PiecesCli : public test::TempDirTest {
 protected:
  std::vector<std::string> base(const std::string& tracer) {
    return {"--tracer", tracer, "--resolution", "24x16", "--seed", "5", "-q"};
  }
  fs::path render(const std::string& tracer, const std::vector<std::string>& extra, const std::string& out) {
    std::vector<std::string> args{"render", "-o", (dir_ / out).string()};
    for (const std::string& a : base(tracer)) args.push_back(a);
    args.insert(args.end(), extra.begin(), extra.end());
    const test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 0) << r.err;
    return dir_ / out;
  }
};

TEST_F(PiecesCli, AnySplitMergedIsBitIdenticalToOneRender) {
  for (const std::string tracer : {"reference", "wavefront"}) {
    const std::vector<float> whole = test::pixel_floats(render(tracer, {"--spp", "8"}, "whole.exr"));
    const std::vector<std::vector<std::string>> splits = {
        {"0..1", "1..2"}, {"0..3", "3..8"}, {"0..1", "1..2", "2..3", "3..4", "4..5", "5..6", "6..7", "7..8"}};
    for (const auto& split : splits) {
      // 1+1 is a 2-spp render; the others make up the 8 of `whole`.
      const std::uint32_t total = split.size() == 2 && split[1] == "1..2" ? 2 : 8;
      const std::vector<float> expected =
          total == 8 ? whole : test::pixel_floats(render(tracer, {"--spp", std::to_string(total)}, "two.exr"));
      std::vector<std::string> merge{"merge", "-o", (dir_ / "merged.exr").string(), "-q"};
      for (std::size_t i = 0; i < split.size(); ++i) {
        const std::string part = "part" + std::to_string(i) + ".pfilm";
        render(tracer, {"--spp", std::to_string(total), "--passes", split[i]}, part);
        merge.push_back((dir_ / part).string());
      }
      std::reverse(merge.begin() + 4, merge.end());  // the order given does not matter
      const test::CliResult r = run_cli(merge);
      ASSERT_EQ(r.code, 0) << r.err;
      EXPECT_EQ(test::pixel_floats(dir_ / "merged.exr"), expected) << tracer << ", " << split.size() << " parts";
    }
  }
}

TEST_F(PiecesCli, AResumedRenderIsBitIdenticalAndRecordsItsHistory) {
  const std::vector<float> whole = test::pixel_floats(render("reference", {"--spp", "6"}, "whole.exr"));
  const std::string ck = (dir_ / "ck.pfilm").string();
  // A checkpoint of passes 0..2 (the render of --passes 0..2 writes it at its end), resumed twice.
  render("reference", {"--spp", "6", "--passes", "0..2", "--checkpoint", ck}, "first.pfilm");
  render("reference", {"--spp", "4", "--checkpoint", ck, "--resume", ck}, "second.exr");
  const fs::path final_exr = render("reference", {"--spp", "6", "--checkpoint", ck, "--resume", ck}, "final.exr");
  EXPECT_EQ(test::pixel_floats(final_exr), whole);
  ImageMetadata meta;
  read_image(final_exr, &meta);
  const auto value = [&](const std::string& key) {
    for (const auto& [k, v] : meta)
      if (k == key) return v;
    return std::string("(missing)");
  };
  EXPECT_EQ(value("passes"), "0..6");
  EXPECT_EQ(value("resumes"), "2");
  EXPECT_EQ(value("processes"), "1");
  EXPECT_EQ(value("fingerprint").size(), 32u);
}

// A progressive render (--target-relmse) resumed from a checkpoint stops at
// the pass an uninterrupted one stops at, with the same bits: its passes stay
// on the grid from 0 and it decides from the film it resumed.
TEST_F(PiecesCli, ATargetRelmseRenderResumedStopsWhereTheUninterruptedOneDoes) {
  // 256x256: a pass of render_until is 4 samples per pixel.
  const std::vector<std::string> common{"--resolution", "256x256", "-q"};
  const auto run = [&](std::vector<std::string> extra, const std::string& out) {
    std::vector<std::string> args{"render", "-o", (dir_ / out).string(), "--seed", "3"};
    args.insert(args.end(), common.begin(), common.end());
    args.insert(args.end(), extra.begin(), extra.end());
    const test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 0) << r.err;
  };
  run({"--target-relmse", "0.05", "--spp", "64"}, "whole.exr");
  const std::string ck = (dir_ / "ck.pfilm").string();
  run({"--spp", "8", "--checkpoint", ck, "--aov", "variance"}, "first.exr");
  run({"--target-relmse", "0.05", "--spp", "64", "--resume", ck}, "resumed.exr");
  ImageMetadata whole_meta, resumed_meta;
  const std::vector<float> whole = test::pixel_floats(dir_ / "whole.exr");
  read_image(dir_ / "whole.exr", &whole_meta);
  read_image(dir_ / "resumed.exr", &resumed_meta);
  const auto spp = [](const ImageMetadata& m) {
    for (const auto& [k, v] : m)
      if (k == "spp") return v;
    return std::string();
  };
  EXPECT_EQ(spp(resumed_meta), spp(whole_meta));
  EXPECT_GT(std::stoi(spp(whole_meta)), 8);  // it did go on past the checkpoint
  EXPECT_LT(std::stoi(spp(whole_meta)), 64);  // and stopped on the target, not the cap
  EXPECT_EQ(test::pixel_floats(dir_ / "resumed.exr"), whole);
}

TEST_F(PiecesCli, ResumeRefusesAnotherSceneFileMeshSettingOrVersion) {
  const fs::path mesh = write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string scene_text = R"({"pathlab_scene": 1, "camera": {"position": [0.3, 0.3, 2], "look_at": [0.3, 0.3, 0]},
    "materials": {"white": {"type": "diffuse"}},
    "shapes": [{"type": "mesh", "file": "tri.obj", "material": "white"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}], "render": {"spp": 2}})";
  const fs::path scene = write("scene.json", scene_text);
  const std::string ck = (dir_ / "ck.pfilm").string();
  const auto resume = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"render", scene.string(), "-o", (dir_ / "out.exr").string(), "--resume", ck, "-q",
                                  "--resolution", "8x8"};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_cli(args);
  };
  const test::CliResult made = run_cli({"render", scene.string(), "-o", (dir_ / "x.exr").string(), "--checkpoint",
                                        ck, "--passes", "0..1", "-q", "--resolution", "8x8"});
  ASSERT_EQ(made.code, 0) << made.err;
  ASSERT_EQ(resume({}).code, 0);

  test::CliResult r = resume({"--seed", "9"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("this render: setting seed 9"), std::string::npos) << r.err;
  r = resume({"--strategy", "bsdf"});
  EXPECT_NE(r.err.find("setting strategy"), std::string::npos) << r.err;
  r = resume({"--tracer", "wavefront"});
  EXPECT_NE(r.err.find("setting tracer"), std::string::npos) << r.err;
  // Every setting of sample_settings() is in the fingerprint: the texture
  // filter was once left out of it, so such a resume was accepted.
  r = resume({"--texture-filter", "point"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("setting texture_filter"), std::string::npos) << r.err;
  r = resume({"--light-sampling", "solid_angle"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("setting light_sampling"), std::string::npos) << r.err;
  r = resume({"--intersection", "fast"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("setting intersection"), std::string::npos) << r.err;
  write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1.5 0\nf 1 2 3\n");
  r = resume({});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("file tri.obj"), std::string::npos) << r.err;
  write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write("scene.json", scene_text + " ");
  r = resume({});
  EXPECT_NE(r.err.find("scene scene.json"), std::string::npos) << r.err;
  write("scene.json", scene_text);
  ASSERT_EQ(resume({}).code, 0);
  // Another version: the checkpoint as another build would have written it.
  PartialFilm pf = read_partial_film(ck);
  pf.info.fingerprint.lines[0] = "pathlab 0.0.1 0123456789ab";
  pf.info.fingerprint.digest = "0123456789abcdef0123456789abcdef";
  write_partial_film(pf.film, pf.info, ck);
  r = resume({});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("checkpoint: pathlab 0.0.1"), std::string::npos) << r.err;
  // Nothing written by the refused runs.
  EXPECT_FALSE(fs::exists(dir_ / "out.png") && fs::last_write_time(dir_ / "out.png") > fs::last_write_time(ck));
}

TEST_F(PiecesCli, ADamagedCheckpointIsRefusedWithExit2AndNothingWritten) {
  const std::string ck = (dir_ / "ck.pfilm").string();
  render("reference", {"--spp", "4", "--passes", "0..2", "--checkpoint", ck}, "part.pfilm");
  std::string bytes;
  {
    std::ifstream in(ck, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::string flipped = bytes;
  flipped[bytes.size() - 40] = static_cast<char>(flipped[bytes.size() - 40] ^ 0x04);
  std::string length_flipped = bytes;  // the header's length field, once "truncated"
  length_flipped[13] = static_cast<char>(length_flipped[13] ^ 0x01);
  for (const auto& [content, problem] : std::vector<std::pair<std::string, std::string>>{
           {bytes.substr(0, bytes.size() / 2), "truncated"}, {flipped, "checksum"}, {"", "empty"},
           {length_flipped, "its header is corrupt: its length field says"},
           {"P3\n1 1\n255\n0 0 0\n", "too short"}}) {
    std::ofstream(ck, std::ios::binary) << content;
    std::vector<std::string> args{"render", "-o", (dir_ / "out.exr").string(), "--spp", "4", "--resume", ck,
                                  "--checkpoint", ck};
    for (const std::string& a : base("reference")) args.push_back(a);
    const test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 2) << problem;
    EXPECT_NE(r.err.find(ck), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(problem), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
    EXPECT_FALSE(fs::exists(dir_ / "out.png"));
    // The damaged checkpoint is left as it was, for the user to look at.
    std::ifstream in(ck, std::ios::binary);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), content) << problem;
  }
}

// A folder opens as a stream that fails every read: it was "read failed".
TEST_F(PiecesCli, ResumeFromAFolderSaysItIsAFolder) {
  const fs::path folder = dir_ / "ck.pfilm";
  fs::create_directories(folder);
  std::vector<std::string> args{"render", "-o", (dir_ / "out.exr").string(), "--spp", "4", "--resume", folder.string()};
  for (const std::string& a : base("reference")) args.push_back(a);
  const test::CliResult r = run_cli(args);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(folder.string() + ": not a usable partial film: it is a folder, not a file"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("read failed"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
}

// ------------------------------------------------------- Signals and kill -9

int run_binary(const std::vector<std::string>& args, int signal, std::chrono::milliseconds delay,
               const fs::path& wait_for = {}) {
  return test::run_process(PATHLAB_BINARY, args, signal, delay, wait_for);
}

class Interrupted : public test::TempDirTest {
 protected:
  std::vector<std::string> args(const std::string& out, std::vector<std::string> extra) {
    std::vector<std::string> a{"render", "-o", (dir_ / out).string(), "--resolution", "64x64", "--spp", "320", "-q"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
};

TEST_F(Interrupted, KillNineAtAnyMomentThenResumeGivesTheSameBits) {
  ASSERT_EQ(run_binary(args("whole.exr", {}), 0, {}), 0);
  const std::vector<float> whole = test::pixel_floats(dir_ / "whole.exr");
  // A batch here is 64 passes (2^18 samples): five of them, a checkpoint
  // after each. Each kill lands a while after the first checkpoint exists,
  // so that there is always something to resume from.
  int resumed = 0;
  for (const int ms : {0, 100, 300}) {
    const std::string ck = (dir_ / ("ck" + std::to_string(ms) + ".pfilm")).string();
    const int killed = run_binary(args("killed.exr", {"--checkpoint", ck, "--checkpoint-every", "0.001"}), SIGKILL,
                                  std::chrono::milliseconds(ms), ck);
    if (killed == 0) continue;  // it finished first: nothing to resume from
    EXPECT_EQ(killed, 128 + SIGKILL);
    ASSERT_TRUE(fs::exists(ck));
    ASSERT_EQ(run_binary(args("resumed.exr", {"--checkpoint", ck, "--resume", ck}), 0, {}), 0) << ms << " ms";
    EXPECT_EQ(test::pixel_floats(dir_ / "resumed.exr"), whole) << "killed " << ms << " ms after its first checkpoint";
    ++resumed;
  }
  EXPECT_GT(resumed, 0) << "every render finished before its kill: the test resumed nothing";
}

TEST_F(Interrupted, SigintWritesTheCheckpointAndTheImageOfWhatIsDone) {
  const std::string ck = (dir_ / "ck.pfilm").string();
  // Signalled once its first checkpoint is there, so once it is rendering.
  const int code = run_binary(args("part.exr", {"--checkpoint", ck, "--checkpoint-every", "0.001"}), SIGINT,
                              std::chrono::milliseconds(0), ck);
  if (code == 0) GTEST_SKIP() << "the render finished before the signal";
  EXPECT_EQ(code, 128 + SIGINT);
  ASSERT_TRUE(fs::exists(ck));
  ASSERT_TRUE(fs::exists(dir_ / "part.exr"));
  ASSERT_TRUE(fs::exists(dir_ / "part.png"));
  const PartialFilm pf = read_partial_film(ck);
  EXPECT_LT(pf.info.passes.end, 320u);
  ImageMetadata meta;
  read_image(dir_ / "part.exr", &meta);
  EXPECT_NE(std::find(meta.begin(), meta.end(), std::pair<std::string, std::string>("interrupted", "yes")), meta.end());
  EXPECT_NE(std::find(meta.begin(), meta.end(),
                      std::pair<std::string, std::string>("spp", std::to_string(pf.info.passes.end))),
            meta.end());
}

}  // namespace
}  // namespace pathlab
