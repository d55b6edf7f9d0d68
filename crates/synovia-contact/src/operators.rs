//! Contact pairs and the discrete contact operators of docs/model.md §5.
//!
//! A [`ContactPair`] joins the contact part of a body `k` to the other side through a contact
//! discretisation ([`ContactDiscretisation`], one open trait, one file per kind in
//! [`crate::discretisation`]): node-to-node on matching meshes, node-to-segment (2D) /
//! node-to-facet (3D) or dual mortar on non-matching meshes, a rigid obstacle described by a
//! signed distance, or any type implementing the trait ([`ContactPair::custom`]).
//! [`ContactGeometry`] computes what every discretisation shares — the outward nodal normals
//! `n^k` (docs/model.md §1), the lumped weights `κ_i = ∫_{Γ_c} φ_i ds` (row sums of the boundary
//! mass of part `k`) and the shortest edge of part `k` in the configuration it is built on —
//! asks the pair's discretisation for its rows, and stores for every contact node `s_r`
//!
//! * the normal `n_r` and an orthonormal tangent basis,
//! * the weight `κ_r`,
//! * the gap `d_r`, e.g. `d_r = (x_l − x_k) · n_r` (node-to-node),
//!   `d_r = (Σ_j w_j x_{l,j} − x_k) · n_r` (node-to-segment, mortar) or `d_r = φ(x_k)` (obstacle).
//!
//! From these, [`ContactGeometry::normal_constraints`] builds `B_hn` in the reduced unknowns of a
//! [`DofMap`] (`(B_hn U)_r = [U_n](s_r) = n_r · (u^k(s_r) − u^l(s_r))`, with
//! `u^l(s_r) = Σ_j w_j u^l_j` for the weighted partners), and
//! [`ContactGeometry::friction_constraints`] builds `B_Ht` on the dual cells of the contact nodes:
//! `(B_Ht U)_r = g_{c,r} κ_r T_rᵀ [U_t](s_r)`, the cell integral `∫_{cell r} g_c [U_t] ds` with the
//! nodal (lumped) rule, `T_r` the tangent basis (one vector in 2D, two in 3D), for the cells with
//! `g_{c,r} > 0` only (docs/model.md §5: `λ_t` vanishes outside `supp g_c`).
//!
//! In 3D the report puts `λ_t` on the triangles `Δ_H` of a separate contact triangulation of
//! size `H`; with `H = h` one 2-vector per contact triangle gives about twice as many
//! tangential constraints as tangential unknowns, which violates the inf–sup condition. synovia
//! uses the dual (median) cells of the contact nodes as the triangulation `Δ_H` in 2D and 3D,
//! which keeps `B_Ht` of full rank and the semismooth Newton systems well posed.
//!
//! The node-to-segment operator is not exact for a uniform pressure on non-matching meshes
//! (the slave nodal forces are passed to the master nodes by point interpolation, not by the
//! mortar integral; see `docs/contact.md` for the measured error); dual mortar is.
//!
//! # Rebuilding the geometry at a pose
//!
//! [`ContactGeometry::new_deformed`] builds the pairing, normals, tangents and weights in the
//! configuration `x + u⁰` (a pose: rigid motion plus small elastic displacement), with
//! small-deformation kinematics from there. The constraints keep acting on the *total*
//! displacement `U` from the reference configuration, so the gap is returned in total form:
//! the linearised condition `([U] − [u⁰]) · n ≤ d(x + u⁰)` is `[U] · n ≤ d(x + u⁰) + [u⁰] · n`,
//! which for node-to-segment is `(Σ_j w_j X_{l,j} − X_s) · n` with the reference positions `X`
//! and the weights and normal of the pose. The discretisations measure `d(x + u⁰)`; the geometry
//! adds `[u⁰] · n`. Node-to-node pairs keep the pairing of the reference configuration (normals
//! from the pose).

use std::sync::Arc;

use synovia_fem::{BodyId, DofMap, Model};
use synovia_mesh::math::{Point, Real, Tensor, Vector};

use crate::discretisation::{ContactRow, PairContext};
use crate::error::ContactError;
use crate::problem::{FrictionConstraints, NormalConstraints};
use crate::search::area_normal;
use synovia_linalg::SparseRows;
use synovia_mesh::mesh::nodal_normals_at;

pub use crate::discretisation::{
    ContactDiscretisation, DualMortar, NodeToNode, NodeToSegment, NormalChoice, RigidObstacle,
};
pub use crate::obstacle::{
    CylinderObstacle, DistanceFn, FnObstacle, PlaneObstacle, SignedDistance, SphereObstacle,
};

/// A contact pair `Γ_c^{kl}` (docs/model.md §1, §3): the contact part of body `k` and the
/// discretisation that couples it to the other side.
#[derive(Debug, Clone)]
pub struct ContactPair<const D: usize> {
    /// Name for reports and errors.
    pub name: String,
    /// Body `k` (whose outward normal is `n`; the slave side).
    pub body: BodyId,
    /// Its contact part.
    pub part: String,
    /// The discretisation producing the pair's rows, gaps and weights.
    pub discretisation: Arc<dyn ContactDiscretisation<D>>,
    /// Coulomb coefficient `F_c ≥ 0` (0: frictionless).
    pub friction: Real,
    /// Reporting only: the plane that splits the pair's figures into two sides
    /// ([`PairSplit`]; `None`: the pair is reported as a whole only).
    pub report_split: Option<PairSplit>,
}

/// A plane that splits a pair's reported figures into two sides (e.g. `medial` and
/// `lateral`): a contact node belongs to the positive side when `(x − point)·normal ≥ 0` for
/// its position `x` (the position the centre of pressure is computed from), else to the
/// negative side. Reporting only: the contact problem is not changed. In 2D the third
/// components of `point` and `normal` are ignored.
#[derive(Debug, Clone, PartialEq)]
pub struct PairSplit {
    /// Name of the side `(x − point)·normal ≥ 0`.
    pub positive: String,
    /// Name of the side `(x − point)·normal < 0`.
    pub negative: String,
    /// A point of the plane.
    pub point: [Real; 3],
    /// Its normal (pointing into the positive side; any length > 0).
    pub normal: [Real; 3],
}

impl PairSplit {
    /// A split plane through `point` with `normal` towards the side named `positive`.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] for a point or normal that is not finite, a zero
    /// normal, empty or equal side names.
    pub fn new(
        positive: &str,
        negative: &str,
        point: [Real; 3],
        normal: [Real; 3],
    ) -> Result<Self, ContactError> {
        let bad = |m: String| Err(ContactError::InvalidParameter(m));
        if point.iter().chain(&normal).any(|x| !x.is_finite()) {
            return bad(format!("split plane: point {point:?} and normal {normal:?} must be finite"));
        }
        if normal.iter().all(|&x| x == 0.0) {
            return bad("split plane: the normal is zero".into());
        }
        if positive.is_empty() || negative.is_empty() || positive == negative {
            return bad(format!(
                "split plane: the sides need two different non-empty names, got `{positive}` and `{negative}`"
            ));
        }
        Ok(Self { positive: positive.into(), negative: negative.into(), point, normal })
    }
    /// Whether position `x` (dimension 2 or 3) lies on the positive side.
    pub fn is_positive(&self, x: &[Real]) -> bool {
        x.iter().zip(self.point.iter().zip(&self.normal)).map(|(x, (p, n))| (x - p) * n).sum::<Real>() >= 0.0
    }
}

