//! The coupled run's energy balance (`contact_broker::energy_balance`): the ISPH gate and a falling solid, whose
//! fluid and structure together must not gain energy beyond the bound, and a run that does must say so.

use super::*;

/// The scene's gate (E = 12 MPa) with ISPH at Δx = 4 mm to t = 0.2 s, at `coupling.max_dt = 1e-2` s (the coupling
/// never caps the ISPH step; the scene's 1e-4 s is the next test, which passes): the fluid's energy must stay
/// within the growth bound, as it does with WCSPH (measured: WCSPH +0.0009 of the budget, then falls steadily).
/// Measured after the PPE's void rows (`sph-node/src/isph/ppe.rs`): +0.242 of the budget at max_dt 1e-4 (was
/// +0.24–0.26), +0.145 at 1e-2 (was +0.258). Split per part of the step (2026-11-22, closed to 1e-13 J/m per step;
/// docs/PERFORMANCE.md "Stress tests"): at 1e-4 the corrector makes +8.74 J/m and the contact's velocity
/// corrections take −6.33 back (positions −0.09, viscosity −0.005, gravity and XSPH 0): +2.31 J/m = +0.240 E_b.
/// Half of the +8.74 is made in 20 steps, on rows against the gate: the PPE source replaces their normal velocity
/// by the face's (`isph::contact::face_normal_velocity`), and where that face is a neighbour's (a convex-corner
/// normal under the gate's tip) or the particle is not really moving with it, the mismatch (≈ 1 m/s) becomes
/// ρ Δv Δx/Δt ≈ 190 kPa, which the corrector's truncated gradient turns into a kick of 4.6 m/s into the gate. At 1e-2
/// the same happens on the particles the contact holds: a contact point on the gate's face is ≈ 15 times lighter
/// than a particle, so the contact's impulses move the nodes and the particles keep approaching at up to 4 m/s.
/// 2026-11-27 (night), at 1e-4, frames every step around the first large gain: at t = 0.1019 s nine particles along
/// the deflected gate's underside (the top layer of the jet under it, x = 0.126–0.147 m, y = 3–26 mm), all free
/// surface (p = 0) the step before, carry 30–68 kPa and gain 0.165 J/m (+0.017 of the budget) in one step; the
/// next three steps add +0.024. Instrumented (not committed): in that step the contact face of the particles under
/// the tip jumps from the tip's underside (n = (−0.13, −0.99)) to the plane of the gate's upstream face (n = (−0.74,
/// −0.67)), inherited from a neighbour (`isph::contact::contact_rows_into` takes the first neighbour's face that cuts
/// the support); the jet flowing under the tip at (1.1, 0.2) m/s then "approaches" that plane at 0.95 m/s, the PPE
/// source stops it (ρ u Δx/Δt ≈ 38 kPa) and the whole jet under the gate goes from clipped suction (p = 0) to 35–68
/// kPa. Choosing the candidate face the particle is furthest in front of (the separating plane of a convex corner)
/// instead: +0.068 (from +0.071 in that run, output every 2 ms), the kicks at other times remain.
/// 2026-11-28 (ninth): at 1e-2 the gain is chaotic, 0.533 / 0.055 / 0.017 of the budget with outputs every 5 / 2 / 1
/// ms (which end coupling steps elsewhere); the structure's own face velocity, sent by the broker, does not hold it
/// at every setting either (docs/CORRECTIONS.md "The structure's own face velocity, sent by the broker").
/// The gate of `assert_isph_gate` at `coupling.max_dt` with the structure's energy as the first probe, and `more`
/// settings.
fn isph_gate(max_dt: &str, more: &[&str]) -> Outcome {
    let mut sets = gate(GATE_E, &["fluid.solver=isph", &format!("coupling.max_dt={max_dt}")]);
    sets.extend(more.iter().map(|s| s.to_string()));
    sets.push("probe[0]={name=\"structure\",kind=\"energy\",part=\"total\",of=\"structure\"}".into());
    // Tests run side by side: one folder and run id per setting, the extra keys by their FNV-1a hash.
    let tag = more
        .iter()
        .flat_map(|s| s.bytes().chain([0]))
        .fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
        });
    run(
        &format!("gate-isph-{}-{tag:016x}", max_dt.replace('-', "m")),
        "scenes/elastic_gate.toml",
        &sets,
    )
}

