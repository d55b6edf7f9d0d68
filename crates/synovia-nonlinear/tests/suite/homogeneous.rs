//! Homogeneous finite deformations (uniaxial stress, equibiaxial stress, simple shear) of a
//! neo-Hookean and a Mooney–Rivlin block solved by the Newton iteration: every cell's Cauchy
//! stress equals the closed-form one to 1e-10 (relative to the shear modulus), on a mesh with
//! perturbed interior nodes (P1 reproduces the homogeneous field exactly).

use std::sync::Arc;

use synovia_contact::operators::ContactPair;
use synovia_fem::nonlinear::cell_stresses;
use synovia_fem::{ComponentMask, ElasticParams, Kinematics, Model};
use synovia_material::{mooney_rivlin, neo_hookean, Material};
use synovia_mesh::generators::{box_mesh, Grading};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::{BoundaryKind, Mesh};
use synovia_nonlinear::{NewtonParams, NonlinearContact};
use synovia_pdas::Pdas;

const LAMBDA: f64 = 12.0;
const MU: f64 = 3.0;

fn block() -> Mesh<3> {
    let mut mesh = box_mesh([0.0; 3], [1.0; 3], [3, 3, 3], [Grading::Uniform; 3]).expect("mesh");
    mesh.map_nodes(|x| {
        let interior = x.iter().all(|&c| c > 1e-9 && c < 1.0 - 1e-9);
        if !interior {
            return *x;
        }
        let s: f64 = x.iter().enumerate().map(|(i, c)| (7.3 * c + 1.7 * i as f64).sin()).sum();
        Point::<3>::from_fn(|i, _| x[i] + 0.05 * (3.1 * s + i as f64).sin())
    })
    .expect("perturbation keeps cells valid");
    mesh
}

/// Solves the block in finite strain at `t = 1` in `levels` equal load levels and returns every
/// cell's Cauchy stress (Voigt `xx, yy, zz, yz, xz, xy`).
fn solve(model: &Model<3>, levels: usize) -> Vec<Vec<f64>> {
    let kin = [Kinematics::FiniteStrain];
    let mut nl = NonlinearContact::new(
        model,
        &[] as &[ContactPair<3>],
        &kin,
        ElasticParams::default(),
        NewtonParams::default().with_tolerance(1e-13),
    )
    .expect("set-up");
    let results =
        nl.run(model, &crate::common::level_times(levels), &Pdas::default(), |_| Ok(())).expect("converges");
    let last = results.last().expect("levels");
    assert!(
        last.report.residual() <= 1e-12
            || last.report.iterations.last().is_some_and(|i| i.increment <= 1e-13),
        "residual {}",
        last.report.residual()
    );
    // quadratic convergence: the last iterations at least square the residual
    let it = &last.report.iterations;
    assert!(it.len() <= 8, "{} Newton iterations", it.len());
    let stresses: Vec<Vec<f64>> = cell_stresses(model, &kin, &last.contact.displacement)
        .expect("stresses")
        .remove(0)
        .into_iter()
        .map(|(_, s, _)| s)
        .collect();
    // the output fields (VTU writers) carry the same Cauchy stresses
    let fields = synovia_fem::post::body_fields_with_kinematics(model, &last.contact.displacement, &kin)
        .expect("fields")
        .remove(0);
    for (a, b) in fields.cell_stress.iter().zip(&stresses) {
        assert!(a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-14 * (1.0 + y.abs())));
    }
    stresses
}

fn check(stresses: &[Vec<f64>], expected: [f64; 6], what: &str) {
    for (c, s) in stresses.iter().enumerate() {
        for k in 0..6 {
            assert!(
                (s[k] - expected[k]).abs() <= 1e-10 * MU,
                "{what}: cell {c} component {k}: {} vs {}",
                s[k],
                expected[k]
            );
        }
    }
}

/// Root of a scalar equation by Newton's method from 1 (the lateral stretch of a free face).
fn root(f: impl Fn(f64) -> f64) -> f64 {
    let mut x = 1.0;
    for _ in 0..100 {
        let h = 1e-7 * x;
        let d = (f(x + h) - f(x - h)) / (2.0 * h);
        let step = f(x) / d;
        x -= step;
        if step.abs() < 1e-15 {
            break;
        }
    }
    x
}

