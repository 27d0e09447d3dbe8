#!/usr/bin/env bash
# Counts the frames the whole ground-truth pipeline delivers from a 1920x1080 replay at its own rate
# (15 Hz): captures the world at 15 fps, starts replay.launch's nodelets in one manager, loads the
# output_counter nodelet beside them (subscribed to every ground-truth output, zero-copy) and reads
# its counts after the replay. The replay is a raw bag written by capture_to_bag (each message at its
# stamp, so that it plays at 15 frames/s) played by the viper/bag_player nodelet in the same manager
# (--source bag, the default: replay.launch bag:=, zero-copy) or by rosbag play --clock in its own
# process, kept alive until the counts are in (--source rosbag), or the capture itself through
# capture_bridge as a nodelet of the same manager (--source capture: replay.launch capture:=).
# --throughput plays as fast as the pipeline takes instead: rate 0 with back-pressure (the player
# sends a frame only while fewer than --in-flight frames are unfinished, output_counter's ~progress
# saying which are finished), and reports the sustained frames/s from the first draw list to the
# last output. --sweep R1,R2,... plays a capture at each rate in turn and names the fastest sustained
# rate (every frame through every node, first draw list to last output) with no frame lost.
# Exits 1 if any output missed a frame.
#
# Usage: scripts/measure_pipeline.sh [--frames N (45)] [--width W (1920)] [--height H (1080)] [--no-flow]
#                                    [--source bag|rosbag|capture (bag)] [--rate R (1.0: replay speed factor)]
#                                    [--queue-size Q (30: the nodelets' input queues, replay.launch's queue_size)]
#                                    [--throughput [--in-flight K (8)]] [--sweep R1,R2,...]
#                                    [--bag-compression lz4|none|bz2 (capture_to_bag's, lz4)]
#                                    [--capture-codec lz4|zstd (the capture's compression, lz4)]
#                                    [--manager-threads N (replay.launch's manager_threads, 4)]
#                                    [--perf FILE (perf record --call-graph dwarf of the manager while it plays)]
#                                    [--kernels (then each node's kernels alone on the same capture or bag,
#                                     scripts/measure_kernels.sh, and the manager's CPU over their sum)]
# Needs a built workspace: the sourced one (source devel/setup.bash), else this checkout's devel space.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
frames=45 width=1920 height=1080 flow=true queue=30 source=bag rate=1.0 throughput=false in_flight=8 sweep="" compression=lz4 perf_out="" codec=lz4 threads=4 kernels=false
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --width) width="$2"; shift 2 ;;
    --height) height="$2"; shift 2 ;;
    --no-flow) flow=false; shift ;;
    --queue-size) queue="$2"; shift 2 ;;
    --source) source="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --throughput) throughput=true; rate=0; shift ;;
    --in-flight) in_flight="$2"; shift 2 ;;
    --sweep) sweep="$2"; shift 2 ;;
    --bag-compression) compression="$2"; shift 2 ;;
    --perf) perf_out="$2"; shift 2 ;;
    --capture-codec) codec="$2"; shift 2 ;;
    --manager-threads) threads="$2"; shift 2 ;;
    --kernels) kernels=true; shift ;;
    *) echo "usage: $0 [--frames N] [--width W] [--height H] [--no-flow] [--source bag|rosbag|capture] [--rate R] [--queue-size Q] [--throughput [--in-flight K]] [--sweep R1,R2,...] [--bag-compression lz4|none|bz2] [--capture-codec zstd|lz4] [--manager-threads N] [--perf FILE] [--kernels]" >&2; exit 2 ;;
  esac
done
case "$source" in bag|rosbag|capture) ;; *) echo "measure_pipeline: --source is bag, rosbag or capture" >&2; exit 2 ;; esac
if [ "$throughput" = true ] && [ "$source" = rosbag ]; then
  echo "measure_pipeline: --throughput needs a player with back-pressure: --source bag or capture" >&2; exit 2
