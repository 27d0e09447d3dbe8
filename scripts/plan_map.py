#!/usr/bin/env python3
"""Map of a dataset plan's city: every sequence's route coloured by split (PNG).

usage: plan_map.py PLAN.yaml OUT.png [--world devel/lib/viper/world] [--metres-per-pixel 3]

Runs `world --print-route` for every sequence of the plan (its seed, ego mode, the plan's city seed
and the sequence's region) and draws the path points (every 5 m) over the city's road grid, with each
split's region shaded: train blue, val orange, test green. North (+y) is up. Used for
docs/city_splits.png.
"""
import argparse
import os
import subprocess
import sys

import yaml

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "world", "scripts"))
from contact_sheet import write_png  # noqa: E402

BLOCK = 72.0  # metres between intersections (RoadDims::kBlock)
SIDEWALK = 11.0  # the farthest a path runs from its road's centre line
COLOURS = {"train": ((205, 220, 245), (30, 80, 200)), "val": ((250, 225, 200), (220, 110, 20)),
           "test": ((210, 240, 210), (30, 150, 50))}


def route_points(world, plan, seq):
    region = plan["city"]["regions"][seq["split"]][seq.get("region", 0)]
    args = [world, "--print-route", "--seed", str(seq["seed"]), "--ego", seq.get("ego", "drive"),
            "--city-seed", str(plan["city"]["seed"]), "--region", ",".join(str(v) for v in region)]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        if line.startswith("path_points"):
            return [tuple(float(v) for v in p.split(",")) for p in line.split()[2:]]
    raise SystemExit("world printed no path_points for %s/%s: %s" % (seq["split"], seq["id"], out))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("plan")
    parser.add_argument("out")
    parser.add_argument("--world", default="devel/lib/viper/world")
    parser.add_argument("--metres-per-pixel", type=float, default=3.0)
    a = parser.parse_args()
    with open(a.plan) as f:
        plan = yaml.safe_load(f)
    if "city" not in plan:
        raise SystemExit("%s has no city: its sequences are towns of their own" % a.plan)
    size_i, size_j = plan["city"]["size"]
    pad = 2 * BLOCK
    x0, y0 = -pad, -pad
    w = int(((size_i - 1) * BLOCK + 2 * pad) / a.metres_per_pixel) + 1
    h = int(((size_j - 1) * BLOCK + 2 * pad) / a.metres_per_pixel) + 1
    img = bytearray(b"\xf4" * (w * h * 3))

    def put(px, py, colour):
        if 0 <= px < w and 0 <= py < h:
            o = ((h - 1 - py) * w + px) * 3
            img[o:o + 3] = bytes(colour)

    def pixel(x, y):
        return int((x - x0) / a.metres_per_pixel), int((y - y0) / a.metres_per_pixel)

    for split, regions in plan["city"]["regions"].items():
        for i0, j0, i1, j1 in regions:
            ax, ay = pixel(i0 * BLOCK - SIDEWALK, j0 * BLOCK - SIDEWALK)
            bx, by = pixel(i1 * BLOCK + SIDEWALK, j1 * BLOCK + SIDEWALK)
            for py in range(ay, by + 1):
                for px in range(ax, bx + 1):
                    put(px, py, COLOURS[split][0])
    grid = (175, 175, 175)
    for i in range(size_i):
        for y in range(h):
            put(pixel(i * BLOCK, 0)[0], y, grid)
    for j in range(size_j):
        for x in range(w):
            put(x, pixel(0, j * BLOCK)[1], grid)
    for seq in plan["sequences"]:
        colour = COLOURS[seq["split"]][1]
        for x, y in route_points(a.world, plan, seq):
            px, py = pixel(x, y)
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    put(px + dx, py + dy, colour)
    write_png(a.out, w, h, img)
    print("plan_map: %d routes of %s -> %s (%dx%d, %.1f m a pixel)" %
          (len(plan["sequences"]), a.plan, a.out, w, h, a.metres_per_pixel))


if __name__ == "__main__":
    main()
