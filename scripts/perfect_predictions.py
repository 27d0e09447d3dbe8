#!/usr/bin/env python3
"""Turns a ground-truth bag into a bag that feeds evaluate every metric: a perfect perception.

Usage: perfect_predictions.py GT_BAG OUT_BAG
GT_BAG is what replay.launch's record:= writes. OUT_BAG holds what evaluate subscribes to, each
message at its header stamp (so `rosbag play` plays it at the capture's rate, whatever speed the
ground truth was recorded at):
  - the ground truth: /capture/draws, /ground_truth/{semantic, instance_ids, flow/forward,
    flow/forward_visible, odom}, copied;
  - the predictions, separate messages of the same bytes or made from them:
    /perception/semantic (the semantic image), /perception/flow (forward flow), /perception/odom
    (the odometry), /perception/instances (viper/InstancePredictionArray: one mask per instance id,
    cropped to its box, of its majority class, score 1), /perception/flow_sparse
    (opencv_apps/FlowArrayStamped: the forward flow at every 8th pixel of every 8th row, stamped
    with the next frame and placed in the first, as opencv_apps' fback_flow publishes).
Frames missing a ground-truth topic are reported and skipped for the predictions made from it;
the exit status is then 1 (the output is still written), as it is when the ground-truth bag has no frame. Run it with Debian's /usr/bin/python3 in a sourced
workspace (viper's Python messages).
"""
import sys

import numpy as np
import rosbag
from genpy import Time
from opencv_apps.msg import Flow, FlowArrayStamped
from sensor_msgs.msg import Image
from viper.msg import InstancePrediction, InstancePredictionArray

COPIED = ["/capture/draws", "/ground_truth/semantic", "/ground_truth/instance_ids",
          "/ground_truth/flow/forward", "/ground_truth/flow/forward_visible", "/ground_truth/odom"]
RENAMED = {"/ground_truth/semantic": "/perception/semantic",
           "/ground_truth/flow/forward": "/perception/flow",
           "/ground_truth/odom": "/perception/odom"}
SPARSE_STEP = 8


def header_stamp(raw):
    """The header stamp of a raw message (every copied type starts with a std_msgs/Header:
    uint32 seq, then the stamp as uint32 secs, uint32 nsecs)."""
    secs, nsecs = np.frombuffer(raw[1], dtype="<u4", count=2, offset=4)
    return Time(int(secs), int(nsecs))


def image_array(msg, dtype, channels=1):
    a = np.frombuffer(msg.data, dtype=dtype)
    row = msg.step // np.dtype(dtype).itemsize
    a = a.reshape(msg.height, row)[:, :msg.width * channels]
    return a.reshape(msg.height, msg.width, channels) if channels > 1 else a


def instances(semantic_msg, ids_msg):
    sem = image_array(semantic_msg, np.uint8)
    ids = image_array(ids_msg, np.int32)
    out = InstancePredictionArray()
    out.header = semantic_msg.header
    ys, xs = np.nonzero(ids > 0)
    if ys.size == 0:
        return out
    labels = ids[ys, xs]
    order = np.argsort(labels, kind="stable")
    labels, ys, xs = labels[order], ys[order], xs[order]
    starts = np.flatnonzero(np.r_[True, labels[1:] != labels[:-1]])
    ends = np.r_[starts[1:], labels.size]
    for s, e in zip(starts, ends):
        y, x = ys[s:e], xs[s:e]
        classes, counts = np.unique(sem[y, x], return_counts=True)
        x0, y0, x1, y1 = int(x.min()), int(y.min()), int(x.max()) + 1, int(y.max()) + 1
        mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
        mask[y - y0, x - x0] = 255
        p = InstancePrediction()
        p.class_id = int(classes[np.argmax(counts)])
        p.score = 1.0
        p.x_offset, p.y_offset = x0, y0
        p.mask = Image(header=semantic_msg.header, height=y1 - y0, width=x1 - x0, encoding="mono8",
                       step=x1 - x0, data=mask.tobytes())
        out.instances.append(p)
    return out


def sparse(flow_msg, next_stamp):
    uv = image_array(flow_msg, np.float32, 2)
    out = FlowArrayStamped()
    out.header = flow_msg.header
    out.header.stamp = next_stamp
    grid = uv[::SPARSE_STEP, ::SPARSE_STEP]
    ys, xs = np.nonzero(np.isfinite(grid).all(axis=2))
    for y, x in zip(ys.tolist(), xs.tolist()):
        f = Flow()
        f.point.x, f.point.y = x * SPARSE_STEP, y * SPARSE_STEP
        f.velocity.x, f.velocity.y = float(grid[y, x, 0]), float(grid[y, x, 1])
        out.flow.append(f)
    return out


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    gt_path, out_path = sys.argv[1:]
    frames = {}  # stamp -> {topic: raw or decoded message}
    with rosbag.Bag(gt_path) as bag:
        for topic, raw, _ in bag.read_messages(topics=COPIED, raw=True):
            frames.setdefault(header_stamp(raw), {})[topic] = raw
    if not frames:
        sys.exit("perfect_predictions: %s has none of %s" % (gt_path, ", ".join(COPIED)))
    stamps = sorted(frames)
    missing = 0
    with rosbag.Bag(out_path, "w") as out:
        for i, stamp in enumerate(stamps):
            frame = frames[stamp]
            for topic in COPIED:
                if topic not in frame:
                    if not (topic.startswith("/ground_truth/flow/") and i == len(stamps) - 1):
                        print("perfect_predictions: %s: no %s at %d.%09d" % (gt_path, topic, stamp.secs, stamp.nsecs))
                        missing += 1
                    continue
                out.write(topic, frame[topic], stamp, raw=True)
                if topic in RENAMED:
                    out.write(RENAMED[topic], frame[topic], stamp, raw=True)
            if "/ground_truth/semantic" in frame and "/ground_truth/instance_ids" in frame:
                sem = Image().deserialize(frame["/ground_truth/semantic"][1])
                ids = Image().deserialize(frame["/ground_truth/instance_ids"][1])
                out.write("/perception/instances", instances(sem, ids), stamp)
            if "/ground_truth/flow/forward" in frame and i + 1 < len(stamps):
                flow = Image().deserialize(frame["/ground_truth/flow/forward"][1])
                out.write("/perception/flow_sparse", sparse(flow, stamps[i + 1]), stamps[i + 1])
    print("perfect_predictions: %d frames, %d missing ground-truth messages -> %s" % (len(stamps), missing, out_path))
    sys.exit(1 if missing else 0)


if __name__ == "__main__":
    main()
