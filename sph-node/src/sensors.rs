//! Pressure sensors (`DESIGN.md` §5 `pressure` probes): the Shepard-normalised SPH pressure at a point, the mean
//! over a sensor's face, and the time mean over a sampling interval that the node keeps step by step
//! ([`IntervalSensors`]). The broker evaluates instantaneous probes with [`pressure_at`] on its snapshot, the node
//! the interval means on its own state: the same formula on the same numbers.

use cosim_proto::scene::{sensors_face_mean, PressureSensor, Scene};
use serde::{Deserialize, Serialize};

use crate::kernel::CubicSpline;

/// The particles the probes read: fluid (positions, masses, densities, pressures) and wall positions (their volume
/// is the lattice cell Δx²).
pub struct PressureField<'a> {
    /// Fluid positions.
    pub x: &'a [[f64; 2]],
    /// Fluid masses.
    pub m: &'a [f64],
    /// Fluid densities.
    pub rho: &'a [f64],
    /// Fluid pressures.
    pub p: &'a [f64],
    /// Wall particle positions (the water-level gauges count them as filled space; pressures leave them out).
    pub wall_x: &'a [[f64; 2]],
    /// Smoothing length h.
    pub h: f64,
    /// Particle spacing Δx.
    pub spacing: f64,
}

/// The fluid's pressure at `point`: the Shepard-normalised SPH interpolation Σ_f p_f V_f W / Σ_f V_f W over the
/// fluid particles within the kernel's reach (V_f = m_f/ρ_f), as DualSPHysics' gauges interpolate (fluid particles
/// only, kernel-corrected: `JDsGaugeItem.cpp`, `CODE_IsFluid`); 0, the atmosphere's gauge pressure, where no fluid
/// particle is in reach (a dry sensor).
///
/// Wall particles are left out: their pressures are the boundary condition's device, not the fluid's state (WCSPH:
/// Adami et al. 2012's extrapolation; ISPH: the unknowns of the walls' Neumann rows, which carry the impulse that
/// stops the fluid's normal motion). Each wall particle's value is a Shepard mean over the fluid in *its* reach, so one
/// drop within 2h of a wall gives every wall particle in that reach the drop's full term, whatever their distance
/// along the wall: at the Lobovsky sensors (ISPH, H/30) a single free-surface particle running ahead of the front
/// made four wall particles over 4 cm of the wall read 12–15 ρgH for 5 ms, and a probe that took walls in reported
/// 10.5 ρgH where the fluid's pressure was 0 (docs/CORRECTIONS.md, "What a pressure probe reads").
pub fn pressure_at(field: &PressureField<'_>, point: [f64; 2]) -> f64 {
    let kernel = CubicSpline::new(field.h);
    let support2 = kernel.support() * kernel.support();
    let (mut num, mut den) = (0.0, 0.0);
    for ((x, (m, rho)), p) in field.x.iter().zip(field.m.iter().zip(field.rho)).zip(field.p) {
        let r2 = (x[0] - point[0]).powi(2) + (x[1] - point[1]).powi(2);
        if r2 < support2 {
            let w = kernel.w(r2.sqrt()) * (m / rho);
            num += p * w;
            den += w;
        }
    }
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// A sensor's value: the mean of the pressure over its face's points.
pub fn sensor_pressure(field: &PressureField<'_>, sensor: &PressureSensor) -> f64 {
    sensors_face_mean(sensor.points.iter().map(|&x| pressure_at(field, x)))
}

/// The running time integrals of the interval sensors since the last sample: what a node carries between steps
/// (and in its checkpoint) to report each sensor's time mean at the next snapshot.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SensorLog {
    /// Σ p_k Δt_k per sensor [Pa s].
    pub integral: Vec<f64>,
    /// Σ Δt_k [s].
    pub time: f64,
}

/// The scene's interval sensors and their log.
#[derive(Clone, Debug, Default)]
pub struct IntervalSensors {
    sensors: Vec<PressureSensor>,
    log: SensorLog,
}

impl IntervalSensors {
    /// The interval sensors of `scene` (`average = "interval"` pressure probes), none logged yet.
    pub fn new(scene: &Scene) -> Self {
        let sensors = PressureSensor::interval(scene);
        let log = SensorLog {
            integral: vec![0.0; sensors.len()],
            time: 0.0,
        };
        Self { sensors, log }
    }

    /// How many there are.
    pub fn len(&self) -> usize {
        self.sensors.len()
    }

    /// Whether the scene has none.
    pub fn is_empty(&self) -> bool {
        self.sensors.is_empty()
    }

    /// Log the state after a step of length `dt`.
    pub fn after_step(&mut self, field: &PressureField<'_>, dt: f64) {
        for (sum, sensor) in self.log.integral.iter_mut().zip(&self.sensors) {
            *sum += sensor_pressure(field, sensor) * dt;
        }
        self.log.time += dt;
    }

    /// Each sensor's time mean since the last call (the value in `field` where no step was logged since), and a
    /// fresh log.
    pub fn take_means(&mut self, field: &PressureField<'_>) -> Vec<f64> {
        let means = if self.log.time > 0.0 {
            self.log.integral.iter().map(|s| s / self.log.time).collect()
        } else {
            self.sensors.iter().map(|s| sensor_pressure(field, s)).collect()
        };
        self.log.integral.iter_mut().for_each(|s| *s = 0.0);
        self.log.time = 0.0;
        means
    }

