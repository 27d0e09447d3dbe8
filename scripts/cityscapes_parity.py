#!/usr/bin/env python3
"""Runs cityscapesScripts' own evaluation on the parity cases and writes its scores as a table.

Usage: cityscapes_parity.py CITYSCAPES_CHECKOUT CASES_DIR OUT_CSV [--classes config/viper_classes.csv]

CITYSCAPES_CHECKOUT: a checkout of github.com/mcordts/cityscapesScripts (not part of this package;
fetch it yourself). CASES_DIR: what `write_parity_cases` writes (one folder per case: cls/, inst/,
pred_cls/, pred_inst/; committed as test/evaluation/data/cityscapes_parity). OUT_CSV gets
`case,metric,class_id,value`: metric iou per scored class and mean_iou, iiou per instance class
and mean_iiou (evalPixelLevelSemanticLabeling.evaluateImgLists: classScores, averageScoreClasses,
classInstScores, averageScoreInstClasses; its average instance sizes set to the case's, as the
package takes them from what it has seen), ap and ap50
per instance class and mean_ap, mean_ap50 (evalInstanceLevelSemanticLabeling.evaluateImgLists:
averages), values in 0..1 as repr (every digit), "nan" for NaN. test_cityscapes_parity compares
the package's scores of the same cases with it.

The reference runs unchanged, with two things set around it: its label table is replaced by
the package's class table (name, id; hasInstances = instance_eval; ignoreInEval = not
class_eval), and the ground truth is written in its formats: labelIds = the class ids, instanceIds
= class * 1000 + k for the k-th instance of the class in the frame (VIPER's instance ids are any
16-bit number), the class id where there is no instance. Needs Debian's python3-numpy and
python3-pil (run it with /usr/bin/python3); pyquaternion, which the reference's helpers import
for 3D boxes only, is stubbed when it is absent (Debian does not package it).
"""
import argparse
import csv
import importlib
import math
import os
import sys
import tempfile
import types

import numpy as np
from PIL import Image


def read_classes(path):
    """(id, name, class_eval, instance_eval) of each row of the class table."""
    with open(path, newline="") as f:
        return [(int(r["id"]), r["classname"], r["class_eval"] == "1", r["instance_eval"] == "1")
                for r in csv.DictReader(f)]


def stub_pyquaternion():
    """cityscapesScripts' helpers import pyquaternion (for 3D boxes, never used by the 2D
    evaluations); Debian has no package of it, so an absent one is replaced by a module whose
    Quaternion fails if anything calls it."""
    try:
        importlib.import_module("pyquaternion")
    except ImportError:
        module = types.ModuleType("pyquaternion")

        class Quaternion:
            def __init__(self, *args, **kwargs):
                raise RuntimeError("pyquaternion is not installed (the parity check does not use 3D boxes)")
        module.Quaternion = Quaternion
        sys.modules["pyquaternion"] = module


def install_labels(classes):
    """Replaces the label table in every module of the reference that imported it."""
    from cityscapesscripts.helpers import csHelpers, labels as cs_labels
    from cityscapesscripts.evaluation import (evalInstanceLevelSemanticLabeling, evalPixelLevelSemanticLabeling,
                                              instances2dict)
    table = [cs_labels.Label(name, cid, cid, name, cid, inst, not scored, (0, 0, 0))
             for cid, name, scored, inst in classes]
    names = {
        "labels": table,
        "name2label": {l.name: l for l in table},
        "id2label": {l.id: l for l in table},
        "trainId2label": {l.trainId: l for l in table},
        "category2labels": {l.name: [l] for l in table},
    }
    for module in (cs_labels, csHelpers, evalInstanceLevelSemanticLabeling, evalPixelLevelSemanticLabeling,
                   instances2dict):
        for key, value in names.items():
            if hasattr(module, key):
                setattr(module, key, value)
    return evalPixelLevelSemanticLabeling, evalInstanceLevelSemanticLabeling


def cityscapes_instance_ids(cls_path, inst_path):
    """The instanceIds image of one frame: class * 1000 + k per instance, the class elsewhere."""
    cls = np.array(Image.open(cls_path)).astype(np.int64)
    inst = np.array(Image.open(inst_path).convert("RGB")).astype(np.int64)
    ids = inst[..., 1] * 256 + inst[..., 2]
    out = cls.copy()
    per_class = {}
    for i in np.unique(ids[ids > 0]):
        classes = np.unique(cls[ids == i])
        if len(classes) != 1 or classes[0] == 0:
            sys.exit("{}: instance {} has classes {}: Cityscapes' format needs one class > 0 per instance"
                     .format(inst_path, i, classes.tolist()))
        c = int(classes[0])
        per_class[c] = per_class.get(c, 0) + 1
        if per_class[c] > 999:
            sys.exit("{}: more than 999 instances of class {}".format(inst_path, c))
        out[ids == i] = c * 1000 + per_class[c]
    return out.astype(np.uint16)


