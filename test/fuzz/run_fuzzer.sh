#!/bin/bash
# Builds the capture stream fuzzer with clang (libFuzzer + ASan + UBSan) straight from the core
# sources, seeds it with a valid stream and payload, and runs it for SECONDS (default 20).
# Usage: test/fuzz/run_fuzzer.sh [SECONDS] [WORK_DIR]
# Prints "fuzz: PASSED (N runs)" or "fuzz: FAILED ..." last; exits non-zero on any crash or leak.
set -u
seconds=${1:-20}
repo=$(cd "$(dirname "$0")/../.." && pwd)
work=${2:-$(mktemp -d /tmp/viper_fuzz.XXXXXX)}
mkdir -p "$work/corpus"

cxx=${CXX_FUZZ:-clang++}
if ! command -v "$cxx" > /dev/null; then
  echo "fuzz: FAILED ($cxx not found; install the Debian package clang)"
  exit 2
fi
sources=("$repo"/src/capture/capture_stream*.cpp "$repo/src/capture/capture_frame.cpp" "$repo/src/capture/content_key.cpp")
flags=(-std=c++17 -O1 -g -I "$repo/include" -I /usr/include/eigen3)
libs=(-lzstd -lxxhash)

echo "building fuzzer in $work"
if ! "$cxx" "${flags[@]}" -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
    "$repo/test/fuzz/capture_reader_fuzzer.cpp" "${sources[@]}" "${libs[@]}" -o "$work/capture_reader_fuzzer"; then
  echo "fuzz: FAILED (fuzzer did not build; libFuzzer comes with clang's runtime, Debian package libclang-rt-14-dev or clang)"
  exit 2
fi
if ! "$cxx" "${flags[@]}" "$repo/test/fuzz/make_seed_corpus.cpp" "${sources[@]}" "${libs[@]}" \
    -o "$work/make_seed_corpus" || ! "$work/make_seed_corpus" "$work/corpus"; then
  echo "fuzz: FAILED (seed corpus)"
  exit 2
fi

# rss/malloc limits well above the reader's 1 GiB payload cap; leaks are detected at exit.
"$work/capture_reader_fuzzer" "$work/corpus" -max_total_time="$seconds" -max_len=65536 \
  -rss_limit_mb=4096 -malloc_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$work/" \
  > "$work/fuzz.log" 2>&1
rc=$?
runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/fuzz.log" | grep -o '[0-9]*$')
if [ $rc -eq 0 ]; then
  echo "fuzz: PASSED (${runs:-?} runs)"
  exit 0
fi
tail -n 40 "$work/fuzz.log"
echo "fuzz: FAILED (exit $rc after ${runs:-?} runs; log and crashing input in $work)"
exit 1
