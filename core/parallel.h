// The one parallel loop of pathlab, over TBB. Everything that runs in
// parallel goes through parallel_for, so a ThreadLimit of 1 really makes a
// render single-threaded.
#pragma once

#include <cstddef>
#include <memory>
#include <utility>

namespace pathlab {

// While alive, limits every parallel_for to `threads` worker threads
// (0 = all hardware threads). Nested limits combine: the smallest wins.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Number of threads a parallel_for would use now.
int max_threads();

namespace detail {
using RangeFn = void (*)(void* body, std::size_t begin, std::size_t end);
void parallel_for_impl(std::size_t begin, std::size_t end, std::size_t grain, RangeFn fn, void* body);
}  // namespace detail

// Calls body(b, e) on disjoint sub-ranges [b, e) covering [begin, end), each
// at most `grain` long (and at least, except the last). The split depends
// only on (begin, end, grain), never on the thread count, so results that
// depend on the chunking are still deterministic.
template <typename Body>
void parallel_for(std::size_t begin, std::size_t end, std::size_t grain, Body&& body) {
  auto call = [](void* b, std::size_t lo, std::size_t hi) { (*static_cast<std::remove_reference_t<Body>*>(b))(lo, hi); };
  detail::parallel_for_impl(begin, end, grain, call, &body);
}

}  // namespace pathlab
