//! One `[[solid]]`: its name, rectangle, mesh, material, damping and clamps.

use super::{check, coordinates, finite_positive, magnitude, Invalid};
use crate::scene::schema::SolidSpec;
use crate::Num;

/// `solid[s]`, in file order; the first problem found as its dotted key and one line.
pub(super) fn validate_solid(s: usize, solid: &SolidSpec) -> Result<(), Invalid> {
    let key = |k: &str| format!("solid[{s}].{k}");
    check(
        !solid.name.trim().is_empty(),
        || key("name"),
        || "must not be empty".into(),
    )?;
    for k in 0..2 {
        check(
            solid.min[k].is_finite() && solid.max[k].is_finite() && solid.max[k] > solid.min[k],
            || key("max"),
            || {
                format!(
                    "must be greater than min in every component, got min {:?} max {:?}",
                    solid.min, solid.max
                )
            },
        )?;
        check(
            solid.divisions[k] > 0,
            || key("divisions"),
            || format!("must be at least 1 in every component, got {:?}", solid.divisions),
        )?;
    }
    coordinates(&key("max"), solid.min, solid.max)?;
    let m = &solid.material;
    finite_positive(&key("material.density"), m.density)?;
    magnitude(&key("material.density"), m.density, "kg/m³")?;
    finite_positive(&key("material.youngs_modulus"), m.youngs_modulus)?;
    magnitude(&key("material.youngs_modulus"), m.youngs_modulus, "Pa")?;
    check(
        m.poisson_ratio.is_finite() && (0.0..0.5).contains(&m.poisson_ratio),
        || key("material.poisson_ratio"),
        || format!("must be in [0, 0.5), got {}", Num(m.poisson_ratio)),
    )?;
    check(
        solid.damping.is_finite() && solid.damping >= 0.0,
        || key("damping"),
        || format!("must be zero or positive, got {}", Num(solid.damping)),
    )?;
    magnitude(&key("damping"), solid.damping, "1/s")?;
    if let Some(zeta) = solid.mesh_damping {
        check(
            zeta.is_finite() && (0.0..1.0).contains(&zeta),
            || key("mesh_damping"),
            || {
                format!(
                    "must be in [0, 1) (the damping ratio of the mesh's highest mode), got {}",
                    Num(zeta)
                )
            },
        )?;
    }
    for (f, b) in solid.fixed.iter().enumerate() {
        check(
            b.min.iter().chain(&b.max).all(|v| v.is_finite()),
            || key(&format!("fixed[{f}]")),
            || format!("corners must be finite, got min {:?} max {:?}", b.min, b.max),
        )?;
        check(
            solid.has_node_in(b),
            || key(&format!("fixed[{f}]")),
            || format!("box min {:?} max {:?} holds no node of the mesh", b.min, b.max),
        )?;
    }
    Ok(())
}
