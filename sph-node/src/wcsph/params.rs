//! [`WcsphParams`]: what only the WCSPH solver uses, beyond the shared [`crate::params::SphParams`].

use cosim_proto::scene::{DensityFilter, FluidSpec};
use serde::{Deserialize, Serialize};

use crate::error::{Result, SphError};
use crate::setup;

/// WCSPH settings: the sound speed and artificial viscosity of the rates, the density filter, APD and the δ-SPH
/// diffusion.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WcsphParams {
    /// Speed of sound c0 (Tait law, Eq. (11), stable step).
    pub c0: f64,
    /// α_π of Eq. (11).
    pub alpha: f64,
    /// Density filter interval in steps (`None`: off); the filter (Shepard or MLS) is chosen by
    /// [`WcsphParams::mls`].
    pub shepard_interval: Option<u32>,
    /// The density filter passes (every [`WcsphParams::shepard_interval`] steps) use the first-order MLS filter
    /// (Colagrossi & Landrini 2003) instead of Shepard's.
    pub mls: bool,
    /// APD β (0: off; §4.4, Xu et al. 2009).
    pub apd: f64,
    /// Central body force a = −k x (k = Ω², Monaghan & Rafiee 2013 oscillating drop); 0 for scenes.
    pub central_force: f64,
    /// δ of the δ-SPH density diffusion in the continuity equation (0: off; `fluid.density_diffusion`,
    /// [`crate::wcsph::density_diffusion`]).
    pub density_diffusion: f64,
    /// The density diffusion leaves out the hydrostatic correction of Fourtakas et al. 2019 (plain Molteni &
    /// Colagrossi 2009; tests and comparisons only, no scene key).
    pub density_diffusion_uncorrected: bool,
    /// Skin of the search's Verlet candidate lists in units of h (0: the cells are searched every step;
    /// `fluid.verlet_skin`, [`crate::neighbors::VerletCandidates`]).
    pub verlet_skin: f64,
}

impl WcsphParams {
    /// The scene's `[fluid]` settings for WCSPH (`gravity` for the default sound speed).
    pub fn from_scene(spec: &FluidSpec, gravity: [f64; 2]) -> Result<Self> {
        let shepard_interval = match spec.density_filter() {
            DensityFilter::None => None,
            DensityFilter::Shepard | DensityFilter::Mls if spec.density_filter_interval == 0 => {
                return Err(SphError::InvalidScene {
                    key: "fluid.density_filter_interval".into(),
                    message: "must be at least 1 step".into(),
                })
            }
            DensityFilter::Shepard | DensityFilter::Mls => Some(spec.density_filter_interval),
        };
        Ok(Self {
            c0: setup::sound_speed(spec, gravity)?,
            alpha: spec.artificial_viscosity,
            shepard_interval,
            mls: spec.density_filter() == DensityFilter::Mls,
            // The scene's default is 0 for now: with β = 0.04 the 10 s still tank ends 8–11 % off the hydrostatic
            // pressure (the δ+-SPH shift fights the cubic spline's pairing mode; docs/CORRECTIONS.md).
            apd: spec.apd(),
            central_force: 0.0,
            density_diffusion: spec.density_diffusion,
            density_diffusion_uncorrected: false,
            verlet_skin: spec.verlet_skin(),
        })
    }
}
