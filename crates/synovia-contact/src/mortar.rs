//! Dual (biorthogonal) mortar coupling of non-matching contact surfaces (docs/model.md §5, beyond the
//! report's node-to-node case; Wohlmuth 2000, Hüeber–Wohlmuth 2005; the 3D segmentation of
//! Puso–Laursen 2004 and Popp–Gee–Wall 2009/2010).
//!
//! # The mortar matrices
//!
//! Part `k` is the *slave* side `Γ_s` (it carries the multipliers), part `l` the *master* side
//! `Γ_m`. With the P1 slave basis `φ_j`, the P1 master basis `φ_k` and the dual basis `ψ_j` of
//! the slave surface (biorthogonal: `∫_{Γ_s} ψ_j φ_i ds = δ_ij ∫_{Γ_s} φ_j ds`),
//!
//! ```text
//! D_jj = ∫ ψ_j φ_j ds           (diagonal: D_ji = 0 for i ≠ j by biorthogonality)
//! M_jk = ∫ ψ_j (φ_k ∘ π) ds      (π: the projection of the slave surface onto the master)
//! ```
//!
//! with, on a slave segment `ξ ∈ [0, 1]`, `ψ_1 = 2φ_1 − φ_2 = 2 − 3ξ`, `ψ_2 = 2φ_2 − φ_1`, and on
//! a slave triangle `ψ_j = 3φ_j − Σ_{i≠j} φ_i = 4φ_j − 1` (affine P1 elements, so the dual
//! basis is the same on every element).
//!
//! **Segmentation** (integration cells on which both `ψ_j` and `φ_k ∘ π` are polynomials):
//! every slave facet is its own auxiliary line / plane (a P1 facet is flat; Popp's auxiliary
//! plane through the facet centre with the facet normal is the facet plane). The master facets
//! that face it are projected onto that plane along the slave facet normal `n_s`, so `π` is
//! affine on each cell:
//!
//! * 2D: the projected master segment is an interval of the slave parameter `ξ`; its
//!   intersection with `[0, 1]` is the cell;
//! * 3D: the projected master triangle is clipped against the slave triangle
//!   (Sutherland–Hodgman; both are convex triangles, which is small enough to write here), the
//!   clip polygon (convex) is split into a fan of triangles.
//!
//! The integrands `ψ_j φ_k` are quadratic on each cell, so the 2-point Gauss rule (2D) and the
//! symmetric 3-point rule of degree 2 on each fan triangle (3D) integrate them exactly: for a
//! flat interface `D` and `M` are exact to round-off, which is what makes the contact patch
//! test exact.
//!
//! # The constraint rows
//!
//! The dual basis makes `D` diagonal, so the mortar multiplier condenses node by node and each
//! slave node `j` gives one constraint row of the per-contact-node form of docs/model.md §5
//! (`(B_hn U)_r ≤ d_r` with the node weight `κ_r`):
//!
//! ```text
//! D_jj n_j · u_j − Σ_k M_jk n_j · u_k ≤ g̃_j,    g̃_j = ∫ ψ_j n_j · (x_m ∘ π − x_s) ds
//! ⇔  n_j · (u_j − Σ_k w_jk u_k) ≤ d_j,   w_jk = M_jk / D_jj,  d_j = g̃_j / D_jj,  κ_j = D_jj
//! ```
//!
//! `n_j` is the outward nodal normal of the slave surface (as for a conforming pair). The rows
//! enter `B_hn`, `κ` and `d` of docs/model.md §5 unchanged, so the PDAS / semismooth Newton, AU-PDAS and
//! Uzawa–MPRGP systems of docs/model.md §6 keep their form. The nodal
//! forces `B_hnᵀ diag(κ) Λ_n` are then `D_jj Λ_j n_j` on slave node `j` and
//! `−Σ_j M_jk Λ_j n_j` on master node `k`: a uniform pressure is passed exactly. Friction rows
//! (docs/model.md §5, `B_Ht`) use the same weights in the slave tangent basis:
//! `g_{c,j} D_jj T_jᵀ (u_j − Σ_k w_jk u_k)`.
//!
//! # Boundary of the slave surface
//!
//! `D_jj` is integrated over the same cells as `M`, i.e. `D_jj = Σ_k M_jk = ∫_{Γ_s ∩ π⁻¹(Γ_m)}
//! ψ_j ds`, so `Σ_k w_jk = 1` holds for every row (a rigid translation never opens or closes a
//! gap), and for a node whose support is fully covered by master facets `D_jj = ∫ φ_j ds`, the
//! lumped weight. Slave nodes whose support is covered only in part have a smaller (possibly
//! negative, since `ψ_j` changes sign) `D_jj`; nodes with `D_jj < MIN_COVERAGE · ∫ φ_j ds`
//! (one quarter) — in particular slave nodes without any master overlap — are **left out of the
//! pair** (like node-to-segment's nodes beyond the master rim; they can enter at a later pose).
//! No crosspoint modification of the dual basis is made: the constraints of the remaining
//! nodes near the rim act with the dual functions of the full slave elements.

