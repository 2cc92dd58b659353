// Partial films / checkpoints (core/partial_film.cpp): read_partial_film.
// A real file ends in an XXH3-128 checksum of everything before it, which a
// mutation would almost always break, stopping the reader before it looks at
// the header. So an input is a file WITHOUT its checksum, and the target
// appends the right one: every mutation of the header and arrays reaches the
// reader's checks. (A wrong checksum is one test in tests/test_partial_film.cpp.)
#include "fuzz/fuzz_target.h"

#include "core/partial_film.h"

#include <xxhash.h>

#include <vector>

namespace pathlab::fuzz {

int partial_film(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  const XXH128_hash_t h = XXH3_128bits(data, size);
  for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<std::uint8_t>(h.low64 >> (8 * i)));
  for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<std::uint8_t>(h.high64 >> (8 * i)));
  const std::filesystem::path file = write_input("input.pfilm", bytes.data(), bytes.size());
  return expect_input_error_only([&] { read_partial_film(file); });
}

}  // namespace pathlab::fuzz

PATHLAB_FUZZ_TARGET(partial_film)
