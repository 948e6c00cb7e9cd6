#!/bin/bash
# repro.sh DEFECT — one reproduction per defect of sweep/REPORT.md (from the repository root: run from anywhere; the build in target/release).
# Outputs under /tmp/sweep/<case>/. Every command is bounded by `timeout`.
cd "$(dirname "$0")/../../.."
S=docs/experiments/hostile_sweep
case $1 in
  D1)  TMO=30 $S/run_ext.sh D1 sph dt_tiny 5 ;;                                   # coupling step collapse: hang
  D1b) TMO=30 $S/run_ext.sh D1b fem jump 5 ;;                                     # structure speed: crawl
  D1c) TMO=30 $S/restart.sh D1c broker.dt_contact=1e-300 ;;                       # crafted checkpoint: hang
  D2)  TMO=25 $S/run_ext.sh D2 fem pos_far 5 ;;                                   # ±1e308 positions: grid loop
  D2b) TMO=25 $S/run_ext.sh D2b fem mesh_far 5 ;;
  D3)  TMO=15 $S/run_ext.sh D3 sph setup_spacing_tiny 5 --set contact.algorithm=particle_particle ;;  # memory bomb
  D4)  $S/run_ext.sh D4 fem error_after_answer 5 ;;                               # NodeError ignored -> ok
  D5)  $S/run_ext.sh D5 fem secs_max 5 ;;                                         # summary lost
  D6)  $S/run_ext.sh D6 sph setup_spacing_tiny 5 ;;                               # setup vs scene unchecked
  D7)  rm -rf /tmp/sweep/D7; mkdir -p /tmp/sweep/D7; cp -r /tmp/sweep/ck_run/checkpoints/104 /tmp/sweep/D7/ck; python3 $S/shift_t.py /tmp/sweep/D7/ck 0.0149 && timeout 60 target/release/cosim run scenes/elastic_gate.toml --quiet --out /tmp/sweep/D7/out --restart /tmp/sweep/D7/ck --set fluid.spacing=0.006 --set run.end_time=0.02; echo rc=$? ;;
  D8)  $S/replay.sh D8 fem drop 16 ;;                                             # replay: silent partial
  D8b) $S/replay.sh D8b fem flipcrc 10 40 ;;
  D9)  TRACE=/tmp/sweep/rec_ext/out/trace EXEC="$S/exec_hostile.sh secs_nan" $S/replay.sh D9 fem none ;;
  D10) TMO=12 $S/restart.sh D10 sph.symlink=/dev/zero ;;                          # memory bomb (watch RSS)
  D10b) TMO=12 $S/restart.sh D10b sph.fifo=1 ;;                                   # hang
  D10c) mkdir -p /tmp/sweep/D10c && ln -sf /dev/zero /tmp/sweep/D10c/trace.bin && timeout 8 target/release/cosim replay /tmp/sweep/D10c/trace.bin --node fem; echo rc=$? ;;
  D11) $S/run_ext.sh D11 fem mesh_no_interface 5 ;;                               # blames sph-node
  D11b) $S/restart.sh D11b broker.roi2=inf ;;
  D12) $S/run_ext.sh D12 fem vel_huge 5 ;;                                        # fem's absurd state blamed on sph
  D12b) $S/run_ext.sh D12b sph v_huge 5 ;;
  D12c) $S/run_ext.sh D12c fem collapse_half 5 ;;
  D13) $S/run_ext.sh D13 fem pos_1e150 5 ;;                                       # absurd positions end ok
  D13b) SCENE=scenes/dam_break.toml NOSETS=1 $S/run_ext.sh D13b sph snap_v_huge 0 --set run.end_time=0.01 --set fluid.spacing=0.02; cat /tmp/sweep/D13b/out/probes.csv ;;
  D14) $S/snap_ext.sh ckpt_empty ;;
  D15) $S/run_ext.sh D15 fem mesh_reversed 5 ;;
  D16) rm -rf /tmp/sweep/D16; (timeout 60 target/release/cosim run scenes/csm3.toml --external fem --quiet --out /tmp/sweep/D16 & P=$!; sleep 3; kill -TERM $P; wait $P; echo rc=$?) ; python3 -c "import json;print(json.load(open('/tmp/sweep/D16/summary.json'))['message'])" ;;
  D17) (timeout 60 target/release/cosim run scenes/hydrostatic_plate.toml --quiet --run-id d17 --break step=3 --out /tmp/sweep/D17 --set fluid.spacing=0.1 --set 'solid[0].divisions=[20,2]' --set run.end_time=0.01 &) ; sleep 3; target/release/cosim snapshot d17 --out /tmp/sweep/D17; target/release/cosim ctl d17 resume; sleep 14; ls -la --time-style=full-iso /tmp/sweep/D17/frames/particles_0000*.vtu ;;
  D18) EXEC=$S/exec_bg.sh $S/replay.sh D18 fem none; pgrep -af "sleep 77[89]" ;;   # then kill the two sleeps by pid
  D19) REREG=50000 $S/run_ext.sh D19 fem flood_future 5; ls -la /tmp/sweep/D19/out/logs/contact-broker.log ;;
  D20) ERRMSG='first\nsecond\r\e[31mRED' $S/run_ext.sh D20 fem error_only 5 | cat -A ;;
  D21) $S/run_ext.sh D21 fem step_back 5 --set coupling.step_timeout=3 ;;
  D22) $S/replay.sh D22 fem swap 10 14 ;;
  D23) $S/restart.sh D23 fem.x0=1e300 ;;
  *) echo "usage: repro.sh D1|D1b|...|D23"; exit 2 ;;
esac
