//! Integration tests of synovia-material: closed forms, reductions, rotations, errors.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::Arc;

use approx::assert_relative_eq;
use nalgebra::{Matrix2, Matrix3, Rotation3, Unit, Vector2, Vector3};
use synovia_material::{
    anisotropic, bond_strain_matrix, bond_stress_matrix, check_admissible, from_lame, isotropic,
    plane_strain, plane_strain_from_lame, plane_stress, transversely_isotropic,
    transversely_isotropic_plane_strain, transversely_isotropic_plane_stress, voigt_len, KelvinVoigt,
    LinearElastic, Material, MaterialError, Reduction, Symmetry, TransverseIsotropy, VoigtMatrix,
    VoigtVector,
};

// ---------------------------------------------------------------- helpers

/// `max |a − b| ≤ tol · max |b|`.
fn assert_mat_close(a: &VoigtMatrix, b: &VoigtMatrix, tol: f64) {
    assert_eq!(a.shape(), b.shape());
    let err = (a - b).amax();
    assert!(err <= tol * b.amax(), "matrices differ by {err} (scale {}):\n{a}\n{b}", b.amax());
}

fn sub(c: &VoigtMatrix, idx: &[usize]) -> VoigtMatrix {
    VoigtMatrix::from_fn(idx.len(), idx.len(), |i, j| c[(idx[i], idx[j])])
}

fn inv(c: &VoigtMatrix) -> VoigtMatrix {
    c.clone().try_inverse().expect("invertible")
}

/// A cartilage-like transversely isotropic set (admissible:
/// `ν_pa = 0.5`, `1 − ν_p − 2 ν_ap ν_pa = 0.55 > 0`).
fn ti_params() -> TransverseIsotropy {
    TransverseIsotropy { e_p: 10.0, nu_p: 0.35, e_a: 2.0, nu_ap: 0.1, g_a: 0.8 }
}

fn rotation() -> Matrix3<f64> {
    *Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)), 0.9).matrix()
}

fn strain3() -> VoigtVector {
    VoigtVector::from_column_slice(&[1e-3, -4e-4, 2.5e-4, 7e-4, -3e-4, 5e-4])
}

fn strain2() -> VoigtVector {
    VoigtVector::from_column_slice(&[1e-3, -4e-4, 6e-4])
}

/// Central finite-difference Jacobian of `m.stress` at `e`.
fn fd_tangent<const D: usize>(m: &dyn Material<D>, e: &VoigtVector) -> VoigtMatrix {
    let n = e.len();
    let h = 1e-6;
    let mut t = VoigtMatrix::zeros(n, n);
    for j in 0..n {
        let mut ep = e.clone();
        let mut em = e.clone();
        ep[j] += h;
        em[j] -= h;
        let col = (m.stress(&ep) - m.stress(&em)) / (2.0 * h);
        t.set_column(j, &col);
    }
    t
}

/// Central finite-difference gradient of `m.energy_density` at `e`.
fn fd_gradient<const D: usize>(m: &dyn Material<D>, e: &VoigtVector) -> VoigtVector {
    let h = 1e-6;
    VoigtVector::from_fn(e.len(), |j, _| {
        let mut ep = e.clone();
        let mut em = e.clone();
        ep[j] += h;
        em[j] -= h;
        (m.energy_density(&ep) - m.energy_density(&em)) / (2.0 * h)
    })
}

// ---------------------------------------------------------------- isotropic

