//! `DIR/report.md`: what each case ran, how its error is defined, the results table and the scaling table.

use std::collections::BTreeMap;
use std::fmt::Write;

use super::record::Record;
use super::suite::{describe, Case, Metric};

/// Everything the report needs besides the records.
pub struct Context<'a> {
    /// The cases, in the order they ran.
    pub cases: &'a [Case],
    /// Quick suite.
    pub quick: bool,
    /// Whole bench, wall time [s].
    pub total_seconds: f64,
    /// The command line.
    pub command: String,
    /// The 1-minute load average at the start and at the end.
    pub load: (Option<f64>, Option<f64>),
}

/// The report as markdown.
pub fn render(ctx: &Context, records: &[Record]) -> String {
    let mut md = String::new();
    let suite = if ctx.quick { "quick" } else { "full" };
    let _ = writeln!(md, "# cosim bench ({suite} suite)\n");
    let _ = writeln!(
        md,
        "`{}`: {} cases in {:.0} s wall time on {} cores. Every case is one child process \
         (`cosim run --in-process`); wall time is the run's own (`summary.json`), peak RSS the child's VmHWM.\n",
        ctx.command,
        records.len(),
        ctx.total_seconds,
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    let load = |l: Option<f64>| l.map_or("?".into(), |l| format!("{l:.2}"));
    let _ = writeln!(
        md,
        "Load average (1 min) {} at the start, {} at the end (the bench itself adds about 1; more means other \
         programs shared the cores and the times are longer than on an idle machine; `load_average` in bench.json \
         has each case's).\n",
        load(ctx.load.0),
        load(ctx.load.1)
    );
    cases_section(&mut md, ctx.cases);
    results_section(&mut md, records);
    lobovsky_section(&mut md, records);
    stress_section(&mut md, records);
    scaling_section(&mut md, records);
    let failed: Vec<&Record> = records.iter().filter(|r| r.status != "ok").collect();
    if !failed.is_empty() {
        let _ = writeln!(md, "## Cases without a result\n");
        for r in failed {
            let _ = writeln!(
                md,
                "- {} {} {} Δx = {}: **{}**: {}",
                r.case, r.solver, r.contact, r.spacing, r.status, r.message
            );
        }
        md.push('\n');
    }
    md
}

fn cases_section(md: &mut String, cases: &[Case]) {
    let _ = writeln!(md, "## What each case runs\n");
    let _ = writeln!(
        md,
        "| case | solver | contact | scene | spacings Δx [m] | end time [s] | other `--set` | threads |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
    let mut groups: Vec<(String, Vec<&Case>)> = Vec::new();
    for c in cases {
        let key = format!("{}|{}|{}|{:?}", c.case, c.solver, c.contact, c.threads);
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1.push(c),
            None => groups.push((key, vec![c])),
        }
    }
    for (_, g) in &groups {
        let c = g[0];
        let spacings: Vec<String> = g.iter().map(|c| c.spacing.to_string()).collect();
        let ends: Vec<String> = dedup(g.iter().map(|c| c.end_time.to_string()));
        let extra = other_sets(g);
        let _ = writeln!(
            md,
            "| {} | {} | {} | `{}` | {} | {} | {} | {} |",
            c.case,
            c.solver,
            c.contact,
            c.scene.display(),
            spacings.join(", "),
            ends.join(", "),
            extra,
            c.threads.map_or("all".into(), |n| n.to_string()),
        );
    }
    let _ = writeln!(md, "\nError of each case (relative, dimensionless):\n");
    let mut seen = Vec::new();
    for c in cases {
        if !seen.contains(&c.metric) {
            seen.push(c.metric);
            let detail = match c.metric {
                Metric::DamBreak => {
                    " on the experiment's time axis shifted by ΔT₀ (the offset that aligns Koshizuka & Oka's MPS \
                     front with the experiment, from the reference files only), points with Z ≥ 1.2 and \
                     T ≤ 2.5; `error` = mean of |Z(T − ΔT₀) − Z_exp(T)| / Z_exp, `error_max` the largest \
                     (as `sph-node/tests/dam_break.rs`, which asserts the largest below 5 % at Δx = a/40)"
                }
                Metric::Plate => "; `error` = |w̄ − w| / |w| (as `cosim/tests/fsi.rs`)",
                Metric::Gate => {
                    " (published SPH–FEM and SPH peaks span 0.039–0.043 m); `error` = |peak − 0.043| / 0.043"
                }
                Metric::Lobovsky => {
                    " on the data's own time axis (t* = t √(g/H), p* = p/(ρgH)); `error` = the larger of the two \
                     sensors' RMS [ρgH], `value` sensor 1's peak [ρgH]; issue 16's bounds: first impact within \
                     ±0.1 t*, peak 1.5–6, RMS ≤ 0.25, lowest ≥ −0.5 (table below)"
                }
                Metric::Stress => {
                    "; each must end `ok` with every probe sample finite and `energy_growth` ≤ 0.05 (the bound of \
                     `cosim/tests/stress/`), or be stopped `unstable` by a guard with a reason"
                }
                Metric::Scaling => {
                    "; the WCSPH dam break at ~5,000 to ~100,000 particles for ~60 steps (quick) or ~200 (full), \
                     one frame at the start and one at the end"
                }
            };
            let _ = writeln!(md, "- **{}**: {}{}.", c.case, describe(c.metric), detail);
        }
    }
    md.push('\n');
}

/// The "other `--set`" cell of a group of cases (one case at several spacings): the overrides every case of the group
/// has, then, where some differ between spacings (the Lobovsky sensor probes, half a spacing in front of the wall),
/// each spacing's own; `run.output_interval` is left out (how often a run writes, not what it computes).
fn other_sets(group: &[&Case]) -> String {
    let shown = |c: &Case| -> Vec<String> {
        let keep = |s: &&String| !s.starts_with("run.output_interval");
        dedup(c.extra.iter().filter(keep).cloned())
    };
    let each: Vec<Vec<String>> = group.iter().map(|c| shown(c)).collect();
    let quote = |sets: &[String]| format!("`{}`", sets.join("`, `"));
    let common: Vec<String> = each
        .first()
        .map(|first| {
            let everywhere = |s: &&String| each.iter().all(|e| e.contains(s));
            first.iter().filter(everywhere).cloned().collect()
        })
        .unwrap_or_default();
    let mut parts = Vec::new();
    if !common.is_empty() {
        parts.push(quote(&common));
    }
    for (c, sets) in group.iter().zip(&each) {
        let own: Vec<String> = sets.iter().filter(|s| !common.contains(s)).cloned().collect();
        if !own.is_empty() {
            parts.push(format!("at Δx = {}: {}", c.spacing, quote(&own)));
        }
    }
    if parts.is_empty() {
        "–".into()
    } else {
        parts.join("; ")
    }
}

fn dedup(items: impl Iterator<Item = String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for i in items {
        if !out.contains(&i) {
            out.push(i);
        }
    }
    out
}

fn results_section(md: &mut String, records: &[Record]) {
    let rows: Vec<&Record> = records
        .iter()
        .filter(|r| r.case != "scaling" && r.case != "stress")
        .collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(md, "## Error against run time\n");
    let _ = writeln!(
        md,
        "| case | solver | contact | Δx [m] | particles | steps | wall [s] | CPU [s] | particle-steps/s | value | error | peak RSS [MB] | status |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {:.2} | {} | {:.3e} | {} | {} | {} | {} |",
            r.case,
            r.solver,
            r.contact,
            r.spacing,
            r.particles,
            r.steps,
            r.wall_seconds,
            cpu(r.cpu_seconds),
            r.particle_steps_per_second,
            match (r.value, r.sensors.is_empty()) {
                (Some(v), true) => format!("{v:.4e}"),
                (Some(v), false) => format!("{v:.2} ρgH"),
                (None, _) => "–".into(),
            },
            match (r.error, r.error_max, r.sensors.is_empty()) {
                (Some(e), _, false) => format!("{e:.3} ρgH"),
                (Some(e), Some(m), true) => format!("{:.2} % (max {:.2} %)", 100.0 * e, 100.0 * m),
                (Some(e), None, true) => format!("{:.2} %", 100.0 * e),
                _ => "–".into(),
            },
            mb(r.peak_rss_bytes),
            r.status_shown(),
        );
    }
    md.push_str(
        "\nThe same as `pareto.svg`: error against wall time, one curve per case, solver and contact. A status \"ok, made \
         … %\" is a run whose fluid and structure gained more than a tenth of the energy the water can release \
         (`summary.json` `energy_growth`): nothing in a scene supplies it, so its result is not physical.\n\n",
    );
}