/// The largest gain of summary.json's `energy_growth` (a fraction of its budget): checked against the `energy`
/// (fluid) and `structure` probes of the same output times (to round-off) and its budget against the lattice's,
/// Σ m g (h − h_min) = ρ g W Δx² n (n − 1)/2 for the gate's n = H/Δx = 35 rows of W/Δx = 25 particles; and the
/// run's warning is printed exactly when the gain passes `WARN_GROWTH`.
fn assert_energy_balance(case: &str, out: &Outcome) -> f64 {
    let g = &out.summary["energy_growth"];
    let field = |k: &str| {
        g[k].as_f64()
            .unwrap_or_else(|| panic!("{case}: energy_growth.{k} in {g}"))
    };
    let (largest, at, budget) = (field("largest"), field("at"), field("budget"));
    let lattice = RHO0 * G * 0.1 * 0.004 * 0.004 * 35.0 * 34.0 / 2.0;
    assert!(
        (budget / lattice - 1.0).abs() < 1e-9,
        "{case}: budget {budget} J/m, lattice {lattice}"
    );
    let (fluid, structure) = (out.probe("energy"), out.probe("structure"));
    let total: Vec<f64> = fluid.iter().zip(&structure).map(|(f, s)| f + s).collect();
    let (k, gain) = total
        .iter()
        .map(|e| e - total[0])
        .enumerate()
        .fold((0, 0.0), |best, (k, e)| if e > best.1 { (k, e) } else { best });
    assert!(
        (largest * budget - gain).abs() <= 1e-9 * budget,
        "{case}: summary {largest} × {budget} J/m against the probes' {gain} J/m"
    );
    let t: Vec<f64> = out.rows.iter().map(|r| r[0]).collect();
    assert_eq!(at, t[k], "{case}: the largest gain's time");
    let warned = out
        .stderr
        .contains("cosim: warning: the fluid and the structure gained");
    assert_eq!(
        warned,
        largest > WARN_GROWTH,
        "{case}: {largest} of the budget; stderr: {}",
        out.stderr
    );
    largest
}

