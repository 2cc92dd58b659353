#include "core/image_io.h"

#include "core/error.h"

#include <OpenImageIO/imageio.h>
#include "tests/temp_dir.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class ImageIoTest : public test::TempDirTest {};

std::vector<std::string> list_folder(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Decodes a PNG pixel read back as float into its 8-bit code value.
int code(float v) { return static_cast<int>(std::lround(v * 255.0f)); }

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

// Writes a single-image EXR with `channels` channels through OIIO directly.
void write_raw_exr(const fs::path& file, int channels, const std::vector<float>& data, int w, int h) {
  OIIO::ImageSpec spec(w, h, channels, OIIO::TypeFloat);
  auto out = OIIO::ImageOutput::create(file.string());
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(file.string(), spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeFloat, data.data()));
  ASSERT_TRUE(out->close());
}

TEST_F(ImageIoTest, ExrRoundTripIsBitExact) {
  const std::vector<float> values = {0.0f,     -0.0f,    1.0f,       0.1f,      1e-30f,
                                     1.17549435e-38f,   3.0e38f,    -1.0f,     -123.456f,
                                     65504.0f, 1e10f,    -1e-20f,    0.333333f, kInfinity,
                                     std::numeric_limits<float>::max(), 7.0f, 2.5e-7f, -4096.5f};
  Image image(3, 2);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    image.pixels[i] = vec3(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
  }
  const fs::path file = dir_ / "round.exr";
  write_exr(file, image, {});
  const Image back = read_image(file);
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(std::bit_cast<std::uint32_t>(back.pixels[i][c]),
                std::bit_cast<std::uint32_t>(image.pixels[i][c]))
          << "pixel " << i << " channel " << c;
    }
  }
}

