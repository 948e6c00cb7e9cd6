#!/usr/bin/env python3
"""The Lobovsky dam break (H = 0.3 m) for DualSPHysics 5.4, read with the same sensors as ours (issue 16).

  python3 lobovsky.py case DP KERNEL HDP C0 > X_Def.xml   the case from lobovsky_Def.xml.in (C0 = auto: DualSPHysics'
                                                          default, 20 sqrt(g H); KERNEL 1 cubic spline, 2 Wendland)
  python3 lobovsky.py probes GAUGE_CSV C0 > probes.csv    its Sensors gauge (the Shepard mean of the fluid's density at
                                                          sensors 1 and 2, every step) as our probes.csv

The gauge gives density; pressure is the case's Tait law, p = (c0^2 rho0 / 7) ((rho / rho0)^7 - 1), applied to the
interpolated density (ours interpolates pressure: the same to first order in rho / rho0 - 1). Columns as
scenes/lobovsky_dam_break.toml writes them: `p_sensor1`, `p_sensor2` the mean over each 1 ms interval of every step's
value, weighted by its step (our `average = "interval"`); `p_sensor1_raw`, `p_sensor2_raw` the last step's value
at or before each sample time. bench/lobovsky_score.py scores the result.
"""
import csv
import math
import os
import sys

RHO0, GAMMA, G, H = 1000.0, 7.0, 9.81, 0.3
INTERVAL = 0.001
END = 1.25


def case(dp, kernel, hdp, c0):
    here = os.path.dirname(os.path.abspath(__file__))
    text = open(os.path.join(here, "lobovsky_Def.xml.in")).read()
    half = dp / 2
    auto = c0 == "auto"
    values = {
        "DP": dp, "PMIN": -0.04 + half, "KERNEL": kernel, "HDP": hdp,
        "C0": 0 if auto else float(c0), "C0AUTO": "true" if auto else "false",
        # boxes from particle centre to particle centre (fluid 0..0.6 x 0..0.3, walls 0.03 thick, face at x = 1.61)
        "F0": half, "FX": 0.6 - dp, "FZ": 0.3 - dp,
        "W0": -0.03 + half, "WL": 1.67 - dp, "WT": 0.03 - dp, "WH": 0.6 - dp, "R0": 1.61 + half,
        "PX": 1.61 - half,  # half a spacing in front of the wall, as our sensor probes
    }
    for k, v in values.items():
        text = text.replace(f"@{k}@", f"{v:.10g}" if isinstance(v, float) else str(v))
    assert "@" not in text.split("-->", 1)[1], "unfilled placeholder"
    sys.stdout.write(text)


def pressure(rho, c0):
    if rho == 0.0:  # kcdummy: no fluid in reach, the atmosphere's gauge pressure (as ours)
        return 0.0
    return c0 * c0 * RHO0 / GAMMA * ((rho / RHO0) ** GAMMA - 1.0)


def read_gauge(path):
    """(time, rho at sensor 1, rho at sensor 2) per step; DualSPHysics writes ';'-separated CSV with a header."""
    rows = []
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip()]
    sep = ";" if ";" in lines[0] else ","
    for line in lines:
        cells = [c.strip() for c in line.split(sep)]
        try:
            vals = [float(c) for c in cells if c != ""]
        except ValueError:
            continue  # header lines
        if len(vals) >= 3:
            rows.append((vals[0], vals[-2], vals[-1]))
    return rows


def probes(gauge_csv, c0):
    c0 = float(c0)
    rows = read_gauge(gauge_csv)
    if not rows:
        sys.exit(f"lobovsky.py: no gauge rows in {gauge_csv}")
    ts = [r[0] for r in rows]
    ps = [(pressure(r[1], c0), pressure(r[2], c0)) for r in rows]
    eps = 1e-12
    out = csv.writer(sys.stdout)
    out.writerow(["t", "p_sensor1", "p_sensor2", "p_sensor1_raw", "p_sensor2_raw"])
    k = 0  # the step in progress at the interval's start
    for i in range(1, int(round(END / INTERVAL)) + 1):
        t_start, t_end = (i - 1) * INTERVAL, i * INTERVAL
        while k + 1 < len(ts) and ts[k + 1] <= t_start + eps:
            k += 1
        # every step's value holds from its time to the next step's (piecewise constant, weighted by its step)
        acc, span, j = [0.0, 0.0], 0.0, k
        while j < len(ts) and ts[j] <= t_end + eps:
            t0 = max(ts[j], t_start)
            t1 = min(ts[j + 1], t_end) if j + 1 < len(ts) else t_end
            if t1 > t0:
                acc = [acc[0] + ps[j][0] * (t1 - t0), acc[1] + ps[j][1] * (t1 - t0)]
                span += t1 - t0
            j += 1
        if span == 0.0:
            continue
        raw = ps[j - 1]  # the last step at or before t_end
        out.writerow([f"{t_end:.6f}", acc[0] / span, acc[1] / span, raw[0], raw[1]])


if __name__ == "__main__":
    if len(sys.argv) == 6 and sys.argv[1] == "case":
        case(float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), sys.argv[5])
    elif len(sys.argv) == 4 and sys.argv[1] == "probes":
        probes(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
