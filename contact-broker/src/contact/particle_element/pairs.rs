//! The contact pairs of a pass: each (particle, master) pair the pass acted on, with the gap at which it was first
//! detected and the position multiplier λ and velocity impulse J it applied to that pair (`DESIGN.md` §4.5, Long
//! et al. 2016 after Johnson & Stryk 2001: x_s += (λ/m_s) n, v_s += (J/m_s) n), summed over the sweeps. Recorded
//! as the pass goes (one entry per correction) into a vector kept in the workspace, then merged per pair: no
//! allocation once the vector has grown to a step's size. Only read, never fed back: the physics does not see it.

use super::detection::Master;

/// The master of a [`ContactPair`]: a boundary segment (index into the pass's segments), or a boundary node acting
/// on its own (convex corner, end of an open chain).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PairMaster {
    /// Segment index.
    Segment(u32),
    /// Node index.
    Node(u32),
}

impl From<Master> for PairMaster {
    fn from(m: Master) -> Self {
        match m {
            Master::Segment(k) => PairMaster::Segment(k),
            Master::Node(k) => PairMaster::Node(k),
        }
    }
}

/// One (particle, master) pair the last pass acted on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPair {
    /// The particle (index into the pass's particles).
    pub particle: usize,
    /// The master.
    pub master: PairMaster,
    /// Gap g when the pass first acted on the pair [m] (negative: penetrating): at the particle's position when
    /// detected in the position phase, or in the touching set for a pair only the velocity phase acted on.
    pub gap: f64,
    /// Position multiplier λ applied to the pair, all sweeps [kg m]: the particle moved by λ/m_s along the
    /// contact normal (λ = −g/w, `DESIGN.md` §4.5; against an immovable master m_s μ, `projection.rs`).
    pub lambda: f64,
    /// Velocity impulse J applied to the pair, all sweeps [kg m/s] (J = −v_rel/w, `DESIGN.md` §4.5; against an
    /// immovable master m_s μ).
    pub impulse: f64,
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