TEST_F(ImageIoTest, ExrKeepsRowOrderAndChannelNames) {
  Image image(2, 2);
  image.at(0, 0) = vec3(1, 2, 3);
  image.at(1, 1) = vec3(4, 5, 6);
  const fs::path file = dir_ / "order.exr";
  write_exr(file, image, {});
  const Image back = read_image(file);
  EXPECT_EQ(back.at(0, 0), vec3(1, 2, 3));
  EXPECT_EQ(back.at(1, 1), vec3(4, 5, 6));
  EXPECT_EQ(back.at(1, 0), vec3(0));

  auto in = OIIO::ImageInput::open(file.string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().channelnames, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(in->spec().format, OIIO::TypeFloat);
  EXPECT_EQ(in->spec().get_string_attribute("compression"), "zip");
}

TEST_F(ImageIoTest, ExrMetadataRoundTrips) {
  const std::string long_value(300, 'x');
  ImageMetadata metadata = {{"scene", "scenes/cornell.json"},
                            {"spp", "1024"},
                            {"json", "{\"a\": [1, 2], \"b\": \"q\"}"},
                            {"long", long_value}};
  const fs::path file = dir_ / "meta.exr";
  write_exr(file, Image(1, 1), metadata);

  ImageMetadata back = {{"stale", "entry"}};
  read_image(file, &back);
  std::sort(metadata.begin(), metadata.end());
  std::sort(back.begin(), back.end());
  EXPECT_EQ(back, metadata);
}

// OIIO 2.4's EXR reader drops empty string attributes: the pair is written
// but not read back. Pin that down so a change in OIIO is noticed.
TEST_F(ImageIoTest, ExrEmptyMetadataValueIsDroppedOnRead) {
  const fs::path file = dir_ / "empty.exr";
  write_exr(file, Image(1, 1), {{"empty", ""}, {"kept", "yes"}});
  ImageMetadata back;
  read_image(file, &back);
  EXPECT_EQ(back, (ImageMetadata{{"kept", "yes"}}));
}

TEST_F(ImageIoTest, PngEncodesKnownRadiances) {
  Image image(6, 1);
  image.at(0, 0) = vec3(0.0f);
  image.at(1, 0) = vec3(0.0031308f);
  image.at(2, 0) = vec3(0.5f);
  image.at(3, 0) = vec3(1.0f);
  image.at(4, 0) = vec3(2.0f, -1.0f, kInfinity);
  image.at(5, 0) = vec3(0.5f, std::nanf(""), 0.5f);
  const fs::path file = dir_ / "known.png";
  write_png(file, image);

  const Image back = read_image(file);
  ASSERT_EQ(back.width, 6);
  ASSERT_EQ(back.height, 1);
  EXPECT_EQ(code(back.at(0, 0).x), 0);
  EXPECT_EQ(code(back.at(1, 0).x), 10);  // 12.92 * 0.0031308 * 255 = 10.31
  EXPECT_EQ(code(back.at(2, 0).x), 188);
  EXPECT_EQ(code(back.at(3, 0).x), 255);
  EXPECT_EQ(code(back.at(4, 0).x), 255);  // clamped above
  EXPECT_EQ(code(back.at(4, 0).y), 0);    // clamped below
  EXPECT_EQ(code(back.at(4, 0).z), 255);  // +inf
  EXPECT_EQ(code(back.at(5, 0).x), 255);  // NaN pixel: magenta
  EXPECT_EQ(code(back.at(5, 0).y), 0);
  EXPECT_EQ(code(back.at(5, 0).z), 255);

  auto in = OIIO::ImageInput::open(file.string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->format_name(), std::string("png"));
  EXPECT_EQ(in->spec().format, OIIO::TypeUInt8);
  EXPECT_EQ(in->spec().nchannels, 3);
}

TEST_F(ImageIoTest, PngAppliesExposure) {
  Image image(3, 1);
  image.at(0, 0) = vec3(0.25f);  // +1 stop -> 0.5
  image.at(1, 0) = vec3(1.0f);   // +1 stop -> 2, clamps
  image.at(2, 0) = vec3(0.125f);
  const fs::path up = dir_ / "up.png";
  write_png(up, image, 1.0f);
  Image back = read_image(up);
  EXPECT_EQ(code(back.at(0, 0).x), 188);
  EXPECT_EQ(code(back.at(1, 0).x), 255);

  const fs::path down = dir_ / "down.png";
  image.at(0, 0) = vec3(1.0f);  // -1 stop -> 0.5
  write_png(down, image, -1.0f);
  back = read_image(down);
  EXPECT_EQ(code(back.at(0, 0).x), 188);
  EXPECT_EQ(code(back.at(2, 0).x), code(linear_to_srgb(0.0625f)));
}

TEST_F(ImageIoTest, WriteCreatesNestedFolders) {
  const fs::path exr = dir_ / "a" / "b" / "c" / "out.exr";
  const fs::path png = dir_ / "d" / "e" / "out.png";
  write_exr(exr, Image(2, 2), {});
  write_png(png, Image(2, 2));
  EXPECT_TRUE(fs::is_regular_file(exr));
  EXPECT_TRUE(fs::is_regular_file(png));
  EXPECT_EQ(list_folder(exr.parent_path()), std::vector<std::string>{"out.exr"});
  EXPECT_EQ(list_folder(png.parent_path()), std::vector<std::string>{"out.png"});
}

// The folder is made only by the write itself: a render that fails after
// the check leaves no empty folder.
TEST_F(ImageIoTest, EnsureWritableCreatesNoFolderAndLeavesNoProbe) {
  const fs::path file = dir_ / "x" / "y" / "render.exr";
  ensure_writable(file);
  EXPECT_FALSE(fs::exists(dir_ / "x"));
  EXPECT_TRUE(list_folder(dir_).empty());
  write_exr(file, Image(1, 1), {});
  EXPECT_EQ(list_folder(file.parent_path()), std::vector<std::string>{"render.exr"});
}

TEST_F(ImageIoTest, WriteUnderRegularFileThrowsInputError) {
  write_text(dir_ / "plain", "not a folder");
  const std::vector<std::string> before = list_folder(dir_);
  const fs::path file = dir_ / "plain" / "sub" / "out.exr";
  try {
    write_exr(file, Image(1, 1), {});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string() + ": cannot write output: "), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(write_png(dir_ / "plain" / "out.png", Image(1, 1)), InputError);
  EXPECT_THROW(ensure_writable(dir_ / "plain" / "out.png"), InputError);
  EXPECT_EQ(list_folder(dir_), before);
}

TEST_F(ImageIoTest, WriteIntoProcThrowsInputError) {
  const fs::path file = "/proc/pathlab-test.exr";
  try {
    write_exr(file, Image(1, 1), {});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/proc/pathlab-test.exr: cannot write output: ", 0), 0u)
        << e.what();
  }
  EXPECT_THROW(write_png("/proc/pathlab-test.png", Image(1, 1)), InputError);
  EXPECT_FALSE(fs::exists(file));
  for (const std::string& name : list_folder("/proc")) {
    EXPECT_EQ(name.find("pathlab"), std::string::npos) << name;
  }
}

TEST_F(ImageIoTest, WriteOntoFolderThrowsInputError) {
  fs::create_directories(dir_ / "taken.exr");
  EXPECT_THROW(write_exr(dir_ / "taken.exr", Image(1, 1), {}), InputError);
  EXPECT_TRUE(fs::is_directory(dir_ / "taken.exr"));
  EXPECT_EQ(list_folder(dir_), std::vector<std::string>{"taken.exr"});
}

TEST_F(ImageIoTest, WriteReplacesExistingFile) {
  const fs::path exr = dir_ / "out.exr";
  Image first(2, 2);
  first.at(0, 0) = vec3(1.0f);
  write_exr(exr, first, {{"run", "1"}});
  Image second(3, 1);
  second.at(2, 0) = vec3(0.25f, 0.5f, 0.75f);
  write_exr(exr, second, {{"run", "2"}});

  ImageMetadata metadata;
  const Image back = read_image(exr, &metadata);
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.height, 1);
  EXPECT_EQ(back.at(2, 0), vec3(0.25f, 0.5f, 0.75f));
  EXPECT_EQ(metadata, (ImageMetadata{{"run", "2"}}));

  const fs::path png = dir_ / "out.png";
  write_text(png, "old content");
  write_png(png, second);
  EXPECT_EQ(read_image(png).width, 3);
  EXPECT_EQ(list_folder(dir_), (std::vector<std::string>{"out.exr", "out.png"}));
}

