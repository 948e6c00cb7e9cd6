#!/bin/bash
# run_ext.sh CASE fem|sph MODE AT [--set ...]   — a coarse hydrostatic plate (or SCENE=...) with a hostile external node.
# Output: /tmp/sweep/CASE/{out/,cosim.stderr,cosim.stdout,node.stderr,rc}
CASE=$1; NODE=$2; MODE=$3; AT=$4; shift 4
cd "$(dirname "$0")/../../.."
SCENE=${SCENE:-scenes/hydrostatic_plate.toml}
D=/tmp/sweep/$CASE; rm -rf $D; mkdir -p $D
if [ -z "$NOSETS" ]; then
  if [[ $SCENE == *hydrostatic* ]]; then DEF=(--set fluid.spacing=0.1 --set 'solid[0].divisions=[20,2]' --set run.end_time=${END:-0.01});
  else DEF=(--set fluid.spacing=0.006 --set run.end_time=${END:-0.01}); fi
fi
timeout ${TMO:-120} target/release/cosim run $SCENE --quiet --external $NODE --wait-external ${WAIT:-20} --out $D/out "${DEF[@]}" "$@" >$D/cosim.stdout 2>$D/cosim.stderr &
CP=$!
for i in $(seq 1 300); do [ -f $D/out/external.json ] && break; sleep 0.1; done
timeout ${TMO:-120} target/py/bin/python docs/experiments/hostile_sweep/hostile_$NODE.py --from $D/out/external.json --mode $MODE --at $AT 2>$D/node.stderr &
NP=$!
START=$(date +%s.%N)
wait $CP; RC=$?
END_T=$(date +%s.%N)
sleep ${NODEWAIT:-0.5}; kill $NP 2>/dev/null; wait $NP 2>/dev/null; NRC=$?
echo $RC > $D/rc
printf "== %s: cosim rc=%s node rc=%s wall=%.1fs\n" $CASE $RC $NRC $(echo "$END_T - $START" | bc)
echo "-- cosim stderr:"; head -c 1500 $D/cosim.stderr
echo "-- summary:"; python3 -c "import json,sys; s=json.load(open('$D/out/summary.json')); print(s['status'], '|', s['message'][:600], '| steps', s['steps'], 't', s['sim_time'])" 2>&1 | head -5
grep -l "panicked\|RUST_BACKTRACE" $D/out/logs/* $D/*.stderr 2>/dev/null | sed 's/^/PANIC in /'