impl<const D: usize> ContactPair<D> {
    /// A pair of part `part` of body `body` with any discretisation (e.g. one defined outside
    /// this crate), frictionless.
    pub fn custom(
        name: &str,
        body: BodyId,
        part: &str,
        discretisation: Arc<dyn ContactDiscretisation<D>>,
    ) -> Self {
        Self {
            name: name.to_string(),
            body,
            part: part.to_string(),
            discretisation,
            friction: 0.0,
            report_split: None,
        }
    }
    /// The pair with its reported figures split by a plane into two sides ([`PairSplit`]).
    #[must_use]
    pub fn with_report_split(mut self, split: PairSplit) -> Self {
        self.report_split = Some(split);
        self
    }
    /// Body–body node-to-node pair ([`NodeToNode`]) with default pairing direction, tolerance
    /// and normal.
    pub fn node_to_node(name: &str, body_k: BodyId, part_k: &str, body_l: BodyId, part_l: &str) -> Self {
        Self::custom(name, body_k, part_k, Arc::new(NodeToNode::<D>::new(body_l, part_l)))
    }
    /// Body–body pair on non-matching meshes: node-to-segment (2D) / node-to-facet (3D)
    /// ([`NodeToSegment`]), with the nodes of `part_k` of body `k` as slave nodes projected
    /// onto the facets of `part_l` of body `l` (no search-distance limit; see
    /// [`ContactPair::with_search_distance`]).
    ///
    /// **Which side is the slave**: the *softer* body (docs/contact.md, "Which side is the
    /// slave"); with comparable stiffness, the finer mesh. A slave much stiffer than a coarser
    /// master cannot conform to the master's coarse trace, and the slave pressure does not
    /// converge (`examples/nts_slave_choice.rs`: E₁/E₂ = 100, L² error 84 % at every mesh
    /// size vs 1.1 % with the softer side as slave).
    pub fn node_to_segment(name: &str, body_k: BodyId, part_k: &str, body_l: BodyId, part_l: &str) -> Self {
        Self::custom(name, body_k, part_k, Arc::new(NodeToSegment::new(body_l, part_l)))
    }
    /// Body–body pair on non-matching meshes coupled by **dual mortar** ([`DualMortar`], 2D and
    /// 3D; docs/model.md §5, [`crate::mortar`]): `part_k` of body `k` is the slave side,
    /// `part_l` of body `l` the master side; no search-distance limit (see
    /// [`ContactPair::with_search_distance`]). Passes the contact patch test exactly on
    /// non-matching meshes. The slave side is chosen as for
    /// [`ContactPair::node_to_segment`]: the softer body.
    pub fn mortar(name: &str, body_k: BodyId, part_k: &str, body_l: BodyId, part_l: &str) -> Self {
        Self::custom(name, body_k, part_k, Arc::new(DualMortar::new(body_l, part_l)))
    }
    /// Body–rigid-obstacle pair ([`RigidObstacle`]).
    pub fn rigid(name: &str, body: BodyId, part: &str, obstacle: Arc<dyn SignedDistance<D>>) -> Self {
        Self::custom(name, body, part, Arc::new(RigidObstacle::new(obstacle)))
    }
    /// The built-in discretisation of this pair as a `T`, if it is one.
    fn built_in<T: Clone + 'static>(&self) -> Option<T> {
        let any: &dyn std::any::Any = &*self.discretisation;
        any.downcast_ref::<T>().cloned()
    }
    /// Sets the search distance of a node-to-segment, mortar or rigid-obstacle pair (no effect
    /// on other pairs; see [`RigidObstacle::search_distance`] for the rigid case).
    #[must_use]
    pub fn with_search_distance(mut self, distance: Real) -> Self {
        if let Some(mut d) = self.built_in::<NodeToSegment>() {
            d.search_distance = Some(distance);
            self.discretisation = Arc::new(d);
        } else if let Some(mut d) = self.built_in::<DualMortar>() {
            d.search_distance = Some(distance);
            self.discretisation = Arc::new(d);
        } else if let Some(mut d) = self.built_in::<RigidObstacle<D>>() {
            d.search_distance = Some(distance);
            self.discretisation = Arc::new(d);
        }
        self
    }
    /// Sets the Coulomb coefficient.
    #[must_use]
    pub fn with_friction(mut self, coefficient: Real) -> Self {
        self.friction = coefficient;
        self
    }
    /// Uses a fixed normal (and pairing direction) for a node-to-node pair (no effect on other
    /// pairs).
    #[must_use]
    pub fn with_fixed_normal(mut self, direction: Vector<D>) -> Self {
        if let Some(d) = self.built_in::<NodeToNode<D>>() {
            self.discretisation = Arc::new(d.with_fixed_normal(direction));
        }
        self
    }
    /// Sets the absolute pairing tolerance of a node-to-node pair (no effect on other pairs).
    #[must_use]
    pub fn with_pairing_tolerance(mut self, tolerance: Real) -> Self {
        if let Some(d) = self.built_in::<NodeToNode<D>>() {
            self.discretisation = Arc::new(d.with_tolerance(tolerance));
        }
        self
    }
    /// The kind of the pair's discretisation ([`ContactDiscretisation::kind`]).
    pub fn kind(&self) -> &str {
        self.discretisation.kind()
    }
    /// The other side's body and part ([`ContactDiscretisation::partner_part`]; `None` for a
    /// rigid obstacle).
    pub fn partner_part(&self) -> Option<(BodyId, &str)> {
        self.discretisation.partner_part()
    }
}

/// One contact node `s_r`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactNode<const D: usize> {
    /// Index of the pair it belongs to.
    pub pair: usize,
    /// Body `k` and node.
    pub node: (BodyId, usize),
    /// Partner node on body `l` (node-to-node), or `None` (rigid obstacle, node-to-segment).
    pub partner: Option<(BodyId, usize)>,
    /// Node-to-segment: the master nodes `(body l, node j, w_j)` of the master point
    /// `Σ_j w_j x_{l,j}` (`w_j > 0`, `Σ_j w_j = 1`); mortar: `w_j = M_rj / D_rr` (`Σ_j w_j = 1`,
    /// some may be negative; [`crate::mortar`]); empty for the other pair kinds.
    pub master: Vec<(BodyId, usize, Real)>,
    /// Position of the node of body `k` (in the configuration the geometry was built on).
    pub position: Point<D>,
    /// Unit normal `n_r`.
    pub normal: Vector<D>,
    /// Orthonormal tangents (`D − 1` used).
    pub tangents: [Vector<D>; 2],
    /// Lumped weight `κ_r` (mortar: `D_rr`).
    pub weight: Real,
    /// Initial gap `d_r`.
    pub gap: Real,
    /// Coulomb coefficient of the pair.
    pub friction: Real,
}

/// A rigid placement `x ↦ R x + t` of a body in space (`R` a proper rotation): the body's
/// *frame*, for bodies that move by large rigid motions (a flexing femur) while their elastic
/// deformation stays small.
///
/// Linear elasticity cannot carry a large rotation as a displacement (the linearised strain of
/// a rotation by `θ` is `cos θ − 1`), but it does not need to: the stiffness of a body in its
/// own frame does not depend on where the body is. A geometry built with placements
/// ([`ContactGeometry::new_placed`]) pairs and measures the bodies in their placed positions and
/// writes the constraint rows for displacements **in each body's frame**: a displacement `u`
/// of body `b` is `R_b u` in space, so its row coefficients are `R_bᵀ n` instead of `n`. The
/// stiffness `A` and its factorisation stay those of the reference meshes — one factorisation
/// serves every pose (issue 6: the `knee2d` gait cycle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPlacement<const D: usize> {
    rotation: Tensor<D>,
    translation: Vector<D>,
}

