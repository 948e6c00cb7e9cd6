//! Uniaxial patch tests: a homogeneous plane-strain uniaxial stress state (σ_yy = 0, finite stretch, rigidly rotated)
//! must be reproduced exactly by every element, with zero net force on interior nodes and the exact resultant on
//! the loaded edges — on the structured meshes of the solver and on an irregular patch.
//!
//! Corotational linear law, stretch `U = diag(1 + ε, 1 − ν/(1 − ν) ε)`: then `T = diag(E' ε, 0)`,
//! `E' = E/(1 − ν²)`, `P = R T`, `σ = R T U Rᵀ / J = R diag(E' ε / (1 − ν/(1 − ν) ε), 0) Rᵀ` exactly.

mod common;

use common::*;
use cosim_proto::scene::{ElementKind, MaterialModel, MaterialSpec};
use fem_node::element::{Element, Quad4, Tri3};
use fem_node::material::{Lame, Material};
use fem_node::FemModel;
use fem_node::FemSolver;

const E: f64 = 2.0e6;
const NU: f64 = 0.35;
const EPS: f64 = 0.01;
const ANGLE: f64 = 0.7;

/// `x = Q U X`.
fn deform(p: [f64; 2]) -> [f64; 2] {
    let u = [p[0] * (1.0 + EPS), p[1] * (1.0 - NU / (1.0 - NU) * EPS)];
    let (s, c) = ANGLE.sin_cos();
    [c * u[0] - s * u[1], s * u[0] + c * u[1]]
}

fn rotate(v: [f64; 2]) -> [f64; 2] {
    let (s, c) = ANGLE.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

fn e_prime() -> f64 {
    E / (1.0 - NU * NU)
}

/// Exact Cauchy stress `[σxx, σyy, σxy]`.
fn exact_stress() -> [f64; 3] {
    let s = e_prime() * EPS / (1.0 - NU / (1.0 - NU) * EPS);
    let (sn, c) = ANGLE.sin_cos();
    [s * c * c, s * sn * sn, s * sn * c]
}

fn assert_close(a: f64, b: f64, scale: f64, what: &str) {
    assert!((a - b).abs() <= 1e-9 * scale, "{what}: {a} vs {b}");
}

#[test]
fn structured_meshes_pass_the_uniaxial_patch_test() {
    for element in [ElementKind::Quad4, ElementKind::Tri3] {
        let mut spec = cantilever(
            [0.0, 2.0],
            [0.0, 1.0],
            [4, 3],
            element,
            material(MaterialModel::LinearElastic, 1000.0, E, NU),
        );
        spec.fixed.clear();
        let model = FemModel::from_solids(&[spec], [0.0, 0.0]).unwrap();
        let mut s = FemSolver::new(model, 0.9).unwrap();
        let x: Vec<[f64; 2]> = s.model().reference().iter().map(|&p| deform(p)).collect();
        s.state_mut().x = x;
        s.refresh_accelerations().unwrap();
        let sigma = exact_stress();
        for stress in s.cell_stress() {
            for k in 0..3 {
                assert_close(stress[k], sigma[k], e_prime() * EPS, &format!("{element:?} stress {k}"));
            }
        }
        // f_int = −m a (no gravity, no damping).
        let m = s.model().masses();
        let force = |k: usize| [-m[k] * s.state().a[k][0], -m[k] * s.state().a[k][1]];
        let (mut right, mut left) = ([0.0; 2], [0.0; 2]);
        for (k, p) in s.model().reference().iter().enumerate() {
            let f = force(k);
            if p[0] == 2.0 {
                right = [right[0] + f[0], right[1] + f[1]];
            } else if p[0] == 0.0 {
                left = [left[0] + f[0], left[1] + f[1]];
            } else if p[1] != 0.0 && p[1] != 1.0 {
                for fd in f {
                    assert_close(fd, 0.0, e_prime() * EPS, &format!("{element:?} interior node {k}"));
                }
            }
        }
        // f_int = ∂E/∂x on the right edge sums to the traction resultant P N H₀ = Q (E' ε H₀, 0), H₀ = 1.
        let resultant = rotate([e_prime() * EPS * 1.0, 0.0]);
        for d in 0..2 {
            assert_close(
                right[d],
                resultant[d],
                e_prime() * EPS,
                &format!("{element:?} right edge"),
            );
            assert_close(
                left[d],
                -resultant[d],
                e_prime() * EPS,
                &format!("{element:?} left edge"),
            );
        }
    }
}

#[test]
fn irregular_patch_passes_the_uniaxial_patch_test() {
    // 3 × 3 nodes on the unit square, the five inner/mid-edge nodes moved off the grid.
    let nodes: [[f64; 2]; 9] = [
        [0.0, 0.0],
        [0.55, 0.0],
        [1.0, 0.0],
        [0.0, 0.45],
        [0.42, 0.6],
        [1.0, 0.38],
        [0.0, 1.0],
        [0.61, 1.0],
        [1.0, 1.0],
    ];
    let quads: [[u32; 4]; 4] = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]];
    let lame = Lame::from_young_poisson(E, NU);
    let material = Material::from_spec(&MaterialSpec {
        model: MaterialModel::LinearElastic,
        density: 1.0,
        youngs_modulus: E,
        poisson_ratio: NU,
    });
    let mut elements = Vec::new();
    for q in quads {
        let x = q.map(|k| nodes[k as usize]);
        elements.push(Element::Quad4(Quad4::new(q, x, lame).unwrap()));
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            elements.push(Element::Tri3(Tri3::new(t, t.map(|k| nodes[k as usize])).unwrap()));
        }
    }
    let x: Vec<[f64; 2]> = nodes.iter().map(|&p| deform(p)).collect();
    let sigma = exact_stress();
    for kind in ["quad", "tri"] {
        let mut centre = [0.0; 2];
        for e in elements
            .iter()
            .filter(|e| matches!((kind, e), ("quad", Element::Quad4(_)) | ("tri", Element::Tri3(_))))
        {
            let stress = e.cauchy_stress(&x, &material);
            for k in 0..3 {
                assert_close(stress[k], sigma[k], e_prime() * EPS, &format!("{kind} stress"));
            }
            let mut f = [[0.0; 2]; 4];
            e.internal_forces(&x, &material, &mut f).unwrap();
            for (i, &n) in e.nodes().iter().enumerate() {
                if n == 4 {
                    centre = [centre[0] + f[i][0], centre[1] + f[i][1]];
                }
            }
        }
        for c in centre {
            assert_close(c, 0.0, e_prime() * EPS, &format!("{kind} centre node"));
        }
    }
}
