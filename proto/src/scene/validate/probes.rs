//! The `[[probe]]` list: unique names, the keys each kind needs, points where the fluid can reach or on a solid, and
//! a pressure sensor's face.

use std::collections::HashSet;

use super::{check, finite_positive, probe_point, Invalid};
use crate::scene::schema::{ProbeKind, Scene};
use crate::Num;

/// The largest half-width of a pressure sensor's face, in fluid spacings.
const SENSOR_RADIUS_MAX: f64 = 100.0;

/// Every probe of `scene`, in file order (`solids`: the solids' names); the first problem as its key and one line.
pub(super) fn validate_probes(scene: &Scene, solids: &HashSet<&str>) -> Result<(), Invalid> {
    let mut names = HashSet::with_capacity(scene.probes.len());
    for (p, probe) in scene.probes.iter().enumerate() {
        let key = |k: &str| format!("probe[{p}].{k}");
        check(
            !probe.name.trim().is_empty() && !probe.name.contains(','),
            || key("name"),
            || "must be non-empty and contain no comma".into(),
        )?;
        check(
            names.insert(probe.name.as_str()),
            || key("name"),
            || format!("`{}` is used by another probe", probe.name),
        )?;
        let finite = |v: &[f64]| v.iter().all(|v| v.is_finite());
        check(
            probe.point.is_none_or(|p| finite(&p)),
            || key("point"),
            || format!("must be finite, got {:?}", probe.point.unwrap_or_default()),
        )?;
        check(
            probe.x_max.is_none_or(f64::is_finite),
            || key("x_max"),
            || format!("must be finite, got {}", Num(probe.x_max.unwrap_or_default())),
        )?;
        // A fluid probe outside everything the scene holds would read 0 (or, a gauge, its distance to the
        // water) for the whole run.
        if let (Some(point), ProbeKind::Pressure | ProbeKind::WaterLevel) = (probe.point, probe.kind) {
            let [lo, hi] = extent(scene);
            check(
                (0..2).all(|k| (lo[k]..=hi[k]).contains(&point[k])),
                || key("point"),
                || {
                    format!(
                        "{point:?} lies outside the scene: its blocks, walls and solids span x {:.3} to {:.3} m and y \
                         {:.3} to {:.3} m with their size around them; no water reaches it",
                        Num(lo[0]),
                        Num(hi[0]),
                        Num(lo[1]),
                        Num(hi[1])
                    )
                },
            )?;
        }
        if let Some(name) = &probe.solid {
            check(
                solids.contains(name.as_str()),
                || key("solid"),
                || format!("no solid named `{name}` (solids: {})", solid_names(scene)),
            )?;
        }
        match probe.kind {
            ProbeKind::NodeDisplacement => {
                check(
                    probe.solid.is_some(),
                    || key("solid"),
                    || "missing key (node_displacement)".into(),
                )?;
                check(
                    probe.point.is_some(),
                    || key("point"),
                    || "missing key (node_displacement)".into(),
                )?;
                let on = scene.solids.iter().find(|s| Some(&s.name) == probe.solid.as_ref());
                if let (Some(point), Some(solid)) = (probe.point, on) {
                    probe_point::on_solid(p, point, solid)?;
                }
                check(
                    probe.component.is_some(),
                    || key("component"),
                    || "missing key (node_displacement)".into(),
                )?;
            }
            ProbeKind::Energy => {
                check(probe.part.is_some(), || key("part"), || "missing key (energy)".into())?;
            }
            ProbeKind::InterfaceLoad => {
                check(
                    !scene.solids.is_empty() && scene.fluid.is_some(),
                    || key("kind"),
                    || "needs a [[solid]] and a [fluid] in the scene".into(),
                )?;
                check(
                    probe.component.is_some(),
                    || key("component"),
                    || "missing key (interface_load)".into(),
                )?;
            }
            ProbeKind::SurgeFront | ProbeKind::ColumnHeight | ProbeKind::Pressure | ProbeKind::WaterLevel => {
                check(
                    scene.fluid.is_some(),
                    || key("kind"),
                    || "needs a [fluid] in the scene".into(),
                )?;
                let (needed, present) = match probe.kind {
                    ProbeKind::SurgeFront => ("component", probe.component.is_some()),
                    ProbeKind::ColumnHeight => ("x_max", probe.x_max.is_some_and(f64::is_finite)),
                    _ => ("point", probe.point.is_some()),
                };
                check(
                    present,
                    || key(needed),
                    || format!("missing key ({:?})", probe.kind).to_lowercase(),
                )?;
                if let (ProbeKind::ColumnHeight, Some(x_max), Some(fluid)) = (probe.kind, probe.x_max, &scene.fluid) {
                    // The first column of particles of a block is half a spacing inside it (sph-node setup).
                    let first = fluid
                        .blocks
                        .iter()
                        .map(|b| b.min[0] + 0.5 * fluid.spacing)
                        .fold(f64::INFINITY, f64::min);
                    check(
                        x_max >= first,
                        || key("x_max"),
                        || {
                            format!(
                                "{} is left of every fluid particle (the first are at x = {}): the column \
                                 would be empty from the start",
                                Num(x_max),
                                Num(first)
                            )
                        },
                    )?;
                }
            }
        }
        // A sensor's face and time mean (pressure probes only).
        for (k, present) in [
            ("radius", probe.radius.is_some()),
            ("normal", probe.normal.is_some()),
            ("average", probe.average.is_some()),
        ] {
            check(
                !present || probe.kind == ProbeKind::Pressure,
                || key(k),
                || "only a pressure probe takes this key".into(),
            )?;
        }
        if let Some(r) = probe.radius {
            check(
                r.is_finite() && r >= 0.0,
                || key("radius"),
                || format!("must be a finite length >= 0, got {}", Num(r)),
            )?;
            // The face is sampled a quarter spacing apart (`sensors.rs`): 8 points a spacing of radius.
            let dx = scene.fluid.as_ref().map_or(f64::INFINITY, |f| f.spacing);
            check(
                r <= SENSOR_RADIUS_MAX * dx,
                || key("radius"),
                || {
                    format!(
                        "{} m is more than {SENSOR_RADIUS_MAX} fluid spacings ({} m): a sensor's face is \
                         sampled every quarter spacing, every step",
                        Num(r),
                        Num(SENSOR_RADIUS_MAX * dx)
                    )
                },
            )?;
            let n = probe.normal.unwrap_or([0.0, 0.0]);
            check(
                r == 0.0 || (finite(&n) && n[0].hypot(n[1]) > 0.0),
                || key("normal"),
                || match probe.normal {
                    None => "missing key (a face with radius > 0 needs the normal it lies across)".into(),
                    Some(n) => format!("must be a finite non-zero vector, got {n:?}"),
                },
            )?;
        }
        if let Some(r) = &probe.reference {
            finite_positive(&key("reference.scale"), r.scale.abs())?;
            for (k, v) in [("t_scale", r.t_scale), ("t_offset", r.t_offset)] {
                check(
                    v.is_finite(),
                    || key(&format!("reference.{k}")),
                    || format!("must be finite, got {}", Num(v)),
                )?;
            }
        }
    }
    Ok(())
}

/// The box around the fluid's blocks, the walls and the solids, padded on every side by its larger size: where
/// the water can go (the fluid node's domain pads by half that, `sph_node::setup`).
fn extent(scene: &Scene) -> [[f64; 2]; 2] {
    let (lo, hi) = scene.bounds();
    let pad = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    [[lo[0] - pad, lo[1] - pad], [hi[0] + pad, hi[1] + pad]]
}

fn solid_names(scene: &Scene) -> String {
    if scene.solids.is_empty() {
        return "none".into();
    }
    scene
        .solids
        .iter()
        .map(|s| s.name.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}
