//! The bench suite: which scenes run at which spacings, with which solver and contact algorithm, for how long.
//!
//! `--quick` (under 10 minutes on a 2-core machine) uses coarse spacings and, where the metric allows, shortened
//! end times; the full suite refines further and runs the scenes' own end times. [`Case::describe`] is what
//! `report.md` says each case runs.

use std::path::{Path, PathBuf};

/// Which reference a case is measured against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// Surge front against Martin & Moyce (1952).
    DamBreak,
    /// Mean mid-span deflection after the transient against the clamped-plate formula.
    Plate,
    /// Peak horizontal displacement of the free end against the published 0.043 m.
    Gate,
    /// Wall-impact pressure at sensors 1 and 2 against Lobovsky et al. (2014) (`bench/lobovsky.rs`).
    Lobovsky,
    /// No error: cost per particle-step only.
    Scaling,
    /// No error: status and the fluid's energy against its budget (stress tests of numerical stability).
    Stress,
}

/// One run of the suite.
#[derive(Clone, Debug)]
pub struct Case {
    /// `dam_break` | `hydrostatic_plate` | `elastic_gate` | `scaling` | `stress`.
    pub case: &'static str,
    /// Which stress test (`still_tank`, `tall_dam_break`, …); empty for the other cases.
    pub variant: &'static str,
    /// Scene file.
    pub scene: PathBuf,
    /// `wcsph` | `isph`.
    pub solver: &'static str,
    /// `particle_element` | `particle_particle` | `none`.
    pub contact: &'static str,
    /// Fluid spacing [m].
    pub spacing: f64,
    /// Simulated end time [s].
    pub end_time: f64,
    /// Worker threads (`--threads`); `None`: all cores.
    pub threads: Option<usize>,
    /// Runs of the case; the record kept is the one with the median fluid cost per particle-step (the scaling
    /// runs are short, and another program taking a core for a second would skew a single one).
    pub repeats: usize,
    /// Further `--set` overrides beyond solver, contact, spacing and end time.
    pub extra: Vec<String>,
    /// Reference the error is computed against.
    pub metric: Metric,
}

impl Case {
    /// The `--set` overrides of this case.
    pub fn sets(&self) -> Vec<String> {
        let mut sets = vec![
            format!("fluid.solver={}", self.solver),
            format!("fluid.spacing={}", self.spacing),
            format!("run.end_time={}", self.end_time),
        ];
        if self.contact != "none" {
            sets.push(format!("contact.algorithm={}", self.contact));
        }
        sets.extend(self.extra.iter().cloned());
        sets
    }

    /// A short unique name, used for the run's folder.
    pub fn id(&self) -> String {
        let contact = match self.contact {
            "particle_element" => "_pe",
            "particle_particle" => "_pp",
            _ => "",
        };
        let threads = self.threads.map(|n| format!("_t{n}")).unwrap_or_default();
        let variant = if self.variant.is_empty() {
            String::new()
        } else {
            format!("_{}", self.variant)
        };
        format!(
            "{}{variant}_{}{contact}_dx{}{threads}",
            self.case, self.solver, self.spacing
        )
    }
}

/// The part of the suite a bench run asks for.
#[derive(Clone, Debug, Default)]
pub struct Selection {
    /// Quick suite.
    pub quick: bool,
    /// Cases to run (empty: all).
    pub only: Vec<String>,
    /// Solvers to run (empty: both).
    pub solvers: Vec<String>,
    /// Contact algorithms to run on the gate (empty: both).
    pub contacts: Vec<String>,
    /// Spacings replacing the suite's own for every case but scaling and stress (empty: the suite's).
    pub spacings: Vec<f64>,
    /// End time replacing the suite's own for every case but scaling and stress.
    pub end_time: Option<f64>,
}

/// The case names, in suite order.
pub const CASES: [&str; 6] = [
    "dam_break",
    "hydrostatic_plate",
    "elastic_gate",
    "lobovsky_dam_break",
    "scaling",
    "stress",
];

/// Scaling: the dam-break column at these spacings is ~5,000, 20,000, 50,000 and 100,000 particles
/// (0.1 m × 0.2 m / Δx²).
const SCALING_SPACINGS: [f64; 4] = [0.002, 0.001, 0.000632, 0.000447];

/// WCSPH's stable step on the dam break is about 0.0148 Δx (measured: 4,062 steps to 0.2 s at Δx = 0.0033 m);
/// scaling runs end after about this many steps (quick, full).
const SCALING_STEPS: (f64, f64) = (60.0, 200.0);

