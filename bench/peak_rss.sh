#!/usr/bin/env bash
# Peak resident memory of a command and of every process it starts (the numbers docs/PERFORMANCE.md, "Scene
# sizing", compares with `cosim check`'s estimate).
#
#   bench/peak_rss.sh COMMAND [ARG...]
#     e.g. bench/peak_rss.sh target/release/cosim run scenes/dam_break.toml --quiet --set fluid.spacing=0.000447 \
#            --set run.end_time=0.0004 --set run.output_interval=0.0002 --out /tmp/rss
#
# Samples VmRSS of every process in COMMAND's tree (threads not counted twice) every 50 ms and prints, per process
# name, the highest reading, then the highest sum over the tree ("whole"). A peak shorter than 50 ms can be missed:
# `/usr/bin/time -v` gives the exact peak of the largest single process. COMMAND's own output goes to /dev/null;
# its exit status is returned.
set -uo pipefail
[ $# -gt 0 ] || { echo "usage: bench/peak_rss.sh COMMAND [ARG...]" >&2; exit 2; }
command -v pstree > /dev/null || { echo "bench/peak_rss.sh: needs pstree (Debian: psmisc)" >&2; exit 2; }
"$@" > /dev/null 2>&1 &
root=$!
declare -A peak
whole=0
while kill -0 "$root" 2> /dev/null; do
  sum=0
  for pid in $(pstree -p -T "$root" | grep -o '([0-9]*)' | tr -d '()'); do
    kib=$(awk '/^VmRSS/ {print $2}' "/proc/$pid/status" 2> /dev/null)
    [ -n "$kib" ] || continue
    name=$(cat "/proc/$pid/comm" 2> /dev/null)
    sum=$((sum + kib))
    [ "${peak[$name]:-0}" -ge "$kib" ] || peak[$name]=$kib
  done
  [ "$whole" -ge "$sum" ] || whole=$sum
  sleep 0.05
done
wait "$root"
status=$?
for name in "${!peak[@]}"; do
  awk -v n="$name" -v k="${peak[$name]}" 'BEGIN {printf "%s %.1f MiB\n", n, k / 1024}'
done | sort
awk -v k="$whole" 'BEGIN {printf "whole %.1f MiB\n", k / 1024}'
exit "$status"
