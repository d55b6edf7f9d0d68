//! Degrees of freedom and linear constraints (docs/model.md §1, §4: `V = u₂ + V_0`).
//!
//! Every node carries `D` displacement components. Bonded interfaces merge coincident nodes
//! into one *node group*; every group collects the linear constraints of the boundary parts its
//! nodes lie on: `c_jᵀ u = g_j(t)` (a Dirichlet component: `c_j = e_k`, `g_j = u₂,k(x, t)`;
//! clamped: `g_j = 0`; symmetry `Γ₀`: `c_j = n`, the nodal normal, `g_j = 0`). The group's
//! displacement is then parametrised as
//!
//! ```text
//! u = u_p(t) + N ũ,     Nᵀ N = I,   C N = 0,   u_p = Σ_i q_i (q_i · u) ∈ range Cᵀ
//! ```
//!
//! with `ũ ∈ R^{D − rank C}` the group's free (reduced) unknowns. The reduced stiffness
//! `Ñ ᵀ K Ñ` is symmetric positive definite whenever no rigid motion satisfies the constraints,
//! which [`DofMap::check_coercive`] verifies from the data (docs/model.md §4). Constraints along normals
//! that are not coordinate axes need no special treatment.

use std::collections::BTreeSet;

use nalgebra::DMatrix;
use synovia_mesh::matching::match_nodes;
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::BoundaryKind;

use crate::error::{FemError, UnmatchedInterface};
use crate::model::{BodyId, Model};

/// Where the right-hand side `g_j(t)` of a node constraint comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ConstraintValue {
    /// `g = 0` (clamped, symmetry).
    Zero,
    /// `g = c · u₂(x, t)` of prescribed condition number `index` of the model.
    Prescribed {
        /// Index into [`Model::prescribed`].
        index: usize,
    },
}

/// One linear constraint `cᵀ u = g(t)` on a node group.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeConstraint<const D: usize> {
    /// Unit direction `c`.
    pub direction: Vector<D>,
    /// The value source.
    pub value: ConstraintValue,
}

/// The unknowns of one node group (one node, or several nodes bonded together).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeGroup<const D: usize> {
    /// First reduced dof of the group.
    pub first_dof: usize,
    /// Number of reduced dofs (`D − rank C`).
    pub n_dofs: usize,
    /// Orthonormal basis `N` of the free directions (first `n_dofs` entries used).
    pub basis: [Vector<D>; 3],
    /// `true` if unconstrained (`N = I`).
    pub free: bool,
    /// Position (of the first node of the group).
    pub position: Point<D>,
    /// The body and node the group's position belongs to (for error messages).
    pub origin: (BodyId, usize),
    /// The constraints.
    pub constraints: Vec<NodeConstraint<D>>,
    /// Orthonormal constrained directions `q_i = Σ_j L_ij c_j`: `(q_i, L_i·)`.
    ortho: Vec<(Vector<D>, Vec<Real>)>,
    /// Dependent constraints `c_j = Σ_i α_i q_i`: `(j, α)`.
    dependent: Vec<(usize, Vec<Real>)>,
}

/// The map from the nodes of every body to the reduced unknowns (free dofs), with the
/// constraints that define the lift `u_p(t)`.
#[derive(Debug, Clone)]
pub struct DofMap<const D: usize> {
    node_offset: Vec<usize>,
    group_of: Vec<usize>,
    groups: Vec<NodeGroup<D>>,
    n_dofs: usize,
    body_component: Vec<usize>,
}

struct UnionFind(Vec<usize>);
impl UnionFind {
    fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.0[hi] = lo;
        }
    }
}