/// The wall-impact case, per sensor, with issue 16's bounds.
fn lobovsky_section(md: &mut String, records: &[Record]) {
    let rows: Vec<&Record> = records.iter().filter(|r| !r.sensors.is_empty()).collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(md, "## Wall impact (Lobovsky et al. 2014, H = 0.3 m)\n");
    let _ = writeln!(
        md,
        "Sensor probes (1 ms means), t* = t √(g/H), p* = p/(ρgH); the recording's value in brackets. Issue 16's \
         bounds: first impact within ±0.1 t*, peak 1.5–6, RMS t* 3–7 ≤ 0.25, lowest ≥ −0.5, and the peak not \
         growing from H/60 to H/120 by more than from H/30 to H/60. The impulse, ∫ p* dt* from 0.05 t* before \
         the first impact to 0.5 t* after it, is not bounded: the same impulse under a taller peak is a shorter \
         pulse.\n"
    );
    let _ = writeln!(
        md,
        "| solver | Δx [m] | sensor | first impact t* | peak p* | impulse | RMS t* 3–7 | lowest p* | exact zeros | wall [s] |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        for s in &r.sensors {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.3} ({:.3}) | {:.2} ({:.2}) | {:.3} ({:.3}) | {:.3} | {:.2} | {} | {:.1} |",
                r.solver,
                r.spacing,
                s.probe,
                s.first_impact,
                s.first_impact_data,
                s.peak,
                s.peak_data,
                s.impulse,
                s.impulse_data,
                s.rms,
                s.min,
                s.zeros,
                r.wall_seconds
            );
        }
    }
    md.push('\n');
}

