#!/bin/bash
# Capture overhead at 1920x1080, without and with `capture`, runs alternated: the capture test
# program (measure_overhead.sh) free-running and held to 60 frames/s, and the world; each under
# three settings of the capture: synchronous read-back with one writer thread (the layer as it
# was before parallel writers), synchronous read-back with the default writer threads (half the
# CPUs less one), and asynchronous read-back with them (the default on a GPU: --readback auto). The interceptor's split comes from VIPER_CAPTURE_STATS
# (read-back on the render thread, waiting for the writer, writer threads' time summed).
# Prints the GL renderer and the CPU count first: the ratios depend on both.
# usage: measure_capture_overhead.sh [BIN_DIR] [RUNS]
#   (BIN_DIR: the sourced workspace's executables, else devel/lib/viper; RUNS 3)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir measure_capture_overhead "${1:-}" capture viper_gl_test_program world
runs=${2:-3}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "machine: $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"$bin/viper_gl_test_program" --mode direct --size 64x64 --frames 1 | grep renderer=
export VIPER_CAPTURE_STATS=1
settings=("--readback sync --writer-threads 1" "--readback sync" "--readback async")
measure() {  # LOAD PROGRAM_OPTIONS
  for s in "${settings[@]}"; do
    bash "$here/test/capture/measure_overhead.sh" "$bin" 1920x1080 60 "$1" "$runs" "$s" "$2" 2> >(grep "per frame\|synchronously" >&2)
  done
}
echo "== capture test program, 1920x1080, 304 draws a frame, free-running"
measure 300 ""
echo "== capture test program, 1920x1080, 3004 draws a frame, free-running"
measure 3000 ""
echo "== capture test program, 1920x1080, 304 draws a frame, held to 60 frames/s (--frame-ms 16.667)"
measure 300 "--frame-ms 16.667"
echo "== world, 1920x1080, 61 frames (frame 0 left out)"
world=("$bin/world" --frames 61 --width 1920 --height 1080 --benchmark)
for ((i = 0; i < runs; ++i)); do
  "${world[@]}" | grep "world benchmark" | tail -1 | sed 's/^/plain: /'
  for s in "${settings[@]}"; do
    read -r -a opts <<< "$s"
    "$bin/capture" --output "$out/w.vcap" --profile "$here/config/profiles/world.yaml" --fps 15 "${opts[@]}" \
      -- "${world[@]}" 2>&1 | grep "world benchmark: [0-9]\|per frame\|synchronously" | tr '\n' ' ' | sed "s/^/captured (${s:-defaults}): /"
    echo
  done
done
