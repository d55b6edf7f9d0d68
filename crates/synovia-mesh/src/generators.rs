//! Mesh generators for synovia's verification problems and joint models.
//!
//! Every generator builds a structured grid of quadrilaterals (2D) or hexahedra (3D) on a
//! parameter box, splits each quad into 2 triangles and each hex into the 6 tetrahedra of the
//! Kuhn (Freudenthal) subdivision, and maps the nodes by a geometric map. The Kuhn subdivision is
//! conforming across neighbouring hexes. Boxes ([`rectangle`], [`box_mesh`]) and the layered
//! arcs use the same diagonal pattern in every cell; the mapped squares and cubes ([`disc`],
//! [`half_disc`], [`ball`], [`hemisphere`], [`layered_cap_3d`]) mirror it about the coordinate
//! planes of the parameter box so that every diagonal points away from its center: the cells at
//! the corners of the square, where the map flattens the boundary, are then cut through the
//! corner node and no sliver appears.
//!
//! All returned cells are positively oriented (the generators check that the geometric map does
//! not fold a cell) and every generator creates named boundary parts of kind
//! [`BoundaryKind::TractionFree`]; re-tag them (remove and re-add with another kind, or use the
//! names in the problem set-up) as the problem needs. Invalid parameters (non-positive sizes,
//! zero divisions, NaN, inconsistent lengths) give [`MeshError::InvalidParameter`].
//!
//! Any generated mesh can be refined locally with [`crate::refine`]; [`half_disc_refined`] and
//! [`hemisphere_refined`] are the typical Hertz set-ups.

use crate::error::MeshError;
use crate::math::{Point, Real};
use crate::mesh::{BoundaryKind, Mesh};
use crate::refine::{refine_toward_within, SphereProjection};

/// A distribution of the nodes of one axis of a structured grid (see [`nodes_1d`]).
///
/// Sizes `h_k = x_{k+1} − x_k`, `k = 0 … n−1`, are counted from the low end `a` of the interval.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum Grading {
    /// Equal cell sizes.
    #[default]
    Uniform,
    /// Geometric sizes from the low end: `h_{k+1} = ratio · h_k` (`ratio > 0`). `ratio < 1` makes
    /// the cells finer toward the high end, `ratio > 1` finer toward the low end, `ratio = 1` is
    /// uniform.
    Geometric {
        /// Size ratio of successive cells (`> 0`).
        ratio: Real,
    },
    /// Finest at the low end, growing away from it: `h_{k+1} = ratio · h_k` with `ratio ≥ 1`.
    TowardLow {
        /// Growth factor of successive cells away from the low end (`≥ 1`).
        ratio: Real,
    },
    /// Finest at the high end, growing away from it: `h_k = ratio · h_{k+1}` with `ratio ≥ 1`.
    TowardHigh {
        /// Growth factor of successive cells away from the high end (`≥ 1`).
        ratio: Real,
    },
    /// Local refinement of a tensor grid: cells in the window `|x − center| ≤ width / 2` are
    /// `ratio` times smaller than cells far from it. In between, the cell size grows linearly
    /// (each cell about 20 % larger than its neighbour on the window side), so the transition
    /// zone is as long as the sizes need; if `n` is too small for it to fit in `[a, b]` the
    /// refinement is correspondingly weaker. A window that misses `[a, b]` still refines the end
    /// of `[a, b]` that is nearer to it, through the transition zone.
    Refined {
        /// Center of the fine window.
        center: Real,
        /// Width of the fine window (`> 0`).
        width: Real,
        /// Cell size ratio far / window (`≥ 1`; `1` is uniform).
        ratio: Real,
    },
}

fn invalid(msg: impl Into<String>) -> MeshError {
    MeshError::InvalidParameter(msg.into())
}

fn check_ratio(name: &str, ratio: Real, min_inclusive: Option<Real>) -> Result<(), MeshError> {
    let ok = ratio.is_finite()
        && match min_inclusive {
            Some(m) => ratio >= m,
            None => ratio > 0.0,
        };
    if ok {
        Ok(())
    } else {
        Err(invalid(format!(
            "grading {name}: ratio must be finite and {}, got {ratio}",
            match min_inclusive {
                Some(m) => format!(">= {m}"),
                None => "> 0".to_string(),
            }
        )))
    }
}

