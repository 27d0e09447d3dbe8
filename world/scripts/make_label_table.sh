#!/bin/bash
# Generates the world's resource label table (config/labels/world_labels.yaml by default) from
# one capture of the default sequence and its oracle: every mesh key gets the majority class of
# its draws (tools/make_label_table.cpp). Frame size does not change mesh keys, so frames are small.
#
# usage: make_label_table.sh DEVEL_LIB_VIPER_DIR INTERCEPT_SO [OUT.yaml] [extra world options]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=../../scripts/package_binaries.sh
source "$repo/scripts/package_binaries.sh"
viper_bin_dir make_label_table.sh "${1:?directory with world and make_label_table (devel/lib/viper)}" \
  capture world make_label_table
bin_dir=$bin
intercept=${2:?path of libviper_intercept.so}
out=${3:-config/labels/world_labels.yaml}
shift $(( $# >= 3 ? 3 : $# ))
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Meshes are the same in every condition except the particles (class 0): day covers the rest.
"$bin_dir/capture" --library "$intercept" --output "$tmp/day.vcap" --profile "$repo/config/profiles/world.yaml" \
  --condition day --fps 15 -- "$bin_dir/world" --condition day --width 480 --height 270 --oracle "$tmp/day.txt" "$@"
mkdir -p "$(dirname "$out")"
"$bin_dir/make_label_table" "$tmp/day.vcap" "$tmp/day.txt" "$out"
