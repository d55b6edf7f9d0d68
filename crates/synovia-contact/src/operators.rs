//! Contact pairs and the discrete contact operators of docs/model.md §5.
//!
//! A [`ContactPair`] joins the contact part of a body `k` either to the contact part of another
//! body `l` with nodes at matching positions (node-to-node, the conforming case of the report),
//! to the contact part of another body `l` with an arbitrary (non-matching) mesh
//! (node-to-segment in 2D, node-to-facet in 3D: [`Partner::Segment`]; dual mortar:
//! [`Partner::Mortar`]), or to a rigid obstacle
//! described by a signed-distance function (the foundation case). For every contact node `s_r`
//! of body `k` [`ContactGeometry`] stores
//!
//! * the normal `n_r` (the outward nodal normal `n^k` of body `k`, docs/model.md §1, or a fixed
//!   direction; for node-to-segment the master facet's outward normal negated), and an
//!   orthonormal tangent basis,
//! * the lumped weight `κ_r = ∫_{Γ_c} φ_r ds` (row sums of the boundary mass of part `k`),
//! * the initial gap `d_r = (x_l − x_k) · n_r` (node-to-node), `d_r = (Σ_j w_j x_{l,j} − x_k) · n_r`
//!   (node-to-segment, `w_j` the weights of the projection of `x_k` on its master facet) or
//!   `d_r = φ(x_k)` (obstacle).
//!
//! From these, [`ContactGeometry::normal_constraints`] builds `B_hn` in the reduced unknowns of a
//! [`DofMap`] (`(B_hn U)_r = [U_n](s_r) = n_r · (u^k(s_r) − u^l(s_r))`, with
//! `u^l(s_r) = Σ_j w_j u^l_j` for node-to-segment), and
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
//! # Non-matching meshes: node-to-segment / node-to-facet
//!
//! For a [`Partner::Segment`] pair, part `k` is the *slave* side and part `l` the *master*
//! side. Every slave node `x_s` is projected onto the master facets with the R*-tree search of
//! [`crate::search`] (closest facet containing the orthogonal projection; see there for the
//! rule at convex master edges and at the rim of the master part). The pair uses
//!
//! * the normal `n = −n_l`, the master facet's outward unit normal negated (it points from `k`
//!   into `l`, like `n^k` of a conforming pair). The master normal, not the slave nodal normal,
//!   is used because then `d` is the exact distance of `x_s` to the master facet plane and a
//!   flat master surface gives the exact normal whatever the slave mesh;
//! * the master point `x_m = Σ_j w_j x_{l,j}` (barycentric weights on the facet's nodes,
//!   [`ContactNode::master`]), `[u_n] = (u_k − Σ_j w_j u_{l,j}) · n`,
//!   `d = (x_m − x_s) · n` (the signed distance, negative if `x_s` is inside body `l`);
//! * the tangent basis of `n` and the weight `κ_s` from the slave facets (the multipliers live
//!   on the slave side, docs/model.md §5).
//!
//! Slave nodes without a master facet — farther than the pair's search distance, facing no
//! master facet, or beyond the rim of the master part — are left out of the pair; they can
//! enter it when the geometry is rebuilt at a later pose. The operator is not exact for a
//! uniform pressure on non-matching meshes (the slave nodal forces are passed to the master
//! nodes by point interpolation, not by the mortar integral); see `docs/contact.md` for the
//! measured error.
//!
//! # Non-matching meshes: dual mortar
//!
//! A [`Partner::Mortar`] pair ([`ContactPair::mortar`]) couples slave part `k` and master part
//! `l` with Wohlmuth's dual (biorthogonal) multipliers ([`crate::mortar`]): `D` is diagonal, so
//! each slave node `j` keeps one row of the same form, `n_j · (u_j − Σ_k w_jk u_k) ≤ d_j` with
//! `w_jk = M_jk / D_jj` ([`ContactNode::master`]), `κ_j = D_jj` and `d_j = g̃_j / D_jj` (the
//! weighted gap), `n_j` the slave nodal normal. Friction rows use the slave tangent basis as
//! above. The solvers run unchanged; a uniform pressure is transmitted exactly.
//!
//! # Rebuilding the geometry at a pose
//!
//! [`ContactGeometry::new_deformed`] builds the pairing, normals, tangents and weights in the
//! configuration `x + u⁰` (a pose: rigid motion plus small elastic displacement), with
//! small-deformation kinematics from there. The constraints keep acting on the *total*
//! displacement `U` from the reference configuration, so the gap is returned in total form:
//! the linearised condition `([U] − [u⁰]) · n ≤ d(x + u⁰)` is `[U] · n ≤ d(x + u⁰) + [u⁰] · n`,
//! which for node-to-segment is `(Σ_j w_j X_{l,j} − X_s) · n` with the reference positions `X`
//! and the weights and normal of the pose. Node-to-node pairs keep the pairing of the
//! reference configuration (normals from the pose).