/// The `n + 1` nodes `a = x_0 < x_1 < … < x_n = b` of `[a, b]` distributed by `grading`.
///
/// The end points are exact. Fails with [`MeshError::InvalidParameter`] unless `a < b` are
/// finite, `n ≥ 1` and the grading's parameters are valid, or if the grading is so extreme that
/// two nodes coincide in floating point.
pub fn nodes_1d(a: Real, b: Real, n: usize, grading: Grading) -> Result<Vec<Real>, MeshError> {
    if !(a.is_finite() && b.is_finite() && a < b) {
        return Err(invalid(format!("nodes_1d: need finite a < b, got [{a}, {b}]")));
    }
    if n == 0 {
        return Err(invalid("nodes_1d: the number of cells n must be at least 1"));
    }
    let mut x = match grading {
        Grading::Uniform => (0..=n).map(|i| a + (b - a) * (i as Real / n as Real)).collect(),
        Grading::Geometric { ratio } => {
            check_ratio("Geometric", ratio, None)?;
            geometric(a, b, n, ratio)
        }
        Grading::TowardLow { ratio } => {
            check_ratio("TowardLow", ratio, Some(1.0))?;
            geometric(a, b, n, ratio)
        }
        Grading::TowardHigh { ratio } => {
            check_ratio("TowardHigh", ratio, Some(1.0))?;
            geometric(a, b, n, 1.0 / ratio)
        }
        Grading::Refined { center, width, ratio } => {
            if !center.is_finite() {
                return Err(invalid(format!("grading Refined: center must be finite, got {center}")));
            }
            if !(width.is_finite() && width > 0.0) {
                return Err(invalid(format!(
                    "grading Refined: width must be positive and finite, got {width}"
                )));
            }
            check_ratio("Refined", ratio, Some(1.0))?;
            refined(a, b, n, center, width, ratio)
        }
    };
    x[0] = a;
    x[n] = b;
    if let Some(k) = x
        .windows(2)
        .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) || !w[1].is_finite())
    {
        return Err(invalid(format!(
            "nodes_1d: grading {grading:?} with n = {n} on [{a}, {b}] makes nodes {k} and {} coincide",
            k + 1
        )));
    }
    Ok(x)
}

/// Geometric sizes `h_k ∝ ratio^k`, scaled so that the largest is 1 (no overflow).
fn geometric(a: Real, b: Real, n: usize, ratio: Real) -> Vec<Real> {
    let sizes: Vec<Real> = (0..n)
        .map(|k| if ratio >= 1.0 { (1.0 / ratio).powf((n - 1 - k) as Real) } else { ratio.powf(k as Real) })
        .collect();
    let total: Real = sizes.iter().sum();
    let mut x = Vec::with_capacity(n + 1);
    let mut s = 0.0;
    x.push(a);
    for h in &sizes {
        s += h;
        x.push(a + (b - a) * (s / total));
    }
    x
}

/// Neighbouring cells of the transition zone of [`Grading::Refined`] differ in size by about
/// this fraction.
const REFINED_GROWTH: Real = 0.2;

