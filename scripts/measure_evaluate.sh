#!/usr/bin/env bash
# Does evaluate keep up with a 1920x1080 replay at 15 Hz with every metric on? Captures the world,
# makes its ground truth with replay.launch at a slow rate (record:=), turns it into a bag that also
# holds a perfect perception's outputs for every metric (scripts/perfect_predictions.py: semantic,
# instances, dense and sparse flow, odometry), plays that bag at its own rate (15 Hz) into evaluate
# and reads back what it scored: every metric must have scored every frame (flow: every frame but
# the last), with perfect scores. The player and evaluate are nodelets of one manager (--source
# manager, the default: zero-copy, as in evaluate.launch nodelet:=true) or rosbag play --keep-alive
# and the evaluate node, two processes (--source rosbag). Also reports the CPU time per frame of the
# manager (player and evaluate) or of the evaluate node. Exits 1 if a metric lost a frame or a score
# is not perfect.
#
# Usage: scripts/measure_evaluate.sh [--frames N (45)] [--width W (1920)] [--height H (1080)]
#                                    [--rate R (1.0: the player's factor)] [--queue-size Q (10)]
#                                    [--source manager|rosbag (manager)]
# Needs a built workspace: the sourced one (source devel/setup.bash), else this checkout's devel space.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
frames=45 width=1920 height=1080 rate=1.0 queue=10 source=manager
# shellcheck source=options.sh
source "$here/scripts/options.sh"
viper_options '' "usage: $0 [--frames N] [--width W] [--height H] [--rate R] [--queue-size Q] [--source manager|rosbag]" \
  --frames=frames --width=width --height=height --rate=rate --queue-size=queue --source=source -- "$@"
case "$source" in manager|rosbag) ;; *) echo "measure_evaluate: --source is manager or rosbag" >&2; exit 2 ;; esac
source "$here/scripts/measure_common.sh" measure_evaluate capture world $([ "$source" = manager ] || echo evaluate)
port=$(( 20000 + RANDOM % 20000 ))
export ROS_MASTER_URI="http://localhost:$port" ROS_HOME="$work/ros_home"

echo "measure_evaluate: capturing $frames frames of the world at ${width}x${height}"
"$bin/capture" --output "$work/world.vcap" --profile "$here/config/profiles/world.yaml" --fps 15 \
  -- "$bin/world" --frames "$frames" --width "$width" --height "$height" >/dev/null

# Ground truth at a tenth of real time, recording only what evaluate reads (~29 MB per 1080p frame):
# rosbag record cannot write all of replay.launch's 1080p topics at 15 Hz (it drops, with a warning).
echo "measure_evaluate: ground truth (${SECONDS} s)"
"$py" "$(command -v roslaunch)" -p "$port" viper replay.launch capture:="$work/world.vcap" rate:=0.1 start_delay:=5 \
  label_table:="$here/config/labels/world_labels.yaml" >"$work/replay.log" 2>&1 &
launch=$!
pids+=($launch)
for _ in $(seq 150); do ros_tool rosnode list 2>/dev/null | grep -q /ground_truth/flow && break; sleep 0.2; done
ros_tool rosbag record -b 4096 -O "$work/gt.bag" __name:=gt_recorder /capture/draws /ground_truth/semantic \
  /ground_truth/instance_ids /ground_truth/flow/forward /ground_truth/flow/forward_visible /ground_truth/odom \
  >"$work/record.log" 2>&1 &
pids+=($!)
"$py" "$here/scripts/count_topics.py" --expect "$frames" --timeout 30 /ground_truth/odom \
  "/ground_truth/flow/forward_visible@$((frames - 1))" || { echo "measure_evaluate: ground truth incomplete" >&2; grep -i "error\|warn" "$work/replay.log" | tail -20 >&2; exit 1; }
sleep 2  # the recorder writes what it received
ros_tool rosnode kill /gt_recorder >/dev/null
for _ in $(seq 300); do [ -f "$work/gt.bag" ] && [ ! -f "$work/gt.bag.active" ] && break; sleep 0.2; done
[ -f "$work/gt.bag" ] || { echo "measure_evaluate: rosbag did not write the ground-truth bag" >&2; cat "$work/record.log" >&2; exit 1; }
kill -INT "$launch"
wait "$launch" || true

echo "measure_evaluate: perfect predictions (${SECONDS} s)"
"$py" "$here/scripts/perfect_predictions.py" "$work/gt.bag" "$work/scored.bag"
rm -f "$work/gt.bag"

