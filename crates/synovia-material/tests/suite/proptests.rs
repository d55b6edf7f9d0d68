//! Property tests: admissible parameters give SPD matrices; Bond rotations preserve
//! admissibility, the Kelvin moduli and the strain energy.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Matrix2, Matrix3, Rotation3, Vector3};
use proptest::prelude::*;
use synovia_material::{
    anisotropic, bond_strain_matrix, check_admissible, isotropic, plane_strain, plane_stress,
    transversely_isotropic, Material, TransverseIsotropy, VoigtMatrix, VoigtVector,
};

fn rotation(angles: (f64, f64, f64)) -> Matrix3<f64> {
    *Rotation3::from_euler_angles(angles.0, angles.1, angles.2).matrix()
}

fn angles() -> impl Strategy<Value = (f64, f64, f64)> {
    (-3.2f64..3.2, -3.2f64..3.2, -3.2f64..3.2)
}

/// A random SPD 6×6 matrix `AᵀA + s I`.
fn spd6() -> impl Strategy<Value = VoigtMatrix> {
    (proptest::collection::vec(-1.0f64..1.0, 36), 0.05f64..2.0).prop_map(|(a, s)| {
        let a = VoigtMatrix::from_vec(6, 6, a);
        a.transpose() * &a + VoigtMatrix::identity(6, 6) * s
    })
}

fn strain() -> impl Strategy<Value = VoigtVector> {
    proptest::collection::vec(-1.0f64..1.0, 6).prop_map(VoigtVector::from_vec)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn admissible_isotropic_parameters_give_spd(
        log_e in -3.0f64..12.0,
        nu in -0.999f64..0.499,
    ) {
        let e = 10f64.powf(log_e);
        for c in [
            isotropic(e, nu).unwrap().stiffness().clone(),
            plane_strain(e, nu).unwrap().stiffness().clone(),
            plane_stress(e, nu).unwrap().stiffness().clone(),
        ] {
            prop_assert!(check_admissible(&c).is_ok());
            let eig = nalgebra::SymmetricEigen::new(c.clone()).eigenvalues;
            prop_assert!(eig.iter().all(|&l| l > 0.0));
        }
    }

    #[test]
    fn rotations_preserve_admissibility_moduli_and_energy(
        c in spd6(),
        ang in angles(),
        eps in strain(),
    ) {
        let m = anisotropic::<3>(c).unwrap();
        let r = rotation(ang);
        let mr = m.rotated(&r).unwrap();
        prop_assert!(check_admissible(mr.stiffness()).is_ok());
        let (k0, k1) = (m.kelvin_moduli(), mr.kelvin_moduli());
        let scale = k0.amax();
        prop_assert!((&k0 - &k1).amax() <= 1e-11 * scale, "{} vs {}", k0, k1);
        let n = bond_strain_matrix(&r).unwrap();
        let (w0, w1) = (m.energy_density(&eps), mr.energy_density(&(&n * &eps)));
        prop_assert!((w0 - w1).abs() <= 1e-11 * scale * eps.norm_squared());
        // 2D: rotating the plane strain reduction about z.
        let m2 = m.plane_strain();
        let (co, si) = (ang.0.cos(), ang.0.sin());
        let m2r = m2.rotated(&Matrix2::new(co, -si, si, co)).unwrap();
        prop_assert!(check_admissible(m2r.stiffness()).is_ok());
        let (q0, q1) = (m2.kelvin_moduli(), m2r.kelvin_moduli());
        prop_assert!((&q0 - &q1).amax() <= 1e-11 * scale);
    }

    #[test]
    fn transversely_isotropic_is_spd_for_any_axis(
        ax in -1.0f64..1.0, ay in -1.0f64..1.0, az in 0.1f64..1.0,
        ratio in 0.05f64..20.0,
        nu_p in -0.5f64..0.45,
        nu_ap in 0.0f64..0.2,
    ) {
        let p = TransverseIsotropy { e_p: ratio, nu_p, e_a: 1.0, nu_ap, g_a: 0.3 };
        // Admissible iff 1 − ν_p − 2 ν_ap ν_pa > 0 (given |ν_p| < 1).
        let admissible = 1.0 - nu_p - 2.0 * nu_ap * p.nu_pa() > 1e-6;
        match transversely_isotropic(p, Vector3::new(ax, ay, az)) {
            Ok(m) => {
                prop_assert!(admissible);
                prop_assert!(check_admissible(m.stiffness()).is_ok());
                let local = transversely_isotropic(p, Vector3::z()).unwrap();
                let (k0, k1) = (local.kelvin_moduli(), m.kelvin_moduli());
                prop_assert!((&k0 - &k1).amax() <= 1e-10 * k0.amax());
            }
            Err(_) => prop_assert!(!admissible),
        }
    }
}
