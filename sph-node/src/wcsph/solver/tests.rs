//! The cell-sorted WCSPH pipeline against plain gathers and against the solver as it was before it.

use super::*;
use crate::boundary::adami;
use crate::boundary::adami::wall_pressure;
use crate::boundary::repulsion::Repulsion;
use crate::corrections::xsph::{self, xsph_correction};
use crate::neighbors::CellList;
use crate::particles::separation;
use crate::wcsph::drift_pass::{self, DriftPass};
use crate::wcsph::momentum::Pairs;
use crate::wcsph::{continuity, momentum, MomentumParams};

mod reference;
use reference::Reference;

fn dam_break(spacing: f64) -> WcsphSolver {
    dam_break_with(spacing, &[])
}

/// [`dam_break`] with more scene overrides.
fn dam_break_with(spacing: f64, sets: &[&str]) -> WcsphSolver {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
    let mut sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    sets.push(format!("fluid.spacing={spacing}"));
    let scene = cosim_proto::scene::parse("dam_break.toml", &text, &sets).unwrap();
    let mut solver = WcsphSolver::new(&scene).unwrap();
    for _ in 0..60 {
        let dt = solver.stable_dt();
        solver.step(dt).unwrap();
    }
    solver
}

/// The ∇W factors of the pairs of `i` with `neighbors` straight from the kernel (dW/dr / r, 0 at r = 0), as a plain
/// gather computes ∇W where it uses it.
fn factors(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> Vec<f64> {
    neighbors
        .iter()
        .map(|&j| {
            let (_, r) = separation(view.x[i], view.x[j as usize]);
            if r > 0.0 {
                kernel.dw_dr(r) / r
            } else {
                0.0
            }
        })
        .collect()
}

/// m/ρ of every particle of `view`.
fn volumes(view: &ParticleView<'_>) -> Vec<f64> {
    view.m.iter().zip(view.rho).map(|(m, r)| m / r).collect()
}

/// p/ρ² of every particle of `view`.
fn pr2_of(view: &ParticleView<'_>) -> Vec<f64> {
    view.p.iter().zip(view.rho).map(|(p, r)| p / (r * r)).collect()
}

/// Dρ_i/Dt over `neighbors` as a plain gather, ∇W computed from the kernel where it is used; `vol` = [`volumes`].
fn density_rate(i: usize, view: &ParticleView<'_>, vol: &[f64], neighbors: &[u32], kernel: &CubicSpline) -> f64 {
    continuity::density_rate(i, view, vol, neighbors, &factors(i, view, neighbors, kernel), None)
}

/// Dv_i/Dt over `neighbors` as a plain gather, ∇W computed from the kernel where it is used; `pr2` = [`pr2_of`].
fn acceleration(
    i: usize,
    view: &ParticleView<'_>,
    pr2: &[f64],
    neighbors: &[u32],
    kernel: &CubicSpline,
    params: &MomentumParams,
) -> [f64; 2] {
    let grad = factors(i, view, neighbors, kernel);
    let pairs = Pairs {
        idx: neighbors,
        grad: &grad,
    };
    momentum::acceleration(i, view, pr2, pairs, kernel.h(), params)
}

fn bits(a: &[[f64; 2]]) -> Vec<[u64; 2]> {
    a.iter().map(|a| a.map(f64::to_bits)).collect()
}

/// The sorted lists with precomputed ∇W factors give, bit for bit, what the reference gathers give on the
/// lists of a plain cell list over the same (sorted) particles: same neighbours in the same order, same
/// continuity, momentum, wall pressure and XSPH.
#[test]
fn fast_passes_equal_the_reference_gathers() {
    // The cells searched every step: the gather order of a plain cell list (the Verlet lists keep an older one).
    let solver = dam_break_with(0.005, &["fluid.verlet_skin=0"]);
    let view = solver.view();
    let kernel = solver.kernel;
    let nf = view.n_fluid;
    let (vol, pr2) = (volumes(&view), pr2_of(&view));
    assert!(
        view.v[..nf].iter().any(|v| v[0].abs() > 1e-3),
        "the column must be moving"
    );
    let cells = CellList::new(view.x, kernel.support());
    let reference = cells.neighbor_list(view.x, view.x.len(), kernel.support());
    let list = &solver.scratch.list;
    for i in 0..nf {
        assert_eq!(list.of(i), reference.of(i), "neighbours of slot {i}");
    }
    let mut drho = Vec::new();
    let fast_vol = &solver.sorted.vol;
    list.map_pairs_into(&mut drho, |i, idx, grad| {
        continuity::density_rate(i, &view, fast_vol, idx, grad, None)
    });
    for (i, d) in drho.iter().enumerate() {
        assert_eq!(
            d.to_bits(),
            density_rate(i, &view, &vol, reference.of(i), &kernel).to_bits()
        );
    }
    let params = MomentumParams {
        gravity: solver.params.gravity,
        alpha: solver.wcsph.alpha,
        c0: solver.wcsph.c0,
        nu: solver.params.nu,
    };
    assert!(params.nu > 0.0 && params.alpha > 0.0);
    let mut accel = Vec::new();
    momentum::accelerations_into(&view, &solver.sorted.pr2, list, &kernel, &params, &mut accel);
    let expected: Vec<_> = (0..nf)
        .map(|i| acceleration(i, &view, &pr2, reference.of(i), &kernel, &params))
        .collect();
    assert_eq!(bits(&accel), bits(&expected));
    let mut xsph = Vec::new();
    xsph::xsph_into(&view, list, &kernel, 0.5, &mut xsph);
    let expected: Vec<_> = (0..nf)
        .map(|i| xsph_correction(i, &view, reference.of(i), &kernel, 0.5))
        .collect();
    assert_eq!(bits(&xsph), bits(&expected));
    // The drift pass (rate, APD, XSPH in one loop) and the density increment with the shift after it: every
    // result, bit for bit those of the separate gathers, for each combination of APD and XSPH.
    let ap = apd::ApdParams {
        beta: 0.04,
        v_max: 1.0,
        dt: 1e-4,
    };
    let alone: Vec<_> = (0..nf)
        .map(|i| apd::apd_shift(i, &view, reference.of(i), &kernel, &ap))
        .collect();
    assert!(alone.iter().any(|d| d[0] != 0.0));
    for (apd_on, eps) in [(true, 0.5), (true, 0.0), (false, 0.5), (false, 0.0)] {
        let pass = DriftPass {
            view: &view,
            vol: &solver.sorted.vol,
            kernel: &kernel,
            diffusion: None,
            apd: apd_on.then_some(&ap),
            xsph: eps,
        };
        let (mut rate, mut shift, mut corr) = (Vec::new(), Vec::new(), Vec::new());
        drift_pass::drift_pass_into(&pass, list, &mut rate, &mut shift, &mut corr);
        assert_eq!(
            rate.iter().map(|d| d.to_bits()).collect::<Vec<_>>(),
            drho.iter().map(|d| d.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(
            bits(&shift),
            if apd_on { bits(&alone) } else { vec![] },
            "APD {apd_on}, XSPH {eps}"
        );
        assert_eq!(
            bits(&corr),
            if eps > 0.0 { bits(&expected) } else { vec![] },
            "APD {apd_on}, XSPH {eps}"
        );
    }
    let dt = 1e-4;
    let mut inc = Vec::new();
    list.map_pairs_into(&mut inc, |i, idx, grad| {
        continuity::density_increment(i, &view, fast_vol, idx, grad, None, &alone, dt)
    });
    for (i, d) in inc.iter().enumerate() {
        let rate = density_rate(i, &view, &vol, reference.of(i), &kernel);
        let moved = apd::shift_density_change(i, &view, reference.of(i), &kernel, &alone);
        assert_eq!(d.to_bits(), (0.5 * dt * rate + moved).to_bits(), "slot {i}");
    }
    let mut wall = Vec::new();
    let g = solver.params.gravity;
    adami::wall_pressures_sorted_into(&view, &solver.scratch.cells, &kernel, g, &solver.eos, &mut wall);
    assert!(wall.iter().any(|w| w.0 > 0.0));
    for (w, &(p, rho)) in wall.iter().enumerate() {
        let (ep, erho) = wall_pressure(nf + w, &view, reference.of(nf + w), &kernel, g, &solver.eos);
        assert_eq!((p.to_bits(), rho.to_bits()), (ep.to_bits(), erho.to_bits()), "wall {w}");
    }
}

/// Edits through `state_mut` reach the sorted working copy: handing the state out without changing it leaves
/// the run bit-identical, and the drift starts from an edited position.
#[test]
fn state_edits_are_taken() {
    // Without APD: its shift of particle 0 depends on where its neighbours are, which the edit moves too.
    // The cells searched every step: with Verlet candidates an edit can bring a gather forward in one run and not
    // the other, which changes the order of the sums everywhere.
    let mut a = dam_break_with(0.01, &["fluid.apd=0", "fluid.verlet_skin=0"]);
    let mut b = a.clone();
    let _ = b.state_mut();
    for _ in 0..20 {
        let dt = a.stable_dt();
        a.step(dt).unwrap();
        b.step(dt).unwrap();
    }
    assert_eq!(a.state(), b.state());
    // Move particle 0: the step's first density rate and XSPH use the last search's positions, as they
    // always have, and the drift starts from the edited one; the densities of particle 0 and its neighbours
    // follow the move (`density_follows_edits`), and the step's first density rate carries that 2h further,
    // which changes the XSPH of the particles within 2h of those (2.4e-10 m for particle 0 here): particle 0
    // lands 1e-4 m further, and every particle beyond 6h lands where it did.
    let x0 = a.state().x[0];
    a.state_mut().x[0] = [x0[0] + 1e-4, x0[1]];
    let dt = a.stable_dt();
    a.step(dt).unwrap();
    b.step(dt).unwrap();
    let (xa, xb) = (&a.state().x, &b.state().x);
    assert!((xa[0][0] - xb[0][0] - 1e-4).abs() < 1e-8 && (xa[0][1] - xb[0][1]).abs() < 1e-8);
    let far = 3.0 * a.kernel.support();
    let beyond: Vec<usize> = (1..xa.len()).filter(|&i| separation(xb[i], x0).1 > far).collect();
    assert!(beyond.len() > xa.len() / 2);
    assert!(beyond.iter().all(|&i| xa[i] == xb[i]));
    assert_ne!(a.state().v, b.state().v);
    // The neighbour lists are those of the new positions.
    let list = &a.scratch.list;
    let view = a.view();
    let cells = CellList::new(view.x, a.kernel.support());
    let reference = cells.neighbor_list(view.x, view.x.len(), a.kernel.support());
    assert!((0..view.n_fluid).all(|i| list.of(i) == reference.of(i)));
}

/// A position edit raises the density of a particle moved towards its neighbours as the continuity equation
/// would (`density_follows_edits`): the top particle of the column, whose neighbours all lie below it, moved
/// down by Δx/100 gains δρ = Σ_j m_j δr·∇W_ij, within 2 % (the rest of the difference is the step's own
/// continuity at the two positions).
#[test]
fn a_position_edit_moves_the_density() {
    let mut a = dam_break(0.01);
    let mut b = a.clone();
    let top = (0..a.state().len())
        .max_by(|&i, &j| a.state().x[i][1].total_cmp(&a.state().x[j][1]))
        .unwrap();
    let dy = -1e-4;
    let expected = {
        let view = a.view();
        let k = a.sorted.slot[top] as usize;
        let mut shift = vec![[0.0; 2]; view.n_fluid];
        shift[k] = [0.0, dy];
        apd::shift_density_change(k, &view, a.scratch.list.of(k), &a.kernel, &shift)
    };
    assert!(expected > 1.0, "the top particle is compressed: {expected}");
    let x = a.state().x[top];
    a.state_mut().x[top] = [x[0], x[1] + dy];
    let dt = 1e-6;
    a.step(dt).unwrap();
    b.step(dt).unwrap();
    let gained = a.state().rho[top] - b.state().rho[top];
    assert!(
        (gained - expected).abs() < 0.02 * expected,
        "gained {gained}, expected {expected}"
    );
}

/// Over a run with MLS, APD, viscosity, XSPH and edits through `state_mut` (positions and velocities of some
/// particles, as the contact corrections make), the solver stays bit-identical to the reference: state, wall
/// pressures and accelerations after every step, with 1 and 2 threads.
#[test]
fn equals_the_reference_solver_bit_for_bit() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
    let overrides = [
        "fluid.spacing=0.005".to_string(),
        "fluid.density_filter=\"mls\"".to_string(),
        "fluid.density_filter_interval=7".to_string(),
        // The reference searches the cells every step.
        "fluid.verlet_skin=0".to_string(),
    ];
    let scene = cosim_proto::scene::parse("dam_break.toml", &text, &overrides).unwrap();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut solver = WcsphSolver::new(&scene).unwrap();
            solver.set_apd(0.05);
            let mut reference = Reference::new(
                solver.params.clone(),
                solver.wcsph.clone(),
                solver.state.clone(),
                solver.walls.clone(),
                solver.wall_boxes.clone(),
            );
            for step in 0..150 {
                if step % 25 == 10 {
                    for i in (0..solver.state.len()).step_by(97) {
                        let kick = [1e-3 * (i % 7) as f64, -2e-3];
                        let shift = [1e-5 * (i % 3) as f64, 1e-5];
                        for st in [solver.state_mut(), &mut reference.state] {
                            st.v[i] = [st.v[i][0] + kick[0], st.v[i][1] + kick[1]];
                            st.x[i] = [st.x[i][0] + shift[0], st.x[i][1] + shift[1]];
                        }
                    }
                }
                let dt = solver.stable_dt();
                solver.step(dt).unwrap();
                reference.step(dt);
                assert!(
                    solver.state == reference.state,
                    "state after step {step}, {threads} threads"
                );
                assert_eq!(solver.walls, reference.walls, "walls after step {step}");
                assert_eq!(
                    bits(&solver.accel),
                    bits(&reference.accel),
                    "accelerations after step {step}"
                );
            }
            assert!(
                solver.state.v.iter().any(|v| v[0].abs() > 1e-2),
                "the column must be moving"
            );
        });
    }
}