/// The suite for `sel`, reading the scenes in `scenes`.
pub fn suite(scenes: &Path, sel: &Selection) -> Vec<Case> {
    let q = sel.quick;
    let mut cases = Vec::new();
    let mut add = |case: &'static str,
                   solver: &'static str,
                   contact: &'static str,
                   spacings: &[f64],
                   end_time: f64,
                   extra: &[&str],
                   metric: Metric| {
        let spacings = if sel.spacings.is_empty() {
            spacings
        } else {
            &sel.spacings
        };
        for &spacing in spacings {
            cases.push(Case {
                case,
                variant: "",
                scene: scenes.join(format!("{case}.toml")),
                solver,
                contact,
                spacing,
                end_time: sel.end_time.unwrap_or(end_time),
                threads: None,
                repeats: 1,
                extra: extra.iter().map(|s| s.to_string()).collect(),
                metric,
            });
        }
    };
    // Dam break: the error needs the front up to T = 2.5 (t = 0.18 s); the scene ends at 0.2 s.
    let dam: &[f64] = if q {
        &[0.01, 0.005, 0.0033]
    } else {
        &[0.005, 0.0033, 0.0025, 0.002]
    };
    for solver in ["wcsph", "isph"] {
        add("dam_break", solver, "none", dam, 0.2, &[], Metric::DamBreak);
    }
    // Hydrostatic plate: the side walls are 0.075 m thick, three layers at 0.025 m, two at 0.0375 m (coarser is
    // unstable: particles leak through). ISPH couples at 2e-4 s as in tests/fsi.rs (its own step is ~1.7e-3 s).
    let plate: &[f64] = if q {
        &[0.0375, 0.03, 0.025]
    } else {
        &[0.03, 0.025, 0.02, 0.0167]
    };
    let plate_end = if q { 0.15 } else { 0.3 };
    add(
        "hydrostatic_plate",
        "wcsph",
        "particle_element",
        plate,
        plate_end,
        &[],
        Metric::Plate,
    );
    add(
        "hydrostatic_plate",
        "isph",
        "particle_element",
        plate,
        plate_end,
        &["coupling.max_dt=2e-4"],
        Metric::Plate,
    );
    // Elastic gate: the peak comes near 0.12 s; walls are 12 mm thick (three layers at 4 mm). The quick suite
    // starts at 4.5 mm, as tests/fsi.rs does (coarser gates lose a particle through the floor after ~0.33 s).
    let gate: &[f64] = if q {
        &[0.0045, 0.004, 0.0035]
    } else {
        &[0.004, 0.003, 0.002]
    };
    let gate_end = if q { 0.15 } else { 0.2 };
    for solver in ["wcsph", "isph"] {
        for contact in ["particle_element", "particle_particle"] {
            add("elastic_gate", solver, contact, gate, gate_end, &[], Metric::Gate);
        }
    }
    // Wall impact (Lobovsky et al. 2014): H/30 (quick), H/30, H/60 and H/120 (full), the scene's end time t* = 7.15
    // (the recording's end); the sensor probes follow the spacing, half a spacing in front of the wall.
    let lobovsky: &[f64] = if q { &[0.01] } else { &[0.01, 0.005, 0.0025] };
    let lobovsky = if sel.spacings.is_empty() {
        lobovsky
    } else {
        &sel.spacings
    };
    for solver in ["wcsph", "isph"] {
        for &spacing in lobovsky {
            cases.push(Case {
                case: "lobovsky_dam_break",
                variant: "",
                scene: scenes.join("lobovsky_dam_break.toml"),
                solver,
                contact: "none",
                spacing,
                end_time: sel.end_time.unwrap_or(LOBOVSKY_END),
                threads: None,
                repeats: 1,
                extra: super::lobovsky::probe_sets(spacing),
                metric: Metric::Lobovsky,
            });
        }
    }
    for threads in [1, 2] {
        for &spacing in &SCALING_SPACINGS {
            cases.push(Case {
                case: "scaling",
                variant: "",
                scene: scenes.join("dam_break.toml"),
                solver: "wcsph",
                contact: "none",
                spacing,
                end_time: scaling_end(spacing, q),
                threads: Some(threads),
                repeats: SCALING_REPEATS,
                extra: vec![format!("run.output_interval={}", scaling_end(spacing, q))],
                metric: Metric::Scaling,
            });
        }
    }
    cases.extend(stress(scenes, q));
    let wanted = |list: &[String], v: &str| list.is_empty() || list.iter().any(|w| w == v);
    cases.retain(|c| {
        wanted(&sel.only, c.case)
            && wanted(&sel.solvers, c.solver)
            && (c.contact == "none" || wanted(&sel.contacts, c.contact))
    });
    cases
}

/// End time of the wall-impact case [s]: the scene's, t* = 7.15, where the recording ends.
const LOBOVSKY_END: f64 = 1.25;

/// Runs of each scaling case (the median is kept).
const SCALING_REPEATS: usize = 3;

/// End time of a scaling run at `spacing`: about [`SCALING_STEPS`] WCSPH steps, rounded to 1e-5 s.
fn scaling_end(spacing: f64, quick: bool) -> f64 {
    let steps = if quick { SCALING_STEPS.0 } else { SCALING_STEPS.1 };
    (steps * 0.0148 * spacing * 1e5).round() / 1e5
}