impl<const D: usize> DofMap<D> {
    /// Builds the dof map of a model: bonds tied nodes, collects constraints and numbers the
    /// free unknowns group by group.
    pub fn new(model: &Model<D>) -> Result<Self, FemError> {
        model.validate()?;
        let bodies = model.bodies();
        let mut node_offset = Vec::with_capacity(bodies.len() + 1);
        let mut total = 0;
        for b in bodies {
            node_offset.push(total);
            total += b.mesh.n_nodes();
        }
        node_offset.push(total);

        // 1. ties
        let mut uf = UnionFind((0..total).collect());
        let mut body_uf = UnionFind((0..bodies.len()).collect());
        for (tie_index, tie) in model.ties().iter().enumerate() {
            let (ba, bb) = (model.body(tie.body_a)?, model.body(tie.body_b)?);
            let pa = ba
                .mesh
                .boundary_part(&tie.part_a)
                .map_err(|source| FemError::Mesh { body: ba.name.clone(), source })?
                .nodes();
            let pb = bb
                .mesh
                .boundary_part(&tie.part_b)
                .map_err(|source| FemError::Mesh { body: bb.name.clone(), source })?
                .nodes();
            let xa: Vec<Point<D>> = pa.iter().map(|&i| *ba.mesh.node(i)).collect();
            let xb: Vec<Point<D>> = pb.iter().map(|&i| *bb.mesh.node(i)).collect();
            let tol = tie
                .tolerance
                .unwrap_or_else(|| 1e-8 * ba.mesh.min_edge_length().min(bb.mesh.min_edge_length()));
            let pairs = match_nodes(&xa, &xb, tol).map_err(|u| {
                // the unmatched node farthest from the other part (the first 2000 of each side)
                let nearest = |x: &Point<D>, other: &[Point<D>]| {
                    other.iter().map(|y| (x - y).norm()).fold(Real::INFINITY, Real::min)
                };
                let mut worst: Option<(Real, String, usize, Vec<f64>)> = None;
                let sides = [(&u.first, &xa, &xb, &pa, &ba.name), (&u.second, &xb, &xa, &pb, &bb.name)];
                for (unmatched, xs, other, ids, name) in sides {
                    for &i in unmatched.iter().take(2000) {
                        let d = nearest(&xs[i], other);
                        if worst.as_ref().is_none_or(|w| d > w.0) {
                            worst = Some((d, name.clone(), ids[i], xs[i].iter().copied().collect()));
                        }
                    }
                }
                let max_distance = worst.as_ref().map_or(0.0, |w| w.0);
                FemError::UnmatchedInterface(Box::new(UnmatchedInterface {
                    tie: tie_index,
                    max_distance,
                    example: worst.map(|(_, b, n, x)| (b, n, x)),
                    body_a: ba.name.clone(),
                    part_a: tie.part_a.clone(),
                    body_b: bb.name.clone(),
                    part_b: tie.part_b.clone(),
                    unmatched_a: u.first.iter().map(|&i| pa[i]).collect(),
                    unmatched_b: u.second.iter().map(|&j| pb[j]).collect(),
                }))
            })?;
            for (i, j) in pairs {
                uf.union(node_offset[tie.body_a.0] + pa[i], node_offset[tie.body_b.0] + pb[j]);
            }
            body_uf.union(tie.body_a.0, tie.body_b.0);
        }
        let body_component: Vec<usize> = (0..bodies.len()).map(|b| body_uf.find(b)).collect();

        // 2. groups in order of their first node
        let mut group_of = vec![usize::MAX; total];
        let mut groups: Vec<NodeGroup<D>> = Vec::new();
        for (bi, body) in bodies.iter().enumerate() {
            for i in 0..body.mesh.n_nodes() {
                let g = node_offset[bi] + i;
                let root = uf.find(g);
                if group_of[root] == usize::MAX {
                    group_of[root] = groups.len();
                    groups.push(NodeGroup {
                        first_dof: 0,
                        n_dofs: D,
                        basis: [Vector::<D>::zeros(); 3],
                        free: true,
                        position: *body.mesh.node(i),
                        origin: (BodyId(bi), i),
                        constraints: Vec::new(),
                        ortho: Vec::new(),
                        dependent: Vec::new(),
                    });
                }
                group_of[g] = group_of[root];
            }
        }

        // 3. constraints from parts
        let unit = |k: usize| {
            let mut e = Vector::<D>::zeros();
            e[k] = 1.0;
            e
        };
        for (bi, body) in bodies.iter().enumerate() {
            for part in body.mesh.boundary_parts() {
                match part.kind() {
                    BoundaryKind::Clamped => {
                        for n in part.nodes() {
                            let grp = &mut groups[group_of[node_offset[bi] + n]];
                            for k in 0..D {
                                grp.constraints.push(NodeConstraint {
                                    direction: unit(k),
                                    value: ConstraintValue::Zero,
                                });
                            }
                        }
                    }
                    BoundaryKind::Symmetry => {
                        let normals = body
                            .mesh
                            .nodal_normals(part.name())
                            .map_err(|source| FemError::Mesh { body: body.name.clone(), source })?;
                        for (n, normal) in normals {
                            groups[group_of[node_offset[bi] + n]]
                                .constraints
                                .push(NodeConstraint { direction: normal, value: ConstraintValue::Zero });
                        }
                    }
                    _ => {}
                }
            }
        }
        for (index, p) in model.prescribed().iter().enumerate() {
            let body = model.body(p.body)?;
            let part = body
                .mesh
                .boundary_part(&p.part)
                .map_err(|source| FemError::Mesh { body: body.name.clone(), source })?;
            for n in part.nodes() {
                let grp = &mut groups[group_of[node_offset[p.body.0] + n]];
                for k in 0..D {
                    if p.components.contains(k) {
                        grp.constraints.push(NodeConstraint {
                            direction: unit(k),
                            value: ConstraintValue::Prescribed { index },
                        });
                    }
                }
            }
        }

        // 4. orthonormalise and number
        let mut next = 0;
        for grp in groups.iter_mut() {
            grp.factor_constraints();
            grp.first_dof = next;
            next += grp.n_dofs;
        }
        Ok(Self { node_offset, group_of, groups, n_dofs: next, body_component })
    }

