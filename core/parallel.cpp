#include "core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <thread>
#ifdef PATHLAB_TSAN
#include <atomic>
#include <exception>
#include <mutex>
#include <vector>
#endif

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
  const auto chunk = [&](std::size_t c) { fn(body, begin + c * grain, std::min(end, begin + (c + 1) * grain)); };
  if (chunks == 1 || max_threads() == 1) {
    // Same chunks in the same order as the parallel path, on this thread.
    for (std::size_t c = 0; c < chunks; ++c) chunk(c);
    return;
  }
#ifdef PATHLAB_TSAN
  // Under ThreadSanitizer (tools/run-tsan.sh) the chunks run on threads of
  // their own, not on TBB's workers. Debian's libtbb is not instrumented:
  // TSan cannot see its scheduler hand a range from one thread to another
  // and reports hundreds of races in TBB's templates per render, and every
  // worker's stack has libtbb in it, so suppressing those hides every race
  // in pathlab's own code as well (it hid one planted in the wavefront's
  // loop). pthread_create and join are what TSan understands. The same
  // chunks, taken in any order, as with TBB; the first exception a chunk
  // throws is rethrown here, as tbb::parallel_for does.
  const std::size_t threads = std::min<std::size_t>(chunks, static_cast<std::size_t>(max_threads()));
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    try {
      for (std::size_t c; (c = next.fetch_add(1)) < chunks;) chunk(c);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = chunks;
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
#else
  // simple_partitioner with grain 1 over chunk indices: exactly our chunks.
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, chunks, 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t c = r.begin(); c < r.end(); ++c) chunk(c);
      },
      tbb::simple_partitioner());
#endif
}

}  // namespace detail
}  // namespace pathlab