impl<const D: usize> Default for BodyPlacement<D> {
    fn default() -> Self {
        Self::identity()
    }
}

impl<const D: usize> BodyPlacement<D> {
    /// The identity placement (the body where its mesh is).
    pub fn identity() -> Self {
        Self { rotation: Tensor::<D>::identity(), translation: Vector::<D>::zeros() }
    }

    /// `x ↦ R x + t`.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] if `R` or `t` is not finite, or `R` is not a proper
    /// rotation (`‖RᵀR − I‖_max > 1e-10` or `det R < 0`).
    pub fn new(rotation: Tensor<D>, translation: Vector<D>) -> Result<Self, ContactError> {
        let finite = rotation.iter().chain(translation.iter()).all(|v| v.is_finite());
        let orthogonality = (rotation.transpose() * rotation - Tensor::<D>::identity()).amax();
        if !finite || orthogonality > 1e-10 || synovia_mesh::math::det(&rotation) <= 0.0 {
            return Err(ContactError::InvalidParameter(format!(
                "a body placement needs a finite proper rotation and translation (‖RᵀR − I‖ = {orthogonality:.1e}, det R = {:.3})",
                synovia_mesh::math::det(&rotation)
            )));
        }
        Ok(Self { rotation, translation })
    }

    /// The rotation `R` about the point `c`: `x ↦ R (x − c) + c`.
    ///
    /// # Errors
    /// As [`BodyPlacement::new`].
    pub fn rotation_about(center: Point<D>, rotation: Tensor<D>) -> Result<Self, ContactError> {
        Self::new(rotation, center - rotation * center)
    }

    /// The rotation `R`.
    pub fn rotation(&self) -> &Tensor<D> {
        &self.rotation
    }
    /// The translation `t`.
    pub fn translation(&self) -> &Vector<D> {
        &self.translation
    }
    /// `true` for the identity placement.
    pub fn is_identity(&self) -> bool {
        *self == Self::identity()
    }
    /// The placed position `R x + t` of a point `x` of the mesh.
    pub fn position(&self, x: &Point<D>) -> Point<D> {
        self.rotation * x + self.translation
    }
    /// A vector of the body frame in space: `R v`.
    pub fn to_global(&self, v: &Vector<D>) -> Vector<D> {
        self.rotation * v
    }
    /// A vector in space in the body frame: `Rᵀ v`.
    pub fn to_body(&self, v: &Vector<D>) -> Vector<D> {
        self.rotation.tr_mul(v)
    }
}

impl BodyPlacement<2> {
    /// The planar rotation by `angle` (radians, counter-clockwise) about `center`.
    ///
    /// # Errors
    /// If `angle` or `center` is not finite.
    pub fn planar_rotation(center: Point<2>, angle: Real) -> Result<Self, ContactError> {
        let (s, c) = angle.sin_cos();
        Self::rotation_about(center, Tensor::<2>::new(c, -s, s, c))
    }
}

/// The geometry of all contact pairs of a model: the contact nodes with normals, weights, gaps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ContactGeometry<const D: usize> {
    /// Pair names, with the range of their nodes in `nodes`.
    pub pairs: Vec<(String, std::ops::Range<usize>)>,
    /// The reporting split of each pair ([`ContactPair::report_split`]), in the order of
    /// `pairs` (may be shorter: missing entries have none).
    pub report_splits: Vec<Option<PairSplit>>,
    /// All contact nodes, pair by pair.
    pub nodes: Vec<ContactNode<D>>,
    /// Neighbours of each contact node (nodes sharing a contact facet of body `k`), for nested
    /// iteration ([`crate::nested`]).
    pub adjacency: Vec<Vec<usize>>,
    /// Placement of each body ([`ContactGeometry::new_placed`]); empty: every body where its
    /// mesh is.
    placements: Vec<BodyPlacement<D>>,
    /// Motion of the partner's material point at each contact node since the slip origin
    /// ([`ContactGeometry::set_partner_motion`]); empty: none.
    partner_motion: Vec<Vector<D>>,
}

/// The friction operator for given slip bounds: constraints plus the contact node of each cell.
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionOperator {
    /// `B_Ht` rows and shift.
    pub constraints: FrictionConstraints,
    /// `cell_node[c]` = index (into [`ContactGeometry::nodes`]) of the node of friction cell `c`.
    pub cell_node: Vec<usize>,
    /// `g_c` of each cell.
    pub slip_bound: Vec<Real>,
}

fn tangent_basis<const D: usize>(n: &Vector<D>) -> [Vector<D>; 2] {
    let mut t = [Vector::<D>::zeros(); 2];
    if D == 2 {
        t[0][0] = -n[1];
        t[0][1] = n[0];
    } else if D == 3 {
        // axis least aligned with n
        let k = (0..3).min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs())).unwrap_or(0);
        let mut e = Vector::<D>::zeros();
        e[k] = 1.0;
        let t1 = e - n * n.dot(&e);
        let t1 = t1 / t1.norm();
        let t2 = Vector::<D>::from_fn(|i, _| {
            let (a, b) = ((i + 1) % 3, (i + 2) % 3);
            n[a] * t1[b] - n[b] * t1[a]
        });
        t[0] = t1;
        t[1] = t2;
    }
    t
}

impl<const D: usize> ContactNode<D> {
    /// The jump `[u](s_r) = u^k(s_r) − u^l(s_r)` of nodal displacements `displacement[body][node]`:
    /// `u^l` is the partner node's (node-to-node), `Σ_j w_j u^l_j` (node-to-segment) or 0
    /// (rigid obstacle). `None` if the displacements do not fit the node.
    pub fn jump(&self, displacement: &[Vec<Vector<D>>]) -> Option<Vector<D>> {
        self.jump_mapped(displacement, |_, u| *u)
    }

    /// [`ContactNode::jump`] with each nodal displacement passed through `map(body, u)` first
    /// (e.g. from a body frame into space).
    fn jump_mapped(
        &self,
        displacement: &[Vec<Vector<D>>],
        map: impl Fn(BodyId, &Vector<D>) -> Vector<D>,
    ) -> Option<Vector<D>> {
        let at = |b: BodyId, i: usize| displacement.get(b.0).and_then(|u| u.get(i)).map(|u| map(b, u));
        let mut j = at(self.node.0, self.node.1)?;
        if let Some((b, i)) = self.partner {
            j -= at(b, i)?;
        }
        for &(b, i, w) in &self.master {
            j -= at(b, i)? * w;
        }
        Some(j)
    }
}

impl<const D: usize> ContactGeometry<D> {
    /// Builds the contact nodes of every pair in the reference configuration.
    pub fn new(model: &Model<D>, pairs: &[ContactPair<D>]) -> Result<Self, ContactError> {
        Self::build(model, pairs, None, true, None)
    }

