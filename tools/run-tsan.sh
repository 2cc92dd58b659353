#!/usr/bin/env bash
# ThreadSanitizer over pathlab's threaded code: the one parallel_for
# (core/parallel.*) as the film (tests/test_film.cpp) and the wavefront
# tracer (tests/test_wavefront.cpp) use it, at one and two threads.
# Configures and builds BUILD_DIR (default build-tsan) with clang and
# -DPATHLAB_TSAN=ON, then runs those tests; fails on any report.
#
#   tools/run-tsan.sh [BUILD_DIR]
#
# TBB: Debian's libtbb is not built with TSan, so the synchronisation inside
# its scheduler (task hand-off between worker threads) is invisible to it. The
# hand-offs pathlab relies on go through tbb::parallel_for's templates, which
# are compiled into pathlab's own (instrumented) code; fuzz/tsan.supp
# suppresses reports whose racing access lies inside libtbb itself only,
# never one in pathlab's code.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build-tsan}"
CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPATHLAB_WERROR=ON \
  -DPATHLAB_TSAN=ON -DPATHLAB_BUILD_GUI=OFF -DPATHLAB_WITH_VTK=OFF -DPATHLAB_WITH_MPI=OFF -DPATHLAB_BUILD_BENCH=OFF \
  ${PATHLAB_DATA_DIR:+-DPATHLAB_DATA_DIR="$PATHLAB_DATA_DIR"} >/dev/null
cmake --build "$build" --target pathlab_unit_tests pathlab_stat_tests
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$root/fuzz/tsan.supp ${TSAN_OPTIONS:-}"
"$build/tests/pathlab_unit_tests" --gtest_brief=1 --gtest_filter='Film.*'
"$build/tests/pathlab_stat_tests" --gtest_brief=1 \
  --gtest_filter='Wavefront.*:Tracers.*:*SameSeed.*:*VectorStages.*'
echo "run-tsan: no ThreadSanitizer report"