/// Nodes of [`Grading::Refined`]: equidistribution of the density `1 / h(x)`, with the relative
/// size `h = 1 / ratio` in the window, `h = 1` far from it, and `h` linear in between with a
/// slope chosen so that neighbouring cells grow by [`REFINED_GROWTH`].
fn refined(a: Real, b: Real, n: usize, center: Real, width: Real, ratio: Real) -> Vec<Real> {
    let uniform = || (0..=n).map(|i| a + (b - a) * (i as Real / n as Real)).collect();
    if ratio == 1.0 {
        return uniform();
    }
    let hf = 1.0 / ratio;
    let hw = 0.5 * width;
    // Relative size with transition slope `s` (transition length (1 − hf) / s).
    let size = |x: Real, s: Real| -> Real {
        let d = (x - center).abs() - hw;
        if d <= 0.0 {
            hf
        } else {
            (hf + s * d).min(1.0)
        }
    };
    let breaks = |s: Real| -> Vec<Real> {
        let l = (1.0 - hf) / s;
        let mut br = vec![a, b];
        for p in [center - hw - l, center - hw, center + hw, center + hw + l] {
            if p > a && p < b {
                br.push(p);
            }
        }
        br.sort_by(|p, q| p.total_cmp(q));
        br
    };
    // ∫ dx / h over a piece where h is linear, from its end values.
    let piece_integral = |len: Real, hs: Real, he: Real| -> Real {
        let u = (he - hs) / hs;
        if u.abs() < 1e-8 {
            len / hs * (1.0 - 0.5 * u)
        } else {
            len * u.ln_1p() / (he - hs)
        }
    };
    let cumulative = |br: &[Real], s: Real| -> Vec<Real> {
        let mut cum = vec![0.0; br.len()];
        for k in 1..br.len() {
            let (p, q) = (br[k - 1], br[k]);
            cum[k] = cum[k - 1] + piece_integral(q - p, size(p, s), size(q, s));
        }
        cum
    };
    // Fixed point s = growth · n / I(s): the coarse cell size I / n times s is the growth.
    let mut s = REFINED_GROWTH * n as Real / ((b - a) * ratio);
    for _ in 0..200 {
        let br = breaks(s);
        let total = cumulative(&br, s)[br.len() - 1];
        let next = REFINED_GROWTH * n as Real / total;
        let done = (next - s).abs() <= 1e-13 * s;
        s = next;
        if done {
            break;
        }
    }
    if !(s.is_finite() && s > 0.0) {
        return uniform();
    }
    let br = breaks(s);
    let cum = cumulative(&br, s);
    let total = cum[br.len() - 1];
    let mut x = Vec::with_capacity(n + 1);
    let mut piece = 1;
    for i in 0..=n {
        let t = total * (i as Real / n as Real);
        while piece + 1 < br.len() && cum[piece] < t {
            piece += 1;
        }
        let (p, q) = (br[piece - 1], br[piece]);
        let (hs, he) = (size(p, s), size(q, s));
        let k = (he - hs) / (q - p);
        let tau = (t - cum[piece - 1]).max(0.0);
        // Solve ∫_0^y dt / (hs + k t) = tau.
        let y = if (k * tau).abs() < 1e-12 { hs * tau } else { hs * (k * tau).exp_m1() / k };
        x.push((p + y).min(q));
    }
    x
}

/// Node coordinates of `[-1, 1]` in `2n` equal cells, exactly antisymmetric, `0` a node.
fn symmetric_coords(n: usize) -> Vec<Real> {
    (0..=2 * n).map(|i| (i as Real - n as Real) / n as Real).collect()
}

/// Node coordinates of `[-1, 0]` in `n` equal cells, `-1` and `0` exact.
fn lower_half_coords(n: usize) -> Vec<Real> {
    (0..=n).map(|i| (i as Real - n as Real) / n as Real).collect()
}

/// All permutations of `0..d` with their signs.
fn permutations(d: usize) -> Vec<(Vec<usize>, i32)> {
    fn rec(prefix: &mut Vec<usize>, d: usize, out: &mut Vec<(Vec<usize>, i32)>) {
        if prefix.len() == d {
            let mut inversions = 0;
            for i in 0..d {
                for j in (i + 1)..d {
                    if prefix[i] > prefix[j] {
                        inversions += 1;
                    }
                }
            }
            out.push((prefix.clone(), if inversions % 2 == 0 { 1 } else { -1 }));
            return;
        }
        for k in 0..d {
            if !prefix.contains(&k) {
                prefix.push(k);
                rec(prefix, d, out);
                prefix.pop();
            }
        }
    }
    let mut out = Vec::new();
    rec(&mut Vec::new(), d, &mut out);
    out
}

/// A side of the parameter box: `(axis, high)`.
type Side = (usize, bool);

