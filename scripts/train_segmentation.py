#!/usr/bin/env python3
"""Trains the semantic segmentation baseline (docs/baselines.md): a small fully convolutional
network on a generated dataset in VIPER's layout (img and cls), exported to ONNX for the
semantic_baseline nodelet (OpenCV's DNN module).

The network takes an RGB image scaled to [0, 1] (N x 3 x H x W, H and W multiples of 8) and gives one
logit per training class (the `trainid` column of config/viper_classes.csv, 0..22) at every pixel
(N x 23 x H x W). Pixels of classes without a train id are ignored by the loss. Fixed seed, one
thread: the same data and the same torch give the same model. The log says what was trained on,
the loss as it went, the time, and the mean IoU on the plan's val split (a region of the city that
neither training nor the benchmark's test routes visit).

Usage: train_segmentation.py --root ROOT --plan PLAN.yaml --set all|day_sunset --out MODEL.onnx
         [--log LOG] [--steps 2000] [--batch 8] [--lr 0.002] [--seed 1]
         [--classes config/viper_classes.csv] [--width-mult 24,48,96]
Needs python3-torch (scripts/setup.sh --training).
"""
import argparse
import csv
import glob
import hashlib
import io
import os
import sys
import time

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F
import yaml
from PIL import Image

CONDITIONS = ["day", "sunset", "rain", "snow", "night"]
IGNORE = 255


def read_classes(path):
    """Class id -> train id (255: not trained on), and the number of train ids."""
    to_train = np.full(256, IGNORE, np.uint8)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["class_eval"] == "1":
                to_train[int(row["id"])] = int(row["trainid"])
    n = int(to_train[to_train != IGNORE].max()) + 1
    return to_train, n


def load_sequences(root, sequences, to_train):
    """Images (N, H, W, 3 uint8), train-id labels (N, H, W uint8) and each frame's condition."""
    images, labels, conds = [], [], []
    for s in sequences:
        split = s["split"]
        paths = sorted(glob.glob(os.path.join(root, split, "img", s["id"], "*.png")))
        if len(paths) != s["frames"]:
            raise SystemExit(f"train_segmentation: {split}/{s['id']}: {len(paths)} of {s['frames']} images "
                             f"under {root} (generate the plan first)")
        for p in paths:
            cls_path = p.replace(os.sep + "img" + os.sep, os.sep + "cls" + os.sep)
            images.append(np.asarray(Image.open(p).convert("RGB")))
            labels.append(to_train[np.asarray(Image.open(cls_path))])  # palette indices are class ids
            conds.append(s["condition"])
    if not images:
        raise SystemExit("train_segmentation: no sequences to read")
    return np.stack(images), np.stack(labels), conds


def conv_bn_relu(cin, cout, stride=1, dilation=1):
    return nn.Sequential(nn.Conv2d(cin, cout, 3, stride, padding=dilation, dilation=dilation, bias=False),
                         nn.BatchNorm2d(cout), nn.ReLU(inplace=True))


class SegmentationNet(nn.Module):
    """Encoder to 1/8 with dilated convolutions at the end (context), class scores at 1/8, 1/4 and
    1/2 summed on the way back up (FCN-8s' skips), bilinear upsampling to the input's size."""

    def __init__(self, classes, widths):
        super().__init__()
        a, b, c = widths
        self.enc2 = nn.Sequential(conv_bn_relu(3, a, 2), conv_bn_relu(a, a))
        self.enc4 = nn.Sequential(conv_bn_relu(a, b, 2), conv_bn_relu(b, b))
        self.enc8 = nn.Sequential(conv_bn_relu(b, c, 2), conv_bn_relu(c, c), conv_bn_relu(c, c, dilation=2),
                                  conv_bn_relu(c, c, dilation=4))
        self.score8, self.score4, self.score2 = nn.Conv2d(c, classes, 1), nn.Conv2d(b, classes, 1), nn.Conv2d(a, classes, 1)

    def forward(self, x):
        x2 = self.enc2(x)
        x4 = self.enc4(x2)
        x8 = self.enc8(x4)
        up = lambda t: F.interpolate(t, scale_factor=2.0, mode="bilinear", align_corners=False)
        y = up(self.score8(x8)) + self.score4(x4)
        y = up(y) + self.score2(x2)
        return up(y)


def batches(n, batch, steps, rng):
    """Indices of each step's batch: epochs of a shuffled order, as many as the steps need."""
    order = []
    while len(order) < steps * batch:
        order.extend(rng.permutation(n).tolist())
    return [order[i * batch:(i + 1) * batch] for i in range(steps)]


def to_tensor(images):
    return torch.from_numpy(images).permute(0, 3, 1, 2).float().div_(255.0)


def confusion(net, images, labels, classes, chunk=16):
    conf = np.zeros((classes, classes), np.int64)
    with torch.no_grad():
        for i in range(0, len(images), chunk):
            pred = net(to_tensor(images[i:i + chunk])).argmax(1).numpy()
            gt = labels[i:i + chunk]
            keep = gt != IGNORE
            conf += np.bincount(gt[keep].astype(np.int64) * classes + pred[keep],
                                minlength=classes * classes).reshape(classes, classes)
    return conf


