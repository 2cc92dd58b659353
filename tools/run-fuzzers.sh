#!/usr/bin/env bash
# Runs every libFuzzer target of a PATHLAB_FUZZ=ON build (fuzz/, README
# "Fuzzing and sanitizers") for a bounded time or number of executions, one
# after the other, starting from its committed corpus (fuzz/corpus/<name>/).
# Fails (exit 1) on the first crash, leak, sanitizer report, timeout (an
# input that takes over 10 s) or out-of-memory (over 2 GB, or one allocation
# over 1 GB); the input that did it is left in out/fuzz/<name>/ as
# crash-*/leak-*/timeout-*/oom-*: fix the loader and keep it in the corpus.
#
#   tools/run-fuzzers.sh BUILD_DIR [--time SECONDS | --runs N] [TARGET...]
#
# --time 45 (the default) is what CI runs; --runs 1000000 the long check
# (ctest label long). New inputs the fuzzer finds go to out/fuzz/<name>/new/,
# never into the repository's corpus.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:?usage: tools/run-fuzzers.sh BUILD_DIR [--time S | --runs N] [TARGET...]}"
shift
build="$(cd "$build" && pwd)"
limit=(-max_total_time=45)
if [ "${1:-}" = "--time" ]; then limit=(-max_total_time="$2"); shift 2
elif [ "${1:-}" = "--runs" ]; then limit=(-runs="$2"); shift 2
fi
targets=("$@")
# envmap only when named: through Debian's OpenImageIO it runs at tens of
# executions per second, not thousands (README, "Fuzzing and sanitizers").
if [ ${#targets[@]} -eq 0 ]; then targets=(gltf obj partial_film ply scene); fi
out="${PATHLAB_FUZZ_OUT:-$root/out/fuzz}"
# A UBSan report is a finding too (by default UBSan prints and goes on).
export UBSAN_OPTIONS="print_stacktrace=1 halt_on_error=1 ${UBSAN_OPTIONS:-}"
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp ${LSAN_OPTIONS:-}"

failed=()
for name in "${targets[@]}"; do
  exe="$build/fuzz/fuzz_$name"
  if [ ! -x "$exe" ]; then echo "run-fuzzers: $exe missing (configure with -DPATHLAB_FUZZ=ON, clang)" >&2; exit 2; fi
  mkdir -p "$out/$name/new"
  dict=()
  if [ -f "$root/fuzz/$name.dict" ]; then dict=(-dict="$root/fuzz/$name.dict"); fi
  start=$(date +%s)
  echo "run-fuzzers: $name (${limit[*]})"
  if ! "$exe" "${limit[@]}" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 -print_final_stats=1 \
      "${dict[@]}" -artifact_prefix="$out/$name/" "$out/$name/new" "$root/fuzz/corpus/$name" \
      > "$out/$name/log.txt" 2>&1; then
    failed+=("$name")
    echo "run-fuzzers: $name FAILED; the end of $out/$name/log.txt:" >&2
    tail -n 60 "$out/$name/log.txt" >&2
  fi
  grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb" "$out/$name/log.txt" | tr '\n' ' ' || true
  echo "($(( $(date +%s) - start )) s)"
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "run-fuzzers: ${#failed[@]} failed: ${failed[*]}" >&2
  exit 1
fi
echo "run-fuzzers: ${#targets[@]} targets, no finding"
