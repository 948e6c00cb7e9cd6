#!/usr/bin/env python3
"""Medians of the runs of bench/dualsphysics/compare.sh, per case and build, and the ratios against DualSPHysics.

    python3 bench/dualsphysics/parse.py OUT

Prints one line per (build, case) and a Markdown table; writes OUT/summary_medians.json. Run tags are
BUILD_CASE_tTHREADS_I (BUILD `ds` is DualSPHysics). Fluid particle-steps per CPU-second = fluid particles x steps /
(user + sys seconds); wall s per simulated s = elapsed / simulated time; RSS per fluid particle = peak RSS / fluid
particles. Our step count is `sph_substeps` of summary.json; DualSPHysics' is "Steps of simulation" of Run.out.
"""
import glob
import json
import os
import re
import statistics as st
import sys


def time_v(path):
    """CPU seconds (user + sys), wall seconds and peak RSS (KiB) from a /usr/bin/time -v report."""
    text = open(path).read()

    def field(key):
        m = re.search(re.escape(key) + r': (.*)', text)
        if not m:
            raise ValueError(f'{path}: no "{key}"')
        return m.group(1).strip()

    parts = field('Elapsed (wall clock) time (h:mm:ss or m:ss)').split(':')
    wall = sum(float(x) * 60 ** i for i, x in enumerate(reversed(parts)))
    cpu = float(field('User time (seconds)')) + float(field('System time (seconds)'))
    return cpu, wall, int(field('Maximum resident set size (kbytes)'))


def ours(d):
    s = json.load(open(os.path.join(d, 'summary.json')))
    if s['status'] != 'ok':
        raise ValueError(f'{d}: status {s["status"]}')
    return dict(nf=s['particles'], nb=s['counts']['sph-node']['wall_particles'], steps=s['sph_substeps'],
                t=s['sim_time'], out=0)


def dsph(d):
    text = open(os.path.join(d, 'Run.out')).read()

    def count(pattern):
        m = re.search(pattern, text)
        return int(m.group(1).replace(',', '')) if m else None

    steps = count(r'Steps of simulation\.*: ([\d,]+)')
    nf, nb = count(r'CaseNfluid=([\d,]+)'), count(r'CaseNbound=([\d,]+)')
    if None in (steps, nf, nb):
        raise ValueError(f'{d}/Run.out: no step or particle count (did the run finish?)')
    rows = [line.split(';') for line in open(os.path.join(d, 'RunPARTs.csv')) if re.match(r'^\d+;', line)]
    return dict(nf=nf, nb=nb, steps=steps, t=float(rows[-1][1]), out=count(r'Excluded particles\.*: ([\d,]+)') or 0)


def main(out):
    runs = {}
    for tf in sorted(glob.glob(os.path.join(out, '*.time'))):
        tag = os.path.basename(tf)[:-5]
        build, case, threads, _ = tag.split('_')
        try:
            r = (dsph if build == 'ds' else ours)(tf[:-5])
        except (OSError, ValueError, KeyError) as e:
            print(f'skipped {tag}: {e}')
            continue
        r['cpu'], r['wall'], r['rss'] = time_v(tf)
        runs.setdefault((case, threads, build), []).append(r)
    table = {}
    for (case, threads, build), rs in sorted(runs.items()):
        med = lambda f: st.median(f(r) for r in rs)
        m = dict(n=len(rs), nf=rs[0]['nf'], nb=rs[0]['nb'], steps=med(lambda r: r['steps']),
                 t=med(lambda r: r['t']), cpu=med(lambda r: r['cpu']), wall=med(lambda r: r['wall']),
                 fps=med(lambda r: r['nf'] * r['steps'] / r['cpu']), wps=med(lambda r: r['wall'] / r['t']),
                 rsspp=med(lambda r: r['rss'] * 1024 / r['nf']), out=[r['out'] for r in rs],
                 cpus=[round(r['cpu'], 1) for r in rs], walls=[round(r['wall'], 1) for r in rs])
        table.setdefault(f'{case}_{threads}', {})[build] = m
        print(f"{case} {threads} {build:8s} n={m['n']} nf={m['nf']} steps={m['steps']:.0f} t={m['t']:.4f} "
              f"cpu={m['cpu']:.1f} {m['cpus']} wall={m['wall']:.1f} {m['walls']} fps={m['fps']:.3e} "
              f"wall/sim={m['wps']:.0f} rss/fluid={m['rsspp']:.0f} B removed={m['out']}")
    print()
    print('| case | threads | build | fluid particle-steps per CPU-s | / DualSPHysics | wall s per simulated s '
          '| / DualSPHysics | peak RSS per fluid particle | steps | runs |')
    print('|---|---:|---|---:|---:|---:|---:|---:|---:|---:|')
    for key, builds in table.items():
        case, threads = key.split('_')
        ds = builds.get('ds')
        for build, m in sorted(builds.items(), key=lambda kv: kv[0] == 'ds'):
            speed = f"{m['fps'] / ds['fps']:.2f}" if ds and build != 'ds' else ''
            # wall ratio as a speed-up: DualSPHysics' wall per simulated second over ours
            wall = f"{ds['wps'] / m['wps']:.2f}" if ds and build != 'ds' else ''
            name = 'DualSPHysics' if build == 'ds' else build
            print(f"| {case} | {threads[1:]} | {name} | {m['fps']:.3g} | {speed} | {m['wps']:.0f} | {wall} "
                  f"| {m['rsspp']:.0f} B | {m['steps']:.0f} | {m['n']} |")
    json.dump(table, open(os.path.join(out, 'summary_medians.json'), 'w'), indent=1)


if __name__ == '__main__':
    if len(sys.argv) != 2:
        sys.exit('usage: parse.py OUT')
    main(sys.argv[1])
