#!/bin/bash
# The coupled ISPH gate (issue 16) with its fluid and structure energies; prints their largest gain over the
# budget 9.6138 J/m (docs/CORRECTIONS.md "The structure's own face velocity, sent by the broker").
# usage (from the repository root): docs/experiments/gate_energy.sh BIN OUTDIR MAX_DT [--set ...]
BIN=$1; D=$2; M=$3; shift 3
rm -rf $D
$BIN run ./scenes/elastic_gate.toml --in-process --quiet --out $D --set fluid.spacing=0.004 --set run.end_time=0.2 --set 'probe[1]={name="energy",kind="energy",part="total",of="fluid"}' --set 'probe[0]={name="es",kind="energy",part="total",of="structure"}' --set solid[0].material.youngs_modulus=12e6 --set fluid.solver=isph --set coupling.max_dt=$M "$@" 2>&1 | tail -1
python3 - $D <<'PY'
import sys,csv,glob,os
d=sys.argv[1]
fs=glob.glob(os.path.join(d,'**','probes*.csv'),recursive=True)
rows=list(csv.DictReader(open(fs[0])))
keys=rows[0].keys()
t=[float(r['t']) for r in rows]
ef=[float(r['energy']) for r in rows]; es=[float(r['es']) for r in rows]
B=9.6138
tot=[a+b for a,b in zip(ef,es)]
mf=max(x-ef[0] for x in ef)/B; mt=max(x-tot[0] for x in tot)/B
it=max(range(len(tot)),key=lambda i:tot[i])
print(f"fluid max {mf:+.4f}  fluid+struct max {mt:+.4f} at t={t[it]:.3f}")
PY