/// With Verlet candidates (the default), each step's lists hold exactly the particles closer than the support (the
/// plain cell list's, as sets), with the kernel's ∇W factors, on steps that filter old candidates as on those that
/// gather new ones; the run does not depend on the thread count, and it stays within round-off of the run that
/// searches the cells every step.
#[test]
fn verlet_lists_are_the_neighbours_of_the_positions() {
    let run = |threads: usize, sets: &[&str]| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut solver = dam_break_with(0.005, sets);
            let mut filtered = 0;
            for _ in 0..200 {
                let before = solver.scratch.verlet.as_ref().map(|v| v.gathers());
                let dt = solver.stable_dt();
                solver.step(dt).unwrap();
                let reused = before.is_some() && before == solver.scratch.verlet.as_ref().map(|v| v.gathers());
                filtered += usize::from(reused);
                if threads > 1 {
                    continue;
                }
                let view = solver.view();
                let kernel = solver.kernel;
                let reference =
                    CellList::new(view.x, kernel.support()).neighbor_list(view.x, view.n_fluid, kernel.support());
                for chunk in solver.scratch.list.chunks() {
                    let grad = chunk.grad();
                    for k in 0..chunk.len() {
                        let i = chunk.first() + k;
                        let mut got: Vec<(u32, u64)> =
                            chunk.range(k).map(|p| (chunk.idx[p], grad[p].to_bits())).collect();
                        got.sort_unstable();
                        let mut want = reference.of(i).to_vec();
                        want.sort_unstable();
                        let want: Vec<(u32, u64)> = want
                            .iter()
                            .zip(factors(i, &view, &want, &kernel))
                            .map(|(&j, g)| (j, g.to_bits()))
                            .collect();
                        assert_eq!(got, want, "neighbours of slot {i}");
                    }
                }
            }
            (
                solver.state.clone(),
                filtered,
                solver.scratch.verlet.as_ref().map_or(0, |v| v.gathers()),
            )
        })
    };
    let (one, filtered, gathers) = run(1, &[]);
    assert!(
        (100..=197).contains(&filtered),
        "{filtered} of 200 steps filtered old candidates ({gathers} gathers in 260 steps)"
    );
    let (two, ..) = run(2, &[]);
    assert!(one == two, "1 and 2 threads");
    let (cells, none, _) = run(1, &["fluid.verlet_skin=0"]);
    assert_eq!(none, 0);
    let dx = one
        .x
        .iter()
        .zip(&cells.x)
        .map(|(a, b)| separation(*a, *b).1)
        .fold(0.0, f64::max);
    assert!(dx < 1e-12, "largest position difference {dx} m after 260 steps");
}
