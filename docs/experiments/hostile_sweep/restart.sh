#!/bin/bash
# restart.sh CASE EDIT...  — craft a checkpoint from /tmp/sweep/ck_run/checkpoints/104 and restart the coarse gate from it.
CASE=$1; shift
cd "$(dirname "$0")/../../.."
D=/tmp/sweep/$CASE; rm -rf $D; mkdir -p $D
python3 sweep/ckedit.py /tmp/sweep/ck_run/checkpoints/104 $D/ck "$@" 2>$D/ckedit.stderr || cat $D/ckedit.stderr
SCENE=${SCENE:-scenes/elastic_gate.toml}
START=$(date +%s.%N)
timeout ${TMO:-60} target/release/cosim run $SCENE --quiet ${INPROC:+--in-process} --out $D/out --restart $D/ck ${NOSETS:---set fluid.spacing=0.006} --set run.end_time=${END:-0.02} ${EXTRA} >$D/stdout 2>$D/stderr
RC=$?
printf "== %s: rc=%s wall=%.1fs\n" $CASE $RC $(echo "$(date +%s.%N) - $START" | bc)
head -c 1200 $D/stderr | grep -v "particle weighs"
[ -f $D/out/summary.json ] && python3 -c "import json; s=json.load(open('$D/out/summary.json')); print('summary:', s['status'], '|', s['message'][:400], '| steps', s['steps'], 't', s['sim_time'])"
grep -l "panicked" $D/out/logs/* 2>/dev/null | sed 's/^/PANIC in /'
true