    /// Builds the contact nodes of every pair in the configuration `x + u⁰`, `u⁰ =
    /// displacement[body][node]` (a pose; see the [module docs](self)): pairing of
    /// node-to-segment pairs, normals, tangents, weights and the evaluation point of rigid
    /// obstacles are those of the pose, the gaps are in total form (the constraints act on the
    /// displacement from the reference configuration). With `u⁰ = 0` it equals
    /// [`ContactGeometry::new`].
    pub fn new_deformed(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        displacement: &[Vec<Vector<D>>],
    ) -> Result<Self, ContactError> {
        check_pose(model, displacement)?;
        Self::build(model, pairs, Some(displacement), true, None)
    }

    /// [`ContactGeometry::new_deformed`] through the discretisations' re-pairing hook
    /// ([`ContactDiscretisation::update`]): each pair of `pairs` gets the contact nodes it has in
    /// `self` (same pair name); a pair without any is built from scratch.
    ///
    /// # Errors
    /// As [`ContactGeometry::new_deformed`].
    ///
    /// A geometry built with placements ([`ContactGeometry::new_placed`]) keeps them: the
    /// displacements are then in the bodies' frames, the configuration is the placed deformed
    /// one, `y = P_b(x + u) = x + (P_b(x) − x) + R_b u`, and the gaps are in total form for
    /// displacements from the placed configuration,
    ///
    /// ```text
    /// d_r = φ_r(y) + [R u⁰]_r · n_r      (rows on u in the bodies' frames, R_bᵀ n_r)
    /// ```
    ///
    /// so a finite-strain Newton iteration on bodies moved by large rigid motions keeps the
    /// bodies' own stiffness (docs/model.md §12, "Bodies in their own frames").
    pub fn updated(
        &self,
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        displacement: &[Vec<Vector<D>>],
    ) -> Result<Self, ContactError> {
        check_pose(model, displacement)?;
        if self.placements.iter().all(BodyPlacement::is_identity) {
            return Self::build(model, pairs, Some(displacement), true, Some(self));
        }
        if self.placements.len() != model.bodies().len() {
            return Err(ContactError::InvalidParameter(format!(
                "a geometry placed for {} bodies updated on a model of {}",
                self.placements.len(),
                model.bodies().len()
            )));
        }
        // the placed deformed configuration as a displacement of the reference mesh:
        // w = (P(x) − x) + R u, and the placement's own part o = P(x) − x
        let offsets = placement_offsets(model, &self.placements);
        let world: Vec<Vec<Vector<D>>> = offsets
            .iter()
            .zip(displacement)
            .zip(&self.placements)
            .map(|((o, u), p)| o.iter().zip(u).map(|(o, u)| o + p.to_global(u)).collect())
            .collect();
        let mut geometry = Self::build(model, pairs, Some(&world), true, Some(self))?;
        // total form in w: φ + [w]·n; the rows act on u from the placed configuration, so
        // the placement's part [o]·n comes off: φ + [R u]·n
        for node in &mut geometry.nodes {
            node.gap -= node.jump(&offsets).map_or(0.0, |j| j.dot(&node.normal));
        }
        geometry.placements.clone_from(&self.placements);
        Ok(geometry)
    }

