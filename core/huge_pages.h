// An allocator for large arrays that tracing reads at random (the triangles
// resolve() reads for every hit): on Linux, arrays of 2 MiB or more are
// aligned to 2 MiB and marked MADV_HUGEPAGE, so that the kernel's
// transparent huge pages back them where it allows (Debian's default,
// "madvise", does). One TLB entry then covers 2 MiB instead of 4 KiB: a
// 40 MiB triangle array needs 20 entries instead of 10,000, and a hit's
// triangle no longer costs a page walk as well as a cache miss. Elsewhere,
// or if the kernel declines, the memory is ordinary memory. The vector does
// not zero what it allocates (see HugePageAllocator::construct).
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace pathlab {

namespace detail {
// Raw storage for `bytes` bytes, aligned at least as malloc aligns (to 2 MiB
// and advised MADV_HUGEPAGE from 2 MiB up); throws std::bad_alloc.
void* allocate_huge_page_backed(std::size_t bytes);
void free_huge_page_backed(void* p) noexcept;
}  // namespace detail

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}  // converting, as allocators must
  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(detail::allocate_huge_page_backed(n * sizeof(T)));
  }
  void deallocate(T* p, std::size_t) noexcept { detail::free_huge_page_backed(p); }
  // Elements are default-initialised, not value-initialised: resizing to n
  // trivially constructible elements leaves the new memory untouched, for
  // the owner to fill in parallel (fresh pages then fault in on the thread
  // that fills them; recycled memory holds whatever it held).
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace pathlab