use std::fmt;
use std::sync::Arc;

use synovia_fem::{BodyId, DofMap, Model};
use synovia_mesh::matching::match_nodes;
use synovia_mesh::math::{Point, Real, Tensor, Vector};

use crate::error::ContactError;
use crate::problem::{FrictionConstraints, NormalConstraints};
use crate::search::{area_normal, FacetSearch};
use synovia_linalg::SparseRows;
use synovia_mesh::mesh::nodal_normals_at;

/// A rigid obstacle given by a signed distance `φ` (positive in the free space outside the
/// obstacle, negative inside) and its gradient.
pub trait SignedDistance<const D: usize>: Send + Sync + fmt::Debug {
    /// `φ(x)`.
    fn distance(&self, x: &Point<D>) -> Real;
    /// `∇φ(x)`: the unit normal of the obstacle surface pointing into the free space.
    fn gradient(&self, x: &Point<D>) -> Vector<D>;
    /// Checks the obstacle's parameters (finite, positive radius, unit directions); the
    /// error names the offending parameter. [`ContactGeometry::new`] calls it for every rigid
    /// pair and reports a failure as [`ContactError::InvalidPair`]. Default: no check.
    fn validate(&self) -> Result<(), String> {
        Ok(())
    }
}

/// `Err` naming `what` unless every entry of `v` is finite.
fn check_finite(what: &str, v: &[Real]) -> Result<(), String> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("{what} {v:?} is not finite"))
    }
}

/// `Err` unless `v` is a finite unit vector (within 1e-9).
fn check_unit(what: &str, v: &[Real]) -> Result<(), String> {
    check_finite(what, v)?;
    let n = v.iter().map(|x| x * x).sum::<Real>().sqrt();
    if (n - 1.0).abs() > 1e-9 {
        return Err(format!("{what} {v:?} must be a unit vector (length {n:e})"));
    }
    Ok(())
}

/// `Err` unless `r` is finite and positive.
fn check_radius(r: Real) -> Result<(), String> {
    if r.is_finite() && r > 0.0 {
        Ok(())
    } else {
        Err(format!("radius {r} must be finite and > 0"))
    }
}

/// The half-space `{(x − p) · n < 0}` is the obstacle; `n` points into the free space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneObstacle<const D: usize> {
    /// A point of the plane.
    pub point: Point<D>,
    /// Unit normal pointing out of the obstacle.
    pub normal: Vector<D>,
}

impl<const D: usize> PlaneObstacle<D> {
    /// A plane through `point` with normal `normal` (normalised; error if zero).
    pub fn new(point: Point<D>, normal: Vector<D>) -> Result<Self, ContactError> {
        let len = normal.norm();
        if !(len.is_finite() && len > 0.0) || point.iter().any(|x| !x.is_finite()) {
            return Err(ContactError::InvalidParameter(
                "plane obstacle needs a finite point and a non-zero normal".into(),
            ));
        }
        Ok(Self { point, normal: normal / len })
    }
}