    /// Builds the contact nodes of every pair with body `b` placed at `placements[b]`
    /// ([`BodyPlacement`]: one per body of the model, in order): pairing, normals, tangents,
    /// weights and gaps are those of the placed bodies, and the constraint rows act on
    /// displacements in each body's frame (coefficients `R_bᵀ n`). Loads, prescribed
    /// displacements and the solution of a body are then in its frame as well (rotate them with
    /// [`BodyPlacement::to_global`] / [`BodyPlacement::to_body`]); the stiffness is that of the
    /// reference mesh, so a factorisation of `A` serves every placement
    /// ([`crate::StaticContact::place_bodies`]). With identity placements it equals
    /// [`ContactGeometry::new`].
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] if there is not one placement per body, or if two
    /// tied bodies (which share nodes) have different placements; the errors of
    /// [`ContactGeometry::new`].
    pub fn new_placed(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        placements: &[BodyPlacement<D>],
    ) -> Result<Self, ContactError> {
        let bodies = model.bodies();
        if placements.len() != bodies.len() {
            return Err(ContactError::InvalidParameter(format!(
                "{} body placements for {} bodies (one per body)",
                placements.len(),
                bodies.len()
            )));
        }
        for tie in model.ties() {
            if placements[tie.body_a.0] != placements[tie.body_b.0] {
                return Err(ContactError::InvalidParameter(format!(
                    "tied bodies `{}` and `{}` must have the same placement",
                    bodies[tie.body_a.0].name, bodies[tie.body_b.0].name
                )));
            }
        }
        if placements.iter().all(BodyPlacement::is_identity) {
            return Self::build(model, pairs, None, true, None);
        }
        // the placed configuration as a displacement u⁰ = R x + t − x of the reference mesh
        let offsets = placement_offsets(model, placements);
        // the rows act on the displacement from the placed configuration: gaps of the placed
        // bodies, not in total form
        let mut geometry = Self::build(model, pairs, Some(&offsets), false, None)?;
        geometry.placements = placements.to_vec();
        Ok(geometry)
    }

    /// The placement of `body` ([`ContactGeometry::new_placed`]; identity otherwise).
    pub fn placement(&self, body: BodyId) -> BodyPlacement<D> {
        self.placements.get(body.0).copied().unwrap_or_default()
    }

    /// The jump `[u](s_r)` of contact node `r` in space for nodal displacements
    /// `displacement[body][node]` in the bodies' frames: [`ContactNode::jump`] with each body's
    /// displacement rotated by its placement. `None` if `r` or the displacements do not fit.
    pub fn jump(&self, r: usize, displacement: &[Vec<Vector<D>>]) -> Option<Vector<D>> {
        let node = self.nodes.get(r)?;
        if self.placements.is_empty() {
            return node.jump(displacement);
        }
        node.jump_mapped(displacement, |b, u| self.placement(b).to_global(u))
    }

    /// Sets the motion `w_r` of the partner's material point at each contact node since the
    /// slip origin (the previous level): for a rigid partner moved from pose `P_{i−1}` to `P_i`,
    /// `w_r = P_i(P_{i−1}⁻¹(y_r)) − y_r` at the node's deformed position `y_r`. Incremental slip
    /// (docs/model.md (3.9)) is then measured relative to the partner,
    /// `[v_t] − ([u_t(t_{i−1})] + w_{r,t})` ([`ContactGeometry::slip_origin`]). An empty vector
    /// removes it (partners at rest, the default).
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] unless there is one finite vector per contact node
    /// (or none).
    pub fn set_partner_motion(&mut self, motion: Vec<Vector<D>>) -> Result<(), ContactError> {
        if !(motion.is_empty() || motion.len() == self.nodes.len())
            || motion.iter().any(|w| w.iter().any(|v| !v.is_finite()))
        {
            return Err(ContactError::InvalidParameter(format!(
                "partner motion: {} vectors (all finite) needed for {} contact nodes, {} given",
                self.nodes.len(),
                self.nodes.len(),
                motion.len()
            )));
        }
        self.partner_motion = motion;
        Ok(())
    }

    /// The partner motion set by [`ContactGeometry::set_partner_motion`] (empty: none).
    pub fn partner_motion(&self) -> &[Vector<D>] {
        &self.partner_motion
    }

    /// The origin of the incremental slip at contact node `r`: the jump `[u](s_r)` of the
    /// previous level's displacements plus the partner's motion since then (if set),
    /// `[u_{i−1}](s_r) + w_r`. `None` if the displacements do not fit the node.
    pub fn slip_origin(&self, r: usize, previous: &[Vec<Vector<D>>]) -> Option<Vector<D>> {
        let j = self.jump(r, previous)?;
        Some(match self.partner_motion.get(r) {
            Some(w) => j + w,
            None => j,
        })
    }

    fn build(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        displacement: Option<&[Vec<Vector<D>>]>,
        total_form: bool,
        previous: Option<&ContactGeometry<D>>,
    ) -> Result<Self, ContactError> {
        // positions of the configuration the geometry is built on
        let posed: Vec<Vec<Point<D>>> = model
            .bodies()
            .iter()
            .enumerate()
            .map(|(b, body)| match displacement {
                Some(u) => body.mesh.nodes().iter().zip(&u[b]).map(|(x, v)| x + v).collect(),
                None => body.mesh.nodes().to_vec(),
            })
            .collect();
        let mut parts = Vec::with_capacity(pairs.len());
        for pair in pairs {
            parts.push(PartData::new(model, pair, &posed[pair.body.0])?);
        }
        Self::build_from(model, pairs, &posed, &mut parts, displacement, total_form, previous)
    }

    /// [`ContactGeometry::new`] with what does not depend on the partners' poses — the
    /// reference positions, and per pair the weights, normals, shortest edge and duplicate
    /// check of its part and the adjacency of its rows — taken from `cache` when it still
    /// fits the model (same node positions, same part facets) and kept there otherwise: a
    /// rebuild at a new pose of a rigid partner then only asks the discretisations for their
    /// rows. Equal to [`ContactGeometry::new`].
    ///
    /// # Errors
    /// As [`ContactGeometry::new`].
    pub fn new_cached(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        cache: &mut GeometryCache<D>,
    ) -> Result<Self, ContactError> {
        let bodies = model.bodies();
        let fits = cache.positions.len() == bodies.len()
            && cache.positions.iter().zip(bodies).all(|(p, b)| p.as_slice() == b.mesh.nodes());
        if !fits {
            *cache = GeometryCache {
                positions: bodies.iter().map(|b| b.mesh.nodes().to_vec()).collect(),
                parts: Vec::new(),
            };
        }
        // taken out while the geometry is built (put back on success)
        let mut kept = std::mem::take(&mut cache.parts);
        let mut parts = Vec::with_capacity(pairs.len());
        for pair in pairs {
            check_friction(pair)?;
            let body = model.body(pair.body)?;
            let part = body.mesh.boundary_part(&pair.part)?;
            let found = kept.iter().position(|d| {
                d.body == pair.body && d.part == pair.part && d.facets.iter().eq(part.facets().flatten())
            });
            parts.push(match found {
                Some(i) => kept.swap_remove(i),
                None => PartData::new(model, pair, &cache.positions[pair.body.0])?,
            });
        }
        let geometry = Self::build_from(model, pairs, &cache.positions, &mut parts, None, true, None)?;
        // the parts of these pairs, and at most as many others (pairs that alternate)
        kept.truncate(parts.len());
        parts.extend(kept);
        cache.parts = parts;
        Ok(geometry)
    }

    #[allow(clippy::too_many_arguments)]
    fn build_from(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        posed: &[Vec<Point<D>>],
        parts: &mut [PartData<D>],
        displacement: Option<&[Vec<Vector<D>>]>,
        total_form: bool,
        previous: Option<&ContactGeometry<D>>,
    ) -> Result<Self, ContactError> {
        let mut nodes = Vec::new();
        let mut ranges = Vec::new();
        let mut adjacency: Vec<Vec<usize>> = Vec::new();
        for (pi, (pair, data)) in pairs.iter().zip(parts.iter_mut()).enumerate() {
            check_friction(pair)?;
            let invalid = |reason: String| ContactError::InvalidPair { pair: pair.name.clone(), reason };
            let pos_k = &posed[pair.body.0];
            let start = nodes.len();
            let context = PairContext {
                model,
                name: &pair.name,
                body: pair.body,
                part: &pair.part,
                positions: posed,
                posed: displacement.is_some(),
                normals: &data.normals,
                weights: &data.weights,
                min_edge: data.min_edge,
            };
            let rows = match previous.and_then(|g| g.pair_nodes(&pair.name)) {
                Some(old) => pair.discretisation.update(&context, old)?,
                None => pair.discretisation.rows(&context)?,
            };
            let mut seen = vec![false; data.on_part.len()];
            nodes.reserve(rows.len());
            for row in rows {
                check_row(model, &data.on_part, &row).map_err(&invalid)?;
                if std::mem::replace(&mut seen[row.node], true) {
                    return Err(invalid(format!("two rows for node {} of part `{}`", row.node, pair.part)));
                }
                let mut node = ContactNode {
                    pair: pi,
                    node: (pair.body, row.node),
                    partner: row.partner,
                    master: row.master,
                    position: pos_k[row.node],
                    normal: row.normal,
                    tangents: tangent_basis(&row.normal),
                    weight: row.weight,
                    gap: row.gap,
                    friction: pair.friction,
                };
                // total form: d(x + u⁰) + [u⁰] · n
                if let (true, Some(u)) = (total_form, displacement) {
                    node.gap += node.jump(u).map_or(0.0, |j| j.dot(&node.normal));
                }
                nodes.push(node);
            }
            if nodes.len() == start {
                return Err(invalid("the contact part has no nodes".into()));
            }
            // adjacency of the new rows through the facets of part k (kept for the same rows)
            let same_rows = data
                .adjacency
                .as_ref()
                .is_some_and(|(kept, _)| kept.iter().eq(nodes[start..].iter().map(|n| &n.node.1)));
            if !same_rows {
                data.adjacency = Some(data.row_adjacency(&nodes[start..]));
            }
            if let Some((_, local)) = &data.adjacency {
                adjacency.extend(local.iter().map(|a| a.iter().map(|&r| r + start).collect::<Vec<usize>>()));
            }
            ranges.push((pair.name.clone(), start..nodes.len()));
        }
        Ok(Self {
            pairs: ranges,
            nodes,
            adjacency,
            placements: Vec::new(),
            report_splits: pairs.iter().map(|p| p.report_split.clone()).collect(),
            partner_motion: Vec::new(),
        })
    }

    /// The contact nodes of the pair called `name`, if any.
    pub fn pair_nodes(&self, name: &str) -> Option<&[ContactNode<D>]> {
        self.pairs.iter().find(|(n, _)| n == name).and_then(|(_, r)| self.nodes.get(r.clone()))
    }

    /// Number of contact nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }
    /// `true` if there are no contact nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// `(u^k − u^l)` of node `r` as reduced-row entries of `v · (u^k − u^l)` (plus the lift part);
    /// `u^l = Σ_j w_j u^l_j` for node-to-segment.
    fn relative_row(
        &self,
        dofs: &DofMap<D>,
        lifts: &[Vector<D>],
        r: usize,
        v: &Vector<D>,
    ) -> (Vec<(usize, Real)>, Real) {
        let node = &self.nodes[r];
        let mut entries = Vec::with_capacity(2 * D);
        // v in the frame of `body` (rows act on displacements in the bodies' frames)
        let framed = |body: BodyId| match self.placements.get(body.0) {
            Some(p) => p.to_body(v),
            None => *v,
        };
        let mut lift = 0.0;
        let mut add = |body: BodyId, i: usize, w: Real| {
            let vb = framed(body);
            let gi = dofs.group_of(body, i);
            let g = &dofs.groups()[gi];
            for k in 0..g.n_dofs {
                entries.push((g.first_dof + k, w * g.basis[k].dot(&vb)));
            }
            lift += w * lifts[gi].dot(&vb);
        };
        add(node.node.0, node.node.1, 1.0);
        if let Some((bl, j)) = node.partner {
            add(bl, j, -1.0);
        }
        for &(bl, j, w) in &node.master {
            add(bl, j, -w);
        }
        (entries, lift)
    }

    /// One row per contact node on every free dof of the node, its partner and its master
    /// nodes (value 1): the dofs its normal and tangential rows can use whatever their
    /// directions (a row drops the dofs its direction has no component along).
    pub(crate) fn node_dof_rows(&self, dofs: &DofMap<D>) -> SparseRows {
        let mut rows = SparseRows::new(dofs.n_dofs());
        for node in &self.nodes {
            let mut entries = Vec::with_capacity(2 * D);
            let mut add = |body: BodyId, i: usize| {
                let g = &dofs.groups()[dofs.group_of(body, i)];
                entries.extend((0..g.n_dofs).map(|k| (g.first_dof + k, 1.0)));
            };
            add(node.node.0, node.node.1);
            if let Some((b, j)) = node.partner {
                add(b, j);
            }
            for &(b, j, _) in &node.master {
                add(b, j);
            }
            rows.push_row(entries);
        }
        rows
    }

    /// `B_hn`, `κ` and the reduced gaps `d − [u_p]_n` for the lifts `u_p` of prescribed
    /// displacements at the current time.
    pub fn normal_constraints(&self, dofs: &DofMap<D>, lifts: &[Vector<D>]) -> NormalConstraints {
        let mut rows = SparseRows::new(dofs.n_dofs());
        let mut weights = Vec::with_capacity(self.len());
        let mut gap = Vec::with_capacity(self.len());
        for r in 0..self.len() {
            let n = self.nodes[r].normal;
            let (entries, lift) = self.relative_row(dofs, lifts, r, &n);
            rows.push_row(entries);
            weights.push(self.nodes[r].weight);
            gap.push(self.nodes[r].gap - lift);
        }
        NormalConstraints { rows, weights, gap }
    }

    /// `[u]·n_r − d_r` per contact node for nodal displacements `displacement[body][node]`
    /// (total, from the reference configuration): the penetration where positive, minus the open
    /// gap where negative. On a geometry rebuilt at the pose `u` itself
    /// ([`ContactGeometry::new_deformed`]) this is the signed distance of the pose's slave nodes
    /// to their master facets, negated.
    pub fn penetration(&self, displacement: &[Vec<Vector<D>>]) -> Result<Vec<Real>, ContactError> {
        (0..self.len())
            .map(|r| {
                let n = &self.nodes[r];
                self.jump(r, displacement).map(|j| j.dot(&n.normal) - n.gap).ok_or_else(|| {
                    ContactError::InvalidParameter("displacements do not fit the contact nodes".into())
                })
            })
            .collect()
    }

    /// For each contact node of `self`, the index of the node of `from` with the same pair index
    /// and body-`k` node (`None` if `from` has none): carries nodal contact data (e.g. `Λ_n`)
    /// to a rebuilt geometry.
    pub fn node_map(&self, from: &ContactGeometry<D>) -> Vec<Option<usize>> {
        let index: std::collections::HashMap<(usize, BodyId, usize), usize> =
            from.nodes.iter().enumerate().map(|(r, n)| ((n.pair, n.node.0, n.node.1), r)).collect();
        self.nodes.iter().map(|n| index.get(&(n.pair, n.node.0, n.node.1)).copied()).collect()
    }

    /// Whether `self` has the rows of `other`, node for node in the same order (then
    /// [`ContactGeometry::transfer`] from it is the identity).
    pub fn same_rows(&self, other: &ContactGeometry<D>) -> bool {
        self.nodes.len() == other.nodes.len()
            && self.nodes.iter().zip(&other.nodes).all(|(a, b)| a.pair == b.pair && a.node == b.node)
    }

    /// Nodal values of `from` (one per node of `from`) carried to the nodes of `self` through
    /// [`ContactGeometry::node_map`]; nodes new in `self` get 0.
    pub fn transfer(&self, from: &ContactGeometry<D>, values: &[Real]) -> Vec<Real> {
        self.node_map(from)
            .into_iter()
            .map(|r| r.and_then(|r| values.get(r)).copied().unwrap_or(0.0))
            .collect()
    }

    /// Tresca slip bounds `g_{c,r} = F_c |Λ_n,r|` from nodal pressures (docs/model.md §3).
    pub fn slip_bounds_from_pressure(&self, lambda_n: &[Real]) -> Vec<Real> {
        self.nodes.iter().zip(lambda_n).map(|(n, l)| n.friction * l.abs()).collect()
    }

    /// `B_Ht` for the slip bounds `g_c` (one per contact node; cells with `g_c = 0` are left out),
    /// with the shift `s = B_Ht (U_prev − u_p)` of incremental slip when the previous nodal
    /// displacements `previous[body][node]` are given (docs/model.md §3: slip measured from the previous
    /// time level).
    pub fn friction_constraints(
        &self,
        dofs: &DofMap<D>,
        lifts: &[Vector<D>],
        slip_bound: &[Real],
        previous: Option<&[Vec<Vector<D>>]>,
    ) -> Result<FrictionOperator, ContactError> {
        if slip_bound.len() != self.len() {
            return Err(ContactError::InvalidParameter(format!(
                "{} slip bounds for {} contact nodes",
                slip_bound.len(),
                self.len()
            )));
        }
        let mut rows = SparseRows::new(dofs.n_dofs());
        let mut shift = Vec::new();
        let mut cell_node = Vec::new();
        let mut bounds = Vec::new();
        for (r, &g) in slip_bound.iter().enumerate() {
            if !g.is_finite() || g < 0.0 {
                return Err(ContactError::InvalidParameter(format!(
                    "slip bound g_c = {g} at contact node {r}"
                )));
            }
            if g == 0.0 {
                continue;
            }
            let node = &self.nodes[r];
            let scale = g * node.weight;
            for t in node.tangents.iter().take(D - 1) {
                let (entries, lift) = self.relative_row(dofs, lifts, r, t);
                rows.push_row(entries.into_iter().map(|(c, v)| (c, scale * v)));
                let prev = match previous {
                    Some(p) => t.dot(&self.slip_origin(r, p).ok_or_else(|| {
                        ContactError::InvalidParameter(
                            "previous displacements do not fit the contact nodes".into(),
                        )
                    })?),
                    None => 0.0,
                };
                shift.push(scale * (prev - lift));
            }
            cell_node.push(r);
            bounds.push(g);
        }
        Ok(FrictionOperator {
            constraints: FrictionConstraints { rows, components: D - 1, shift },
            cell_node,
            slip_bound: bounds,
        })
    }
}

