//! The pressure Poisson equation (`DESIGN.md` §4.3, step 2) as sparse rows built from the neighbour lists.
//!
//! Unknowns: the pressures of all particles, fluid first, then walls (the indices of [`ParticleView`]).
//!
//! * Interior fluid particle i (Shao & Lo 2003, Eq. (15); Cummins & Rudman 1999):
//!   Σ_j 8 m_j/(ρ_i+ρ_j)² (p_i − p_j)(r_ij · ∇_i W_ij)/(r_ij² + η²) = source_i, η = 0.1h, j over fluid and
//!   walls. Stored with the sign flipped (c_ij = −8 m_j/(ρ_i+ρ_j)² r_ij·∇_iW_ij/(r_ij²+η²) ≥ 0) so that the
//!   diagonal Σ_j c_ij is positive: c_i p_i − Σ_j c_ij p_j = −source_i.
//!   Where the support of an interior particle is cut by the void (no particle, fluid or wall, beyond a free
//!   surface), the part of Σ_j c_ij that the void takes away beyond [`VOID_TOLERANCE`] of the full lattice's is
//!   added to the diagonal: the void counts as p = 0 ([`full_support_coefficient`], [`fluid_row`]).
//! * Free-surface fluid particle (∇·r ≤ threshold − 0.25): p_i = 0 (Dirichlet); within 0.25 of the threshold the row is
//!   (1 − φ) × the interior row + φ × the Dirichlet row, φ falling from 1 to 0 across the band
//!   ([`super::free_surface::dirichlet_weight`]).
//! * Wall particle w (Adami et al. 2012, Eq. (27), a_w = 0): p_w − Σ_f (W_wf/Σ_f W_wf) p_f =
//!   Σ_f [ρ_f g · r_wf + ρ_f (ũ_f · n)(r_wf · n)/Δt] W_wf / Σ_f W_wf, ũ_f = u*_f − Δt g, n the wall's normal: the
//!   projection's condition u^{n+1} · n = 0 ([`super::wall_normal`]); a wall particle with no fluid in reach gets
//!   p_w = 0.

use super::sparse::RowSink;
pub use super::sparse::SparseRows;
use super::wall_normal;
use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

/// Makes the system nonsingular: every unknown must reach a Dirichlet row (p = 0: a free-surface particle, or a
/// wall particle with no fluid in reach) through the nonzero entries of its row. A group of rows that does not
/// (a fluid particle pushed inside a wall, whose only neighbours are wall particles that extrapolate from it alone;
/// a pocket of fluid cut off from every free surface) is a pure Neumann problem: singular, and with an inconsistent
/// right-hand side BiCGSTAB diverges. A fluid row with a Dirichlet weight φ > 0 (`weight`, see
/// [`super::free_surface::dirichlet_weight`]; empty for none) anchors its group as a Dirichlet row does: its diagonal
/// exceeds the sum of its off-diagonal entries by φ times itself. The highest fluid particle (largest −g · x, then the lowest index) of each
/// such group is given p = 0: its row becomes Dirichlet, `b` and `free` are set accordingly.
///
/// Returns the particles anchored this way (in the order they were anchored). Sequential and in index order, so
/// the result does not depend on the thread count.
pub fn anchor_floating_groups(
    a: &mut SparseRows,
    b: &mut [f64],
    free: &mut [bool],
    weight: &[f64],
    x: &[[f64; 2]],
    n_fluid: usize,
    gravity: [f64; 2],
) -> Vec<usize> {
    let n = a.n();
    // Transposed graph of the off-diagonal nonzeros: who points at j.
    let mut count = vec![0u32; n + 1];
    let mut dirichlet = vec![true; n];
    for (i, d) in dirichlet.iter_mut().enumerate() {
        let (c, v) = a.row(i);
        for (&j, &vij) in c.iter().zip(v) {
            if j as usize != i && vij != 0.0 {
                count[j as usize + 1] += 1;
                *d = false;
            }
        }
    }
    for (d, &w) in dirichlet.iter_mut().zip(weight) {
        *d |= w > 0.0;
    }
    for k in 0..n {
        count[k + 1] += count[k];
    }
    let mut fill = count.clone();
    let mut from = vec![0u32; count[n] as usize];
    for i in 0..n {
        let (c, v) = a.row(i);
        for (&j, &vij) in c.iter().zip(v) {
            if j as usize != i && vij != 0.0 {
                from[fill[j as usize] as usize] = i as u32;
                fill[j as usize] += 1;
            }
        }
    }
    // Anchored: reaches a Dirichlet row. Breadth-first from the Dirichlet rows along the reversed edges.
    let mut anchored = dirichlet;
    let mut queue: Vec<u32> = (0..n as u32).filter(|&i| anchored[i as usize]).collect();
    let spread = |queue: &mut Vec<u32>, anchored: &mut Vec<bool>| {
        while let Some(j) = queue.pop() {
            for &i in &from[count[j as usize] as usize..count[j as usize + 1] as usize] {
                if !anchored[i as usize] {
                    anchored[i as usize] = true;
                    queue.push(i);
                }
            }
        }
    };
    spread(&mut queue, &mut anchored);
    let mut floating: Vec<usize> = (0..n_fluid).filter(|&i| !anchored[i]).collect();
    if floating.is_empty() {
        return floating;
    }
    let height = |i: usize| -(gravity[0] * x[i][0] + gravity[1] * x[i][1]);
    floating.sort_by(|&i, &j| height(j).total_cmp(&height(i)).then(i.cmp(&j)));
    let mut pinned = Vec::new();
    for i in floating {
        if anchored[i] {
            continue;
        }
        a.set_dirichlet(i);
        b[i] = 0.0;
        free[i] = true;
        anchored[i] = true;
        pinned.push(i);
        queue.push(i as u32);
        spread(&mut queue, &mut anchored);
    }
    pinned
}

