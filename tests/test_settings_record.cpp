// Every setting that changes a sample is recorded: in a render's EXR header
// (read back with OpenImageIO) and in trace-pixel's header and JSON; and
// trace-pixel reports what the film received for a sample under --clamp,
// bit for bit.
#include "tests/cli_util.h"
#include "apps/cli/commands.h"
#include "core/image_io.h"
#include "core/render.h"
#include "core/simd/simd.h"
#include "tests/temp_dir.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using test::CliResult;
using test::run_cli;

// Every "pathlab:" string attribute of an EXR header, read by OIIO itself.
std::map<std::string, std::string> exr_header(const fs::path& file) {
  std::map<std::string, std::string> header;
  auto in = OIIO::ImageInput::open(file.string());
  EXPECT_TRUE(in) << file;
  if (!in) return header;
  for (const OIIO::ParamValue& attr : in->spec().extra_attribs) {
    const std::string name = attr.name().string();
    if (attr.type() == OIIO::TypeString && name.rfind("pathlab:", 0) == 0)
      header[name.substr(8)] = attr.get<OIIO::ustring>().string();
  }
  return header;
}

std::string joined(const std::vector<std::string>& args) {
  std::string line = "pathlab";
  for (const std::string& a : args) line += " " + a;
  return line;
}

// Non-default values of every setting that changes a sample.
const std::vector<std::string> kSettings = {
    "--tracer",         "wavefront", "--strategy", "light", "--seed", "77", "--max-depth", "3",
    "--rr-depth",       "2",         "--bsdf-sampling", "cospow", "--light-sampling", "solid_angle", "--light-sampler", "bvh", "--clamp", "0.375", "--min-pdf", "0.03125",
    "--general-shading", "--texture-filter", "point", "--bvh", "compact", "--intersection", "fast", "--resolution", "8x6"};

class SettingsRecord : public test::TempDirTest {};

TEST_F(SettingsRecord, RenderWritesEverySettingIntoTheExrHeader) {
  const fs::path exr = dir_ / "out.exr";
  std::vector<std::string> args = {"render", "--spp", "3", "-q", "-o", exr.string()};
  args.insert(args.end(), kSettings.begin(), kSettings.end());
  const CliResult r = run_cli(args);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto h = exr_header(exr);
  const std::map<std::string, std::string> want = {
      {"tracer", "wavefront"},     {"strategy", "light"},    {"seed", "77"},
      {"max_depth", "3"},          {"rr_depth", "2"},        {"bsdf_sampling", "cospow"},
      {"light_sampling", "solid_angle"}, {"light_sampler", "bvh"},
      {"clamp", "0.375"},          {"min_pdf", "0.03125"},   {"general_shading", "on"},
      {"texture_filter", "point"}, {"bvh", "compact"},       {"spp", "3"}, {"intersection", "fast"},
      {"resolution", "8x6"},       {"filter", "box"},        {"scene", "<built-in cornell>"},
      {"version", PATHLAB_VERSION}, {"git_revision", git_revision()}, {"clamped", "yes"},
      {"command_line", joined(args)},
  };
  for (const auto& [key, value] : want) {
    ASSERT_TRUE(h.count(key)) << "pathlab:" << key << " missing from the EXR header";
    EXPECT_EQ(h.at(key), value) << key;
  }
  EXPECT_NE(std::string(git_revision()), "");
  // The built-in Cornell box's light (radiance 17) is far above the clamp.
  EXPECT_GT(std::stoull(h.at("clamped_samples")), 0u);
  EXPECT_GT(std::stod(h.at("clamped_energy_fraction")), 0.0);
  // Every setting sample_settings() names is in the header.
  for (const auto& [key, value] : sample_settings(RenderSettings{})) EXPECT_TRUE(h.count(key)) << key;
}

TEST_F(SettingsRecord, UnclampedRenderSaysSo) {
  const fs::path exr = dir_ / "plain.exr";
  ASSERT_EQ(run_cli({"render", "--spp", "1", "--resolution", "4x4", "-q", "-o", exr.string()}).code, 0);
  const auto h = exr_header(exr);
  EXPECT_EQ(h.at("clamped"), "no");
  EXPECT_EQ(h.at("clamp"), "0");
  EXPECT_EQ(h.at("clamped_samples"), "0");
  EXPECT_EQ(h.at("general_shading"), "off");
  EXPECT_EQ(h.at("texture_filter"), "cone");
  EXPECT_EQ(h.at("bsdf_sampling"), "vndf");
  EXPECT_EQ(h.at("light_sampling"), "area");
  EXPECT_EQ(h.at("light_sampler"), "power");
  EXPECT_EQ(h.at("intersection"), "robust");
}

