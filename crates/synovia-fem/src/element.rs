//! P1 simplex kernels: shape gradients, strain–displacement matrix, element stiffness, mass and
//! load vectors.
//!
//! On a simplex `T` with vertices `x_0 … x_D` the P1 shape functions are the barycentric
//! coordinates `φ_a`; their gradients are constant. With the Jacobian
//! `J = [x_1 − x_0, …, x_D − x_0]`, `∇φ_k = J^{-T} e_k` for `k ≥ 1` and
//! `∇φ_0 = −Σ_{k≥1} ∇φ_k`. Element vectors are ordered node-major: `(a, i) ↦ D a + i`.

use nalgebra::DMatrix;
use synovia_mesh::math::{factorial, inverse_with_det, Point, Real, Tensor, Vector};

use crate::quadrature::QuadratureRule;

/// Geometry of one P1 simplex: measure and constant shape-function gradients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplexGeometry<const D: usize> {
    /// Measure `|T| = det J / D!` (positive for positively oriented cells).
    pub measure: Real,
    /// `J^{-T}`: column `k` is `∇φ_{k+1}`.
    inv_jt: Tensor<D>,
}

impl<const D: usize> SimplexGeometry<D> {
    /// Geometry of the simplex with the given `D + 1` vertices; `None` if it is degenerate.
    pub fn new(vertices: &[Point<D>]) -> Option<Self> {
        let mut j = Tensor::<D>::zeros();
        for k in 0..D {
            j.set_column(k, &(vertices[k + 1] - vertices[0]));
        }
        let (inv, det) = inverse_with_det(&j)?;
        Some(Self { measure: det / factorial(D), inv_jt: inv.transpose() })
    }

    /// `∇φ_a` for local vertex `a ∈ 0..=D`.
    #[inline]
    pub fn grad(&self, a: usize) -> Vector<D> {
        if a == 0 {
            -self.inv_jt.column_sum()
        } else {
            self.inv_jt.column(a - 1).into_owned()
        }
    }

    /// Displacement gradient `∇u = Σ_a u_a ⊗ ∇φ_a` from nodal displacements (node-major).
    pub fn displacement_gradient(&self, u: &[Real]) -> Tensor<D> {
        let mut g = Tensor::<D>::zeros();
        for a in 0..=D {
            let ga = self.grad(a);
            for i in 0..D {
                for j in 0..D {
                    g[(i, j)] += u[D * a + i] * ga[j];
                }
            }
        }
        g
    }
}

/// Voigt strain (engineering shear) of a displacement gradient `∇u`:
/// 2D `(ε_xx, ε_yy, γ_xy)`, 3D `(ε_xx, ε_yy, ε_zz, γ_yz, γ_xz, γ_xy)`, `γ_ij = ∂_j u_i + ∂_i u_j`.
pub fn voigt_strain<const D: usize>(grad_u: &Tensor<D>) -> Vec<Real> {
    let g = grad_u;
    if D == 2 {
        vec![g[(0, 0)], g[(1, 1)], g[(0, 1)] + g[(1, 0)]]
    } else {
        vec![
            g[(0, 0)],
            g[(1, 1)],
            g[(2, 2)],
            g[(1, 2)] + g[(2, 1)],
            g[(0, 2)] + g[(2, 0)],
            g[(0, 1)] + g[(1, 0)],
        ]
    }
}

/// Symmetric tensor from a Voigt stress vector (plain shear components).
pub fn stress_tensor<const D: usize>(voigt: &[Real]) -> Tensor<D> {
    let mut s = Tensor::<D>::zeros();
    if D == 2 {
        s[(0, 0)] = voigt[0];
        s[(1, 1)] = voigt[1];
        s[(0, 1)] = voigt[2];
        s[(1, 0)] = voigt[2];
    } else {
        s[(0, 0)] = voigt[0];
        s[(1, 1)] = voigt[1];
        s[(2, 2)] = voigt[2];
        s[(1, 2)] = voigt[3];
        s[(2, 1)] = voigt[3];
        s[(0, 2)] = voigt[4];
        s[(2, 0)] = voigt[4];
        s[(0, 1)] = voigt[5];
        s[(1, 0)] = voigt[5];
    }
    s
}