/// `Err` unless `row` is a valid contact row: its node on the slave part, the other side's
/// nodes in the model, a finite unit normal, finite weights and gap.
/// What [`ContactGeometry::new_cached`] keeps between rebuilds on the reference meshes (a
/// rigid partner that moves from pose to pose, e.g. a navigation session): the reference node
/// positions of every body and, per pair, the data of its part that do not depend on the
/// partner's pose (lumped weights, nodal normals, shortest edge, the duplicate check, the
/// adjacency of its rows). Checked against the model at every rebuild (positions and part
/// facets compared entry by entry) and rebuilt when they differ; holds the data of at most
/// twice as many parts as the last rebuild's pairs.
#[derive(Debug, Clone, Default)]
pub struct GeometryCache<const D: usize> {
    positions: Vec<Vec<Point<D>>>,
    parts: Vec<PartData<D>>,
}

impl<const D: usize> GeometryCache<D> {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }
    /// Number of pair parts whose data are kept.
    pub fn len(&self) -> usize {
        self.parts.len()
    }
    /// `true` if no part's data are kept.
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }
}

/// The data of a pair's slave part at given positions that every discretisation shares
/// ([`PairContext`]): lumped weights, nodal normals, the shortest facet edge (reference mesh),
/// the part's nodes, and the adjacency of the pair's rows (for the rows' node order it was
/// built for).
#[derive(Debug, Clone)]
struct PartData<const D: usize> {
    body: BodyId,
    part: String,
    /// The part's facets, flattened (to check that a kept entry still fits the mesh).
    facets: Vec<usize>,
    weights: std::collections::HashMap<usize, Real>,
    min_edge: Real,
    normals: Vec<(usize, Vector<D>)>,
    /// By node of the body: whether it is on the part.
    on_part: Vec<bool>,
    /// The row nodes (in row order) and each row's neighbours (row indices of the pair,
    /// sorted): rows sharing a facet of the part.
    adjacency: Option<(Vec<usize>, Vec<Vec<usize>>)>,
}