/// Builds the Kuhn-subdivided structured mesh on the tensor grid `coords`, maps its nodes by
/// `map` and creates the named parts from sides of the parameter box.
///
/// `mirror[ax]`: along axis `ax` the Kuhn diagonal of a cell starts at its end closer to the
/// parameter `0` (mirror symmetric pattern) instead of at its low end.
fn structured<const D: usize>(
    what: &str,
    coords: &[Vec<Real>; D],
    mirror: [bool; D],
    map: impl Fn(&Point<D>) -> Point<D>,
    parts: &[(&str, &[Side])],
) -> Result<Mesh<D>, MeshError> {
    let mut n = [0usize; D];
    let mut stride = [0usize; D];
    let mut n_nodes: usize = 1;
    let mut n_hex: usize = 1;
    for ax in 0..D {
        if coords[ax].len() < 2 {
            return Err(invalid(format!("{what}: axis {ax} needs at least one cell")));
        }
        n[ax] = coords[ax].len() - 1;
        stride[ax] = n_nodes;
        n_nodes = n_nodes.checked_mul(n[ax] + 1).ok_or_else(|| invalid(format!("{what}: too many nodes")))?;
        n_hex = n_hex.checked_mul(n[ax]).ok_or_else(|| invalid(format!("{what}: too many cells")))?;
    }
    let perms = permutations(D);
    n_hex.checked_mul(perms.len() * (D + 1)).ok_or_else(|| invalid(format!("{what}: too many cells")))?;

    let index = |m: &[usize; D]| -> usize { (0..D).map(|ax| m[ax] * stride[ax]).sum() };
    let unflatten = |mut i: usize, dims: &[usize; D]| -> [usize; D] {
        let mut m = [0usize; D];
        for ax in 0..D {
            m[ax] = i % dims[ax];
            i /= dims[ax];
        }
        m
    };

    let mut node_dims = [0usize; D];
    for ax in 0..D {
        node_dims[ax] = n[ax] + 1;
    }
    let mut nodes = Vec::with_capacity(n_nodes);
    for i in 0..n_nodes {
        let m = unflatten(i, &node_dims);
        let p = Point::<D>::from_fn(|ax, _| coords[ax][m[ax]]);
        nodes.push(map(&p));
    }

    let mut cells = Vec::with_capacity(n_hex * perms.len() * (D + 1));
    let mut side_facets: Vec<Vec<Vec<usize>>> = vec![Vec::new(); 2 * D];
    for h in 0..n_hex {
        let c = unflatten(h, &n);
        let mut high = [false; D];
        let mut anchor = c;
        let mut sign = 1;
        for ax in 0..D {
            high[ax] = mirror[ax] && coords[ax][c[ax]] + coords[ax][c[ax] + 1] < 0.0;
            if high[ax] {
                anchor[ax] += 1;
                sign = -sign;
            }
        }
        for (perm, psign) in &perms {
            let mut verts: Vec<[usize; D]> = Vec::with_capacity(D + 1);
            let mut v = anchor;
            verts.push(v);
            for &ax in perm {
                if high[ax] {
                    v[ax] -= 1;
                } else {
                    v[ax] += 1;
                }
                verts.push(v);
            }
            if sign * psign < 0 {
                verts.swap(D - 1, D);
            }
            for opp in 0..=D {
                for ax in 0..D {
                    for (hi, bound) in [(false, 0), (true, n[ax])] {
                        let on_side = (0..=D).filter(|&k| k != opp).all(|k| verts[k][ax] == bound);
                        if on_side {
                            let face = (0..=D).filter(|&k| k != opp).map(|k| index(&verts[k]));
                            side_facets[2 * ax + usize::from(hi)].push(face.collect());
                        }
                    }
                }
            }
            cells.extend(verts.iter().map(index));
        }
    }

    let n_cells = cells.len() / (D + 1);
    let (mut mesh, flipped) = Mesh::new_with_repair(nodes, cells)?;
    if flipped != 0 && flipped != n_cells {
        return Err(invalid(format!(
            "{what}: the geometric map folds the mesh ({flipped} of {n_cells} cells inverted)"
        )));
    }
    for (name, sides) in parts {
        let facets: Vec<Vec<usize>> = sides
            .iter()
            .flat_map(|&(ax, hi)| side_facets[2 * ax + usize::from(hi)].iter().cloned())
            .collect();
        mesh.add_boundary_part_from_facets(name, BoundaryKind::TractionFree, &facets)?;
    }
    Ok(mesh)
}

/// The square-to-disc (cube-to-ball) map `p ↦ p ‖p‖_∞ / ‖p‖_2` (`0 ↦ 0`): maps the boundary of
/// `[-1, 1]^D` onto the unit sphere, radially.
fn squircle<const D: usize>(p: &Point<D>) -> Point<D> {
    let inf = p.amax();
    let l2 = p.norm();
    if l2 > 0.0 {
        p * (inf / l2)
    } else {
        Point::<D>::zeros()
    }
}

fn check_center<const D: usize>(what: &str, center: &Point<D>) -> Result<(), MeshError> {
    if center.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(format!("{what}: center has a non-finite coordinate")))
    }
}

fn check_positive(what: &str, name: &str, value: Real) -> Result<(), MeshError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(format!("{what}: {name} must be positive and finite, got {value}")))
    }
}

