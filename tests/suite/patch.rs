//! Patch tests (affine fields reproduced to round-off) for every material class, in 2D and 3D,
//! with Dirichlet and with traction data, and a symmetry (`Γ₀`) condition along an inclined
//! normal.

use std::sync::Arc;

use nalgebra::{DMatrix, Vector2, Vector3};
use synovia::fem::element::voigt_strain;
use synovia::prelude::*;
use synovia_material::{
    from_lame, plane_strain_from_lame, transversely_isotropic_plane_strain,
    transversely_isotropic_plane_stress, KelvinVoigt,
};
use synovia_mesh::math::Tensor;

/// Every material class of the crate, as `(name, material)`.
fn materials_2d() -> Vec<(&'static str, Arc<dyn Material<2>>)> {
    let ti = TransverseIsotropy { e_p: 2.0, nu_p: 0.3, e_a: 7.0, nu_ap: 0.2, g_a: 1.1 };
    let aniso = DMatrix::from_row_slice(3, 3, &[4.0, 1.2, 0.3, 1.2, 3.0, -0.4, 0.3, -0.4, 1.5]);
    let c0 = plane_strain(3.0, 0.25).expect("valid");
    vec![
        ("isotropic plane strain", Arc::new(plane_strain(5.0, 0.3).expect("valid"))),
        ("isotropic plane stress", Arc::new(plane_stress(5.0, 0.3).expect("valid"))),
        ("isotropic from Lamé", Arc::new(plane_strain_from_lame(2.0, 1.0).expect("valid"))),
        (
            "transversely isotropic plane strain",
            Arc::new(transversely_isotropic_plane_strain(ti, Vector2::new(0.6, 0.8)).expect("valid")),
        ),
        (
            "transversely isotropic plane stress",
            Arc::new(transversely_isotropic_plane_stress(ti, Vector2::new(1.0, 2.0)).expect("valid")),
        ),
        ("general anisotropic", Arc::new(anisotropic::<2>(aniso).expect("valid"))),
        (
            "Kelvin–Voigt (elastic part)",
            Arc::new(KelvinVoigt::from_linear(c0.clone(), c0, 1.0, 0.1).expect("valid")),
        ),
    ]
}

fn materials_3d() -> Vec<(&'static str, Arc<dyn Material<3>>)> {
    let ti = TransverseIsotropy { e_p: 2.0, nu_p: 0.3, e_a: 7.0, nu_ap: 0.2, g_a: 1.1 };
    let iso = isotropic(4.0, 0.2).expect("valid");
    let mut aniso = iso.stiffness().clone();
    for i in 0..6 {
        for j in 0..6 {
            aniso[(i, j)] += 0.1 * ((i + 2 * j) as f64).sin() * ((j + 2 * i) as f64).sin();
        }
    }
    vec![
        ("isotropic", Arc::new(isotropic(5.0, 0.3).expect("valid"))),
        ("isotropic from Lamé", Arc::new(from_lame(2.0, 1.0).expect("valid"))),
        (
            "transversely isotropic",
            Arc::new(transversely_isotropic(ti, Vector3::new(1.0, 2.0, 2.0)).expect("valid")),
        ),
        ("general anisotropic", Arc::new(anisotropic::<3>(aniso).expect("valid"))),
        (
            "Kelvin–Voigt (elastic part)",
            Arc::new(KelvinVoigt::from_linear(iso.clone(), iso, 1.0, 0.0).expect("valid")),
        ),
    ]
}

/// Moves interior nodes by a deterministic pseudo-random amount (the patch must be irregular).
fn perturb<const D: usize>(mesh: &mut Mesh<D>, lo: f64, hi: f64, amount: f64) {
    mesh.map_nodes(|x| {
        let interior = x.iter().all(|&c| c > lo + 1e-9 && c < hi - 1e-9);
        if !interior {
            return *x;
        }
        let s: f64 = x.iter().enumerate().map(|(i, c)| (7.3 * c + 1.7 * i as f64).sin()).sum();
        Point::<D>::from_fn(|i, _| x[i] + amount * ((3.1 * s + i as f64).sin()))
    })
    .expect("perturbation keeps cells valid");
}

fn affine<const D: usize>() -> (Vector<D>, Tensor<D>) {
    let a = Vector::<D>::from_fn(|i, _| 0.01 * (i as f64 + 1.0));
    let g = Tensor::<D>::from_fn(|i, j| {
        1e-3 * (1.0 + i as f64 + 2.0 * j as f64) * if (i + j) % 2 == 0 { 1.0 } else { -1.0 }
    });
    (a, g)
}