TEST_F(SettingsRecord, TracePixelRecordsEverySettingInJsonAndText) {
  std::vector<std::string> args = {"trace-pixel", "--pixel", "3,2", "--sample", "1", "--json"};
  args.insert(args.end(), kSettings.begin(), kSettings.end());
  const CliResult r = run_cli(args);
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["tracer"], "wavefront");
  EXPECT_EQ(j["strategy"], "light");
  EXPECT_EQ(j["seed"], 77);
  EXPECT_EQ(j["max_depth"], 3);
  EXPECT_EQ(j["rr_depth"], 2);
  EXPECT_EQ(j["bsdf_sampling"], "cospow");
  EXPECT_EQ(j["light_sampling"], "solid_angle");
  EXPECT_EQ(j["light_sampler"], "bvh");
  EXPECT_EQ(j["clamp"], 0.375);
  EXPECT_EQ(j["min_pdf"], 0.03125);
  EXPECT_EQ(j["general_shading"], true);
  EXPECT_EQ(j["texture_filter"], "point");
  EXPECT_EQ(j["bvh"], "compact");
  EXPECT_EQ(j["intersection"], "fast");
  EXPECT_EQ(j["resolution"], json::array({8, 6}));
  EXPECT_EQ(j["pathlab_version"], PATHLAB_VERSION);
  EXPECT_EQ(j["git_revision"], git_revision());
  EXPECT_EQ(j["command_line"], joined(args));
  EXPECT_TRUE(j["film_radiance"].is_array());
  EXPECT_TRUE(j["clamped"].is_boolean());

  args.erase(args.begin() + 5);  // no --json: the text header
  const CliResult t = run_cli(args);
  ASSERT_EQ(t.code, 0) << t.err;
  for (const char* part : {"strategy light", "seed 77", "max depth 3", "rr depth 2", "bsdf_sampling cospow",
                           "light_sampling solid_angle", "light_sampler bvh", "clamp 0.375", "min_pdf 0.03125", "general_shading on", "texture_filter point",
                           "intersection fast", "bvh compact", "tracer wavefront"})
    EXPECT_NE(t.err.find(part), std::string::npos) << part << "\n" << t.err;
  EXPECT_NE(t.err.find(std::string("pathlab ") + PATHLAB_VERSION + " (git " + git_revision() + ")"), std::string::npos)
      << t.err;
  EXPECT_NE(t.err.find("command: " + joined(args)), std::string::npos) << t.err;
}

TEST(ShellCommandLine, QuotesWhatAShellWouldSplit) {
  const char* argv[] = {"pathlab", "render", "my scene.json", "it's", "--clamp", "0.5", ""};
  EXPECT_EQ(cli::shell_command_line(7, argv), "pathlab render 'my scene.json' 'it'\\''s' --clamp 0.5 ''");
}

// A render of 1 spp with --clamp and the box filter holds each sample's
// clamped radiance, exactly (the film's fixed-point sums are exact for
// these values); trace-pixel's film_radiance must be those bits, for
// clamped and unclamped samples, and for both tracers.
TEST_F(SettingsRecord, ClampedTracePixelReportsWhatTheFilmReceived) {
  const std::string clamp = "0.25";
  for (const char* tracer : {"reference", "wavefront"}) {
    const fs::path exr = dir_ / (std::string(tracer) + ".exr");
    ASSERT_EQ(run_cli({"render", "--spp", "1", "--resolution", "12x12", "--clamp", clamp, "--tracer", tracer,
                       "--seed", "5", "-q", "-o", exr.string()})
                  .code,
              0);
    const Image image = read_image(exr);
    int clamped = 0, unclamped = 0;
    for (int y = 0; y < 12; y += 1) {
      for (int x = (y * 5) % 3; x < 12; x += 3) {
        const CliResult r = run_cli({"trace-pixel", "--pixel", std::to_string(x) + "," + std::to_string(y),
                                     "--sample", "0", "--clamp", clamp, "--tracer", tracer, "--seed", "5",
                                     "--resolution", "12x12", "--json"});
        ASSERT_EQ(r.code, 0) << r.err;
        const json j = json::parse(r.out);
        const vec3 film(j["film_radiance"][0].get<float>(), j["film_radiance"][1].get<float>(),
                        j["film_radiance"][2].get<float>());
        const vec3& pixel = image.at(x, y);
        EXPECT_EQ(std::memcmp(&film, &pixel, sizeof film), 0)
            << tracer << " pixel (" << x << "," << y << "): trace-pixel says (" << film.x << ", " << film.y << ", "
            << film.z << "), the film has (" << pixel.x << ", " << pixel.y << ", " << pixel.z << ")";
        (j["clamped"].get<bool>() ? clamped : unclamped) += 1;
        if (j["clamped"].get<bool>()) {
          EXPECT_NEAR(max_component(film), 0.25f, 1e-6f);  // m * (0.25 / m), rounded
        }
      }
    }
    // Both kinds were compared: the light and the walls near it exceed the clamp.
    EXPECT_GT(clamped, 0) << tracer;
    EXPECT_GT(unclamped, 0) << tracer;
  }
}

// --simd chooses the vectorised code's instruction set: recorded in the EXR,
// said by the wavefront's stage line, the same image at every target; an
// unknown one is refused by name.
TEST_F(SettingsRecord, RenderRecordsTheSimdTargetAndGivesTheSameImage) {
  std::vector<Image> images;
  for (const SimdTarget t : supported_simd_targets()) {
    const std::string name = simd_target_name(t);
    const fs::path exr = dir_ / ("simd-" + name + ".exr");
    const CliResult r = run_cli({"render", "--tracer", "wavefront", "--spp", "2", "--resolution", "24x16", "--simd",
                                 name, "-o", exr.string()});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(exr_header(exr).at("simd"), name);
    const std::string stages = t == SimdTarget::Scalar ? "scalar stages" : "every stage vectorised (" + name + ",";
    EXPECT_NE(r.err.find(stages), std::string::npos) << r.err;
    images.push_back(read_image(exr));
  }
  select_simd_target(SimdTarget::Auto);
  for (std::size_t i = 1; i < images.size(); ++i)
    EXPECT_TRUE(images[i].pixels == images[0].pixels) << "target " << simd_target_name(supported_simd_targets()[i]);
  const CliResult bad = run_cli({"render", "--simd", "neon", "-o", (dir_ / "x.exr").string()});
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.err.find("--simd: neon not in"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace pathlab
