//! The solid-mechanics fields written to every `.vtu` file (library and CLI): stress and strain
//! tensors, principal stresses, von Mises, strain energy density.
//!
//! Tensors are written as VTK's **symmetric tensors**: 6 components in the order
//! `XX, YY, ZZ, XY, YZ, XZ` (ParaView shows them as tensors and names the components so; meshio
//! and VTK read them as 6-component arrays). In 2D the out-of-plane stress `σ_zz` (plane strain:
//! `ν(σ_xx + σ_yy)`) is in `ZZ` and `YZ = XZ = 0`; the strain's `ZZ` is 0 (the in-plane strain
//! of plane strain; plane stress's `ε_zz` is not recovered).

use synovia_fem::post::BodyFields;
use synovia_io::{Field, FieldLocation};
use synovia_mesh::math::{Real, Vector};

/// Number of components of a symmetric tensor field (`XX, YY, ZZ, XY, YZ, XZ`).
pub const SYMMETRIC_TENSOR_COMPONENTS: usize = 6;

/// The solid fields of one body, for a body whose frame is turned into space by `rotate`
/// (the identity for an unplaced body; tensors become `R T Rᵀ`, invariants are unchanged):
///
/// * point `von_mises_nodal` (the von Mises stress recovered to the nodes) and `stress_nodal`
///   (the recovered stress, symmetric tensor);
/// * cell `stress` and `strain` (symmetric tensors; the strain with tensor shear components
///   `ε_xy = γ_xy / 2`), `von_mises`, `principal_stress` (3 values, descending) and
///   `strain_energy_density` (`½ σ : ε`).
pub fn solid_fields<const D: usize>(
    fields: &BodyFields,
    rotate: impl Fn(&Vector<D>) -> Vector<D>,
) -> Vec<Field> {
    let stress_of = |voigt: &[Real], zz: Real| symmetric(&rotated(&stress_matrix::<D>(voigt, zz), &rotate));
    let strain_of = |voigt: &[Real]| symmetric(&rotated(&strain_matrix::<D>(voigt), &rotate));
    let cell_stress: Vec<Real> = fields
        .cell_stress
        .iter()
        .zip(fields.cell_stress_zz.iter().copied().chain(std::iter::repeat(0.0)))
        .flat_map(|(s, zz)| stress_of(s, zz))
        .collect();
    let cell_strain: Vec<Real> = fields.cell_strain.iter().flat_map(|e| strain_of(e)).collect();
    // the recovered stress has no σ_zz in 2D: its ZZ stays 0
    let nodal_stress: Vec<Real> = fields.nodal_stress.iter().flat_map(|s| stress_of(s, 0.0)).collect();
    let energy: Vec<Real> = fields
        .cell_strain
        .iter()
        .zip(&fields.cell_stress)
        .map(|(e, s)| 0.5 * e.iter().zip(s).map(|(a, b)| a * b).sum::<Real>())
        .collect();
    let principal: Vec<Real> = fields.cell_principal.iter().flat_map(|p| p.iter().copied()).collect();
    vec![
        Field::point_scalars("von_mises_nodal", fields.nodal_von_mises.clone()),
        Field::new("stress_nodal", FieldLocation::Point, SYMMETRIC_TENSOR_COMPONENTS, nodal_stress),
        Field::new("stress", FieldLocation::Cell, SYMMETRIC_TENSOR_COMPONENTS, cell_stress),
        Field::new("strain", FieldLocation::Cell, SYMMETRIC_TENSOR_COMPONENTS, cell_strain),
        Field::cell_scalars("von_mises", fields.cell_von_mises.clone()),
        Field::new("principal_stress", FieldLocation::Cell, 3, principal),
        Field::cell_scalars("strain_energy_density", energy),
    ]
}

