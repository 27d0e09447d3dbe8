#!/usr/bin/env bash
# Remakes test/dataset/data/training_formats: the fixture frames written in every training format by
# the package's writers (write_training_format_cases), then read and scored by each format's
# reference code (scripts/training_formats_reference.py). test_training_formats checks the writers
# against it. docs/training_formats.md, "Validation".
#
# Usage: scripts/training_formats_reference.sh --cityscapes CHECKOUT [OUT_DIR]
# CHECKOUT: a checkout of github.com/mcordts/cityscapesScripts (not part of this package).
# Needs a built workspace (the sourced one, else this checkout's devel space), python3-numpy and
# python3-pil.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
usage="usage: $0 --cityscapes CHECKOUT [OUT_DIR]"
cityscapes=""
args=()
while [ $# -gt 0 ]; do
  case $1 in
    --cityscapes) [ $# -ge 2 ] || { echo "$usage" >&2; exit 2; }; cityscapes=$2; shift 2 ;;
    -*) echo "$usage" >&2; exit 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
if [ -z "$cityscapes" ] || [ ${#args[@]} -gt 1 ]; then echo "$usage" >&2; exit 2; fi
out=${args[0]:-$here/test/dataset/data/training_formats}
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir training_formats_reference "" write_training_format_cases
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin/write_training_format_cases" "$work"
"$py" "$here/scripts/training_formats_reference.py" "$work" "$out" --cityscapes "$cityscapes"