#[test]
fn isotropic_3d_compliance_recovers_e_and_nu() {
    let (e, nu) = (2.5e6, 0.28);
    let m = isotropic(e, nu).unwrap();
    let s = inv(m.stiffness());
    assert_relative_eq!(s[(0, 0)], 1.0 / e, max_relative = 1e-12);
    assert_relative_eq!(s[(1, 1)], 1.0 / e, max_relative = 1e-12);
    assert_relative_eq!(s[(2, 2)], 1.0 / e, max_relative = 1e-12);
    assert_relative_eq!(s[(0, 1)], -nu / e, max_relative = 1e-12);
    assert_relative_eq!(s[(0, 2)], -nu / e, max_relative = 1e-12);
    assert_relative_eq!(s[(1, 2)], -nu / e, max_relative = 1e-12);
    for k in 3..6 {
        // Engineering shear: γ = τ / G = 2(1+ν) τ / E.
        assert_relative_eq!(s[(k, k)], 2.0 * (1.0 + nu) / e, max_relative = 1e-12);
    }
    assert!(s[(0, 3)].abs() < 1e-20 && s[(3, 4)].abs() < 1e-20);
    // Uniaxial stress σ_xx = 1: ε_xx = 1/E, ε_yy = ε_zz = −ν/E.
    let sigma = VoigtVector::from_column_slice(&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let eps = m.compliance().unwrap() * sigma;
    assert_relative_eq!(eps[0] * e, 1.0, max_relative = 1e-12);
    assert_relative_eq!(eps[1] * e, -nu, max_relative = 1e-12);
    // Lamé metadata.
    let (l, mu) = m.lame().unwrap();
    assert_relative_eq!(l, e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), max_relative = 1e-14);
    assert_relative_eq!(mu, e / (2.0 * (1.0 + nu)), max_relative = 1e-14);
    assert_eq!(m.reduction(), Reduction::ThreeDimensional);
}

#[test]
fn plane_strain_is_submatrix_of_3d() {
    let (e, nu) = (7.0, 0.33);
    let c3 = isotropic(e, nu).unwrap();
    let ps = plane_strain(e, nu).unwrap();
    assert_mat_close(ps.stiffness(), &sub(c3.stiffness(), &[0, 1, 5]), 1e-14);
    assert_mat_close(c3.plane_strain().stiffness(), ps.stiffness(), 1e-14);
    assert_eq!(ps.reduction(), Reduction::PlaneStrain);
    // σ_zz = λ (ε_xx + ε_yy) = zz stress of the embedded 3D strain.
    let eps = strain2();
    let (lambda, _) = ps.lame().unwrap();
    let szz = ps.out_of_plane_stress(&eps);
    assert_relative_eq!(szz, lambda * (eps[0] + eps[1]), max_relative = 1e-13);
    let eps3 = VoigtVector::from_column_slice(&[eps[0], eps[1], 0.0, 0.0, 0.0, eps[2]]);
    let s3 = c3.stress(&eps3);
    assert_relative_eq!(szz, s3[2], max_relative = 1e-13);
    assert_relative_eq!(c3.plane_strain().out_of_plane_stress(&eps), s3[2], max_relative = 1e-13);
    let s2 = ps.stress(&eps);
    for (i, k) in [0, 1, 5].into_iter().enumerate() {
        assert_relative_eq!(s2[i], s3[k], max_relative = 1e-13);
    }
    // Lamé constructor agrees.
    let (l, mu) = ps.lame().unwrap();
    let pl = plane_strain_from_lame(l, mu).unwrap();
    assert_mat_close(pl.stiffness(), ps.stiffness(), 1e-14);
    let fl = from_lame(l, mu).unwrap();
    assert_mat_close(fl.stiffness(), c3.stiffness(), 1e-14);
}

#[test]
fn plane_stress_is_inverse_of_compliance_submatrix() {
    let (e, nu) = (3.0, -0.4);
    let c3 = isotropic(e, nu).unwrap();
    let s3 = inv(c3.stiffness());
    let expected = inv(&sub(&s3, &[0, 1, 5]));
    let ps = plane_stress(e, nu).unwrap();
    assert_mat_close(ps.stiffness(), &expected, 1e-13);
    assert_mat_close(c3.plane_stress().unwrap().stiffness(), &expected, 1e-13);
    assert_eq!(ps.out_of_plane_stress(&strain2()), 0.0);
    assert_eq!(ps.reduction(), Reduction::PlaneStress);
    // Uniaxial stress in the plane: ε_xx = σ/E, ε_yy = −ν σ/E.
    let eps = ps.compliance().unwrap() * VoigtVector::from_column_slice(&[1.0, 0.0, 0.0]);
    assert_relative_eq!(eps[0], 1.0 / e, max_relative = 1e-13);
    assert_relative_eq!(eps[1], -nu / e, max_relative = 1e-13);
}