/// The run's energy balance warns where a run made energy: the gate of the test below without the bound the
/// structure's speed sets on the coupling step (`coupling.structure_courant = 0`, as every run was before
/// 2026-12-02) gains its whole budget, fluid and structure together, by t = 0.165 s (measured 2026-11-29: 1.057 of
/// 9.339 J/m) and ends `ok`,
/// the symptom the summary's `energy_growth` and the warning are for (`contact_broker::energy_balance`). The warning
/// names a coupling step to try, half the run's mean step to one digit (`energy_balance::shorter_step`: 1.54e-4 s
/// here, so 7e-5), and the same gate run at that step stays within the bound (measured: 0.057 of the budget).
/// Both runs solve the pressure to 1e-8, the tolerance these figures were measured at: at the default 1e-6 the
/// gain at 1e-2 grows past twice the budget and the fluid node stops the run as unstable at t = 0.158 s (the
/// trajectory of an overlong coupling step follows the last bits; measured 2026-11-29, fourteenth session).
#[test]
fn a_run_that_makes_energy_says_so() {
    const TIGHT: &str = "fluid.ppe_tolerance=1e-8";
    const UNBOUNDED: &str = "coupling.structure_courant=0";
    let case = "elastic gate isph, coupling.max_dt = 1e-2, coupling.structure_courant = 0";
    let out = isph_gate("1e-2", &[TIGHT, UNBOUNDED]);
    out.assert_ok_and_finite(case);
    let growth = assert_energy_balance(case, &out);
    assert!(
        growth > WARN_GROWTH,
        "{case}: {growth:.4} of the budget: no longer a run that makes energy"
    );
    let (steps, t) = (
        out.summary["steps"].as_u64().expect("steps"),
        out.summary["sim_time"].as_f64().expect("sim_time"),
    );
    let hint = out
        .stderr
        .split("--set coupling.max_dt=")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .unwrap_or_else(|| panic!("{case}: no coupling step suggested; stderr: {}", out.stderr));
    let dt: f64 = hint.parse().expect("the suggested step");
    assert!(
        out.stderr.contains("--set coupling.structure_courant=0.05 (now 0)"),
        "{case}: the structure's Courant number not suggested; stderr: {}",
        out.stderr
    );
    assert!(
        out.stderr.contains("--set solid[0].mesh_damping=0.02"),
        "{case}: the mesh damping not suggested; stderr: {}",
        out.stderr
    );
    let mean = t / steps as f64;
    // One significant digit, at most half the mean step and more than a fifth of it.
    assert!(
        dt <= 0.5 * mean && dt > 0.2 * mean && hint.trim_start_matches(|c: char| c.is_ascii_digit()).starts_with('e'),
        "{case}: suggested {hint} for a mean step of {mean:e} s"
    );
    let case =
        format!("elastic gate isph, coupling.max_dt = {hint} (the step suggested), coupling.structure_courant = 0");
    let out = isph_gate(hint, &[TIGHT, UNBOUNDED]);
    out.assert_ok_and_finite(&case);
    let growth = assert_energy_balance(&case, &out);
    assert!(
        growth <= WARN_GROWTH,
        "{case}: {growth:.4} of the budget: the suggested step does not help"
    );
}

/// The gate at ISPH's own step (`coupling.max_dt = 1e-2`, ~4.8e-4 s, ~115 of the gate's FE steps): ends ok with
/// fluid + structure within `WARN_GROWTH` and the fluid within `GROWTH` of the budget. Found by this test and ignored
/// from 2026-11-28 to 2026-12-02: the coupled energy grew with the structure's surface moving a large part of h
/// between two contact passes (unstable at t = 0.158 s with the pressure solved to the default 1e-6; 1.057 of the
/// budget to 1e-8, `a_run_that_makes_energy_says_so`; 0.07–0.13 with `solid[0].mesh_damping = 0.25`). With the
/// coupling step bounded by the structure's speed (`coupling.structure_courant`, 0.05 h / |v|_max; docs/CORRECTIONS.md
/// "The coupling step bounded by the structure's speed"), measured 2026-12-02: 0.056 of the budget, and 0.054 / 0.082
/// / 0.068 with output every 2 / 1 / 2.5 ms; the fluid's own gain at most 0.0076.
#[test]
fn isph_elastic_gate_stays_within_the_energy_bound() {
    assert_isph_gate("1e-2");
}

/// The gate of the test above at ISPH's own step (`coupling.max_dt = 1e-2`) without the structure's bound on the
/// step (`coupling.structure_courant = 0`, so these figures stand as measured) and with the structure's share of
/// the contact impulses spread over two fluid spacings along its surface (`contact.load_spread = 2`,
/// contact-broker/src/load_spread.rs): it ends `ok` with less than its energy budget gained, where without the spread
/// it stops unstable at t = 0.158 s. Measured 2026-11-29 (fifteenth): 0.173 of the budget, and 0.087 / 0.129 / 0.425
/// with output every 2 / 1 / 2.5 ms (the gain at this step follows the trajectory's last bits; docs/CORRECTIONS.md
/// "The structure's mesh against the fluid's particles"); the bound is the budget itself.
#[test]
fn isph_gate_at_its_own_step_ends_with_the_load_spread() {
    let case = "elastic gate isph, coupling.max_dt = 1e-2, contact.load_spread = 2";
    let out = isph_gate("1e-2", &["contact.load_spread=2", "coupling.structure_courant=0"]);
    out.assert_ok_and_finite(case);
    let growth = assert_energy_balance(case, &out);
    assert!(growth < 1.0, "{case}: {growth:.4} of the budget gained");
}

