#!/usr/bin/env bash
# DualSPHysics 5.4 on the Lobovsky dam break (H = 0.3 m), read with our sensors, scored as ours (issue 16).
#
#   bench/dualsphysics/lobovsky.sh DSPH_BIN GENCASE OUT [RUN...]
#     DSPH_BIN, GENCASE  as for compare.sh (README.md: how to build and where GenCase comes from)
#     OUT                folder for the runs; each RUN gets OUT/RUN/probes.csv, which bench/lobovsky_score.py scores
#     RUN                ours30 ours60 (DualSPHysics with our settings: cubic spline, h = 1.3 dp, c0 = 10 sqrt(2 g H)
#                        = 24.26 m/s) and own30 own60 (its own defaults: Wendland, h = sqrt(2) dp, c0 = 20 sqrt(g H));
#                        30 / 60: dp = H/30, H/60. Default: ours30 own30.
# Both with DBC walls, artificial viscosity 0.02, Fourtakas density diffusion 0.1, symplectic, CFL 0.2, no shifting
# (lobovsky/lobovsky_Def.xml.in). The Sensors gauge gives the Shepard mean of the fluid's density at sensors 1 and 2
# half a spacing in front of the wall every step; lobovsky/lobovsky.py turns it into pressure (the case's Tait law)
# and into our probe columns (1 ms means and instants).
set -euo pipefail
usage="usage: lobovsky.sh DSPH_BIN GENCASE OUT [ours30 ours60 own30 own60]"
ds=$(readlink -f "${1:?$usage}"); gencase=$(readlink -f "${2:?$usage}"); out=${3:?$usage}
shift 3
runs=("$@"); [[ ${#runs[@]} -gt 0 ]] || runs=(ours30 own30)
here=$(cd "$(dirname "$0")" && pwd)
[[ -x $ds && -x $gencase ]] || { echo "lobovsky.sh: $ds or $gencase is not executable" >&2; exit 2; }
mkdir -p "$out"; out=$(cd "$out" && pwd)
for r in "${runs[@]}"; do
  case $r in
    ours30) args=(0.01 1 1.3 24.2611) ;;
    ours60) args=(0.005 1 1.3 24.2611) ;;
    own30) args=(0.01 2 1.4142136 auto) ;;
    own60) args=(0.005 2 1.4142136 auto) ;;
    *) echo "lobovsky.sh: unknown run $r ($usage)" >&2; exit 2 ;;
  esac
  d=$out/$r; rm -rf "$d"; mkdir -p "$d"
  python3 "$here/lobovsky/lobovsky.py" case "${args[@]}" >"$d/lob_Def.xml"
  (cd "$d" && "$gencase" lob_Def case/lob -save:all >gencase.log 2>&1) || { echo "lobovsky.sh: GenCase failed, see $d/gencase.log" >&2; exit 1; }
  (cd "$d" && /usr/bin/time -f "%U %S %e %M" -o time.txt "$ds" case/lob run >run.log 2>&1) || {
    echo "lobovsky.sh: DualSPHysics failed, see $d/run.log" >&2; exit 1; }
  c0=$(grep -o 'Cs0=[0-9.]*' "$d/run/Run.out" | cut -d= -f2)
  python3 "$here/lobovsky/lobovsky.py" probes "$d/run/GaugesMesh_Sensors_Rhop.csv" "$c0" >"$d/probes.csv"
  echo "$r: c0 $c0 m/s, user/sys/wall s, max RSS kB: $(cat "$d/time.txt")"
done
