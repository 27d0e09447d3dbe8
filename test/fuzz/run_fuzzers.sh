#!/bin/bash
# Builds the fuzz targets (test/fuzz/CMakeLists.txt: clang, libFuzzer + ASan + UBSan, in
# build/fuzz) and runs them one at a time, each for SECONDS (default 10) or, with --runs N, for
# exactly N executions. Each starts from the seeds its own binary writes with the package's writers
# (VIPER_FUZZ_SEEDS) and the inputs that once failed (test/fuzz/regressions/TARGET), with the
# dictionary test/fuzz/dict/TARGET.dict where there is one.
# Usage: test/fuzz/run_fuzzers.sh [--runs N] [--work DIR] [SECONDS] [TARGET...]
#   TARGET: a name of test/fuzz/CMakeLists.txt's viper_fuzzer() lines (default: all), e.g. npy;
#   SECONDS may be left out before a TARGET.
# Prints one line per target, "fuzz TARGET: PASSED (N runs in S s)" or "fuzz TARGET: FAILED (...)";
# exits 0 if all passed, 1 if one failed, 2 if the targets could not be built. A failed target's
# log and crashing input stay in the work folder (default: a new folder under /tmp, removed when
# every target passed).
set -u
repo=$(cd "$(dirname "$0")/../.." && pwd)
runs=""
work=""
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    *) break ;;
  esac
done
seconds=10
if [[ "${1:-}" =~ ^[0-9]+$ ]]; then seconds=$1; shift; fi
all=$(sed -n 's/^viper_fuzzer(\([a-z_]*\) .*/\1/p' "$repo/test/fuzz/CMakeLists.txt")
targets=${*:-$all}
for t in $targets; do
  if ! grep -qx "$t" <<< "$all"; then echo "fuzz: unknown target '$t' (targets: $(echo $all))"; exit 2; fi
done
own_work=0
[ -z "$work" ] && { work=$(mktemp -d /tmp/viper_fuzz.XXXXXX); own_work=1; }
mkdir -p "$work"
build="$repo/build/fuzz"

cxx=${CXX_FUZZ:-clang++}
if ! command -v "$cxx" > /dev/null; then
  echo "fuzz: FAILED ($cxx not found; install the Debian package clang)"
  exit 2
fi
if [ ! -f "$repo/devel/include/viper/DrawList.h" ] && [ -f "$repo/build/Makefile" ]; then
  nice make -C "$repo/build" viper_generate_messages_cpp > "$work/messages.log" 2>&1
fi
echo "building fuzz targets in $build (log: $work/build.log)"
if ! { nice cmake -S "$repo/test/fuzz" -B "$build" -DCMAKE_CXX_COMPILER="$cxx" &&
       nice cmake --build "$build" -j "${FUZZ_JOBS:-2}" --target $(printf '%s_fuzzer ' $targets); } \
     > "$work/build.log" 2>&1; then
  tail -n 30 "$work/build.log"
  echo "fuzz: FAILED (targets did not build: $work/build.log; libFuzzer comes with the Debian package clang)"
  exit 2
fi

failed=0
for t in $targets; do
  bin="$build/${t}_fuzzer"
  mkdir -p "$work/$t/seeds" "$work/$t/corpus"
  if ! VIPER_FUZZ_SEEDS="$work/$t/seeds" "$bin" > "$work/$t/seeds.log" 2>&1; then
    echo "fuzz $t: FAILED (seeds: $(tail -n 1 "$work/$t/seeds.log"))"
    failed=1
    continue
  fi
  limit=(-max_total_time="$seconds")
  [ -n "$runs" ] && limit=(-runs="$runs")
  regressions=()
  [ -d "$repo/test/fuzz/regressions/$t" ] && regressions=("$repo/test/fuzz/regressions/$t")
  dict=()
  [ -f "$repo/test/fuzz/dict/$t.dict" ] && dict=(-dict="$repo/test/fuzz/dict/$t.dict")
  # rss/malloc limits well above what a reader may allocate for a 16 KiB input; leaks are
  # detected at exit; an input that takes 30 s is a hang.
  start=$(date +%s)
  "$bin" "$work/$t/corpus" "$work/$t/seeds" "${regressions[@]}" "${limit[@]}" "${dict[@]}" -max_len=16384 -timeout=30 \
    -rss_limit_mb=4096 -malloc_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$work/$t/" \
    > "$work/$t/fuzz.log" 2>&1
  rc=$?
  elapsed=$(( $(date +%s) - start ))
  executed=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/$t/fuzz.log" | grep -o '[0-9]*$')
  if [ $rc -eq 0 ]; then
    echo "fuzz $t: PASSED (${executed:-?} runs in $elapsed s)"
  else
    grep -m 3 -E '^==[0-9]+==ERROR|SUMMARY|deadly signal|Timeout|out-of-memory' "$work/$t/fuzz.log" | sed 's/^/  /'
    echo "fuzz $t: FAILED (exit $rc after ${executed:-?} runs; log and input in $work/$t)"
    failed=1
  fi
done
# A folder of our own is removed when every target passed; a failure's log and input stay.
[ $failed -eq 0 ] && [ $own_work -eq 1 ] && rm -rf "$work"
exit $failed