impl<const D: usize> SignedDistance<D> for PlaneObstacle<D> {
    fn distance(&self, x: &Point<D>) -> Real {
        (x - self.point).dot(&self.normal)
    }
    fn gradient(&self, _x: &Point<D>) -> Vector<D> {
        self.normal
    }
    fn validate(&self) -> Result<(), String> {
        check_finite("plane point", self.point.as_slice())?;
        check_unit("plane normal", self.normal.as_slice())
    }
}

/// A rigid ball (circle in 2D) `|x − c| ≤ R`, or with `cavity = true` the outside of it (a
/// spherical socket whose inside is free).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereObstacle<const D: usize> {
    /// Centre.
    pub center: Point<D>,
    /// Radius `R > 0`.
    pub radius: Real,
    /// `true`: the body moves inside the sphere (socket); `false`: outside (ball).
    pub cavity: bool,
}

impl<const D: usize> SphereObstacle<D> {
    /// A ball (`cavity = false`) or spherical socket (`cavity = true`); error if the centre
    /// is not finite or the radius not finite and positive.
    pub fn new(center: Point<D>, radius: Real, cavity: bool) -> Result<Self, ContactError> {
        let s = Self { center, radius, cavity };
        s.validate().map_err(|m| ContactError::InvalidParameter(format!("sphere obstacle: {m}")))?;
        Ok(s)
    }
}

impl<const D: usize> SignedDistance<D> for SphereObstacle<D> {
    fn validate(&self) -> Result<(), String> {
        check_finite("sphere centre", self.center.as_slice())?;
        check_radius(self.radius)
    }
    fn distance(&self, x: &Point<D>) -> Real {
        let r = (x - self.center).norm();
        if self.cavity {
            self.radius - r
        } else {
            r - self.radius
        }
    }
    fn gradient(&self, x: &Point<D>) -> Vector<D> {
        let v = x - self.center;
        let r = v.norm();
        let g = if r > 0.0 { v / r } else { Vector::<D>::zeros() };
        if self.cavity {
            -g
        } else {
            g
        }
    }
}

/// A rigid infinite cylinder in 3D `dist(x, axis) ≤ R` (or its outside with `cavity`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderObstacle {
    /// A point of the axis.
    pub point: Point<3>,
    /// Unit axis direction.
    pub axis: Vector<3>,
    /// Radius.
    pub radius: Real,
    /// `true`: the free space is inside the cylinder.
    pub cavity: bool,
}

impl CylinderObstacle {
    /// A cylinder about the axis through `point` along `axis` (normalised); error if the point
    /// or axis is not finite, the axis is zero, or the radius not finite and positive.
    pub fn new(point: Point<3>, axis: Vector<3>, radius: Real, cavity: bool) -> Result<Self, ContactError> {
        let bad = |m: String| ContactError::InvalidParameter(format!("cylinder obstacle: {m}"));
        check_finite("cylinder axis", axis.as_slice()).map_err(bad)?;
        let len = axis.norm();
        if len <= 0.0 {
            return Err(bad("axis is zero".into()));
        }
        let s = Self { point, axis: axis / len, radius, cavity };
        s.validate().map_err(bad)?;
        Ok(s)
    }
}

impl SignedDistance<3> for CylinderObstacle {
    fn validate(&self) -> Result<(), String> {
        check_finite("cylinder point", self.point.as_slice())?;
        check_unit("cylinder axis", self.axis.as_slice())?;
        check_radius(self.radius)
    }
    fn distance(&self, x: &Point<3>) -> Real {
        let v = x - self.point;
        let r = (v - self.axis * v.dot(&self.axis)).norm();
        if self.cavity {
            self.radius - r
        } else {
            r - self.radius
        }
    }
    fn gradient(&self, x: &Point<3>) -> Vector<3> {
        let v = x - self.point;
        let radial = v - self.axis * v.dot(&self.axis);
        let r = radial.norm();
        let g = if r > 0.0 { radial / r } else { Vector::<3>::zeros() };
        if self.cavity {
            -g
        } else {
            g
        }
    }
}

/// A user-defined obstacle from a closure returning `(φ(x), ∇φ(x))`.
pub struct FnObstacle<const D: usize> {
    f: DistanceFn<D>,
}