/// Fraction of the full lattice's Σ_j c_ij that an interior row may miss before the void counts as p = 0
/// ([`fluid_row`]). The second row under a flat free surface misses 2.2 % (h = 1.3 Δx), a particle at the surface
/// 33 %; the disorder of the interior stays below a few per cent.
pub const VOID_TOLERANCE: f64 = 0.05;

/// Σ_j c_ij over a full square lattice of spacing `dx` around a particle (masses ρ0 Δx², densities ρ0): the
/// diagonal of an interior row whose support nothing cuts.
pub fn full_support_coefficient(kernel: &CubicSpline, dx: f64, rho0: f64) -> f64 {
    let reach = (kernel.support() / dx).ceil() as i64 + 1;
    let m = rho0 * dx * dx;
    let mut s = 0.0;
    for iy in -reach..=reach {
        for ix in -reach..=reach {
            let r = (ix as f64 * dx).hypot(iy as f64 * dx);
            if r > 0.0 && r < kernel.support() {
                s += laplacian_coefficient(m, rho0, rho0, r, kernel);
            }
        }
    }
    s
}

/// Coefficient c_ij ≥ 0 of pair ij in an interior row (Shao & Lo 2003, Eq. (15), sign flipped).
#[inline]
pub fn laplacian_coefficient(m_j: f64, rho_i: f64, rho_j: f64, r: f64, kernel: &CubicSpline) -> f64 {
    let h = kernel.h();
    let eta2 = 0.01 * h * h;
    let rs = rho_i + rho_j;
    // Shao & Lo 2003 Eq. (15): 8 m_j/(ρ_i+ρ_j)² · (r_ij·∇_iW_ij)/(r_ij²+η²), r_ij·∇_iW_ij = r dW/dr
    -8.0 * m_j / (rs * rs) * r * kernel.dw_dr(r) / (r * r + eta2)
}

