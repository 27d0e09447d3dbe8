#!/usr/bin/env bash
# The package built with sanitizers in a tree of its own outside the package (VIPER_SANITIZE_DIR,
# default /tmp/viper-sanitize-KIND, with build/ and devel/: asan is AddressSanitizer with
# LeakSanitizer and UndefinedBehaviorSanitizer, tsan ThreadSanitizer; not inside the package, where
# rosrun would find a second copy of every executable), then every gtest binary and every rostest run
# from it, with that tree's devel/setup.bash sourced. A sanitizer report fails the test (halt_on_error;
# UBSan is fatal). Programs the tests start (generate, capture, world, the nodes and nodelets the
# launch files start, ...) come from the same tree, so they run sanitized too; the capture layer
# preloaded into a sanitized program skips ASan's link-order check. The nodelet manager is Debian's
# uninstrumented /usr/lib/nodelet/nodelet: a wrapper in the tree's devel space (found first by
# roslaunch) starts it with the sanitizer's runtime preloaded, which the instrumented nodelets need.
# Rostests (the catkin targets run_tests_viper_rostest_*): a test fails on a failed or missing result
# (build/test_results), or on a sanitizer report from any process it started: reports go to files
# (log_path, VIPER_SANITIZE_DIR/reports/N/) and the ROS logs (ROS_HOME, ROS_LOG_DIR inside the tree,
# ros_home/log/N/) and the rostest's output are searched for one too. VIPER_TEST_TIME_SCALE (default
# 1 for asan, 4 for tsan) multiplies the rostests' time limits and the testers' timeouts.
# First, after the build, the sanitized capture layer is checked to start at all (preloaded into
# /bin/true and into a sanitized program, and `capture` of the GL test program): the layer exports
# dlsym, which the sanitizer's runtime calls from its own start (docs/sanitizers.md); a failure there
# is one failed test, named "capture layer".
# Each rostest holds /tmp/viper-rostest.lock (VIPER_ROSTEST_LOCK) while it runs, as other checkouts'
# rostests do (they share rostest's port).
# Prints a line per test and ends with "N passed, N failed" (gtest binaries and rostests counted
# apart first); logs in VIPER_SANITIZE_DIR/logs/.
# Usage: scripts/sanitize.sh [asan|tsan] [TEST_NAME_REGEX]   (the regex selects gtest binaries and
# rostests by name; VIPER_SANITIZE_TESTS=gtest or rostest runs only those; the build alone takes
# about 40 minutes on 2 cores; docs/sanitizers.md)
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
kind=${1:-asan}
filter=${2:-.}
suites=${VIPER_SANITIZE_TESTS:-all}
case "$kind" in
  asan) flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" ;;
  tsan) flags="-fsanitize=thread -fno-omit-frame-pointer" ;;
  *) echo "usage: scripts/sanitize.sh [asan|tsan] [TEST_NAME_REGEX]" >&2; exit 2 ;;
