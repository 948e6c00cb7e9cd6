//! What every contact algorithm offers the interface (`DESIGN.md` §3 step 4): one pass that corrects the bodies in
//! place after a coupling step. Each implementation owns its parameters and its scratch memory (as salva couples
//! its fluid to other solvers behind a trait); the unit type `()` is the algorithm that does nothing, for scenes
//! with `[contact] algorithm = "none"`.

use super::bodies::{Nodes, Particles, Segment};
use super::error::ContactError;
use super::pair::ContactPair;

/// A fluid–structure contact algorithm: [`ParticleElement`](super::ParticleElement),
/// [`ParticleParticle`](super::ParticleParticle), or `()` for none.
///
/// An implementation may keep scratch arrays between calls to avoid reallocating them, never state: the result of
/// a call depends on its arguments only.
pub trait ContactAlgorithm: Send {
    /// Whether a pass can change anything. `false` for `()`, so a caller may skip the pass and the copies it needs.
    fn active(&self) -> bool {
        true
    }

    /// Corrects `particles` and `nodes` in place after a coupling step of length `dt` [s]. Nothing is modified
    /// when an error is returned.
    fn correct(
        &mut self,
        particles: Particles<'_>,
        nodes: Nodes<'_>,
        segments: &[Segment],
        dt: f64,
    ) -> Result<PassReport, ContactError>;

    /// The (particle, master) pairs the last pass acted on, where the algorithm records them (particle–element);
    /// `None` where it does not.
    fn pairs(&self) -> Option<&[ContactPair]> {
        None
    }
}

/// What one pass did, whatever the algorithm: what the run reports and the impulse the structure received.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PassReport {
    /// Contacts found (the algorithm's own count: penetrating pairs, or pairs within the force range).
    pub contacts: usize,
    /// Deepest penetration of the contact range [m] (0 without contact).
    pub max_penetration: f64,
    /// Impulse received by each node [N·s/m]: m Δv for a free node, the reaction passed to the support for a fixed
    /// one. Interface load = impulse / Δt.
    pub node_impulse: Vec<[f64; 2]>,
    /// How stiff the pass's contact force was (particle–particle); zero for an algorithm that exerts none.
    pub stiffness: Stiffness,
}

/// Bounds on the squared frequencies [1/s²] at which a contact force holds the bodies, for the coupling step that
/// applies it explicitly (docs/CORRECTIONS.md "`particle_particle` heats the structure"): each is the largest row
/// sum of M⁻¹K (Gershgorin) over the pass's pairs, K their radial stiffness −m ∂a/∂r.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stiffness {
    /// Over the fluid particles: max_i Σ_j 2 k_ij / m_i.
    pub particles: f64,
    /// Over the free structure nodes: max_a Σ 2 N_a k_ij / m_a, the pair's reaction spread on the node with its
    /// shape function N_a.
    pub nodes: f64,
}

/// No contact (`[contact] algorithm = "none"`): nothing is corrected and no node receives an impulse.
impl ContactAlgorithm for () {
    fn active(&self) -> bool {
        false
    }

    fn correct(
        &mut self,
        _particles: Particles<'_>,
        nodes: Nodes<'_>,
        _segments: &[Segment],
        _dt: f64,
    ) -> Result<PassReport, ContactError> {
        Ok(PassReport {
            node_impulse: vec![[0.0; 2]; nodes.x.len()],
            ..PassReport::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{particle_element, particle_particle, ContactParams, ParticleElement, ParticleParticle};
    use crate::contact::{ParticleParticleParams, ParticleParticleReport};

    type V = [f64; 2];

    /// A free segment along y = 0 (structure above, fluid below) and two particles inside the contact thickness,
    /// approaching it.
    fn scene() -> (Vec<V>, Vec<V>, Vec<V>, Vec<V>) {
        (
            vec![[0.3, -0.01], [0.7, -0.02]],
            vec![[0.1, 1.0], [0.0, 0.5]],
            vec![[0.0, 0.0], [1.0, 0.0]],
            vec![[0.0, 0.0], [0.0, -0.2]],
        )
    }

    fn bits(v: &[V]) -> Vec<[u64; 2]> {
        v.iter().map(|p| [p[0].to_bits(), p[1].to_bits()]).collect()
    }

    /// Runs `f` on the scene and returns the bits of the corrected particles and nodes and what `f` returned.
    fn run<R>(f: impl FnOnce(Particles, Nodes, &[Segment]) -> R) -> (Vec<[u64; 2]>, Vec<[u64; 2]>, R) {
        let (mut px, mut pv, mut nx, mut nv) = scene();
        let (pm, nm, fixed) = ([1.0, 2.0], [3.0, 4.0], [false, false]);
        let p = Particles {
            x: &mut px,
            v: &mut pv,
            m: &pm,
        };
        let n = Nodes {
            x: &mut nx,
            v: &mut nv,
            m: &nm,
            fixed: &fixed,
        };
        let r = f(p, n, &[Segment { a: 0, b: 1 }]);
        (bits(&[px, pv].concat()), bits(&[nx, nv].concat()), r)
    }

    #[test]
    fn no_contact_is_inactive_and_changes_nothing() {
        assert!(!().active());
        let (p, n, r) = run(|p, n, s| ().correct(p, n, s, 0.01).unwrap());
        let (px, pv, nx, nv) = scene();
        assert_eq!(p, bits(&[px, pv].concat()));
        assert_eq!(n, bits(&[nx, nv].concat()));
        assert_eq!((r.contacts, r.max_penetration), (0, 0.0));
        assert_eq!(r.node_impulse, vec![[0.0; 2]; 2]);
    }

    /// The trait objects give the bits of the functions they wrap, on a fresh workspace and on a used one.
    #[test]
    fn algorithms_behind_the_trait_match_their_functions() {
        let params = ContactParams::for_spacing(0.05);
        let (p0, n0, r0) = run(|p, n, s| particle_element(p, n, s, &params).unwrap());
        assert!(r0.contacts == 2 && r0.max_penetration > 0.0, "{r0:?}");
        let mut pe: Box<dyn ContactAlgorithm> = Box::new(ParticleElement::new(params));
        for _ in 0..2 {
            assert!(pe.active());
            let (p, n, r) = run(|p, n, s| pe.correct(p, n, s, 0.01).unwrap());
            assert_eq!((p, n), (p0.clone(), n0.clone()));
            assert_eq!((r.contacts, r.max_penetration), (r0.contacts, r0.max_penetration));
            assert_eq!(bits(&r.node_impulse), bits(&r0.node_impulse));
        }

        let params = ParticleParticleParams::monaghan(0.05, 9.81, 1.0);
        let (p0, n0, r0): (_, _, ParticleParticleReport) =
            run(|p, n, s| particle_particle(p, n, s, &params, 0.01).unwrap());
        assert!(r0.contacts > 0, "{r0:?}");
        let mut pp: Box<dyn ContactAlgorithm> = Box::new(ParticleParticle::new(params, true));
        for _ in 0..2 {
            let (p, n, r) = run(|p, n, s| pp.correct(p, n, s, 0.01).unwrap());
            assert_eq!((p, n), (p0.clone(), n0.clone()));
            assert_eq!((r.contacts, r.max_penetration), (r0.contacts, r0.max_penetration));
            assert_eq!(bits(&r.node_impulse), bits(&r0.node_impulse));
        }
    }
}
