//! `cosim compare`: one probe of several runs in one plot, peaks printed; a missing probe is named.

mod common;

use std::time::Duration;

use common::*;

fn fake_run(dir: &std::path::Path, rows: &str) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("probes.csv"), format!("t,tip_x,other\n{rows}")).unwrap();
}

#[test]
fn compare_draws_every_run_and_prints_its_peak() {
    let dir = scratch("compare");
    let (a, b) = (dir.join("a"), dir.join("b"));
    fake_run(&a, "0,0,1\n0.1,0.04,1\n0.2,0.03,1\n");
    fake_run(&b, "0,0,1\n0.1,-0.05,1\n0.2,0.01,1\n");
    let svg = dir.join("cmp.svg");
    let out = run_bounded(
        std::process::Command::new(cosim()).args([
            "compare",
            &format!("wcsph={}", a.display()),
            b.to_str().unwrap(),
            "--probe",
            "tip_x",
            "--out",
            svg.to_str().unwrap(),
        ]),
        Duration::from_secs(30),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        stdout.contains("wcsph: peak tip_x = 4.000000e-2 at t = 0.1 s"),
        "{stdout}"
    );
    assert!(stdout.contains("peak tip_x = -5.000000e-2 at t = 0.1 s"), "{stdout}");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains(">\nwcsph\n</text>"), "legend names the run");

    let missing = run_bounded(
        std::process::Command::new(cosim()).args([
            "compare",
            a.to_str().unwrap(),
            "--probe",
            "nope",
            "--out",
            svg.to_str().unwrap(),
        ]),
        Duration::from_secs(30),
    );
    let err = String::from_utf8_lossy(&missing.stderr);
    assert_eq!(missing.status.code(), Some(2), "{err}");
    assert!(
        err.contains("probes.csv") && err.contains("no probe `nope`") && err.contains("tip_x, other"),
        "{err}"
    );
}
