#!/usr/bin/env python3
"""A hostile / buggy external structure node, derived from examples/python/rigid_plate_node.py.

    hostile_fem.py --from OUT/external.json --mode MODE [--at STEP]

MODE selects one misbehaviour (see MODES below); --at the coupling step it starts at (default 5).
"""
import argparse
import json
import math
import os
import queue
import struct
import sys
import time
import tomllib

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "examples", "python"))
import zenoh  # noqa: E402
from rigid_plate_node import (RigidPlate, header, read_command, u32s, vec2s, f64s)  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("--from", dest="from_file", required=True)
ap.add_argument("--mode", default="none")
ap.add_argument("--at", type=int, default=5)
ap.add_argument("--timeout", type=float, default=60.0)
args = ap.parse_args()
MODE, AT = args.mode, args.at


def log(*a):
    print("hostile_fem:", *a, file=sys.stderr, flush=True)


deadline = time.monotonic() + 30
while True:
    try:
        info = json.load(open(args.from_file))
        break
    except (OSError, ValueError):
        if time.monotonic() > deadline:
            sys.exit("no external.json")
        time.sleep(0.05)
RUN, CONNECT = info["run"], info["connect"]
conf = zenoh.Config.from_json5(json.dumps({
    "mode": "peer", "scouting": {"multicast": {"enabled": False}},
    "connect": {"endpoints": [CONNECT], "timeout_ms": 5000, "exit_on_failure": True},
    "listen": {"endpoints": []}}))
session = zenoh.open(conf)
base = f"cosim/{RUN}"
BLOCK = zenoh.CongestionControl.BLOCK
inbox = queue.Queue()
sub = session.declare_subscriber(f"{base}/broker/fem", lambda s: inbox.put(("cmd", s.payload.to_bytes())))
alive_sub = session.liveliness().declare_subscriber(f"{base}/broker/alive",
                                                    lambda s: inbox.put(("broker", s.kind)), history=True)
token = session.liveliness().declare_token(f"{base}/fem/alive")
pub_state = session.declare_publisher(f"{base}/fem/state", congestion_control=BLOCK)

scene_text = None
end = time.monotonic() + 5
while scene_text is None and time.monotonic() < end:
    for reply in session.get(f"{base}/scene", timeout=1.0):
        if reply.ok is not None:
            scene_text = reply.ok.payload.to_bytes().decode()
    if scene_text is None:
        time.sleep(0.2)
scene = tomllib.loads(scene_text)
plate = RigidPlate(scene, 3.0e8, 0.1)

# ---- the registration, spoilt as MODE asks ----------------------------------------------------------------------
names = [plate.name]
nodes = list(plate.ref)
masses = list(plate.masses)
node_solid = [0] * len(nodes)
cells = [list(c) for c in plate.cells]
cell_solid = [0] * len(cells)
segments = list(plate.segments)
fixed = []
dt_stable = plate.h

if MODE == "mesh_zero_len":          # two interface nodes at the same place (segment of length 0)
    a, b = segments[3]
    nodes[b] = nodes[a]
elif MODE == "mesh_all_same":        # every node at one point
    nodes = [nodes[0]] * len(nodes)
elif MODE == "mesh_crossing":        # swap two node positions: crossing segments, inverted cells
    nodes[1], nodes[len(nodes) - 2] = nodes[len(nodes) - 2], nodes[1]
elif MODE == "mass_tiny":
    masses = [1e-300] * len(masses)
elif MODE == "mass_huge":
    masses = [1e300] * len(masses)
elif MODE == "mesh_far":             # finite but astronomically far apart
    nodes[0] = (-1e308, -1e308)
    nodes[-1] = (1e308, 1e308)
elif MODE == "mesh_1e6":             # the plate 1e6 m long (reference)
    nodes = [(x * 1e6, y) for x, y in nodes]
elif MODE == "mesh_no_interface":
    segments = []
elif MODE == "mesh_one_segment":
    segments = segments[:1]
elif MODE == "mesh_names_wrong":     # a solid of another name than the scene's
    names = ["not_the_plate"]
elif MODE == "mesh_two_solids":
    names = [plate.name, "extra"]
elif MODE == "mesh_plate_empty":     # the scene's solid has no node: all nodes belong to a second solid
    names = [plate.name, "extra"]
    node_solid = [1] * len(nodes)
    cell_solid = [1] * len(cells)
elif MODE == "mesh_dup_segments":
    segments = segments + segments
elif MODE == "mesh_reversed":        # clockwise boundary: normals point into the structure
    segments = [(b, a) for a, b in segments]
elif MODE == "mesh_all_fixed":
    fixed = list(range(len(nodes)))
elif MODE == "mesh_dup_fixed":
    fixed = [0] * 100000
elif MODE == "mesh_dt_tiny":
    dt_stable = 1e-300
elif MODE == "mesh_degenerate_cells":
    cells = [[0, 0, 0, 0] for _ in cells]