    /// Number of reduced (free) unknowns.
    pub fn n_dofs(&self) -> usize {
        self.n_dofs
    }
    /// The node groups, in dof order.
    pub fn groups(&self) -> &[NodeGroup<D>] {
        &self.groups
    }
    /// The group of node `node` of body `body`.
    #[inline]
    pub fn group_of(&self, body: BodyId, node: usize) -> usize {
        self.group_of[self.node_offset[body.0] + node]
    }
    /// The reduced dofs of node `node` of body `body` (those of its node group).
    pub fn node_dofs(&self, body: BodyId, node: usize) -> std::ops::Range<usize> {
        let g = &self.groups[self.group_of(body, node)];
        g.first_dof..g.first_dof + g.n_dofs
    }
    /// Offset of body `body`'s nodes in the global node numbering.
    pub fn node_offset(&self, body: BodyId) -> usize {
        self.node_offset[body.0]
    }

    /// The lifts `u_p(t)` of every group at time `t` (zero for free groups), checking that
    /// dependent constraints agree.
    pub fn lifts(&self, model: &Model<D>, t: Real) -> Result<Vec<Vector<D>>, FemError> {
        let mut out = vec![Vector::<D>::zeros(); self.groups.len()];
        // buffers reused across the groups: the constrained values, their projections
        let (mut g, mut proj): (Vec<Real>, Vec<Real>) = (Vec::new(), Vec::new());
        for (gi, grp) in self.groups.iter().enumerate() {
            if grp.constraints.is_empty() {
                continue;
            }
            g.clear();
            for c in &grp.constraints {
                g.push(match c.value {
                    ConstraintValue::Zero => 0.0,
                    ConstraintValue::Prescribed { index } => {
                        let u2 = (model.prescribed()[index].value)(&grp.position, t);
                        if u2.iter().any(|v| !v.is_finite()) {
                            return Err(FemError::NonFiniteData {
                                what: format!(
                                    "prescribed displacement on part `{}`",
                                    model.prescribed()[index].part
                                ),
                                x: grp.position.iter().copied().collect(),
                                t,
                            });
                        }
                        c.direction.dot(&u2)
                    }
                });
            }
            proj.clear();
            proj.extend(grp.ortho.iter().map(|(_, l)| l.iter().zip(&g).map(|(a, b)| a * b).sum::<Real>()));
            for (j, alpha) in &grp.dependent {
                let pred: Real = alpha.iter().zip(&proj).map(|(a, b)| a * b).sum();
                let scale = pred.abs().max(g[*j].abs());
                if (pred - g[*j]).abs() > 1e-9 * scale {
                    let (body, node) = grp.origin;
                    return Err(FemError::ConflictingConstraints {
                        body: model.body(body)?.name.clone(),
                        node,
                        residual: (pred - g[*j]).abs(),
                    });
                }
            }
            let mut up = Vector::<D>::zeros();
            for ((q, _), s) in grp.ortho.iter().zip(&proj) {
                up += q * *s;
            }
            out[gi] = up;
        }
        Ok(out)
    }