fn check_friction<const D: usize>(pair: &ContactPair<D>) -> Result<(), ContactError> {
    if pair.friction.is_finite() && pair.friction >= 0.0 {
        return Ok(());
    }
    Err(ContactError::InvalidPair {
        pair: pair.name.clone(),
        reason: format!("friction coefficient {} must be finite and ≥ 0", pair.friction),
    })
}

impl<const D: usize> PartData<D> {
    /// The data of `pair`'s part at the positions `pos_k` of its body's nodes.
    fn new(model: &Model<D>, pair: &ContactPair<D>, pos_k: &[Point<D>]) -> Result<Self, ContactError> {
        check_friction(pair)?;
        let invalid = |reason: String| ContactError::InvalidPair { pair: pair.name.clone(), reason };
        let body = model.body(pair.body)?;
        let part = body.mesh.boundary_part(&pair.part)?;
        // lumped weights and nodal normals of part k
        let mut weights = std::collections::HashMap::new();
        let mut min_edge = Real::INFINITY;
        for f in part.facets() {
            let m = area_normal(pos_k, f).norm() / D as Real;
            for (a, &i) in f.iter().enumerate() {
                *weights.entry(i).or_insert(0.0) += m;
                for &j in &f[..a] {
                    min_edge = min_edge.min((body.mesh.node(i) - body.mesh.node(j)).norm());
                }
            }
        }
        let normals = nodal_normals_at(pos_k, part.facets());
        let reference = |i: usize| *body.mesh.node(i);
        // distinct nodes of the part at the same reference position (a duplicated node,
        // e.g. an unmerged mesh seam) would give two constraints on one point
        {
            let mut seen: std::collections::HashMap<[u64; D], usize> = std::collections::HashMap::new();
            for i in part.nodes() {
                let key: [u64; D] = std::array::from_fn(|a| (reference(i)[a] + 0.0).to_bits());
                if let Some(j) = seen.insert(key, i) {
                    return Err(invalid(format!(
                        "nodes {j} and {i} of part `{}` of body `{}` coincide at {:?} (duplicated node)",
                        pair.part,
                        body.name,
                        reference(i).as_slice()
                    )));
                }
            }
        }
        let mut on_part = vec![false; body.mesh.n_nodes()];
        for &(i, _) in &normals {
            if let Some(o) = on_part.get_mut(i) {
                *o = true;
            }
        }
        Ok(Self {
            body: pair.body,
            part: pair.part.clone(),
            facets: part.facets().flatten().copied().collect(),
            weights,
            min_edge,
            normals,
            on_part,
            adjacency: None,
        })
    }

    /// The adjacency of rows on the nodes of `rows` (in order) through the part's facets.
    fn row_adjacency(&self, rows: &[ContactNode<D>]) -> (Vec<usize>, Vec<Vec<usize>>) {
        let mut row_of = vec![usize::MAX; self.on_part.len()];
        for (r, node) in rows.iter().enumerate() {
            row_of[node.node.1] = r;
        }
        let mut adjacency = vec![Vec::new(); rows.len()];
        for f in self.facets.chunks_exact(D.max(1)) {
            for &a in f {
                for &b in f {
                    let (ra, rb) = (row_of[a], row_of[b]);
                    if ra != usize::MAX && rb != usize::MAX && ra != rb {
                        adjacency[ra].push(rb);
                    }
                }
            }
        }
        for a in adjacency.iter_mut() {
            a.sort_unstable();
            a.dedup();
        }
        (rows.iter().map(|n| n.node.1).collect(), adjacency)
    }
}

fn check_row<const D: usize>(model: &Model<D>, on_part: &[bool], row: &ContactRow<D>) -> Result<(), String> {
    if !on_part.get(row.node).copied().unwrap_or(false) {
        return Err(format!("row for node {}, which is not on the contact part", row.node));
    }
    let exists = |b: BodyId, j: usize| model.bodies().get(b.0).is_some_and(|body| j < body.mesh.n_nodes());
    for (b, j) in row.partner.iter().copied().chain(row.master.iter().map(|&(b, j, _)| (b, j))) {
        if !exists(b, j) {
            return Err(format!(
                "row of node {} refers to node {j} of body {}, which does not exist",
                row.node, b.0
            ));
        }
    }
    let n = row.normal.norm();
    if !(n.is_finite() && (n - 1.0).abs() <= 1e-8) {
        return Err(format!(
            "row of node {}: the normal must be a finite unit vector (length {n:e})",
            row.node
        ));
    }
    if !(row.weight.is_finite() && row.gap.is_finite() && row.master.iter().all(|m| m.2.is_finite())) {
        return Err(format!(
            "row of node {}: weight {} and gap {} (and the partner weights) must be finite",
            row.node, row.weight, row.gap
        ));
    }
    Ok(())
}

/// `Err` unless `displacement` has one finite vector per node of every body of `model`.
/// The placed configuration of every body as a displacement of its reference mesh,
/// `o = P_b(x) − x` per node (one placement per body).
fn placement_offsets<const D: usize>(
    model: &Model<D>,
    placements: &[BodyPlacement<D>],
) -> Vec<Vec<Vector<D>>> {
    model
        .bodies()
        .iter()
        .zip(placements)
        .map(|(b, p)| b.mesh.nodes().iter().map(|x| p.position(x) - x).collect())
        .collect()
}

