#!/bin/bash
# The hydrostatic plate under ISPH: mean and std of its load over 0.05-0.3 s against the water's weight
# (-19,620 N/m) and its mid-span deflection against -6.86e-5 m.
# usage (from the repository root): docs/experiments/plate_load.sh BIN OUTDIR [--set ...]
BIN=$1; D=$2; shift 2
rm -rf $D
$BIN run ./scenes/hydrostatic_plate.toml --in-process --quiet --out $D --set fluid.solver=isph "$@" 2>&1 | tail -1
python3 - $D <<'PY'
import sys,csv,statistics as st
rows=list(csv.DictReader(open(sys.argv[1]+'/probes.csv')))
w=[r for r in rows if 0.05<=float(r['t'])<=0.3]
ly=[float(r['load_y']) for r in w]; u=[float(r['mid_uy']) for r in w]
W=-19620.0
m=st.mean(ly)
print(f"load mean {100*(m/W-1):+.2f} %, std {100*st.pstdev(ly)/abs(W):.1f} %, mid_uy mean {st.mean(u):.4e} ({100*(st.mean(u)/-6.86e-5-1):+.1f} %) n={len(w)} tend={rows[-1]['t']}")
PY
