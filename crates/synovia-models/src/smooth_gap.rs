//! First and second derivatives of the gap of a [`crate::knee2d::SmoothNodeToSegment`] row with
//! respect to the positions of the nodes it depends on: the ingredients of a consistent
//! linearisation of the contact geometry on the deformed configuration (docs/nonlinear.md,
//! "Cost", third round). Not used by the Newton iteration yet.
//!
//! A row pairs the slave node `x_s` with the master segment `a → b` (a facet of the master
//! part, oriented as the part's facets), whose neighbours along the part are `p` (the facet
//! `p → a`) and `q` (the facet `b → q`). With `⊥(t) = (t_y, −t_x)` the unit nodal normals of
//! the part are those of [`synovia_mesh::mesh::nodal_normals_at`],
//!
//! ```text
//! n_a = ⊥(x_b − x_p) / |⊥(x_b − x_p)|,   n_b = ⊥(x_q − x_a) / |⊥(x_q − x_a)|,
//! ```
//!
//! the master point is `x(ξ) = x_a + ξ e`, `e = x_b − x_a`, with `ξ ∈ [0, 1]` the root of
//! `(x_s − x(ξ)) × ñ(ξ) = 0`, `ñ(ξ) = (1 − ξ) n_a + ξ n_b` (the root closest to `x_s`, as the
//! rows choose it), and the gap is
//!
//! ```text
//! g(x_s, x_p, x_a, x_b, x_q) = (x_s − x(ξ)) · n(ξ),   n = ñ / |ñ|.
//! ```
//!
//! [`smooth_gap`] evaluates `g`, its gradient and its Hessian with respect to the ten
//! coordinates `(x_s, x_p, x_a, x_b, x_q)` (each `(x, y)`, in this order) exactly, by
//! forward-mode differentiation with second-order dual numbers through the same formulas
//! (including the quadratic's root, whose derivatives are those of the implicit function).
//! Since `x_s − x(ξ) = g n`, the gradient is `∂g = n · (δx_s − (1 − ξ) δx_a − ξ δx_b) −
//! (e · n) δξ`: the row's normal on the slave and master weights, plus the term of the normal
//! field's tilt against the segment. The Hessian, weighted by the multiplier, is the
//! geometric contact stiffness `κ Λ_n ∂²g/∂u²` a consistent tangent adds; it couples the slave
//! node with all four master nodes.

use synovia_mesh::math::{Point, Real};

/// Number of coordinates a row's gap depends on: five nodes in 2D.
pub const N: usize = 10;

/// A value with its gradient and Hessian with respect to the [`N`] coordinates.
#[derive(Debug, Clone, Copy)]
struct Dual2 {
    v: Real,
    g: [Real; N],
    h: [[Real; N]; N],
}

impl Dual2 {
    fn constant(v: Real) -> Self {
        Self { v, g: [0.0; N], h: [[0.0; N]; N] }
    }

    fn variable(v: Real, i: usize) -> Self {
        let mut d = Self::constant(v);
        d.g[i] = 1.0;
        d
    }

    /// `f(self)` for a scalar function with `f(v)`, `f'(v)`, `f''(v)` given.
    fn chain(&self, f: Real, df: Real, d2f: Real) -> Self {
        let mut out = Self::constant(f);
        for i in 0..N {
            out.g[i] = df * self.g[i];
            for j in 0..N {
                out.h[i][j] = df * self.h[i][j] + d2f * self.g[i] * self.g[j];
            }
        }
        out
    }

    fn add(&self, o: &Self) -> Self {
        let mut out = *self;
        out.v += o.v;
        for i in 0..N {
            out.g[i] += o.g[i];
            for j in 0..N {
                out.h[i][j] += o.h[i][j];
            }
        }
        out
    }

    fn scale(&self, s: Real) -> Self {
        let mut out = *self;
        out.v *= s;
        for i in 0..N {
            out.g[i] *= s;
            for j in 0..N {
                out.h[i][j] *= s;
            }
        }
        out
    }

