#!/usr/bin/env bash
# The segmentation baseline's two committed networks, from nothing: the training plan
# (scripts/segmentation_plan.py: the train region of generate's small preset), its frames generated
# (img, cls and inst at 256x144, no flow), and scripts/train_segmentation.py run twice with the same
# seed and steps: on every condition (models/segmentation_all.onnx) and on day and sunset only
# (models/segmentation_day_sunset.onnx), each with its log beside it. Needs python3-torch
# (scripts/setup.sh --training). Runs at nice 15 on one thread.
# Usage: source devel/setup.bash; scripts/train_segmentation_models.sh [--work build/segmentation]
#          [--models models] [--steps 2000] [--seed 1]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
work="$here/build/segmentation" models="$here/models" steps=2000 seed=1
while [ $# -gt 0 ]; do
  case "$1" in
    --work) work=$2 ;; --models) models=$2 ;; --steps) steps=$2 ;; --seed) seed=$2 ;;
    *) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
  esac
  shift 2
done
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir train_segmentation_models "" generate
generate=$bin/generate
"$py" -c "import torch" 2> /dev/null || { echo "train_segmentation_models: no python3-torch (scripts/setup.sh --training)" >&2; exit 2; }
mkdir -p "$work" "$models"

"$generate" --write-plan small --plan "$work/small.yaml" > /dev/null
"$py" "$here/scripts/segmentation_plan.py" "$work/small.yaml" "$work/plan.yaml"
start=$(date +%s)
# Finished sequences are skipped: a second run reuses the frames.
nice -n 15 "$generate" --plan "$work/plan.yaml" --out "$work/data" --outputs layout --img-format png --no-flow \
  > "$work/generate.log" 2>&1 || { echo "train_segmentation_models: generate failed (log: $work/generate.log)" >&2; exit 1; }
echo "train_segmentation_models: frames generated in $(( $(date +%s) - start )) s ($work/data)"

for set in all day_sunset; do
  name=segmentation_$set
  nice -n 15 "$py" "$here/scripts/train_segmentation.py" --root "$work/data" --plan "$work/plan.yaml" \
    --set "$set" --steps "$steps" --seed "$seed" --out "$models/$name.onnx" --log "$models/$name.log" \
    > /dev/null || { echo "train_segmentation_models: training $name failed (log: $models/$name.log)" >&2; exit 1; }
  tail -3 "$models/$name.log"
done
