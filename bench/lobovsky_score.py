#!/usr/bin/env python3
"""Scores a run of scenes/lobovsky_dam_break.toml against the recorded peak event (Lobovsky et al. 2014, H = 0.3 m),
with the criteria of issue 16 and cosim/tests/lobovsky.rs, on the data's own time axis:

  first impact  the first sample after t* = 1 with p* >= 0.1, against the data's (bound: within +-0.1 in t*)
  peak          the largest p* up to 0.5 t* after the first impact (bound: 1.5-6, a factor 2 of 3.04 / 1.95)
  RMS           of p*_sim - p*_data (the data interpolated at the sample times) for t* in [3, 7] (bound: 0.25)
  min           the lowest p* (bound: >= -0.5)
  zeros         samples of exactly 0 from 0.1 t* after the first impact on (the sensors stay under water; bound: none)
  impulse       the first impact's pressure impulse, the integral of p* dt* from 0.05 t* before it to 0.5 t* after it,
                each series from its own first impact, against the data's (not bounded: the same impulse under a
                taller peak is a shorter pulse, as WCSPH's acoustic rho c0 u is)
  mean          the mean of p*_sim - p*_data over t* in [3, 7] (the part of the RMS that is a bias, not noise)

and, where the run has them (`level_H1` ... `level_H4`), the water-level gauges against the recorded levels:
  the RMS of (level_sim - level_data)/H over the run's samples in the data's time range, and the mean difference.

t* = t sqrt(g/H), p* = p/(rho g H). Usage: python3 bench/lobovsky_score.py OUT_DIR [OUT_DIR ...]
(OUT_DIR holds probes.csv with p_sensor1, p_sensor2 and, if present, p_sensor1_raw, p_sensor2_raw).
Exit status 0 whatever the scores: this reports, it does not judge.
"""
import csv
import math
import os
import sys

G, H, RHO = 9.81, 0.3, 1000.0
T_SCALE = math.sqrt(H / G)  # t = T_SCALE t*
P_SCALE = RHO * G * H  # p = P_SCALE p*
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "data")


def data(sensor):
    return series(f"lobovsky2014_H300_sensor{sensor}_event.csv", "p_star")


def series(name, column):
    with open(os.path.join(DATA, name)) as f:
        return [(float(r["t_star"]), float(r[column])) for r in csv.DictReader(f)]


def at(s, t):
    for (t0, p0), (t1, p1) in zip(s, s[1:]):
        if t0 <= t <= t1:
            return p0 + (p1 - p0) * (t - t0) / (t1 - t0)
    return s[-1][1] if t > s[-1][0] else s[0][1]


def first_impact(s):
    return next(t for t, p in s if t > 1.0 and p >= 0.1)


def impulse(s, t1):
    a, b = t1 - 0.05, t1 + 0.5
    return sum(0.5 * (p0 + p1) * (u1 - u0) for (u0, p0), (u1, p1) in zip(s, s[1:]) if u0 >= a and u1 <= b)


def score(sim, ref):
    t1, t1d = first_impact(sim), first_impact(ref)
    peak = max(p for t, p in sim if t <= t1 + 0.5)
    diffs = [p - at(ref, t) for t, p in sim if 3.0 <= t <= 7.0]
    rms = math.sqrt(sum(d * d for d in diffs) / len(diffs)) if diffs else float("nan")
    mean = sum(diffs) / len(diffs) if diffs else float("nan")
    zeros = sum(1 for t, p in sim if t > t1 + 0.1 and p == 0.0)
    return (t1, t1d, peak, max(p for _, p in ref), rms, min(p for _, p in sim), zeros,
            impulse(sim, t1), impulse(ref, t1d), mean)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print("run | probe | first impact t* (data) | peak p* (data) | impulse (data) | RMS t* 3-7 (mean) | min p* | exact zeros")
    for out in sys.argv[1:]:
        path = os.path.join(out, "probes.csv")
        try:
            with open(path) as f:
                rows = list(csv.DictReader(f))
        except OSError as e:
            sys.exit(f"{path}: {e}")
        for sensor in (1, 2):
            ref = data(sensor)
            for name in (f"p_sensor{sensor}", f"p_sensor{sensor}_raw"):
                if not rows or name not in rows[0]:
                    continue
                sim = [(float(r["t"]) / T_SCALE, float(r[name]) / P_SCALE) for r in rows]
                t1, t1d, peak, peakd, rms, low, zeros, imp, impd, mean = score(sim, ref)
                print(f"{out} | {name} | {t1:.3f} ({t1d:.3f}) | {peak:.2f} ({peakd:.2f}) | {imp:.3f} ({impd:.3f}) | "
                      f"{rms:.3f} ({mean:+.3f}) | {low:.2f} | {zeros}")
        for gauge in (1, 2, 3, 4):
            name = f"level_H{gauge}"
            if not rows or name not in rows[0]:
                continue
            ref = series(f"lobovsky2014_H300_level_H{gauge}.csv", "level")
            diffs = [
                float(r[name]) / H - at(ref, float(r["t"]) / T_SCALE)
                for r in rows
                if ref[0][0] <= float(r["t"]) / T_SCALE <= ref[-1][0]
            ]
            rms = math.sqrt(sum(d * d for d in diffs) / len(diffs))
            print(f"{out} | {name} | level/H: RMS difference {rms:.3f}, mean {sum(diffs) / len(diffs):+.3f} ({len(diffs)} samples)")


if __name__ == "__main__":
    main()
