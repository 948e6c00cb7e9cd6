//! The contact pairs of a pass: each (particle, master) pair the pass acted on, with the gap at which it was first
//! detected and the position multiplier λ and velocity impulse J it applied to that pair (`DESIGN.md` §4.5, Long
//! et al. 2016 after Johnson & Stryk 2001: x_s += (λ/m_s) n, v_s += (J/m_s) n), summed over the sweeps. Recorded
//! as the pass goes (one entry per correction) into a vector kept in the workspace, then merged per pair: no
//! allocation once the vector has grown to a step's size. Only read, never fed back: the physics does not see it.

use super::detection::Master;
pub use crate::contact::pair::{ContactPair, PairMaster};

impl From<Master> for PairMaster {
    fn from(m: Master) -> Self {
        match m {
            Master::Segment(k) => PairMaster::Segment(k),
            Master::Node(k) => PairMaster::Node(k),
        }
    }
}

/// Where a phase writes what it did: the pass's report and its pair log.
pub(super) struct Out<'a> {
    pub report: &'a mut super::report::ContactReport,
    pub pairs: &'a mut PairLog,
}

/// The pairs of one pass: raw entries (each with its order) while it runs, one per pair once
/// [`PairLog::finish`] merged them.
#[derive(Clone, Debug, Default)]
pub(super) struct PairLog {
    entries: Vec<(ContactPair, u32)>,
    pairs: Vec<ContactPair>,
}

impl PairLog {
    /// Empties the log for a new pass (keeps its capacity).
    pub fn clear(&mut self) {
        self.entries.clear();
        self.pairs.clear();
    }

    /// Notes that the pass applied `lambda` and `impulse` to particle `s` against master `m` at gap `g`.
    pub fn record(&mut self, s: usize, m: Master, g: f64, lambda: f64, impulse: f64) {
        let order = self.entries.len() as u32;
        let pair = ContactPair {
            particle: s,
            master: m.into(),
            gap: g,
            lambda,
            impulse,
        };
        self.entries.push((pair, order));
    }

    /// Merges the entries per (particle, master), pairs in that order: λ and J summed in the order they were
    /// applied, the gap of the first. No allocation once grown (an unstable sort on a key that ends with the
    /// entry's order is deterministic).
    pub fn finish(&mut self) {
        self.entries
            .sort_unstable_by_key(|(p, order)| (p.particle, p.master, *order));
        for &(p, _) in &self.entries {
            match self.pairs.last_mut() {
                Some(last) if last.particle == p.particle && last.master == p.master => {
                    last.lambda += p.lambda;
                    last.impulse += p.impulse;
                }
                _ => self.pairs.push(p),
            }
        }
    }

    /// The pairs, after [`PairLog::finish`].
    pub fn pairs(&self) -> &[ContactPair] {
        &self.pairs
    }
}