fn check_count(what: &str, name: &str, value: usize) -> Result<(), MeshError> {
    if value >= 1 {
        Ok(())
    } else {
        Err(invalid(format!("{what}: {name} must be at least 1, got 0")))
    }
}

/// The rectangle `[x0, x1] × [y0, y1]` with `nx × ny` quads, each split into two triangles along
/// the same diagonal (from its `(x_i, y_j)` to its `(x_{i+1}, y_{j+1})` corner), with the node
/// distributions `gx`, `gy` of [`nodes_1d`].
///
/// Boundary parts (all [`BoundaryKind::TractionFree`]): `"left"` (`x = x0`), `"right"`
/// (`x = x1`), `"bottom"` (`y = y0`), `"top"` (`y = y1`).
#[allow(clippy::too_many_arguments)]
pub fn rectangle(
    x0: Real,
    x1: Real,
    y0: Real,
    y1: Real,
    nx: usize,
    ny: usize,
    gx: Grading,
    gy: Grading,
) -> Result<Mesh<2>, MeshError> {
    let coords = [nodes_1d(x0, x1, nx, gx)?, nodes_1d(y0, y1, ny, gy)?];
    structured(
        "rectangle",
        &coords,
        [false; 2],
        |p| *p,
        &[("left", &[(0, false)]), ("right", &[(0, true)]), ("bottom", &[(1, false)]), ("top", &[(1, true)])],
    )
}

/// The box `[lo, hi]` with `n[0] × n[1] × n[2]` hexahedra, each split into the 6 tetrahedra of
/// the Kuhn subdivision around its main diagonal (from its low corner to its high corner, the
/// same in every hex), with the node distributions `g` of [`nodes_1d`] per axis.
///
/// Boundary parts (all [`BoundaryKind::TractionFree`]): `"left"` / `"right"` (`x = lo[0]` /
/// `x = hi[0]`), `"front"` / `"back"` (`y = lo[1]` / `y = hi[1]`), `"bottom"` / `"top"`
/// (`z = lo[2]` / `z = hi[2]`).
pub fn box_mesh(lo: [Real; 3], hi: [Real; 3], n: [usize; 3], g: [Grading; 3]) -> Result<Mesh<3>, MeshError> {
    let coords = [
        nodes_1d(lo[0], hi[0], n[0], g[0])?,
        nodes_1d(lo[1], hi[1], n[1], g[1])?,
        nodes_1d(lo[2], hi[2], n[2], g[2])?,
    ];
    structured(
        "box_mesh",
        &coords,
        [false; 3],
        |p| *p,
        &[
            ("left", &[(0, false)]),
            ("right", &[(0, true)]),
            ("front", &[(1, false)]),
            ("back", &[(1, true)]),
            ("bottom", &[(2, false)]),
            ("top", &[(2, true)]),
        ],
    )
}

/// The disc `|x − center| ≤ radius`, as the mapped square: the square `[-1, 1]²` with `2n × 2n`
/// quads (mirror-symmetric diagonals) mapped by `p ↦ center + radius · p ‖p‖_∞ / ‖p‖_2`.
///
/// `n` is the number of cells along a radius; the center and the four points
/// `center ± radius e_x`, `center ± radius e_y` are nodes, and every boundary node lies on the
/// circle. Boundary part: `"boundary"` (the whole circle, [`BoundaryKind::TractionFree`]).
pub fn disc(center: Point<2>, radius: Real, n: usize) -> Result<Mesh<2>, MeshError> {
    check_center("disc", &center)?;
    check_positive("disc", "radius", radius)?;
    check_count("disc", "n", n)?;
    let coords = [symmetric_coords(n), symmetric_coords(n)];
    structured(
        "disc",
        &coords,
        [true; 2],
        |p| center + squircle(p) * radius,
        &[("boundary", &[(0, false), (0, true), (1, false), (1, true)])],
    )
}