/// What a case runs, in words, for `report.md`.
pub fn describe(metric: Metric) -> &'static str {
    match metric {
        Metric::DamBreak => "surge front (probe `surge_front` + Δx/2, so Z(0) = 1) against Martin & Moyce 1952, n² = 2",
        Metric::Plate => "mean mid-span deflection (probe `mid_uy`) over 0.05 s < t ≤ end against −6.86e-5 m",
        Metric::Gate => "peak horizontal displacement of the free end (probe `tip_x`) against 0.043 m",
        Metric::Lobovsky => {
            "pressure at sensors 1 and 2 (probes `p_sensor1`, `p_sensor2`, 1 ms means) against Lobovsky et al. 2014's \
             peak event: first impact, peak, RMS for t* in [3, 7], lowest sample, exact zeros"
        }
        Metric::Scaling => "no error: fluid cost per particle-step",
        Metric::Stress => {
            "no error: status, and the fluid's energy (probe `energy`) against its budget E_b = ρ0 g Σ W H²/2"
        }
    }
}

/// The tall dam break of the stress tests (`cosim/tests/stress/`): the dam-break scene with a 0.1 m × 0.3 m
/// column in a closed tank 0.3 m wide and 0.6 m high, walls 0.03 m thick.
const TALL_DAM_BREAK: [&str; 8] = [
    "fluid.block.max=[0.1,0.3]",
    "wall[0].min=[-0.03,-0.03]",
    "wall[0].max=[0.33,0.0]",
    "wall[1].min=[-0.03,0.0]",
    "wall[1].max=[0.0,0.6]",
    "wall[2].min=[0.3,0.0]",
    "wall[2].max=[0.33,0.6]",
    "run.output_interval=0.01",
];

/// The still tank of the stress tests: 0.3 m wide, 0.5 m deep (as `sph-node/tests/still_water_long.rs`), with a
/// kinetic-energy probe in place of the second front probe.
const STILL_TANK: [&str; 10] = [
    "fluid.block.max=[0.3,0.5]",
    "wall[0].min=[-0.075,-0.075]",
    "wall[0].max=[0.375,0.0]",
    "wall[1].min=[-0.075,0.0]",
    "wall[1].max=[0.0,0.6]",
    "wall[2].min=[0.3,0.0]",
    "wall[2].max=[0.375,0.6]",
    "run.output_interval=0.05",
    "probe[1]={name=\"kinetic\",kind=\"energy\",part=\"kinetic\",of=\"fluid\"}",
    "probe[2].x_max=0.03",
];

/// The fluid's total energy as the gate's second probe.
const GATE_ENERGY: &str = "probe[1]={name=\"energy\",kind=\"energy\",part=\"total\",of=\"fluid\"}";

/// The stress cases: the longer variants of `cosim/tests/stress/` (each must end `ok` with its energy within
/// the budget, or be stopped `unstable` by a guard; `report.md` and `docs/PERFORMANCE.md` give the bounds).
fn stress(scenes: &Path, quick: bool) -> Vec<Case> {
    let mut cases = Vec::new();
    let mut add =
        |variant: &'static str, scene: &str, solver: &'static str, spacing: f64, end_time: f64, extra: &[&str]| {
            cases.push(Case {
                case: "stress",
                variant,
                scene: scenes.join(scene),
                solver,
                contact: "none",
                spacing,
                end_time,
                threads: None,
                repeats: 1,
                extra: extra.iter().map(|s| s.to_string()).collect(),
                metric: Metric::Stress,
            });
        };
    let (still, tall, gate_end) = if quick {
        ((10.0, 4.0), 0.01, 0.2)
    } else {
        ((30.0, 10.0), 0.005, 0.4)
    };
    add("still_tank", "dam_break.toml", "wcsph", 0.025, still.0, &STILL_TANK);
    add("still_tank", "dam_break.toml", "isph", 0.025, still.1, &STILL_TANK);
    for solver in ["wcsph", "isph"] {
        add("tall_dam_break", "dam_break.toml", solver, tall, 2.0, &TALL_DAM_BREAK);
        let mut cfl = TALL_DAM_BREAK.to_vec();
        cfl.extend(["fluid.cfl=0.9", "coupling.max_dt=0.05"]);
        add("tall_dam_break_cfl0.9", "dam_break.toml", solver, tall, 1.0, &cfl);
    }
    for solver in ["wcsph", "isph"] {
        add(
            "gate_stiff",
            "elastic_gate.toml",
            solver,
            0.004,
            gate_end,
            &[
                GATE_ENERGY,
                "solid[0].material.youngs_modulus=1.2e8",
                "coupling.fem_cfl=0.9",
            ],
        );
        add(
            "gate_soft",
            "elastic_gate.toml",
            solver,
            0.004,
            gate_end,
            &[GATE_ENERGY, "solid[0].material.youngs_modulus=1.2e6"],
        );
    }
    // The coarse WCSPH gate: a particle once fell through the floor near x = 0.3 m after t ≈ 0.35 s.
    add("gate_coarse", "elastic_gate.toml", "wcsph", 0.005, 0.45, &[GATE_ENERGY]);
    add(
        "gate_large_dt",
        "elastic_gate.toml",
        "isph",
        0.004,
        gate_end,
        &[GATE_ENERGY, "coupling.max_dt=1e-2"],
    );
    // The coupled scenes run with their own contact algorithm.
    for c in &mut cases {
        if c.scene.ends_with("elastic_gate.toml") {
            c.contact = "particle_element";
        }
    }
    cases
}