fn check_pose<const D: usize>(model: &Model<D>, displacement: &[Vec<Vector<D>>]) -> Result<(), ContactError> {
    let bodies = model.bodies();
    let fits = displacement.len() == bodies.len()
        && bodies
            .iter()
            .zip(displacement)
            .all(|(b, u)| u.len() == b.mesh.n_nodes() && u.iter().all(|v| v.iter().all(|c| c.is_finite())));
    if fits {
        Ok(())
    } else {
        Err(ContactError::InvalidParameter(
            "the displacement of the pose does not fit the model (one finite vector per node of every body)"
                .into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;
    use synovia_mesh::generators::{box_mesh, Grading};

    /// A unit box whose top is the contact part of a rigid sphere obstacle centred at
    /// `centre` (shared: the partner moves), with a search distance; and a node-to-segment
    /// pair of its right side against a wall (a pair whose rows do not move).
    fn boxed(n: usize, centre: Arc<Mutex<Point<3>>>) -> (Model<3>, Vec<ContactPair<3>>) {
        let mesh = box_mesh([0.0; 3], [1.0; 3], [n, n, n], [Grading::Uniform; 3]).expect("mesh");
        let mut model = Model::<3>::new();
        let material = synovia_material::isotropic(1.0, 0.3).expect("material");
        let material = Arc::new(material);
        let b = model.add_body("box", mesh, material.clone()).expect("body");
        let wall =
            box_mesh([1.01, 0.0, 0.0], [2.0, 1.0, 1.0], [2, 3, 3], [Grading::Uniform; 3]).expect("mesh");
        let w = model.add_body("wall", wall, material).expect("body");
        let sphere = FnObstacle::new(move |x: &Point<3>| {
            let c = *centre.lock().expect("centre");
            let d = x - c;
            let len = d.norm();
            (len - 1.0, d / len)
        });
        let pairs = vec![
            ContactPair::rigid("top", b, "top", Arc::new(sphere)).with_search_distance(0.05),
            ContactPair::node_to_segment("sides", b, "right", w, "left").with_friction(0.2),
        ];
        (model, pairs)
    }

    /// Rebuilds at poses of a moving partner with the kept pose-independent data equal fresh
    /// builds exactly (nodes, normals, gaps, weights, adjacency); a model with another mesh
    /// refreshes the cache instead of using it.
    #[test]
    fn cached_rebuilds_equal_fresh_builds() {
        let centre = Arc::new(Mutex::new(Point::<3>::new(0.5, 0.5, 2.02)));
        let (model, pairs) = boxed(4, centre.clone());
        let mut cache = GeometryCache::new();
        assert!(cache.is_empty());
        for pose in 0..5 {
            let s = pose as Real;
            *centre.lock().expect("centre") = Point::<3>::new(0.4 + 0.05 * s, 0.5 - 0.03 * s, 2.0 - 0.01 * s);
            let fresh = ContactGeometry::new(&model, &pairs).expect("fresh");
            let cached = ContactGeometry::new_cached(&model, &pairs, &mut cache).expect("cached");
            assert_eq!(cached, fresh, "pose {pose}");
            assert_eq!(cache.len(), 2);
            // the far rows keep the body's normal, the near ones the sphere's: rows changed
            assert!(fresh.nodes.iter().any(|n| n.gap <= 0.05) && fresh.nodes.iter().any(|n| n.gap > 0.05));
        }
        // another mesh (finer): the kept data do not fit it
        let (finer, finer_pairs) = boxed(5, centre.clone());
        let fresh = ContactGeometry::new(&finer, &finer_pairs).expect("fresh");
        let cached = ContactGeometry::new_cached(&finer, &finer_pairs, &mut cache).expect("cached");
        assert_eq!(cached, fresh);
        assert_eq!(cache.len(), 2);
        // an invalid pair is an error with or without the cache
        let mut bad = pairs.clone();
        bad[1].friction = -1.0;
        assert!(ContactGeometry::new_cached(&model, &bad, &mut cache).is_err());
        assert!(ContactGeometry::new(&model, &bad).is_err());
        // and the cache still serves the valid pairs afterwards
        let cached = ContactGeometry::new_cached(&model, &pairs, &mut cache).expect("cached");
        assert_eq!(cached, ContactGeometry::new(&model, &pairs).expect("fresh"));
    }

    /// A placed geometry updated on displacements in the bodies' frames equals the geometry
    /// of the moved meshes updated on the same displacements in space (`R u`): nodes,
    /// normals, weights and gaps in total form, and the jumps its rows measure.
    #[test]
    fn placed_deformed_geometry_equals_the_moved_meshes() {
        let centre = Arc::new(Mutex::new(Point::<3>::new(0.5, 0.5, 2.02)));
        let (model, pairs) = boxed(3, centre.clone());
        // the wall turned by 0.05 rad about the box's right face's vertical axis
        let axis = nalgebra::Unit::new_normalize(Vector::<3>::new(0.1, 0.2, 1.0));
        let rotation = *nalgebra::Rotation3::from_axis_angle(&axis, 0.05).matrix();
        let turned =
            BodyPlacement::rotation_about(Point::<3>::new(1.0, 0.5, 0.5), rotation).expect("rotation");
        let placements = vec![BodyPlacement::identity(), turned];
        // smooth displacements in the bodies' frames, the wall's towards the box
        let u: Vec<Vec<Vector<3>>> = model
            .bodies()
            .iter()
            .enumerate()
            .map(|(b, body)| {
                body.mesh
                    .nodes()
                    .iter()
                    .map(|x| {
                        let s = if b == 0 { 1.0 } else { -1.0 };
                        Vector::<3>::new(0.004 * s + 0.001 * x[1], 0.002 * x[2], -0.001 * x[0])
                    })
                    .collect()
            })
            .collect();
        let placed = ContactGeometry::new_placed(&model, &pairs, &placements)
            .expect("placed")
            .updated(&model, &pairs, &u)
            .expect("updated");
        let (mut moved_model, _) = boxed(3, centre);
        moved_model.body_mut(BodyId(1)).expect("wall").mesh.map_nodes(|x| turned.position(x)).expect("moved");
        let w: Vec<Vec<Vector<3>>> =
            u.iter().zip(&placements).map(|(u, p)| u.iter().map(|v| p.to_global(v)).collect()).collect();
        let moved = ContactGeometry::new(&moved_model, &pairs)
            .expect("moved")
            .updated(&moved_model, &pairs, &w)
            .expect("updated");
        assert_eq!(placed.len(), moved.len());
        assert_eq!(placed.placement(BodyId(1)), turned);
        let mut near = 0;
        for r in 0..placed.len() {
            let (a, b) = (&placed.nodes[r], &moved.nodes[r]);
            assert_eq!((a.node, a.partner), (b.node, b.partner), "row {r}");
            assert!((a.normal - b.normal).norm() < 1e-12, "row {r}: normals");
            assert!((a.weight - b.weight).abs() < 1e-12, "row {r}: weights");
            assert!((a.gap - b.gap).abs() < 1e-12, "row {r}: gaps {} and {}", a.gap, b.gap);
            let (ja, jb) = (placed.jump(r, &u).expect("jump"), moved.jump(r, &w).expect("jump"));
            assert!((ja - jb).norm() < 1e-12, "row {r}: jumps");
            near += usize::from(a.pair == 1 && a.gap < 0.05);
        }
        assert!(near > 0, "the turned wall is paired with the box's side");
        // a model of another number of bodies does not fit the placements
        let mut one = Model::<3>::new();
        let body = model.body(BodyId(0)).expect("box");
        one.add_body("box", body.mesh.clone(), body.material.clone()).expect("body");
        let err = ContactGeometry::new_placed(&model, &pairs, &placements)
            .expect("placed")
            .updated(&one, &pairs[..1], &u[..1])
            .expect_err("bodies");
        assert!(err.to_string().contains("bodies"), "{err}");
    }
}
