#!/usr/bin/env bash
# Each pipeline node's kernels alone on the frames of a capture, one core, no ROS: the least CPU a
# frame the whole pipeline could take on this machine. bench_ground_truth (and bench_bag_reader for
# a bag) run on the capture, their benchmarks interleaved at random so that a machine drifting in
# speed weighs on each alike; the medians of --repetitions runs.
#   player     capture_bridge: BM_BridgeFrameCapture (read a frame, decompress its images into
#              storage of the bridge's, depth in metres and the ids' masks and checks in one pass);
#              with --bag, bag_player: BM_BagFileReaderBulkSink's CPU a frame (read, check and
#              decompress the bag's chunks)
#   instances  BM_InstancePictures/1/1 (objects, tracking, semantic, instance ids, boundaries and
#              both pictures from the runs of draws) + BM_OverlayClasses/4/1 (the overlay)
#   flow       BM_FlowForwardAndBackwardCapture/1/0 (forward and backward flow of a frame pair)
#   boxes      BM_BoxesCapture/1 (odometry, 0.3 ms a frame in the pipeline, has no benchmark)
# measure_pipeline.sh --kernels runs this after its replay and divides the manager's CPU a frame by
# the sum (docs/pipeline_speed.md).
#
# Usage: scripts/measure_kernels.sh CAPTURE.vcap [--bag RAW.bag] [--labels LABELS.yaml (the world's)]
#                                   [--repetitions N (3)]
# Needs a built workspace: the sourced one (source devel/setup.bash), else this checkout's devel space.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
usage="usage: $0 CAPTURE.vcap [--bag RAW.bag] [--labels LABELS.yaml] [--repetitions N]"
[ $# -ge 1 ] || { echo "$usage" >&2; exit 2; }
capture=$1; shift
bag="" labels="$here/config/labels/world_labels.yaml" reps=3
# shellcheck source=options.sh
source "$here/scripts/options.sh"
viper_options '' "$usage" --bag=bag --labels=labels --repetitions=reps -- "$@"
[ -f "$capture" ] || { echo "measure_kernels: no capture at $capture" >&2; exit 2; }
[ -z "$bag" ] || [ -f "$bag" ] || { echo "measure_kernels: no bag at $bag" >&2; exit 2; }
source "$here/scripts/measure_common.sh" measure_kernels bench_ground_truth ${bag:+bench_bag_reader}  # $bin, $work
out="$work/bench.txt"

# The CPU ms of each median line, "NAME_median  REAL ms  CPU ms  ITERATIONS ..." (of the one line
# "NAME ..." with --repetitions 1, which makes no aggregates). The bridge's
# benchmark only without a bag (whose player is the bag reader, below).
bridge="BridgeFrameCapture|"
[ -z "$bag" ] || bridge=""
VIPER_BENCH_CAPTURE="$capture" VIPER_BENCH_LABELS="$labels" "$bin/bench_ground_truth" \
  --benchmark_filter="^BM_(${bridge}InstancePictures/1/1|OverlayClasses/4/1|FlowForwardAndBackwardCapture/1/0|BoxesCapture/1)\$" \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
  --benchmark_report_aggregates_only=true >"$out" 2>&1 || { cat "$out" >&2; exit 1; }
ms() {
  local v
  v=$(awk -v n="$1" '($1 == n "_median" || $1 == n) && $5 == "ms" {print $4}' "$out")
  [ -n "$v" ] || { echo "measure_kernels: no median of $1 from bench_ground_truth:" >&2; cat "$out" >&2; exit 1; }
  echo "$v"
}
pictures=$(ms BM_InstancePictures/1/1)
overlay=$(ms BM_OverlayClasses/4/1)
flow=$(ms BM_FlowForwardAndBackwardCapture/1/0)
boxes=$(ms BM_BoxesCapture/1)
if [ -z "$bag" ]; then
  player_name=capture_bridge
  player=$(ms BM_BridgeFrameCapture)
else
  player_name=bag_player
  VIPER_BENCH_BAG="$bag" "$bin/bench_bag_reader" --benchmark_filter='^BM_BagFileReaderBulkSink' \
    --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true >"$out" 2>&1 || { cat "$out" >&2; exit 1; }
  player=$(awk '$1 ~ /^BM_BagFileReaderBulkSink/ && $1 !~ /_(mean|stddev|cv)$/' "$out" |
    sed -n 's/.*cpu_ms_per_frame=\([0-9.]*\).*/\1/p')
  [ -n "$player" ] || { echo "measure_kernels: no cpu_ms_per_frame from bench_bag_reader:" >&2; cat "$out" >&2; exit 1; }
fi
awk -v pn="$player_name" -v p="$player" -v pi="$pictures" -v o="$overlay" -v f="$flow" -v b="$boxes" -v r="$reps" 'BEGIN {
  printf "kernels alone (one core, medians of %d, interleaved):\n", r
  printf "  %-15s %6.1f ms CPU a frame\n", pn, p
  printf "  %-15s %6.1f ms (pictures %.1f, overlay %.1f)\n", "instances", pi + o, pi, o
  printf "  %-15s %6.1f ms\n  %-15s %6.1f ms\n", "flow", f, "boxes", b
  printf "kernels: %.1f ms CPU a frame in all\n", p + pi + o + f + b
}'
