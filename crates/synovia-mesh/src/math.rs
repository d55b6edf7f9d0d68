//! Dimension and scalar aliases shared by every synovia crate.
//!
//! All geometric code is generic over the spatial dimension `const D: usize` (2 or 3) through
//! nalgebra's `Const<D>`; this module is the one place that names the fixed-size types.

use nalgebra::{SMatrix, SVector};

/// Scalar type of all computations.
pub type Real = f64;
/// A point of `R^D`.
pub type Point<const D: usize> = SVector<Real, D>;
/// A vector of `R^D`.
pub type Vector<const D: usize> = SVector<Real, D>;
/// A `D × D` matrix (displacement gradient, strain or stress tensor).
pub type Tensor<const D: usize> = SMatrix<Real, D, D>;

/// Number of vertices of a P1 simplex in dimension `d` (`d + 1`: triangle or tetrahedron).
pub const fn nodes_per_cell(d: usize) -> usize {
    d + 1
}

/// Length of a Voigt vector of a symmetric `d × d` tensor (`3` in 2D, `6` in 3D).
pub const fn voigt_len(d: usize) -> usize {
    d * (d + 1) / 2
}

/// `true` for the dimensions synovia supports (2 and 3).
pub const fn is_supported_dim(d: usize) -> bool {
    d == 2 || d == 3
}

/// Signed measure of the simplex `x_0 … x_D` times `D!`: `det[x_1 − x_0, …, x_D − x_0]`.
///
/// Positive for counter-clockwise triangles and positively oriented tetrahedra.
pub fn simplex_det<const D: usize>(vertices: &[Point<D>]) -> Real {
    let mut m = SMatrix::<Real, D, D>::zeros();
    for k in 0..D {
        m.set_column(k, &(vertices[k + 1] - vertices[0]));
    }
    det(&m)
}

/// Determinant of a `2 × 2` or `3 × 3` matrix (explicit formula; `NaN` for other sizes).
///
/// Written out because nalgebra's generic `determinant` needs allocator bounds that every
/// `const D` caller would have to repeat.
pub fn det<const D: usize>(m: &Tensor<D>) -> Real {
    match D {
        1 => m[(0, 0)],
        2 => m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)],
        3 => {
            m[(0, 0)] * (m[(1, 1)] * m[(2, 2)] - m[(1, 2)] * m[(2, 1)])
                - m[(0, 1)] * (m[(1, 0)] * m[(2, 2)] - m[(1, 2)] * m[(2, 0)])
                + m[(0, 2)] * (m[(1, 0)] * m[(2, 1)] - m[(1, 1)] * m[(2, 0)])
        }
        _ => Real::NAN,
    }
}

/// Inverse of a `2 × 2` or `3 × 3` matrix by the adjugate formula, with its determinant.
/// Returns `None` when the determinant is zero or not finite.
pub fn inverse_with_det<const D: usize>(m: &Tensor<D>) -> Option<(Tensor<D>, Real)> {
    let d = det(m);
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    let mut inv = Tensor::<D>::zeros();
    match D {
        1 => inv[(0, 0)] = 1.0 / d,
        2 => {
            inv[(0, 0)] = m[(1, 1)] / d;
            inv[(0, 1)] = -m[(0, 1)] / d;
            inv[(1, 0)] = -m[(1, 0)] / d;
            inv[(1, 1)] = m[(0, 0)] / d;
        }
        3 => {
            for i in 0..3 {
                for j in 0..3 {
                    // cofactor C_ji / det
                    let (r0, r1) = ((j + 1) % 3, (j + 2) % 3);
                    let (c0, c1) = ((i + 1) % 3, (i + 2) % 3);
                    inv[(i, j)] = (m[(r0, c0)] * m[(r1, c1)] - m[(r0, c1)] * m[(r1, c0)]) / d;
                }
            }
        }
        _ => return None,
    }
    Some((inv, d))
}

/// `D!` as a float (the ratio of the determinant to the simplex measure).
pub fn factorial(d: usize) -> Real {
    (1..=d).map(|k| k as Real).product()
}