    /// The log, for a checkpoint.
    pub fn log(&self) -> &SensorLog {
        &self.log
    }

    /// Continue from a checkpoint's log; `Err` names what does not fit this scene's sensors.
    pub fn restore(&mut self, log: SensorLog) -> Result<(), String> {
        if log.integral.len() != self.sensors.len() || !(log.time >= 0.0 && log.time.is_finite()) {
            return Err(format!(
                "sensors: the checkpoint logs {} interval sensors over {} s, the scene has {}",
                log.integral.len(),
                log.time,
                self.sensors.len()
            ));
        }
        self.log = log;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Particle spacing of the test lattices [m].
    const DX: f64 = 0.01;

    /// A 20 × 20 lattice of fluid particles Δx apart (0.1 kg/m, ρ = 1000), no walls.
    struct Lattice {
        x: Vec<[f64; 2]>,
        m: Vec<f64>,
        rho: Vec<f64>,
    }

    impl Lattice {
        fn new() -> Self {
            let x: Vec<[f64; 2]> = (0..400).map(|k| [DX * (k % 20) as f64, DX * (k / 20) as f64]).collect();
            let n = x.len();
            Self {
                x,
                m: vec![0.1; n],
                rho: vec![1000.0; n],
            }
        }

        /// The lattice carrying pressures `p`, read with h = 1.3 Δx.
        fn field<'a>(&'a self, p: &'a [f64]) -> PressureField<'a> {
            PressureField {
                x: &self.x,
                m: &self.m,
                rho: &self.rho,
                p,
                wall_x: &[],
                h: 1.3 * DX,
                spacing: DX,
            }
        }
    }

    /// A still column's hydrostatic pressure p = ρ g (H − y) on a lattice: a sensor's interval mean over steps of
    /// different lengths is the time-weighted mean of its per-step values.
    #[test]
    fn the_interval_mean_weights_each_step_by_its_length() {
        let lattice = Lattice::new();
        let sensor = PressureSensor {
            probe: 0,
            points: vec![[0.1, 0.1]],
        };
        let mut sensors = IntervalSensors {
            sensors: vec![sensor.clone()],
            log: SensorLog {
                integral: vec![0.0],
                time: 0.0,
            },
        };
        let mut values = Vec::new();
        for (scale, dt) in [(1.0, 1e-3), (3.0, 2e-3), (0.5, 5e-4)] {
            let p: Vec<f64> = lattice.x.iter().map(|x| scale * 9810.0 * (0.2 - x[1])).collect();
            let field = lattice.field(&p);
            values.push((sensor_pressure(&field, &sensor), dt));
            sensors.after_step(&field, dt);
        }
        let want = values.iter().map(|(v, dt)| v * dt).sum::<f64>() / 3.5e-3;
        let p: Vec<f64> = vec![0.0; lattice.x.len()];
        let field = lattice.field(&p);
        let got = sensors.take_means(&field);
        assert!((got[0] - want).abs() <= 1e-12 * want.abs(), "{got:?} vs {want}");
        // The point value of the middle step is ~3× the hydrostatic 981 Pa: the mean sits between, weighted.
        assert!(values[0].0 > 900.0 && values[0].0 < 1100.0, "{values:?}");
        // A fresh log: with no step since, the value now (0 here).
        assert_eq!(sensors.take_means(&field), vec![0.0]);
    }

    /// The probe reads the fluid, not the walls: a lone free-surface drop (p = 0) in reach of five wall particles,
    /// as at the Lobovsky sensors, reads exactly the drop's pressure; a point with no fluid in reach reads 0 (the
    /// atmosphere), not NaN; inside a lattice with a linear pressure the Shepard mean is exact.
    #[test]
    fn a_pressure_probe_interpolates_the_fluid_only() {
        let walls: Vec<[f64; 2]> = (0..5).map(|k| [1.615, -0.005 + DX * k as f64]).collect();
        let drop = [[1.6009, 0.0052]];
        let (m, rho) = ([0.1], [1000.0]);
        let probe = |p: f64, point: [f64; 2]| {
            let p = [p];
            let field = PressureField {
                x: &drop,
                m: &m,
                rho: &rho,
                p: &p,
                wall_x: &walls,
                h: 1.3 * DX,
                spacing: DX,
            };
            pressure_at(&field, point)
        };
        assert_eq!(probe(0.0, [1.605, 0.015]), 0.0);
        assert_eq!(probe(1234.5, [1.605, 0.015]), 1234.5);
        // out of the drop's reach (2h = 2.6 cm): dry, 0 — not NaN
        assert_eq!(probe(1234.5, [1.605, 0.05]), 0.0);
        // a lattice with p = ρ g (0.2 − y): at a lattice point inside, the Shepard mean of the linear field is exact
        let lattice = Lattice::new();
        let p: Vec<f64> = lattice.x.iter().map(|x| 9810.0 * (0.2 - x[1])).collect();
        let got = pressure_at(&lattice.field(&p), [0.1, 0.1]);
        assert!((got - 981.0).abs() <= 1e-9, "{got}");
    }
}