// ---------------------------------------------------------------- transversely isotropic

#[test]
fn transversely_isotropic_axis_z_matches_closed_form() {
    let p = ti_params();
    let (ep, nup, ea, nuap, ga) = (p.e_p, p.nu_p, p.e_a, p.nu_ap, p.g_a);
    let mut s = VoigtMatrix::zeros(6, 6);
    s[(0, 0)] = 1.0 / ep;
    s[(1, 1)] = 1.0 / ep;
    s[(0, 1)] = -nup / ep;
    s[(1, 0)] = -nup / ep;
    s[(0, 2)] = -nuap / ea;
    s[(2, 0)] = -nuap / ea;
    s[(1, 2)] = -nuap / ea;
    s[(2, 1)] = -nuap / ea;
    s[(2, 2)] = 1.0 / ea;
    s[(3, 3)] = 1.0 / ga;
    s[(4, 4)] = 1.0 / ga;
    s[(5, 5)] = 2.0 * (1.0 + nup) / ep;

    let m = transversely_isotropic(p, Vector3::new(0.0, 0.0, 2.0)).unwrap();
    assert_mat_close(m.stiffness(), &inv(&s), 1e-12);
    assert_mat_close(&m.compliance().unwrap(), &s, 1e-12);
    // Uniaxial stress along the axis: in-plane strain −ν_ap σ/E_a; in-plane stress gives
    // axial strain −ν_pa σ/E_p with ν_pa/E_p = ν_ap/E_a.
    let sc = m.compliance().unwrap();
    assert_relative_eq!(sc[(2, 0)], -p.nu_pa() / p.e_p, max_relative = 1e-12);
}

#[test]
fn transversely_isotropic_isotropic_limit() {
    let (e, nu) = (4.0, 0.3);
    let p = TransverseIsotropy { e_p: e, nu_p: nu, e_a: e, nu_ap: nu, g_a: e / (2.0 * (1.0 + nu)) };
    let iso = isotropic(e, nu).unwrap();
    for axis in [Vector3::z(), Vector3::x(), Vector3::new(0.3, -1.0, 0.7)] {
        let ti = transversely_isotropic(p, axis).unwrap();
        assert_mat_close(ti.stiffness(), iso.stiffness(), 1e-12);
    }
    let ps = transversely_isotropic_plane_strain(p, Vector2::new(1.0, 1.0)).unwrap();
    assert_mat_close(ps.stiffness(), plane_strain(e, nu).unwrap().stiffness(), 1e-12);
    let pss = transversely_isotropic_plane_stress(p, Vector2::new(1.0, -2.0)).unwrap();
    assert_mat_close(pss.stiffness(), plane_stress(e, nu).unwrap().stiffness(), 1e-12);
}