/// The same gate at ISPH's own step without the structure's bound on the step, with its mesh-scale ringing damped
/// (`solid[0].mesh_damping = 0.25`: stiffness-proportional damping, a ratio of 0.25 at the mesh's highest mode,
/// 5e-5 at the gate's first bending mode; fem-node/src/solver/central_difference.rs): it ends `ok` where the undamped
/// run stops unstable at t = 0.158 s. Measured 2026-12-01 (sixteenth): 0.116 of the budget, and 0.133 / 0.074 / 0.128
/// with output every 2 / 1 / 2.5 ms (docs/CORRECTIONS.md "Damping the structure's mesh-scale ringing"); the bound is
/// half the budget.
#[test]
fn isph_gate_at_its_own_step_ends_with_mesh_damping() {
    let case = "elastic gate isph, coupling.max_dt = 1e-2, solid[0].mesh_damping = 0.25";
    let out = isph_gate("1e-2", &["solid[0].mesh_damping=0.25", "coupling.structure_courant=0"]);
    out.assert_ok_and_finite(case);
    let growth = assert_energy_balance(case, &out);
    assert!(growth < 0.5, "{case}: {growth:.4} of the budget gained");
}

/// ISPH + `particle_particle` on the 4 mm gate heats the structure linearly, the light mesh ringing under the
/// particles' force (+11.2 J/m by t = 0.2 s, +24.3 by 0.4 s; docs/CORRECTIONS.md "ISPH + `particle_particle`"). With
/// the mesh's ringing damped (`solid[0].mesh_damping = 0.25`) it holds 0.93 J/m at 0.2 s and 0.68 at 0.4 s, and the
/// fluid and the structure together gain at most 0.49 of the budget, at the impact (t = 0.065–0.08 s), against
/// 1.26 by 0.2 s undamped (measured 2026-12-01, sixteenth). Bounds: the structure's energy at 0.2 s under 2 J/m, the
/// largest gain under 0.75 of the budget.
#[test]
fn isph_particle_particle_gate_stops_heating_with_mesh_damping() {
    let case = "elastic gate isph + particle_particle, solid[0].mesh_damping = 0.25";
    let out = isph_gate(
        "1e-4",
        &[
            "contact.algorithm=particle_particle",
            "solid[0].mesh_damping=0.25",
            "coupling.structure_courant=0",
        ],
    );
    out.assert_ok_and_finite(case);
    let growth = assert_energy_balance(case, &out);
    let structure = out.probe("structure");
    let last = structure[structure.len() - 1];
    eprintln!(
        "{case}: structure {last:.3} J/m at the end, largest gain {growth:.4} of the budget, {:.1} s wall",
        out.wall
    );
    assert!(last < 2.0, "{case}: the structure holds {last:.3} J/m at the end");
    assert!(growth < 0.75, "{case}: {growth:.4} of the budget gained");
}

/// The scene's own coupling step, `coupling.max_dt = 1e-4` s, of the gate above (about 9 s): within the growth
/// bound since an inherited contact face must stand for the structure near the particle
/// (`isph::contact::ContactLayer::inherited_face`; measured 2026-11-28 eighth: +0.0003 of the budget, was +0.064;
/// taking the first neighbour's face again, this test fails). Fluid + structure together gain +0.054 of the
/// budget (was +0.186; WCSPH +0.0014): docs/CORRECTIONS.md "The coupled ISPH gate creates energy".
#[test]
fn isph_elastic_gate_at_the_scenes_coupling_step_stays_within_the_energy_bound() {
    assert_isph_gate("1e-4");
}