elif MODE == "mesh_huge":            # many nodes: N given by --at
    n = AT
    nodes = [(i * 1e-3, -0.025) for i in range(n)]
    masses = [1.0] * n
    node_solid = [0] * n
    cells = [[0, 1, 2]]
    cell_solid = [0]
    segments = [(i, i + 1) for i in range(n - 1)]


def mesh_bytes():
    body = struct.pack("<Q", len(names)) + b"".join(struct.pack("<Q", len(s.encode())) + s.encode() for s in names)
    body += vec2s(nodes) + f64s(masses) + u32s(node_solid)
    body += struct.pack("<Q", len(cells)) + b"".join(u32s(c) for c in cells)
    body += u32s(cell_solid)
    body += struct.pack("<Q", len(segments)) + b"".join(struct.pack("<2I", a, b) for a, b in segments)
    body += u32s(fixed) + struct.pack("<d", dt_stable)
    return header(RUN, 0, 0.0) + body


interface = sorted({n for s in segments for n in s})
CUR = [0, 0.0]
if MODE.startswith("ckpt_"):
    def on_ck(q):
        kind = MODE[5:]
        name = b"fem-node"
        if kind == "garbage":
            data = b"garbage"
        elif kind == "empty":
            data = b""
        elif kind == "big":
            data = b"\x00" * 200_000_000
        elif kind == "other":
            name, data = b"sph-node", b"x"
        body = struct.pack("<Q", len(name)) + name + struct.pack("<Q", len(data)) + data
        q.reply(q.key_expr, header(RUN, CUR[0], CUR[1]) + body)
    ckq = session.declare_queryable(f"{base}/fem/checkpoint", on_ck)
log(f"mode {MODE} at {AT}: {len(nodes)} nodes, {len(segments)} segments")
session.put(f"{base}/fem/mesh", mesh_bytes(), congestion_control=BLOCK)


def state(cmd, t, substeps, seconds, xs=None, vs=None, dts=None, env_step=None, snap=None, energies=None):
    ids = interface if cmd["want_interface"] else []
    # Positions: each node's reference + displacement (of the possibly spoilt mesh).
    x = xs if xs is not None else [(nodes[n][0] + plate.u[0], nodes[n][1] + plate.u[1]) for n in ids]
    v = vs if vs is not None else [tuple(plate.v)] * len(ids)
    body = u32s(ids) + vec2s(x) + vec2s(v)
    body += struct.pack("<Idd", substeps, dts if dts is not None else plate.h, seconds)
    if cmd["want_snapshot"] if snap is None else snap:
        n = len(nodes)
        body += b"\x01" + vec2s([(nodes[k][0] + plate.u[0], nodes[k][1] + plate.u[1]) for k in range(n)])
        body += vec2s([tuple(plate.v)] * n)
        body += struct.pack("<Q", len(cells)) + b"\x00" * (24 * len(cells))
        e = energies if energies is not None else plate.energies()
        body += struct.pack("<Q", len(names)) + b"".join(struct.pack("<3d", *e) for _ in names)
    else:
        body += b"\x00"
    return header(RUN, cmd["step"] if env_step is None else env_step, t) + body


def error(msg, status="failed"):
    body = struct.pack("<Q", len(status)) + status.encode() + struct.pack("<Q", len(msg.encode())) + msg.encode()
    session.put(f"{base}/fem/error", header(RUN, 0, 0.0) + body, congestion_control=BLOCK)


