#!/bin/bash
# replay.sh CASE NODE OP ARGS... — damage ${TRACE:-/tmp/sweep/rec/trace} with trace_edit.py and replay it (EXEC=... for --exec)
CASE=$1; NODE=$2; shift 2
cd "$(dirname "$0")/../../.."; D=/tmp/sweep/$CASE; rm -rf $D; mkdir -p $D
[ "$1" != "none" ] && python3 sweep/trace_edit.py ${TRACE:-/tmp/sweep/rec/trace} $D/trace "$@" 2>/dev/null || cp -r ${TRACE:-/tmp/sweep/rec/trace} $D/trace
START=$(date +%s.%N)
timeout ${TMO:-60} target/release/cosim replay $D/trace --node $NODE ${EXEC:+--exec "$EXEC"} --timeout ${RT:-10} ${RARGS} >$D/stdout 2>$D/stderr
RC=$?
printf "== %s: rc=%s wall=%.1fs\n" $CASE $RC $(echo "$(date +%s.%N) - $START" | bc)
cat $D/stdout | head -c 600; head -c 800 $D/stderr
grep -l panicked $D/stderr $D/stdout 2>/dev/null | sed 's/^/PANIC /'
true
