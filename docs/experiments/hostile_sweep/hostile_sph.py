#!/usr/bin/env python3
"""A hostile / buggy external fluid node: a static particle block (it only applies the broker's corrections),
speaking docs/PROTOCOL.md on the sph/* topics.

    hostile_sph.py --from OUT/external.json --mode MODE [--at STEP]
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
from rigid_plate_node import header, read_command, u32s, vec2s, f64s  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("--from", dest="from_file", required=True)
ap.add_argument("--mode", default="none")
ap.add_argument("--at", type=int, default=5)
ap.add_argument("--timeout", type=float, default=60.0)
args = ap.parse_args()
MODE, AT = args.mode, args.at


def log(*a):
    print("hostile_sph:", *a, file=sys.stderr, flush=True)


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
session = zenoh.open(zenoh.Config.from_json5(json.dumps({
    "mode": "peer", "scouting": {"multicast": {"enabled": False}},
    "connect": {"endpoints": [CONNECT], "timeout_ms": 5000, "exit_on_failure": True},
    "listen": {"endpoints": []}})))
base = f"cosim/{RUN}"
BLOCK = zenoh.CongestionControl.BLOCK
inbox = queue.Queue()
sub = session.declare_subscriber(f"{base}/broker/sph", lambda s: inbox.put(("cmd", s.payload.to_bytes())))
alive_sub = session.liveliness().declare_subscriber(f"{base}/broker/alive",
                                                    lambda s: inbox.put(("broker", s.kind)), history=True)
token = session.liveliness().declare_token(f"{base}/sph/alive")
pub_state = session.declare_publisher(f"{base}/sph/state", congestion_control=BLOCK)

scene_text = None
end = time.monotonic() + 5
while scene_text is None and time.monotonic() < end:
    for reply in session.get(f"{base}/scene", timeout=1.0):
        if reply.ok is not None:
            scene_text = reply.ok.payload.to_bytes().decode()
    if scene_text is None:
        time.sleep(0.2)
scene = tomllib.loads(scene_text)
fl = scene["fluid"]
dx = fl["spacing"]
rho0 = fl.get("density", 1000.0)
h = fl.get("smoothing_ratio", 1.3) * dx
g = scene["run"].get("gravity", [0.0, -9.81])


def fill(lo, hi):
    nx, ny = round((hi[0] - lo[0]) / dx), round((hi[1] - lo[1]) / dx)
    return [(lo[0] + (i + 0.5) * dx, lo[1] + (j + 0.5) * dx) for j in range(ny) for i in range(nx)]


x = [p for b in fl["block"] for p in fill(b["min"], b["max"])]
walls = [p for w in scene.get("wall", []) for p in fill(w["min"], w["max"])]
n = len(x)
v = [(0.0, 0.0)] * n
m = [rho0 * dx * dx] * n
top = max(p[1] for p in x) + 0.5 * dx
sensors = sum(1 for p in scene.get("probe", []) if p.get("kind") == "pressure" and p.get("average") == "interval")
c0 = 10 * math.sqrt(2 * 9.81 * 2.0)
dt_stable = 0.25 * h / c0

setup = dict(particles=n, spacing=dx, h=h, density=rho0, walls=walls, dt_stable=dt_stable, sensors=sensors)
if MODE == "setup_particles0":
    setup["particles"] = 0
elif MODE == "setup_particles_max":
    setup["particles"] = 2**32 - 1
elif MODE == "setup_spacing_tiny":
    setup["spacing"] = 1e-300
elif MODE == "setup_spacing_huge":
    setup["spacing"] = 1e300
elif MODE == "setup_h_tiny":
    setup["h"] = 1e-300
elif MODE == "setup_h_huge":
    setup["h"] = 1e300
elif MODE == "setup_density_tiny":
    setup["density"] = 1e-300
elif MODE == "setup_density_huge":
    setup["density"] = 1e300
elif MODE == "setup_walls_far":
    setup["walls"] = walls + [(-1e308, -1e308), (1e308, 1e308)]
elif MODE == "setup_walls_many":
    setup["walls"] = [(0.0, -1.0)] * (AT)
elif MODE == "setup_dt_tiny":
    setup["dt_stable"] = 1e-300
elif MODE == "setup_sensors_more":
    setup["sensors"] = sensors + 3


def setup_bytes():
    s = setup
    body = struct.pack("<Iddd", s["particles"], s["spacing"], s["h"], s["density"]) + vec2s(s["walls"])
    body += struct.pack("<dI", s["dt_stable"], s["sensors"])
    return header(RUN, 0, 0.0) + body


log(f"mode {MODE} at {AT}: {n} particles, {len(walls)} walls")
session.put(f"{base}/sph/setup", setup_bytes(), congestion_control=BLOCK)


def pressure(p):
    return rho0 * 9.81 * max(0.0, top - p[1])


def state(cmd, t, spoil):
    roi = cmd["roi"]
    if roi is None:
        ids = []
    else:
        ids = [i for i in range(n) if roi[0] <= x[i][0] <= roi[2] and roi[1] <= x[i][1] <= roi[3]]
    xs = [x[i] for i in ids]
    vs = [v[i] for i in ids]
    ms = [m[i] for i in ids]
    dts, secs, substeps = dt_stable, 0.001, 1 if cmd["dt"] > 0 else 0
    snap = cmd["want_snapshot"]
    sx, sv, srho, sp, sm = list(x), list(v), [rho0] * n, [pressure(p) for p in x], list(m)
    wall_p = [0.0] * len(setup["walls"])
    sens = [0.0] * setup["sensors"]
    if spoil:
        if MODE == "m_huge":
            ms = [1e300] * len(ms)
        elif MODE == "m_max_v":
            ms = [1.7e308] * len(ms)
            vs = [(0.0, -10.0)] * len(vs)
        elif MODE == "m_tiny":
            ms = [1e-300] * len(ms)
        elif MODE == "roi_far":
            if xs:
                xs[0] = (-1e308, -1e308)
                xs[-1] = (1e308, 1e308)
        elif MODE == "roi_outside":           # particles reported a km away from where they are
            xs = [(p[0] + 1e3, p[1]) for p in xs]
        elif MODE == "v_huge":
            vs = [(0.0, -1e200)] * len(vs)
        elif MODE == "dt_tiny":
            dts = 1e-300
        elif MODE == "dt_small":
            dts = 1e-11
        elif MODE == "secs_max":
            secs = 1.7e308
        elif MODE == "rho_tiny":
            srho = [1e-300] * n
        elif MODE == "p_huge":
            sp = [1e308] * n
        elif MODE == "p_neg":
            sp = [-1e308] * n
        elif MODE == "snap_x_far":
            sx = [(1e300, 1e300)] * n
        elif MODE == "snap_m_huge":
            sm = [1e300] * n
        elif MODE == "snap_v_huge":
            sv = [(1e300, 1e300)] * n
        elif MODE == "sensors_nan":
            sens = [float("nan")] * len(sens)
        elif MODE == "roi_ignored":             # never reports anything near the structure
            ids, xs, vs, ms = [], [], [], []
        elif MODE == "roi_dup_particles":       # two ids at the same position
            if len(xs) > 1:
                xs[1] = xs[0]
    body = u32s(ids) + vec2s(xs) + vec2s(vs) + f64s(ms) + struct.pack("<Idd", substeps, dts, secs)
    if snap:
        body += b"\x01" + vec2s(sx) + vec2s(sv) + f64s(srho) + f64s(sp) + f64s(sm) + f64s(wall_p) + f64s(sens)
    else:
        body += b"\x00"
    return header(RUN, cmd["step"], t) + body


expected, last, now = 0, None, 0.0
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
        pub_state.put(last[1])
        continue
    cmd = read_command(payload, RUN)
    if cmd["step"] != expected:
        log(f"step {cmd['step']} expected {expected}")
        continue
    for cid, cdx, cdv, _ in cmd["corrections"]:
        if cid < n:
            x[cid] = (x[cid][0] + cdx[0], x[cid][1] + cdx[1])
            v[cid] = (v[cid][0] + cdv[0], v[cid][1] + cdv[1])
    if cmd["stop"]:
        log("stop at", cmd["step"])
        break
    now += cmd["dt"]
    ans = state(cmd, now, cmd["step"] >= AT)
    pub_state.put(ans)
    last = (payload, ans)
    expected += 1
log("done")
session.close()