/// The lower half disc `{|x − center| ≤ radius, y ≤ center_y}`: a cylinder cross-section resting
/// on a flat, touching it at its lowest point `(cx, cy − radius)`, which is a node.
///
/// Built as the mapped rectangle `[-1, 1] × [-1, 0]` with `2n × n` quads (mirror-symmetric
/// diagonals) under `p ↦ center + radius · p ‖p‖_∞ / ‖p‖_2`; `n` is the number of cells along a
/// radius. Boundary parts ([`BoundaryKind::TractionFree`]): `"arc"` (the lower semicircle, all its
/// nodes on the circle) and `"top"` (the flat cut `y = cy`, `cx − radius ≤ x ≤ cx + radius`).
pub fn half_disc(center: Point<2>, radius: Real, n: usize) -> Result<Mesh<2>, MeshError> {
    check_center("half_disc", &center)?;
    check_positive("half_disc", "radius", radius)?;
    check_count("half_disc", "n", n)?;
    let coords = [symmetric_coords(n), lower_half_coords(n)];
    structured(
        "half_disc",
        &coords,
        [true; 2],
        |p| center + squircle(p) * radius,
        &[("arc", &[(0, false), (0, true), (1, false)]), ("top", &[(1, true)])],
    )
}

/// The ball `|x − center| ≤ radius`, as the mapped cube: `[-1, 1]³` with `(2n)³` hexes, each cut
/// into 6 Kuhn tetrahedra (mirror-symmetric pattern), mapped by
/// `p ↦ center + radius · p ‖p‖_∞ / ‖p‖_2`.
///
/// `n` is the number of cells along a radius; the center and the six poles `center ± radius e_i`
/// are nodes, every boundary node lies on the sphere. Boundary part: `"boundary"` (the sphere,
/// [`BoundaryKind::TractionFree`]).
pub fn ball(center: Point<3>, radius: Real, n: usize) -> Result<Mesh<3>, MeshError> {
    check_center("ball", &center)?;
    check_positive("ball", "radius", radius)?;
    check_count("ball", "n", n)?;
    let coords = [symmetric_coords(n), symmetric_coords(n), symmetric_coords(n)];
    let all: [Side; 6] = [(0, false), (0, true), (1, false), (1, true), (2, false), (2, true)];
    structured("ball", &coords, [true; 3], |p| center + squircle(p) * radius, &[("boundary", &all)])
}

/// The lower hemisphere `{|x − center| ≤ radius, z ≤ center_z}`: a sphere resting on a flat,
/// touching it at its lowest point `(cx, cy, cz − radius)`, which is a node.
///
/// Built as the mapped box `[-1, 1]² × [-1, 0]` with `2n × 2n × n` hexes (6 Kuhn tetrahedra
/// each, mirror-symmetric pattern) under `p ↦ center + radius · p ‖p‖_∞ / ‖p‖_2`; `n` is the
/// number of cells along a radius. Boundary parts ([`BoundaryKind::TractionFree`]): `"cap"` (the
/// spherical surface, all its nodes on the sphere) and `"top"` (the flat disc `z = cz`).
pub fn hemisphere(center: Point<3>, radius: Real, n: usize) -> Result<Mesh<3>, MeshError> {
    check_center("hemisphere", &center)?;
    check_positive("hemisphere", "radius", radius)?;
    check_count("hemisphere", "n", n)?;
    let coords = [symmetric_coords(n), symmetric_coords(n), lower_half_coords(n)];
    let cap: [Side; 5] = [(0, false), (0, true), (1, false), (1, true), (2, false)];
    structured(
        "hemisphere",
        &coords,
        [true; 3],
        |p| center + squircle(p) * radius,
        &[("cap", &cap), ("top", &[(2, true)])],
    )
}

/// [`half_disc`] refined `levels` times toward the disc `|x − refine_center| ≤ refine_radius`
/// (typically the contact zone around the lowest point), with the new nodes of the arc projected
/// onto the circle ([`SphereProjection`]). Same parts as [`half_disc`]. In the refined zone the
/// cell size is about `radius / n / 2^(levels / 2)`.
pub fn half_disc_refined(
    center: Point<2>,
    radius: Real,
    n: usize,
    refine_center: Point<2>,
    refine_radius: Real,
    levels: usize,
) -> Result<Mesh<2>, MeshError> {
    half_disc_refined_within(center, radius, n, refine_center, refine_radius, levels, usize::MAX)
}

