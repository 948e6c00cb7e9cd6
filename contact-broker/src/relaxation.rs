//! The contact reaction the structure receives, relaxed across coupling steps: the cure for the added-mass
//! instability of the explicit coupling of a light structure with an incompressible fluid (issue 16;
//! docs/CORRECTIONS.md "The ISPH + `particle_particle` gate: the reaction relaxed").
//!
//! The coupling is explicit: the structure receives, after each step, the impulse the contact pass computed from
//! the state that step ended in. Against an incompressible fluid (ISPH) the force that answers the structure's
//! acceleration moves the whole water in front of it at once, with its added mass m_a: in the model
//! m_s a^{n+1} = −m_a a^n the error is multiplied by r = m_a/m_s every step and grows for r > 1 (Causin, Gerbeau &
//! Nobile 2005, Comput. Methods Appl. Mech. Engrg. 194:4506). Here each structure node is owed the impulse the pass
//! gave it, O += J^n, and receives the fraction ω of what it is owed, G^n = ω O, O −= G^n; so
//! G^n = ω J^n + (1 − ω) G^{n−1}, and the model becomes a^{n+1} = (1 − ω (1 + r)) a^n: stable for ω < 2/(1 + r),
//! and with ω = 1/(1 + r) the error is gone in one step. This is the fictitious-mass method of Baek & Karniadakis
//! (2012, J. Comput. Phys. 231:629) applied to the contact's impulse: m_s Δv^n = G^n ⇔ (m_s + m_f) Δv^n =
//! J^n + m_f Δv^{n−1} with m_f = m_s (1 − ω)/ω. The fluid still receives its whole impulse at once (it is what
//! keeps particles off the structure); what the structure has not yet received is held here ([`Relaxation::owed`],
//! saved with a checkpoint), so Σ G + O = Σ J to round-off: linear momentum is conserved over the run, the owed
//! part reaching the structure a few steps late (its lag is about Δt/ω).
//!
//! The lag has a cost of its own. The repulsive force holds a particle in its range like a spring of frequency
//! Ω_c = √(D (p1 − p2)) / r0 (the force's slope at r0), and a structure that receives that spring's reaction
//! through a first-order lag τ = Δt/ω is driven in quadrature with it: energy is fed in at a rate ∝ Ω_c τ /
//! (1 + (Ω_c τ)²), worst at Ω_c τ = 1 (the shipped obstacle, Ω_c τ ≈ 1 at ω = 0.27, gains 27.5 J/m there, 0.8 J/m
//! at ω = 1 and 0.16 J/m at ω = 0.03). So by default the lag also spans [`LAG_PERIODS`] radians of the force's
//! oscillation: ω_n = min(1/(1 + r), Δt_n Ω_c / 5) in a coupling step of length Δt_n. Longer is not better: at
//! Ω_c τ = 10 the gate's interface answers so late that its tip overshoots to 0.057 m (docs/CORRECTIONS.md).
//!
//! With WCSPH the relaxation is off (ω = 1) unless the scene asks: the fluid's compressibility already spreads the
//! water's answer over the acoustic time (the shipped gate with ω = 0.1, Ω_c τ ≈ 2: unstable at t = 0.336 s; with
//! 0.02, Ω_c τ ≈ 11, its energy is kept better than at 1, which docs/CORRECTIONS.md records and leaves as a
//! choice). Fixed nodes pass their reaction on at once.

use cosim_proto::scene::{ContactAlgorithm, FluidSolver, Scene};
use serde::{Deserialize, Serialize};

use crate::contact::ParticleParticleParams;

/// Ω_c τ of the default lag: how many radians of the repulsive force's own oscillation it spans.
pub const LAG_PERIODS: f64 = 5.0;

/// How much of its owed contact impulse a structure node receives per coupling step, and why (`summary.json`
/// `reaction_relaxation`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RelaxationChoice {
    /// The largest ω ∈ (0, 1] of a step.
    pub omega: f64,
    /// The lag τ [s] that bounds ω at Δt/τ in a step of length Δt; 0 for none.
    pub lag: f64,
    /// Where ω comes from, for the run's log.
    pub reason: String,
}

