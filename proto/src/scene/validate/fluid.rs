//! The `[fluid]` section: sizes, corrections, solver options, and blocks that hold particles and stay out of the
//! walls and solids.

use super::{check, coordinates, finite_positive, magnitude, Invalid, CFL_MIN};
use crate::scene::schema::{BoxSpec, DensityFilter, FluidSolver, FluidSpec, SolidSpec, ISPH_PPE_TOLERANCE_RANGE};
use crate::Num;

/// The largest artificial viscosity α: its kinematic viscosity α h c0 / 8 (2D) holds the step to 0.125 h² / ν =
/// h / (α c0), which is the acoustic step 0.25 h / c0 at α = 4.
const ARTIFICIAL_VISCOSITY_MAX: f64 = 4.0;

/// The fluid section: positive sizes, a sensible smoothing ratio, blocks that hold particles and stay out of walls.
pub(super) fn validate_fluid(f: &FluidSpec, walls: &[BoxSpec], solids: &[SolidSpec]) -> Result<(), Invalid> {
    finite_positive("fluid.density", f.density)?;
    magnitude("fluid.density", f.density, "kg/m³")?;
    // A tiny spacing is refused by the particles it makes (`sizing.rs`), a large one by the blocks it leaves empty.
    finite_positive("fluid.spacing", f.spacing)?;
    check(
        f.kinematic_viscosity.is_finite() && f.kinematic_viscosity >= 0.0,
        || "fluid.kinematic_viscosity".into(),
        || format!("must be zero or positive, got {}", Num(f.kinematic_viscosity)),
    )?;
    magnitude("fluid.kinematic_viscosity", f.kinematic_viscosity, "m²/s")?;
    check(
        (1.0..=2.0).contains(&f.smoothing_ratio),
        || "fluid.smoothing_ratio".into(),
        || {
            format!(
                "must be in [1, 2] (h = ratio x spacing), got {}",
                Num(f.smoothing_ratio)
            )
        },
    )?;
    if let Some(c) = f.sound_speed {
        finite_positive("fluid.sound_speed", c)?;
        magnitude("fluid.sound_speed", c, "m/s")?;
    }
    check(
        (CFL_MIN..=1.0).contains(&f.cfl),
        || "fluid.cfl".into(),
        || {
            format!(
                "must be in [{CFL_MIN:e}, 1] (a factor on the stable step of DESIGN.md §4.2/§4.3; above 1 the fluid \
                 is stepped past its stability limit), got {}",
                Num(f.cfl)
            )
        },
    )?;
    check(
        (0.0..=ARTIFICIAL_VISCOSITY_MAX).contains(&f.artificial_viscosity),
        || "fluid.artificial_viscosity".into(),
        || {
            format!(
                "must be in [0, {ARTIFICIAL_VISCOSITY_MAX}] (Monaghan's α; 0.01–0.1 is usual; past 4 its viscosity, \
                 α h c0 / 8, needs a shorter step than the acoustic one the solver takes), got {}",
                Num(f.artificial_viscosity)
            )
        },
    )?;
    check(
        f.density_filter_interval >= 1,
        || "fluid.density_filter_interval".into(),
        || "must be at least 1".into(),
    )?;
    check(
        f.xsph.is_finite() && (0.0..=1.0).contains(&f.xsph),
        || "fluid.xsph".into(),
        || format!("must be in [0, 1], got {}", Num(f.xsph)),
    )?;
    check(
        f.apd().is_finite() && (0.0..=1.0).contains(&f.apd()),
        || "fluid.apd".into(),
        || format!("must be in [0, 1], got {}", Num(f.apd())),
    )?;
    check(
        f.density_diffusion.is_finite() && (0.0..=1.0).contains(&f.density_diffusion),
        || "fluid.density_diffusion".into(),
        || {
            format!(
                "must be in [0, 1] (δ of δ-SPH; 0.1 is usual), got {}",
                Num(f.density_diffusion)
            )
        },
    )?;
    check(
        f.verlet_skin().is_finite() && (0.0..=1.0).contains(&f.verlet_skin()),
        || "fluid.verlet_skin".into(),
        || {
            format!(
                "must be in [0, 1] (units of h; 0 searches every step), got {}",
                Num(f.verlet_skin())
            )
        },
    )?;
    check(
        f.verlet_skin.is_none() || f.solver == FluidSolver::Wcsph,
        || "fluid.verlet_skin".into(),
        || "applies to solver = \"wcsph\" only (the ISPH search runs every step)".into(),
    )?;
    check(
        f.density_diffusion == 0.0 || f.solver == FluidSolver::Wcsph,
        || "fluid.density_diffusion".into(),
        || "applies to solver = \"wcsph\" only (ISPH takes its pressure from the Poisson equation)".into(),
    )?;
    if f.solver == FluidSolver::Isph {
        check(
            f.density_filter() == DensityFilter::None,
            || "fluid.density_filter".into(),
            || "ISPH takes no density filter (its pressure comes from the Poisson equation); set \"none\"".into(),
        )?;
        check(
            f.ppe_tolerance().is_finite() && ISPH_PPE_TOLERANCE_RANGE.contains(&f.ppe_tolerance()),
            || "fluid.ppe_tolerance".into(),
            || {
                format!(
                    "must be in [{:e}, {:e}] (the pressure solve's relative residual), got {}",
                    ISPH_PPE_TOLERANCE_RANGE.start(),
                    ISPH_PPE_TOLERANCE_RANGE.end(),
                    Num(f.ppe_tolerance())
                )
            },
        )?;
    } else {
        for (set, key) in [
            (f.ppe_source.is_some(), "fluid.ppe_source"),
            (f.ppe_tolerance.is_some(), "fluid.ppe_tolerance"),
        ] {
            check(!set, || key.into(), || "applies to solver = \"isph\" only".into())?;
        }
    }
    check(
        !f.blocks.is_empty(),
        || "fluid.block".into(),
        || "at least one [[fluid.block]] is needed".into(),
    )?;
    for (b, block) in f.blocks.iter().enumerate() {
        let key = || format!("fluid.block[{b}]");
        check(
            (0..2).all(|k| block.min[k].is_finite() && block.max[k].is_finite()),
            key,
            || "corners must be finite".into(),
        )?;
        coordinates(&key(), block.min, block.max)?;
        check((0..2).all(|k| block.max[k] - block.min[k] >= f.spacing), key, || {
            format!(
                "holds no particle: min {:?} max {:?} is narrower than the spacing {}",
                block.min,
                block.max,
                Num(f.spacing)
            )
        })?;
        for (w, wall) in walls.iter().enumerate() {
            // Overlap of more than half a spacing in both directions: particles would sit inside the wall.
            let overlap =
                (0..2).all(|k| block.max[k].min(wall.max[k]) - block.min[k].max(wall.min[k]) > 0.5 * f.spacing);
            check(!overlap, key, || {
                format!("overlaps wall[{w}] (min {:?} max {:?})", wall.min, wall.max)
            })?;
        }
        for solid in solids {
            // The same rule against a solid's rectangle: particles inside a structure would be pushed out by
            // the contact in the first step, with an impulse no physics asked for.
            let overlap =
                (0..2).all(|k| block.max[k].min(solid.max[k]) - block.min[k].max(solid.min[k]) > 0.5 * f.spacing);
            check(!overlap, key, || {
                format!(
                    "overlaps solid `{}` (min {:?} max {:?})",
                    solid.name, solid.min, solid.max
                )
            })?;
        }
    }
    Ok(())
}
