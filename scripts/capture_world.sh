#!/usr/bin/env bash
# Runs the world under the capture layer, writing a capture stream that capture_bridge can follow
# live (launch/world_live.launch starts it as a node). Resolves both executables in the sourced
# workspace, else in this checkout's devel space (scripts/package_binaries.sh), so it works from
# `roslaunch` and from a shell.
#
# Usage: scripts/capture_world.sh OUTPUT.vcap [world options, e.g. --condition rain --frames 300]
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 OUTPUT.vcap [world options]" >&2; exit 2; }
output=$1
shift
# roslaunch appends __name:= and __log:= to a node's arguments: they are not the world's.
args=()
for a in "$@"; do
  case "$a" in __*:=*) ;; *) args+=("$a") ;; esac
done
here=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir capture_world "" capture world
mkdir -p "$(dirname "$output")"
rm -f "$output"
condition=day
for ((i = 0; i < ${#args[@]}; ++i)); do
  [ "${args[$i]}" = --condition ] && condition=${args[$((i + 1))]:-day}
done
exec "$bin/capture" --output "$output" --profile "$here/config/profiles/world.yaml" --condition "$condition" \
  --fps 15 -- "$bin/world" "${args[@]}"