/// The ω of `scene` with the repulsive force `force`: `contact.reaction_relaxation` when it is given (every step);
/// else, for `particle_particle` with ISPH, min(1/(1 + r), Δt Ω_c / [`LAG_PERIODS`]) with r = ρ_f L / (ρ_s h) the
/// largest added-mass ratio of the solids, L the longer of the solid's longest side and the deepest water, h its
/// shortest side (a plate of thickness h whose motion moves a water column as long as L: an estimate on the safe
/// side, since a smaller ω only lengthens the lag), and Ω_c = √(D (p1 − p2)) / r0; else 1.
pub fn choose(scene: &Scene, force: &ParticleParticleParams) -> RelaxationChoice {
    if let Some(omega) = scene.contact.reaction_relaxation {
        return RelaxationChoice {
            omega,
            lag: 0.0,
            reason: "contact.reaction_relaxation".into(),
        };
    }
    let isph = scene.fluid.as_ref().filter(|f| f.solver == FluidSolver::Isph);
    let (Some(fluid), ContactAlgorithm::ParticleParticle) = (isph, scene.contact.algorithm) else {
        return RelaxationChoice {
            omega: 1.0,
            lag: 0.0,
            reason: "off: not ISPH with particle_particle".into(),
        };
    };
    let depth = fluid.blocks.iter().map(|b| b.max[1] - b.min[1]).fold(0.0, f64::max);
    let worst = scene
        .solids
        .iter()
        .map(|s| {
            let (w, h) = (s.max[0] - s.min[0], s.max[1] - s.min[1]);
            let r = fluid.density * w.max(h).max(depth) / (s.material.density * w.min(h));
            (r, s.name.as_str())
        })
        .max_by(|a, b| a.0.total_cmp(&b.0));
    match worst {
        Some((r, name)) if r.is_finite() && r > 0.0 => {
            let (omega, omega_c) = (
                1.0 / (1.0 + r),
                (force.strength * f64::from(force.p1 - force.p2)).sqrt() / force.r0,
            );
            let lag = if omega_c.is_finite() && omega_c > 0.0 {
                LAG_PERIODS / omega_c
            } else {
                0.0
            };
            RelaxationChoice {
                omega,
                lag,
                reason: format!(
                    "ISPH with particle_particle: at most 1/(1 + r) = {omega:.4}, added-mass ratio r = {r:.3} of solid \
                     `{name}`, and Δt/τ, lag τ = {LAG_PERIODS}/Ω_c = {lag:.3e} s"
                ),
            }
        }
        _ => RelaxationChoice {
            omega: 1.0,
            lag: 0.0,
            reason: "off: no solid with an added-mass ratio".into(),
        },
    }
}

/// The impulse each structure node is owed and not yet given (`particle_particle` with ω < 1), and the choice of ω.
#[derive(Clone, Debug, PartialEq)]
pub struct Relaxation {
    /// ω ≤ `choice.omega` a step and, where `choice.lag` τ > 0, ω ≤ Δt/τ.
    choice: RelaxationChoice,
    /// Per interface node [N·s/m]; empty while nothing is owed, so ω = 1 costs nothing.
    owed: Vec<[f64; 2]>,
}

impl Relaxation {
    /// Relaxation as `choice` says; ω 1 and lag 0 give every impulse at once.
    pub fn new(choice: RelaxationChoice) -> Self {
        Self {
            choice,
            owed: Vec::new(),
        }
    }

    /// Whether impulses are held back at all.
    pub fn active(&self) -> bool {
        self.choice.omega < 1.0 || self.choice.lag > 0.0
    }

    /// The choice of ω where impulses are held back; `None` where every one is given at once.
    pub fn choice(&self) -> Option<&RelaxationChoice> {
        self.active().then_some(&self.choice)
    }

    /// ω of a step of length `dt`.
    pub fn omega(&self, dt: f64) -> f64 {
        let RelaxationChoice { omega, lag, .. } = self.choice;
        if lag > 0.0 {
            omega.min(dt / lag)
        } else {
            omega
        }
    }

    /// The impulse owed to each interface node; empty where nothing ever was.
    pub fn owed(&self) -> &[[f64; 2]] {
        &self.owed
    }

    /// Restore what a checkpoint saved ([`Relaxation::owed`]): empty, or one impulse per interface node.
    pub fn restore(&mut self, owed: &[[f64; 2]], nodes: usize) -> anyhow::Result<()> {
        anyhow::ensure!(
            owed.is_empty() || owed.len() == nodes,
            "owed contact impulse for {} nodes, the interface has {nodes}",
            owed.len()
        );
        self.owed = owed.to_vec();
        Ok(())
    }

    /// Turns the impulses `impulse` the pass gave the interface nodes after a step of length `dt` into those they
    /// receive now: a free node is owed its impulse and receives ω of what it is owed; a fixed one receives its own
    /// at once. Returns per node the impulse received less the pass's (to add to the node's velocity times its
    /// mass), and overwrites `impulse` with the impulse received.
    pub fn give(&mut self, impulse: &mut [[f64; 2]], fixed: &[bool], dt: f64) -> Vec<[f64; 2]> {
        if !self.active() {
            return vec![[0.0; 2]; impulse.len()];
        }
        if self.owed.len() != impulse.len() {
            self.owed = vec![[0.0; 2]; impulse.len()];
        }
        let w = self.omega(dt);
        let mut change = vec![[0.0; 2]; impulse.len()];
        for ((j, owed), (c, &fixed)) in impulse.iter_mut().zip(&mut self.owed).zip(change.iter_mut().zip(fixed)) {
            if fixed {
                continue;
            }
            for d in 0..2 {
                let total = owed[d] + j[d];
                let given = w * total;
                owed[d] = total - given;
                c[d] = given - j[d];
                j[d] = given;
            }
        }
        change
    }
}

#[cfg(test)]
mod tests;
