#!/usr/bin/env bash
# Soak: the whole ground-truth pipeline (replay.launch's nodelets in one manager, every output
# subscribed by output_counter in the same manager) fed for MINUTES minutes at 15 Hz, by
#   --source bag:     a 1920x1080 raw bag of FRAMES frames of the world, looped by the bag_player
#                     nodelet (~loop: stamps keep increasing), or
#   --source follow:  capture_bridge ~follow on a capture the world writes live under `capture`
#                     (the world renders MINUTES x 60 x 15 frames at 15 fps; size: --width/--height).
# Every 10 s it samples the manager's resident memory (rss.csv) and the output counts. At the end it
# stops the source, waits for the last outputs and checks: every per-frame output has as many
# messages as /capture/draws (the overlay: as frames with both draws and color), every flow output as many as its pairs of consecutive frames (a bag
# loop restarts the capture's frame numbers: no flow spans the seam); no ERROR or FATAL in the log;
# the memory slope after warm-up (the first fifth of the run) is printed in MB per hour (a fit over
# the samples). Exits 1 on a lost frame or a logged error.
# Usage: source devel/setup.bash; scripts/soak_pipeline.sh [--minutes 30] [--source bag|follow]
#          [--frames 90] [--width 1920] [--height 1080] [--keep DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
minutes=30 source=bag frames=90 width=1920 height=1080 keep=""
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) minutes=$2 ;; --source) source=$2 ;; --frames) frames=$2 ;; --width) width=$2 ;;
    --height) height=$2 ;; --keep) keep=$2 ;;
    *) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
  esac
  shift 2
done
case "$source" in bag|follow) ;; *) echo "soak_pipeline: --source is bag or follow" >&2; exit 2 ;; esac
source "$here/scripts/measure_common.sh" soak_pipeline capture world $([ "$source" = follow ] || echo capture_to_bag)
[ -n "$keep" ] && { mkdir -p "$keep"; trap 'cleanup_keep' EXIT; }
cleanup_keep() {
  local pid
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  cp -r "$work"/*.csv "$work"/*.txt "$work"/*.log "$keep"/ 2>/dev/null || true
  rm -rf "$work"
}

if [ "$source" = bag ]; then
  "$bin/capture" --output "$work/world.vcap" --profile "$here/config/profiles/world.yaml" --fps 15 \
    -- "$bin/world" --frames "$frames" --width "$width" --height "$height" > /dev/null
  "$bin/capture_to_bag" --output "$work/raw.bag" "$work/world.vcap" > /dev/null
  rm "$work/world.vcap"
  replay_args=(bag:="$work/raw.bag" loop:=true start_delay:=8)
  echo "soak_pipeline: $frames-frame ${width}x${height} bag looped by bag_player for $minutes min"
else
  live_frames=$((minutes * 60 * 15))
  # The world renders ahead under capture; the bridge follows the growing file at 15 Hz.
  "$bin/capture" --output "$work/live.vcap" --profile "$here/config/profiles/world.yaml" --fps 15 \
    -- "$bin/world" --frames "$live_frames" --width "$width" --height "$height" > "$work/world.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 100); do [ -s "$work/live.vcap" ] && break; sleep 0.2; done
  replay_args=(capture:="$work/live.vcap" follow:=true start_delay:=8)
  echo "soak_pipeline: capture_bridge following the world's live ${width}x${height} capture for $minutes min"
fi
COUNTER_ARGS="_report_period_s:=10" start_pipeline label_table:="$here/config/labels/world_labels.yaml" "${replay_args[@]}"
[ -n "$manager" ] || { echo "soak_pipeline: no /viper_manager" >&2; tail -20 "$work/launch.log" >&2; exit 1; }

echo "seconds,rss_mb,draws" > "$work/rss.csv"
start=$SECONDS
while [ $((SECONDS - start)) -lt $((minutes * 60)) ]; do
  sleep 10
  rss=$(awk '/^VmRSS/ {print $2 / 1024}' "/proc/$manager/status")
  draws=$(awk '$1 == "/capture/draws" {print $2}' "$work/counts.txt" 2> /dev/null || echo 0)
  echo "$((SECONDS - start)),$rss,${draws:-0}" >> "$work/rss.csv"
done

# Stop the source, then let the pipeline finish what it holds: the counter reports once idle.
if [ "$source" = bag ]; then
  rosrun nodelet nodelet unload /bag_player /viper_manager > /dev/null 2>&1 || true
else
  rosrun nodelet nodelet unload /capture/capture_bridge /viper_manager > /dev/null 2>&1 || true
fi
rm -f "$work/counts.txt"
for _ in $(seq 300); do [ -f "$work/counts.txt" ] && break; sleep 0.2; done
[ -f "$work/counts.txt" ] || { echo "soak_pipeline: output_counter wrote no final counts" >&2; exit 1; }

"$py" - "$work" "$frames" "$source" <<'PY'
import csv, re, sys
work, frames, source = sys.argv[1], int(sys.argv[2]), sys.argv[3]
counts = {l.split()[0]: int(l.split()[1]) for l in open(work + "/counts.txt") if l.strip()}
draws = counts.get("/capture/draws", 0)
# A bag loop restarts the frame numbers: flow pairs only consecutive frames within one pass.
passes = -(-draws // frames) if source == "bag" else 1
status = 0
print(f"draw lists: {draws} ({passes} passes)" if source == "bag" else f"draw lists: {draws}")
for topic in ("semantic", "semantic_color", "instance_ids", "boundaries", "instances_viper", "semantic_overlay",
              "objects", "boxes", "boxes_optical", "odom", "flow/forward", "flow/forward_visible", "flow/backward",
              "flow/backward_visible"):
    want = draws - passes if topic.startswith("flow/") else draws
    if topic == "semantic_overlay":  # semantic and color of a frame; the source may stop between the two
        want = min(draws, counts.get("/capture/color/image_raw", 0))
    n = counts.get(topic, 0)
    print(f"{topic}: {n} of {want}")
    status |= n != want
rows = [(float(r["seconds"]), float(r["rss_mb"])) for r in csv.DictReader(open(work + "/rss.csv"))]
warm = [r for r in rows if r[0] >= rows[-1][0] / 5] if rows else []
if len(warm) >= 2:
    n = len(warm)
    mx = sum(t for t, _ in warm) / n
    my = sum(m for _, m in warm) / n
    slope = sum((t - mx) * (m - my) for t, m in warm) / sum((t - mx) ** 2 for t, _ in warm)
    print(f"manager resident memory: {warm[0][1]:.0f} MB after warm-up, {rows[-1][1]:.0f} MB at the end, "
          f"max {max(m for _, m in rows):.0f} MB; slope after warm-up {slope * 3600:+.1f} MB/hour ({n} samples)")
log = open(work + "/launch.log", errors="replace").read()
errors = [l for l in log.splitlines() if re.search(r"\[ERROR\]|\[FATAL\]", l)]
print(f"errors in the log: {len(errors)}")
for l in errors[:10]:
    print("  " + l[:200])
status |= bool(errors)
print("soak_pipeline: " + ("passed" if status == 0 else "FAILED"))
sys.exit(status)
PY
