#!/usr/bin/env python3
"""numpy's side of test_numpy_interop: checks our .npz files with numpy, and writes .npz files
the way numpy.savez and numpy.savez_compressed do for the C++ reader to check.

  numpy_interop.py check-ours DIR WIDTH HEIGHT FILE...
      DIR/input.f32 holds the float32 flow we wrote (HEIGHT x WIDTH x (u, v), little-endian);
      each DIR/FILE must load with numpy.load as float16 'u' and 'v' arrays of shape
      (HEIGHT, WIDTH) equal, bit for bit (any NaN for NaN), to input.astype(numpy.float16).
  numpy_interop.py write-numpy DIR
      writes DIR/<name>.npz and DIR/<name>.expected.f32 (the values as float32, interleaved
      u, v) for several variants, and DIR/manifest.txt with lines "<name> WIDTH HEIGHT".
  numpy_interop.py check-png DIR NAME...
      each DIR/NAME.png must decode with PIL (an independent PNG decoder, which checks every chunk's
      CRC) to the pixels in DIR/NAME.raw (row-major bytes) in mode DIR/NAME.mode (RGB, L or P),
      and a P image's palette must be DIR/NAME.palette (768 bytes).
Exit code 0 when everything matched; numpy missing is an error, not a skip.
"""
import sys

import numpy as np


def same_bits(expected, got):
    """Bitwise equality of two float16 arrays, where any NaN equals any NaN of the same sign."""
    e = expected.view(np.uint16)
    g = got.view(np.uint16)
    both_nan = np.isnan(expected) & np.isnan(got) & (np.signbit(expected) == np.signbit(got))
    bad = ~((e == g) | both_nan)
    return int(bad.sum()), np.argwhere(bad)[:5].tolist()


def check_ours(folder, width, height, files):
    flow = np.fromfile(folder + "/input.f32", dtype="<f4").reshape(height, width, 2)
    failures = 0
    for name in files:
        with np.load(folder + "/" + name) as npz:
            if sorted(npz.files) != ["u", "v"]:
                print(f"{name}: entries {npz.files}, expected u and v")
                failures += 1
                continue
            for key, channel in (("u", 0), ("v", 1)):
                got = npz[key]
                if got.dtype != np.float16 or got.shape != (height, width) or not got.flags.c_contiguous:
                    print(f"{name}:{key}: dtype {got.dtype} shape {got.shape}, expected float16 {(height, width)}")
                    failures += 1
                    continue
                expected = np.ascontiguousarray(flow[:, :, channel]).astype(np.float16)
                bad, where = same_bits(expected, got)
                if bad:
                    print(f"{name}:{key}: {bad} values differ from numpy's float16 conversion, e.g. at {where}")
                    failures += 1
                else:
                    print(f"{name}:{key}: {got.size} values equal numpy's astype(float16)")
    return failures


def write_numpy(folder):
    rng = np.random.default_rng(20170101)
    height, width = 19, 31
    u32 = rng.normal(0.0, 40.0, (height, width)).astype(np.float32)
    v32 = rng.uniform(-3000.0, 3000.0, (height, width)).astype(np.float32)
    specials = [np.nan, np.inf, -np.inf, 2.0**-24, -(2.0**-24), 1023 * 2.0**-24, 65504.0, -65504.0, -0.0, 0.1]
    for i, s in enumerate(specials):
        u32[i, 2 * i] = s
        v32[height - 1 - i, i] = s
    u16, v16 = u32.astype(np.float16), v32.astype(np.float16)
    variants = {
        "savez_f2": (np.savez, u16, v16),
        "savez_compressed_f2": (np.savez_compressed, u16, v16),
        "savez_compressed_f4_fortran": (np.savez_compressed, np.asfortranarray(u32), np.asfortranarray(v32)),
        "savez_f2_fortran": (np.savez, np.asfortranarray(u16), np.asfortranarray(v16)),
        "savez_f2_bigendian": (np.savez, u16.astype(">f2"), v16.astype(">f2")),
        "savez_f4": (np.savez, u32, v32),
    }
    with open(folder + "/manifest.txt", "w") as manifest:
        for name, (save, u, v) in variants.items():
            save(folder + "/" + name + ".npz", u=u, v=v)
            expected = np.stack([u.astype(np.float32), v.astype(np.float32)], axis=-1)
            np.ascontiguousarray(expected).astype("<f4").tofile(folder + "/" + name + ".expected.f32")
            manifest.write(f"{name} {width} {height}\n")
    print(f"numpy {np.__version__}: wrote {len(variants)} npz variants")
    return 0


def check_png(folder, names):
    from PIL import Image

    failures = 0
    for name in names:
        base = folder + "/" + name
        mode = open(base + ".mode").read().strip()
        with Image.open(base + ".png") as image:
            image.load()
            if image.mode != mode:
                print(f"{name}.png: PIL mode {image.mode}, expected {mode}")
                failures += 1
                continue
            if image.tobytes() != open(base + ".raw", "rb").read():
                print(f"{name}.png: PIL's pixels differ from ours")
                failures += 1
                continue
            if mode == "P" and bytes(image.getpalette()[:768]) != open(base + ".palette", "rb").read():
                print(f"{name}.png: PIL's palette differs from ours")
                failures += 1
                continue
            print(f"{name}.png: {image.size[0]}x{image.size[1]} {mode} equal in PIL")
    return failures


def main(argv):
    if len(argv) >= 5 and argv[1] == "check-ours":
        return 1 if check_ours(argv[2], int(argv[3]), int(argv[4]), argv[5:]) else 0
    if len(argv) >= 4 and argv[1] == "check-png":
        return 1 if check_png(argv[2], argv[3:]) else 0
    if len(argv) == 3 and argv[1] == "write-numpy":
        return write_numpy(argv[2])
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
