#!/usr/bin/env bash
# SuperTuxKart (Debian's supertuxkart 1.4, a program whose source and assets are not ours) under the
# capture layer: an AI-driven race on a chosen track, captured from the first frame the race's
# camera draws, then checked against its own depth (capture_check) and turned into a raw bag.
#
# Usage: scripts/capture_supertuxkart.sh [--track candela_city] [--frames 60] [--width 1280]
#          [--height 720] [--karts 4] [--seed 1] [--skip 0] [--out DIR (build/stk)] [--no-bag]
#          [--bin DIR (the sourced workspace's, else devel/lib/viper)] [--game-args "--kart=tux --ai=nolok,pidgin"] [--no-check]
#          [--render-driver gl|vulkan (gl)]
# Writes DIR/<track>.vcap and DIR/<track>_raw.bag. Needs `supertuxkart` and `Xvfb` (installed by
# scripts/setup.sh --test-programs); runs the game in its own Xvfb display unless --display :N.
# The game runs with its forward pipeline (--disable-dynamic-lights) and without anisotropic
# filtering (Mesa 22.3's llvmpipe hangs in one instanced draw with it, with or without capture).
# Sound is off (ALSOFT_DRIVERS=null) unless ALSOFT_DRIVERS is set. --render-driver vulkan: the game
# draws through Vulkan (lavapipe without a GPU), captured by the Vulkan layer with
# config/profiles/supertuxkart_vulkan.yaml.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
track=candela_city; frames=60; width=1280; height=720; karts=4; seed=1; skip=0
out="$here/build/stk"; bag=1; display=""; bin=""; game_args=""; driver=gl
check=1
# shellcheck source=options.sh
source "$here/scripts/options.sh"
viper_options '2,16' "capture_supertuxkart: unknown option '{}' (see --help)" '__*:=*=' --no-check=check:0 \
  --track=track --frames=frames --width=width --height=height --karts=karts --seed=seed --skip=skip \
  --out=out --display=display --bin=bin --game-args=game_args --no-bag=bag:0 --render-driver=driver -- "$@"
case "$driver" in
  gl) profile="$here/config/profiles/supertuxkart.yaml"; driver_args="" ;;
  vulkan) profile="$here/config/profiles/supertuxkart_vulkan.yaml"; driver_args="--render-driver=vulkan" ;;
  *) echo "capture_supertuxkart: --render-driver must be gl or vulkan, not '$driver'" >&2; exit 2 ;;
esac
stk=/usr/games/supertuxkart
# The executables of --bin DIR, else of the sourced workspace (a devel space outside the package,
# such as scripts/sanitize.sh's, included), else of the package's own devel space.
# shellcheck source=game_capture.sh
source "$here/scripts/game_capture.sh"
game_capture_setup capture_supertuxkart "$stk" "$bin" "$check" "$bag"
mkdir -p "$out"
out=$(cd "$out" && pwd)
capture="$out/$track.vcap"

# The game keeps its configuration under $HOME/.config: a fresh one per run, so that nothing a
# user set (or an earlier run left) changes what is rendered.
game_home=$(mktemp -d)
xvfb_pid=""
cleanup() {
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true
  rm -rf "$game_home"
}
trap cleanup EXIT
if [ -z "$display" ]; then
  # A screen larger than the window: the game shrinks a window that does not fit.
  for n in $(seq 90 140); do
    [ -e "/tmp/.X11-unix/X$n" ] || [ -e "/tmp/.X$n-lock" ] && continue
    Xvfb ":$n" -screen 0 "$((width + 64))x$((height + 64))x24" -nolisten tcp >/dev/null 2>&1 &
    xvfb_pid=$!
    display=":$n"
    for _ in $(seq 50); do [ -e "/tmp/.X11-unix/X$n" ] && break; sleep 0.1; done
    break
  done
  [ -n "$display" ] || { echo "capture_supertuxkart: no free X display number for Xvfb" >&2; exit 1; }
fi

# Long enough a race that it never ends before the frames are captured (the layer stops the game).
race_s=$((frames / 2 + 120))
echo "== capturing $frames frames of SuperTuxKart ($driver, $track, ${width}x${height}, $karts karts, seed $seed) -> $capture"
rm -f "$capture"
status=0
# Sound off (OpenAL Soft's null device), unless ALSOFT_DRIVERS says otherwise: nothing in a capture
# needs it, and opening PulseAudio hangs the game with a sanitizer runtime preloaded (a sanitized
# capture layer: docs/sanitizers.md).
HOME="$game_home" DISPLAY="$display" ALSOFT_DRIVERS="${ALSOFT_DRIVERS:-null}" "$bin/capture" --output "$capture" \
  --profile "$profile" --condition day --frames "$frames" \
  --skip-frames "$skip" --start-on-scene -- \
  "$stk" $driver_args --track="$track" --numkarts="$karts" --seed="$seed" --profile-time="$race_s" \
  ${STK_PIPELINE:---disable-dynamic-lights} --anisotropic=0 --windowed --screensize="${width}x${height}" $game_args \
  > "$out/$track.game.log" 2>&1 || status=$?
game_capture_result capture_supertuxkart "$status" "$out/$track.game.log"

game_capture_outputs "$capture" "$check" "$bag" "$out/${track}_raw.bag" \
  "ids, matrices and meshes against the capture's own depth"