TEST_F(ImageIoTest, ReadMissingFileThrowsInputError) {
  const fs::path file = dir_ / "missing.exr";
  try {
    read_image(file);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(file.string() + ": cannot read image: ", 0), 0u) << e.what();
  }
  EXPECT_THROW(read_image(dir_), InputError);
}

TEST_F(ImageIoTest, ReadGarbageThrowsInputError) {
  const fs::path file = dir_ / "garbage.exr";
  write_text(file, "this is not an OpenEXR file, just some text\n");
  try {
    read_image(file);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(file.string() + ": cannot read image: ", 0), 0u) << e.what();
  }
}

TEST_F(ImageIoTest, ReadReplicatesOneChannelAndRejectsTwo) {
  const fs::path gray = dir_ / "gray.exr";
  write_raw_exr(gray, 1, {0.5f, 2.0f}, 2, 1);
  const Image back = read_image(gray);
  EXPECT_EQ(back.at(0, 0), vec3(0.5f));
  EXPECT_EQ(back.at(1, 0), vec3(2.0f));

  const fs::path rgba = dir_ / "rgba.exr";
  write_raw_exr(rgba, 4, {1.0f, 2.0f, 3.0f, 4.0f}, 1, 1);
  EXPECT_EQ(read_image(rgba).at(0, 0), vec3(1.0f, 2.0f, 3.0f));

  const fs::path two = dir_ / "two.exr";
  write_raw_exr(two, 2, {1.0f, 2.0f}, 1, 1);
  try {
    read_image(two);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("2 channels"), std::string::npos) << e.what();
  }
}

TEST(ImageIoSrgb, InverseRoundTripsEveryEightBitCode) {
  for (int c = 0; c < 256; ++c) {
    const float v = static_cast<float>(c) / 255.0f;
    EXPECT_EQ(std::lround(linear_to_srgb(srgb_to_linear(v)) * 255.0f), c);
  }
  EXPECT_EQ(srgb_to_linear(0.0f), 0.0f);
  EXPECT_EQ(srgb_to_linear(1.0f), 1.0f);
}

TEST(ImageIoSrgb, HitsEndpoints) {
  EXPECT_EQ(linear_to_srgb(0.0f), 0.0f);
  EXPECT_EQ(linear_to_srgb(1.0f), 1.0f);
  EXPECT_EQ(linear_to_srgb(-1.0f), 0.0f);
  EXPECT_EQ(linear_to_srgb(5.0f), 1.0f);
  EXPECT_NEAR(linear_to_srgb(0.5f), 0.735357f, 1e-6f);
  EXPECT_NEAR(linear_to_srgb(0.18f), 0.461356f, 1e-6f);
}

TEST(ImageIoSrgb, IsMonotone) {
  float previous = linear_to_srgb(0.0f);
  for (int i = 1; i <= 100000; ++i) {
    const float v = linear_to_srgb(static_cast<float>(i) / 100000.0f);
    ASSERT_GE(v, previous) << "at " << i;
    previous = v;
  }
}

TEST(ImageIoSrgb, IsContinuousAtBreakpoint) {
  const float below = linear_to_srgb(0.0031308f);
  const float above = linear_to_srgb(std::nextafter(0.0031308f, 1.0f));
  EXPECT_NEAR(below, 0.0404500f, 1e-6f);
  // The standard's rounded constants leave a step of about 1e-7 here.
  EXPECT_NEAR(above, below, 1e-6f);
}

}  // namespace
}  // namespace pathlab
