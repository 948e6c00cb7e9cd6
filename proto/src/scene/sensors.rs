//! Pressure sensors: the points a `pressure` probe averages over (its face, `radius` and `normal`), and the probes
//! whose time mean over the sampling interval the fluid node computes every step (`average = "interval"`). The
//! broker (instantaneous probes) and the fluid node (interval means) read both from here, so they sample the same
//! points.

use super::schema::{Average, ProbeKind, Scene};

/// One pressure probe's face: the points whose interpolated pressures it averages.
#[derive(Clone, Debug, PartialEq)]
pub struct PressureSensor {
    /// Index of the probe in the scene's `[[probe]]` list.
    pub probe: usize,
    /// The points of the face: `point` alone for a point sensor, else points a quarter spacing apart across
    /// `normal`, over `point ± radius`, both ends included.
    pub points: Vec<[f64; 2]>,
}

impl PressureSensor {
    /// The face of pressure probe `probe` of `scene` (fluid spacing `spacing`); `None` for another kind.
    pub fn of(scene: &Scene, probe: usize, spacing: f64) -> Option<Self> {
        let spec = scene.probes.get(probe)?;
        if spec.kind != ProbeKind::Pressure {
            return None;
        }
        let point = spec.point?;
        let radius = spec.radius.unwrap_or(0.0);
        let points = match spec.normal {
            Some(n) if radius > 0.0 => {
                let len = (n[0] * n[0] + n[1] * n[1]).sqrt();
                let tangent = [-n[1] / len, n[0] / len];
                let half = (radius / (0.25 * spacing)).ceil().max(1.0) as usize;
                (0..=2 * half)
                    .map(|k| {
                        let s = radius * (k as f64 / half as f64 - 1.0);
                        [point[0] + s * tangent[0], point[1] + s * tangent[1]]
                    })
                    .collect()
            }
            _ => vec![point],
        };
        Some(Self { probe, points })
    }

    /// The pressure probes of `scene` whose interval mean the fluid node computes, in scene order.
    pub fn interval(scene: &Scene) -> Vec<Self> {
        let Some(fluid) = &scene.fluid else {
            return Vec::new();
        };
        (0..scene.probes.len())
            .filter(|&p| scene.probes[p].average == Some(Average::Interval))
            .filter_map(|p| Self::of(scene, p, fluid.spacing))
            .collect()
    }
}

/// The mean of `values` (one per face point): their sum over their count, so a point sensor's value is its one
/// point's, bit for bit.
pub fn face_mean(values: impl ExactSizeIterator<Item = f64>) -> f64 {
    let n = values.len();
    values.sum::<f64>() / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped Lobovsky scene (Δx = 0.01 m): probes 0 and 1 are interval sensors, 2 and 3 their instantaneous
    /// twins, at x = 1.605 m, y = 3 and 15 mm.
    fn lobovsky(sets: &[&str]) -> Scene {
        let text = include_str!("../../../scenes/lobovsky_dam_break.toml");
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        crate::scene::parse("lobovsky_dam_break.toml", text, &sets).expect("the shipped scene")
    }

    #[test]
    fn a_face_spans_its_width_across_the_normal_a_quarter_spacing_apart() {
        let s = lobovsky(&["probe[0].radius=0.005", "probe[0].normal=[-2.0, 0.0]"]);
        let faces = PressureSensor::interval(&s);
        assert_eq!(faces.iter().map(|f| f.probe).collect::<Vec<_>>(), vec![0, 1]);
        let y: Vec<f64> = faces[0].points.iter().map(|p| p[1]).collect();
        // radius 5 mm, quarter spacing 2.5 mm: 5 points from y = 0.008 down to −0.002 (the tangent of −x is −y).
        assert_eq!(y.len(), 5, "{y:?}");
        for (got, want) in y.iter().zip([0.008, 0.0055, 0.003, 0.0005, -0.002]) {
            assert!((got - want).abs() < 1e-15, "{y:?}");
        }
        assert!(faces[0].points.iter().all(|p| p[0] == 1.605));
        assert_eq!(faces[1].points, vec![[1.605, 0.015]]);
    }

    #[test]
    fn a_point_sensor_is_its_point_and_not_in_the_interval_list_unless_asked() {
        let s = lobovsky(&[]);
        assert_eq!(
            PressureSensor::of(&s, 2, 0.01).expect("pressure").points,
            vec![[1.605, 0.003]]
        );
        assert!(
            PressureSensor::of(&s, 4, 0.01).is_none(),
            "surge_front is not a pressure probe"
        );
        let none = lobovsky(&["probe[0].average=none", "probe[1].average=none"]);
        assert!(PressureSensor::interval(&none).is_empty());
        assert_eq!(face_mean([3.25].into_iter()), 3.25);
    }
}
