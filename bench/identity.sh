#!/usr/bin/env bash
# Bit-identity check for refactors: runs every shipped scene (short, coarse) and its solver/contact variants,
# in-process and as processes, with checkpoints and a restart from the middle one, and writes one line per output
# file, `sha256  case/path`, to MANIFEST (summary.json with its wall-clock fields removed).
#
#   bench/identity.sh OUT_DIR > before.txt        # on the old commit's build
#   bench/identity.sh OUT_DIR > after.txt         # on the new one
#   diff before.txt after.txt                     # empty: probes, frames, plots and summaries byte-identical
#
# Checkpoint files are listed apart (`ckpt` lines): a checkpoint format change alters their bytes by design; what
# must hold then is that the restart from them gives the same probes and frames (`restart` cases).
# Each case has a fixed run id (checkpoints hold it). COSIM (default target/release/cosim) picks the build.
set -euo pipefail
out=${1:?usage: bench/identity.sh OUT_DIR}
cosim=${COSIM:-target/release/cosim}
rm -rf "$out"; mkdir -p "$out"

run() { # case scene mode [--set ...]
  local name=$1 scene=$2 mode=$3; shift 3
  local flags=(-q --out "$out/$name" --run-id "identity-$name")
  [[ $mode == in ]] && flags+=(--in-process)
  "$cosim" run "scenes/$scene.toml" "${flags[@]}" "$@" >"$out/$name.log" 2>&1 || {
    echo "identity: case $name failed, see $out/$name.log" >&2; tail -3 "$out/$name.log" >&2; exit 1; }
}

# name                   scene              mode  overrides
run csm3                 csm3               in    --set run.end_time=0.5
run csm3_proc            csm3               proc  --set run.end_time=0.5
run dam_wcsph            dam_break          in    --set run.end_time=0.06 --set fluid.spacing=0.01 --checkpoint-interval 0.02
run dam_wcsph_proc       dam_break          proc  --set run.end_time=0.06 --set fluid.spacing=0.01
run dam_isph             dam_break          in    --set run.end_time=0.06 --set fluid.spacing=0.01 --set fluid.solver=isph --checkpoint-interval 0.02
run dam_delta            dam_break          in    --set run.end_time=0.06 --set fluid.spacing=0.01 --set fluid.density_diffusion=0.1 --set fluid.density_filter=none
run dam_mls              dam_break          in    --set run.end_time=0.06 --set fluid.spacing=0.01 --set fluid.density_filter=mls --set fluid.apd=0
run plate                hydrostatic_plate  in    --set run.end_time=0.02 --checkpoint-interval 0.0073
run plate_isph           hydrostatic_plate  in    --set run.end_time=0.02 --set fluid.solver=isph
run gate                 elastic_gate       in    --set run.end_time=0.02 --set fluid.spacing=0.004 --checkpoint-interval 0.01
run gate_proc            elastic_gate       proc  --set run.end_time=0.02 --set fluid.spacing=0.004 --checkpoint-interval 0.01
run gate_pp              elastic_gate       in    --set run.end_time=0.02 --set fluid.spacing=0.004 --set contact.algorithm=particle_particle
run gate_none            elastic_gate       in    --set run.end_time=0.02 --set fluid.spacing=0.004 --set contact.algorithm=none
run gate_isph            elastic_gate       in    --set run.end_time=0.02 --set fluid.spacing=0.004 --set fluid.solver=isph --checkpoint-interval 0.01
run obstacle             elastic_obstacle   in    --set run.end_time=0.02 --checkpoint-interval 0.01
run bench5000            bench_5000         in    --set run.end_time=0.05
run lobovsky             lobovsky_dam_break in    --set run.end_time=0.03 --set fluid.spacing=0.02 --set coupling.max_dt=2.5e-4 --checkpoint-interval 0.0105
run lobovsky_isph        lobovsky_dam_break in    --set run.end_time=0.03 --set fluid.spacing=0.02 --set fluid.solver=isph --set coupling.max_dt=2.5e-4 --checkpoint-interval 0.0105

# Restarts from a middle checkpoint, to the same end: their probes and frames must equal the uninterrupted runs'.
restart() { # name from_case scene mode [--set ...]
  local name=$1 from=$2 scene=$3 mode=$4; shift 4
  local ck; ck=$(ls -d "$out/$from"/checkpoints/* | sort -t/ -k"$(($(tr -cd / <<<"$out/$from/checkpoints/" | wc -c)+1))" -n | head -1)
  run "$name" "$scene" "$mode" --restart "$ck" "$@"
}
restart dam_wcsph_restart  dam_wcsph  dam_break         in   --set run.end_time=0.06 --set fluid.spacing=0.01
restart dam_isph_restart   dam_isph   dam_break         in   --set run.end_time=0.06 --set fluid.spacing=0.01 --set fluid.solver=isph
restart plate_restart      plate      hydrostatic_plate in   --set run.end_time=0.02
restart gate_restart       gate       elastic_gate      in   --set run.end_time=0.02 --set fluid.spacing=0.004
restart gate_proc_restart  gate_proc  elastic_gate      proc --set run.end_time=0.02 --set fluid.spacing=0.004
restart gate_isph_restart  gate_isph  elastic_gate      in   --set run.end_time=0.02 --set fluid.spacing=0.004 --set fluid.solver=isph
restart obstacle_restart   obstacle   elastic_obstacle  in   --set run.end_time=0.02
restart lobovsky_restart   lobovsky   lobovsky_dam_break in  --set run.end_time=0.03 --set fluid.spacing=0.02 --set coupling.max_dt=2.5e-4
restart lobovsky_isph_restart lobovsky_isph lobovsky_dam_break in --set run.end_time=0.03 --set fluid.spacing=0.02 --set fluid.solver=isph --set coupling.max_dt=2.5e-4

cd "$out"
find . -type f ! -name '*.log' | sort | while read -r f; do
  case $f in
    */summary.json)
      h=$(python3 -c 'import json,sys; s=json.load(open(sys.argv[1]))
for k in ("wall_seconds","timings","run_id","mode"): s.pop(k,None)
print(json.dumps(s,sort_keys=True))' "$f" | sha256sum | cut -c1-16); echo "$h  $f";;
    */checkpoint.json)
      h=$(python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); s.pop("write_seconds",None); s["files"]["broker.bin"].pop("crc32",None)
print(json.dumps(s,sort_keys=True))' "$f" | sha256sum | cut -c1-16); echo "ckpt $h  $f";;
    */broker.bin) echo "ckpt bytes=$(stat -c %s "$f")  $f";;  # holds the run's wall-clock timings
    */checkpoints/*) echo "ckpt $(sha256sum "$f" | cut -c1-16)  $f";;
    */external.json) ;;
    *) echo "$(sha256sum "$f" | cut -c1-16)  $f";;
  esac
done