/// [`half_disc_refined`] that fails with [`MeshError::InvalidParameter`] once a level leaves
/// more than `max_cells` cells ([`refine_toward_within`](crate::refine::refine_toward_within)).
///
/// # Errors
/// As [`half_disc_refined`], and when the cell count exceeds `max_cells`.
pub fn half_disc_refined_within(
    center: Point<2>,
    radius: Real,
    n: usize,
    refine_center: Point<2>,
    refine_radius: Real,
    levels: usize,
    max_cells: usize,
) -> Result<Mesh<2>, MeshError> {
    check_center("half_disc_refined (refine_center)", &refine_center)?;
    check_positive("half_disc_refined", "refine_radius", refine_radius)?;
    let mesh = half_disc(center, radius, n)?;
    let proj = SphereProjection::new(center, radius)?;
    refine_toward_within(&mesh, |x| (x - refine_center).norm() <= refine_radius, levels, &proj, max_cells)
}

/// [`hemisphere`] refined `levels` times toward the ball `|x − refine_center| ≤ refine_radius`
/// (typically the contact zone around the lowest point), with the new nodes of the cap projected
/// onto the sphere ([`SphereProjection`]). Same parts as [`hemisphere`]. The cell size in the
/// refined zone halves about every three levels.
pub fn hemisphere_refined(
    center: Point<3>,
    radius: Real,
    n: usize,
    refine_center: Point<3>,
    refine_radius: Real,
    levels: usize,
) -> Result<Mesh<3>, MeshError> {
    hemisphere_refined_within(center, radius, n, refine_center, refine_radius, levels, usize::MAX)
}

/// [`hemisphere_refined`] that fails with [`MeshError::InvalidParameter`] once a level leaves
/// more than `max_cells` cells ([`refine_toward_within`](crate::refine::refine_toward_within)).
///
/// # Errors
/// As [`hemisphere_refined`], and when the cell count exceeds `max_cells`.
pub fn hemisphere_refined_within(
    center: Point<3>,
    radius: Real,
    n: usize,
    refine_center: Point<3>,
    refine_radius: Real,
    levels: usize,
    max_cells: usize,
) -> Result<Mesh<3>, MeshError> {
    check_center("hemisphere_refined (refine_center)", &refine_center)?;
    check_positive("hemisphere_refined", "refine_radius", refine_radius)?;
    let mesh = hemisphere(center, radius, n)?;
    let proj = SphereProjection::new(center, radius)?;
    refine_toward_within(&mesh, |x| (x - refine_center).norm() <= refine_radius, levels, &proj, max_cells)
}

fn check_layers(what: &str, radii: &[Real], n_radial: &[usize]) -> Result<Vec<Vec<Real>>, MeshError> {
    if radii.len() < 2 {
        return Err(invalid(format!("{what}: need at least two radii (one layer)")));
    }
    if n_radial.len() + 1 != radii.len() {
        return Err(invalid(format!(
            "{what}: {} radii make {} layers, but n_radial has {} entries",
            radii.len(),
            radii.len() - 1,
            n_radial.len()
        )));
    }
    check_positive(what, "radii[0]", radii[0])?;
    for (k, w) in radii.windows(2).enumerate() {
        if !(w[1].is_finite() && w[1] > w[0]) {
            return Err(invalid(format!(
                "{what}: radii must increase strictly, got radii[{k}] = {} and radii[{}] = {}",
                w[0],
                k + 1,
                w[1]
            )));
        }
    }
    radii
        .windows(2)
        .zip(n_radial)
        .enumerate()
        .map(|(k, (w, &nr))| {
            if nr == 0 {
                return Err(invalid(format!("{what}: n_radial[{k}] must be at least 1")));
            }
            nodes_1d(w[0], w[1], nr, Grading::Uniform)
        })
        .collect()
}

