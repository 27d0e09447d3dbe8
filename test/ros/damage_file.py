#!/usr/bin/env python3
"""Writes a copy of a file with 64 bytes in its middle inverted: a damaged chunk for the readers' tests.

Usage: damage_file.py IN OUT
"""
import sys

if len(sys.argv) != 3:
    sys.exit(__doc__)
data = bytearray(open(sys.argv[1], "rb").read())
middle = len(data) // 2
data[middle:middle + 64] = bytes(b ^ 0xFF for b in data[middle:middle + 64])
open(sys.argv[2], "wb").write(data)
