#!/usr/bin/env bash
# Remakes test/dataset/data/training_formats: the fixture frames written in every training format by
# the package's writers (write_training_format_cases), then read and scored by each format's
# reference code (scripts/training_formats_reference.py). test_training_formats checks the writers
# against it. docs/training_formats.md, "Validation".
#
# Usage: scripts/training_formats_reference.sh --cityscapes CHECKOUT --cocoapi PYTHONAPI [--out DIR]
# CHECKOUT: a checkout of github.com/mcordts/cityscapesScripts; PYTHONAPI: the PythonAPI folder of
# github.com/cocodataset/cocoapi, its extension built (training_formats_reference.py says how).
# Neither is part of this package. --out: test/dataset/data/training_formats by default. Needs a
# built workspace (the sourced one, else this checkout's devel space), python3-numpy and python3-pil.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=options.sh
source "$here/scripts/options.sh"
cityscapes="" cocoapi="" out=$here/test/dataset/data/training_formats
viper_options '7,11' "$0: unknown argument '{}' (see --help)" --cityscapes=cityscapes --cocoapi=cocoapi --out=out -- "$@"
if [ -z "$cityscapes" ] || [ -z "$cocoapi" ]; then echo "$0: --cityscapes and --cocoapi are needed (see --help)" >&2; exit 2; fi
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir training_formats_reference "" write_training_format_cases
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin/write_training_format_cases" "$work"
"$py" "$here/scripts/training_formats_reference.py" "$work" "$out" --cityscapes "$cityscapes" --cocoapi "$cocoapi"
