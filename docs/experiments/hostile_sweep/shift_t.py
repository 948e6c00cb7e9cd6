#!/usr/bin/env python3
"""shift_t.py CK NEW_T: replace every f64 equal to the checkpoint's t in broker.bin by NEW_T, set the manifest's t,
rewrite size and CRC (a checkpoint whose broker thinks it is at another time than the nodes' states)."""
import json, struct, sys, zlib, os
ck, new = sys.argv[1], float(sys.argv[2])
m = json.load(open(os.path.join(ck, "checkpoint.json")))
b = open(os.path.join(ck, "broker.bin"), "rb").read()
old = struct.pack("<d", m["t"])
print("occurrences", b.count(old), file=sys.stderr)
b = b.replace(old, struct.pack("<d", new))
open(os.path.join(ck, "broker.bin"), "wb").write(b)
m["t"] = new
m["files"]["broker.bin"] = {"bytes": len(b), "crc32": "%08x" % (zlib.crc32(b) & 0xffffffff)}
json.dump(m, open(os.path.join(ck, "checkpoint.json"), "w"))
