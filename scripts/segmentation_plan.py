#!/usr/bin/env python3
"""The dataset plan the segmentation baseline is trained on (docs/baselines.md, "Semantic and
instance segmentation"): the city and regions of generate's small preset, and in its train region

- PER_CONDITION sequences of every condition (the "all" training set), plus
- EXTRA more day and EXTRA more sunset sequences, so that the day + sunset training set holds as
  many frames as the "all" one (2 * (PER_CONDITION + EXTRA) = 5 * PER_CONDITION);

and in its val region one sequence of every condition (the training log's held-out check). The
plan's `training_sets` name the sequences of each set: `all` (the first PER_CONDITION of every
condition) and `day_sunset` (every day and sunset sequence). Frames
are FPS apart in time (3 fps: a driving camera moves about 2-3 m between frames, so that neighbouring
frames are not near copies), WIDTH x HEIGHT. Ego modes take turns, every sequence has its own seed.
The test region is left alone: scripts/measure_segmentation.sh scores on it.

Usage: segmentation_plan.py SMALL_PRESET.yaml OUT.yaml [--per-condition 4] [--extra 6] [--frames 60]
         [--val-frames 20] [--width 256] [--height 144] [--fps 3]
"""
import argparse
import sys

import yaml

CONDITIONS = ["day", "sunset", "rain", "snow", "night"]
EGOS = ["drive", "ride", "walk"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("preset")
    ap.add_argument("out")
    ap.add_argument("--per-condition", type=int, default=4)
    ap.add_argument("--extra", type=int, default=6, help="more day and more sunset sequences each")
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--val-frames", type=int, default=20)
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=144)
    ap.add_argument("--fps", type=float, default=3.0)
    args = ap.parse_args()
    if 2 * (args.per_condition + args.extra) != 5 * args.per_condition:
        print(f"segmentation_plan: 2 * ({args.per_condition} + {args.extra}) day + sunset sequences differ from "
              f"5 * {args.per_condition}: the two training sets would not be the same size", file=sys.stderr)

    with open(args.preset) as f:
        preset = yaml.safe_load(f)
    if "city" not in preset:
        print(f"segmentation_plan: {args.preset} has no city (write it with generate --write-plan small)",
              file=sys.stderr)
        return 2
    wanted = [("train", c) for c in CONDITIONS for _ in range(args.per_condition)]
    wanted += [("train", c) for c in ("day", "sunset") for _ in range(args.extra)]
    wanted += [("val", c) for c in CONDITIONS]
    sequences = []
    for i, (split, condition) in enumerate(wanted):
        sequences.append({
            "id": f"{i + 1:03d}", "split": split, "condition": condition, "ego": EGOS[i % len(EGOS)],
            "seed": 1000 + i, "frames": args.frames if split == "train" else args.val_frames,
            "width": args.width, "height": args.height, "region": 0,
        })
    train = [s for s in sequences if s["split"] == "train"]
    sets = {"all": [s["id"] for c in CONDITIONS for s in [t for t in train if t["condition"] == c][:args.per_condition]],
            "day_sunset": [s["id"] for s in train if s["condition"] in ("day", "sunset")]}
    # generate reads name, fps, sequences and city; training_sets is train_segmentation.py's.
    plan = {"name": "segmentation", "fps": args.fps, "city": preset["city"], "sequences": sequences,
            "training_sets": sets}
    with open(args.out, "w") as f:
        yaml.safe_dump(plan, f, sort_keys=False)
    frames = sum(s["frames"] for s in sequences)
    print(f"segmentation_plan: {len(sequences)} sequences, {frames} frames -> {args.out} (training sets: " +
          ", ".join(f"{k} {sum(s['frames'] for s in train if s['id'] in v)} frames" for k, v in sets.items()) + ")")
    return 0


if __name__ == "__main__":
    sys.exit(main())
