#!/bin/bash
# The defects a sweep of extreme scene values found (2026-12-06, docs/VALIDATION.md twenty-eighth), one line each:
# row number, exit code, first line said. After the fixes every row is refused at `check` (exit 2) naming its key,
# or runs `ok`. Run from anywhere after `cargo build --release`: bench/extreme_values.sh
cd "$(dirname "$0")/.."
C=target/release/cosim
D="${TMPDIR:-/tmp}/extreme_values"
R() { timeout 60 $C run "$@" --quiet --set run.end_time=0.002 --out "$D"/x > "$D"/o 2>&1; echo "rc=$? $(grep -v '^\s*$' "$D"/o | tail -1 | cut -c1-170)"; }
K() { timeout 30 $C check "$@" > "$D"/o 2>&1; echo "rc=$? $(head -1 "$D"/o | cut -c1-170)"; }
mkdir -p "$D"
echo "1  $(K scenes/lobovsky_dam_break.toml --set 'probe[0].radius=1e300' --set 'probe[0].normal=[1.0,0.0]')"
echo "2  $(R scenes/elastic_gate.toml --set coupling.step_timeout=1e300)"
echo "4  $(K scenes/lobovsky_dam_break.toml --set 'probe[0].radius=1e5' --set 'probe[0].normal=[1.0,0.0]')"
echo "6  $(K scenes/elastic_gate.toml --set contact.algorithm=\"particle_particle\" --set contact.thickness=1e-9)"
echo "9  $(K scenes/elastic_gate.toml --set contact.thickness=1e300)"
echo "10 $(K scenes/lobovsky_dam_break.toml --set 'probe[4].point=[0.3,-1e300]')"
echo "11 $(K scenes/elastic_gate.toml --set 'solid[0].material.density=1e300')"
echo "12 $(K scenes/elastic_gate.toml --set fluid.density=1e300)"
echo "12b $(K scenes/dam_break.toml --set fluid.density=4.9e-324)"
echo "13 $(K scenes/elastic_gate.toml --set fluid.sound_speed=1e-300)"
echo "14 $(K scenes/dam_break.toml --set fluid.artificial_viscosity=1e6)"
echo "15 $(K scenes/csm3.toml --set 'solid[0].material.density=1e-300')"
echo "16 $(K scenes/csm3.toml --set 'solid[0].damping=1e300')"
echo "16b $(K scenes/csm3.toml --set 'solid[0].damping=1e20')"
echo "17 $(K scenes/csm3.toml --set coupling.fem_cfl=1e-300)"
echo "18 $(K scenes/elastic_gate.toml --set fluid.solver=\"isph\" --set fluid.cfl=1e-300)"
echo "19 $(K scenes/csm3.toml --set 'run.gravity=[0.0,1e300]')"
echo "20 $(R scenes/elastic_gate.toml --in-process --set 'run.gravity=[0.0,-1e-30]')"
echo "21 $(K scenes/elastic_gate.toml --set contact.thickness=1.0)"
echo "22 $(K scenes/elastic_gate.toml --set 'solid[0].material.youngs_modulus=1e300')"
echo "23 $(K scenes/elastic_gate.toml --set fluid.cfl=1e-300)"
echo "25 $(K scenes/dam_break.toml --set 'run.gravity=[0.0,1e40]')"
echo "26 $(K scenes/elastic_gate.toml --set 'solid[0].min=[1e299,1e299]' --set 'solid[0].max=[1e300,1e300]' --set 'solid[0].fixed=[]')"
