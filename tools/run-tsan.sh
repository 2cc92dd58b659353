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
# its scheduler (task hand-off between worker threads) is invisible to it,
# and a suppression of libtbb matches every stack on one of its workers. So a
# TSan build runs pathlab's parallel_for on std::threads (core/parallel.cpp);
# TBB's workers then run only Embree's BVH builds, and fuzz/tsan.supp
# suppresses what Embree, TBB and OpenImageIO do inside themselves. First the
# run proves it can fail: a race planted in a parallel_for
# (Parallel.PlantedRaceForThreadSanitizer) must be reported.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build-tsan}"
CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPATHLAB_WERROR=ON \
  -DPATHLAB_TSAN=ON -DPATHLAB_BUILD_GUI=OFF -DPATHLAB_WITH_VTK=OFF -DPATHLAB_WITH_MPI=OFF -DPATHLAB_BUILD_BENCH=OFF \
  ${PATHLAB_DATA_DIR:+-DPATHLAB_DATA_DIR="$PATHLAB_DATA_DIR"} >/dev/null
cmake --build "$build" --target pathlab_unit_tests pathlab_stat_tests
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$root/fuzz/tsan.supp ${TSAN_OPTIONS:-}"
planted="$build/planted-race.log"
if PATHLAB_TSAN_PLANTED_RACE=1 "$build/tests/pathlab_unit_tests" --gtest_filter='Parallel.PlantedRaceForThreadSanitizer' \
    > "$planted" 2>&1 || ! grep -q 'ThreadSanitizer: data race' "$planted"; then
  echo "run-tsan: the race planted in a parallel_for was not reported ($planted): this run could not fail" >&2
  exit 1
fi
echo "run-tsan: the planted race is reported"
"$build/tests/pathlab_unit_tests" --gtest_brief=1 --gtest_filter='Film.*'
"$build/tests/pathlab_stat_tests" --gtest_brief=1 \
  --gtest_filter='Wavefront.*:Tracers.*:*SameSeed.*:*VectorStages.*'
echo "run-tsan: no ThreadSanitizer report"