use nalgebra::{Vector2, Vector3};
use rstar::{PointDistance, RTree, RTreeObject, AABB};
use synovia_mesh::math::{Point, Real};

/// Nodes with `D_jj` below this fraction of their lumped weight `∫ φ_j ds` are left out.
pub const MIN_COVERAGE: Real = 0.25;

/// One condensed mortar row: slave node `j` with `D_jj` and the master weights
/// `w_jk = M_jk / D_jj` (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct MortarRow {
    /// Slave node `j` (mesh index of the slave body).
    pub slave: usize,
    /// `D_jj = ∫ ψ_j ds` over the covered part of its support.
    pub d: Real,
    /// The lumped weight `∫ φ_j ds` over all slave facets of the node.
    pub lumped: Real,
    /// `(master node k, w_jk = M_jk / D_jj)`, `Σ_k w_jk = 1`; weights may be negative.
    pub master: Vec<(usize, Real)>,
}

/// A master facet in the R*-tree (bounding box only).
#[derive(Debug, Clone)]
struct Boxed {
    facet: usize,
    envelope: AABB<[Real; 3]>,
}

impl RTreeObject for Boxed {
    type Envelope = AABB<[Real; 3]>;
    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

impl PointDistance for Boxed {
    /// The squared distance to the bounding box (a lower bound of the distance to the facet).
    fn distance_2(&self, point: &[Real; 3]) -> Real {
        self.envelope.distance_2(point)
    }
}

fn embed<const D: usize>(x: &Point<D>) -> Vector3<Real> {
    let mut v = Vector3::zeros();
    for k in 0..D.min(3) {
        v[k] = x[k];
    }
    v
}

fn envelope(points: &[Vector3<Real>], pad: Real) -> AABB<[Real; 3]> {
    let mut lo = [Real::INFINITY; 3];
    let mut hi = [Real::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] - pad);
            hi[k] = hi[k].max(p[k] + pad);
        }
    }
    AABB::from_corners(lo, hi)
}

/// Outward area normal of an embedded facet (2 or 3 corners): in 2D `(t_y, −t_x)`, in 3D
/// `½ (b − a) × (c − a)` (the orientation convention of `synovia_mesh::mesh`).
fn area_normal3(c: &[Vector3<Real>]) -> Vector3<Real> {
    if c.len() == 2 {
        let t = c[1] - c[0];
        Vector3::new(t[1], -t[0], 0.0)
    } else {
        (c[1] - c[0]).cross(&(c[2] - c[0])) * 0.5
    }
}

/// Accumulated `M_jk` (and `D_jj = Σ_k M_jk`) of one slave node.
#[derive(Debug, Default, Clone)]
struct Acc {
    lumped: Real,
    d: Real,
    m: Vec<(usize, Real)>,
}

impl Acc {
    fn add(&mut self, k: usize, v: Real) {
        self.d += v;
        match self.m.iter_mut().find(|e| e.0 == k) {
            Some(e) => e.1 += v,
            None => self.m.push((k, v)),
        }
    }
}