/// Row `r` of the strain–displacement matrix block `B_a` (Voigt row `r`, displacement
/// component `i`) for the gradient `g = ∇φ_a`: `ε_voigt = Σ_a B_a u_a`.
#[inline]
fn b_entry<const D: usize>(g: &Vector<D>, r: usize, i: usize) -> Real {
    if D == 2 {
        match (r, i) {
            (0, 0) => g[0],
            (1, 1) => g[1],
            (2, 0) => g[1],
            (2, 1) => g[0],
            _ => 0.0,
        }
    } else {
        match (r, i) {
            (0, 0) => g[0],
            (1, 1) => g[1],
            (2, 2) => g[2],
            (3, 1) => g[2],
            (3, 2) => g[1],
            (4, 0) => g[2],
            (4, 2) => g[0],
            (5, 0) => g[1],
            (5, 1) => g[0],
            _ => 0.0,
        }
    }
}

/// Element stiffness `K_T = |T| Bᵀ C B` of the bilinear form
/// `a(u, v) = ∫_T C e(u) : e(v) dx` (docs/model.md §2), for a constant Voigt stiffness `C`
/// (`voigt_len(D)` square, engineering-shear convention). Written into `out`, a
/// `D(D+1) × D(D+1)` row-major buffer, node-major dof order.
pub fn stiffness_into<const D: usize>(geo: &SimplexGeometry<D>, c: &DMatrix<Real>, out: &mut [Real]) {
    let n = D * (D + 1);
    let nv = D * (D + 1) / 2;
    // B: nv × n
    let mut b = [[0.0; 12]; 6];
    for a in 0..=D {
        let g = geo.grad(a);
        for (r, row) in b.iter_mut().enumerate().take(nv) {
            for i in 0..D {
                row[D * a + i] = b_entry::<D>(&g, r, i);
            }
        }
    }
    // CB: nv × n
    let mut cb = [[0.0; 12]; 6];
    for r in 0..nv {
        for s in 0..nv {
            let crs = c[(r, s)];
            if crs != 0.0 {
                for k in 0..n {
                    cb[r][k] += crs * b[s][k];
                }
            }
        }
    }
    for p in 0..n {
        for q in p..n {
            let mut s = 0.0;
            for r in 0..nv {
                s += b[r][p] * cb[r][q];
            }
            s *= geo.measure;
            out[p * n + q] = s;
            out[q * n + p] = s;
        }
    }
}

/// Consistent mass matrix of density `rho`: `M_ab = ρ |T| (1 + δ_ab) / ((D+1)(D+2))` on each
/// displacement component (the exact integral of `ρ φ_a φ_b` for constant `ρ`). Written into
/// `out` (`D(D+1)` square, row-major).
pub fn consistent_mass_into<const D: usize>(geo: &SimplexGeometry<D>, rho: Real, out: &mut [Real]) {
    let n = D * (D + 1);
    out[..n * n].iter_mut().for_each(|x| *x = 0.0);
    let base = rho * geo.measure / ((D + 1) * (D + 2)) as Real;
    for a in 0..=D {
        for b in 0..=D {
            let m = if a == b { 2.0 * base } else { base };
            for i in 0..D {
                out[(D * a + i) * n + D * b + i] = m;
            }
        }
    }
}

/// Row-sum lumped mass `ρ |T| / (D + 1)` per node and component (diagonal), into `out`
/// (length `D(D+1)`).
pub fn lumped_mass_into<const D: usize>(geo: &SimplexGeometry<D>, rho: Real, out: &mut [Real]) {
    let m = rho * geo.measure / (D + 1) as Real;
    out[..D * (D + 1)].iter_mut().for_each(|x| *x = m);
}

/// Mass element matrix with coefficient `c` (`ρ` for `M_ρ`, `α` for `M_α`, docs/model.md §7):
/// consistent ([`consistent_mass_into`]) or row-sum lumped (diagonal), into `out`
/// (`D(D+1)` square, row-major).
pub fn mass_into<const D: usize>(geo: &SimplexGeometry<D>, c: Real, lumped: bool, out: &mut [Real]) {
    if lumped {
        let n = D * (D + 1);
        out[..n * n].iter_mut().for_each(|x| *x = 0.0);
        let m = c * geo.measure / (D + 1) as Real;
        for k in 0..n {
            out[k * n + k] = m;
        }
    } else {
        consistent_mass_into(geo, c, out);
    }
}