/// A closure `x ↦ (φ(x), ∇φ(x))`.
pub type DistanceFn<const D: usize> = Arc<dyn Fn(&Point<D>) -> (Real, Vector<D>) + Send + Sync>;

impl<const D: usize> FnObstacle<D> {
    /// Wraps `f(x) = (φ(x), ∇φ(x))`.
    pub fn new(f: impl Fn(&Point<D>) -> (Real, Vector<D>) + Send + Sync + 'static) -> Self {
        Self { f: Arc::new(f) }
    }
}

impl<const D: usize> fmt::Debug for FnObstacle<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("FnObstacle")
    }
}

impl<const D: usize> SignedDistance<D> for FnObstacle<D> {
    fn distance(&self, x: &Point<D>) -> Real {
        (self.f)(x).0
    }
    fn gradient(&self, x: &Point<D>) -> Vector<D> {
        (self.f)(x).1
    }
}

/// Which normal a node-to-node pair uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalChoice<const D: usize> {
    /// The outward nodal normal `n^k` of body `k` (docs/model.md §1; default).
    BodyK,
    /// A fixed unit direction from body `k` toward body `l` for every node.
    Fixed(Vector<D>),
}

/// What the contact part of body `k` touches.
#[derive(Debug, Clone)]
pub enum Partner<const D: usize> {
    /// The contact part `part` of body `body`, with nodes at matching positions.
    Body {
        /// The other body `l`.
        body: BodyId,
        /// Its contact part.
        part: String,
        /// Pairing direction: nodes are paired when their positions agree after projecting out
        /// this direction (default: the mean outward normal of part `k`).
        direction: Option<Vector<D>>,
        /// Pairing tolerance (absolute; default `1e-6 ×` the shortest facet edge of part `k`).
        tolerance: Option<Real>,
        /// Normal used for the pairs.
        normal: NormalChoice<D>,
    },
    /// A rigid obstacle.
    Rigid(Arc<dyn SignedDistance<D>>),
    /// The contact part `part` of body `body` with any mesh: node-to-segment (2D) /
    /// node-to-facet (3D). Body `k` is the slave side, body `l` the master side (see the
    /// [module docs](self)).
    Segment {
        /// The other (master) body `l`.
        body: BodyId,
        /// Its contact part.
        part: String,
        /// Largest distance from a slave node to its master point; slave nodes farther away are
        /// left out of the pair (`None`: every slave node is paired with its closest master
        /// facet).
        search_distance: Option<Real>,
    },
    /// The contact part `part` of body `body` with any mesh, coupled by dual mortar
    /// (Wohlmuth's biorthogonal multipliers; exact segment integration in 2D, polygon clipping
    /// in 3D): body `k` is the slave side (it carries the multipliers), body `l` the master
    /// side. One condensed row per slave node; see [`crate::mortar`].
    Mortar {
        /// The other (master) body `l`.
        body: BodyId,
        /// Its contact part.
        part: String,
        /// Largest gap (along the slave facet normal) of an integration cell; farther master
        /// facets are not coupled (`None`: every master facet facing and overlapping a slave
        /// facet near its closest master facet).
        search_distance: Option<Real>,
    },
}

/// A contact pair `Γ_c^{kl}` (docs/model.md §1, §3).
#[derive(Debug, Clone)]
pub struct ContactPair<const D: usize> {
    /// Name for reports and errors.
    pub name: String,
    /// Body `k` (whose outward normal is `n`).
    pub body: BodyId,
    /// Its contact part.
    pub part: String,
    /// The partner.
    pub partner: Partner<D>,
    /// Coulomb coefficient `F_c ≥ 0` (0: frictionless).
    pub friction: Real,
}