/// The 3 × 3 stress of a Voigt stress (`[xx, yy, xy]` with `σ_zz` in 2D; `[xx, yy, zz, yz,
/// xz, xy]` in 3D).
fn stress_matrix<const D: usize>(v: &[Real], zz: Real) -> [[Real; 3]; 3] {
    match (D, v) {
        (2, &[xx, yy, xy, ..]) => [[xx, xy, 0.0], [xy, yy, 0.0], [0.0, 0.0, zz]],
        (_, &[xx, yy, zz, yz, xz, xy, ..]) => [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]],
        _ => [[0.0; 3]; 3],
    }
}

/// The 3 × 3 strain tensor of a Voigt strain with engineering shears (`γ = 2ε`).
fn strain_matrix<const D: usize>(v: &[Real]) -> [[Real; 3]; 3] {
    match (D, v) {
        (2, &[xx, yy, gxy, ..]) => [[xx, 0.5 * gxy, 0.0], [0.5 * gxy, yy, 0.0], [0.0, 0.0, 0.0]],
        (_, &[xx, yy, zz, gyz, gxz, gxy, ..]) => {
            let (yz, xz, xy) = (0.5 * gyz, 0.5 * gxz, 0.5 * gxy);
            [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
        }
        _ => [[0.0; 3]; 3],
    }
}

/// `R T Rᵀ` for the rotation `R` applied by `rotate` (on the first `D` axes; in 2D the `z` axis
/// is kept).
fn rotated<const D: usize>(t: &[[Real; 3]; 3], rotate: &impl Fn(&Vector<D>) -> Vector<D>) -> [[Real; 3]; 3] {
    let r: [[Real; 3]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            if i >= D || j >= D {
                return if i == j { 1.0 } else { 0.0 };
            }
            let mut e = Vector::<D>::zeros();
            e[j] = 1.0;
            rotate(&e)[i]
        })
    });
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            (0..3).map(|k| (0..3).map(|l| r[i][k] * t[k][l] * r[j][l]).sum::<Real>()).sum()
        })
    })
}

/// `[XX, YY, ZZ, XY, YZ, XZ]` of a symmetric 3 × 3 tensor.
fn symmetric(t: &[[Real; 3]; 3]) -> [Real; 6] {
    [t[0][0], t[1][1], t[2][2], t[0][1], t[1][2], t[0][2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotating_a_uniaxial_stress_by_a_quarter_turn_moves_it_to_the_other_axis() {
        // σ_xx = 1 turned by +90° about z becomes σ_yy = 1
        let quarter = |v: &Vector<3>| Vector::<3>::new(-v[1], v[0], v[2]);
        let t = rotated(&stress_matrix::<3>(&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0), &quarter);
        let s = symmetric(&t);
        for (got, want) in s.iter().zip([0.0, 1.0, 0.0, 0.0, 0.0, 0.0]) {
            assert!((got - want).abs() < 1e-15, "{s:?}");
        }
        // 2D: pure shear τ_xy = 1 turned by 45° becomes the principal pair (1, −1), σ_zz kept
        let (c, sn) = (std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2);
        let turn = |v: &Vector<2>| Vector::<2>::new(c * v[0] - sn * v[1], sn * v[0] + c * v[1]);
        let s = symmetric(&rotated(&stress_matrix::<2>(&[0.0, 0.0, 1.0], 0.25), &turn));
        for (got, want) in s.iter().zip([-1.0, 1.0, 0.25, 0.0, 0.0, 0.0]) {
            assert!((got - want).abs() < 1e-15, "{s:?}");
        }
    }

    #[test]
    fn strain_tensor_halves_the_engineering_shears() {
        let e = symmetric(&strain_matrix::<3>(&[1.0, 2.0, 3.0, 0.4, 0.6, 0.8]));
        assert_eq!(e, [1.0, 2.0, 3.0, 0.4, 0.2, 0.3]);
        let e = symmetric(&strain_matrix::<2>(&[1.0, 2.0, 0.5]));
        assert_eq!(e, [1.0, 2.0, 0.0, 0.25, 0.0, 0.0]);
    }
}