expected, last = 0, None
NONFIN, MAXC = [0], [0.0]
while True:
    try:
        kind, payload = inbox.get(timeout=args.timeout)
    except queue.Empty:
        log("no command: exit")
        sys.exit(3)
    if kind == "broker":
        if payload == zenoh.SampleKind.DELETE:
            log("broker gone")
            time.sleep(0.5)
            sys.exit(0)
        continue
    if last is not None and payload == last[0]:
        if MODE != "no_resend_answer":
            pub_state.put(last[1])
        continue
    cmd = read_command(payload, RUN)
    if cmd["step"] != expected:
        log(f"step {cmd['step']} expected {expected}")
        continue
    for c in cmd["corrections"]:
        for val in (*c[1], *c[2]):
            if not math.isfinite(val):
                NONFIN[0] += 1
            else:
                MAXC[0] = max(MAXC[0], abs(val))
    try:
        plate.apply([c for c in cmd["corrections"] if c[0] < len(plate.masses)])
    except ValueError as e:
        log(e)
    if cmd["stop"] and MODE == "ignore_stop":
        log("ignoring the stop"); time.sleep(100000)
    if cmd["stop"]:
        log("stop at", cmd["step"], f"corrections non-finite {NONFIN[0]}, largest {MAXC[0]:.3e}")
        break
    substeps = plate.advance(cmd["dt"]) if cmd["dt"] > 0 else 0
    t = plate.t
    step = cmd["step"]
    hit = step >= AT
    kw = {}
    secs = 0.001
    if hit:
        if MODE == "jump":
            plate.u[1] += 1e6 if step == AT else 0.0
        elif MODE == "vel_huge":
            kw["vs"] = [(0.0, 1e200)] * len(interface)
        elif MODE == "vel_1e3":
            kw["vs"] = [(0.0, 1e3)] * len(interface)
        elif MODE == "pos_far":
            xs = [(nodes[n][0], nodes[n][1]) for n in interface]
            xs[0] = (-1e308, -1e308)
            xs[-1] = (1e308, 1e308)
            kw["xs"] = xs
        elif MODE == "pos_1e150":
            kw["xs"] = [(nodes[n][0] * 1e150, nodes[n][1]) for n in interface]
        elif MODE == "into_fluid":           # the structure 0.5 m up into the water, at rest
            if step == AT:
                plate.u[1] += 0.5
        elif MODE == "through_fluid":        # the structure goes up through the water at 100 m/s
            plate.u[1] += 100.0 * cmd["dt"]
            plate.v = [0.0, 100.0]
        elif MODE == "collapse":              # every interface node at one point, in the water
            kw["xs"] = [(0.5, 0.05)] * len(interface)
        elif MODE == "collapse_half":          # half of the nodes at one point
            xs = [(nodes[n][0] + plate.u[0], nodes[n][1] + plate.u[1]) for n in interface]
            kw["xs"] = [(0.5, 0.0) if k % 2 else p for k, p in enumerate(xs)]
        elif MODE == "flip_y":                 # the plate mirrored: inside out
            kw["xs"] = [(nodes[n][0], -nodes[n][1] - 0.05) for n in interface]
        elif MODE == "swap":                 # x reported in reverse order
            x = [(nodes[n][0] + plate.u[0], nodes[n][1] + plate.u[1]) for n in interface]
            kw["xs"] = x[::-1]
        elif MODE == "secs_neg":
            secs = -1.0
        elif MODE == "secs_nan":
            secs = float("nan")
        elif MODE == "secs_huge":
            secs = 1e300
        elif MODE == "secs_max":
            secs = 1.7e308
        elif MODE == "dt_tiny":
            kw["dts"] = 1e-300
        elif MODE == "dt_inf":
            kw["dts"] = float("inf")
        elif MODE == "t_nan":
            t = float("nan")
        elif MODE == "t_wrong":
            t = 123.0
        elif MODE == "substeps_max":
            substeps = 2**32 - 1
        elif MODE == "energy_huge":
            kw["energies"] = (1e308, 1e308, 1e308)
            kw["snap"] = True
        elif MODE == "energy_neg":
            kw["energies"] = (-1e300, 0.0, 0.0)
            kw["snap"] = True
        elif MODE == "snapshot_unasked":
            kw["snap"] = True
        elif MODE == "no_snapshot_vel":
            pass
    ans = state(cmd, t, substeps, secs, **kw)
    if hit and MODE == "wrong_step":
        ans = state(cmd, t, substeps, secs, env_step=step + 1)
    if hit and MODE == "step_back":
        ans = state(cmd, t, substeps, secs, env_step=max(step - 1, 0))
    if hit and MODE == "late" and step == AT:
        log("sleeping")
        time.sleep(float(os.environ.get("LATE", "100")))
    if hit and MODE == "drop" and step == AT:
        log("dropping out without a word")
        os._exit(0)
    if hit and MODE == "hang" and step == AT:
        log("hanging, token held")
        time.sleep(100000)
    if hit and MODE == "error_then_answer" and step == AT:
        error("deliberate failure", "unstable")
    if hit and MODE == "error_only" and step == AT:
        msg = os.environ.get("ERRMSG", "deliberate failure")
        if msg == "BIG":
            msg = "x" * 50_000_000
        msg = msg.replace("\\n", "\n").replace("\\r", "\r").replace("\\e", "\x1b")
        error(msg, os.environ.get("ERRSTATUS", "unstable"))
        time.sleep(100000)
    if hit and MODE == "error_after_answer" and step == AT:
        pub_state.put(ans)
        time.sleep(0.3)
        error("deliberate failure after the answer", "unstable")
        last = (payload, ans); expected += 1
        continue
    if hit and MODE == "reregister" and step == AT:
        for _ in range(int(os.environ.get("REREG", "1"))):
            session.put(f"{base}/fem/mesh", mesh_bytes(), congestion_control=BLOCK)
    if hit and MODE == "flood_other_run":
        for _ in range(2000):
            session.put(f"cosim/otherrun/fem/state", ans, congestion_control=BLOCK)
    if hit and MODE == "flood_future" and step == AT:
        fut = state(cmd, t, substeps, secs, env_step=step + 1000)
        for _ in range(int(os.environ.get("REREG", "2000"))):
            pub_state.put(fut)
    CUR[0], CUR[1] = step, t
    pub_state.put(ans)
    if hit and MODE == "twice":
        pub_state.put(ans)
    if hit and MODE == "twice_different":
        pub_state.put(state(cmd, t + 1.0, substeps, secs, xs=[(0.0, 5.0)] * len(interface) if cmd["want_interface"] else None))
    last = (payload, ans)
    expected += 1
log(f"done: corrections non-finite {NONFIN[0]}, largest |component| {MAXC[0]:.3e}")
session.close()
