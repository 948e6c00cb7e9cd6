#!/usr/bin/env bash
# Side-by-side speed comparison of our WCSPH with DualSPHysics 5.4 (CPU) on the same 2D dam break (issue 20).
# How the cases were made and what differs between the two codes: bench/dualsphysics/README.md.
#
#   bench/dualsphysics/compare.sh DSPH_BIN GENCASE OUT [CASE...]
#     DSPH_BIN  DualSPHysics5.4CPU_linux64, built from source (README.md)
#     GENCASE   GenCase_linux64 of the DualSPHysics repository (makes the .bi4 cases from the XML here)
#     OUT       folder for the runs, the log and summary_medians.json
#     CASE      20kA 20kB 80kA 80kB (1 thread, 3 pairs each) and 20kA2 20kB2 80kA2 80kB2 (2 threads, 1 pair);
#               default: the four 1-thread cases
#   COSIM="name=path name=path"  our builds to time (default: ours=target/release/cosim); each pair runs every
#               build of ours, then DualSPHysics, so that all of them meet the same machine state
#   PAIRS=N     pairs per case (default 3 for 1 thread, 1 for 2 threads)
#
# Every run is timed by /usr/bin/time -v (CPU = user + sys, wall, peak RSS). Then:
#   python3 bench/dualsphysics/parse.py OUT      # medians per case and build, and the ratios against DualSPHysics
# Run it on a quiet machine (nothing else running): the load average goes into OUT/log.txt with every run.
set -euo pipefail
ds=${1:?usage: compare.sh DSPH_BIN GENCASE OUT [CASE...]}
gencase=${2:?usage: compare.sh DSPH_BIN GENCASE OUT [CASE...]}
out=${3:?usage: compare.sh DSPH_BIN GENCASE OUT [CASE...]}
shift 3
cases=("$@")
[[ ${#cases[@]} -gt 0 ]] || cases=(20kA 20kB 80kA 80kB)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
ds=$(readlink -f "$ds")
gencase=$(readlink -f "$gencase")
[[ -x $ds ]] || { echo "compare.sh: DualSPHysics binary $ds is not executable" >&2; exit 2; }
[[ -x $gencase ]] || { echo "compare.sh: GenCase binary $gencase is not executable" >&2; exit 2; }
command -v /usr/bin/time >/dev/null || { echo "compare.sh: needs /usr/bin/time (Debian package time)" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
log=$out/log.txt
read -r -a builds <<<"${COSIM:-ours=$repo/target/release/cosim}"
for b in "${builds[@]}"; do
  [[ $b == *=* && -x ${b#*=} ]] || { echo "compare.sh: COSIM entry '$b' is not name=executable" >&2; exit 2; }
done

# The .bi4 case of each XML, made once (GenCase writes next to its output name).
make_case() { # case
  local c=$1
  [[ -f $out/cases/${c}_out/$c.bi4 ]] && return
  mkdir -p "$out/cases"
  cp "$here/${c}_Def.xml" "$out/cases/"
  (cd "$out/cases" && "$gencase" "${c}_Def" "${c}_out/$c" -save:all >"${c}_gencase.log" 2>&1) || {
    echo "compare.sh: GenCase failed for $c, see $out/cases/${c}_gencase.log" >&2; exit 1; }
}

run_ours() { # tag cosim spacing end cfg threads
  local tag=$1 bin=$2 sp=$3 end=$4 cfg=$5 th=$6
  local dir=$out/$tag extra=()
  rm -rf "$dir"
  [[ $cfg == A ]] && extra=(--set fluid.apd=0)
  (cd "$repo" && /usr/bin/time -v -o "$dir.time" "$bin" run scenes/dam_break.toml --in-process --threads "$th" \
    --quiet --out "$dir" --set fluid.spacing="$sp" --set run.end_time="$end" --set run.output_interval=1.0 \
    "${extra[@]}" >"$dir.stdout" 2>&1)
}

run_ds() { # tag case threads
  local tag=$1 c=$2 th=$3
  local dir=$out/$tag
  rm -rf "$dir"
  (cd "$out/cases" && /usr/bin/time -v -o "$dir.time" "$ds" "${c}_out/$c" "$dir" -ompthreads:"$th" \
    >"$dir.stdout" 2>&1)
}

pairs() { # size cfg spacing end threads n
  local size=$1 cfg=$2 sp=$3 end=$4 th=$5 n=$6 c="d$1$2"
  make_case "$c"
  for i in $(seq 1 "$n"); do
    for b in "${builds[@]}"; do
      echo "$(date +%T) ${b%%=*} ${size}${cfg} t$th #$i load: $(cut -d' ' -f1-3 /proc/loadavg)" >>"$log"
      run_ours "${b%%=*}_${size}${cfg}_t${th}_$i" "${b#*=}" "$sp" "$end" "$cfg" "$th"
    done
    echo "$(date +%T) ds ${size}${cfg} t$th #$i load: $(cut -d' ' -f1-3 /proc/loadavg)" >>"$log"
    run_ds "ds_${size}${cfg}_t${th}_$i" "$c" "$th"
  done
}

for g in "${cases[@]}"; do
  case $g in
    20kA | 20kB) pairs 20k "${g:3:1}" 0.001 0.1 1 "${PAIRS:-3}" ;;
    80kA | 80kB) pairs 80k "${g:3:1}" 0.0005 0.02 1 "${PAIRS:-3}" ;;
    20kA2 | 20kB2) pairs 20k "${g:3:1}" 0.001 0.1 2 "${PAIRS:-1}" ;;
    80kA2 | 80kB2) pairs 80k "${g:3:1}" 0.0005 0.02 2 "${PAIRS:-1}" ;;
    *) echo "compare.sh: unknown case $g (20kA 20kB 80kA 80kB, or with a 2 for two threads)" >&2; exit 2 ;;
  esac
done
echo "$(date +%T) done: ${cases[*]}" >>"$log"
