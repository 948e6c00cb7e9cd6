//! The gaps the position phase last computed at a particle's position, against the masters gathered there, kept
//! for the later visits of the same pass that would detect the same masters at the same position again (the next
//! sweep's visit of a particle the projection moved, and the touching set). Used only while the nodes are static
//! (`Setup::nodes_static`): a detection then depends on nothing but the particle's position and the master. A
//! memo is used only where the particle's position is the same to the bit and the gathered masters are the same
//! list, so every reuse returns what the detection would have (`f64::INFINITY` where it found no contact).

use super::detection::Master;
use crate::contact::geometry::Vec2;

/// One particle's memo: its position, and where its masters and their gaps lie in [`Memo`]'s arrays.
#[derive(Clone, Copy, Debug)]
struct Entry {
    x: Vec2,
    start: usize,
    len: usize,
}

/// The memos of one pass (scratch: emptied at the start of every pass).
#[derive(Clone, Debug, Default)]
pub(crate) struct Memo {
    entries: Vec<Entry>,
    masters: Vec<Master>,
    gaps: Vec<f64>,
}

impl Memo {
    /// Forgets every memo (keeps the capacity).
    pub fn clear(&mut self) {
        self.entries.clear();
        self.masters.clear();
        self.gaps.clear();
    }

    /// Stores the `gaps` of `masters` at position `x`; the memo's index.
    pub fn push(&mut self, x: Vec2, masters: &[Master], gaps: &[f64]) -> u32 {
        debug_assert_eq!(masters.len(), gaps.len());
        let start = self.masters.len();
        self.masters.extend_from_slice(masters);
        self.gaps.extend_from_slice(gaps);
        self.entries.push(Entry {
            x,
            start,
            len: masters.len(),
        });
        (self.entries.len() - 1) as u32
    }

    /// The gaps of memo `i` if it was taken at `x` (to the bit) with the same `masters` in the same order.
    pub fn gaps(&self, i: Option<u32>, x: Vec2, masters: &[Master]) -> Option<&[f64]> {
        let e = self.entries.get(i? as usize)?;
        let same_x = e.x[0].to_bits() == x[0].to_bits() && e.x[1].to_bits() == x[1].to_bits();
        let range = e.start..e.start + e.len;
        (same_x && self.masters[range.clone()] == *masters).then(|| &self.gaps[range])
    }
}
