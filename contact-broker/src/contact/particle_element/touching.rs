//! The touching set: the contacts within the touch gap after the position phase, their geometry frozen at the
//! corrected positions, grouped by particle in index order. They are the velocity phase's contacts.

use super::detection::{Hit, Master};
use super::memo::Memo;
use super::report::ContactReport;
use super::setup::{Mark, Setup};
use crate::contact::geometry::Vec2;

/// A contact of the velocity phase.
#[derive(Clone, Copy, Debug)]
pub(super) struct Contact {
    /// The particle.
    pub s: usize,
    /// Its geometry at the corrected positions.
    pub hit: Hit,
    /// Its master.
    pub master: Master,
    /// The master cannot move (all its nodes fixed).
    pub rigid: bool,
}

/// Collects into `contacts` every particle–master pair within `Setup::touch` of touching at particle positions
/// `particle_x` and node positions `node_x`; `masters` is scratch, `memo` the gaps the position phase kept.
#[allow(clippy::too_many_arguments)]
pub(super) fn collect(
    setup: &Setup,
    particle_x: &[Vec2],
    node_x: &[Vec2],
    marks: &[Mark],
    memo: &Memo,
    masters: &mut Vec<Master>,
    contacts: &mut Vec<Contact>,
    report: &mut ContactReport,
) {
    contacts.clear();
    for (s, mark) in marks.iter().enumerate() {
        // Never moved, and the first sweep's detection at this very position found no gap within `touch`.
        if setup.nodes_static && !mark.corrected && mark.clear {
            continue;
        }
        setup.gather(node_x, particle_x[s], masters);
        let d = setup.detector(node_x);
        // The position phase's last gaps at this very position, where it kept them: only the masters within the
        // touch gap are detected again (for their geometry).
        let known = if setup.nodes_static {
            memo.gaps(mark.memo, particle_x[s], masters)
        } else {
            None
        };
        for (i, &m) in masters.iter().enumerate() {
            if known.is_some_and(|g| g[i] > setup.touch || g[i].is_nan()) {
                continue;
            }
            if let Some(hit) = d.detect(m, particle_x[s]).filter(|h| h.g <= setup.touch) {
                report.residual_penetration = report.residual_penetration.max(-hit.g);
                contacts.push(Contact {
                    s,
                    hit,
                    master: m,
                    rigid: d.is_rigid(m, setup.fixed),
                });
            }
        }
    }
    report.touching = contacts.len();
}