/// The condensed dual-mortar rows of a slave surface (`slave_facets`, node indices into
/// `slave_pos`) against a master surface (`master_facets` into `master_pos`), facets
/// outward-oriented (segments in 2D, triangles in 3D). Master facets are coupled to a slave
/// facet when they face it (`n_m · n_s < 0`) and their projection overlaps it; with
/// `search_distance = Some(s)` only cells whose smallest gap along `n_s` is at most `s`
/// count. Rows are sorted by slave node; nodes with too little coverage are left out (see the
/// [module docs](self)).
pub fn mortar_rows<const D: usize>(
    slave_pos: &[Point<D>],
    slave_facets: &[Vec<usize>],
    master_pos: &[Point<D>],
    master_facets: &[Vec<usize>],
    search_distance: Option<Real>,
) -> Vec<MortarRow> {
    if D != 2 && D != 3 {
        return Vec::new();
    }
    let corners =
        |pos: &[Point<D>], f: &[usize]| -> Vec<Vector3<Real>> { f.iter().map(|&i| embed(&pos[i])).collect() };
    let master: Vec<Vec<Vector3<Real>>> = master_facets.iter().map(|f| corners(master_pos, f)).collect();
    let h_master = master
        .iter()
        .map(|c| {
            let mut h: Real = 0.0;
            for a in 0..c.len() {
                for b in 0..a {
                    h = h.max((c[a] - c[b]).norm());
                }
            }
            h
        })
        .fold(0.0, Real::max);
    let tree = RTree::bulk_load(
        master.iter().enumerate().map(|(facet, c)| Boxed { facet, envelope: envelope(c, 0.0) }).collect(),
    );
    let mut acc: std::collections::BTreeMap<usize, Acc> = std::collections::BTreeMap::new();
    for sf in slave_facets {
        let sc = corners(slave_pos, sf);
        let an = area_normal3(&sc);
        let area = an.norm();
        if !(area.is_finite() && area > 0.0) {
            continue;
        }
        let ns = an / area;
        for &j in sf.iter() {
            acc.entry(j).or_default().lumped += area / D as Real;
        }
        // candidate master facets: bounding boxes near the slave facet
        let pad = match search_distance {
            Some(s) => s + h_master,
            None => {
                let centre = sc.iter().fold(Vector3::zeros(), |a, p| a + p) / sc.len() as Real;
                let q = [centre[0], centre[1], centre[2]];
                let r0 = tree.nearest_neighbor(&q).map_or(0.0, |b| b.envelope.distance_2(&q).sqrt());
                r0 + 2.0 * h_master + area.powf(1.0 / (D as Real - 1.0))
            }
        };
        let query = envelope(&sc, pad);
        for b in tree.locate_in_envelope_intersecting(&query) {
            let mc = &master[b.facet];
            let nm = area_normal3(mc);
            if nm.dot(&ns) >= 0.0 {
                continue;
            }
            let cells = if D == 2 { segment_cells(&sc, mc, &ns) } else { triangle_cells(&sc, mc, &ns) };
            let Some(cells) = cells else { continue };
            if let Some(s) = search_distance {
                if cells.min_gap > s {
                    continue;
                }
            }
            for (w, phi_s, phi_m) in cells.points {
                // dual basis of the slave facet: ψ_a = D φ_a − Σ_{b≠a} φ_b (2D: 2φ_a − φ_b,
                // 3D: 4φ_a − 1)
                let sum: Real = phi_s.iter().take(D).sum();
                for (a, &j) in sf.iter().enumerate() {
                    let psi = D as Real * phi_s[a] - (sum - phi_s[a]);
                    let e = acc.entry(j).or_default();
                    for (c, &k) in master_facets[b.facet].iter().enumerate() {
                        e.add(k, w * psi * phi_m[c]);
                    }
                }
            }
        }
    }
    acc.into_iter()
        .filter(|(_, a)| a.lumped > 0.0 && a.d >= MIN_COVERAGE * a.lumped)
        .map(|(slave, a)| {
            let tiny = 1e-14 * a.d;
            let master = a.m.iter().filter(|e| e.1.abs() > tiny).map(|&(k, v)| (k, v / a.d)).collect();
            MortarRow { slave, d: a.d, lumped: a.lumped, master }
        })
        .collect()
}

