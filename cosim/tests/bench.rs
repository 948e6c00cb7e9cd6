//! `cosim bench` end to end on a tiny selection of the suite: bench.json's records, the error falling with
//! spacing on the dam break, a blown-up case recorded instead of stopping the bench, report.md and pareto.svg.

mod common;

use std::path::Path;
use std::time::Duration;

use common::*;

const LIMIT: Duration = Duration::from_secs(120);

/// The fields every record has, numeric ones finite.
const NUMBERS: [&str; 7] = [
    "spacing",
    "particles",
    "steps",
    "wall_seconds",
    "particle_steps_per_second",
    "peak_rss_bytes",
    "threads",
];

fn bench(name: &str, args: &[&str]) -> (std::process::Output, Scratch) {
    let out = scratch(name).child("bench");
    let mut all = vec!["bench", "--quick", "--out", out.to_str().unwrap()];
    all.extend(args);
    let mut cmd = std::process::Command::new(cosim());
    cmd.current_dir(root()).args(&all).env("COSIM_BIN_DIR", bin_dir());
    (run_bounded(&mut cmd, LIMIT), out)
}

fn records(out: &Path) -> Vec<serde_json::Value> {
    let list = json(&out.join("bench.json"));
    let list = list.as_array().expect("bench.json is a list").clone();
    for r in &list {
        for key in ["case", "solver", "contact", "status", "message"] {
            assert!(r[key].is_string(), "{key} in {r}");
        }
        for key in NUMBERS {
            let v = r[key]
                .as_f64()
                .unwrap_or_else(|| panic!("{key} is not a number in {r}"));
            assert!(v.is_finite() && v >= 0.0, "{key} = {v}");
        }
        assert!(r.get("error").is_some(), "error (a number or null) in {r}");
    }
    list
}

/// A minimal well-formedness check of an SVG document: one `<svg>` root, every tag closed in order.
fn assert_svg(text: &str) {
    let mut open: Vec<String> = Vec::new();
    let mut rest = text;
    let mut tags = 0;
    while let Some(k) = rest.find('<') {
        let end = rest[k..].find('>').expect("an unterminated tag") + k;
        let tag = &rest[k + 1..end];
        rest = &rest[end + 1..];
        if tag.starts_with('?') || tag.starts_with('!') {
            continue;
        }
        tags += 1;
        let name = |t: &str| {
            t.split(|c: char| c.is_whitespace() || c == '/')
                .next()
                .unwrap_or("")
                .to_string()
        };
        if let Some(closing) = tag.strip_prefix('/') {
            assert_eq!(
                open.pop().as_deref(),
                Some(closing.trim()),
                "tag </{closing}> closes nothing open"
            );
        } else if !tag.ends_with('/') {
            open.push(name(tag));
        }
        if open.is_empty() {
            assert!(rest.trim().is_empty(), "content after the root element");
        }
    }
    assert!(open.is_empty(), "unclosed tags {open:?}");
    assert!(text.contains("<svg") && tags > 10, "an SVG with a drawing");
}

#[test]
fn dam_break_error_falls_with_spacing_and_outputs_are_written() {
    let (output, out) = bench(
        "db",
        &["--only", "dam_break", "--solver", "wcsph", "--spacing", "0.01,0.005"],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "cosim bench failed: {stderr}");
    // One progress line per case.
    assert_eq!(stderr.lines().filter(|l| l.starts_with('[')).count(), 2, "{stderr}");
    let list = records(&out);
    assert_eq!(list.len(), 2);
    let error = |r: &serde_json::Value| r["error"].as_f64().expect("a dam-break error");
    for r in &list {
        assert_eq!(r["case"], "dam_break");
        assert_eq!(r["solver"], "wcsph");
        assert_eq!(r["contact"], "none");
        assert_eq!(r["status"], "ok", "{r}");
        assert!(r["particles"].as_u64().unwrap() > 0 && r["steps"].as_u64().unwrap() > 0);
        assert!(
            r["peak_rss_bytes"].as_u64().unwrap() > 1 << 20,
            "peak RSS of a real process"
        );
        assert!(error(r).is_finite() && error(r) > 0.0);
        // A dam break only loses energy (the viscosities): summary.json's balance, which counts the WCSPH fluid's
        // elastic energy, never rises above its start (measured 0 at Δx = 2 mm, `docs/VALIDATION.md`).
        let made = r["energy_made"].as_f64().expect("energy_made");
        eprintln!("dam break dx = {}: energy made {made:.2e} of the budget", r["spacing"]);
        assert!((0.0..1e-3).contains(&made), "energy made: {made} of the budget");
    }
    // 200 particles at Δx = a/10: 7.5 %; 800 at a/20: 3.9 % (mean front error, shifted experiment).
    let (coarse, fine) = (error(&list[0]), error(&list[1]));
    eprintln!("dam-break front error: {coarse:.4} at 0.01 m, {fine:.4} at 0.005 m");
    assert!(fine < 0.7 * coarse, "refining should cut the error: {coarse} -> {fine}");
    assert!(coarse < 0.15, "even a/10 follows the experiment to 15 %: {coarse}");
    assert!(list[1]["particles"].as_u64() > list[0]["particles"].as_u64());

    let report = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    assert!(
        report.contains("| dam_break | wcsph | none | 0.005 | 800 |"),
        "{report}"
    );
    assert!(
        report.contains("Martin & Moyce"),
        "the report states the error definition"
    );
    assert_svg(&std::fs::read_to_string(out.join("pareto.svg")).expect("pareto.svg"));
}

