#!/usr/bin/env python3
"""Runs the training formats' reference code on the files write_training_format_cases wrote and
writes what it read and scored as the fixture test_training_formats checks the writers against.

Usage: training_formats_reference.py CASES_DIR OUT_DIR --cityscapes CHECKOUT --cocoapi PYTHONAPI
                                     --kitti-devkit DIR

CASES_DIR: what `write_training_format_cases CASES_DIR` wrote. OUT_DIR gets one text file per
format (test/dataset/data/training_formats): lines of space-separated fields,
  file NAME MODE HEIGHTxWIDTHxCHANNELS SHA256   what the reference's reader gave for a file: the
      reader's mode or dtype, the array's shape, the SHA-256 of its values as little-endian int32,
      row-major, channels interleaved in the reader's order;
  rle NAME COUNTS AREA X,Y,W,H                  the reference's own encoding of a decoded mask;
  score NAME VALUE                              a score of the reference's evaluation (repr).

--cityscapes: a checkout of github.com/mcordts/cityscapesScripts (not part of this package; fetch it
yourself). Its images are read as its evaluation reads them (PIL's Image.open, numpy.array); its
evalPixelLevelSemanticLabeling and evalInstanceLevelSemanticLabeling score the ground truth as
predictions of itself (every prediction file made from the ground-truth files alone), with its own
label table and settings. Needs Debian's python3-numpy and python3-pil (run it with
/usr/bin/python3); pyquaternion, which the reference's helpers import for 3D boxes only, is stubbed
when it is absent.

--cocoapi: the PythonAPI folder of github.com/cocodataset/cocoapi with pycocotools' extension built
(`python3 setup.py build_ext --inplace` there: Debian's cython3, python3-dev, and python3-matplotlib,
which coco.py imports). Each annotation of coco/instances.json and instances_amodal.json is decoded
by COCO.annToMask and encoded again by mask.encode (column-major); COCOeval scores the annotations
as detections of themselves (score 1), segm and bbox.

--kitti-devkit: a folder with KITTI's io_flow.h (flow 2012/2015 devkit, cpp/), io_depth.h (depth
completion devkit, cpp/) and the log_colormap.h they include; a small reader is compiled against them
(g++, Debian's libpng++-dev) and reads each flow and depth PNG with their FlowImage and DepthImage.
"""
import argparse
import glob
import hashlib
import os
import subprocess
import sys
import tempfile

import numpy as np
from PIL import Image

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cityscapes_parity import evaluate_instances, stub_pyquaternion  # noqa: E402  (as the parity check)


def values_line(name, mode, array):
    a = np.ascontiguousarray(np.asarray(array).astype("<i4"))
    shape = list(np.asarray(array).shape) + [1] * (3 - np.asarray(array).ndim)
    return "file {} {} {} {}".format(name, mode, "x".join(str(s) for s in shape), hashlib.sha256(a.tobytes()).hexdigest())


