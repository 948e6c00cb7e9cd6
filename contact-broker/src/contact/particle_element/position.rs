//! The position phase (`DESIGN.md` §4.5 "Position"): Gauss–Seidel sweeps over the particles in index order, each
//! particle's masters in segment order, that push every penetrating particle out to the contact thickness and move
//! the master nodes by their share (λ = −g/w); against immovable masters the exact limit of the sweeps instead
//! (`projection.rs`).

use super::detection::{Hit, Master};
use super::memo::Memo;
use super::pairs::Out;
use super::projection;
use super::report::ContactReport;
use super::rigid::Gaps;
use super::setup::{Mark, Setup};
use crate::contact::bodies::{Nodes, Particles};
use crate::contact::geometry::{axpy, Vec2};

/// Runs the position sweeps until a sweep's deepest penetration is within `tol_x` or `params.sweeps` are done.
/// Where the masters move, a sweep after which a node had left the reach its segment grid allows for rebuilds the
/// grid and is followed by another sweep, within the same count (`segment_grid.rs`): the particles that node
/// moved onto were not gathered in it.
/// `masters` and `rigid` are scratch: the masters near the particle being visited, and the immovable ones of them;
/// `gaps` and `memo` too (their gaps, [`Gaps`], and those kept per particle, [`Memo`]).
///
/// While every master is immovable in this phase (masters held, or all nodes fixed: `Setup::nodes_static`), the
/// nodes do not move, so a visit depends on nothing but the particle's own position. A particle that a visit left
/// where it was is then skipped by the later sweeps, and one that also touched nothing in the first sweep by the
/// touching set ([`touching`](super::touching)): they would repeat the same detection on the same inputs and find
/// the same nothing (bit-identical result).
#[allow(clippy::too_many_arguments)]
pub(super) fn phase(
    setup: &mut Setup,
    particles: &mut Particles,
    nodes: &mut Nodes,
    masters: &mut Vec<Master>,
    rigid: &mut Vec<Master>,
    gaps: &mut Gaps,
    memo: &mut Memo,
    marks: &mut [Mark],
    out: Out,
) {
    let Out { report, pairs } = out;
    for sweep in 0..setup.params.sweeps {
        let first = sweep == 0;
        let mut worst = 0.0f64;
        for (s, mark) in marks.iter_mut().enumerate() {
            if setup.nodes_static && !first && mark.still {
                continue;
            }
            mark.still = true;
            if first {
                mark.clear = true;
            }
            // Static nodes, first sweep: a particle with no master within the touch gap among those whose detection
            // may find a contact (the rest find none) is neither moved nor near, the same outcome as the full visit.
            if setup.nodes_static && first && clear(setup, nodes.x, particles.x[s], masters) {
                continue;
            }
            setup.gather(nodes.x, particles.x[s], masters);
            if masters.is_empty() {
                continue;
            }
            rigid.clear();
            let im_s = 1.0 / particles.m[s];
            for &m in masters.iter() {
                if setup.detector(nodes.x).is_rigid(m, &setup.pos_fixed) {
                    rigid.push(m);
                    continue;
                }
                let Some(h) = setup.detector(nodes.x).detect(m, particles.x[s]) else {
                    continue;
                };
                if h.g >= 0.0 {
                    continue;
                }
                worst = worst.max(-h.g);
                if first {
                    report.note_contact(m, h.g);
                }
                let lam = correct(setup, &h, im_s, &mut particles.x[s], nodes.x, report);
                pairs.record(s, m, h.g, lam, 0.0);
                mark.corrected = true;
            }
            // Immovable masters: the exact limit of the sweeps, per particle. While the nodes are static, the gaps
            // a visit ends with are kept for the next visit at the same position (`memo.rs`).
            let memo_gaps = if setup.nodes_static {
                memo.gaps(mark.memo, particles.x[s], rigid)
            } else {
                None
            };
            let known = memo_gaps.is_some_and(|g| {
                gaps.x0.clear();
                gaps.x0.extend_from_slice(g);
                true
            });
            let projected = projection::position(
                setup,
                particles,
                s,
                nodes.x,
                rigid,
                first,
                gaps,
                known,
                Out {
                    report: &mut *report,
                    pairs: &mut *pairs,
                },
            );
            worst = worst.max(projected.worst);
            if projected.near {
                mark.clear = false;
            }
            if projected.penetrated {
                mark.still = false;
            }
            if projected.moved {
                mark.corrected = true;
            }
            // Kept for the particles visited again: by the next sweep (penetrated), or by the touching set (a
            // master within the touch gap); a memo that still holds needs no copy.
            let revisited = projected.penetrated || !mark.clear;
            if setup.nodes_static && projected.gaps_valid && revisited && (projected.moved || !known) {
                mark.memo = Some(memo.push(particles.x[s], rigid, &gaps.x0));
            }
        }
        report.position_sweeps += 1;
        let regridded = setup.regrid_if_stale(nodes.x);
        if worst <= setup.tol_x && !regridded {
            break;
        }
    }
}

/// Whether no master near `xs` ([`Setup::gather_near`], into the scratch `masters`) is within the touch gap.
fn clear(setup: &Setup, node_x: &[Vec2], xs: Vec2, masters: &mut Vec<Master>) -> bool {
    setup.gather_near(node_x, xs, masters);
    let d = setup.detector(node_x);
    // NaN is not within the gap, as in `projection::position`.
    masters
        .iter()
        .all(|&m| d.detect(m, xs).is_none_or(|h| h.g > setup.touch || h.g.is_nan()))
}

/// The position correction of one penetrating contact `h` of a particle with inverse mass `im_s` at `x_s`; the
/// multiplier λ it applied.
fn correct(setup: &Setup, h: &Hit, im_s: f64, x_s: &mut Vec2, node_x: &mut [Vec2], report: &mut ContactReport) -> f64 {
    let (inv_m, pos_fixed) = (setup.inv_m, &*setup.pos_fixed);
    // DESIGN.md §4.5: w = 1/m_s + N1²/m1 + N2²/m2 (a fixed node adds 0), λ = −g/w.
    let w = im_s + h.na * h.na * inv_m[h.a] + h.nb * h.nb * inv_m[h.b];
    let lam = -h.g / w;
    // x_s += (λ/m_s) n; x1 −= (λ N1/m1) n; x2 −= (λ N2/m2) n.
    *x_s = axpy(*x_s, lam * im_s, h.n);
    for (k, nk) in [(h.a, h.na), (h.b, h.nb)] {
        if !pos_fixed[k] && nk != 0.0 {
            node_x[k] = axpy(node_x[k], -lam * nk * inv_m[k], h.n);
        }
        report.node_position_impulse[k] = axpy(report.node_position_impulse[k], -lam * nk, h.n);
    }
    lam
}