/// Symmetry rollers on `left`, `front`, `bottom`; the x-displacement of `right` prescribed
/// (and of `back` for biaxial).
fn stretched(material: Arc<dyn Material<3>>, stretch: f64, biaxial: bool) -> Model<3> {
    let mut mesh = block();
    for p in ["left", "front", "bottom"] {
        mesh.set_part_kind(p, BoundaryKind::Symmetry).expect("part");
    }
    mesh.set_part_kind("right", BoundaryKind::Prescribed).expect("part");
    if biaxial {
        mesh.set_part_kind("back", BoundaryKind::Prescribed).expect("part");
    }
    let mut model = Model::new();
    let b = model.add_body("block", mesh, material).expect("body");
    let s = stretch - 1.0;
    model
        .prescribe_components(b, "right", ComponentMask::only(0), move |_, t| {
            Vector::<3>::new(t * s, 0.0, 0.0)
        })
        .expect("right");
    if biaxial {
        model
            .prescribe_components(b, "back", ComponentMask::only(1), move |_, t| {
                Vector::<3>::new(0.0, t * s, 0.0)
            })
            .expect("back");
    }
    model
}

#[test]
fn neo_hookean_uniaxial_stress() {
    let a = 1.4;
    let law = Arc::new(synovia_material::Hyperelastic::new(
        synovia_material::NeoHookean::from_lame(LAMBDA, MU).expect("law"),
    ));
    let model = stretched(law, a, false);
    // lateral stretch b: σ_yy = (μ(b² − 1) + λ ln(a b²)) / J = 0
    let b = root(|b| MU * (b * b - 1.0) + LAMBDA * (a * b * b).ln());
    let j = a * b * b;
    let sxx = (MU * (a * a - 1.0) + LAMBDA * j.ln()) / j;
    check(&solve(&model, 4), [sxx, 0.0, 0.0, 0.0, 0.0, 0.0], "uniaxial");
    assert!(b < 1.0 && sxx > 0.0);
}

#[test]
fn neo_hookean_equibiaxial_stress() {
    let a = 1.25;
    let law = Arc::new(synovia_material::Hyperelastic::new(
        synovia_material::NeoHookean::from_lame(LAMBDA, MU).expect("law"),
    ));
    let model = stretched(law, a, true);
    let c = root(|c| MU * (c * c - 1.0) + LAMBDA * (a * a * c).ln());
    let j = a * a * c;
    let s = (MU * (a * a - 1.0) + LAMBDA * j.ln()) / j;
    check(&solve(&model, 3), [s, s, 0.0, 0.0, 0.0, 0.0], "equibiaxial");
}

fn sheared(material: Arc<dyn Material<3>>, gamma: f64) -> Model<3> {
    let mut mesh = block();
    for p in ["left", "right", "front", "back", "bottom", "top"] {
        mesh.set_part_kind(p, BoundaryKind::Prescribed).expect("part");
    }
    let mut model = Model::new();
    let b = model.add_body("block", mesh, material).expect("body");
    for p in ["left", "right", "front", "back", "bottom", "top"] {
        model.prescribe(b, p, move |x, t| Vector::<3>::new(t * gamma * x[1], 0.0, 0.0)).expect("shear");
    }
    model
}

#[test]
fn neo_hookean_simple_shear() {
    let g = 0.8;
    let law = Arc::new(
        neo_hookean(MU * (3.0 * LAMBDA + 2.0 * MU) / (LAMBDA + MU), LAMBDA / (2.0 * (LAMBDA + MU)))
            .expect("law"),
    );
    let model = sheared(law, g);
    // J = 1: σ = μ (B − I), B = [[1+γ², γ, 0], [γ, 1, 0], [0, 0, 1]]
    check(&solve(&model, 2), [MU * g * g, 0.0, 0.0, 0.0, 0.0, MU * g], "simple shear");
}

#[test]
fn mooney_rivlin_simple_shear() {
    let (c1, c2, lam) = (1.0, 0.5, 10.0);
    let g = 0.6;
    let model = sheared(Arc::new(mooney_rivlin(c1, c2, lam).expect("law")), g);
    // Rivlin: σ = 2(W₁ + I₁W₂) B − 2W₂ B² + W_J I at J = 1, W_J = −2(c₁ + 2c₂)
    let b = nalgebra::Matrix3::new(1.0 + g * g, g, 0.0, g, 1.0, 0.0, 0.0, 0.0, 1.0);
    let i1 = 3.0 + g * g;
    let sigma = b * (2.0 * (c1 + i1 * c2))
        - b * b * (2.0 * c2)
        - nalgebra::Matrix3::identity() * (2.0 * (c1 + 2.0 * c2));
    let expected = [sigma[(0, 0)], sigma[(1, 1)], sigma[(2, 2)], sigma[(1, 2)], sigma[(0, 2)], sigma[(0, 1)]];
    assert!((expected[5] - 2.0 * g * (c1 + c2)).abs() < 1e-14);
    check(&solve(&model, 2), expected, "Mooney-Rivlin simple shear");
}
