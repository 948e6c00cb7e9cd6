//! Where a `node_displacement` probe looks: its point must lie on its solid. The probe reads the solid's node
//! nearest the point (`contact_broker::probes`), so a point off the solid — a typo, a point of another solid, metres
//! for millimetres — read some edge node and the run ended `ok` with a plot of the wrong thing (found 2026-12-06:
//! `--set probe[0].point=[1e308,1e308]` on csm3 plotted the bar's corner). A point within one cell's diagonal of the
//! solid's rectangle is taken (a corner node sits on it).

use super::{check, Invalid};
use crate::scene::schema::SolidSpec;

/// `probe[p].point` against the rectangle and cells of `solid`.
pub(super) fn on_solid(p: usize, point: [f64; 2], solid: &SolidSpec) -> Result<(), Invalid> {
    let cell = [0, 1].map(|k| (solid.max[k] - solid.min[k]) / f64::from(solid.divisions[k].max(1)));
    let reach = cell[0].hypot(cell[1]);
    let outside = [0, 1].map(|k| (solid.min[k] - point[k]).max(point[k] - solid.max[k]).max(0.0));
    let distance = outside[0].hypot(outside[1]);
    check(
        distance <= reach,
        || format!("probe[{p}].point"),
        || {
            format!(
                "{point:?} lies {distance:.3e} m outside solid `{}` (min {:?} max {:?}), more than a cell's diagonal \
                 ({reach:.3e} m): the probe would read the node nearest it, on the solid's edge",
                solid.name, solid.min, solid.max,
            )
        },
    )
}