esac
root=${VIPER_SANITIZE_DIR:-${TMPDIR:-/tmp}/viper-sanitize-$kind}
build="$root/build" devel="$root/devel" logs="$root/logs"
mkdir -p "$build" "$logs"
# The options hold for the programs the build runs too (the tests' data: captures, layouts).
# Leak detection is on by default; our GL programs turn it off for Mesa (gl_common/sanitizer_options.h).
export ASAN_OPTIONS="halt_on_error=1:verify_asan_link_order=0:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# ROS's libraries are Debian's, not instrumented: TSan sees their mutexes (through its pthread
# interceptors) but not their atomics, so their own memcpy, send, new and delete look racy.
# ignore_noninstrumented_modules drops the accesses of interceptors called from such a library
# (its locks still count); the lock-order inversions inside ROS are suppressed by library.
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:ignore_noninstrumented_modules=1:suppressions=$here/scripts/sanitize_tsan.supp"
# GCC 12's ThreadSanitizer instrumentation of the AVX-512 flow kernel (flow_avx512.cpp) changes what
# it computes (pixels counted twice and as without depth: test_flow_from_metres fails), while the same
# file built without TSan at -O0, -O1, -O3 or with UBSan agrees with the scalar path: under TSan the
# kernels stop at AVX2 (VIPER_INSTRUCTIONS, instructions.h).
[ "$kind" = tsan ] && export VIPER_INSTRUCTIONS=${VIPER_INSTRUCTIONS:-avx2}
# ROS's own libraries are not ours to fix: their known leaks at exit are suppressed by file.
export LSAN_OPTIONS="suppressions=$here/scripts/sanitize_lsan.supp:print_suppressions=0"
# A tree configured from another checkout: cmake would refuse it ("does not match the source").
cached=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$build/CMakeCache.txt" 2>/dev/null)
if [ -n "$cached" ] && ! [ "$cached/CMakeLists.txt" -ef "$here/CMakeLists.txt" ]; then
  echo "sanitize: $build was configured from $cached, not $here: run $cached/scripts/sanitize.sh," \
    "or set VIPER_SANITIZE_DIR to another tree (or remove $build for a full build from here)"
  echo "0 passed, 1 failed"; exit 1
fi
launcher=()
command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
(cd "$build" && cmake "$here" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DPython3_EXECUTABLE=/usr/bin/python3 -DCATKIN_DEVEL_PREFIX="$devel" "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" \
  -DCMAKE_SHARED_LINKER_FLAGS="$flags" -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=TRUE > "$logs/cmake.log" 2>&1) ||
  { echo "sanitize: cmake failed; see $logs/cmake.log"; echo "0 passed, 1 failed"; exit 1; }
# The build runs programs too (captures of the test scene and the world for the tests' data): with
# -k a step that fails there is one failed test, and the tests that do not need it still run.
build_failed=0
if ! make -C "$build" -k -j"$(nproc)" all tests > "$logs/make.log" 2>&1; then
  build_failed=1
  echo "sanitize $kind: the build FAILED ($logs/make.log); the tests that were built still run:"
  grep -E "\*\*\* .*(Error|Segmentation)" "$logs/make.log" | grep -v "Makefile2\|Makefile:" | head -5 | sed 's/^/    /'
fi

# Everything the tests start by package and name (rosrun, roslaunch, rostest) comes from this tree.
export ROS_HOME="$root/ros_home" ROS_LOG_DIR="$root/ros_home/log"
# That tree's devel space, Debian's python3 first on PATH (scripts/package_binaries.sh, as in
# scripts/test.sh); the tree's executables are $devel/lib/viper.
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_ros_env sanitize "$devel"
report='ERROR: (Address|Leak|Thread)Sanitizer|runtime error:|WARNING: ThreadSanitizer'
cd "$here" || exit 1

