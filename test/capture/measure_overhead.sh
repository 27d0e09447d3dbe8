#!/bin/bash
# Frame time of the capture test program with and without the interceptor, alternating runs.
# usage: measure_overhead.sh BUILD_DEVEL_LIB_VIPER_DIR [SIZE] [FRAMES] [LOAD] [RUNS] [CAPTURE_OPTIONS] [PROGRAM_OPTIONS]
#   CAPTURE_OPTIONS: extra options of `capture` (e.g. "--readback async --writer-threads 4")
#   PROGRAM_OPTIONS: extra options of the test program (e.g. "--frame-ms 16.7": a program held to 60 fps)
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=../../scripts/package_binaries.sh
source "$repo/scripts/package_binaries.sh"
viper_bin_dir measure_overhead "${1:?directory holding capture and viper_gl_test_program}" capture viper_gl_test_program
dir=$bin
size=${2:-1920x1080}
frames=${3:-30}
load=${4:-300}
runs=${5:-3}
read -r -a capture_options <<< "${6:-}"
read -r -a program_options <<< "${7:-}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
prog=("$dir/viper_gl_test_program" --mode direct --size "$size" --frames "$frames" --load "$load" "${program_options[@]}")
profile="$repo/config/profiles/viper_scene.yaml"
plain=() captured=()
for ((i = 0; i < runs; ++i)); do
  plain+=("$("${prog[@]}" | sed -n 's/frame_ms=//p')")
  captured+=("$("$dir/capture" --output "$out/o.vcap" --profile "$profile" "${capture_options[@]}" -- "${prog[@]}" |
    sed -n 's/frame_ms=//p')")
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
p=$(median "${plain[@]}") c=$(median "${captured[@]}")
echo "size=$size draws/frame=$((load + 4)) ${7:-} capture ${6:-(defaults)}: plain_ms=[${plain[*]}] captured_ms=[${captured[*]}]"
echo "median plain ${p} ms, captured ${c} ms, ratio $(awk -v a="$c" -v b="$p" 'BEGIN {printf "%.2f", a / b}')"
echo "stream: $(stat -c %s "$out/o.vcap") bytes for $frames frames"
