#!/bin/bash
# snap_ext.sh MODE — a paused run (step 3) with a hostile external fem node; then cosim snapshot / inspect --node / --particle.
MODE=$1; cd "$(dirname "$0")/../../.."; D=/tmp/sweep/snap_$MODE; rm -rf $D; mkdir -p $D; ID=snap$RANDOM
(timeout 60 target/release/cosim run scenes/hydrostatic_plate.toml --quiet --external fem --run-id $ID --break step=3 --out $D/out --set fluid.spacing=0.1 --set 'solid[0].divisions=[20,2]' --set run.end_time=0.01 --set coupling.step_timeout=5 > $D/run.out 2>&1 &)
sleep 1.5; (timeout 55 target/py/bin/python docs/experiments/hostile_sweep/hostile_fem.py --from $D/out/external.json --mode $MODE 2>$D/node.err &)
sleep 2.5
for a in "snapshot $ID --out $D/snap" "inspect $ID --node 3" "inspect $ID --particle 3"; do echo "== cosim $a"; timeout 30 target/release/cosim $a 2>&1 | head -c 400; echo " rc=${PIPESTATUS[0]}"; done
timeout 10 target/release/cosim ctl $ID stop >/dev/null; sleep 1; cat $D/run.out | grep -v "waiting up to"