/// Row of fluid particle i and its right-hand side, given `source_i` and `keep` = 1 − φ, the share of the Poisson row
/// ([`super::free_surface::dirichlet_weight`]; 0: on the free surface, the row is Dirichlet p = 0).
///
/// `hydrostatic = Some((g, ρ0))` for a particle in contact with a structure the fluid does not see (its support is
/// cut by the structure, [`super::contact`]): the row is written for p − ρ0 g · x,
/// Σ_j c_ij [(p_i − p_j) − ρ0 g · (x_i − x_j)] = −source_i, so that the missing side carries the Neumann condition
/// ∂p/∂n = ρ0 g · n (the hydrostatic field solves the truncated row exactly; on a full support the added term is
/// the SPH Laplacian of a linear field, ≈ 0). Without it the cut row reads ∂p/∂n = 0 at the structure.
///
/// Otherwise (`hydrostatic = None`) a support that the void cuts gets the void as p = 0: with `full` the diagonal of
/// a full support ([`full_support_coefficient`]), the row's diagonal becomes Σ_j c_ij + max(0, full − Σ_j c_ij −
/// [`VOID_TOLERANCE`] full). The corrector's symmetric gradient (§4.3 step 5) sees the void as p = 0: its
/// Σ_j m_j p_i/ρ_i² ∇_iW_ij does not vanish on a cut support and pushes the particle into the void. With the void
/// left out of the row (∂p/∂n = 0 there) the PPE does not know that push: the projection is no longer the adjoint
/// pair of the corrector's gradient and the velocity divergence (u^{n+1} = u* − Δt G p with D u^{n+1} = 0 takes
/// Δt² |G p|² of kinetic energy out only when the PPE's operator is D G), and a particle whose support is cut but
/// which is not on the free surface by ∇·r (the top of a thin sheet that hits a wall, ∇·r 1.53–1.58 next to the
/// walls) is given the pressure of a closed box and then thrown out of the sheet by it (the tall dam break at 2× its
/// step: 19 kPa, particles thrown up at 5 m/s, 9 % of the energy budget created in one step).
#[allow(clippy::too_many_arguments)]
pub fn fluid_row(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    keep: f64,
    source: f64,
    hydrostatic: Option<([f64; 2], f64)>,
    full: f64,
    row: &mut RowSink<'_>,
) -> f64 {
    if keep <= 0.0 {
        // §4.3 step 3: Dirichlet p = 0 on the free surface
        row.push(i as u32, 1.0);
        return 0.0;
    }
    let (xi, rho_i) = (view.x[i], view.rho[i]);
    row.push(i as u32, 0.0);
    let mut diag = 0.0;
    let mut rhs = -source;
    for &j in neighbors {
        let (r_ij, r) = separation(xi, view.x[j as usize]);
        let c = laplacian_coefficient(view.m[j as usize], rho_i, view.rho[j as usize], r, kernel);
        diag += c;
        row.push(j, -c);
        if let Some((g, rho0)) = hydrostatic {
            rhs += c * rho0 * (g[0] * r_ij[0] + g[1] * r_ij[1]);
        }
    }
    if hydrostatic.is_none() {
        // The void as p = 0 beyond the tolerance (see above): consistent with the symmetric gradient of the corrector
        diag += (full - diag - VOID_TOLERANCE * full).max(0.0);
    }
    let values = row.values_mut();
    values[0] = diag;
    if keep < 1.0 {
        // (1 − φ) × the Poisson row + φ × the Dirichlet row diag · p_i = 0 (`free_surface::dirichlet_weight`)
        for e in &mut values[1..] {
            *e *= keep;
        }
        return keep * rhs;
    }
    rhs
}

/// Row of wall particle w (a `view` index ≥ `n_fluid`) and its right-hand side: Adami et al. 2012, Eq. (27), with
/// the normal motion of the fluid ([`super::wall_normal`]; `view.v` holds u* of the fluid, `normal` is w's normal,
/// `touch` its depth behind the face plus Δx/2 ([`wall_normal::normal_motion_term`]), `dt` the step).
#[allow(clippy::too_many_arguments)]
pub fn wall_row(
    w: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    gravity: [f64; 2],
    normal: [f64; 2],
    touch: f64,
    dt: f64,
    row: &mut RowSink<'_>,
) -> f64 {
    let xw = view.x[w];
    row.push(w as u32, 1.0);
    let (mut sum_w, mut sum_rho_r, mut sum_motion) = (0.0, [0.0, 0.0], 0.0);
    for &f in neighbors {
        let f = f as usize;
        if f >= view.n_fluid {
            continue;
        }
        let (r_wf, r) = separation(xw, view.x[f]);
        let wgt = kernel.w(r);
        sum_w += wgt;
        sum_rho_r[0] += view.rho[f] * r_wf[0] * wgt;
        sum_rho_r[1] += view.rho[f] * r_wf[1] * wgt;
        sum_motion += wall_normal::normal_motion_term(view.rho[f], view.v[f], r_wf, normal, touch, dt, gravity) * wgt;
        row.push(f as u32, wgt);
    }
    if sum_w <= 0.0 {
        row.clear();
        row.push(w as u32, 1.0);
        return 0.0;
    }
    for e in &mut row.values_mut()[1..] {
        // Adami et al. 2012, Eq. (27): p_w = Σ_f p_f W_wf / Σ_f W_wf + …
        *e = -*e / sum_w;
    }
    // Adami et al. 2012, Eq. (27), a_w = 0: … + g · Σ_f ρ_f r_wf W_wf / Σ_f W_wf; + the normal motion stopped by the
    // projection (Cummins & Rudman 1999: ∂p/∂n = ρ u*·n/Δt), `wall_normal`
    (gravity[0] * sum_rho_r[0] + gravity[1] * sum_rho_r[1] + sum_motion) / sum_w
}