fn check_patch<const D: usize>(
    name: &str,
    mut mesh: Mesh<D>,
    material: Arc<dyn Material<D>>,
    traction_side: Option<&str>,
) {
    let (a, g) = affine::<D>();
    let exact = move |x: &Point<D>| a + g * x;
    let parts: Vec<String> = mesh.boundary_parts().iter().map(|p| p.name().to_string()).collect();
    let c = material.linear_stiffness().expect("linear");
    let strain = nalgebra::DVector::from_vec(voigt_strain::<D>(&g));
    let sigma = &c * &strain;
    let sigma_t = synovia::fem::element::stress_tensor::<D>(sigma.as_slice());
    for p in &parts {
        let kind =
            if Some(p.as_str()) == traction_side { BoundaryKind::Traction } else { BoundaryKind::Prescribed };
        mesh.set_part_kind(p, kind).expect("part");
    }
    let mut model = Model::<D>::new();
    let b = model.add_body("patch", mesh, material).expect("body");
    for p in &parts {
        if Some(p.as_str()) == traction_side {
            model.traction(b, p, move |_, n, _| sigma_t * n).expect("traction");
        } else {
            model.prescribe(b, p, move |x, _| exact(x)).expect("prescribe");
        }
    }
    let sol = solve_elastic(&model, 0.0).expect("solve");
    let mesh = &model.bodies()[0].mesh;
    let mut err: f64 = 0.0;
    for (x, u) in mesh.nodes().iter().zip(&sol.displacement[0]) {
        err = err.max((u - exact(x)).norm());
    }
    let scale = mesh.nodes().iter().map(|x| exact(x).norm()).fold(0.0, f64::max);
    assert!(err <= 1e-12 * scale, "{name} ({D}D, traction {traction_side:?}): max nodal error {err:e}");
    let fields = synovia::fem::post::body_fields(&model, &sol.displacement).expect("fields");
    for s in &fields[0].cell_stress {
        for (k, v) in s.iter().enumerate() {
            assert!((v - sigma[k]).abs() <= 1e-10 * sigma.amax(), "{name}: stress {k} = {v} vs {}", sigma[k]);
        }
    }
}

#[test]
fn affine_fields_are_reproduced_in_2d_for_every_material() {
    for (name, m) in materials_2d() {
        let mut mesh = rectangle(0.0, 1.0, 0.0, 1.0, 5, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
        perturb(&mut mesh, 0.0, 1.0, 0.04);
        check_patch(name, mesh.clone(), m.clone(), None);
        check_patch(name, mesh, m, Some("right"));
    }
}

#[test]
fn affine_fields_are_reproduced_in_3d_for_every_material() {
    for (name, m) in materials_3d() {
        let mut mesh = box_mesh([0.0; 3], [1.0; 3], [3, 3, 3], [Grading::Uniform; 3]).expect("mesh");
        perturb(&mut mesh, 0.0, 1.0, 0.05);
        check_patch(name, mesh.clone(), m.clone(), None);
        check_patch(name, mesh, m, Some("top"));
    }
}

/// A block rotated by 30° rests on two rollers (`Γ₀`, `u · n = 0` along inclined normals) and is
/// compressed by a pressure `p` on the opposite face: the exact stress is uniaxial,
/// `σ = −p n_top ⊗ n_top`, and must be reproduced in every cell.
#[test]
fn symmetry_rollers_along_inclined_normals_give_exact_uniaxial_stress() {
    let angle = 30f64.to_radians();
    let rot = nalgebra::Rotation2::new(angle);
    let mut mesh = rectangle(0.0, 2.0, 0.0, 1.0, 6, 3, Grading::Uniform, Grading::Uniform).expect("mesh");
    perturb(&mut mesh, 0.0, 1.0, 0.03);
    mesh.map_nodes(|x| rot * x).expect("rotation");
    mesh.set_part_kind("bottom", BoundaryKind::Symmetry).expect("part");
    mesh.set_part_kind("left", BoundaryKind::Symmetry).expect("part");
    mesh.set_part_kind("top", BoundaryKind::Traction).expect("part");
    let p = 0.02;
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(10.0, 0.3).expect("valid"))).expect("body");
    model.traction(b, "top", move |_, n, _| -p * n).expect("traction");
    let sol = solve_elastic(&model, 0.0).expect("solve");
    let n_top = rot * Vector2::new(0.0, 1.0);
    let expected = -p * n_top * n_top.transpose();
    let fields = synovia::fem::post::body_fields(&model, &sol.displacement).expect("fields");
    for s in &fields[0].cell_stress {
        let st = synovia::fem::element::stress_tensor::<2>(s);
        assert!((st - expected).norm() < 1e-12, "stress {st} vs {expected}");
    }
    // the roller condition holds at every node of the rollers
    let mesh = &model.bodies()[0].mesh;
    for part in ["bottom", "left"] {
        for (node, n) in mesh.nodal_normals(part).expect("normals") {
            assert!(sol.displacement[0][node].dot(&n).abs() < 1e-14, "u·n ≠ 0 on {part}");
        }
    }
}