def mean_iou(conf):
    tp = np.diag(conf).astype(float)
    denom = conf.sum(0) + conf.sum(1) - tp
    iou = tp[denom > 0] / denom[denom > 0]
    return 100.0 * iou.mean() if len(iou) else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", required=True, help="generated dataset (VIPER layout)")
    ap.add_argument("--plan", required=True, help="its plan (which sequence has which condition)")
    ap.add_argument("--set", required=True, help="a training set of the plan's training_sets (all, day_sunset)")
    ap.add_argument("--out", required=True, help="ONNX model to write")
    ap.add_argument("--log", help="log file (default: OUT with .log)")
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--lr", type=float, default=0.002)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--classes", default=os.path.join(os.path.dirname(__file__), "..", "config", "viper_classes.csv"))
    ap.add_argument("--width-mult", default="24,48,96", help="channels at 1/2, 1/4 and 1/8 of the input")
    args = ap.parse_args()
    log_path = args.log or os.path.splitext(args.out)[0] + ".log"
    log_file = open(log_path, "w")

    def log(text):
        print(text)
        log_file.write(text + "\n")
        log_file.flush()

    torch.set_num_threads(1)
    torch.manual_seed(args.seed)
    torch.use_deterministic_algorithms(True)
    rng = np.random.RandomState(args.seed)
    with open(args.plan) as f:
        plan = yaml.safe_load(f)
    to_train, classes = read_classes(args.classes)
    started = time.time()
    sets = plan.get("training_sets", {})
    if args.set not in sets:
        raise SystemExit(f"train_segmentation: {args.plan} has no training set '{args.set}' "
                         f"(its sets: {', '.join(sets) or 'none; write the plan with segmentation_plan.py'})")
    ids = set(sets[args.set])
    images, labels, conds = load_sequences(
        args.root, [s for s in plan["sequences"] if s["split"] == "train" and s["id"] in ids], to_train)
    val_images, val_labels, val_conds = load_sequences(
        args.root, [s for s in plan["sequences"] if s["split"] == "val"], to_train)
    conditions = [c for c in CONDITIONS if c in conds]
    h, w = images.shape[1:3]
    if h % 8 or w % 8:
        raise SystemExit(f"train_segmentation: frames are {w}x{h}; the network needs multiples of 8")
    log(f"train_segmentation: {' '.join(sys.argv[1:])}")
    log(f"torch {torch.__version__}, 1 thread, seed {args.seed}")
    log(f"train: set {args.set}, {len(images)} frames {w}x{h} "
        f"({', '.join(f'{c} {conds.count(c)}' for c in conditions)}); val: {len(val_images)} frames")

    counts = np.bincount(labels[labels != IGNORE].ravel(), minlength=classes).astype(float)
    freq = counts / counts.sum()
    # ENet's weighting, milder (1.10 instead of 1.02): rare classes (people, traffic lights) count up
    # to ~10x, without drowning the frequent ones.
    weights = torch.tensor(1.0 / np.log(1.10 + freq), dtype=torch.float32)
    log("class pixel shares % (train id order): " + " ".join(f"{100 * f:.2f}" for f in freq))

    widths = tuple(int(v) for v in args.width_mult.split(","))
    net = SegmentationNet(classes, widths)
    log(f"network: widths {widths}, {sum(p.numel() for p in net.parameters()):,} parameters")
    opt = torch.optim.Adam(net.parameters(), lr=args.lr)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=args.lr, total_steps=args.steps, pct_start=0.1)
    net.train()
    running, tick = 0.0, time.time()
    for step, idx in enumerate(batches(len(images), args.batch, args.steps, rng), 1):
        x, y = images[idx], labels[idx]
        flip = rng.rand(len(idx)) < 0.5
        x = np.where(flip[:, None, None, None], x[:, :, ::-1], x)
        y = np.where(flip[:, None, None], y[:, :, ::-1], y)
        loss = F.cross_entropy(net(to_tensor(np.ascontiguousarray(x))), torch.from_numpy(y.astype(np.int64)),
                               weight=weights, ignore_index=IGNORE)
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
        running += loss.item()
        if step % 100 == 0 or step == args.steps:
            n = 100 if step % 100 == 0 else step % 100
            log(f"step {step}/{args.steps}: loss {running / n:.4f}, {(time.time() - tick) / n:.2f} s a step")
            running, tick = 0.0, time.time()

    net.eval()
    log(f"trained in {time.time() - started:.0f} s")
    per_condition = []
    for c in CONDITIONS:
        pick = [k for k, v in enumerate(val_conds) if v == c]
        per_condition.append(f"{c} {mean_iou(confusion(net, val_images[pick], val_labels[pick], classes)):.1f}")
    log("val mean IoU % (train ids, at the network's resolution): " + ", ".join(per_condition) +
        f", all {mean_iou(confusion(net, val_images, val_labels, classes)):.1f}")

    buffer = io.BytesIO()
    torch.onnx.export(net, torch.zeros(1, 3, h, w), buffer, opset_version=11, input_names=["image"],
                      output_names=["scores"], do_constant_folding=True)
    with open(args.out, "wb") as f:
        f.write(buffer.getvalue())
    log(f"wrote {args.out}: {len(buffer.getvalue()):,} bytes, sha256 {hashlib.sha256(buffer.getvalue()).hexdigest()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