/// Assembles the whole system: `sources` (one per fluid particle), `weight` (the Dirichlet weights φ of
/// [`super::free_surface::dirichlet_weight`], 1 on the free surface; empty for none), `contact`
/// (particles against a structure, see [`fluid_row`]; empty for none), the walls' `normals` and `touch` distances
/// (one per wall particle, see [`super::wall_normal`]) and the step `dt` in. `view.v` holds u* of the
/// fluid. `full`: the diagonal of a full support ([`full_support_coefficient`]) for the void rows of
/// [`fluid_row`]. The matrix goes into `a` and the right-hand side into `b`, reusing their allocations.
#[allow(clippy::too_many_arguments)]
pub fn assemble(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    gravity: [f64; 2],
    rho0: f64,
    weight: &[f64],
    contact: &[bool],
    sources: &[f64],
    normals: &[[f64; 2]],
    touch: &[f64],
    dt: f64,
    full: f64,
    a: &mut SparseRows,
    b: &mut Vec<f64>,
) {
    let nf = view.n_fluid;
    // Entries per row at most: a free-surface row has 1; a fluid row the particle and its neighbours; a wall row the
    // wall particle and its fluid neighbours.
    let bound = |i: usize| match i < nf {
        true if weight.get(i).is_some_and(|&w| w >= 1.0) => 1,
        true => 1 + list.of(i).len(),
        false => 1 + list.of(i).iter().filter(|&&j| (j as usize) < nf).count(),
    };
    a.assemble(view.x.len(), b, bound, |i, row| {
        if i < view.n_fluid {
            let hydrostatic = contact.get(i).copied().unwrap_or(false).then_some((gravity, rho0));
            // 1 − φ: the share of the Poisson row (`free_surface::dirichlet_weight`; all of it where no weight is given)
            let keep = 1.0 - weight.get(i).copied().unwrap_or(0.0);
            fluid_row(i, view, list.of(i), kernel, keep, sources[i], hydrostatic, full, row)
        } else {
            let normal = normals.get(i - view.n_fluid).copied().unwrap_or([0.0; 2]);
            let touch = touch.get(i - view.n_fluid).copied().unwrap_or(0.0);
            wall_row(i, view, list.of(i), kernel, gravity, normal, touch, dt, row)
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Diagonal of the row of the particle at the origin of a lattice with rows `iy` in `rows`, with the void term.
    fn lattice_diagonal(rows: std::ops::RangeInclusive<i32>, hydrostatic: bool) -> (f64, f64) {
        let lattice = super::super::lattice::Lattice::new(rows);
        let (view, neighbors, kernel) = (lattice.view(), &lattice.neighbors, &lattice.kernel);
        let (dx, rho0) = (lattice.dx, lattice.rho0);
        let full = full_support_coefficient(kernel, dx, rho0);
        let hydro = hydrostatic.then_some(([0.0, -9.81], rho0));
        let mut a = SparseRows::default();
        a.assemble(
            1,
            &mut Vec::new(),
            |_| neighbors.len() + 1,
            |_, row| fluid_row(0, &view, neighbors, kernel, 1.0, 0.0, hydro, full, row),
        );
        (a.row(0).1[0], full)
    }

    #[test]
    fn a_row_in_the_surface_band_is_the_interior_row_scaled_off_the_diagonal() {
        // The second row under a flat surface, with a source: the band row keeps the diagonal and scales the
        // neighbours' entries and the right-hand side by 1 − φ (`free_surface::dirichlet_weight`).
        let lattice = super::super::lattice::Lattice::new(-5..=1);
        let (view, neighbors, kernel) = (lattice.view(), &lattice.neighbors, &lattice.kernel);
        let (dx, rho0) = (lattice.dx, lattice.rho0);
        let full = full_support_coefficient(kernel, dx, rho0);
        let row = |keep: f64| {
            let mut a = SparseRows::default();
            let mut b = Vec::new();
            a.assemble(
                1,
                &mut b,
                |_| neighbors.len() + 1,
                |_, row| fluid_row(0, &view, neighbors, kernel, keep, 250.0, None, full, row),
            );
            let (_, values) = a.row(0);
            (values.to_vec(), b[0])
        };
        let (interior, b1) = row(1.0);
        let (band, b) = row(0.25);
        assert_eq!(band[0], interior[0]);
        for (e, e1) in band[1..].iter().zip(&interior[1..]) {
            assert!((e - 0.25 * e1).abs() <= 1e-15 * e1.abs(), "{e} against 0.25 × {e1}");
        }
        assert!(
            b1 == -250.0 && (b - 0.25 * b1).abs() < 1e-12,
            "right-hand side {b} against 0.25 × {b1}"
        );
    }

    #[test]
    fn a_support_cut_by_the_void_counts_it_as_zero_pressure() {
        // Inside a full lattice: no void, the diagonal is the full one.
        let (d, full) = lattice_diagonal(-5..=5, false);
        assert!((d - full).abs() < 1e-9 * full, "{d} vs {full}");
        // At the top row of a half lattice (a third of the support missing): the diagonal is the full one less the
        // tolerance.
        let (d, full) = lattice_diagonal(-5..=0, false);
        assert!((d - (1.0 - VOID_TOLERANCE) * full).abs() < 1e-9 * full, "{d} vs {full}");
        // The second row (2.2 % missing, within the tolerance) and a row against a structure (Neumann) are left as
        // they are: Σ_j c_ij, below the full diagonal.
        let (d, full) = lattice_diagonal(-5..=1, false);
        assert!(d < 0.99 * full && d > (1.0 - VOID_TOLERANCE) * full, "{d} vs {full}");
        let (d, full) = lattice_diagonal(-5..=0, true);
        assert!(d < 0.7 * full, "{d} vs {full}");
    }

    #[test]
    fn a_group_without_a_dirichlet_row_is_anchored_at_its_highest_particle() {
        // 0: free surface; 1–2: fluid connected to it; 3–4: fluid connected only through wall 5 (a particle pushed
        // into a wall): a pure Neumann group.
        let rows: Vec<Vec<(u32, f64)>> = vec![
            vec![(0, 1.0)],
            vec![(1, 2.0), (0, -1.0), (2, -1.0)],
            vec![(2, 1.0), (1, -1.0)],
            vec![(3, 1.0), (5, -1.0)],
            vec![(4, 1.0), (5, -1.0)],
            vec![(5, 1.0), (3, -0.5), (4, -0.5)],
        ];
        let mut a = SparseRows::from_rows(&rows);
        let mut b = vec![0.0, 1.0, 1.0, 1.0, 1.0, 0.5];
        let mut free = vec![true, false, false, false, false];
        let x = [
            [0.0, 0.5],
            [0.0, 0.4],
            [0.0, 0.3],
            [0.0, -0.01],
            [0.0, -0.005],
            [0.0, -0.01],
        ];
        let pinned = anchor_floating_groups(&mut a, &mut b, &mut free, &[], &x, 5, [0.0, -9.81]);
        assert_eq!(pinned, vec![4]);
        assert!(free[4] && !free[3]);
        assert_eq!(b[4], 0.0);
        assert_eq!(a.row(4).1, &[1.0, 0.0]);
        // Anchored groups are left alone.
        assert!(anchor_floating_groups(&mut a, &mut b, &mut free, &[], &x, 5, [0.0, -9.81]).is_empty());
    }
}
