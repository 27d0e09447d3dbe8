#!/usr/bin/env bash
# Measures the figures of docs/figures.md marked (mf), on this machine, and prints them. Takes ~10 minutes.
# Usage: scripts/measure_figures.sh [OUT_DIR (build/figures)]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out="${1:-$here/build/figures}"
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
# (measure_generate.sh and bench_bag_writer.sh, run below, find theirs the same way.)
viper_bin_dir measure_figures "" capture world viper_gl_test_program bench_capture_stream bench_capture_finish \
  bench_ground_truth
mkdir -p "$out"
echo "machine: $(nproc) cores, $(free -g | awk '/Mem/ {print $2}') GiB, $(. /etc/os-release; echo "$PRETTY_NAME")"

echo "== capture stream: write and read of a 1920x1080 frame vs memcpy of the same bytes"
"$bin/bench_capture_stream" --benchmark_min_time=2 2>/dev/null | tee "$out/stream.txt"

echo "== capture writer: finishing a 1920x1080 frame, vectorised and one pixel at a time, vs memcpy"
"$bin/bench_capture_finish" --benchmark_min_time=2 2>/dev/null | tee "$out/finish.txt"

echo "== ground-truth kernels at 1920x1080 on one core: synthetic frames (200 objects) and a world capture"
"$bin/capture" --output "$out/world_bench.vcap" --profile "$here/config/profiles/world.yaml" --fps 15 \
  -- "$bin/world" --frames 24 --width 1920 --height 1080 >/dev/null
export VIPER_BENCH_CAPTURE="$out/world_bench.vcap" VIPER_BENCH_LABELS="$here/config/labels/world_labels.yaml"
taskset -c 1 "$bin/bench_ground_truth" --benchmark_filter=-Flow --benchmark_min_time=2 2>/dev/null |
  tee "$out/ground_truth.txt"
# Flow: every instruction path (the benchmarks' second argument) and memcpy, interleaved, so that
# the VM's drift falls on all of them alike; three processes, as memory placement differs by process.
for run in 1 2 3; do
  taskset -c 1 "$bin/bench_ground_truth" --benchmark_filter=Flow --benchmark_repetitions=5 \
    --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true \
    --benchmark_min_time=0.3 2>/dev/null | grep -E "median" | tee -a "$out/ground_truth.txt"
done
unset VIPER_BENCH_CAPTURE VIPER_BENCH_LABELS
rm -f "$out/world_bench.vcap"

echo "== interceptor overhead: capture test program, 1920x1080, 304 draws/frame"
bash "$here/test/capture/measure_overhead.sh" "$bin" 1920x1080 30 300 3 | tee "$out/overhead_test_program.txt"

echo "== world: frame time without and with capture (31 frames, frame 0 left out)"
for size in "1920 1080" "1280 720"; do
  set -- $size
  plain=$("$bin/world" --frames 31 --width "$1" --height "$2" --benchmark | grep "world benchmark" | tail -1)
  captured=$("$bin/capture" --output "$out/world_${2}p.vcap" --profile "$here/config/profiles/world.yaml" --fps 15 \
    -- "$bin/world" --frames 31 --width "$1" --height "$2" --benchmark | grep "world benchmark" | tail -1)
  echo "world ${1}x${2}: plain: $plain | captured: $captured" | tee -a "$out/world.txt"
  rm -f "$out/world_${2}p.vcap"
done

echo "== generate end to end at 1920x1080, both outputs (2 sequences of 300 frames, 2 shards)"
bash "$here/scripts/measure_generate.sh" | tee "$out/generate.txt"

echo "== bag writers: rosbag against BagFileWriter on 10 frames of 1080p ground truth"
bash "$here/scripts/bench_bag_writer.sh" | tee "$out/bag_writer.txt"