    /// The displacement of every node of every body, `u = u_p + N ũ`, from reduced unknowns.
    pub fn expand(&self, reduced: &[Real], lifts: &[Vector<D>]) -> Result<Vec<Vec<Vector<D>>>, FemError> {
        if reduced.len() != self.n_dofs {
            return Err(FemError::Length {
                what: "reduced solution",
                expected: self.n_dofs,
                got: reduced.len(),
            });
        }
        let nb = self.node_offset.len() - 1;
        let mut out = Vec::with_capacity(nb);
        for b in 0..nb {
            let mut body = Vec::with_capacity(self.node_offset[b + 1] - self.node_offset[b]);
            for g in self.node_offset[b]..self.node_offset[b + 1] {
                let gi = self.group_of[g];
                body.push(self.group_displacement(gi, reduced, lifts));
            }
            out.push(body);
        }
        Ok(out)
    }

    /// `u_p + N ũ` of group `gi`.
    #[inline]
    pub fn group_displacement(&self, gi: usize, reduced: &[Real], lifts: &[Vector<D>]) -> Vector<D> {
        let grp = &self.groups[gi];
        let mut u = lifts[gi];
        for k in 0..grp.n_dofs {
            u += grp.basis[k] * reduced[grp.first_dof + k];
        }
        u
    }

    /// Restricts a full nodal vector field (e.g. a nodal force) to the reduced unknowns:
    /// `ũ_k = N_kᵀ v` summed over the nodes of each group (the transpose of [`DofMap::expand`]
    /// without lift).
    pub fn restrict(&self, full: &[Vec<Vector<D>>]) -> Vec<Real> {
        let mut out = vec![0.0; self.n_dofs];
        for (b, body) in full.iter().enumerate() {
            for (i, v) in body.iter().enumerate() {
                let grp = &self.groups[self.group_of[self.node_offset[b] + i]];
                for k in 0..grp.n_dofs {
                    out[grp.first_dof + k] += grp.basis[k].dot(v);
                }
            }
        }
        out
    }

    /// Checks that no rigid motion of any connected set of bodies satisfies the homogeneous
    /// constraints (docs/model.md §4, coercivity): [`DofMap::floating_components`] must be empty.
    pub fn check_coercive(&self, model: &Model<D>) -> Result<(), FemError> {
        match self.floating_components(model).into_iter().next() {
            None => Ok(()),
            Some(c) => Err(FemError::SemiCoercive { bodies: c.bodies, free_modes: c.modes.len() }),
        }
    }

