#!/usr/bin/env python3
"""Tables of the reference baselines over the world's conditions, from the evaluate reports that
scripts/measure_baselines.sh writes (OUT/<condition>_<dis|farneback>/{flow,odometry}.csv).

The column "all" pools the conditions the way evaluate pools frames: flow figures are means over
pixels, so they are weighted by each condition's pixel count; KITTI errors are means over segments,
so they are weighted by segment count. Exit 1 if a report is missing or scored fewer frames than
the sequences have (a frame lost on the way makes the numbers incomparable).

Usage: baseline_tables.py [--frames N] OUT_DIR
"""
import argparse
import csv
import os
import sys

CONDITIONS = ["day", "sunset", "rain", "snow", "night"]
RUNS = {"dis": ("DIS (flow_baseline)", "lk_flow (opencv_apps)"),
        "farneback": ("Farneback (flow_baseline)", "fback_flow (opencv_apps)")}
FLOW_METRICS = [("wauc", "WAUC %", "{:.2f}"), ("epe_px", "EPE px", "{:.3f}"), ("outlier_percent", "Fl %", "{:.2f}")]


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def pooled(parts, value, weight):
    """Weighted mean of value over the parts (dicts), or None without weight."""
    total = sum(float(p[weight]) for p in parts if p.get(value))
    if total <= 0:
        return None
    return sum(float(p[value]) * float(p[weight]) for p in parts if p.get(value)) / total


def fmt(value, pattern):
    return "–" if value is None else pattern.format(value)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("--frames", type=int, default=0, help="frames per sequence (0: do not check counts)")
    args = ap.parse_args()

    problems = []
    flow = {}  # (run, input, region, condition) -> row
    odometry = {}  # (condition, length) -> row
    paths = {}  # condition -> ground-truth path length, m
    conditions = []
    for condition in CONDITIONS:
        if not any(os.path.isdir(os.path.join(args.out_dir, f"{condition}_{run}")) for run in RUNS):
            continue  # not measured
        for run in RUNS:
            report = os.path.join(args.out_dir, f"{condition}_{run}")
            try:
                rows = read_rows(os.path.join(report, "flow.csv"))
            except OSError as e:
                problems.append(f"{report}: no flow.csv ({e.strerror})")
                continue
            if condition not in conditions:
                conditions.append(condition)
            for r in rows:
                if r["condition"] == condition:
                    flow[(run, r["input"], r["region"], condition)] = r
                    if args.frames and r["region"] == "all" and int(r["frames"]) != args.frames - 1:
                        problems.append(f"{report}: {r['input']} flow scored {r['frames']} of "
                                        f"{args.frames - 1} frame pairs")
            if run == "dis":
                try:
                    for r in read_rows(os.path.join(report, "odometry.csv")):
                        if r["condition"] == condition:
                            odometry[(condition, r["length_m"])] = r
                    for r in read_rows(os.path.join(report, "summary.csv")):
                        if r["condition"] == condition:
                            paths[condition] = float(r["odometry_path_m"] or 0)
                            if args.frames and int(r["odometry_poses"]) != args.frames:
                                problems.append(f"{report}: odometry scored {r['odometry_poses']} of "
                                                f"{args.frames} poses")
                except OSError as e:
                    problems.append(f"{report}: no odometry.csv or summary.csv ({e.strerror})")
    if not conditions:
        print(f"baseline_tables: no reports under {args.out_dir}", file=sys.stderr)
        return 1

    header = "| method | metric | " + " | ".join(conditions) + " | all |"
    rule = "|---|---|" + "---:|" * (len(conditions) + 1)
    print("### Optical flow (all: every pixel with ground-truth flow; noc: visible in the next frame)\n")
    print(header)
    print(rule)
    for run, names in RUNS.items():
        for kind, name in zip(("dense", "sparse"), names):
            for region in ("all", "noc"):
                parts = {c: flow.get((run, kind, region, c)) for c in conditions}
                for key, label, pattern in FLOW_METRICS:
                    if region == "noc" and key == "outlier_percent":
                        continue
                    cells = [fmt(float(p[key]) if p and p[key] else None, pattern) for p in parts.values()]
                    total = pooled([p for p in parts.values() if p], key, "pixels")
                    print(f"| {name} | {label}{' noc' if region == 'noc' else ''} | " + " | ".join(cells) +
                          f" | {fmt(total, pattern)} |")
            counts = [flow.get((run, kind, "all", c)) for c in conditions]
            unit = "px" if kind == "dense" else "vectors"
            print(f"| {name} | pairs / {unit} | " + " | ".join(
                f"{p['frames']} / {int(p['pixels']):,}" if p else "–" for p in counts) + " | |")

    lengths = sorted({k[1] for k in odometry if k[1] != "all"}, key=float)
    print("\n### Visual odometry (vo_baseline; KITTI protocol on segments of "
          f"{', '.join(lengths)} m)\n")
    print("| metric | " + " | ".join(conditions) + " | all |")
    print("|---|" + "---:|" * (len(conditions) + 1))
    for key, label, pattern in (("translation_percent", "translation error %", "{:.2f}"),
                                ("rotation_deg_per_m", "rotation error deg/m", "{:.4f}")):
        rows = [odometry.get((c, "all")) for c in conditions]
        cells = [fmt(float(r[key]) if r and r[key] else None, pattern) for r in rows]
        total = pooled([r for r in rows if r], key, "segments")
        print(f"| {label} | " + " | ".join(cells) + f" | {fmt(total, pattern)} |")
    for length in lengths:
        rows = [odometry.get((c, length)) for c in conditions]
        cells = [fmt(float(r["translation_percent"]) if r and r["translation_percent"] else None, "{:.2f}")
                 for r in rows]
        total = pooled([r for r in rows if r], "translation_percent", "segments")
        print(f"| translation % at {length} m | " + " | ".join(cells) + f" | {fmt(total, '{:.2f}')} |")
    print("| path m | " + " | ".join(fmt(paths.get(c), "{:.1f}") for c in conditions) + " | |")
    seg = [odometry.get((c, "all")) for c in conditions]
    print("| segments | " + " | ".join(r["segments"] if r else "–" for r in seg) +
          f" | {sum(int(r['segments']) for r in seg if r)} |")

    for p in problems:
        print(f"baseline_tables: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
