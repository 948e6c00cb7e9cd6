//! `[contact]`: the contact algorithm between water and structures and its settings.

use serde::{Deserialize, Serialize};

/// Contact algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactAlgorithm {
    /// Long et al. 2016 particle–element contact.
    ParticleElement,
    /// Repulsive-force baseline.
    ParticleParticle,
    /// No contact.
    None,
}

impl ContactAlgorithm {
    /// The scene spelling (`particle_element` | `particle_particle` | `none`).
    pub fn name(self) -> &'static str {
        match self {
            ContactAlgorithm::ParticleElement => "particle_element",
            ContactAlgorithm::ParticleParticle => "particle_particle",
            ContactAlgorithm::None => "none",
        }
    }
}

/// `[contact]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Algorithm.
    #[serde(default = "default_algorithm")]
    pub algorithm: ContactAlgorithm,
    /// Contact thickness r_c \[m\]; default spacing / 2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// Gauss–Seidel sweeps.
    #[serde(default = "default_sweeps")]
    pub sweeps: u32,
    /// Whether the position correction also moves the structure's nodes (λ N_a / m_a, `DESIGN.md` §4.5 as
    /// written). Off by default: the structure takes its share of the *velocity* correction (the momentum), and
    /// its displacement follows from its own dynamics; moving FE nodes by a share of the penetration that goes
    /// with 1/m rather than with 1/stiffness puts strain energy ½ k δ² into stiff structures that no contact
    /// had (the hydrostatic plate inverts an element within 120 steps with it on).
    #[serde(default)]
    pub move_structure: bool,
    /// `particle_particle` only: the fraction ω ∈ (0, 1] of the contact impulse it is owed that each structure
    /// node receives per coupling step (the rest later), against the added-mass instability of the explicit
    /// coupling with ISPH. Default: 1 (all at once) with WCSPH; with ISPH 1/(1 + r), r the largest added-mass
    /// ratio of the scene's solids (`contact-broker/src/relaxation.rs`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reaction_relaxation: Option<f64>,
    /// The structure's share of each contact impulse spread over the interface nodes within this many fluid
    /// spacings of its node, along the surface, with weights 1 − d/R (`contact-broker/src/load_spread.rs`); 0, the
    /// default, leaves it on the segment's nodes as the contact algorithm puts it. In [0, 4].
    #[serde(default, skip_serializing_if = "super::is_zero")]
    pub load_spread: f64,
}

fn default_algorithm() -> ContactAlgorithm {
    ContactAlgorithm::ParticleElement
}

fn default_sweeps() -> u32 {
    3
}

impl Default for ContactSpec {
    fn default() -> Self {
        Self {
            algorithm: default_algorithm(),
            thickness: None,
            sweeps: default_sweeps(),
            move_structure: false,
            reaction_relaxation: None,
            load_spread: 0.0,
        }
    }
}