    fn sub(&self, o: &Self) -> Self {
        self.add(&o.scale(-1.0))
    }

    fn mul(&self, o: &Self) -> Self {
        let mut out = Self::constant(self.v * o.v);
        for i in 0..N {
            out.g[i] = self.v * o.g[i] + o.v * self.g[i];
            for j in 0..N {
                out.h[i][j] =
                    self.v * o.h[i][j] + o.v * self.h[i][j] + self.g[i] * o.g[j] + o.g[i] * self.g[j];
            }
        }
        out
    }

    fn recip(&self) -> Self {
        let v = self.v;
        self.chain(1.0 / v, -1.0 / (v * v), 2.0 / (v * v * v))
    }

    fn div(&self, o: &Self) -> Self {
        self.mul(&o.recip())
    }

    fn sqrt(&self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s, -0.25 / (s * self.v))
    }
}

/// A 2D vector of [`Dual2`].
type V2 = [Dual2; 2];

fn vsub(a: &V2, b: &V2) -> V2 {
    [a[0].sub(&b[0]), a[1].sub(&b[1])]
}

fn vscale(a: &V2, s: &Dual2) -> V2 {
    [a[0].mul(s), a[1].mul(s)]
}

fn vadd(a: &V2, b: &V2) -> V2 {
    [a[0].add(&b[0]), a[1].add(&b[1])]
}

fn dot(a: &V2, b: &V2) -> Dual2 {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1]))
}

fn cross(a: &V2, b: &V2) -> Dual2 {
    a[0].mul(&b[1]).sub(&a[1].mul(&b[0]))
}

/// `⊥(t) / |⊥(t)|` with `⊥(t) = (t_y, −t_x)`.
fn unit_perp(t: &V2) -> V2 {
    let len = dot(t, t).sqrt();
    [t[1].div(&len), t[0].scale(-1.0).div(&len)]
}

/// The gap of a row, its gradient and its Hessian (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothGap {
    /// `g = (x_s − x(ξ)) · n(ξ)`.
    pub gap: Real,
    /// The master point's parameter `ξ ∈ [0, 1]`.
    pub xi: Real,
    /// The unit normal `n(ξ)` of the master normal field at the master point.
    pub normal: [Real; 2],
    /// `∂g/∂c_i` for the coordinates `c = (x_s, x_p, x_a, x_b, x_q)`.
    pub gradient: [Real; N],
    /// `∂²g/∂c_i ∂c_j`.
    pub hessian: [[Real; N]; N],
}

