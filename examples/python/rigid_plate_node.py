#!/usr/bin/env python3
"""A structure node written in Python: a rigid plate on springs, joining a cosim run in place of `fem-node`.

It speaks docs/PROTOCOL.md over eclipse-zenoh (PyPI `eclipse-zenoh` 1.10) with nothing but the standard library:

    cosim run scenes/hydrostatic_plate.toml --external fem --out out/plate_py &
    python3 examples/python/rigid_plate_node.py --run RUN --connect tcp/127.0.0.1:PORT

(`cosim run` prints RUN and the endpoint and writes them to out/plate_py/external.json; `--from FILE` reads that
file instead.)

The model. The scene's first `[[solid]]` box is taken as a rigid body of mass M = density × area (per metre of
thickness) that translates in x and y; its `fixed` boxes are replaced by a spring of stiffness k and a dashpot of
damping ratio zeta on each axis (c = 2 zeta sqrt(k M)):

    M u'' = M g - k u - c u' + J / dt,

J being the impulse the contact broker hands the plate's nodes as velocity corrections (sum of m_a dv_a). Under
water of depth H on a span L the static answer is u_y = -(rho_f g H L + M g) / k: that is what
cosim/tests/external_python.rs checks. The body is integrated with semi-implicit Euler at 1/40 of its dry period.

For the broker the body is the box meshed as the scene asks (`divisions`, quad4, counter-clockwise), with lumped
nodal masses; every node moves with the body. Position corrections (`dx`, only sent with
`contact.move_structure = true`) shift the body by their mass-weighted mean.
"""

import argparse
import json
import math
import queue
import struct
import sys
import time
import tomllib

import zenoh

PROTOCOL_VERSION = 3


# --- wire format (docs/PROTOCOL.md §3-§5) -------------------------------------------------------------------------

class Reader:
    def __init__(self, payload):
        self.b, self.i = payload, 0

    def take(self, fmt):
        v = struct.unpack_from(fmt, self.b, self.i)
        self.i += struct.calcsize(fmt)
        return v

    def u8(self):
        return self.take("<B")[0]

    def u32(self):
        return self.take("<I")[0]

    def u64(self):
        return self.take("<Q")[0]

    def f64(self):
        return self.take("<d")[0]

    def boolean(self):
        v = self.u8()
        if v not in (0, 1):
            raise ValueError(f"bool tag {v}")
        return v == 1

    def string(self):
        n = self.u64()
        if self.i + n > len(self.b):
            raise ValueError("string runs past the end")
        s = self.b[self.i:self.i + n].decode("utf-8")
        self.i += n
        return s

    def seq(self, item):
        n = self.u64()
        if n > len(self.b):
            raise ValueError(f"count {n} longer than the message")
        return [item() for _ in range(n)]


def header(run, step, t):
    rb = run.encode()
    return struct.pack("<IQ", PROTOCOL_VERSION, len(rb)) + rb + struct.pack("<Qd", step, t)


def vec2s(points):
    return struct.pack("<Q", len(points)) + b"".join(struct.pack("<2d", *p) for p in points)


def f64s(values):
    return struct.pack(f"<Q{len(values)}d", len(values), *values)


def u32s(values):
    return struct.pack(f"<Q{len(values)}I", len(values), *values)


def read_command(payload, run):
    """Envelope<StepCommand> -> dict; raises ValueError on anything PROTOCOL.md §7 refuses."""
    r = Reader(payload)
    version = r.u32()
    if version != PROTOCOL_VERSION:
        raise ValueError(f"protocol version {version}, expected {PROTOCOL_VERSION}")
    run_got, step, t = r.string(), r.u64(), r.f64()
    dt = r.f64()
    # Protocol 3: each correction may carry the structure's face (fluid corrections only; refused on a node's).
    corrections = r.seq(lambda: (r.u32(), r.take("<2d"), r.take("<2d"), r.take("<4d") if r.boolean() else None))
    roi = r.take("<4d") if r.boolean() else None
    want_interface, want_snapshot, stop = r.boolean(), r.boolean(), r.boolean()
    if r.i != len(payload):
        raise ValueError("trailing bytes")
    if run_got != run:
        raise ValueError(f"run {run_got!r}, expected {run!r}")
    return dict(step=step, t=t, dt=dt, corrections=corrections, roi=roi, want_interface=want_interface,
                want_snapshot=want_snapshot, stop=stop)