def evaluate_instances(instance, pred_lists, gt_instances, prediction_path, work):
    """evalInstanceLevelSemanticLabeling.evaluateImgLists' averages, its caches and matches.json in `work`."""
    instance.args.gtInstancesFile = os.path.join(work, "gtInstances.json")
    instance.args.predictionPath = prediction_path
    instance.args.JSONOutput = False
    instance.args.quiet = True
    cwd = os.getcwd()
    os.chdir(work)  # the reference writes matches.json into the current folder
    try:
        return instance.evaluateImgLists(pred_lists, gt_instances, instance.args)["averages"]
    finally:
        os.chdir(cwd)


def score_case(case_dir, work, pixel, instance, classes):
    frames = sorted(f[:-4] for f in os.listdir(os.path.join(case_dir, "cls")) if f.endswith(".png"))
    if not frames:
        sys.exit("{}: no frames in cls/".format(case_dir))
    gt_labels, gt_instances, pred_labels, pred_lists = [], [], [], []
    sizes = {}  # class id -> sizes of its instances, every frame
    for name in frames:
        labels_path = os.path.join(work, name + "_gtFine_labelIds.png")
        ids_path = os.path.join(work, name + "_gtFine_instanceIds.png")
        Image.open(os.path.join(case_dir, "cls", name + ".png")).convert("L").save(labels_path)
        ids = cityscapes_instance_ids(os.path.join(case_dir, "cls", name + ".png"),
                                      os.path.join(case_dir, "inst", name + ".png"))
        Image.fromarray(ids).save(ids_path)
        for i, size in zip(*np.unique(ids[ids > 1000], return_counts=True)):
            sizes.setdefault(int(i) // 1000, []).append(int(size))
        gt_labels.append(labels_path)
        gt_instances.append(ids_path)
        pred_labels.append(os.path.join(case_dir, "pred_cls", name + ".png"))
        pred_lists.append(os.path.abspath(os.path.join(case_dir, "pred_inst", name + ".txt")))

    # iIoU weighs an instance by the average size of its class: Cityscapes takes them from its
    # training set, the package from the instances it has seen, so the average of the case's.
    names = {cid: name for cid, name, _, _ in classes}
    pixel.args.avgClassSize = {names[c]: sum(v) / len(v) for c, v in sizes.items()}
    pixel.args.evalInstLevelScore = True
    pixel.args.JSONOutput = False
    pixel.args.quiet = True
    semantic = pixel.evaluateImgLists(pred_labels, gt_labels, pixel.args)

    averages = evaluate_instances(instance, pred_lists, gt_instances, os.path.abspath(case_dir), work)

    rows = []
    for cid, name, scored, inst in classes:
        if scored:
            rows.append(("iou", cid, semantic["classScores"][name]))
        if inst and scored:
            rows.append(("iiou", cid, semantic["classInstScores"][name]))
            rows.append(("ap", cid, averages["classes"][name]["ap"]))
            rows.append(("ap50", cid, averages["classes"][name]["ap50%"]))
    rows.append(("mean_iou", -1, semantic["averageScoreClasses"]))
    rows.append(("mean_iiou", -1, semantic["averageScoreInstClasses"]))
    rows.append(("mean_ap", -1, averages["allAp"]))
    rows.append(("mean_ap50", -1, averages["allAp50%"]))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("cityscapes")
    parser.add_argument("cases")
    parser.add_argument("out")
    parser.add_argument("--classes", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                                          "config", "viper_classes.csv"))
    a = parser.parse_args()
    if not os.path.isfile(os.path.join(a.cityscapes, "cityscapesscripts", "evaluation",
                                       "evalInstanceLevelSemanticLabeling.py")):
        sys.exit("{}: not a cityscapesScripts checkout (no cityscapesscripts/evaluation)".format(a.cityscapes))
    sys.path.insert(0, os.path.abspath(a.cityscapes))
    classes = read_classes(a.classes)
    stub_pyquaternion()
    pixel, instance = install_labels(classes)
    cases = sorted(d for d in os.listdir(a.cases) if os.path.isdir(os.path.join(a.cases, d)))
    with open(a.out, "w", newline="") as f:
        out = csv.writer(f, lineterminator="\n")
        out.writerow(["case", "metric", "class_id", "value"])
        for case in cases:
            with tempfile.TemporaryDirectory() as work:
                for metric, cid, value in score_case(os.path.join(a.cases, case), work, pixel, instance, classes):
                    value = float(value)
                    out.writerow([case, metric, cid, "nan" if math.isnan(value) else repr(value)])
            print("{}: scored".format(case), file=sys.stderr)


if __name__ == "__main__":
    main()