/// The gap of the row of slave node `xs` on the master segment `xa → xb` with neighbours `xp`
/// (before `a`) and `xq` (after `b`), with its first and second derivatives (module docs);
/// `None` if the normal field does not pass through `xs` over the segment (no root in
/// `[0, 1]`) or a normal is degenerate.
pub fn smooth_gap(
    xs: &Point<2>,
    xp: &Point<2>,
    xa: &Point<2>,
    xb: &Point<2>,
    xq: &Point<2>,
) -> Option<SmoothGap> {
    let var =
        |x: &Point<2>, k: usize| -> V2 { [Dual2::variable(x[0], 2 * k), Dual2::variable(x[1], 2 * k + 1)] };
    let (s, p, a, b, q) = (var(xs, 0), var(xp, 1), var(xa, 2), var(xb, 3), var(xq, 4));
    let na = unit_perp(&vsub(&b, &p));
    let nb = unit_perp(&vsub(&q, &a));
    if !(na[0].v.is_finite() && na[1].v.is_finite() && nb[0].v.is_finite() && nb[1].v.is_finite()) {
        return None;
    }
    // f(ξ) = (r − ξ e) × (n_a + ξ dn) = c0 + c1 ξ + c2 ξ², as `SmoothNodeToSegment::project`
    let r = vsub(&s, &a);
    let e = vsub(&b, &a);
    let dn = vsub(&nb, &na);
    let c0 = cross(&r, &na);
    let c1 = cross(&r, &dn).sub(&cross(&e, &na));
    let c2 = cross(&e, &dn).scale(-1.0);
    let norm = |v: &V2| (v[0].v * v[0].v + v[1].v * v[1].v).sqrt();
    let scale = norm(&e) * (1.0 + norm(&dn));
    let mut roots = Vec::with_capacity(2);
    if c2.v.abs() <= 1e-14 * scale {
        if c1.v.abs() > 0.0 {
            roots.push(c0.div(&c1).scale(-1.0));
        }
    } else {
        let disc = c1.mul(&c1).sub(&c2.mul(&c0).scale(4.0));
        if disc.v >= 0.0 {
            let sq = disc.sqrt();
            let qq = c1.add(&sq.scale(c1.v.signum())).scale(-0.5);
            if qq.v != 0.0 {
                roots.push(qq.div(&c2));
                roots.push(c0.div(&qq));
            }
        }
    }
    let tol = 1e-12;
    let one = Dual2::constant(1.0);
    roots
        .into_iter()
        .filter(|xi| xi.v.is_finite() && xi.v >= -tol && xi.v <= 1.0 + tol)
        .filter_map(|xi| {
            let nt = vadd(&vscale(&na, &one.sub(&xi)), &vscale(&nb, &xi));
            let len = dot(&nt, &nt).sqrt();
            if len.v <= 0.0 {
                return None;
            }
            let n = [nt[0].div(&len), nt[1].div(&len)];
            let xm = vadd(&a, &vscale(&e, &xi));
            let d = vsub(&s, &xm);
            let dist = (d[0].v * d[0].v + d[1].v * d[1].v).sqrt();
            Some((dist, xi, n, dot(&d, &n)))
        })
        .min_by(|u, v| u.0.total_cmp(&v.0))
        .map(|(_, xi, n, g)| SmoothGap {
            gap: g.v,
            xi: xi.v,
            normal: [n[0].v, n[1].v],
            gradient: g.g,
            hessian: g.h,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Five master nodes on a flattened, perturbed arc and a slave node below the segment
    /// `a → b` (the facets oriented so that the normals point down, toward the slave).
    fn configuration() -> [Point<2>; 5] {
        let at = |deg: Real, r: Real| {
            let t = deg.to_radians();
            Point::<2>::new(r * t.cos(), r * t.sin())
        };
        // the arc x = r (cos θ, sin θ) about the origin traversed by increasing θ below the
        // centre: ⊥(x_b − x_p) points away from the centre, toward the slave node
        let (p, a, b, q) = (at(-100.0, 20.05), at(-90.0, 19.9), at(-80.0, 20.1), at(-70.0, 20.0));
        let s = Point::<2>::new(1.3, -20.3);
        [s, p, a, b, q]
    }

    fn gap_of(c: &[Real; N]) -> SmoothGap {
        let pt = |k: usize| Point::<2>::new(c[2 * k], c[2 * k + 1]);
        smooth_gap(&pt(0), &pt(1), &pt(2), &pt(3), &pt(4)).expect("a master point")
    }

    fn coordinates() -> [Real; N] {
        let x = configuration();
        let mut c = [0.0; N];
        for (k, p) in x.iter().enumerate() {
            c[2 * k] = p[0];
            c[2 * k + 1] = p[1];
        }
        c
    }

    #[test]
    fn gap_equals_the_rows_projection() {
        let [s, _, a, b, _] = configuration();
        let c = coordinates();
        let g = gap_of(&c);
        // the nodal normals as the rows take them (`nodal_normals_at` on the three facets)
        let pts = configuration();
        let facets: [&[usize]; 3] = [&[1, 2], &[2, 3], &[3, 4]];
        let normals: std::collections::HashMap<usize, synovia_mesh::math::Vector<2>> =
            synovia_mesh::mesh::nodal_normals_at(&pts, facets.into_iter()).into_iter().collect();
        let (xi, xm, n) =
            crate::knee2d::SmoothNodeToSegment::project(&s, (&a, &b), (&normals[&2], &normals[&3]))
                .expect("projects");
        let want = (s - xm).dot(&n);
        assert!(g.gap > 0.0 && g.xi > 0.05 && g.xi < 0.95, "{g:?}");
        assert!((g.gap - want).abs() <= 1e-14 * want.abs().max(1.0), "{} vs {want}", g.gap);
        assert!((g.xi - xi).abs() <= 1e-14);
        assert!((g.normal[0] - n[0]).abs() <= 1e-14 && (g.normal[1] - n[1]).abs() <= 1e-14);
    }

    #[test]
    fn gradient_and_hessian_equal_finite_differences() {
        let c = coordinates();
        let g = gap_of(&c);
        let h = 1e-5;
        let (mut err_g, mut err_h): (Real, Real) = (0.0, 0.0);
        let scale_g = g.gradient.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let scale_h = g.hessian.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
        for i in 0..N {
            let (mut cp, mut cm) = (c, c);
            cp[i] += h;
            cm[i] -= h;
            let (gp, gm) = (gap_of(&cp), gap_of(&cm));
            err_g = err_g.max(((gp.gap - gm.gap) / (2.0 * h) - g.gradient[i]).abs() / scale_g);
            for j in 0..N {
                let fd = (gp.gradient[j] - gm.gradient[j]) / (2.0 * h);
                err_h = err_h.max((fd - g.hessian[i][j]).abs() / scale_h);
            }
        }
        println!("gap {:.6}, ξ {:.4}: gradient {err_g:.1e}, Hessian {err_h:.1e} (relative)", g.gap, g.xi);
        assert!(err_g < 1e-6, "gradient vs finite differences: {err_g:e}");
        assert!(err_h < 1e-6, "Hessian vs finite differences: {err_h:e}");
        // the Hessian is symmetric and couples the slave node with every master node
        for i in 0..N {
            for j in 0..N {
                assert!((g.hessian[i][j] - g.hessian[j][i]).abs() <= 1e-12 * scale_h);
            }
        }
        for k in 1..5 {
            let coupling = (0..2).flat_map(|i| (0..2).map(move |j| (i, j)));
            assert!(
                coupling.map(|(i, j)| g.hessian[i][2 * k + j].abs()).fold(0.0, Real::max) > 1e-6 * scale_h
            );
        }
    }

    #[test]
    fn gradient_is_the_rows_operator_plus_the_tilt_term() {
        // ∂g = n · (δx_s − (1 − ξ) δx_a − ξ δx_b) − (e · n) δξ: with δξ from a finite
        // difference, the identity holds to the difference's accuracy
        let c = coordinates();
        let g = gap_of(&c);
        let e = [c[6] - c[4], c[7] - c[5]];
        let en = e[0] * g.normal[0] + e[1] * g.normal[1];
        let h = 1e-6;
        println!("e · n = {en:e}");
        assert!(en.abs() > 1e-4, "the tilt term is tested");
        for i in 0..N {
            let (mut cp, mut cm) = (c, c);
            cp[i] += h;
            cm[i] -= h;
            let dxi = (gap_of(&cp).xi - gap_of(&cm).xi) / (2.0 * h);
            let (node, comp) = (i / 2, i % 2);
            let weight = match node {
                0 => 1.0,
                2 => -(1.0 - g.xi),
                3 => -g.xi,
                _ => 0.0,
            };
            let want = weight * g.normal[comp] - en * dxi;
            assert!((g.gradient[i] - want).abs() < 1e-8, "coordinate {i}: {} vs {want}", g.gradient[i]);
        }
    }
}