/// Integration points of the cells of one slave facet against one master facet:
/// `(weight × measure, slave barycentrics, master barycentrics)`, and the smallest gap along
/// the slave normal at the cell corners.
struct Cells {
    points: Vec<(Real, [Real; 3], [Real; 3])>,
    min_gap: Real,
}

/// 2D: the overlap of the master segment projected onto the slave segment's line along `ns`.
fn segment_cells(s: &[Vector3<Real>], m: &[Vector3<Real>], ns: &Vector3<Real>) -> Option<Cells> {
    let e = s[1] - s[0];
    let l2 = e.norm_squared();
    let xi = |x: &Vector3<Real>| (x - s[0]).dot(&e) / l2;
    let (xa, xb) = (xi(&m[0]), xi(&m[1]));
    if (xb - xa).abs() <= 1e-12 {
        return None;
    }
    let lo = xa.min(xb).max(0.0);
    let hi = xa.max(xb).min(1.0);
    if hi - lo <= 1e-12 {
        return None;
    }
    let len = l2.sqrt();
    // gap along ns between the slave point at ξ and the master line
    let gap = |x: Real| {
        let eta = (x - xa) / (xb - xa);
        let xm = m[0] * (1.0 - eta) + m[1] * eta;
        let xs = s[0] + e * x;
        (xm - xs).dot(ns)
    };
    let g = 0.5 / 3.0_f64.sqrt();
    let points = [0.5 - g, 0.5 + g]
        .iter()
        .map(|&t| {
            let x = lo + (hi - lo) * t;
            let eta = (x - xa) / (xb - xa);
            (0.5 * (hi - lo) * len, [1.0 - x, x, 0.0], [1.0 - eta, eta, 0.0])
        })
        .collect();
    Some(Cells { points, min_gap: gap(lo).min(gap(hi)) })
}

/// Barycentric coordinates of `p` in the 2D triangle `t`.
fn bary2(t: &[Vector2<Real>; 3], p: &Vector2<Real>) -> [Real; 3] {
    let v0 = t[1] - t[0];
    let v1 = t[2] - t[0];
    let v2 = p - t[0];
    let den = v0.perp(&v1);
    let b = v2.perp(&v1) / den;
    let c = v0.perp(&v2) / den;
    [1.0 - b - c, b, c]
}

