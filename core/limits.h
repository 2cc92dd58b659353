// How much memory one input or output may take, so that a gzip bomb, a mesh
// path that names /dev/zero or a 65536^2 film with every AOV is refused with
// a message that names it, before anything is allocated, instead of ending
// in "out of memory" or the OOM killer.
//
// One limit, in MB, from the environment variable PATHLAB_MAX_MEMORY_MB
// (a whole number >= 1); without it, half the machine's physical memory
// (at least 1024 MB). It caps, each on its own:
//   - a mesh file's bytes, and its bytes after gzip decompression (counted
//     as they are inflated);
//   - a render's film: its sums, its variance, its AOV buffers and the image
//     written from it (cmd_render's estimate, docs/scene-format.md "Limits").
// Raise it deliberately for a larger input: PATHLAB_MAX_MEMORY_MB=65536.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace pathlab {

// The limit in bytes. Throws InputError if PATHLAB_MAX_MEMORY_MB is set but
// is not a whole number >= 1.
std::uint64_t memory_limit_bytes();

// Throws InputError "<what> needs N MB, more than the memory limit of M MB
// (PATHLAB_MAX_MEMORY_MB ...)" if `bytes` exceeds the limit.
void check_memory(std::uint64_t bytes, const std::string& what);

// The end of such a message: " (the limit is M MB: PATHLAB_MAX_MEMORY_MB=...
// raises it)".
std::string memory_limit_note();

// "a character device", "a FIFO", "a folder", ... if `file` exists and is
// not a regular file (after symbolic links); "" otherwise.
std::string special_file_kind(const std::filesystem::path& file);

// Throws InputError "<file>: <what> is not a regular file (a device, a
// FIFO or a folder)" if `file` exists and is not one (after symbolic links).
// A missing file is left to whoever opens it.
void require_regular_file(const std::filesystem::path& file, std::string_view what);

}  // namespace pathlab