    /// The rigid motions left free by the homogeneous constraints, per connected set of
    /// bodies (bodies joined by bonded interfaces): the kernel of `K̃` (docs/model.md §4,
    /// semi-coercive problems).
    ///
    /// A rigid motion `r(x) = a + W (x − x̄)` (`W` skew) is unrestrained if `c_jᵀ r(x_j) = 0`
    /// for every constraint; with `ρ_j = (c_jᵀ r_m(x_j))_m` over the rigid modes `r_m`
    /// (positions scaled by the component size), the free combinations are the eigenvectors
    /// of `Σ_j ρ_j ρ_jᵀ` with eigenvalues `≤ 1e-10 ×` the largest. Each is returned as a
    /// vector of reduced unknowns `ũ_k = N_kᵀ r(x_k)`, orthonormalised.
    pub fn floating_components(&self, model: &Model<D>) -> Vec<FloatingComponent> {
        let nm = if D == 2 { 3 } else { 6 };
        let comps: BTreeSet<usize> = self.body_component.iter().copied().collect();
        let mut out = Vec::new();
        for comp in comps {
            let bodies: Vec<usize> =
                (0..self.body_component.len()).filter(|&b| self.body_component[b] == comp).collect();
            // centroid and size of the component
            let mut centre = Point::<D>::zeros();
            let mut count: Real = 0.0;
            let mut lo = Point::<D>::repeat(Real::INFINITY);
            let mut hi = Point::<D>::repeat(Real::NEG_INFINITY);
            for &b in &bodies {
                for x in model.bodies()[b].mesh.nodes() {
                    centre += x;
                    count += 1.0;
                    lo = lo.inf(x);
                    hi = hi.sup(x);
                }
            }
            centre /= count.max(1.0);
            let size = (hi - lo).norm().max(Real::MIN_POSITIVE);
            let mut gram = DMatrix::<Real>::zeros(nm, nm);
            let mut groups = Vec::new();
            let mut seen = vec![false; self.groups.len()];
            for &b in &bodies {
                for g in self.node_offset[b]..self.node_offset[b + 1] {
                    let gi = self.group_of[g];
                    if seen[gi] {
                        continue;
                    }
                    seen[gi] = true;
                    groups.push(gi);
                    let grp = &self.groups[gi];
                    let y = (grp.position - centre) / size;
                    for c in &grp.constraints {
                        let row = rigid_mode_row::<D>(&c.direction, &y);
                        for i in 0..nm {
                            for j in 0..nm {
                                gram[(i, j)] += row[i] * row[j];
                            }
                        }
                    }
                }
            }
            let eig = gram.symmetric_eigen();
            let max = eig.eigenvalues.iter().fold(0.0_f64, |a, &b| a.max(b));
            let free: Vec<usize> =
                (0..nm).filter(|&i| eig.eigenvalues[i] <= 1e-10 * max.max(Real::MIN_POSITIVE)).collect();
            if free.is_empty() {
                continue;
            }
            let mut dofs = Vec::new();
            for &gi in &groups {
                let grp = &self.groups[gi];
                dofs.extend(grp.first_dof..grp.first_dof + grp.n_dofs);
            }
            let mut modes: Vec<Vec<Real>> = Vec::with_capacity(free.len());
            for &i in &free {
                let coeff = eig.eigenvectors.column(i);
                let mut v = vec![0.0; self.n_dofs];
                for &gi in &groups {
                    let grp = &self.groups[gi];
                    let y = (grp.position - centre) / size;
                    let r = rigid_motion_at::<D>(coeff.as_slice(), &y);
                    for k in 0..grp.n_dofs {
                        v[grp.first_dof + k] = grp.basis[k].dot(&r);
                    }
                }
                // Gram–Schmidt against the previous modes (twice, for round-off).
                for _ in 0..2 {
                    for m in &modes {
                        let d: Real = dofs.iter().map(|&k| v[k] * m[k]).sum();
                        for &k in &dofs {
                            v[k] -= d * m[k];
                        }
                    }
                }
                let norm = dofs.iter().map(|&k| v[k] * v[k]).sum::<Real>().sqrt();
                if norm > 1e-12 {
                    for &k in &dofs {
                        v[k] /= norm;
                    }
                    modes.push(v);
                }
            }
            out.push(FloatingComponent {
                bodies: bodies.iter().map(|&b| model.bodies()[b].name.clone()).collect(),
                body_ids: bodies.iter().map(|&b| BodyId(b)).collect(),
                modes,
                dofs,
            });
        }
        out
    }
}

/// A connected set of bodies whose constraints leave rigid motions free (docs/model.md §4,
/// semi-coercive): the kernel of `K̃` restricted to it.
#[derive(Debug, Clone, PartialEq)]
pub struct FloatingComponent {
    /// Names of the bodies.
    pub bodies: Vec<String>,
    /// Their ids.
    pub body_ids: Vec<BodyId>,
    /// Orthonormal kernel vectors in the reduced unknowns (zero outside [`Self::dofs`]).
    pub modes: Vec<Vec<Real>>,
    /// The reduced unknowns of the component's bodies.
    pub dofs: Vec<usize>,
}

