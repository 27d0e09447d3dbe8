#!/usr/bin/env bash
# Runs the VIPER devkit's own submission checks (prepare_submission.py: check_cls_submission,
# check_inst_submission, check_flow_submission, the parts that need none of its encoder binaries)
# on a folder written by viper_submission, then checks what the devkit's script leaves to its
# EVALUATION.md: cls PNGs and instance masks single-channel, .flo files with Middlebury's tag and a
# size that matches their header, odometry lines of 8 numbers with unit quaternions.
#
# Usage: scripts/viper_submission_check.sh DEVKIT_CHECKOUT SUBMISSION [GT_SPLIT_DIR]
# DEVKIT_CHECKOUT: a checkout of github.com/srrichter/viper (not part of this package; its
#   prepare_submission.py and testframes/ are read, nothing of it is copied here).
# SUBMISSION: the --out folder of viper_submission (cls/, inst/, flow/, odometry/).
# GT_SPLIT_DIR: a split of the ground truth in VIPER's layout (e.g. ROOT/test of generate): the
#   frames the submission must cover are taken from its img/ files (flow: every frame whose next
#   frame exists) instead of the devkit's testframes/ lists, which name VIPER's own test set.
# Exit 0 if every check passes, 1 otherwise, 2 on usage errors. Needs Debian's python3 (3.6+),
# python3-pil and python3-numpy.
set -euo pipefail
if [ $# -lt 2 ] || [ $# -gt 3 ]; then echo "usage: $0 DEVKIT_CHECKOUT SUBMISSION [GT_SPLIT_DIR]" >&2; exit 2; fi
checkout=$(cd "$1" && pwd) submission=$(cd "$2" && pwd) gt=${3:+$(cd "$3" && pwd)}
[ -f "$checkout/prepare_submission.py" ] || { echo "$0: $checkout has no prepare_submission.py" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/testframes"
# prepare_submission.py reads ./testframes/<task>_frames.txt from the folder it runs in.
if [ -n "$gt" ]; then
  /usr/bin/python3 - "$gt" "$work/testframes" <<'EOF'
import pathlib, sys
gt, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
frames = sorted({p.stem for p in (gt / 'img').glob('*/*_*.*')})
if not frames:
    sys.exit(f'{gt}/img holds no frame images')
names = set(frames)
following = [f for f in frames if '%s_%05d' % (f[:3], int(f[4:]) + 1) in names]
(out / 'cls_frames.txt').write_text(''.join(f + '\n' for f in frames))
(out / 'inst_frames.txt').write_text(''.join(f + '\n' for f in frames))
(out / 'flow_frames.txt').write_text(''.join(f + '\n' for f in following))
print(f'frames from {gt}/img: {len(frames)} (cls, inst), {len(following)} with a next frame (flow)')
EOF
else
  cp "$checkout"/testframes/*_frames.txt "$work/testframes/"
fi
cd "$work"
/usr/bin/python3 - "$checkout" "$submission" <<'EOF'
import pathlib, struct, sys
import numpy
from PIL import Image
sys.path.insert(0, sys.argv[1])
import prepare_submission as devkit
sub = pathlib.Path(sys.argv[2])
ok = True
print('== devkit: check_cls_submission(%s)' % (sub / 'cls'))
ok &= bool(devkit.check_cls_submission(sub / 'cls'))
print('== devkit: check_inst_submission(%s)' % (sub / 'inst'))
ready, frames = devkit.check_inst_submission(sub / 'inst')
ok &= bool(ready)
if ready:
    print('\t%d instance masks listed over %d frames' % (sum(len(v) for v in frames.values()), len(frames)))
print('== devkit: check_flow_submission(%s)' % (sub / 'flow'))
ok &= bool(devkit.check_flow_submission(sub / 'flow'))

def report(what, bad, total):
    global ok
    print('== %s: %d files, %s' % (what, total, 'Ok' if not bad else '%d bad' % len(bad)))
    for b in bad[:10]:
        print('\t' + b)
    ok &= not bad

pngs = sorted((sub / 'cls').glob('*.png')) + sorted((sub / 'inst').glob('*.png'))
bad = []
for p in pngs:
    with Image.open(p) as im:
        if im.mode not in ('L', 'P'):
            bad.append('%s: mode %s, not a single channel' % (p, im.mode))
report('PNGs single-channel (EVALUATION.md)', bad, len(pngs))
flos = sorted((sub / 'flow').glob('*.flo'))
bad = []
for p in flos:
    data = p.read_bytes()
    tag, w, h = struct.unpack('<fii', data[:12])
    if tag != 202021.25 or len(data) != 12 + 8 * w * h:
        bad.append('%s: tag %r, %dx%d, %d bytes' % (p, tag, w, h, len(data)))
report('.flo Middlebury header and size', bad, len(flos))
txts = sorted((sub / 'odometry').glob('*.txt'))
bad = []
for p in txts:
    rows = numpy.atleast_2d(numpy.loadtxt(p, delimiter=','))
    if rows.shape[1] != 8 or not numpy.allclose(numpy.linalg.norm(rows[:, 4:8], axis=1), 1, atol=1e-6):
        bad.append('%s: %s values a line, or quaternions off unit length' % (p, rows.shape[1]))
    elif (numpy.diff(rows[:, 0]) <= 0).any():
        bad.append('%s: timestamps not increasing' % p)
report('odometry timestamp,tx,ty,tz,qx,qy,qz,qw', bad, len(txts))
print('all checks passed' if ok else 'some checks failed')
sys.exit(0 if ok else 1)
EOF
