//! The velocity phase (`DESIGN.md` §4.5 "Normal velocity"): Gauss–Seidel sweeps over the touching set with the
//! positions frozen, an impulse J = −v_rel/w on every approaching contact; against immovable masters the exact
//! limit of the sweeps instead (`projection.rs`). Tangential velocity is untouched (free slip).

use super::detection::Hit;
use super::pairs::Out;
use super::projection::{self, Planes};
use super::report::ContactReport;
use super::setup::{Mark, Setup};
use super::touching::Contact;
use crate::contact::bodies::{Nodes, Particles};
use crate::contact::geometry::{axpy, dot, scale, sub, Vec2};

/// Runs the velocity sweeps over `contacts` (grouped by particle) until a sweep's fastest approach is within
/// `tolerance` times the first sweep's, or `params.sweeps` are done (none when nothing touches). `planes` is
/// scratch: the immovable contacts of the particle being visited.
pub(super) fn phase(
    setup: &Setup,
    particles: &mut Particles,
    nodes: &mut Nodes,
    contacts: &[Contact],
    planes: &mut Planes,
    marks: &mut [Mark],
    out: Out,
) {
    let Out { report, pairs } = out;
    let mut v_scale = 0.0;
    for sweep in 0..if contacts.is_empty() { 0 } else { setup.params.sweeps } {
        let mut worst = 0.0f64;
        let mut i = 0;
        while i < contacts.len() {
            let s = contacts[i].s;
            let end = i + contacts[i..].iter().take_while(|c| c.s == s).count();
            let (m_s, im_s) = (particles.m[s], 1.0 / particles.m[s]);
            planes.clear();
            for c in &contacts[i..end] {
                let h = c.hit;
                if c.rigid {
                    // n·v_s ≥ n·u with u = N1 v1 + N2 v2 the (prescribed) master velocity.
                    let u = axpy(scale(nodes.v[h.a], h.na), h.nb, nodes.v[h.b]);
                    planes.push(h, c.master, u);
                    continue;
                }
                // v_rel = (v_s − N1 v1 − N2 v2)·n; only approaching contacts are corrected.
                let u = axpy(scale(nodes.v[h.a], h.na), h.nb, nodes.v[h.b]);
                let v_rel = dot(sub(particles.v[s], u), h.n);
                if v_rel >= 0.0 {
                    continue;
                }
                worst = worst.max(-v_rel);
                let j = impulse(setup, &h, v_rel, im_s, &mut particles.v[s], nodes.v, report);
                pairs.record(s, c.master, h.g, 0.0, j);
                marks[s].corrected = true;
            }
            // Immovable masters: exact per particle.
            let (approach, moved) = projection::velocity(particles, s, m_s, planes, pairs, report);
            worst = worst.max(approach);
            if moved {
                marks[s].corrected = true;
            }
            i = end;
        }
        if sweep == 0 {
            v_scale = worst;
        }
        report.velocity_sweeps += 1;
        if worst <= setup.params.tolerance * v_scale {
            break;
        }
    }
}

/// The impulse on one approaching contact `h` (relative normal velocity `v_rel` < 0) of a particle with inverse
/// mass `im_s` and velocity `v_s`; the impulse J it applied.
fn impulse(
    setup: &Setup,
    h: &Hit,
    v_rel: f64,
    im_s: f64,
    v_s: &mut Vec2,
    node_v: &mut [Vec2],
    report: &mut ContactReport,
) -> f64 {
    let (inv_m, fixed) = (setup.inv_m, setup.fixed);
    // J = −v_rel/w; v_s += (J/m_s) n; v1 −= (J N1/m1) n; v2 −= (J N2/m2) n.
    let w = im_s + h.na * h.na * inv_m[h.a] + h.nb * h.nb * inv_m[h.b];
    let j = -v_rel / w;
    *v_s = axpy(*v_s, j * im_s, h.n);
    for (k, nk) in [(h.a, h.na), (h.b, h.nb)] {
        if !fixed[k] && nk != 0.0 {
            node_v[k] = axpy(node_v[k], -j * nk * inv_m[k], h.n);
        }
        report.node_impulse[k] = axpy(report.node_impulse[k], -j * nk, h.n);
    }
    j
}
