#include "core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <thread>

namespace pathlab {

struct ThreadLimit::Impl {
  tbb::global_control control;
  explicit Impl(std::size_t n) : control(tbb::global_control::max_allowed_parallelism, n) {}
};

ThreadLimit::ThreadLimit(int threads) {
  const int n = threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  impl_ = std::make_unique<Impl>(static_cast<std::size_t>(n));
}

ThreadLimit::~ThreadLimit() = default;

int max_threads() {
  return static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

namespace detail {

void parallel_for_impl(std::size_t begin, std::size_t end, std::size_t grain, RangeFn fn, void* body) {
  if (begin >= end) return;
  grain = std::max<std::size_t>(grain, 1);
  const std::size_t chunks = (end - begin + grain - 1) / grain;
  if (chunks == 1 || max_threads() == 1) {
    // Same chunks in the same order as the parallel path, on this thread.
    for (std::size_t c = 0; c < chunks; ++c) fn(body, begin + c * grain, std::min(end, begin + (c + 1) * grain));
    return;
  }
  // simple_partitioner with grain 1 over chunk indices: exactly our chunks.
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, chunks, 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t c = r.begin(); c < r.end(); ++c)
          fn(body, begin + c * grain, std::min(end, begin + (c + 1) * grain));
      },
      tbb::simple_partitioner());
}

}  // namespace detail
}  // namespace pathlab
