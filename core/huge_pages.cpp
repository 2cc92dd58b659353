#include "core/huge_pages.h"

#include <cstdlib>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace pathlab::detail {
namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
}

void* allocate_huge_page_backed(std::size_t bytes) {
  if (bytes == 0) bytes = 1;
  if (bytes < kHugePage) {
    if (void* p = std::malloc(bytes)) return p;
    throw std::bad_alloc();
  }
  // aligned_alloc wants a multiple of the alignment.
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, rounded);
  if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // Advice only: if the kernel has no transparent huge pages, the memory
  // stays as it is.
  (void)madvise(p, rounded, MADV_HUGEPAGE);
#endif
  return p;
}

void free_huge_page_backed(void* p) noexcept { std::free(p); }

}  // namespace pathlab::detail
