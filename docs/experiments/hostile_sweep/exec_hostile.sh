#!/bin/sh
# exec_hostile.sh MODE --run ID --connect EP : hostile_fem.py as a `cosim replay --exec` program
MODE=$1; shift; RUN=$2; EP=$4
F=/tmp/sweep/exec_$RUN.json; printf '{"run":"%s","connect":"%s"}' "$RUN" "$EP" > $F
ROOT=$(cd "$(dirname "$0")/../../.." && pwd); exec $ROOT/target/py/bin/python $ROOT/docs/experiments/hostile_sweep/hostile_fem.py --from $F --mode $MODE --at ${AT:-3}