/// The gate scene (E = 12 MPa) with ISPH at Δx = 4 mm to t = 0.2 s at `coupling.max_dt`: ends ok with the fluid's
/// energy within the growth and floor bounds, and the summary's energy balance is that of the probes.
fn assert_isph_gate(max_dt: &str) {
    let budget = budget(&GATE_BLOCKS);
    let releasable = releasable(&GATE_BLOCKS, GATE_FLOOR);
    let case = format!("elastic gate isph, coupling.max_dt = {max_dt}");
    let out = isph_gate(max_dt, &[]);
    out.assert_ok_and_finite(&case);
    let growth = assert_energy_balance(&case, &out);
    assert!(
        growth <= WARN_GROWTH,
        "{case}: {growth:.4} of the budget gained together"
    );
    let e = out.probe("energy");
    eprintln!(
        "{case}: energy max {:+.4} / end {:+.4} of the budget, {:.1} s wall",
        e.iter().copied().fold(f64::NEG_INFINITY, f64::max) / budget,
        e[e.len() - 1] / budget,
        out.wall
    );
    let energy = assert_energy(&case, &out, budget, releasable);
    report(&case, &out, energy);
}

/// A solid so heavy that its own energies dwarf the water's is not read as making energy: the gate at ρ = 1e20
/// kg/m³ falls under its weight (its wave speed is 3.5e-7 m/s), trading ~1e14 J/m of gravitational for kinetic
/// energy by t = 0.01 s, and the sum of the two moved by ~9 J/m of rounding (multiples of 1/32 J/m, the spacing of
/// doubles there), 0.16 of the water's 9.48 J/m budget: before the balance counted its rounding
/// (`Probes::energy_rounding`), the run ended with the warning that the scheme had made energy. Now the gain is
/// within the rounding, the summary says how large that is (`energy_growth.rounding`, 24 of the budget measured
/// 2026-12-06), and `cosim run` notes that the balance cannot see a gain under twice it. At the scene's density
/// (1100) the rounding is ~1e-10 of the budget, the balance as before.
#[test]
fn a_falling_solid_heavier_than_the_water_by_1e17_makes_no_energy() {
    let sets = |rho: &str| -> Vec<String> {
        [
            "run.end_time=0.01",
            "run.output_interval=0.001",
            &format!("solid[0].material.density={rho}"),
        ]
        .map(String::from)
        .into()
    };
    let heavy = run("heavy-gate", "scenes/elastic_gate.toml", &sets("1e20"));
    heavy.assert_ok_and_finite("gate at ρ_s = 1e20");
    let g = &heavy.summary["energy_growth"];
    let (largest, rounding) = (g["largest"].as_f64(), g["rounding"].as_f64());
    let (Some(largest), Some(rounding)) = (largest, rounding) else {
        panic!("gate at ρ_s = 1e20: energy_growth {g}")
    };
    assert!(
        largest <= WARN_GROWTH,
        "gate at ρ_s = 1e20: a gain of {largest} of the budget; {g}"
    );
    assert!(
        rounding > WARN_GROWTH,
        "gate at ρ_s = 1e20: rounding {rounding} of the budget; {g}"
    );
    assert!(!heavy.stderr.contains("cosim: warning"), "{}", heavy.stderr);
    assert!(
        heavy
            .stderr
            .contains("cosim: note: the energy balance cannot see a gain under"),
        "{}",
        heavy.stderr
    );
    let shipped = run("shipped-gate", "scenes/elastic_gate.toml", &sets("1100"));
    shipped.assert_ok_and_finite("gate at ρ_s = 1100");
    let rounding = shipped.summary["energy_growth"]["rounding"]
        .as_f64()
        .unwrap_or(f64::NAN);
    assert!(rounding < 1e-9, "gate at ρ_s = 1100: rounding {rounding} of the budget");
    assert!(!shipped.stderr.contains("cosim: note"), "{}", shipped.stderr);
}