# The capture layer first: every capture the tests make (and the build's test data) goes through it.
# Its exported dlsym answers the sanitizer runtime's own lookups at the runtime's start; when that
# went wrong, every program it was preloaded into crashed before main (docs/sanitizers.md). Checked
# preloaded alone into an uninstrumented program (the runtime loaded after libc, as the layer's
# dependency) and into an instrumented one (the runtime after the layer), and through `capture`
# (which preloads the runtime first) on the GL test program, its stream read back whole.
layer_failed=0
layer_check() {
  local lib="$devel/lib/libviper_intercept.so" out="$root/layer_check" why=""
  rm -rf "$out" && mkdir -p "$out"
  [ -f "$lib" ] || { echo "$lib missing" > "$out/why"; return 1; }
  ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0" LD_PRELOAD="$lib" timeout 60 /bin/true > "$out/true.log" 2>&1 ||
    why="$why preloaded into /bin/true (exit $?, $out/true.log);"
  LD_PRELOAD="$lib" timeout 60 "$devel/lib/viper/capture" --help > "$out/capture_help.log" 2>&1 &&
    grep -q "^usage:" "$out/capture_help.log" ||
    why="$why preloaded into the sanitized capture --help ($out/capture_help.log);"
  for mode in direct dlopen; do
    if timeout 300 "$devel/lib/viper/capture" --output "$out/$mode.vcap" -- \
      "$devel/lib/viper/viper_gl_test_program" --mode "$mode" --frames 3 > "$out/$mode.log" 2>&1; then
      "$devel/lib/viper/capture_info" "$out/$mode.vcap" > "$out/${mode}_info.log" 2>&1 ||
        why="$why capture_info on the $mode stream ($out/${mode}_info.log);"
    else
      why="$why capture of viper_gl_test_program --mode $mode (exit $?, $out/$mode.log);"
    fi
  done
  if grep -lE "$report" "$out"/*.log > /dev/null 2>&1; then why="$why a sanitizer report in $out;"; fi
  [ -z "$why" ] || { echo "$why" > "$out/why"; return 1; }
}
if layer_check; then
  echo "sanitize $kind: capture layer passed"
else
  layer_failed=1
  echo "sanitize $kind: capture layer FAILED: $(cat "$root/layer_check/why")"
  grep -h -m3 -E "$report|SUMMARY|Segmentation|runtime does not come first" "$root/layer_check"/*.log 2>/dev/null | sed 's/^/    /'
fi

gtest_passed=0 gtest_failed=0
for t in "$devel"/lib/viper/test_*; do
  name=$(basename "$t")
  [[ "$name" =~ $filter && "$suites" != rostest ]] || continue
  "$t" --gtest_list_tests > /dev/null 2>&1 || continue  # a program (test_scene), not a gtest
  if timeout 1200 "$t" > "$logs/$name.log" 2>&1; then
    gtest_passed=$((gtest_passed + 1)); echo "sanitize $kind: $name passed"
  else
    gtest_failed=$((gtest_failed + 1)); echo "sanitize $kind: $name FAILED ($logs/$name.log)"
    grep -m3 -E "$report|\[  FAILED  \]" "$logs/$name.log" | sed 's/^/    /'
  fi
done
echo "gtest binaries: $gtest_passed passed, $gtest_failed failed"

# Rostests, one at a time. The nodelet manager is Debian's uninstrumented executable; roslaunch
# finds this wrapper first (the tree's devel space comes first in CMAKE_PREFIX_PATH), which preloads
# the sanitizer's runtime: an instrumented library dlopened into a program without it cannot run.
case "$kind" in
  asan) runtime=$(gcc -print-file-name=libasan.so) ;;
  tsan) runtime=$(gcc -print-file-name=libtsan.so) ;;
esac
mkdir -p "$devel/lib/nodelet"
# LeakSanitizer's check at exit does not scan thread-local storage in the manager (use_tls=0): the
# runtime (GCC 12's) crashed scanning it in supertuxkart_live's manager, twice of twice ("Tracer
# caught signal 11" after "DTLS 20 at 0x000000008922-0x001000009a24"), most likely a stale entry
# after glibc moved the DTV (_dl_resize_dtv) for the many libraries with thread-local variables
# the manager dlopens. Without that scan, glibc's loader and boost's and glib's thread-specific
# data look leaked: named in sanitize_lsan.supp.
cat > "$devel/lib/nodelet/nodelet" <<WRAPPER
#!/bin/sh
# Written by scripts/sanitize.sh: Debian's nodelet with the $kind runtime preloaded.
LSAN_OPTIONS="\${LSAN_OPTIONS:+\$LSAN_OPTIONS:}use_tls=0" LD_PRELOAD="$runtime\${LD_PRELOAD:+:\$LD_PRELOAD}" exec /usr/lib/nodelet/nodelet "\$@"
WRAPPER
chmod +x "$devel/lib/nodelet/nodelet"
export VIPER_TEST_TIME_SCALE=${VIPER_TEST_TIME_SCALE:-$([ "$kind" = tsan ] && echo 4 || echo 1)}
results="$build/test_results/viper"
rostest_passed=0 rostest_failed=0 i=0
for target in $(make -C "$build" help | sed -n 's/^\.\.\. \(run_tests_viper_rostest_.\+\)$/\1/p'); do
  name=${target#run_tests_viper_rostest_}
  [[ "$name" =~ $filter && "$suites" != gtest ]] || continue
  i=$((i + 1))
  log="$logs/rostest_$i.log" reports="$root/reports/$i" ros_log="$ROS_LOG_DIR/$i"
  rm -rf "$reports" "$ros_log" "$results"/rostest-*.xml "$results"/rosunit-*.xml
  mkdir -p "$reports" "$ros_log"
  echo "$name" > "$log"
  # Every process's report goes to a file of its own (NAME.PID) as well as the test's verdict.
  if ASAN_OPTIONS="$ASAN_OPTIONS:log_path=$reports/asan" UBSAN_OPTIONS="$UBSAN_OPTIONS:log_path=$reports/ubsan" \
    TSAN_OPTIONS="$TSAN_OPTIONS:log_path=$reports/tsan" ROS_LOG_DIR="$ros_log" \
    flock "${VIPER_ROSTEST_LOCK:-/tmp/viper-rostest.lock}" timeout 3600 make -C "$build" "$target" >> "$log" 2>&1; then
    why=""
  else
    why="the rostest did not finish"
  fi
  xml=$(ls "$results"/rostest-*.xml 2>/dev/null | head -1)
  if [ -z "$why" ] && [ -z "$xml" ]; then why="no result file"; fi
  # rostest's own result and the test nodes' (rosunit-*.xml): a rostest stopped from outside
  # writes a passing summary of its own while its test node's result records the failure.
  if [ -z "$why" ] && ! "$py" - "$xml" "$results"/rosunit-*.xml <<'PY'
import os, sys, xml.etree.ElementTree as ET
bad = False
for path in sys.argv[1:]:
    if not os.path.exists(path):
        continue
    root = ET.parse(path).getroot()
    cases = list(root.iter("testcase"))
    failed = [c for c in cases if c.find("failure") is not None or c.find("error") is not None]
    if failed or not cases or root.get("failures", "0") != "0" or root.get("errors", "0") != "0":
        print(path, file=sys.stderr); bad = True
sys.exit(1 if bad else 0)
PY
  then why="test failures ($xml and the test nodes' rosunit-*.xml)"; fi
  [ -n "$xml" ] && cp "$xml" "$logs/rostest_$i.xml"
  # A known crash of Debian's nodelet manager at exit (ros/nodelet_core#99: ~Loader destroys a
  # bond whose pending callback unloads through the half-destroyed Loader) is named, not counted.
  found=""
  for f in "$reports"/*; do
    [ -e "$f" ] || continue
    if grep -q "nodelet::Loader::~Loader" "$f" && grep -q "bond::Bond::flushPendingCallbacks" "$f"; then
      echo "sanitize $kind: rostest $name: the nodelet manager crashed at exit in ROS's ~Loader (ros/nodelet_core#99; $f), not counted"
      continue
    fi
    found="$found $(basename "$f")"
  done
  [ -n "$found" ] && why="${why:+$why; }sanitizer report in $reports:$found"
  hit=$(grep -rlE "$report" "$ros_log" "$log" 2>/dev/null | head -3)
  [ -n "$hit" ] && why="${why:+$why; }sanitizer report in $hit"
  if [ -z "$why" ]; then
    rostest_passed=$((rostest_passed + 1)); echo "sanitize $kind: rostest $name passed"
  else
    rostest_failed=$((rostest_failed + 1)); echo "sanitize $kind: rostest $name FAILED ($log): $why"
    for f in $found; do grep -m2 -E "$report|SUMMARY" "$reports/$f" | sed 's/^/    /'; done
  fi
done
echo "rostests: $rostest_passed passed, $rostest_failed failed"
passed=$((gtest_passed + rostest_passed)) failed=$((gtest_failed + rostest_failed + build_failed + layer_failed))
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