#[test]
fn a_blown_up_case_is_a_record_not_an_abort() {
    // ISPH with the particle-particle contact and its reaction given at once (`contact.reaction_relaxation = 1`, the
    // added-mass instability that the default relaxation cures, docs/CORRECTIONS.md) is unstable on the gate: its
    // elements invert 0.06-0.12 s in at these spacings (2026-11-28, ninth: 0.118 s at 6 mm, 0.067 s at 5.5 mm; at
    // 4.5 and 5 mm it reached 0.15 s, so those do not serve here; with the default relaxation both run to 0.15 s).
    // The first case blows up and the bench goes on to the second.
    let scenes = scratch("unstable_scenes").child("scenes");
    std::fs::create_dir_all(scenes.join("data")).unwrap();
    let peak = "data/elastic_gate_published_peak.csv";
    std::fs::copy(root().join("scenes").join(peak), scenes.join(peak)).unwrap();
    let gate = std::fs::read_to_string(root().join("scenes/elastic_gate.toml")).unwrap();
    let at_once = "algorithm = \"particle_particle\"\nreaction_relaxation = 1.0";
    let gate = gate.replacen("algorithm = \"particle_element\"", at_once, 1);
    assert!(gate.contains("reaction_relaxation"), "the gate's [contact] changed");
    std::fs::write(scenes.join("elastic_gate.toml"), gate).unwrap();
    let (output, out) = bench(
        "unstable",
        &[
            "--only",
            "elastic_gate",
            "--solver",
            "isph",
            "--contact",
            "particle_particle",
            "--spacing",
            "0.006,0.0055",
            "--end-time",
            "0.15",
            "--scenes",
            scenes.to_str().unwrap(),
        ],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "some case failed: {stderr}");
    let list = records(&out);
    assert_eq!(list.len(), 2, "the bench went on after the failure");
    for r in &list {
        assert_eq!(r["status"], "unstable", "{r}");
        assert_eq!(r["contact"], "particle_particle");
        assert!(r["message"].as_str().unwrap().contains("inverted element"), "{r}");
        assert!(r["error"].is_null(), "no error for a blown-up run");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("**unstable**"), "{report}");
    assert_svg(&std::fs::read_to_string(out.join("pareto.svg")).unwrap());
}

/// `cosim bench` killed with SIGKILL (it runs no clean-up) while a case computes: the case, a `cosim bench-run`
/// child, gets SIGTERM from the kernel and stops between two steps with its summary written, instead of computing
/// on to the end of its case (the ISPH dam break at the finest quick spacing takes about 18 s here).
#[test]
fn a_killed_bench_takes_its_case_with_it() {
    let out = scratch("bench_killed").child("bench");
    let mut cmd = std::process::Command::new(cosim());
    cmd.current_dir(root())
        .args(["bench", "--quick", "--only", "dam_break", "--solver", "isph", "--out"])
        .arg(&out)
        .env("COSIM_BIN_DIR", bin_dir())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null());
    let mut bench = Kill(cmd.spawn().unwrap());
    let until = std::time::Instant::now() + LIMIT;
    // The third case (the longest): its folder appears when it starts.
    let case = loop {
        let kids = children(bench.0.id());
        let third = std::fs::read_dir(out.join("runs"))
            .into_iter()
            .flatten()
            .flatten()
            .count()
            >= 3;
        if let (Some(&(pid, _)), true) = (kids.first(), third) {
            break pid;
        }
        assert!(
            std::time::Instant::now() < until,
            "the bench never started its third case"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    // Past its start-up (where it asks to follow the bench).
    std::thread::sleep(Duration::from_millis(500));
    assert!(alive(case), "the case ended before the bench was killed");
    let hit = std::time::Instant::now();
    bench.0.kill().unwrap();
    bench.0.wait().unwrap();
    while alive(case) && hit.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let gone = !alive(case);
    if !gone {
        let _ = std::process::Command::new("kill")
            .args(["-9", &case.to_string()])
            .status();
    }
    assert!(
        gone,
        "the case (pid {case}) kept computing 10 s after the bench was killed"
    );
    eprintln!(
        "a_killed_bench_takes_its_case_with_it: the case gone {:.2?} after the SIGKILL",
        hit.elapsed()
    );
}
