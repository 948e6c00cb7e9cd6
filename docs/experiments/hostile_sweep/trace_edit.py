#!/usr/bin/env python3
"""Damage a cosim trace (docs/PROTOCOL.md §10): trace_edit.py SRC_DIR DST_DIR OP [ARGS]

OPs:  list | flip REC BYTE (crc kept) | flipcrc REC BYTE (crc rewritten) | cut OFFSET | len REC VALUE |
      swap REC1 REC2 | dup REC | drop REC | kind REC K | step REC S | payload_u64 REC OFF VALUE (crc rewritten) |
      setup_nodes_count VALUE (fem/mesh nodes count prefix, crc rewritten) | scene TEXTFILE (crc rewritten)
"""
import os
import shutil
import struct
import sys
import zlib

src, dst, op, *a = sys.argv[1:]
b = open(os.path.join(src, "trace.bin"), "rb").read()
head, recs, o = b[:16], [], 16
while o + 8 <= len(b):
    ln, crc = struct.unpack_from("<II", b, o)
    recs.append(bytearray(b[o + 8:o + 8 + ln]))
    o += 8 + ln


def rec_bytes(r, crc=None):
    return struct.pack("<II", len(r), zlib.crc32(bytes(r)) & 0xffffffff if crc is None else crc) + bytes(r)


out = None
if op == "list":
    for i, r in enumerate(recs):
        print(i, "kind", r[0], "node", r[1], "step", struct.unpack_from("<Q", r, 2)[0], "len", len(r))
    sys.exit(0)
elif op == "flip":
    i, k = int(a[0]), int(a[1])
    crc = zlib.crc32(bytes(recs[i])) & 0xffffffff
    recs[i][k] ^= 0x40
    out = head + b"".join(rec_bytes(r, crc if j == i else None) for j, r in enumerate(recs))
elif op == "flipcrc":
    i, k = int(a[0]), int(a[1])
    recs[i][k] ^= 0x40
elif op == "cut":
    out = b[:int(a[0])]
elif op == "len":
    i, v = int(a[0]), int(a[1])
    parts = [rec_bytes(r) for r in recs]
    parts[i] = struct.pack("<I", v) + parts[i][4:]
    out = head + b"".join(parts)
elif op == "swap":
    i, j = int(a[0]), int(a[1])
    recs[i], recs[j] = recs[j], recs[i]
elif op == "dup":
    i = int(a[0])
    recs.insert(i, bytearray(recs[i]))
elif op == "drop":
    del recs[int(a[0])]
elif op == "kind":
    recs[int(a[0])][0] = int(a[1])
elif op == "step":
    struct.pack_into("<Q", recs[int(a[0])], 2, int(a[1]))
elif op == "payload_u64":
    struct.pack_into("<Q", recs[int(a[0])], 10 + int(a[1]), int(a[2]))
elif op == "payload_u32":
    struct.pack_into("<I", recs[int(a[0])], 10 + int(a[1]), int(a[2]))
elif op == "payload_f64":
    struct.pack_into("<d", recs[int(a[0])], 10 + int(a[1]), float(a[2]))
elif op == "scene":
    r = recs[0]
    recs[0] = r[:10] + bytearray(open(a[0], "rb").read())
if out is None:
    out = head + b"".join(rec_bytes(r) for r in recs)
os.makedirs(dst, exist_ok=True)
open(os.path.join(dst, "trace.bin"), "wb").write(out)
print("wrote", dst, len(out), "bytes", file=sys.stderr)