/// `r(y) = Σ_m c_m r_m(y)` for the rigid modes of [`rigid_mode_row`].
fn rigid_motion_at<const D: usize>(c: &[Real], y: &Vector<D>) -> Vector<D> {
    let mut r = Vector::<D>::zeros();
    for k in 0..D {
        r[k] = c[k];
    }
    if D == 2 {
        r[0] -= c[2] * y[1];
        r[1] += c[2] * y[0];
    } else {
        // c_3 e_x × y + c_4 e_y × y + c_5 e_z × y
        r[1] += -c[3] * y[2];
        r[2] += c[3] * y[1];
        r[0] += c[4] * y[2];
        r[2] += -c[4] * y[0];
        r[0] += -c[5] * y[1];
        r[1] += c[5] * y[0];
    }
    r
}

/// `(cᵀ r_m(y))_m` for the rigid modes: translations `e_k`, rotations `e_k × y` (3D) or
/// `(−y_2, y_1)` (2D).
fn rigid_mode_row<const D: usize>(c: &Vector<D>, y: &Vector<D>) -> [Real; 6] {
    let mut row = [0.0; 6];
    for k in 0..D {
        row[k] = c[k];
    }
    if D == 2 {
        row[2] = -c[0] * y[1] + c[1] * y[0];
    } else {
        // e_k × y
        row[3] = c[1] * (-y[2]) + c[2] * y[1]; // e_x × y = (0, −y_z, y_y)
        row[4] = c[0] * y[2] + c[2] * (-y[0]); // e_y × y = (y_z, 0, −y_x)
        row[5] = c[0] * (-y[1]) + c[1] * y[0]; // e_z × y = (−y_y, y_x, 0)
    }
    row
}

impl<const D: usize> NodeGroup<D> {
    /// Gram–Schmidt on the constraint directions: orthonormal `q_i` with their coefficients,
    /// dependent constraints, and the orthonormal basis `N` of the free directions.
    fn factor_constraints(&mut self) {
        if self.constraints.is_empty() {
            for k in 0..D {
                let mut e = Vector::<D>::zeros();
                e[k] = 1.0;
                self.basis[k] = e;
            }
            self.n_dofs = D;
            self.free = true;
            return;
        }
        self.free = false;
        let m = self.constraints.len();
        for j in 0..m {
            let c = self.constraints[j].direction;
            let mut r = c;
            let mut coeff = vec![0.0; m];
            coeff[j] = 1.0;
            let dots: Vec<Real> = self.ortho.iter().map(|(q, _)| q.dot(&c)).collect();
            for ((q, l), d) in self.ortho.iter().zip(&dots) {
                r -= q * *d;
                for (ci, li) in coeff.iter_mut().zip(l) {
                    *ci -= d * li;
                }
            }
            let len = r.norm();
            if len > 1e-8 && self.ortho.len() < D {
                coeff.iter_mut().for_each(|x| *x /= len);
                self.ortho.push((r / len, coeff));
            } else {
                self.dependent.push((j, dots));
            }
        }
        // pad dependent alphas (ortho may have grown after they were recorded)
        let k = self.ortho.len();
        for (_, a) in self.dependent.iter_mut() {
            a.resize(k, 0.0);
        }
        // null-space basis: repeatedly take the coordinate axis with the largest component
        // orthogonal to the constrained directions and the basis so far
        let mut basis: Vec<Vector<D>> = Vec::new();
        while basis.len() + k < D {
            let mut best: Option<(Vector<D>, Real)> = None;
            for e in 0..D {
                let mut v = Vector::<D>::zeros();
                v[e] = 1.0;
                for (q, _) in &self.ortho {
                    v -= q * q.dot(&v);
                }
                for b in &basis {
                    v -= b * b.dot(&v);
                }
                let len = v.norm();
                if best.as_ref().is_none_or(|(_, l)| len > *l) {
                    best = Some((v, len));
                }
            }
            match best {
                Some((v, len)) if len > 1e-8 => basis.push(v / len),
                _ => break,
            }
        }
        self.n_dofs = basis.len();
        for (i, b) in basis.into_iter().enumerate() {
            self.basis[i] = b;
        }
    }
}
