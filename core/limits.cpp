#include "core/limits.h"

#include "core/error.h"
#include "core/messages.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cstring>

namespace pathlab {
namespace {

constexpr std::uint64_t kMB = 1024 * 1024;

std::uint64_t default_limit_mb() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  const std::uint64_t half = pages > 0 && page > 0 ? static_cast<std::uint64_t>(pages) * page / 2 / kMB : 0;
  return std::max<std::uint64_t>(half, 1024);
}

std::uint64_t limit_mb() {
  const char* text = std::getenv("PATHLAB_MAX_MEMORY_MB");
  if (text == nullptr || *text == '\0') return default_limit_mb();
  std::uint64_t mb = 0;
  const char* end = text + std::strlen(text);
  const auto [ptr, ec] = std::from_chars(text, end, mb);
  if (ec != std::errc() || ptr != end || mb < 1 || mb > (std::uint64_t{1} << 40))
    throw InputError("PATHLAB_MAX_MEMORY_MB=" + quote_input(text) + ": expected a whole number of MB in [1, 2^40]");
  return mb;
}

}  // namespace

std::uint64_t memory_limit_bytes() { return limit_mb() * kMB; }

std::string memory_limit_note() {
  return " (the limit is " + std::to_string(limit_mb()) +
         " MB: set PATHLAB_MAX_MEMORY_MB to raise it; docs/scene-format.md, 'Limits')";
}

void check_memory(std::uint64_t bytes, const std::string& what) {
  if (bytes <= memory_limit_bytes()) return;
  throw InputError(what + " needs " + std::to_string((bytes + kMB - 1) / kMB) + " MB, more than the memory limit" +
                   memory_limit_note());
}

std::string special_file_kind(const std::filesystem::path& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) return {};  // missing or unreadable: the opener says which
  if (S_ISREG(st.st_mode)) return {};
  return S_ISDIR(st.st_mode)    ? "a folder"
         : S_ISFIFO(st.st_mode) ? "a FIFO"
         : S_ISCHR(st.st_mode)  ? "a character device"
         : S_ISBLK(st.st_mode)  ? "a block device"
         : S_ISSOCK(st.st_mode) ? "a socket"
                                : "a special file";
}

void require_regular_file(const std::filesystem::path& file, std::string_view what) {
  if (const std::string kind = special_file_kind(file); !kind.empty())
    throw InputError(file.string() + ": " + std::string(what) + " must be a regular file, not " + kind);
}

}  // namespace pathlab
