//! Internal nodal forces, Eq. (4) of Long et al. 2016: element forces computed independently (in parallel), then
//! assembled serially in element order, so the sum is bit-identical for any number of threads.

use rayon::prelude::*;

use crate::element::ElementFailure;
use crate::model::FemModel;
use crate::state::FemScratch;

/// Below this many elements the element loop runs on the calling thread (waking a pool costs more than it saves).
pub const DEFAULT_PARALLEL_MIN_ELEMENTS: usize = 2048;

/// Fills `scratch.internal` with `f_int(x)`. On failure returns the lowest failing element and why.
pub fn internal_forces(
    model: &FemModel,
    x: &[[f64; 2]],
    scratch: &mut FemScratch,
    parallel_min_elements: usize,
) -> Result<(), (usize, ElementFailure)> {
    let elements = model.elements();
    let buffers = &mut scratch.element_forces;
    let evaluate = |e: usize, out: &mut _| elements[e].internal_forces(x, model.element_material(e), out);
    let ok = if elements.len() >= parallel_min_elements {
        buffers
            .par_iter_mut()
            .with_min_len(256)
            .enumerate()
            .try_for_each(|(e, out)| evaluate(e, out))
            .is_ok()
    } else {
        buffers
            .iter_mut()
            .enumerate()
            .try_for_each(|(e, out)| evaluate(e, out))
            .is_ok()
    };
    if !ok {
        // Which element a parallel loop stops at depends on scheduling; report the first one, always.
        let mut out = [[0.0; 2]; 4];
        for e in 0..elements.len() {
            evaluate(e, &mut out).map_err(|why| (e, why))?;
        }
    }
    let internal = &mut scratch.internal;
    internal.fill([0.0; 2]);
    for (element, forces) in elements.iter().zip(buffers.iter()) {
        for (&n, f) in element.nodes().iter().zip(forces) {
            let node = &mut internal[n as usize];
            node[0] += f[0];
            node[1] += f[1];
        }
    }
    Ok(())
}