impl<const D: usize> ContactPair<D> {
    /// Body–body node-to-node pair with default pairing direction, tolerance and normal.
    pub fn node_to_node(name: &str, body_k: BodyId, part_k: &str, body_l: BodyId, part_l: &str) -> Self {
        Self {
            name: name.to_string(),
            body: body_k,
            part: part_k.to_string(),
            partner: Partner::Body {
                body: body_l,
                part: part_l.to_string(),
                direction: None,
                tolerance: None,
                normal: NormalChoice::BodyK,
            },
            friction: 0.0,
        }
    }
    /// Body–body pair on non-matching meshes: node-to-segment (2D) / node-to-facet (3D), with
    /// the nodes of `part_k` of body `k` as slave nodes projected onto the facets of `part_l`
    /// of body `l` (no search-distance limit; see [`ContactPair::with_search_distance`]).
    pub fn node_to_segment(name: &str, body_k: BodyId, part_k: &str, body_l: BodyId, part_l: &str) -> Self {
        Self {
            name: name.to_string(),
            body: body_k,
            part: part_k.to_string(),
            partner: Partner::Segment { body: body_l, part: part_l.to_string(), search_distance: None },
            friction: 0.0,
        }
    }
    /// Body–body pair on non-matching meshes coupled by **dual mortar** (2D and 3D; docs/model.md §5,
    /// [`crate::mortar`]): `part_k` of body `k` is the slave side, `part_l` of body `l` the
    /// master side; no search-distance limit (see [`ContactPair::with_search_distance`]).
    /// Passes the contact patch test exactly on non-matching meshes.
    pub fn mortar(name: &str, body_k: BodyId, part_k: &str, body_l: BodyId, part_l: &str) -> Self {
        Self {
            name: name.to_string(),
            body: body_k,
            part: part_k.to_string(),
            partner: Partner::Mortar { body: body_l, part: part_l.to_string(), search_distance: None },
            friction: 0.0,
        }
    }
    /// Sets the search distance of a node-to-segment or mortar pair (no effect on other pairs).
    #[must_use]
    pub fn with_search_distance(mut self, distance: Real) -> Self {
        if let Partner::Segment { search_distance, .. } | Partner::Mortar { search_distance, .. } =
            &mut self.partner
        {
            *search_distance = Some(distance);
        }
        self
    }
    /// Body–rigid-obstacle pair.
    pub fn rigid(name: &str, body: BodyId, part: &str, obstacle: Arc<dyn SignedDistance<D>>) -> Self {
        Self {
            name: name.to_string(),
            body,
            part: part.to_string(),
            partner: Partner::Rigid(obstacle),
            friction: 0.0,
        }
    }
    /// Sets the Coulomb coefficient.
    #[must_use]
    pub fn with_friction(mut self, coefficient: Real) -> Self {
        self.friction = coefficient;
        self
    }
    /// Uses a fixed normal (and pairing direction) for a node-to-node pair.
    #[must_use]
    pub fn with_fixed_normal(mut self, direction: Vector<D>) -> Self {
        if let Partner::Body { normal, direction: dir, .. } = &mut self.partner {
            *normal = NormalChoice::Fixed(direction);
            *dir = Some(direction);
        }
        self
    }
}

