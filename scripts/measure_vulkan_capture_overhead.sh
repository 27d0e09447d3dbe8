#!/bin/bash
# Capture overhead of the Vulkan layer: vk_test_scene drawn plainly and under `capture`, runs
# alternated, the mean frame time of each run (rendering finished: --benchmark) and the medians.
# Headless by default (no X server, no swapchain: a frame ends with each submission of the scene
# pass, docs/capture_layer.md#what-a-frame-holds), so it runs on a GPU machine without a display as
# on lavapipe; --windowed draws into a window of an X server of its own (xvfb-run) and presents.
# Host-visible buffers: on a discrete GPU the layer reads meshes only from host-visible memory.
# Prints the Vulkan device and the CPU first: the ratio depends on both. --frame-ms T holds each
# frame of both to at least T ms (16.667: a program held to 60 frames/s); --stats prints each
# captured run's costs per frame (VIPER_CAPTURE_STATS).
# usage: measure_vulkan_capture_overhead.sh [--windowed] [--frame-ms T] [--stats] [BIN_DIR] [RUNS]
#          [WIDTHxHEIGHT] [FRAMES]
#   (BIN_DIR: the sourced workspace's executables, else devel/lib/viper; RUNS 3; 1920x1080; 120 frames)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
mode=--headless
held=()
stats=()
while [ $# -gt 0 ]; do
  case "$1" in
    --windowed) mode=""; shift ;;
    --frame-ms) held=(--frame-ms "${2:?--frame-ms takes a number of milliseconds}"); shift 2 ;;
    --stats) stats=(VIPER_CAPTURE_STATS=1); shift ;;
    *) break ;;
  esac
done
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir measure_vulkan_capture_overhead "${1:-}" capture vk_test_scene
runs=${2:-3}
size=${3:-1920x1080}
frames=${4:-120}
width=${size%x*} height=${size#*x}
work=$(mktemp -d /tmp/viper_vulkan_overhead.XXXXXX)
trap 'rm -rf "$work"' EXIT
x=()
[ -n "$mode" ] || x=(xvfb-run -a -s "-screen 0 ${width}x${height}x24")
program=("$bin/vk_test_scene" $mode --host-visible-buffers --frames "$frames" --width "$width" --height "$height" --benchmark
  "${held[@]}")
echo "machine: $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"${x[@]}" "$bin/vk_test_scene" $mode --frames 1 --width 64 --height 64 2>&1 | sed -n 's/^vk_test_scene: 64x64, \(.*, Vulkan [0-9.]*\).*/device: \1/p'
echo "vk_test_scene ${mode:---windowed} --host-visible-buffers ${held[*]}, ${width}x${height}, $frames frames, $runs runs of each, alternated"
ms() { sed -n 's/.*mean_frame_ms=\([0-9.]*\).*/\1/p' | tail -1; }
median() { sort -n | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
for ((i = 0; i < runs; ++i)); do
  "${x[@]}" "${program[@]}" 2>/dev/null | ms >> "$work/plain"
  env "${stats[@]}" "${x[@]}" "$bin/capture" --output "$work/o.vcap" \
    --profile "$here/config/profiles/vk_test_scene.yaml" --fps 15 -- "${program[@]}" > "$work/captured.log" 2>&1
  ms < "$work/captured.log" >> "$work/captured"
  [ ${#stats[@]} = 0 ] || sed -n 's/^\[viper capture\] Vulkan: .* per frame: /captured run per frame: /p' "$work/captured.log"
  grep -q "$frames frames written" "$work/captured.log" || { echo "capture did not write $frames frames:" >&2; cat "$work/captured.log" >&2; exit 1; }
  rm -f "$work/o.vcap"
done
plain=$(median < "$work/plain") captured=$(median < "$work/captured")
echo "plain:    $(tr '\n' ' ' < "$work/plain")ms a frame; median $plain"
echo "captured: $(tr '\n' ' ' < "$work/captured")ms a frame; median $captured"
awk -v p="$plain" -v c="$captured" 'BEGIN {printf "ratio: %.2fx\n", c / p}'
