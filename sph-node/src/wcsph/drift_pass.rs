//! The first pass over the pairs of a WCSPH step, at xⁿ with the half-kicked velocities v^{n+½} and the densities
//! ρⁿ: the density rate of the continuity equation (Eq. (9) of Long et al. 2016, with the δ-SPH term when on), the
//! XSPH correction of the drift and the APD shift (`DESIGN.md` §4.4), in one loop (issue 20).
//!
//! The three read the same pairs at the same positions; one loop shares the separation, ∇W_ij and W_ij of each
//! pair. The density rate is bit for bit [`crate::wcsph::continuity::density_rate`]'s. XSPH and APD take ρⁿ
//! (their V_j = m_j/ρ_j and ρ̄_ij), not the density after the half kick of this rate as they did when they ran in
//! a pass of their own after it: a relative change of ½ Δt Dρ/Dt / ρ, below 10⁻⁴ at the scenes' steps, in two
//! corrections that are themselves small (re-validated, `docs/PERFORMANCE.md`).

use crate::corrections::{apd, xsph};
use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{dot, separation, ParticleView};
use crate::wcsph::DensityDiffusion;

/// What one drift pass reads.
#[derive(Clone, Copy, Debug)]
pub struct DriftPass<'a> {
    /// The sorted particles (fluid, then walls) at xⁿ, v^{n+½}, ρⁿ.
    pub view: &'a ParticleView<'a>,
    /// V_j = m_j/ρ_j of every particle.
    pub vol: &'a [f64],
    /// The kernel.
    pub kernel: &'a CubicSpline,
    /// The δ-SPH term of the continuity equation, when on.
    pub diffusion: Option<&'a DensityDiffusion>,
    /// The APD shift's parameters, when it runs this step.
    pub apd: Option<&'a apd::ApdParams>,
    /// XSPH's ε (0: off).
    pub xsph: f64,
}

/// Dρ_i/Dt, the APD shift δr_i (zero when APD is off) and the XSPH correction (zero when off) of fluid particle i
/// over its pairs with their ∇W factors (`grad[k]` for `neighbors[k]`, see [`crate::neighbors::ListChunk`]).
/// `APD`, `XSPH` and `DIFF` (the δ-SPH term) must say whether `p` has each: the loop is compiled for each case,
/// without the others' accumulators.
#[inline]
pub fn drift_terms<const APD: bool, const XSPH: bool, const DIFF: bool>(
    i: usize,
    p: &DriftPass<'_>,
    neighbors: &[u32],
    grad: &[f64],
) -> (f64, [f64; 2], [f64; 2]) {
    let view = p.view;
    let (xi, vi, rho_i) = (view.x[i], view.v[i], view.rho[i]);
    let (mut sum, mut diff, mut xs) = (0.0, 0.0, [0.0, 0.0]);
    // The terms of one pair (k, j, W_ij, ∇_i W_ij); a macro, so that each of the two loops below has it inline.
    macro_rules! pair {
        ($k:expr, $j:expr, $w:expr, $g:expr) => {{
            let (k, j, w, g): (usize, usize, f64, [f64; 2]) = ($k, $j, $w, $g);
            let vj = view.v[j];
            let v_ij = [vi[0] - vj[0], vi[1] - vj[1]];
            // Eq. (9), Long et al. 2016
            sum += p.vol[j] * dot(v_ij, g);
            if let Some(d) = p.diffusion.filter(|_| DIFF && j < view.n_fluid) {
                // Molteni & Colagrossi 2009 with Fourtakas et al. 2019 (density_diffusion.rs)
                diff += d.pair(xi, view.x[j], rho_i, view.rho[j], grad[k], p.vol[j]);
            }
            if XSPH && j < view.n_fluid {
                // §4.4 XSPH
                xsph::add_term(&mut xs, view, i, j, w);
            }
        }};
    }
    let shift = match p.apd.filter(|_| APD) {
        Some(a) => {
            let grad_of = |k: usize, r_ij: [f64; 2], _| [grad[k] * r_ij[0], grad[k] * r_ij[1]];
            let each = |k: usize, j: usize, w: f64, g: [f64; 2]| pair!(k, j, w, g);
            apd::apd_shift_with(i, view, neighbors, p.kernel, a, |j| p.vol[j], grad_of, each)
        }
        None => {
            for (k, &j) in neighbors.iter().enumerate() {
                let j = j as usize;
                let (r_ij, w) = if XSPH {
                    let (r_ij, r) = separation(xi, view.x[j]);
                    (r_ij, p.kernel.w(r))
                } else {
                    ([xi[0] - view.x[j][0], xi[1] - view.x[j][1]], 0.0)
                };
                pair!(k, j, w, [grad[k] * r_ij[0], grad[k] * r_ij[1]]);
            }
            [0.0, 0.0]
        }
    };
    let rate = match p.diffusion {
        Some(d) => rho_i * sum - d.coef * diff, // Eq. (9), Long et al. 2016, + D_i
        None => rho_i * sum,                    // Eq. (9), Long et al. 2016
    };
    (rate, shift, xsph::finish(xs, p.xsph))
}

/// [`drift_terms`] of every fluid particle: the rates into `rate`, the shifts into `shift` (left empty when APD
/// is off) and the XSPH corrections into `xsph` (left empty when XSPH is off), in parallel over the list's chunks.
pub fn drift_pass_into(
    p: &DriftPass<'_>,
    list: &NeighborList,
    rate: &mut Vec<f64>,
    shift: &mut Vec<[f64; 2]>,
    xsph: &mut Vec<[f64; 2]>,
) {
    // The results a step does not use go into vectors of `()`, which hold no memory.
    let (mut no_shift, mut no_xsph) = (Vec::<()>::new(), Vec::<()>::new());
    macro_rules! run {
        ($diff:literal) => {
            match (p.apd.is_some(), p.xsph > 0.0) {
                (true, true) => list.map_pairs_into3(rate, shift, xsph, |i, n, g| {
                    drift_terms::<true, true, $diff>(i, p, n, g)
                }),
                (true, false) => list.map_pairs_into3(rate, shift, &mut no_xsph, |i, n, g| {
                    let (r, s, _) = drift_terms::<true, false, $diff>(i, p, n, g);
                    (r, s, ())
                }),
                (false, true) => list.map_pairs_into3(rate, &mut no_shift, xsph, |i, n, g| {
                    let (r, _, x) = drift_terms::<false, true, $diff>(i, p, n, g);
                    (r, (), x)
                }),
                (false, false) => list.map_pairs_into3(rate, &mut no_shift, &mut no_xsph, |i, n, g| {
                    (drift_terms::<false, false, $diff>(i, p, n, g).0, (), ())
                }),
            }
        };
    }
    if p.diffusion.is_some() {
        run!(true)
    } else {
        run!(false)
    }
    if p.apd.is_none() {
        shift.clear();
    }
    if p.xsph <= 0.0 {
        xsph.clear();
    }
}