def cityscapes(checkout, cases, out):
    sys.path.insert(0, os.path.abspath(checkout))
    stub_pyquaternion()
    from cityscapesscripts.evaluation import evalInstanceLevelSemanticLabeling as instance
    from cityscapesscripts.evaluation import evalPixelLevelSemanticLabeling as pixel

    root = os.path.join(cases, "cityscapes", "gtFine")
    lines = []
    files = sorted(glob.glob(os.path.join(root, "*", "*", "*_gtFine_*.png")))
    if not files:
        sys.exit("{}: no gtFine files".format(root))
    for path in files:
        image = Image.open(path)
        lines.append(values_line(os.path.relpath(path, root), image.mode, np.array(image)))

    label_files = [f for f in files if f.endswith("_gtFine_labelIds.png")]
    instance_files = [f for f in files if f.endswith("_gtFine_instanceIds.png")]
    with tempfile.TemporaryDirectory() as work:
        # Perfect predictions: the labelIds files themselves, and one mask per ground-truth instance.
        pixel.args.evalInstLevelScore = True
        pixel.args.JSONOutput = False
        pixel.args.quiet = True
        semantic = pixel.evaluateImgLists(label_files, label_files, pixel.args)
        lists = []
        for path in instance_files:
            ids = np.array(Image.open(path))
            stem = os.path.basename(path)[:-len("_gtFine_instanceIds.png")]
            txt = os.path.join(work, stem + ".txt")
            with open(txt, "w") as f:
                for k, i in enumerate(np.unique(ids[ids >= 1000])):
                    mask = stem + "_{}.png".format(k)
                    Image.fromarray(((ids == i) * 255).astype(np.uint8)).save(os.path.join(work, mask))
                    f.write("{} {} 1.0\n".format(mask, int(i) // 1000))
            lists.append(txt)
        averages = evaluate_instances(instance, lists, instance_files, work, work)
    lines.append("score pixel_averageScoreClasses {!r}".format(float(semantic["averageScoreClasses"])))
    lines.append("score pixel_averageScoreInstClasses {!r}".format(float(semantic["averageScoreInstClasses"])))
    for name, value in sorted(semantic["classScores"].items()):
        if not np.isnan(value):
            lines.append("score pixel_iou_{} {!r}".format(name.replace(" ", "_"), float(value)))
    lines.append("score instance_allAp {!r}".format(float(averages["allAp"])))
    lines.append("score instance_allAp50 {!r}".format(float(averages["allAp50%"])))
    for name, value in sorted(averages["classes"].items()):
        if not np.isnan(value["ap"]):
            lines.append("score instance_ap_{} {!r}".format(name.replace(" ", "_"), float(value["ap"])))
    write(out, "cityscapes.txt", "cityscapesScripts (evaluation/evalPixelLevelSemanticLabeling.py, "
          "evalInstanceLevelSemanticLabeling.py)", lines)


def coco(api, cases, out):
    """Per annotation: the mask pycocotools decodes from the file, its own encoding of that mask,
    toBbox and area; COCOeval (segm and bbox) of the annotations as detections of themselves."""
    sys.path.insert(0, os.path.abspath(api))
    if not hasattr(np, "float"):
        np.float = float  # cocoapi's cocoeval.py uses numpy's alias, gone since numpy 1.24
    from pycocotools import mask as mask_utils
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    lines = []
    for name in ("instances.json", "instances_amodal.json"):
        gt = COCO(os.path.join(cases, "coco", name))
        for ann_id in sorted(gt.getAnnIds()):
            ann = gt.loadAnns(ann_id)[0]
            decoded = gt.annToMask(ann)
            again = mask_utils.encode(np.asfortranarray(decoded))
            lines.append("file {}:{} mask {}x{}x1 {}".format(name, ann_id, decoded.shape[0], decoded.shape[1],
                                                           values_line("", "", decoded).split()[-1]))
            lines.append("rle {}:{} {} {} {}".format(name, ann_id, again["counts"].decode(),
                                                     int(mask_utils.area(again)),
                                                     ",".join(str(int(v)) for v in mask_utils.toBbox(again))))
        for iou_type in ("segm", "bbox"):
            detections = [dict(ann, score=1.0) for ann in gt.loadAnns(gt.getAnnIds())]
            for d in detections:
                d.pop("area")  # loadRes computes it from the mask or box
                if iou_type == "bbox":
                    d.pop("segmentation")
            evaluation = COCOeval(gt, gt.loadRes(detections), iou_type)
            evaluation.evaluate()
            evaluation.accumulate()
            evaluation.summarize()
            lines.append("score {}_{}_AP {!r}".format(name[:-5], iou_type, float(evaluation.stats[0])))
            lines.append("score {}_{}_AP50 {!r}".format(name[:-5], iou_type, float(evaluation.stats[1])))
    write(out, "coco.txt", "the COCO API (PythonAPI pycocotools: coco.COCO, mask, cocoeval.COCOeval)", lines)


# Reads KITTI PNGs with the devkits' own classes and prints their values, one pixel a line.
KITTI_HARNESS = r"""
#include <algorithm>
#include <cmath>
#include "io_flow.h"
#include "io_depth.h"
#include <cstdio>
#include <string>
int main(int argc, char** argv) {
  for (int i = 2; i < argc; ++i) {
    if (std::string(argv[1]) == "flow") {
      FlowImage f(argv[i]);
      std::printf("%s %d %d\n", argv[i], f.height(), f.width());
      for (int v = 0; v < f.height(); ++v)
        for (int u = 0; u < f.width(); ++u)
          std::printf("%.9g %.9g %d\n", f.getFlowU(u, v), f.getFlowV(u, v), f.isValid(u, v) ? 1 : 0);
    } else {
      DepthImage d(argv[i]);
      std::printf("%s %d %d\n", argv[i], d.height(), d.width());
      for (int v = 0; v < d.height(); ++v)
        for (int u = 0; u < d.width(); ++u) std::printf("%.9g\n", d.getDepth(u, v));
    }
  }
  return 0;
}
"""


def kitti(devkit, cases, out):
    """Each flow PNG read by the flow devkit's FlowImage (io_flow.h), each depth PNG by the depth
    devkit's DepthImage (io_depth.h): their values as float32 (flow: u, v, valid a pixel)."""
    lines = []
    with tempfile.TemporaryDirectory() as work:
        source = os.path.join(work, "read_kitti.cpp")
        with open(source, "w") as f:
            f.write(KITTI_HARNESS)
        binary = os.path.join(work, "read_kitti")
        subprocess.run(["g++", "-O0", "-w",  # -O0: io_depth.h's setInvalid returns no value (undefined at -O1)
                        "-I", devkit, source, "-o", binary, "-lpng"], check=True)
        for kind, pattern, channels in (("flow", "flow/*.png", 3), ("depth", "depth/*.png", 1)):
            files = sorted(glob.glob(os.path.join(cases, "kitti", pattern)))
            if not files:
                sys.exit("{}: no KITTI {} files".format(cases, kind))
            text = subprocess.run([binary, kind] + files, check=True, capture_output=True, text=True).stdout.split("\n")
            at = 0
            for path in files:
                name, height, width = text[at].split()
                at += 1
                values = np.array([[float(v) for v in line.split()] for line in text[at:at + int(height) * int(width)]],
                                  dtype="<f4")
                at += int(height) * int(width)
                lines.append("file {} devkit {}x{}x{} {}".format(os.path.relpath(path, os.path.join(cases, "kitti")),
                                                                 height, width, channels,
                                                                 hashlib.sha256(values.tobytes()).hexdigest()))
                valid = values[:, 2] > 0.5 if kind == "flow" else values[:, 0] >= 0
                lines.append("score {}_valid_pixels {}".format(os.path.relpath(path, os.path.join(cases, "kitti")),
                                                               int(valid.sum())))
    write(out, "kitti.txt", "the KITTI flow devkit's io_flow.h and the depth devkit's io_depth.h", lines)


def write(out, name, reference, lines):
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, name), "w") as f:
        f.write("# Made by scripts/training_formats_reference.sh with {}.\n".format(reference))
        f.write("\n".join(lines) + "\n")
    print("{}: {} lines".format(os.path.join(out, name), len(lines)), file=sys.stderr)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("cases")
    parser.add_argument("out")
    parser.add_argument("--cityscapes", required=True)
    parser.add_argument("--cocoapi", required=True)
    parser.add_argument("--kitti-devkit", required=True)
    a = parser.parse_args()
    if not os.path.isfile(os.path.join(a.cityscapes, "cityscapesscripts", "evaluation",
                                       "evalInstanceLevelSemanticLabeling.py")):
        sys.exit("{}: not a cityscapesScripts checkout (no cityscapesscripts/evaluation)".format(a.cityscapes))
    if not os.path.isfile(os.path.join(a.cocoapi, "pycocotools", "cocoeval.py")):
        sys.exit("{}: not the COCO API's PythonAPI folder (no pycocotools/cocoeval.py)".format(a.cocoapi))
    cityscapes(a.cityscapes, a.cases, a.out)
    coco(a.cocoapi, a.cases, a.out)
    for header in ("io_flow.h", "io_depth.h"):
        if not os.path.isfile(os.path.join(a.kitti_devkit, header)):
            sys.exit("{}: no {} (the KITTI devkits' cpp folder)".format(a.kitti_devkit, header))
    kitti(a.kitti_devkit, a.cases, a.out)


if __name__ == "__main__":
    main()
