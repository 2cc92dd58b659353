// Environment images (core/environment_map.cpp over core/image_io.cpp's
// read_image, i.e. OpenImageIO): load_environment_map on the bytes written
// as .hdr (Radiance RGBE: "#?" magic, or anything unrecognised), .exr
// (OpenEXR magic) or .png (PNG magic), with clamp_negative off so that
// every texel check runs. The decoders are Debian's, not instrumented for
// coverage or ASan: the fuzzer steers by pathlab's own checks on what they
// return (channels, 2:1 shape, NaN/Inf/negative texels, scale).
//
// OpenImageIO, when a file fails to open as its extension says, tries every
// other reader it has; on mutated bytes that is nearly every input, at a few
// executions per second. The target turns that off (OIIO's global
// "try_all_readers" = 0), which only changes what a misnamed file gets.
#include "fuzz/fuzz_target.h"

#include "core/environment_map.h"

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <string>

namespace pathlab::fuzz {

int envmap(const std::uint8_t* data, std::size_t size) {
  static const bool one_reader = OIIO::attribute("try_all_readers", 0);
  (void)one_reader;
  const char* name = "input.hdr";
  if (size >= 4 && std::memcmp(data, "\x76\x2f\x31\x01", 4) == 0) name = "input.exr";
  if (size >= 4 && std::memcmp(data, "\x89PNG", 4) == 0) name = "input.png";
  const std::filesystem::path file = write_input(name, data, size);
  return expect_input_error_only([&] {
    std::string warning;
    load_environment_map(file, 2.0f, mat3(1.0f), false, &warning);
  });
}

}  // namespace pathlab::fuzz

PATHLAB_FUZZ_TARGET(envmap)