fi
if [ -n "$sweep" ]; then  # one run per rate, each on a capture of its own; the fastest with no loss
  best=none best_fps=0
  for r in ${sweep//,/ }; do
    echo "measure_pipeline: --sweep: rate $r"
    out=$("$0" --frames "$frames" --width "$width" --height "$height" --source "$source" --rate "$r" \
        --queue-size "$queue" --bag-compression "$compression" --capture-codec "$codec" --manager-threads "$threads" $([ "$flow" = true ] || echo --no-flow) 2>&1) && ok=1 || ok=0
    echo "$out" | grep -E "^(nodelet manager|delivered|sustained|measure_pipeline: (no frame|frames))"
    fps=$(echo "$out" | sed -n 's/^sustained: \([0-9.]*\) frames.*/\1/p')
    # A player that falls behind its rate loses nothing but delivers less, and queues let the nodes
    # lag: the sustained rate (first draw list to last output) counts.
    if [ "$ok" = 1 ] && [ -n "$fps" ] && awk -v a="$fps" -v b="$best_fps" 'BEGIN {exit !(a > b)}'; then
      best=$r best_fps=$fps
    fi
  done
  echo "measure_pipeline: --sweep: fastest with no frame lost: ${best_fps} frames/s sustained (at rate $best, of $sweep)"
  [ "$best" != none ]
  exit
fi
executables=(capture world)
[ "$source" = capture ] || executables+=(capture_to_bag)
[ "$kernels" = false ] || executables+=(bench_ground_truth $([ "$source" = capture ] || echo bench_bag_reader))
source "$here/scripts/measure_common.sh" measure_pipeline "${executables[@]}"

echo "measure_pipeline: capturing $frames frames of the world at ${width}x${height}"
"$bin/capture" --output "$work/world.vcap" --codec "$codec" --profile "$here/config/profiles/world.yaml" --fps 15 \
  -- "$bin/world" --frames "$frames" --width "$width" --height "$height" >/dev/null
echo "measure_pipeline: captured (${SECONDS} s)"
# The bridge and the bag player wait 8 s after advertising: output_counter is loaded by then.
pace=()
[ "$throughput" = true ] && pace=(pace_topic:=/ground_truth/output_counter/progress max_in_flight:="$in_flight")
replay_args=(capture:="$work/world.vcap" rate:="$rate" start_delay:=8 "${pace[@]}")
if [ "$source" != capture ]; then
  "$bin/capture_to_bag" --output "$work/raw.bag" --compression "$compression" "$work/world.vcap" >/dev/null
  echo "measure_pipeline: bag written (${SECONDS} s)"
  replay_args=()
  [ "$source" = bag ] && replay_args=(bag:="$work/raw.bag" rate:="$rate" start_delay:=8 "${pace[@]}")
fi
[ "$flow" = true ] || export COUNTER_ARGS="_expect_flow:=false"
start_pipeline label_table:="$here/config/labels/world_labels.yaml" flow:="$flow" queue_size:="$queue" cpu_report_period:=1 \
  manager_threads:="$threads" \
  "${replay_args[@]}"
ticks() { awk '{print $14 + $15}' "/proc/$manager/stat"; }
before=$(ticks)
perf_pid=
if [ -n "${perf_out:-}" ]; then
  perf record -F 499 --call-graph dwarf,16384 -o "$perf_out" -p "$manager" >/dev/null 2>"$work/perf.log" &
  perf_pid=$!
fi
echo "measure_pipeline: playing (${SECONDS} s)"
case "$source" in
  rosbag)
    play_bag --clock --rate="$rate" "$work/raw.bag"  # --delay=2: every subscriber connects first
    played="bag $(du -h "$work/raw.bag" | cut -f1) ($compression) played by rosbag play" ;;
  bag) played="bag $(du -h "$work/raw.bag" | cut -f1) ($compression) played by the bag_player nodelet" ;;
  capture) played="capture $(du -h "$work/world.vcap" | cut -f1) through the bridge nodelet" ;;
esac
for _ in $(seq 600); do [ -f "$work/counts.txt" ] && break; sleep 0.2; done
[ -f "$work/counts.txt" ] || { echo "measure_pipeline: output_counter wrote no counts" >&2; tail -20 "$work/launch.log" >&2; exit 1; }
[ "$source" = rosbag ] && stop_bag
after=$(ticks)
if [ -n "$perf_pid" ]; then
  kill -INT "$perf_pid"; wait "$perf_pid" || true
  echo "measure_pipeline: perf profile of the manager in $perf_out (perf report -i $perf_out --no-children)"