fn stress_section(md: &mut String, records: &[Record]) {
    let rows: Vec<&Record> = records.iter().filter(|r| r.case == "stress").collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(md, "## Stress tests\n");
    let _ = writeln!(
        md,
        "Energy as a fraction of the budget ρ0 g Σ W H²/2: `growth` the largest, `end` the last sample (negative: \
         dissipated).\n"
    );
    let _ = writeln!(
        md,
        "| stress test | solver | Δx [m] | end [s] | steps | wall [s] | status | energy growth | energy end | message |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    let f = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:+.4}"));
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {:.2} | {} | {} | {} | {} |",
            r.variant,
            r.solver,
            r.spacing,
            r.end_time,
            r.steps,
            r.wall_seconds,
            r.status,
            f(r.energy_growth),
            f(r.energy_drift),
            if r.status == "ok" { "" } else { r.message.as_str() }
        );
    }
    md.push('\n');
}

fn cpu(seconds: Option<f64>) -> String {
    seconds.map_or("–".into(), |s| format!("{s:.2}"))
}

fn mb(bytes: Option<u64>) -> String {
    bytes.map_or("–".into(), |b| format!("{:.1}", b as f64 / 1048576.0))
}

fn scaling_section(md: &mut String, records: &[Record]) {
    let rows: Vec<&Record> = records.iter().filter(|r| r.case == "scaling").collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(md, "## Scaling (WCSPH dam break)\n");
    let _ = writeln!(
        md,
        "Cost per particle-step is the fluid node's compute time (`timings.sph`) over particles × steps: set-up \
         and frame writing are left out. `particle-steps/s` divides by the run's whole wall time instead. Each \
         row is the median of {} runs by cost.\n",
        rows.first().map_or(1, |r| r.repeats)
    );
    let _ = writeln!(
        md,
        "| threads | Δx [m] | particles | steps | wall [s] | CPU [s] | cost [ns/particle-step] | particle-steps/s | per core | peak RSS [MB] | RSS per particle [B] | status |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut by_threads: BTreeMap<usize, Vec<&Record>> = BTreeMap::new();
    for r in &rows {
        by_threads.entry(r.threads).or_default().push(r);
        let per_particle = r
            .peak_rss_bytes
            .filter(|_| r.particles > 0)
            .map_or("–".into(), |b| format!("{:.0}", b as f64 / r.particles as f64));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.2} | {} | {:.0} | {:.3e} | {:.3e} | {} | {} | {} |",
            r.threads,
            r.spacing,
            r.particles,
            r.steps,
            r.wall_seconds,
            cpu(r.cpu_seconds),
            r.sph_ns_per_particle_step,
            r.particle_steps_per_second,
            r.particle_steps_per_second / r.threads as f64,
            mb(r.peak_rss_bytes),
            per_particle,
            r.status
        );
    }
    md.push('\n');
    for (threads, rs) in &by_threads {
        let costs: Vec<f64> = rs
            .iter()
            .filter(|r| r.status == "ok")
            .map(|r| r.sph_ns_per_particle_step)
            .collect();
        if costs.len() >= 2 {
            let (lo, hi) = costs
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(lo, hi), &c| (lo.min(c), hi.max(c)));
            let _ = writeln!(
                md,
                "- {threads} thread(s): cost per particle-step from {lo:.0} to {hi:.0} ns, max/min = **{:.2}** \
                 (target ≤ 1.5: O(N) neighbour search).",
                hi / lo
            );
        }
    }
    if let (Some(one), Some(two)) = (by_threads.get(&1), by_threads.get(&2)) {
        let speedups: Vec<String> = one
            .iter()
            .filter_map(|a| {
                let b = two.iter().find(|b| b.spacing == a.spacing && b.status == "ok")?;
                (a.status == "ok").then(|| {
                    format!(
                        "{} particles {:.2}×",
                        a.particles,
                        a.sph_ns_per_particle_step / b.sph_ns_per_particle_step
                    )
                })
            })
            .collect();
        let _ = writeln!(md, "- Speed-up 1 → 2 threads (fluid compute): {}.", speedups.join(", "));
    }
    md.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(spacing: f64, extra: &[&str]) -> Case {
        Case {
            case: "lobovsky_dam_break",
            variant: "",
            scene: "scenes/lobovsky_dam_break.toml".into(),
            solver: "wcsph",
            contact: "none",
            spacing,
            end_time: 1.25,
            threads: None,
            repeats: 1,
            extra: extra.iter().map(|s| s.to_string()).collect(),
            metric: Metric::Lobovsky,
        }
    }

    /// Overrides that differ between the spacings of a case are shown with their spacing, not merged into one list
    /// that no run had; those that all share come first, once.
    #[test]
    fn per_spacing_overrides_are_listed_with_their_spacing() {
        let a = case(
            0.01,
            &[
                "fluid.density_diffusion=0.5",
                "probe[0].point=[1.605,0.003]",
                "run.output_interval=0.01",
            ],
        );
        let b = case(0.005, &["fluid.density_diffusion=0.5", "probe[0].point=[1.6075,0.003]"]);
        assert_eq!(
            other_sets(&[&a, &b]),
            "`fluid.density_diffusion=0.5`; at Δx = 0.01: `probe[0].point=[1.605,0.003]`; \
             at Δx = 0.005: `probe[0].point=[1.6075,0.003]`"
        );
        assert_eq!(
            other_sets(&[&case(0.01, &[]), &case(0.005, &["run.output_interval=1"])]),
            "–"
        );
        let same = case(0.01, &["fluid.apd=0"]);
        assert_eq!(other_sets(&[&same, &case(0.005, &["fluid.apd=0"])]), "`fluid.apd=0`");
    }
}
