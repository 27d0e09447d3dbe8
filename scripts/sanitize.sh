#!/usr/bin/env bash
# The package built with sanitizers in a tree of its own outside the package (VIPER_SANITIZE_DIR,
# default /tmp/viper-sanitize-KIND, with build/ and devel/: asan is AddressSanitizer with
# LeakSanitizer and UndefinedBehaviorSanitizer, tsan ThreadSanitizer; not inside the package, where
# rosrun would find a second copy of every executable), then every gtest binary run from it. A sanitizer report fails the test (halt_on_error; UBSan is fatal).
# Programs the tests start (generate, capture, world, ...) come from the same tree, so they run
# sanitized too; the capture layer preloaded into a sanitized program skips ASan's link-order check.
# Prints a line per test binary and ends with "N passed, N failed"; logs in VIPER_SANITIZE_DIR/logs/.
# Usage: scripts/sanitize.sh [asan|tsan] [TEST_NAME_REGEX]   (the build alone takes about 40 minutes
# on 2 cores; rostests are not run)
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
kind=${1:-asan}
filter=${2:-.}
case "$kind" in
  asan) flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" ;;
  tsan) flags="-fsanitize=thread -fno-omit-frame-pointer" ;;
  *) echo "usage: scripts/sanitize.sh [asan|tsan] [TEST_NAME_REGEX]" >&2; exit 2 ;;
esac
root=${VIPER_SANITIZE_DIR:-${TMPDIR:-/tmp}/viper-sanitize-$kind}
build="$root/build" devel="$root/devel" logs="$root/logs"
mkdir -p "$build" "$logs"
launcher=()
command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
(cd "$build" && cmake "$here" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DPython3_EXECUTABLE=/usr/bin/python3 -DCATKIN_DEVEL_PREFIX="$devel" "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" \
  -DCMAKE_SHARED_LINKER_FLAGS="$flags" > "$logs/cmake.log" 2>&1 &&
  make -j"$(nproc)" all tests > "$logs/make.log" 2>&1) ||
  { echo "sanitize: the $kind build failed; see $logs/"; echo "0 passed, 1 failed"; exit 1; }

# Leak detection is on by default; our GL programs turn it off for Mesa (gl_common/sanitizer_options.h).
export ASAN_OPTIONS="halt_on_error=1:verify_asan_link_order=0:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1"
# ROS's own libraries are not ours to fix: their known leaks at exit are suppressed by file.
export LSAN_OPTIONS="suppressions=$here/scripts/sanitize_lsan.supp:print_suppressions=0"
passed=0 failed=0
cd "$here"
for t in "$devel"/lib/viper/test_*; do
  name=$(basename "$t")
  [[ "$name" =~ $filter ]] || continue
  "$t" --gtest_list_tests > /dev/null 2>&1 || continue  # a program (test_scene), not a gtest
  if timeout 1200 "$t" > "$logs/$name.log" 2>&1; then
    passed=$((passed + 1)); echo "sanitize $kind: $name passed"
  else
    failed=$((failed + 1)); echo "sanitize $kind: $name FAILED ($logs/$name.log)"
    grep -m3 -E "ERROR: (Address|Leak|Thread)Sanitizer|runtime error:|WARNING: ThreadSanitizer|\[  FAILED  \]" \
      "$logs/$name.log" | sed 's/^/    /'
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
