//! Property test: the internal nodal forces of one element sum to zero (linear momentum) and have no net moment
//! (angular momentum) for random shapes, random deformations and every material.

use cosim_proto::scene::{MaterialModel, MaterialSpec};
use fem_node::element::{Element, Quad4, Tri3};
use fem_node::material::Material;
use proptest::prelude::*;

fn material(which: usize) -> Material {
    let model = [
        MaterialModel::LinearElastic,
        MaterialModel::NeoHookean,
        MaterialModel::StVenantKirchhoff,
    ][which];
    Material::from_spec(&MaterialSpec {
        model,
        density: 1000.0,
        youngs_modulus: 1.0e6,
        poisson_ratio: 0.3,
    })
}

fn check(element: &Element, x: &[[f64; 2]], law: &Material) -> Result<(), TestCaseError> {
    let mut f = [[0.0; 2]; 4];
    if element.internal_forces(x, law, &mut f).is_err() {
        // An inverted random deformation is reported, not evaluated.
        return Ok(());
    }
    let n = element.nodes().len();
    let scale = f[..n].iter().flatten().fold(1e-30f64, |m, v| m.max(v.abs()));
    let sum = f[..n].iter().fold([0.0; 2], |s, v| [s[0] + v[0], s[1] + v[1]]);
    let moment: f64 = (0..n).map(|i| x[i][0] * f[i][1] - x[i][1] * f[i][0]).sum();
    prop_assert!(
        sum[0].abs() < 1e-10 * scale && sum[1].abs() < 1e-10 * scale,
        "sum {sum:?}, scale {scale}"
    );
    prop_assert!(moment.abs() < 1e-9 * scale, "moment {moment}, scale {scale}");
    Ok(())
}

/// `x = Q (I + G) X + c + δ`: rotation, homogeneous strain, translation and a per-node jitter (which excites the
/// quad's hourglass modes).
fn deform(reference: &[[f64; 2]], angle: f64, g: [f64; 4], jitter: &[f64]) -> Vec<[f64; 2]> {
    let (s, c) = angle.sin_cos();
    reference
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let u = [p[0] + g[0] * p[0] + g[1] * p[1], p[1] + g[2] * p[0] + g[3] * p[1]];
            [
                c * u[0] - s * u[1] + 0.3 + jitter[2 * i],
                s * u[0] + c * u[1] - 1.1 + jitter[2 * i + 1],
            ]
        })
        .collect()
}

/// One property test per element (as fenris applies its test macros to every element): a random reference shape
/// (`shape` with its corners moved by up to ±0.15), deformed by [`deform`], under every material.
macro_rules! forces_conserve_momentum {
    ($name:ident, corners = $n:literal, shape = $shape:expr, element = $element:expr) => {
        proptest! {
            #[test]
            fn $name(
                corners in prop::collection::vec(-0.15f64..0.15, 2 * $n),
                angle in -3.2f64..3.2,
                g in prop::array::uniform4(-0.3f64..0.3),
                jitter in prop::collection::vec(-0.1f64..0.1, 2 * $n),
                which in 0usize..3,
            ) {
                let shape: [[f64; 2]; $n] = $shape;
                let reference: [[f64; 2]; $n] = std::array::from_fn(|i| [shape[i][0] + corners[2 * i], shape[i][1] + corners[2 * i + 1]]);
                let law = material(which);
                let element: Element = ($element)(reference, &law);
                check(&element, &deform(&reference, angle, g, &jitter), &law)?;
            }
        }
    };
}

forces_conserve_momentum!(
    quad4_forces_conserve_momentum,
    corners = 4,
    shape = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
    element = |reference, law: &Material| Element::Quad4(Quad4::new([0, 1, 2, 3], reference, law.lame()).unwrap())
);

forces_conserve_momentum!(
    tri3_forces_conserve_momentum,
    corners = 3,
    shape = [[0.0, 0.0], [1.0, 0.0], [0.3, 0.9]],
    element = |reference, _: &Material| Element::Tri3(Tri3::new([0, 1, 2], reference).unwrap())
);
