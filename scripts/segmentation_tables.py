#!/usr/bin/env python3
"""Tables of the segmentation baseline over the world's conditions (the paper's Tables 1 and 2),
from the evaluate reports that scripts/measure_segmentation.sh writes
(OUT/<condition>_<model>/{summary,semantic_iou,semantic_iiou,instance_ap}.csv).

Each report holds one condition, and IoU and AP do not pool from per-condition values (they are
ratios of counts over every frame), so the column "mean" is the mean of the conditions' values,
each condition the same number of frames. Exit 1 if a report is missing or scored fewer frames than
were captured.

Usage: segmentation_tables.py [--frames N] [--models "all day_sunset"] OUT_DIR
"""
import argparse
import csv
import os
import sys

CONDITIONS = ["day", "sunset", "rain", "snow", "night"]
NAMES = {"all": "all conditions", "day_sunset": "day + sunset"}


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def mean(values):
    values = [v for v in values if v is not None]
    return sum(values) / len(values) if values else None


def fmt(value):
    return "–" if value is None else f"{value:.1f}"


def number(text):
    return float(text) if text not in ("", None) else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("--frames", type=int, default=0, help="frames per condition (0: do not check counts)")
    ap.add_argument("--models", default="all day_sunset")
    args = ap.parse_args()
    models = args.models.split()

    problems = []
    score = {}  # (model, condition) -> {"miou", "iiou", "ap", "ap50"}
    per_class = {}  # (model, kind, class name, condition) -> value; kind: iou, ap
    conditions = [c for c in CONDITIONS if any(os.path.isdir(os.path.join(args.out_dir, f"{c}_{m}")) for m in models)]
    for model in models:
        for condition in conditions:
            report = os.path.join(args.out_dir, f"{condition}_{model}")
            try:
                summary = [r for r in read_rows(os.path.join(report, "summary.csv")) if r["condition"] == condition]
                iou = [r for r in read_rows(os.path.join(report, "semantic_iou.csv")) if r["condition"] == condition]
                iiou = [r for r in read_rows(os.path.join(report, "semantic_iiou.csv")) if r["condition"] == condition]
                inst = [r for r in read_rows(os.path.join(report, "instance_ap.csv")) if r["condition"] == condition]
            except OSError as e:
                problems.append(f"{report}: {e.strerror}: {e.filename}")
                continue
            if not summary:
                problems.append(f"{report}: no {condition} row in summary.csv")
                continue
            s = summary[0]
            for key in ("semantic_frames", "instance_frames"):
                if args.frames and int(s[key]) != args.frames:
                    problems.append(f"{report}: {key} {s[key]} of {args.frames}")
            score[(model, condition)] = {
                "miou": number(s["mean_iou"]), "ap": number(s["ap"]), "ap50": number(s["ap50"]),
                "iiou": mean([number(r["iiou_percent"]) for r in iiou]),
                "frames": int(s["semantic_frames"])}
            for r in iou:  # class id -1: the report's mean, which the tables above show
                if int(r["class_id"]) >= 0:
                    per_class[(model, "iou", r["class_name"], condition)] = number(r["iou_percent"])
            for r in inst:
                if int(r["class_id"]) >= 0:
                    per_class[(model, "ap", r["class_name"], condition)] = number(r["ap_percent"])
    if not score:
        print(f"segmentation_tables: no reports under {args.out_dir}", file=sys.stderr)
        return 1

    head = "| trained on | metric | " + " | ".join(conditions) + " | mean |"
    rule = "|---|---|" + "---:|" * (len(conditions) + 1)

    def rows(keys):
        for model in models:
            for key, label in keys:
                cells = [score.get((model, c), {}).get(key) for c in conditions]
                print(f"| {NAMES.get(model, model)} | {label} | " + " | ".join(fmt(v) for v in cells) +
                      f" | {fmt(mean(cells))} |")

    print("#### Table 1: semantic segmentation (Cityscapes protocol: IoU over the 23 scored classes)\n")
    print(head)
    print(rule)
    rows([("miou", "mIoU %"), ("iiou", "iIoU %")])
    print("\n#### Table 2: instance segmentation (Cityscapes AP over IoU 0.50:0.05:0.95, and at 0.50)\n")
    print(head)
    print(rule)
    rows([("ap", "AP %"), ("ap50", "AP50 %")])
    frames = [score.get((models[0], c), {}).get("frames") for c in conditions]
    print("\nFrames scored per condition: " + ", ".join(f"{c} {n}" for c, n in zip(conditions, frames)) + ".")

    for kind, title in (("iou", "IoU % per class"), ("ap", "AP % per instance class")):
        names = []
        for key in per_class:
            if key[1] == kind and key[2] not in names:
                names.append(key[2])
        print(f"\n#### {title} (mean of the conditions)\n")
        print("| class | " + " | ".join(NAMES.get(m, m) for m in models) + " |")
        print("|---|" + "---:|" * len(models))
        for name in names:
            print(f"| {name} | " + " | ".join(
                fmt(mean([per_class.get((m, kind, name, c)) for c in conditions])) for m in models) + " |")

    for p in problems:
        print(f"segmentation_tables: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