# --- the model -----------------------------------------------------------------------------------------------------

class RigidPlate:
    def __init__(self, scene, stiffness, damping_ratio):
        solid = scene["solid"][0]
        self.name = solid["name"]
        (x0, y0), (x1, y1) = solid["min"], solid["max"]
        nx, ny = solid.get("divisions", [1, 1])
        rho = solid["material"]["density"]
        self.gravity = scene["run"].get("gravity", [0.0, -9.81])
        self.mass = rho * (x1 - x0) * (y1 - y0)
        self.k = stiffness
        self.c = 2.0 * damping_ratio * math.sqrt(stiffness * self.mass)
        self.period = 2.0 * math.pi * math.sqrt(self.mass / stiffness)
        self.h = self.period / 40.0
        self.u = [0.0, 0.0]
        self.v = [0.0, 0.0]
        self.t = 0.0
        # The box meshed as quad4, node id = j (nx + 1) + i.
        node = lambda i, j: j * (nx + 1) + i
        self.ref = [(x0 + (x1 - x0) * i / nx, y0 + (y1 - y0) * j / ny) for j in range(ny + 1) for i in range(nx + 1)]
        self.cells = [[node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)]
                      for j in range(ny) for i in range(nx)]
        cell_mass = self.mass / (nx * ny)
        self.masses = [0.0] * len(self.ref)
        for cell in self.cells:
            for n in cell:
                self.masses[n] += cell_mass / 4.0
        # Boundary segments counter-clockwise (the body on the left of a -> b).
        seg = [(node(i, 0), node(i + 1, 0)) for i in range(nx)]
        seg += [(node(nx, j), node(nx, j + 1)) for j in range(ny)]
        seg += [(node(i + 1, ny), node(i, ny)) for i in reversed(range(nx))]
        seg += [(node(0, j + 1), node(0, j)) for j in reversed(range(ny))]
        self.segments = seg
        self.interface = sorted({n for s in seg for n in s})

    def positions(self, ids):
        return [(self.ref[n][0] + self.u[0], self.ref[n][1] + self.u[1]) for n in ids]

    def apply(self, corrections):
        """Velocity corrections are impulses m_a dv_a on the body; position corrections shift it (mass-weighted)."""
        for node_id, _, _, face in corrections:
            if node_id >= len(self.masses):  # PROTOCOL.md §7: a correction for an unknown node is an error
                raise ValueError(f"corrections: node {node_id} out of range ({len(self.masses)} nodes)")
            if face is not None:  # PROTOCOL.md §7: faces come with the fluid's corrections only
                raise ValueError(f"corrections: node {node_id} carries a face")
        for node_id, dx, dv, _ in corrections:
            m = self.masses[node_id]
            for k in range(2):
                self.v[k] += m * dv[k] / self.mass
                self.u[k] += m * dx[k] / self.mass

    def advance(self, dt):
        n = max(1, math.ceil(dt / self.h - 1e-9))
        h = dt / n
        for _ in range(n):
            for k in range(2):
                a = self.gravity[k] - (self.k * self.u[k] + self.c * self.v[k]) / self.mass
                self.v[k] += h * a
                self.u[k] += h * self.v[k]
        self.t += dt
        return n

    def energies(self):
        kinetic = 0.5 * self.mass * (self.v[0] ** 2 + self.v[1] ** 2)
        strain = 0.5 * self.k * (self.u[0] ** 2 + self.u[1] ** 2)  # the springs'
        potential = -self.mass * (self.gravity[0] * self.u[0] + self.gravity[1] * self.u[1])
        return kinetic, strain, potential

    # --- messages (PROTOCOL.md §5) ---

    def mesh(self, run):
        body = struct.pack("<Q", 1) + struct.pack("<Q", len(self.name.encode())) + self.name.encode()
        body += vec2s(self.ref) + f64s(self.masses) + u32s([0] * len(self.ref))
        body += struct.pack("<Q", len(self.cells)) + b"".join(u32s(c) for c in self.cells)
        body += u32s([0] * len(self.cells))
        body += struct.pack("<Q", len(self.segments)) + b"".join(struct.pack("<2I", a, b) for a, b in self.segments)
        body += u32s([])  # no clamped nodes: the springs hold the body
        body += struct.pack("<d", self.h)
        return header(run, 0, 0.0) + body

    def state(self, run, cmd, substeps, seconds):
        ids = self.interface if cmd["want_interface"] else []
        body = u32s(ids) + vec2s(self.positions(ids)) + vec2s([tuple(self.v)] * len(ids))
        body += struct.pack("<Idd", substeps, self.h, seconds)
        if cmd["want_snapshot"]:
            n = len(self.ref)
            body += b"\x01" + vec2s(self.positions(range(n))) + vec2s([tuple(self.v)] * n)
            body += struct.pack("<Q", len(self.cells)) + b"\x00" * (24 * len(self.cells))  # rigid: no stress field
            body += struct.pack("<Q", 1) + struct.pack("<3d", *self.energies())
        else:
            body += b"\x00"
        return header(run, cmd["step"], self.t) + body


