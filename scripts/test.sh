#!/usr/bin/env bash
# Builds viper with its tests and runs every test: gtests and rostests (through catkin's run_tests),
# then every fuzz target for a short while (each one test). Ends with "N passed, N failed"; exits
# non-zero if any test failed or none ran. Usage: scripts/test.sh [fuzz_seconds_per_target (default 8)]
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build="$here/build"
fuzz_seconds="${1:-8}"

# What only the tests need (SuperTuxKart, Minetest, apitrace, Chromium, Playwright, Slurm; about 800 MB to download
# on a fresh machine): installed here, not for every user.
bash "$here/scripts/setup.sh" --test-programs --no-build || { echo "0 passed, 1 failed"; exit 1; }
if [ ! -f "$build/Makefile" ]; then
  bash "$here/scripts/setup.sh" || { echo "0 passed, 1 failed"; exit 1; }
else
  # Configured before the test programs were installed (CI's setup, then this): configure again,
  # so that what needs them is found now (mingw-w64 for the Direct3D 11 program: cmake/d3d11.cmake).
  (cd "$build" && cmake . > /dev/null) || { echo "cmake failed"; echo "0 passed, 1 failed"; exit 1; }
fi
export ROS_HOME="$build/ros_home" ROS_LOG_DIR="$build/ros_home/log"
# This checkout's devel space, Debian's python3 first on PATH (scripts/package_binaries.sh).
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_ros_env test.sh "$here/devel"
cd "$build"
make -j"$(nproc)" all tests || { echo "build failed"; echo "0 passed, 1 failed"; exit 1; }
rm -rf "$build/test_results"
# Free space, before and after: the tests write gigabytes at their peak (a wine prefix, captures,
# generated sequences; each test binary removes its folder when it exits), and a test that runs out
# of it fails far from the cause.
free_space() { echo "free space $1: $(df -Ph /tmp | awk 'NR == 2 {print $4}') in /tmp, $(df -Ph "$build" | awk 'NR == 2 {print $4}') in $build"; }
free_space "before the tests"
make -j1 run_tests 2>&1 | tee "$build/run_tests.log" | grep -E "^\[ *(RUN|OK|FAILED|PASSED) *\]|^\[ROSTEST\]|FAILURE|ERROR:|rostest" || true
free_space "after the tests"

"$py" - "$build/test_results" > "$build/test_counts.txt" <<'PY'
import sys, glob, xml.etree.ElementTree as ET
passed = failed = 0
for path in sorted(glob.glob(sys.argv[1] + "/**/*.xml", recursive=True)):
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        print(f"unreadable result {path}: {e}", file=sys.stderr); failed += 1; continue
    cases = root.iter("testcase")
    n = 0
    for c in cases:
        n += 1
        if c.find("failure") is not None or c.find("error") is not None:
            failed += 1; print(f"FAILED: {path}: {c.get('classname')}.{c.get('name')}", file=sys.stderr)
            # Why, in a few lines: a CI log keeps its tail, and this is where the reason is.
            lines = []
            for f in list(c.iter("failure")) + list(c.iter("error")):
                text = f.text or f.get("message") or ""
                lines += [l for l in text.splitlines() if l.strip()][:12]
            for l in lines[:40]: print(f"    {l[:300]}", file=sys.stderr)
        elif c.find("skipped") is None:
            passed += 1
    if n == 0 and root.get("failures", "0") + root.get("errors", "0") != "00":
        failed += 1; print(f"FAILED (no test cases): {path}", file=sys.stderr)
print(passed, failed)
PY
read -r passed failed < "$build/test_counts.txt"

# Every fuzz target (test/fuzz/run_fuzzers.sh, 19 targets: about 2.7 min at 8 s each), one line
# and one test per target; a build failure is one failed test.
bash "$here/test/fuzz/run_fuzzers.sh" "$fuzz_seconds" | tee "$build/fuzz.log"
passed=$((passed + $(grep -c ': PASSED' "$build/fuzz.log")))
failed=$((failed + $(grep -c ': FAILED' "$build/fuzz.log")))

# A real single-node Slurm generating the tiny plan as an array job (about 40 s).
if bash "$here/scripts/test_slurm.sh" > "$build/test_slurm.log" 2>&1; then
  echo "slurm: PASSED"; passed=$((passed + 1))
else
  echo "slurm: FAILED (see $build/test_slurm.log)"; tail -5 "$build/test_slurm.log"; failed=$((failed + 1))
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