/// Sutherland–Hodgman: `poly` (convex, counter-clockwise) clipped by the counter-clockwise
/// convex polygon `clip`.
fn clip_convex(poly: Vec<Vector2<Real>>, clip: &[Vector2<Real>]) -> Vec<Vector2<Real>> {
    let mut out = poly;
    for i in 0..clip.len() {
        if out.is_empty() {
            break;
        }
        let a = clip[i];
        let b = clip[(i + 1) % clip.len()];
        let side = |p: &Vector2<Real>| (b - a).perp(&(p - a));
        let input = std::mem::take(&mut out);
        for k in 0..input.len() {
            let p = input[k];
            let q = input[(k + 1) % input.len()];
            let (sp, sq) = (side(&p), side(&q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                let t = sp / (sp - sq);
                out.push(p + (q - p) * t);
            }
        }
    }
    out
}

/// 3D: the master triangle projected onto the slave triangle's plane along `ns`, clipped
/// against the slave triangle and split into a fan of triangles.
fn triangle_cells(s: &[Vector3<Real>], m: &[Vector3<Real>], ns: &Vector3<Real>) -> Option<Cells> {
    let e1 = (s[1] - s[0]).normalize();
    let e2 = ns.cross(&e1);
    let local = |x: &Vector3<Real>| Vector2::new((x - s[0]).dot(&e1), (x - s[0]).dot(&e2));
    let st = [local(&s[0]), local(&s[1]), local(&s[2])];
    let mt = [local(&m[0]), local(&m[1]), local(&m[2])];
    let s_area = 0.5 * (st[1] - st[0]).perp(&(st[2] - st[0]));
    let m_area = 0.5 * (mt[1] - mt[0]).perp(&(mt[2] - mt[0]));
    if s_area <= 0.0 || m_area.abs() <= 1e-12 * s_area {
        return None;
    }
    let mut poly: Vec<Vector2<Real>> = mt.to_vec();
    if m_area < 0.0 {
        poly.reverse();
    }
    let poly = clip_convex(poly, &st);
    if poly.len() < 3 {
        return None;
    }
    let centre = poly.iter().fold(Vector2::zeros(), |a, p| a + p) / poly.len() as Real;
    // the master plane over the slave plane: x_m(p) = Σ λ_c(p) m_c, gap = (x_m − x_s) · ns
    let gap = |p: &Vector2<Real>| {
        let l = bary2(&mt, p);
        let xm = m[0] * l[0] + m[1] * l[1] + m[2] * l[2];
        (xm - s[0]).dot(ns)
    };
    let min_gap = poly.iter().map(gap).fold(Real::INFINITY, Real::min);
    let mut points = Vec::with_capacity(3 * poly.len());
    let mut covered = 0.0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let area = 0.5 * (a - centre).perp(&(b - centre));
        if area <= 1e-14 * s_area {
            continue;
        }
        covered += area;
        // symmetric 3-point rule, exact for quadratics
        for (l0, l1, l2) in [
            (2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0),
            (1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0),
            (1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0),
        ] {
            let p = centre * l0 + a * l1 + b * l2;
            points.push((area / 3.0, bary2(&st, &p), bary2(&mt, &p)));
        }
    }
    if covered <= 1e-12 * s_area {
        return None;
    }
    Some(Cells { points, min_gap })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matching_segments_give_identity_weights() {
        let s: Vec<Point<2>> = (0..3).map(|i| Point::<2>::new(i as Real, 0.0)).collect();
        // the same segments as slave (outward normal +y: a body below) and master (outward
        // normal −y: a body above)
        let sf = vec![vec![1, 0], vec![2, 1]];
        let mf = vec![vec![0, 1], vec![1, 2]];
        let rows = mortar_rows(&s, &sf, &s, &mf, None);
        assert_eq!(rows.len(), 3);
        for r in &rows {
            assert!((r.d - r.lumped).abs() < 1e-14);
            for &(k, w) in &r.master {
                let expect = if k == r.slave { 1.0 } else { 0.0 };
                assert!((w - expect).abs() < 1e-12, "{r:?}");
            }
        }
    }

    #[test]
    fn clipped_triangles_cover_the_slave_triangle() {
        // slave triangle with normal −z (outward of a body above), master: two triangles of the
        // unit square with normal +z, shifted
        let s = vec![
            Point::<3>::new(0.1, 0.1, 0.0),
            Point::<3>::new(0.1, 0.8, 0.0),
            Point::<3>::new(0.7, 0.2, 0.0),
        ];
        let m = vec![
            Point::<3>::new(0.0, 0.0, -0.01),
            Point::<3>::new(1.0, 0.0, -0.01),
            Point::<3>::new(1.0, 1.0, -0.01),
            Point::<3>::new(0.0, 1.0, -0.01),
        ];
        let rows = mortar_rows(&s, &[vec![0, 1, 2]], &m, &[vec![0, 1, 2], vec![0, 2, 3]], None);
        assert_eq!(rows.len(), 3);
        for r in &rows {
            assert!((r.d - r.lumped).abs() < 1e-14 * r.lumped, "{r:?}");
            let sum: Real = r.master.iter().map(|e| e.1).sum();
            assert!((sum - 1.0).abs() < 1e-13);
            // Σ_k w_jk x_k = x_j for an affine map (flat, parallel surfaces): the first moment
            let x: Real = r.master.iter().map(|&(k, w)| w * m[k][0]).sum();
            let y: Real = r.master.iter().map(|&(k, w)| w * m[k][1]).sum();
            assert!((x - s[r.slave][0]).abs() < 1e-13 && (y - s[r.slave][1]).abs() < 1e-13, "{r:?}");
        }
    }
}
