#!/usr/bin/env python3
# listing_seed.py LISTING > SEED: packs a listing of pieces (.pvtu, .vtm, .pvtk) and the files it
# names into one input of the "listing" fuzz target (tests/fuzz/harness.h): a byte for the
# extension, then [u16 name length][name][u32 length][bytes] records, the listing first.
import os
import re
import struct
import sys

path = sys.argv[1]
folder = os.path.dirname(path)
listing = open(path, "rb").read()
kind = {".pvtu": 0, ".vtm": 1, ".pvtk": 2}[os.path.splitext(path)[1]]
out = bytearray([kind])


def record(name, data):
    out.extend(struct.pack("<H", len(name)) + name + struct.pack("<I", len(data)) + data)


record(os.path.basename(path).encode(), listing)
for name in re.findall(rb'(?:Source|file|fileName)="([^"]+)"', listing):
    record(name, open(os.path.join(folder, name.decode()), "rb").read())
sys.stdout.buffer.write(bytes(out))