# --- the node (PROTOCOL.md §8) -------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", help="run id (printed by `cosim run --external fem`)")
    ap.add_argument("--connect", help="endpoint of the run, e.g. tcp/127.0.0.1:40331")
    ap.add_argument("--from", dest="from_file", help="external.json written by `cosim run --external fem`")
    ap.add_argument("--stiffness", type=float, default=3.0e8, help="spring stiffness k [N/m per m] (default 3e8)")
    ap.add_argument("--damping-ratio", type=float, default=0.1, help="zeta of the dry body (default 0.1)")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds to wait for any one command")
    ap.add_argument("--client", action="store_true",
                    help="--connect is a zenoh router: join through it as a client (docs/PROTOCOL.md section 1)")
    args = ap.parse_args()
    if args.from_file:
        deadline = time.monotonic() + args.timeout
        while True:
            try:
                with open(args.from_file) as f:
                    info = json.load(f)
                break
            except (OSError, ValueError):
                if time.monotonic() > deadline:
                    sys.exit(f"rigid_plate_node: no {args.from_file} after {args.timeout} s")
                time.sleep(0.05)
        args.run, args.connect = info["run"], info["connect"]
        args.client = args.client or info.get("mode") == "client"
    if not args.run or not args.connect:
        sys.exit("rigid_plate_node: give --run and --connect, or --from DIR/external.json")

    settings = {
        "mode": "client" if args.client else "peer",
        "scouting": {"multicast": {"enabled": False}},
        "connect": {"endpoints": [args.connect], "timeout_ms": 5000, "exit_on_failure": True},
    }
    if not args.client:
        settings["listen"] = {"endpoints": []}
    conf = zenoh.Config.from_json5(json.dumps(settings))
    session = zenoh.open(conf)
    base = f"cosim/{args.run}"
    inbox = queue.Queue()
    # Commands and the broker's death arrive on one queue, in order.
    sub = session.declare_subscriber(f"{base}/broker/fem", lambda s: inbox.put(("cmd", s.payload.to_bytes())))
    alive_sub = session.liveliness().declare_subscriber(
        f"{base}/broker/alive", lambda s: inbox.put(("broker", s.kind)), history=True)
    token = session.liveliness().declare_token(f"{base}/fem/alive")
    pub_state = session.declare_publisher(f"{base}/fem/state", congestion_control=zenoh.CongestionControl.BLOCK)

    def fail(message):
        body = struct.pack("<Q", 6) + b"failed" + struct.pack("<Q", len(message.encode())) + message.encode()
        session.put(f"{base}/fem/error", header(args.run, 0, 0.0) + body,
                    congestion_control=zenoh.CongestionControl.BLOCK)
        time.sleep(0.1)
        sys.exit(f"rigid_plate_node: {message}")

    # Asked again while nobody answers: a query that finds no queryable ends at once, and a router may not have
    # heard of the broker's queryable yet when this node starts (bus/src/serve.rs, fetch_scene).
    scene_text, deadline = None, time.monotonic() + 5.0
    while scene_text is None and time.monotonic() < deadline:
        for reply in session.get(f"{base}/scene", timeout=max(0.2, deadline - time.monotonic())):
            if reply.ok is not None:
                scene_text = reply.ok.payload.to_bytes().decode("utf-8")
        if scene_text is None:
            time.sleep(0.2)
    if scene_text is None:
        sys.exit(f"rigid_plate_node: nobody served the scene of run {args.run} at {args.connect}")
    plate = RigidPlate(tomllib.loads(scene_text), args.stiffness, args.damping_ratio)
    print(f"rigid_plate_node: solid {plate.name}, M = {plate.mass:.4g} kg/m, k = {plate.k:.4g} N/m2, "
          f"dry period {plate.period:.3e} s, {len(plate.ref)} nodes", file=sys.stderr)
    session.put(f"{base}/fem/mesh", plate.mesh(args.run), congestion_control=zenoh.CongestionControl.BLOCK)

    expected, steps, started = 0, 0, time.monotonic()
    last = None  # (command bytes, answer bytes): a command that comes again is answered again (PROTOCOL.md §8)
    # When the broker's token goes, its last command (the stop at the end of a run) may still be on its way: the
    # two subscriptions deliver in no common order. And a link lost and restored (a router restarted) takes the
    # token away for a moment too. As the Rust nodes do (PROTOCOL.md §8), keep taking commands, ask for the token
    # every 0.2 s, and fail only when it has been gone for GRACE seconds.
    grace, gone_since = 4.0, None
    while True:
        try:
            kind, payload = inbox.get(timeout=0.2 if gone_since is not None else args.timeout)
        except queue.Empty:
            if gone_since is None:
                fail(f"no command for {args.timeout} s (step {expected})")
            if any(r.ok is not None for r in session.liveliness().get(f"{base}/broker/alive", timeout=0.2)):
                gone_since = None  # back: going on
            elif time.monotonic() - gone_since > grace:
                fail(f"the broker is gone (broker/alive disappeared for {grace:.0f} s)")
            continue
        if kind == "broker":
            if payload == zenoh.SampleKind.DELETE:
                gone_since = gone_since if gone_since is not None else time.monotonic()
            else:
                gone_since = None
            continue
        if last is not None and payload == last[0]:
            pub_state.put(last[1])  # the broker sent it again: our answer was lost; compute nothing
            continue
        clock = time.perf_counter()
        try:
            cmd = read_command(payload, args.run)
            if cmd["step"] != expected:
                raise ValueError(f"step {cmd['step']}, expected {expected}")
        except (ValueError, struct.error, UnicodeDecodeError) as e:
            fail(f"refused a command: {e}")  # PROTOCOL.md §7: never applied
        try:
            plate.apply(cmd["corrections"])
        except ValueError as e:
            fail(f"unusable command: {e}")
        if cmd["stop"]:
            break
        substeps = plate.advance(cmd["dt"]) if cmd["dt"] > 0 else 0
        answer = plate.state(args.run, cmd, substeps, time.perf_counter() - clock)
        pub_state.put(answer)
        last = (payload, answer)
        expected += 1
        steps += 1
    wall = time.monotonic() - started
    print(f"rigid_plate_node: {steps} steps in {wall:.2f} s ({steps / max(wall, 1e-9):.0f} coupled steps/s), "
          f"u = ({plate.u[0]:.4e}, {plate.u[1]:.4e}) m", file=sys.stderr)
    del token, sub, alive_sub
    session.close()


if __name__ == "__main__":
    main()
