#!/usr/bin/env bash
# Remakes test/evaluation/data/cityscapes_parity: the test scene's ground truth (generate, from the
# committed raw bag), the parity cases made from it and the synthetic ones (write_parity_cases),
# and reference.csv, the scores of cityscapesScripts' own evaluation on them
# (scripts/cityscapes_parity.py). test_cityscapes_parity compares the package's scores with it.
#
# Usage: scripts/cityscapes_parity.sh CITYSCAPES_CHECKOUT [OUT_DIR (test/evaluation/data/cityscapes_parity)]
# CITYSCAPES_CHECKOUT: a checkout of github.com/mcordts/cityscapesScripts (not part of this package).
# Needs a built workspace (the sourced one, else this checkout's devel space), python3-numpy and
# python3-pil.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -lt 1 ] || [ $# -gt 2 ]; then echo "usage: $0 CITYSCAPES_CHECKOUT [OUT_DIR]" >&2; exit 2; fi
checkout=$1 out=${2:-$here/test/evaluation/data/cityscapes_parity}
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir cityscapes_parity "" generate write_parity_cases
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin/generate" --input "$here/bags/test_scene_raw.bag" --labels "$here/config/labels/test_scene_labels.yaml" \
  --out "$work/gt" --frames 20 --outputs layout --no-flow >/dev/null
mkdir -p "$out"  # files of the same names are overwritten
"$bin/write_parity_cases" "$out" "$work/gt"
"$py" "$here/scripts/cityscapes_parity.py" "$checkout" "$out" "$out/reference.csv"
echo "$out: $(find "$out" -name '*.png' | wc -l) images, reference.csv $(($(wc -l < "$out/reference.csv") - 1)) rows"
