#!/usr/bin/env bash
# Frame rate of SuperTuxKart with and without the capture layer: a race is traced once per size with
# apitrace, then replayed (glretrace, the same GL calls every time) plainly and under capture,
# alternately, --runs times each; prints the median frames per second of each and their ratio.
# Replaying takes the game's own logic out, so the figure is what the rendering costs.
#
# Usage: scripts/measure_supertuxkart.sh [--sizes "1280x720 1920x1080"] [--runs 3] [--seconds 4]
#          [--pipeline forward|deferred] [--out DIR (build/measure_stk)]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
sizes="1280x720 1920x1080"; runs=3; seconds=4; pipeline=forward; out="$here/build/measure_stk"
# shellcheck source=options.sh
source "$here/scripts/options.sh"
viper_options '2,9' "measure_supertuxkart: unknown option '{}' (see --help)" --sizes=sizes --runs=runs \
  --seconds=seconds --pipeline=pipeline --out=out -- "$@"
case "$pipeline" in
  forward) lights=--disable-dynamic-lights ;;
  deferred) lights=--enable-dynamic-lights ;;
  *) echo "measure_supertuxkart: --pipeline must be forward or deferred" >&2; exit 2 ;;
esac
for tool in /usr/games/supertuxkart apitrace glretrace xvfb-run; do
  command -v "$tool" > /dev/null || { echo "measure_supertuxkart: $tool missing (scripts/setup.sh --test-programs)" >&2; exit 2; }
done
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir measure_supertuxkart "" capture
mkdir -p "$out"

fps_of() { sed -n 's/.*average of \([0-9.]*\) fps.*/\1/p' "$1"; }
median() { sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }

echo "SuperTuxKart $pipeline, candela_city, $seconds s race after loading, glretrace replays; $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), Mesa llvmpipe"
printf '%-10s %8s %10s %10s %7s\n' size frames plain_fps capture_fps ratio
for size in $sizes; do
  w=${size%x*}; h=${size#*x}
  trace="$out/stk_${pipeline}_${size}.trace"
  if [ ! -f "$trace" ]; then
    home=$(mktemp -d)
    HOME="$home" xvfb-run -a -s "-screen 0 $((w + 64))x$((h + 64))x24" apitrace trace -o "$trace" \
      /usr/games/supertuxkart --track=candela_city --numkarts=4 --seed=1 --profile-time="$seconds" $lights \
      --anisotropic=0 --windowed --screensize="$size" > "$out/trace_$size.log" 2>&1
    rm -rf "$home"
  fi
  plain=(); captured=(); frames=0
  for ((r = 0; r < runs; ++r)); do
    xvfb-run -a -s "-screen 0 $((w + 64))x$((h + 64))x24" glretrace -b "$trace" > "$out/plain.log" 2>&1
    plain+=("$(fps_of "$out/plain.log")")
    frames=$(sed -n 's/.*Rendered \([0-9]*\) frames.*/\1/p' "$out/plain.log")
    xvfb-run -a -s "-screen 0 $((w + 64))x$((h + 64))x24" "$bin/capture" --output "$out/replay.vcap" \
      --profile "$here/config/profiles/supertuxkart.yaml" -- glretrace -b "$trace" > "$out/captured.log" 2>&1
    captured+=("$(fps_of "$out/captured.log")")
    rm -f "$out/replay.vcap"
  done
  p=$(printf '%s\n' "${plain[@]}" | median); c=$(printf '%s\n' "${captured[@]}" | median)
  printf "%-10s %8s %10s %10s %7.2f\n" "$size" "$frames" "$p" "$c" "$(awk -v p="$p" -v c="$c" "BEGIN {print p / c}")"
done
