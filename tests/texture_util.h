// Images for texture tests, written with OpenImageIO.
#pragma once

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace pathlab::test {

// Writes `texels` (row by row from the top, channels interleaved) as `file`
// in `format` (FLOAT for EXR, UINT8 for PNG: texels are then codes / 255).
inline void write_image(const std::filesystem::path& file, int width, int height, int channels,
                        const std::vector<float>& texels, OIIO::TypeDesc format = OIIO::TypeDesc::FLOAT) {
  ASSERT_EQ(texels.size(), static_cast<std::size_t>(width * height * channels));
  auto out = OIIO::ImageOutput::create(file.string());
  ASSERT_TRUE(out) << OIIO::geterror();
  const OIIO::ImageSpec spec(width, height, channels, format);
  ASSERT_TRUE(out->open(file.string(), spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, texels.data())) << out->geterror();
  ASSERT_TRUE(out->close());
}

}  // namespace pathlab::test