/// Load vector of a body force `f(x)` on a cell: `F_{a,i} = ∫_T f_i φ_a dx`, by `rule`.
/// Returns `Err(x)` with the first point where `f` is not finite.
pub fn body_force_into<const D: usize>(
    vertices: &[Point<D>],
    measure: Real,
    rule: &QuadratureRule,
    f: &dyn Fn(&Point<D>) -> Vector<D>,
    out: &mut [Real],
) -> Result<(), Point<D>> {
    out[..D * (D + 1)].iter_mut().for_each(|x| *x = 0.0);
    for (lam, w) in rule.barycentric.iter().zip(&rule.weights) {
        let mut x = Point::<D>::zeros();
        for a in 0..=D {
            x += vertices[a] * lam[a];
        }
        let fx = f(&x);
        if fx.iter().any(|v| !v.is_finite()) {
            return Err(x);
        }
        for a in 0..=D {
            for i in 0..D {
                out[D * a + i] += w * measure * lam[a] * fx[i];
            }
        }
    }
    Ok(())
}

/// Load vector of a traction `P(x, n)` on a boundary facet with `D` vertices and outward unit
/// normal `n`: `F_{a,i} = ∫_facet P_i φ_a ds`, by `rule` (a rule on the `(D−1)`-simplex).
pub fn traction_into<const D: usize>(
    vertices: &[Point<D>],
    measure: Real,
    normal: &Vector<D>,
    rule: &QuadratureRule,
    p: &dyn Fn(&Point<D>, &Vector<D>) -> Vector<D>,
    out: &mut [Real],
) -> Result<(), Point<D>> {
    out[..D * D].iter_mut().for_each(|x| *x = 0.0);
    for (lam, w) in rule.barycentric.iter().zip(&rule.weights) {
        let mut x = Point::<D>::zeros();
        for a in 0..D {
            x += vertices[a] * lam[a];
        }
        let px = p(&x, normal);
        if px.iter().any(|v| !v.is_finite()) {
            return Err(x);
        }
        for a in 0..D {
            for i in 0..D {
                out[D * a + i] += w * measure * lam[a] * px[i];
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn iso_plane_strain(e: f64, nu: f64) -> DMatrix<f64> {
        let l = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let m = e / (2.0 * (1.0 + nu));
        DMatrix::from_row_slice(3, 3, &[l + 2.0 * m, l, 0.0, l, l + 2.0 * m, 0.0, 0.0, 0.0, m])
    }

    #[test]
    fn gradients_reproduce_linear_functions() {
        let v = [
            Point::<3>::new(0.1, 0.2, 0.0),
            Point::<3>::new(1.3, 0.1, 0.2),
            Point::<3>::new(0.2, 1.1, 0.3),
            Point::<3>::new(0.3, 0.4, 0.9),
        ];
        let geo = SimplexGeometry::<3>::new(&v).expect("non-degenerate");
        let a = Vector::<3>::new(0.3, -1.2, 2.0);
        let mut g = Vector::<3>::zeros();
        for (k, x) in v.iter().enumerate() {
            g += geo.grad(k) * a.dot(x);
        }
        assert!((g - a).norm() < 1e-13);
        let sum: Vector<3> = (0..4).map(|k| geo.grad(k)).sum();
        assert!(sum.norm() < 1e-13);
    }

    #[test]
    fn stiffness_is_symmetric_psd_with_rigid_kernel() {
        let v = [Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.1), Point::<2>::new(0.3, 0.8)];
        let geo = SimplexGeometry::<2>::new(&v).expect("ok");
        let mut k = vec![0.0; 36];
        stiffness_into(&geo, &iso_plane_strain(10.0, 0.3), &mut k);
        let km = DMatrix::from_row_slice(6, 6, &k);
        assert!((&km - km.transpose()).norm() < 1e-12);
        // rigid motions: translations and rotation (−y, x)
        for mode in [[1.0, 0.0], [0.0, 1.0]] {
            let u = nalgebra::DVector::from_fn(6, |i, _| mode[i % 2]);
            assert!((&km * u).norm() < 1e-12);
        }
        let rot = nalgebra::DVector::from_fn(6, |i, _| if i % 2 == 0 { -v[i / 2][1] } else { v[i / 2][0] });
        assert!((&km * rot).norm() < 1e-12);
        let eig = km.symmetric_eigen().eigenvalues;
        assert_eq!(eig.iter().filter(|&&x| x > 1e-9).count(), 3);
    }
}
