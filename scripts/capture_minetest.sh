#!/usr/bin/env bash
# Minetest (Debian's minetest 5.6.1, a second engine whose source and assets are not ours) under
# the capture layer: a new world of Minetest Game, the player walking with --random-input, captured
# after the world has loaded, then checked against its own depth and flow (capture_check) and
# turned into a raw bag.
#
# Usage: scripts/capture_minetest.sh [--frames 60] [--width 640] [--height 480] [--seed 42]
#          [--skip 60] [--out DIR (build/minetest)] [--no-bag] [--no-check]
#          [--bin DIR (the sourced workspace's, else devel/lib/viper)]
# Writes DIR/minetest.vcap and DIR/minetest_raw.bag. Needs `minetest` and `Xvfb` (installed by
# scripts/setup.sh --test-programs); runs the game in its own Xvfb display. The game's clouds are
# off (they are drawn without shaders and would hold depth but no ids); --seed is the map seed.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
frames=60; width=640; height=480; seed=42; skip=60
out="$here/build/minetest"; bag=1; check=1; bin=""
# shellcheck source=options.sh
source "$here/scripts/options.sh"
viper_options '2,12' "capture_minetest: unknown option '{}' (see --help)" --frames=frames --width=width \
  --height=height --seed=seed --skip=skip --out=out --bin=bin --no-bag=bag:0 --no-check=check:0 -- "$@"
game=/usr/games/minetest
# shellcheck source=game_capture.sh
source "$here/scripts/game_capture.sh"
game_capture_setup capture_minetest "$game" "$bin" "$check" "$bag"
command -v xvfb-run > /dev/null || { echo "capture_minetest: xvfb-run not found (package xvfb)" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
capture="$out/minetest.vcap"

# A fresh HOME, configuration and world per run: nothing a user set changes what is rendered.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/home" "$work/world"
echo "gameid = minetest_game" > "$work/world/world.mt"
printf 'screen_w = %s\nscreen_h = %s\nenable_sound = false\nenable_clouds = false\nfixed_map_seed = %s\n' \
  "$width" "$height" "$seed" > "$work/minetest.conf"

echo "== capturing $frames frames of Minetest (${width}x${height}, map seed $seed) -> $capture"
rm -f "$capture"
status=0
HOME="$work/home" xvfb-run -a -s "-screen 0 $((width + 64))x$((height + 64))x24" "$bin/capture" \
  --output "$capture" --profile "$here/config/profiles/minetest.yaml" --condition day --frames "$frames" \
  --skip-frames "$skip" -- "$game" --go --world "$work/world" --name viper --password viper \
  --config "$work/minetest.conf" --random-input > "$out/minetest.game.log" 2>&1 || status=$?
game_capture_result capture_minetest "$status" "$out/minetest.game.log"

game_capture_outputs "$capture" "$check" "$bag" "$out/minetest_raw.bag" \
  "ids, matrices, meshes and flow against the capture itself" --flow