/// Layered circular annular sectors (e.g. cartilage layers on a bone), one mesh per layer.
///
/// Layer `k` is `{center + r (cos θ, sin θ) : radii[k] ≤ r ≤ radii[k+1], θ0 ≤ θ ≤ θ1}` with
/// `angle_range = (θ0, θ1)` in radians (counter-clockwise from `+x`, `0 < θ1 − θ0 < 2π`), meshed
/// with `n_angle` cells along the arc and `n_radial[k]` cells across the layer (uniform), each
/// quad split into two triangles. All layers use bit-identical angular node positions, so
/// neighbouring layers have coinciding nodes on their shared circle (a bonded interface).
///
/// Boundary parts of each layer ([`BoundaryKind::TractionFree`]): `"inner"` (`r = radii[k]`),
/// `"outer"` (`r = radii[k+1]`), `"side_start"` (`θ = θ0`), `"side_end"` (`θ = θ1`).
pub fn layered_arc_2d(
    center: Point<2>,
    radii: &[Real],
    angle_range: (Real, Real),
    n_angle: usize,
    n_radial: &[usize],
) -> Result<Vec<Mesh<2>>, MeshError> {
    let what = "layered_arc_2d";
    check_center(what, &center)?;
    let (t0, t1) = angle_range;
    let span = t1 - t0;
    if !(t0.is_finite() && t1.is_finite() && span > 0.0 && span < 2.0 * std::f64::consts::PI) {
        return Err(invalid(format!("{what}: need finite angles with 0 < θ1 − θ0 < 2π, got ({t0}, {t1})")));
    }
    check_count(what, "n_angle", n_angle)?;
    let radial = check_layers(what, radii, n_radial)?;
    let angles = nodes_1d(t0, t1, n_angle, Grading::Uniform)?;
    radial
        .into_iter()
        .map(|rs| {
            let coords = [angles.clone(), rs];
            structured(
                what,
                &coords,
                [false; 2],
                |p| {
                    let (t, r) = (p[0], p[1]);
                    center + Point::<2>::new(r * t.cos(), r * t.sin())
                },
                &[
                    ("inner", &[(1, false)]),
                    ("outer", &[(1, true)]),
                    ("side_start", &[(0, false)]),
                    ("side_end", &[(0, true)]),
                ],
            )
        })
        .collect()
}

/// Layered spherical-shell caps around the `−z` axis (a femoral head or an acetabulum with its
/// cartilage), one mesh per layer.
///
/// Layer `k` is the part of the shell `radii[k] ≤ |x − center| ≤ radii[k+1]` within the polar
/// angle `half_angle` (radians, `0 < half_angle < π`) of the downward axis `−e_z`; its lowest
/// point on each sphere, `center − r e_z`, is a node. The surface grid is the square
/// `[-1, 1]²` with `2 n_surface × 2 n_surface` cells (mirror-symmetric Kuhn diagonals), mapped to
/// the unit disc by `p ↦ p ‖p‖_∞ / ‖p‖_2` and then to the sphere patch by the azimuthal
/// equidistant map (a disc point at distance `ρ` from the center goes to polar angle
/// `ρ · half_angle`), so the rim is the circle at polar angle `half_angle`. It is extruded in
/// radius with `n_radial[k]` uniform cells; each hex is cut into 6 Kuhn tetrahedra. All layers use
/// bit-identical directions, so neighbouring layers have coinciding nodes on their shared sphere.
///
/// Boundary parts of each layer ([`BoundaryKind::TractionFree`]): `"inner"`
/// (`|x − center| = radii[k]`), `"outer"` (`|x − center| = radii[k+1]`) and `"rim"` (the conical
/// side at polar angle `half_angle`).
pub fn layered_cap_3d(
    center: Point<3>,
    radii: &[Real],
    half_angle: Real,
    n_surface: usize,
    n_radial: &[usize],
) -> Result<Vec<Mesh<3>>, MeshError> {
    let what = "layered_cap_3d";
    check_center(what, &center)?;
    if !(half_angle.is_finite() && half_angle > 0.0 && half_angle < std::f64::consts::PI) {
        return Err(invalid(format!("{what}: need 0 < half_angle < π, got {half_angle}")));
    }
    check_count(what, "n_surface", n_surface)?;
    let radial = check_layers(what, radii, n_radial)?;
    let square = symmetric_coords(n_surface);
    let direction = |u: Real, v: Real| -> Point<3> {
        let rho = u.abs().max(v.abs());
        let l2 = u.hypot(v);
        let phi = rho * half_angle;
        if l2 > 0.0 {
            let s = phi.sin() / l2;
            Point::<3>::new(s * u, s * v, -phi.cos())
        } else {
            Point::<3>::new(0.0, 0.0, -1.0)
        }
    };
    let rim: [Side; 4] = [(0, false), (0, true), (1, false), (1, true)];
    radial
        .into_iter()
        .map(|rs| {
            let coords = [square.clone(), square.clone(), rs];
            structured(
                what,
                &coords,
                [true, true, false],
                |p| center + direction(p[0], p[1]) * p[2],
                &[("inner", &[(2, false)]), ("outer", &[(2, true)]), ("rim", &rim)],
            )
        })
        .collect()
}
