#!/usr/bin/env bash
# Remakes test/dataset/data/training_formats: the fixture frames written in every training format by
# the package's writers (write_training_format_cases), then read and scored by each format's
# reference code (scripts/training_formats_reference.py). test_training_formats checks the writers
# against it. docs/training_formats.md, "Validation".
#
# Usage: scripts/training_formats_reference.sh --cityscapes CHECKOUT --cocoapi PYTHONAPI
#                                              --kitti-devkit DIR [--out DIR]
# CHECKOUT: a checkout of github.com/mcordts/cityscapesScripts; PYTHONAPI: the PythonAPI folder of
# github.com/cocodataset/cocoapi, its extension built; DIR: KITTI's devkit headers io_flow.h,
# io_depth.h, log_colormap.h (training_formats_reference.py says more). None is part of this
# package. --out: test/dataset/data/training_formats by default. Needs a built workspace (the
# sourced one, else this checkout's devel space), python3-numpy, python3-pil, g++ and libpng++-dev.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=options.sh
source "$here/scripts/options.sh"
cityscapes="" cocoapi="" kitti="" out=$here/test/dataset/data/training_formats
viper_options '7,13' "$0: unknown argument '{}' (see --help)" --cityscapes=cityscapes --cocoapi=cocoapi --kitti-devkit=kitti --out=out -- "$@"
if [ -z "$cityscapes" ] || [ -z "$cocoapi" ] || [ -z "$kitti" ]; then
  echo "$0: --cityscapes, --cocoapi and --kitti-devkit are needed (see --help)" >&2
  exit 2
fi
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir training_formats_reference "" write_training_format_cases
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin/write_training_format_cases" "$work"
"$py" "$here/scripts/training_formats_reference.py" "$work" "$out" --cityscapes "$cityscapes" --cocoapi "$cocoapi" \
  --kitti-devkit "$kitti"