fi
echo "machine: $(nproc) cores; $frames frames ${width}x${height} at rate $rate; $played"
manager_ms=$(echo "scale=1; ($after - $before) * 1000 / $(getconf CLK_TCK) / $frames" | bc)
echo "nodelet manager: $manager_ms ms CPU per frame (at 15 Hz, 2 cores give 133 ms)"
# The rate the source delivered: its draw lists, first to last (a player may fall behind its rate).
awk -v n="$frames" '$1 == "/capture/draws" && $4 > $3 {printf "delivered: %.1f frames/s (the draw lists, first to last)\n", (n - 1) / ($4 - $3)}' "$work/counts.txt"
# Per nodelet: the last 'cpu:' line each logged (its callbacks' thread CPU, cpu_meter.h), from
# rosout's log (the manager's own output is buffered until it exits).
cat "$work"/ros_home/log/*/rosout.log | grep -ao 'cpu: [a-z_]* [0-9]* frames, [0-9.]* ms CPU a frame' |
  awk '{ms[$2] = $5; n[$2] = $3} END {for (k in ms) print k, ms[k], n[k]}' | sort |
  awk -v manager="$manager_ms" '{printf "  %-15s %6.1f ms CPU a frame (over %d frames)\n", $1, $2, $3; sum += $2}
    END {printf "  %-15s %6.1f ms\n  %-15s %6.1f ms (ROS: queues, synchronisers, publishing)\n", "sum", sum, "rest of manager", manager - sum}'
# The kernels alone on the same frames, after the replay (not beside it): their sum is the least
# the manager could spend a frame on this machine.
if [ "$kernels" = true ]; then
  kernel_args=("$work/world.vcap")
  [ "$source" = capture ] || kernel_args+=(--bag "$work/raw.bag")
  kernel_out=$("$here/scripts/measure_kernels.sh" "${kernel_args[@]}")
  echo "$kernel_out"
  kernel_sum=$(echo "$kernel_out" | sed -n 's/^kernels: \([0-9.]*\) ms.*/\1/p')
  awk -v m="$manager_ms" -v k="$kernel_sum" 'BEGIN {printf "whole over kernels: %.2f (the manager %.1f ms a frame, the kernels alone %.1f)\n", m / k, m, k}'
fi
# Sustained: every frame through every node, from the first draw list to the last output of any
# topic (wall-clock seconds in counts.txt); with queues a replay can deliver faster for a while.
awk -v n="$frames" '$1 == "/capture/draws" {first = $3} {if ($4 > last) last = $4}
  END {printf "sustained: %.1f frames/s (%d frames through every node in %.2f s%s)\n", n / (last - first), n, last - first, "'"$([ "$throughput" = true ] && echo ", at most $in_flight frames in flight")"'"}' "$work/counts.txt"
# Flow exists for every frame but one: forward flow of the last frame and backward flow of the first
# have no other frame.
status=0
draws_last=$(awk '$1 == "/capture/draws" {print $4}' "$work/counts.txt")
outputs=(/capture/draws semantic semantic_color instance_ids boundaries instances_viper semantic_overlay objects
         boxes boxes_optical odom)
[ "$flow" = true ] && outputs+=(flow/forward flow/forward_visible flow/backward flow/backward_visible)
for topic in "${outputs[@]}"; do
  want=$frames
  case "$topic" in flow/*) want=$((frames - 1)) ;; esac
  read -r n first last < <(awk -v t="$topic" '$1 == t {print $2, $3, $4}' "$work/counts.txt")  || true
  if [ -z "${n:-}" ]; then
    echo "$topic: 0 of $want"
    status=1
    continue
  fi
  printf '%s: %d of %d, first to last in %.2f s, last one %+.2f s after the last draw list\n' \
    "$topic" "$n" "$want" "$(echo "$last - $first" | bc)" "$(echo "$last - ${draws_last:-$last}" | bc)"
  [ "$n" = "$want" ] || status=1
  n=""
done
[ "$status" = 0 ] && echo "measure_pipeline: no frame dropped" || { echo "measure_pipeline: frames dropped" >&2; grep -i "error\|warn" "$work/launch.log" | tail -20 >&2; }
exit "$status"