/// The master side of a node-to-segment or mortar pair: another body, a valid search distance.
fn check_master(slave: BodyId, master: BodyId, search_distance: Option<Real>) -> Result<(), String> {
    if master == slave {
        return Err("self-contact (master body = slave body) is not supported".into());
    }
    match search_distance {
        Some(s) if !(s.is_finite() && s >= 0.0) => Err(format!("search distance {s} must be finite and ≥ 0")),
        _ => Ok(()),
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
    /// All contact nodes, pair by pair.
    pub nodes: Vec<ContactNode<D>>,
    /// Neighbours of each contact node (nodes sharing a contact facet of body `k`), for nested
    /// iteration ([`crate::nested`]).
    pub adjacency: Vec<Vec<usize>>,
    /// Placement of each body ([`ContactGeometry::new_placed`]); empty: every body where its
    /// mesh is.
    placements: Vec<BodyPlacement<D>>,
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
        Self::build(model, pairs, None)
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
        let bodies = model.bodies();
        let fits = displacement.len() == bodies.len()
            && bodies.iter().zip(displacement).all(|(b, u)| {
                u.len() == b.mesh.n_nodes() && u.iter().all(|v| v.iter().all(|c| c.is_finite()))
            });
        if !fits {
            return Err(ContactError::InvalidParameter(
                "the displacement of the pose does not fit the model (one finite vector per node of every body)"
                    .into(),
            ));
        }
        Self::build(model, pairs, Some(displacement))
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
            return Self::build(model, pairs, None);
        }
        // the placed configuration as a displacement u⁰ = R x + t − x of the reference mesh
        let offsets: Vec<Vec<Vector<D>>> = bodies
            .iter()
            .zip(placements)
            .map(|(b, p)| b.mesh.nodes().iter().map(|x| p.position(x) - x).collect())
            .collect();
        let mut geometry = Self::build(model, pairs, Some(&offsets))?;
        // build gives gaps in total form, d = d_placed + [u⁰]·n; the rows act on the
        // displacement from the placed configuration, so remove the placement's share
        for node in &mut geometry.nodes {
            let shift = node.jump(&offsets).map_or(0.0, |j| j.dot(&node.normal));
            node.gap -= shift;
        }
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

    fn build(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        displacement: Option<&[Vec<Vector<D>>]>,
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
        let mut nodes = Vec::new();
        let mut ranges = Vec::new();
        let mut adjacency: Vec<Vec<usize>> = Vec::new();
        for (pi, pair) in pairs.iter().enumerate() {
            let invalid = |reason: String| ContactError::InvalidPair { pair: pair.name.clone(), reason };
            if !(pair.friction.is_finite() && pair.friction >= 0.0) {
                return Err(invalid(format!(
                    "friction coefficient {} must be finite and ≥ 0",
                    pair.friction
                )));
            }
            let body = model.body(pair.body)?;
            let part = body.mesh.boundary_part(&pair.part)?;
            let pos_k = &posed[pair.body.0];
            let start = nodes.len();
            // lumped weights and nodal normals of part k
            let mut weight = std::collections::HashMap::new();
            let mut min_edge = Real::INFINITY;
            for f in part.facets() {
                let m = area_normal(pos_k, f).norm() / D as Real;
                for (a, &i) in f.iter().enumerate() {
                    *weight.entry(i).or_insert(0.0) += m;
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
                let mut seen: std::collections::HashMap<Vec<u64>, usize> = std::collections::HashMap::new();
                for i in part.nodes() {
                    let key: Vec<u64> = reference(i).iter().map(|x| (x + 0.0).to_bits()).collect();
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
            match &pair.partner {
                Partner::Rigid(obstacle) => {
                    obstacle.validate().map_err(|m| invalid(format!("obstacle: {m}")))?;
                    for (i, nk) in normals {
                        let x = pos_k[i];
                        let phi = obstacle.distance(&x);
                        let grad = obstacle.gradient(&x);
                        let gl = grad.norm();
                        if !(phi.is_finite() && gl.is_finite() && gl > 0.0) {
                            return Err(invalid(format!(
                                "obstacle distance or gradient not finite/zero at node {i}"
                            )));
                        }
                        let n = -grad / gl;
                        if n.dot(&nk) <= 0.0 {
                            return Err(invalid(format!(
                                "at node {i} the obstacle faces away from the body (outward normal · obstacle normal = {:.3} ≤ 0)",
                                n.dot(&nk)
                            )));
                        }
                        // total form: φ(x + u⁰) + u⁰ · n
                        let gap = match displacement {
                            Some(_) => phi + (x - reference(i)).dot(&n),
                            None => phi,
                        };
                        nodes.push(ContactNode {
                            pair: pi,
                            node: (pair.body, i),
                            partner: None,
                            master: Vec::new(),
                            position: x,
                            normal: n,
                            tangents: tangent_basis(&n),
                            weight: weight.get(&i).copied().unwrap_or(0.0),
                            gap,
                            friction: pair.friction,
                        });
                    }
                }
                Partner::Body { body: bl, part: pl, direction, tolerance, normal } => {
                    let other = model.body(*bl)?;
                    let lpart = other.mesh.boundary_part(pl)?;
                    let lnodes = lpart.nodes();
                    // the pairing is made in the reference configuration
                    let ref_normals = match displacement {
                        Some(_) => body.mesh.nodal_normals(&pair.part)?,
                        None => normals.clone(),
                    };
                    let mean_n: Vector<D> = ref_normals.iter().fold(Vector::<D>::zeros(), |a, (_, n)| a + n);
                    let e = direction.unwrap_or(mean_n);
                    let el = e.norm();
                    if !(el.is_finite() && el > 0.0) {
                        return Err(invalid("pairing direction is zero".into()));
                    }
                    let e = e / el;
                    let proj = |x: &Point<D>| x - e * x.dot(&e);
                    let knodes: Vec<usize> = normals.iter().map(|(i, _)| *i).collect();
                    let xk: Vec<Point<D>> = knodes.iter().map(|&i| proj(body.mesh.node(i))).collect();
                    let xl: Vec<Point<D>> = lnodes.iter().map(|&i| proj(other.mesh.node(i))).collect();
                    let tol = tolerance.unwrap_or(1e-6 * min_edge);
                    let pairs_found = match match_nodes(&xk, &xl, tol) {
                        Ok(p) => p,
                        Err(u) => {
                            if !u.first.is_empty() {
                                return Err(ContactError::UnmatchedNodes {
                                    pair: pair.name.clone(),
                                    body: body.name.clone(),
                                    count: u.first.len(),
                                    nodes: u.first.iter().take(10).map(|&i| knodes[i]).collect(),
                                });
                            }
                            // extra nodes on body l are allowed: redo the matching on the matched subset
                            let used: std::collections::HashSet<usize> = u.second.iter().copied().collect();
                            let keep: Vec<usize> = (0..lnodes.len()).filter(|j| !used.contains(j)).collect();
                            let xl2: Vec<Point<D>> = keep.iter().map(|&j| xl[j]).collect();
                            match_nodes(&xk, &xl2, tol)
                                .map_err(|_| invalid("node pairing is ambiguous".into()))?
                                .into_iter()
                                .map(|(a, b)| (a, keep[b]))
                                .collect()
                        }
                    };
                    for (a, b) in pairs_found {
                        let (i, j) = (knodes[a], lnodes[b]);
                        let n = match normal {
                            NormalChoice::BodyK => normals[a].1,
                            NormalChoice::Fixed(v) => {
                                let l = v.norm();
                                if !(l.is_finite() && l > 0.0) {
                                    return Err(invalid("fixed normal is zero".into()));
                                }
                                v / l
                            }
                        };
                        // total form: reference positions
                        let xk = *body.mesh.node(i);
                        let xlj = *other.mesh.node(j);
                        nodes.push(ContactNode {
                            pair: pi,
                            node: (pair.body, i),
                            partner: Some((*bl, j)),
                            master: Vec::new(),
                            position: pos_k[i],
                            normal: n,
                            tangents: tangent_basis(&n),
                            weight: weight.get(&i).copied().unwrap_or(0.0),
                            gap: (xlj - xk).dot(&n),
                            friction: pair.friction,
                        });
                    }
                    // every node penetrating its partner by more than an element edge: the
                    // normals of part k point away from part l (or the parts are swapped)
                    let largest_gap =
                        nodes[start..].iter().map(|c| c.gap).fold(Real::NEG_INFINITY, Real::max);
                    if nodes.len() > start && largest_gap < -min_edge {
                        return Err(invalid(format!(
                            "every node of part `{}` lies more than one element edge ({min_edge:.3e}) behind                              its partner on part `{pl}` (largest gap {largest_gap:.3e}): do the normals of                              `{}` point away from `{pl}`?",
                            pair.part, pair.part
                        )));
                    }
                }
                Partner::Segment { body: bl, part: pl, search_distance } => {
                    check_master(pair.body, *bl, *search_distance).map_err(invalid)?;
                    let other = model.body(*bl)?;
                    let lpart = other.mesh.boundary_part(pl)?;
                    let lfacets: Vec<Vec<usize>> = lpart.facets().map(<[usize]>::to_vec).collect();
                    let search = FacetSearch::new(&posed[bl.0], &lfacets);
                    for (i, nk) in normals {
                        let Some(p) = search.project(&pos_k[i], Some(&nk), *search_distance) else {
                            continue;
                        };
                        let n = -p.normal;
                        // total form: reference positions with the weights of the pose
                        let xm = p
                            .weights
                            .iter()
                            .fold(Point::<D>::zeros(), |acc, &(j, w)| acc + other.mesh.node(j) * w);
                        nodes.push(ContactNode {
                            pair: pi,
                            node: (pair.body, i),
                            partner: None,
                            master: p.weights.iter().map(|&(j, w)| (*bl, j, w)).collect(),
                            position: pos_k[i],
                            normal: n,
                            tangents: tangent_basis(&n),
                            weight: weight.get(&i).copied().unwrap_or(0.0),
                            gap: (xm - reference(i)).dot(&n),
                            friction: pair.friction,
                        });
                    }
                    if nodes.len() == start {
                        return Err(invalid(format!(
                            "no node of part `{}` has a master facet of part `{pl}` (search distance {search_distance:?})",
                            pair.part
                        )));
                    }
                }
                Partner::Mortar { body: bl, part: pl, search_distance } => {
                    check_master(pair.body, *bl, *search_distance).map_err(invalid)?;
                    let other = model.body(*bl)?;
                    let lfacets: Vec<Vec<usize>> =
                        other.mesh.boundary_part(pl)?.facets().map(<[usize]>::to_vec).collect();
                    let sfacets: Vec<Vec<usize>> = part.facets().map(<[usize]>::to_vec).collect();
                    let rows =
                        crate::mortar::mortar_rows(pos_k, &sfacets, &posed[bl.0], &lfacets, *search_distance);
                    let normal_of: std::collections::HashMap<usize, Vector<D>> =
                        normals.into_iter().collect();
                    for row in rows {
                        let Some(&n) = normal_of.get(&row.slave) else { continue };
                        // total form: reference positions with the weights of the pose
                        let xm = row
                            .master
                            .iter()
                            .fold(Point::<D>::zeros(), |acc, &(j, w)| acc + other.mesh.node(j) * w);
                        nodes.push(ContactNode {
                            pair: pi,
                            node: (pair.body, row.slave),
                            partner: None,
                            master: row.master.iter().map(|&(j, w)| (*bl, j, w)).collect(),
                            position: pos_k[row.slave],
                            normal: n,
                            tangents: tangent_basis(&n),
                            weight: row.d,
                            gap: (xm - reference(row.slave)).dot(&n),
                            friction: pair.friction,
                        });
                    }
                    if nodes.len() == start {
                        return Err(invalid(format!(
                            "no node of part `{}` has enough mortar overlap with part `{pl}` (search distance {search_distance:?})",
                            pair.part
                        )));
                    }
                }
            }
            if nodes.len() == start {
                return Err(invalid("the contact part has no nodes".into()));
            }
            // adjacency of the new rows through the facets of part k
            let row_of: std::collections::HashMap<usize, usize> =
                (start..nodes.len()).map(|r| (nodes[r].node.1, r)).collect();
            adjacency.resize(nodes.len(), Vec::new());
            for f in part.facets() {
                for &a in f {
                    for &b in f {
                        if let (Some(&ra), Some(&rb)) = (row_of.get(&a), row_of.get(&b)) {
                            if ra != rb {
                                adjacency[ra].push(rb);
                            }
                        }
                    }
                }
            }
            ranges.push((pair.name.clone(), start..nodes.len()));
        }
        for a in adjacency.iter_mut() {
            a.sort_unstable();
            a.dedup();
        }
        Ok(Self { pairs: ranges, nodes, adjacency, placements: Vec::new() })
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
                    Some(p) => t.dot(&self.jump(r, p).ok_or_else(|| {
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
