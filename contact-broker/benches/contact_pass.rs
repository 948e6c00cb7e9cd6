//! The broker's share of one coupling step of the elastic gate (`scenes/elastic_gate.toml`) at Δx = 1 mm
//! (`cargo bench -p contact-broker --bench contact_pass`): the contact pass ([`Interface::pass`]), the region of
//! interest, and the bincode envelopes of the fluid node's answer and of the next command (what processes mode
//! adds per step on top of the transport). The fluid particles are the node's own, taken inside the region of
//! interest the coordinator asks for and jittered by up to ±Δx/2 (fixed pseudo-random sequence), so that about as
//! many particles penetrate the contact thickness as in a run; the gate is in its reference configuration.
//! Prints medians over repetitions (µs per step); nothing is asserted (machines are shared and noisy).
//!
//! Environment: `CONTACT_BENCH_SPACING` (default 0.001), `CONTACT_BENCH_REPS` (repetitions, default 15),
//! `CONTACT_BENCH_PASSES` (passes per repetition, default 100).

use std::time::Instant;

use contact_broker::interface::Interface;
use cosim_proto::envelope::Envelope;
use cosim_proto::messages::{FemState, SphState, StepCommand};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// Deterministic numbers in [−1, 1) (a 64-bit LCG): the bench needs no randomness, only scatter.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// Median µs per call of `f` over `reps` repetitions of `n` calls.
fn time(reps: usize, n: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..reps)
            .map(|_| {
                let t = Instant::now();
                for _ in 0..n {
                    f();
                }
                t.elapsed().as_secs_f64() * 1e6 / n as f64
            })
            .collect(),
    )
}

fn main() {
    let spacing: f64 = env("CONTACT_BENCH_SPACING", 0.001);
    let reps: usize = env("CONTACT_BENCH_REPS", 15);
    let passes: usize = env("CONTACT_BENCH_PASSES", 100);
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/elastic_gate.toml")).unwrap();
    let scene = cosim_proto::scene::parse("elastic_gate.toml", &text, &[format!("fluid.spacing={spacing}")]).unwrap();
    let fem = fem_node::core::FemCore::new(&scene).unwrap();
    let mut sph = sph_node::core::SphCore::new(&scene).unwrap();
    let mesh = fem.mesh();
    let mut interface = Interface::new(&scene, mesh, sph.setup()).expect("the shipped scene's mesh is valid");
    let ids = interface.node_ids().to_vec();
    let x: Vec<[f64; 2]> = ids.iter().map(|&id| mesh.nodes[id as usize]).collect();
    let roi = interface.roi(&x);
    let fem_state = FemState {
        v: vec![[0.0; 2]; ids.len()],
        ids,
        x,
        substeps: 4,
        dt_stable: 2.5e-5,
        compute_seconds: 0.0,
        snapshot: None,
    };
    let cmd = StepCommand {
        dt: 0.0,
        corrections: Vec::new(),
        roi: Some(roi),
        want_interface: true,
        want_snapshot: false,
        stop: false,
    };
    let mut sph_state: SphState = sph.handle(&cmd).unwrap().unwrap();
    let mut rng = Lcg(7);
    for (x, v) in sph_state.x.iter_mut().zip(&mut sph_state.v) {
        *x = [x[0] + 0.5 * spacing * rng.next(), x[1] + 0.5 * spacing * rng.next()];
        *v = [rng.next(), rng.next()];
    }
    let dt = 1.0e-4;
    let (corrections, stats) = interface.pass(&fem_state, &sph_state, dt).unwrap();
    println!(
        "elastic gate, dx = {spacing} m: {} particles in the region of interest, {} contacts, {} particle and {} \
         node corrections per pass",
        stats.exchanged,
        stats.contacts,
        corrections.sph.len(),
        corrections.fem.len()
    );
    let pass = time(reps, passes, || {
        std::hint::black_box(interface.pass(&fem_state, &sph_state, dt).unwrap());
    });
    let roi_us = time(reps, passes, || {
        std::hint::black_box(interface.roi(&fem_state.x));
    });
    let run = "bench";
    let state_bytes = Envelope::new(run, 1, 0.0, &sph_state).encode();
    let encode = time(reps, passes, || {
        std::hint::black_box(Envelope::new(run, 1, 0.0, &sph_state).encode());
    });
    let decode = time(reps, passes, || {
        std::hint::black_box(Envelope::<SphState>::decode(&state_bytes, run, "sph/state").unwrap());
    });
    let next = StepCommand {
        dt,
        corrections: corrections.sph.clone(),
        ..cmd
    };
    let command = time(reps, passes, || {
        let bytes = Envelope::new(run, 2, 0.0, &next).encode();
        std::hint::black_box(Envelope::<StepCommand>::decode(&bytes, run, "broker/sph").unwrap());
    });
    println!("contact pass            {pass:9.1} µs");
    println!("region of interest      {roi_us:9.1} µs");
    println!(
        "fluid state envelope    {encode:9.1} µs encode, {decode:.1} µs decode ({} bytes)",
        state_bytes.len()
    );
    println!("fluid command envelope  {command:9.1} µs encode + decode");
}