echo "measure_evaluate: scoring at rate $rate (${SECONDS} s)"
roscore -p "$port" >"$work/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do ros_tool rosparam get /run_id >/dev/null 2>&1 && break; sleep 0.2; done
# One heap that keeps freed memory, as replay.launch gives its manager (malloc_tunables): the
# megabyte images of every frame reuse it instead of fresh pages.
tunables=glibc.malloc.arena_max=1:glibc.malloc.mmap_threshold=1073741824:glibc.malloc.trim_threshold=4294967296
# The world's short drive is a few tens of metres: VO segments of 5 to 20 m, one every 5 poses.
# (A list: rosparam parses it; a roscpp node's _name:= would take it for a string.)
ros_tool rosparam set /evaluate/odometry_segment_lengths_m "[5.0, 10.0, 20.0]"
eval_args=(_report_dir:="$work/report" _queue_size:="$queue" _shutdown_after_idle_s:=5 _odometry_step_frames:=5
           semantic:=/perception/semantic instances:=/perception/instances flow:=/perception/flow
           flow_sparse:=/perception/flow_sparse odom:=/perception/odom)
if [ "$source" = manager ]; then
  # evaluate and bag_player as nodelets of one manager: the bag's messages reach evaluate zero-copy.
  GLIBC_TUNABLES="$tunables" rosrun nodelet nodelet manager __name:=manager >"$work/evaluate.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 100); do ros_tool rosnode list 2>/dev/null | grep -q /manager && break; sleep 0.2; done
  rosrun nodelet nodelet load viper/evaluate /manager __name:=evaluate "${eval_args[@]}" >"$work/load.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 100); do ros_tool rosnode list 2>/dev/null | grep -q /evaluate && break; sleep 0.2; done
  process=$(ros_tool rosnode info /manager 2>/dev/null | sed -n 's/^Pid: //p')
  who="the manager (bag_player and evaluate)"
else
  GLIBC_TUNABLES="$tunables" "$bin/evaluate" __name:=evaluate "${eval_args[@]}" >"$work/evaluate.log" 2>&1 &
  process=$!
  pids+=($process)
  for _ in $(seq 100); do ros_tool rosnode list 2>/dev/null | grep -q /evaluate && break; sleep 0.2; done
  who="evaluate"
fi
ticks() { awk '{print $14 + $15}' "/proc/$process/stat"; }
before=$(ticks)
if [ "$source" = manager ]; then
  rosrun nodelet nodelet load viper/bag_player /manager __name:=bag_player _bag:="$work/scored.bag" _rate:="$rate" \
    _start_delay_s:=2 _publish_clock:=false >"$work/play.log" 2>&1 &
  pids+=($!)
else
  play_bag --rate="$rate" "$work/scored.bag"  # --delay=2: evaluate connects first
fi
# The CPU time for the frames: until the process has been idle for 3 s (evaluate writes its report
# only after 5 s without input).
sleep 3  # the player's 2 s delay, and the first frames
after=$(ticks) still=0
while [ "$still" -lt 6 ]; do
  sleep 0.5
  now=$(ticks)
  if [ $((now - after)) -le 1 ]; then still=$((still + 1)); else still=0; fi
  after=$now
done
for _ in $(seq 600); do grep -q "no input for" "$work/evaluate.log" && break; sleep 0.2; done
[ "$source" = rosbag ] && stop_bag
for _ in $(seq 300); do [ -f "$work/report/summary.csv" ] && break; sleep 0.2; done
sleep 1

summary="$work/report/summary.csv"
[ -f "$summary" ] || { echo "measure_evaluate: evaluate wrote no report" >&2; tail -20 "$work/evaluate.log" >&2; exit 1; }
echo "machine: $(nproc) cores; bag: $frames frames ${width}x${height} with ground truth and predictions, $(du -h "$work/scored.bag" | cut -f1), at rate $rate"
[ "$source" = manager ] && grep -o "bag_player: done with .*" "$work/evaluate.log" | sed 's/\x1b\[[0-9;]*m//g'
true
echo "$who: $(echo "scale=1; ($after - $before) * 1000 / $(getconf CLK_TCK) / $frames" | bc) ms CPU per frame (at 15 Hz a frame lasts 66.7 ms)"
"$py" - "$summary" "$frames" <<'EOF'
import csv, sys
rows = {r["condition"]: r for r in csv.DictReader(open(sys.argv[1]))}
n = int(sys.argv[2])
all_ = rows["all"]
checks = [("semantic_frames", n), ("instance_frames", n), ("flow_frames", n - 1), ("sparse_frames", n - 1),
          ("odometry_poses", n)]
ok = True
for key, want in checks:
    got = int(float(all_[key] or 0))
    print("%s: %d of %d" % (key, got, want))
    ok = ok and got == want
for key, want in [("mean_iou", 100.0), ("ap", 100.0), ("flow_epe_px", 0.0), ("sparse_epe_px", 0.0),
                  ("odometry_translation_percent", 0.0)]:
    if key.startswith("odometry") and int(float(all_["odometry_segments"] or 0)) == 0:
        print("%s: no VO segment (path %s m)" % (key, all_["odometry_path_m"]))
        continue
    got = float(all_[key])
    print("%s: %g" % (key, got))
    ok = ok and abs(got - want) < 1e-3
print("measure_evaluate: every frame scored, perfect scores" if ok else "measure_evaluate: frames lost or scores wrong")
sys.exit(0 if ok else 1)
EOF