#[test]
fn transversely_isotropic_rotation_invariance() {
    let p = ti_params();
    let r = rotation();
    let a = Vector3::new(0.3, -0.5, 0.8);
    let m1 = transversely_isotropic(p, a).unwrap();
    let m2 = transversely_isotropic(p, r * a).unwrap();
    let n = bond_strain_matrix(&r).unwrap();
    for eps in [
        strain3(),
        VoigtVector::from_column_slice(&[0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
        VoigtVector::from_column_slice(&[0.0, 0.0, 0.0, 1.0, -2.0, 0.5]),
    ] {
        let rotated = &n * &eps;
        let w1 = m1.energy_density(&eps);
        let w2 = m2.energy_density(&rotated);
        assert_relative_eq!(w1, w2, max_relative = 1e-12);
        // Stresses rotate with the stress Bond matrix.
        let m = bond_stress_matrix(&r).unwrap();
        let s_expected = &m * m1.stress(&eps);
        let s_got = m2.stress(&rotated);
        assert!((s_got - &s_expected).amax() <= 1e-12 * s_expected.amax());
    }
    // rotated() of the material equals building it with the rotated axis.
    let m1r = m1.rotated(&r).unwrap();
    assert_mat_close(m1r.stiffness(), m2.stiffness(), 1e-12);
    match m1r.symmetry() {
        Symmetry::TransverselyIsotropic { axis, .. } => {
            assert!((axis - (r * a).normalize()).amax() < 1e-14)
        }
        other => panic!("unexpected symmetry {other:?}"),
    }
    // Perturbing the axis changes the energy (the test above is not vacuous).
    let m3 = transversely_isotropic(p, a).unwrap();
    let w_wrong = m3.energy_density(&(&n * strain3()));
    assert!((w_wrong - m1.energy_density(&strain3())).abs() > 1e-6 * w_wrong.abs());
}

#[test]
fn transversely_isotropic_axis_x_is_permutation_of_axis_z() {
    let p = ti_params();
    let cz = transversely_isotropic(p, Vector3::z()).unwrap();
    let cx = transversely_isotropic(p, Vector3::new(-5.0, 0.0, 0.0)).unwrap();
    // Swapping x ↔ z maps Voigt indices xx↔zz, yy↔yy, yz↔xy, xz↔xz.
    let perm = [2, 1, 0, 5, 4, 3];
    let permuted = VoigtMatrix::from_fn(6, 6, |i, j| cz.stiffness()[(perm[i], perm[j])]);
    assert_mat_close(cx.stiffness(), &permuted, 1e-13);
    // And they really differ (the material is not isotropic).
    assert!((cx.stiffness() - cz.stiffness()).amax() > 1e-3 * cz.stiffness().amax());
}

#[test]
fn transversely_isotropic_plane_reductions() {
    let p = ti_params();
    let th: f64 = 0.6;
    let axis2 = Vector2::new(th.cos(), th.sin());
    let c3 = transversely_isotropic(p, Vector3::new(th.cos(), th.sin(), 0.0)).unwrap();
    let pe = transversely_isotropic_plane_strain(p, axis2 * 3.0).unwrap();
    assert_mat_close(pe.stiffness(), &sub(c3.stiffness(), &[0, 1, 5]), 1e-13);
    let eps = strain2();
    let eps3 = VoigtVector::from_column_slice(&[eps[0], eps[1], 0.0, 0.0, 0.0, eps[2]]);
    assert_relative_eq!(pe.out_of_plane_stress(&eps), c3.stress(&eps3)[2], max_relative = 1e-12);
    let pst = transversely_isotropic_plane_stress(p, axis2).unwrap();
    let expected = inv(&sub(&inv(c3.stiffness()), &[0, 1, 5]));
    assert_mat_close(pst.stiffness(), &expected, 1e-12);
    assert_eq!(pst.out_of_plane_stress(&eps), 0.0);
    // 2D rotation: axis x rotated by θ equals axis (cos θ, sin θ).
    let px = transversely_isotropic_plane_strain(p, Vector2::x()).unwrap();
    let r2 = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
    let rotated = px.rotated(&r2).unwrap();
    assert_mat_close(rotated.stiffness(), pe.stiffness(), 1e-12);
    assert!(
        (rotated.out_of_plane_row().unwrap() - pe.out_of_plane_row().unwrap()).amax()
            < 1e-12 * pe.stiffness().amax()
    );
    let sx = transversely_isotropic_plane_stress(p, Vector2::x()).unwrap();
    assert_mat_close(sx.rotated(&r2).unwrap().stiffness(), pst.stiffness(), 1e-12);
}

// ---------------------------------------------------------------- anisotropic

fn spd6() -> VoigtMatrix {
    let a = VoigtMatrix::from_fn(6, 6, |i, j| ((i * 7 + j * 3) % 5) as f64 * 0.3 - 0.4);
    a.transpose() * &a + VoigtMatrix::identity(6, 6) * 2.0
}

#[test]
fn anisotropic_accepts_spd_and_rotates() {
    let c = spd6();
    let m = anisotropic::<3>(c.clone()).unwrap();
    assert_mat_close(m.stiffness(), &c, 0.0);
    assert!(check_admissible(&c).is_ok());
    let r = rotation();
    let mr = m.rotated(&r).unwrap();
    assert!(check_admissible(mr.stiffness()).is_ok());
    // Energy invariance under the Bond pair (M, N).
    let n = bond_strain_matrix(&r).unwrap();
    let eps = strain3();
    assert_relative_eq!(m.energy_density(&eps), mr.energy_density(&(&n * &eps)), max_relative = 1e-12);
    // Kelvin moduli are invariant, rotating back recovers C.
    let k0 = m.kelvin_moduli();
    let k1 = mr.kelvin_moduli();
    assert!((k0 - k1).amax() < 1e-12 * c.amax());
    let back = mr.rotated(&r.transpose()).unwrap();
    assert_mat_close(back.stiffness(), &c, 1e-12);
    // A 3×3 planar matrix.
    let c2 = sub(&c, &[0, 1, 5]);
    let m2 = anisotropic::<2>(c2).unwrap();
    assert_eq!(m2.reduction(), Reduction::Planar);
    assert_eq!(m2.out_of_plane_stress(&strain2()), 0.0);
}

// ---------------------------------------------------------------- errors

#[test]
fn parameter_errors() {
    let err = isotropic(-2.5, 0.3).unwrap_err();
    assert_eq!(err, MaterialError::NonPositiveYoungsModulus { e: -2.5 });
    assert!(err.to_string().contains("-2.5"), "{err}");
    assert!(matches!(
        isotropic(0.0, 0.3),
        Err(MaterialError::NonPositiveYoungsModulus { e }) if e == 0.0
    ));
    for nu in [0.5, -1.0, 0.7, -3.0] {
        let err = isotropic(1.0, nu).unwrap_err();
        assert_eq!(err, MaterialError::PoissonRatioOutOfRange { nu });
        assert!(err.to_string().contains(&nu.to_string()), "{err}");
        assert!(err.to_string().contains("(−1, ½)"), "{err}");
        assert!(plane_strain(1.0, nu).is_err());
        assert!(plane_stress(1.0, nu).is_err());
    }
    for (e, nu) in [(f64::NAN, 0.3), (f64::INFINITY, 0.3), (1.0, f64::NAN)] {
        assert!(matches!(isotropic(e, nu), Err(MaterialError::NonFinite { .. })));
    }
    let err = isotropic(f64::NAN, 0.3).unwrap_err();
    assert!(err.to_string().contains("Young"), "{err}");
    assert!(matches!(plane_stress(f64::NEG_INFINITY, 0.3), Err(MaterialError::NonFinite { .. })));
    let err = from_lame(1.0, -0.5).unwrap_err();
    assert_eq!(err, MaterialError::NonPositiveShearModulus { mu: -0.5 });
    assert!(err.to_string().contains("-0.5"));
}

#[test]
fn transversely_isotropic_errors() {
    let mut p = ti_params();
    p.g_a = -1.0;
    assert_eq!(
        transversely_isotropic(p, Vector3::z()).unwrap_err(),
        MaterialError::NonPositiveShearModulus { mu: -1.0 }
    );
    let mut p = ti_params();
    p.e_a = 0.0;
    assert!(matches!(
        transversely_isotropic(p, Vector3::z()),
        Err(MaterialError::NonPositiveYoungsModulus { e }) if e == 0.0
    ));
    let mut p = ti_params();
    p.nu_p = 1.2;
    assert!(matches!(
        transversely_isotropic(p, Vector3::z()),
        Err(MaterialError::NotPositiveDefinite { min_eigenvalue }) if min_eigenvalue < 0.0
    ));
    let mut p = ti_params();
    p.nu_ap = 1.0; // ν_pa = 5: 1 − ν_p − 2 ν_ap ν_pa < 0
    assert!(matches!(
        transversely_isotropic(p, Vector3::z()),
        Err(MaterialError::NotPositiveDefinite { .. })
    ));
    let mut p = ti_params();
    p.e_p = f64::NAN;
    assert!(matches!(transversely_isotropic(p, Vector3::z()), Err(MaterialError::NonFinite { .. })));
    assert!(matches!(
        transversely_isotropic_plane_strain(ti_params(), Vector2::zeros()),
        Err(MaterialError::DegenerateAxis { .. })
    ));
}

#[test]
fn matrix_errors() {
    let mut c = spd6();
    c[(0, 4)] += 0.3;
    let err = anisotropic::<3>(c.clone()).unwrap_err();
    match err {
        MaterialError::NotSymmetric { i, j, a_ij, a_ji } => {
            assert_eq!((i, j), (0, 4));
            assert_eq!((a_ij, a_ji), (c[(0, 4)], c[(4, 0)]));
        }
        ref other => panic!("unexpected {other:?}"),
    }
    assert!(err.to_string().contains(&c[(0, 4)].to_string()), "{err}");

    let indefinite =
        VoigtMatrix::from_diagonal(&VoigtVector::from_column_slice(&[1.0, 1.0, 1.0, 1.0, 1.0, -2.0]));
    let err = anisotropic::<3>(indefinite).unwrap_err();
    match err {
        MaterialError::NotPositiveDefinite { min_eigenvalue } => {
            assert_relative_eq!(min_eigenvalue, -2.0, max_relative = 1e-12)
        }
        ref other => panic!("unexpected {other:?}"),
    }
    assert!(err.to_string().contains("-2"), "{err}");

    let err = anisotropic::<3>(VoigtMatrix::identity(5, 5)).unwrap_err();
    assert_eq!(err, MaterialError::WrongVoigtSize { expected: 6, got: 5 });
    assert!(err.to_string().contains('5') && err.to_string().contains('6'));
    assert!(matches!(
        anisotropic::<2>(VoigtMatrix::identity(3, 4)),
        Err(MaterialError::WrongVoigtSize { expected: 3, got: 4 })
    ));
    assert_eq!(
        anisotropic::<4>(VoigtMatrix::identity(10, 10)).unwrap_err(),
        MaterialError::UnsupportedDimension(4)
    );
    let mut nan = spd6();
    nan[(2, 2)] = f64::NAN;
    assert!(matches!(anisotropic::<3>(nan), Err(MaterialError::NonFinite { .. })));
    // Symmetric within the relative tolerance 1e-10 is accepted.
    let mut nearly = spd6();
    nearly[(1, 3)] += 1e-13 * nearly.amax();
    assert!(anisotropic::<3>(nearly).is_ok());
}

#[test]
fn kelvin_voigt_errors() {
    let c0 = || isotropic(1.0, 0.3).unwrap();
    let c1 = || isotropic(0.1, 0.2).unwrap();
    for rho in [0.0, -1.5] {
        let err = KelvinVoigt::from_linear(c0(), c1(), rho, 0.1).unwrap_err();
        assert_eq!(err, MaterialError::NonPositiveDensity { rho });
        assert!(err.to_string().contains(&rho.to_string()), "{err}");
    }
    assert!(matches!(
        KelvinVoigt::from_linear(c0(), c1(), f64::NAN, 0.1),
        Err(MaterialError::NonFinite { .. })
    ));
    let err = KelvinVoigt::from_linear(c0(), c1(), 1.0, -0.25).unwrap_err();
    assert_eq!(err, MaterialError::NegativeDamping { alpha: -0.25 });
    assert!(err.to_string().contains("-0.25"), "{err}");
    assert!(matches!(
        KelvinVoigt::from_linear(c0(), c1(), 1.0, f64::INFINITY),
        Err(MaterialError::NonFinite { .. })
    ));
    // Zero elasticity is not admissible.
    assert!(matches!(
        KelvinVoigt::<3>::new(Arc::new(LinearElastic::<3>::zero()), None, 1.0, 0.0),
        Err(MaterialError::NotPositiveDefinite { .. })
    ));
    // A user material with an indefinite linear viscosity.
    let bad = UserLinear(VoigtMatrix::from_diagonal(&VoigtVector::from_column_slice(&[1.0, 1.0, -0.5])));
    assert!(matches!(
        KelvinVoigt::<2>::new(
            Arc::new(plane_strain(1.0, 0.3).unwrap()),
            Some(Arc::new(bad)),
            1.0,
            0.0
        ),
        Err(MaterialError::NotPositiveSemiDefinite { min_eigenvalue }) if (min_eigenvalue + 0.5).abs() < 1e-14
    ));
    // A user material of the wrong Voigt size.
    let wrong = UserLinear(VoigtMatrix::identity(6, 6));
    assert!(matches!(
        KelvinVoigt::<2>::new(Arc::new(wrong), None, 1.0, 0.0),
        Err(MaterialError::WrongVoigtSize { expected: 3, got: 6 })
    ));
}

// ---------------------------------------------------------------- Kelvin–Voigt

#[test]
fn kelvin_voigt_parts() {
    let c0 = isotropic(1.0, 0.3).unwrap();
    let c1 = isotropic(0.1, 0.2).unwrap();
    let kv = KelvinVoigt::from_linear(c0.clone(), c1.clone(), 1100.0, 0.0).unwrap();
    assert_eq!(kv.density(), 1100.0);
    assert_eq!(kv.damping(), 0.0);
    assert_mat_close(&kv.elastic().linear_stiffness().unwrap(), c0.stiffness(), 0.0);
    assert_mat_close(&kv.viscous_stiffness().unwrap(), c1.stiffness(), 0.0);
    let (e, edot) = (strain3(), strain3() * -3.0);
    let total = kv.total_stress(&e, &edot);
    let expected = c0.stiffness() * &e + c1.stiffness() * &edot;
    assert!((total - &expected).amax() < 1e-15 * expected.amax().max(1.0));
    // As a Material it is the elastic part.
    assert_mat_close(&kv.linear_stiffness().unwrap(), c0.stiffness(), 0.0);
    assert_relative_eq!(kv.energy_density(&e), c0.energy_density(&e));
    assert!(kv.name().contains("Kelvin"));

    // No viscosity.
    let undamped = KelvinVoigt::from_linear(c0.clone(), LinearElastic::zero(), 1.0, 0.5).unwrap();
    assert!(undamped.viscous().is_none());
    assert_eq!(undamped.viscous_stress(&edot), VoigtVector::zeros(6));
    assert_eq!(undamped.viscous_stiffness().unwrap(), VoigtMatrix::zeros(6, 6));
    // Zero viscosity passed explicitly is fine (PSD).
    let explicit =
        KelvinVoigt::<3>::new(Arc::new(c0), Some(Arc::new(LinearElastic::<3>::zero())), 1.0, 0.0).unwrap();
    assert!(explicit.viscous().is_some());
    // A 2D plane strain body keeps its out-of-plane stress.
    let kv2 =
        KelvinVoigt::from_linear(plane_strain(1.0, 0.3).unwrap(), LinearElastic::zero(), 1.0, 0.0).unwrap();
    assert!(kv2.out_of_plane_stress(&strain2()) != 0.0);
}

// ---------------------------------------------------------------- trait consistency

fn all_3d() -> Vec<Box<dyn Material<3>>> {
    vec![
        Box::new(isotropic(2.0, 0.3).unwrap()),
        Box::new(from_lame(1.0, 0.5).unwrap()),
        Box::new(transversely_isotropic(ti_params(), Vector3::new(1.0, 1.0, 1.0)).unwrap()),
        Box::new(anisotropic::<3>(spd6()).unwrap()),
        Box::new(
            KelvinVoigt::from_linear(isotropic(1.0, 0.2).unwrap(), isotropic(0.5, 0.1).unwrap(), 1.0, 0.1)
                .unwrap(),
        ),
        Box::new(Stiffening { lin: isotropic(1.0, 0.25).unwrap(), beta: 5e5 }),
    ]
}

fn all_2d() -> Vec<Box<dyn Material<2>>> {
    vec![
        Box::new(plane_strain(2.0, 0.3).unwrap()),
        Box::new(plane_stress(2.0, 0.3).unwrap()),
        Box::new(plane_strain_from_lame(-0.75, 1.0).unwrap()),
        Box::new(transversely_isotropic_plane_strain(ti_params(), Vector2::new(1.0, 2.0)).unwrap()),
        Box::new(transversely_isotropic_plane_stress(ti_params(), Vector2::new(1.0, 2.0)).unwrap()),
        Box::new(anisotropic::<2>(sub(&spd6(), &[0, 1, 5])).unwrap()),
    ]
}

fn check_consistency<const D: usize>(m: &dyn Material<D>, eps: &VoigtVector) {
    let sigma = m.stress(eps);
    assert_eq!(sigma.len(), voigt_len(D));
    let t = m.tangent(eps);
    // Tangent = FD of stress.
    let fd = fd_tangent(m, eps);
    assert!((&t - &fd).amax() <= 1e-6 * t.amax(), "{}: tangent", m.name());
    assert!((&t - t.transpose()).amax() <= 1e-12 * t.amax(), "{}", m.name());
    // Stress = FD gradient of energy.
    let g = fd_gradient(m, eps);
    assert!((&g - &sigma).amax() <= 1e-6 * sigma.amax(), "{}: gradient", m.name());
    if let Some(c) = m.linear_stiffness() {
        // Linear: Φ = ½ ε·σ exactly.
        assert_relative_eq!(m.energy_density(eps), 0.5 * eps.dot(&sigma), max_relative = 1e-13);
        assert!((&c * eps - &sigma).amax() <= 1e-15 * sigma.amax().max(1.0));
    }
    assert!(!m.name().is_empty());
}

#[test]
fn energy_stress_tangent_consistency() {
    for m in all_3d() {
        check_consistency::<3>(m.as_ref(), &strain3());
        check_consistency::<3>(m.as_ref(), &(strain3() * -50.0));
    }
    for m in all_2d() {
        check_consistency::<2>(m.as_ref(), &strain2());
    }
}

// ---------------------------------------------------------------- user materials

/// A user-defined linear material (to test KelvinVoigt's validation of foreign materials).
#[derive(Debug)]
struct UserLinear(VoigtMatrix);

impl<const D: usize> Material<D> for UserLinear {
    fn stress(&self, strain: &VoigtVector) -> VoigtVector {
        &self.0 * strain
    }
    fn tangent(&self, _strain: &VoigtVector) -> VoigtMatrix {
        self.0.clone()
    }
    fn energy_density(&self, strain: &VoigtVector) -> f64 {
        0.5 * strain.dot(&(&self.0 * strain))
    }
    fn linear_stiffness(&self) -> Option<VoigtMatrix> {
        Some(self.0.clone())
    }
    fn name(&self) -> String {
        "user linear".into()
    }
}

/// A nonlinear user material: `Φ = ½ εᵀCε + β (tr ε)⁴ / 4`.
#[derive(Debug)]
struct Stiffening {
    lin: LinearElastic<3>,
    beta: f64,
}

fn trace_vec() -> VoigtVector {
    VoigtVector::from_column_slice(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
}

impl Material<3> for Stiffening {
    fn stress(&self, e: &VoigtVector) -> VoigtVector {
        let tr = e.dot(&trace_vec());
        self.lin.stress(e) + trace_vec() * (self.beta * tr.powi(3))
    }
    fn tangent(&self, e: &VoigtVector) -> VoigtMatrix {
        let tr = e.dot(&trace_vec());
        let m = trace_vec();
        self.lin.stiffness() + (&m * m.transpose()) * (3.0 * self.beta * tr * tr)
    }
    fn energy_density(&self, e: &VoigtVector) -> f64 {
        let tr = e.dot(&trace_vec());
        self.lin.energy_density(e) + self.beta * tr.powi(4) / 4.0
    }
    fn name(&self) -> String {
        "stiffening".into()
    }
}

#[test]
fn kelvin_voigt_with_nonlinear_user_material() {
    let kv = KelvinVoigt::<3>::new(
        Arc::new(Stiffening { lin: isotropic(1.0, 0.3).unwrap(), beta: 1e6 }),
        Some(Arc::new(isotropic(0.1, 0.0).unwrap())),
        1.0,
        0.0,
    )
    .unwrap();
    assert!(kv.linear_stiffness().is_none());
    let e = strain3();
    let s = kv.stress(&e);
    let s_lin = isotropic(1.0, 0.3).unwrap().stress(&e);
    assert!((s - s_lin).amax() > 0.0);
    check_consistency::<3>(&kv, &e);
}
