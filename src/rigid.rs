//! Rigid bodies with mixed control (docs/model.md §10, docs/scenario.md `[[rigid_body]]`).
//!
//! A [`RigidBody`] has `3` (2D) or `6` (3D) degrees of freedom `q`: the translation `t` of its
//! reference point `c` and its rotation angles. Its pose maps a point `X` of the body to
//!
//! ```text
//! x = c + t + R(q) (X − c),       2D: R = R(θ);   3D: R = R_{a₁}(q_{a₁}) R_{a₂}(q_{a₂}) R_{a₃}(q_{a₃})
//! ```
//!
//! with the rotation order `a₁ a₂ a₃` (default `z x y`: body-fixed z–x–y angles, the order of
//! the OpenSim knee joint; `q = [t_x, t_y, t_z, θ_x, θ_y, θ_z]`). Each degree of freedom is
//! either **prescribed** by a history (`q_k = h_k(t)`) or **force-controlled**: loaded by a
//! generalised force history `F_k(t)` (a force along `e_k` for a translation, a moment about
//! the angle's axis for a rotation) and found so that the rigid body is in equilibrium,
//!
//! ```text
//! Q_k(q) + F_k(t) = 0,     Q_k = Σ_i f_i · v_k(x_i),
//! ```
//!
//! where `f_i` are the forces the elastic bodies exert on the rigid body at the points `x_i`
//! (contact forces of its pairs, reactions of the parts tied to it) and `v_k = ∂x/∂q_k` the
//! velocity field of degree of freedom `k`: `e_k` for a translation, `a_k × (x − c − t)` for a
//! rotation about the current axis `a_k` of angle `k` (`a_{a₁} = e_{a₁}`,
//! `a_{a₂} = R_{a₁} e_{a₂}`, `a_{a₃} = R_{a₁} R_{a₂} e_{a₃}`). So `Q` is the resultant
//! force and the moment about `c + t` projected on those axes.
//!
//! A rigid body acts on the elastic bodies in two ways:
//!
//! * as a contact partner: [`JointModel::contact_rigid_body`] pairs a part with the body's
//!   shape (any [`SignedDistance`] in the body's own frame, e.g. a [`SurfaceObstacle`] read
//!   from STL), posed by [`PosedObstacle`];
//! * as a rigid plate: [`JointModel::tie_to_rigid_body`] prescribes the exact rigid
//!   displacement `x(X) − X` of its pose on a part of an elastic body.
//!
//! The stiffness is factorised once: a pose changes only the contact rows and gaps (rigid
//! contact partners) and the prescribed displacements (tied parts). The force-controlled
//! degrees of freedom are found by a Newton iteration on `r(q) = Q(q) + F` around the contact
//! solve (a finite-difference Jacobian of the affine piece at the iterate, carried between levels
//! with Broyden updates; bracketed secant steps for a single degree of freedom, line searches
//! on the level's potential `Π(q) = E(q) − F·q` for several, docs/model.md (10.3a)), in which the
//! contact geometry is built at a pose and the gaps follow the motion to first order
//! (`d_r(q) = d_r(q₀) + n_r · v_k(x_r) (q_k − q₀_k)`, the rows and the Schur columns kept); an
//! iterate farther than the geometry tolerance from that pose gets the geometry rebuilt there
//! (docs/model.md §10). The level is accepted
//! when `|r_k| ≤ tolerance × scale` for every force-controlled degree of freedom
//! ([`ForceControlParams`]).
//!
//! Friction against a rigid body measures the slip relative to it: at a quasi-static level the
//! motion of the body's material point at each contact node since the last accepted pose is
//! part of the slip origin (docs/model.md (10.5), [`ContactGeometry::set_partner_motion`]).
//!
//! [`JointModel::contact_rigid_body`]: crate::builder::JointModel::contact_rigid_body
//! [`JointModel::tie_to_rigid_body`]: crate::builder::JointModel::tie_to_rigid_body
//! [`SurfaceObstacle`]: synovia_contact::SurfaceObstacle

use std::fmt;
use std::sync::{Arc, RwLock};
use synovia_time::nonlinear_dynamic::MovingPartners;
use synovia_time::results::{cross3 as cross, embed3 as embed};

use synovia_contact::operators::SignedDistance;
use synovia_mesh::math::{Point, Real, Tensor, Vector};
use synovia_time::history::LoadHistory;

use synovia_contact::operators::ContactGeometry;
use synovia_contact::{ContactSolver, CoordinateBorder, StaticContactResult};
use synovia_nonlinear::{GapControl, GapFriction, NonlinearContact, NonlinearResult};
use synovia_time::quasistatic::{QuasiStaticStepper, StepperCheckpoint};
use synovia_time::results::StepRecord;

use crate::builder::{JointError, JointModel};

/// Number of degrees of freedom of a rigid body in dimension `D` (3 in 2D, 6 in 3D).
pub const fn rigid_dofs(dim: usize) -> usize {
    if dim == 2 {
        3
    } else {
        6
    }
}

/// How one degree of freedom of a [`RigidBody`] is driven.
#[derive(Clone)]
pub enum DofControl {
    /// `q_k = h(t)` (length unit for translations, radians for rotations).
    Prescribed(Arc<dyn LoadHistory>),
    /// Loaded by the generalised force `F_k(t)` (force unit for translations, force × length
    /// for rotations); `q_k` is found from the equilibrium of the rigid body, starting from
    /// the `guess` history if there is one (e.g. a measured coordinate, corrected by the
    /// offset found at the previous level), else from the previous level's value.
    Force {
        /// `F_k(t)`.
        load: Arc<dyn LoadHistory>,
        /// A predictor of `q_k(t)`.
        guess: Option<Arc<dyn LoadHistory>>,
    },
}

impl fmt::Debug for DofControl {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Prescribed(_) => f.write_str("Prescribed"),
            Self::Force { guess, .. } => write!(f, "Force {{ guess: {} }}", guess.is_some()),
        }
    }
}

/// The pose of a rigid body: `x = c + t + R (X − c)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidPose<const D: usize> {
    /// The reference point `c` (in the reference configuration).
    pub centre: Point<D>,
    /// The rotation `R`.
    pub rotation: Tensor<D>,
    /// The translation `t` of `c`.
    pub translation: Vector<D>,
}

impl<const D: usize> RigidPose<D> {
    /// The identity pose about `centre`.
    pub fn identity(centre: Point<D>) -> Self {
        Self { centre, rotation: Tensor::<D>::identity(), translation: Vector::<D>::zeros() }
    }
    /// `x = c + t + R (X − c)`.
    pub fn position(&self, x: &Point<D>) -> Point<D> {
        self.centre + self.translation + self.rotation * (x - self.centre)
    }
    /// `X = c + Rᵀ (x − c − t)`: the body point at the place `x`.
    pub fn to_body(&self, x: &Point<D>) -> Point<D> {
        self.centre + self.rotation.transpose() * (x - self.centre - self.translation)
    }
}

/// A pose shared between a [`RigidBody`], its posed contact shapes and its tied parts: the
/// driver sets it, the shapes and the prescribed displacements read it.
#[derive(Debug, Clone)]
pub struct SharedPose<const D: usize>(Arc<RwLock<RigidPose<D>>>);

impl<const D: usize> SharedPose<D> {
    /// A shared pose starting at `pose`.
    pub fn new(pose: RigidPose<D>) -> Self {
        Self(Arc::new(RwLock::new(pose)))
    }
    /// The current pose.
    pub fn get(&self) -> RigidPose<D> {
        // a poisoned lock still holds a valid pose (plain data, written in one assignment)
        match self.0.read() {
            Ok(p) => *p,
            Err(e) => *e.into_inner(),
        }
    }
    /// Sets the pose.
    pub fn set(&self, pose: RigidPose<D>) {
        match self.0.write() {
            Ok(mut p) => *p = pose,
            Err(e) => *e.into_inner() = pose,
        }
    }
}

/// A contact shape given in a rigid body's own frame, placed by the body's current pose:
/// `φ(x) = φ_body(X)`, `∇φ(x) = R ∇φ_body(X)` with `X` the body point at `x`.
///
/// Near the surface (`|φ| < h`, `h = 10⁻⁶ |X|`) the gradient is taken at the point `h` outside
/// along it, `∇φ_body(X + (h − φ) ∇φ_body(X))`: for a signed distance the gradient is constant
/// along the normal through the closest point, so this is the same vector, but a closest-point
/// shape computes it as `(X − c)/|X − c|`, whose rounding error `≈ ε |X| / |φ|` grows without
/// bound as `X` approaches the surface (measured on the `tkr3d` femur, 1.6e-6 at
/// `φ = 1.3e-9 mm`), and the geometry of finite strain is built on configurations whose contact
/// nodes converge onto it (docs/nonlinear.md, "Rigid bodies with mixed control"). At the offset
/// point the error is `≈ ε / 10⁻⁶ = 2.2e-10`. The offset answer is kept only if its distance is
/// `h` to 10 % and its gradient within 2.6° of the first (a shape that is no distance there, or a
/// closest feature that changed, keeps the gradient at `X`).
#[derive(Debug, Clone)]
pub struct PosedObstacle<const D: usize> {
    shape: Arc<dyn SignedDistance<D>>,
    pose: SharedPose<D>,
}

/// The offset `h / |X|` of [`PosedObstacle`]'s gradient near the surface.
const NEAR_SURFACE: Real = 1e-6;

impl<const D: usize> PosedObstacle<D> {
    /// `shape` (body frame) placed by `pose`.
    pub fn new(shape: Arc<dyn SignedDistance<D>>, pose: SharedPose<D>) -> Self {
        Self { shape, pose }
    }

    /// The gradient `g` at the body point `x` of distance `d`, re-evaluated at the point `h`
    /// outside along it when `|d| < h` (see the type's documentation).
    fn resolved(&self, x: &Point<D>, d: Real, g: Vector<D>) -> Vector<D> {
        let h = NEAR_SURFACE * x.norm();
        if !(d.abs() < h && g.iter().all(|v| v.is_finite())) {
            return g;
        }
        let (d2, g2) = self.shape.distance_and_gradient(&(x + g * (h - d)));
        if (d2 - h).abs() <= 0.1 * h && g2.iter().all(|v| v.is_finite()) && g2.dot(&g) >= 0.999 {
            g2
        } else {
            g
        }
    }
}

impl<const D: usize> SignedDistance<D> for PosedObstacle<D> {
    fn distance(&self, x: &Point<D>) -> Real {
        self.shape.distance(&self.pose.get().to_body(x))
    }
    fn gradient(&self, x: &Point<D>) -> Vector<D> {
        self.distance_and_gradient(x).1
    }
    fn distance_and_gradient(&self, x: &Point<D>) -> (Real, Vector<D>) {
        let pose = self.pose.get();
        let body = pose.to_body(x);
        let (d, g) = self.shape.distance_and_gradient(&body);
        (d, pose.rotation * self.resolved(&body, d, g))
    }
    fn distance_and_gradient_within(&self, x: &Point<D>, reach: Real) -> (Real, Vector<D>) {
        let pose = self.pose.get();
        let body = pose.to_body(x);
        let (d, g) = self.shape.distance_and_gradient_within(&body, reach);
        (d, pose.rotation * self.resolved(&body, d, g))
    }
    fn validate(&self) -> Result<(), String> {
        let p = self.pose.get();
        if !(p.rotation.iter().chain(p.translation.iter()).all(|v| v.is_finite())) {
            return Err("rigid body pose is not finite".into());
        }
        self.shape.validate()
    }
}

/// A rigid body with one [`DofControl`] per degree of freedom (see the
/// [module documentation](self)).
#[derive(Debug, Clone)]
pub struct RigidBody<const D: usize> {
    pub(crate) name: String,
    pub(crate) centre: Point<D>,
    pub(crate) controls: Vec<DofControl>,
    pub(crate) order: [usize; 3],
    pub(crate) pose: SharedPose<D>,
    /// The input of [`RigidBody::prescribe_pose`] and the degrees of freedom it still drives
    /// (re-made for a new rotation order).
    pose_input: Option<(PoseInput<D>, Vec<bool>)>,
}

/// Names of the degrees of freedom (2D and 3D).
pub fn dof_names(dim: usize) -> &'static [&'static str] {
    if dim == 2 {
        &["tx", "ty", "rz"]
    } else {
        &["tx", "ty", "tz", "rx", "ry", "rz"]
    }
}

fn axis_rotation(axis: usize, angle: Real) -> Tensor<3> {
    let (s, c) = angle.sin_cos();
    match axis {
        0 => Tensor::<3>::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        1 => Tensor::<3>::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        _ => Tensor::<3>::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    }
}

/// The angles `[q_x, q_y, q_z]` with `R = Π_{a ∈ order} R_a(q_a)` (the rotation order of a
/// [`RigidBody`], e.g. `[2, 0, 1]` for `R_z R_x R_y`): for the Tait–Bryan order `(i, j, k)` of
/// parity `ε` (+1 for `xyz`, `yzx`, `zxy`, −1 otherwise),
///
/// ```text
/// q_j = asin(ε R_ik),   q_i = atan2(−ε R_jk, R_kk),   q_k = atan2(−ε R_ij, R_ii),
/// ```
///
/// with `q_i, q_k ∈ (−π, π]`, `q_j ∈ [−π/2, π/2]` (at `q_j = ±π/2` the split between `q_i` and
/// `q_k` is one of many, the rotation the same). Written here rather than taken from nalgebra:
/// its `Rotation3::euler_angles_ordered` (0.34), tried in its place, gave angles that rebuild a
/// rotation 1.43 away from the given one at gimbal lock (order `xyz`, middle angle π/2).
pub fn euler_angles(rotation: &Tensor<3>, order: [usize; 3]) -> [Real; 3] {
    let [i, j, k] = order;
    let eps = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
    let mut q = [0.0; 3];
    q[j] = (eps * rotation[(i, k)]).clamp(-1.0, 1.0).asin();
    q[i] = (-eps * rotation[(j, k)]).atan2(rotation[(k, k)]);
    q[k] = (-eps * rotation[(i, j)]).atan2(rotation[(i, i)]);
    q
}

/// A pose set from outside between solves — a navigation tracker's frame — for a rigid body
/// whose degrees of freedom it prescribes ([`RigidBody::prescribe_pose`]): the translation of
/// the body's reference point and its rotation, given as a unit quaternion, an axis and an
/// angle, or a rotation matrix (3D), or an angle (2D). Clones share the pose: keep one, set it
/// before each [`JointSession`](crate::session::JointSession) solve.
#[derive(Debug, Clone)]
pub struct PoseInput<const D: usize>(Arc<RwLock<(Vector<3>, Tensor<3>)>>);

impl<const D: usize> Default for PoseInput<D> {
    fn default() -> Self {
        Self(Arc::new(RwLock::new((Vector::<3>::zeros(), Tensor::<3>::identity()))))
    }
}

impl<const D: usize> PoseInput<D> {
    /// The identity pose (no translation, no rotation).
    pub fn new() -> Self {
        Self::default()
    }
    fn get(&self) -> (Vector<3>, Tensor<3>) {
        match self.0.read() {
            Ok(p) => *p,
            Err(e) => *e.into_inner(),
        }
    }
    fn put(&self, translation: Vector<3>, rotation: Tensor<3>) {
        match self.0.write() {
            Ok(mut p) => *p = (translation, rotation),
            Err(e) => *e.into_inner() = (translation, rotation),
        }
    }
    /// The rotation angles of the current pose for a body with rotation `order`
    /// ([`euler_angles`]; 2D: `[0, 0, θ]`).
    pub fn angles(&self, order: [usize; 3]) -> [Real; 3] {
        euler_angles(&self.get().1, order)
    }
    /// The current translation (`z = 0` in 2D).
    pub fn translation(&self) -> [Real; 3] {
        let t = self.get().0;
        [t[0], t[1], t[2]]
    }
}

fn finite(what: &str, values: &[Real]) -> Result<(), JointError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(JointError::Invalid(format!("pose: {what} {values:?} is not finite")))
    }
}

impl PoseInput<3> {
    /// Sets the translation `t` and the rotation of the unit quaternion `q = [w, x, y, z]`
    /// (normalised here: `R = I + 2w [v]ₓ + 2 [v]ₓ²` with `v = (x, y, z)`).
    ///
    /// # Errors
    /// [`JointError::Invalid`] for non-finite values or a zero quaternion; the pose is unchanged.
    pub fn set_quaternion(&self, translation: [Real; 3], q: [Real; 4]) -> Result<(), JointError> {
        finite("translation", &translation)?;
        finite("quaternion", &q)?;
        let norm = q.iter().map(|v| v * v).sum::<Real>().sqrt();
        if norm <= 1e-12 {
            return Err(JointError::Invalid(format!("pose: quaternion {q:?} has no direction")));
        }
        let unit =
            nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
        self.put(Vector::<3>::from(translation), unit.to_rotation_matrix().into_inner());
        Ok(())
    }
    /// Sets the translation `t` and the rotation by `angle` (rad, right-handed) about `axis`
    /// (normalised here; Rodrigues: `R = I + sin θ [n]ₓ + (1 − cos θ) [n]ₓ²`).
    ///
    /// # Errors
    /// [`JointError::Invalid`] for non-finite values or a zero axis; the pose is unchanged.
    pub fn set_axis_angle(
        &self,
        translation: [Real; 3],
        axis: [Real; 3],
        angle: Real,
    ) -> Result<(), JointError> {
        finite("translation", &translation)?;
        finite("axis", &axis)?;
        finite("angle", &[angle])?;
        let axis = Vector::<3>::from(axis);
        let Some(n) = nalgebra::Unit::try_new(axis, 1e-12) else {
            return Err(JointError::Invalid(format!("pose: rotation axis {axis:?} has no direction")));
        };
        self.put(
            Vector::<3>::from(translation),
            nalgebra::Rotation3::from_axis_angle(&n, angle).into_inner(),
        );
        Ok(())
    }
    /// Sets the translation `t` and the rotation matrix `R` (row-major), which must be a
    /// rotation to 1e-9 (`RᵀR = I`, `det R = 1`).
    ///
    /// # Errors
    /// [`JointError::Invalid`] for non-finite values or a matrix that is not a rotation.
    pub fn set_rotation_matrix(
        &self,
        translation: [Real; 3],
        rotation: [[Real; 3]; 3],
    ) -> Result<(), JointError> {
        finite("translation", &translation)?;
        finite("rotation", rotation.as_flattened())?;
        let r = Tensor::<3>::from_fn(|i, j| rotation[i][j]);
        let defect = (r.transpose() * r - Tensor::<3>::identity()).abs().max();
        if defect > 1e-9 || (r.determinant() - 1.0).abs() > 1e-9 {
            return Err(JointError::Invalid(format!(
                "pose: {rotation:?} is not a rotation (|RᵀR − I| = {defect:.1e}, det = {})",
                r.determinant()
            )));
        }
        self.put(Vector::<3>::from(translation), r);
        Ok(())
    }
}

impl PoseInput<2> {
    /// Sets the translation `t` and the rotation angle (rad, counter-clockwise).
    ///
    /// # Errors
    /// [`JointError::Invalid`] for non-finite values; the pose is unchanged.
    pub fn set(&self, translation: [Real; 2], angle: Real) -> Result<(), JointError> {
        finite("translation", &translation)?;
        finite("angle", &[angle])?;
        self.put(Vector::<3>::new(translation[0], translation[1], 0.0), axis_rotation(2, angle));
        Ok(())
    }
}

/// One degree of freedom of a [`PoseInput`] as a history (the same at every time: the pose is
/// whatever was set last).
#[derive(Debug)]
struct PoseDof<const D: usize> {
    input: PoseInput<D>,
    /// 0–2: translation component; 3–5: angle about x, y, z.
    component: usize,
    order: [usize; 3],
}

impl<const D: usize> LoadHistory for PoseDof<D> {
    fn value(&self, _t: Real) -> Real {
        match self.component {
            c @ 0..=2 => self.input.translation()[c],
            c => self.input.angles(self.order)[c - 3],
        }
    }
}

impl<const D: usize> RigidBody<D> {
    /// A rigid body `name` with reference point `centre`, every degree of freedom prescribed to
    /// zero (it stays where it is until its controls are set).
    ///
    /// # Errors
    /// [`JointError::Invalid`] for an empty name, a non-finite centre or a dimension other
    /// than 2 or 3.
    pub fn new(name: &str, centre: Point<D>) -> Result<Self, JointError> {
        if D != 2 && D != 3 {
            return Err(JointError::Invalid(format!("rigid body `{name}`: dimension {D} is not 2 or 3")));
        }
        if name.is_empty() {
            return Err(JointError::Invalid("a rigid body needs a name".into()));
        }
        if !centre.iter().all(|v| v.is_finite()) {
            return Err(JointError::Invalid(format!("rigid body `{name}`: centre {centre:?} is not finite")));
        }
        let zero: Arc<dyn LoadHistory> = Arc::new(synovia_time::history::Constant(0.0));
        Ok(Self {
            name: name.to_string(),
            centre,
            controls: vec![DofControl::Prescribed(zero); rigid_dofs(D)],
            order: [2, 0, 1],
            pose: SharedPose::new(RigidPose::identity(centre)),
            pose_input: None,
        })
    }

    /// The body's name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// The reference point `c`.
    pub fn centre(&self) -> &Point<D> {
        &self.centre
    }
    /// The controls, one per degree of freedom ([`dof_names`] order).
    pub fn controls(&self) -> &[DofControl] {
        &self.controls
    }
    /// The shared pose (the current one while a model runs).
    pub fn shared_pose(&self) -> &SharedPose<D> {
        &self.pose
    }

    fn check_dof(&self, dof: usize) -> Result<(), JointError> {
        if dof >= rigid_dofs(D) {
            return Err(JointError::Invalid(format!(
                "rigid body `{}`: degree of freedom {dof} does not exist (0…{}: {})",
                self.name,
                rigid_dofs(D) - 1,
                dof_names(D).join(", ")
            )));
        }
        Ok(())
    }

    /// Index of the degree of freedom called `name` (`"tx"`, `"ty"`, `"tz"`, `"rx"`, `"ry"`,
    /// `"rz"`; 2D: `"tx"`, `"ty"`, `"rz"`).
    ///
    /// # Errors
    /// [`JointError::Invalid`] naming the valid names.
    pub fn dof_index(name: &str) -> Result<usize, JointError> {
        dof_names(D).iter().position(|n| *n == name).ok_or_else(|| {
            JointError::Invalid(format!(
                "unknown rigid degree of freedom `{name}` (in {D}D: {})",
                dof_names(D).join(", ")
            ))
        })
    }

    /// Prescribes every degree of freedom by `input`, the pose a caller sets between solves
    /// (a navigation tracker: [`PoseInput::set_quaternion`], [`PoseInput::set_axis_angle`],
    /// [`PoseInput::set_rotation_matrix`]; 2D [`PoseInput::set`]). The rotation is turned into
    /// the body's angles for its rotation order ([`euler_angles`], also after a later
    /// [`RigidBody::with_rotation_order`]), so records report them as usual. A degree of
    /// freedom given another control afterwards ([`RigidBody::prescribe`], [`RigidBody::force`],
    /// e.g. the axial force of a knee simulator) leaves the pose input.
    pub fn prescribe_pose(mut self, input: &PoseInput<D>) -> Self {
        self.pose_input = Some((input.clone(), vec![true; rigid_dofs(D)]));
        self.drive_by_pose();
        self
    }

    /// The controls of the degrees of freedom [`RigidBody::prescribe_pose`] drives.
    fn drive_by_pose(&mut self) {
        let Some((input, driven)) = &self.pose_input else { return };
        let order = if D == 2 { [0, 1, 2] } else { self.order };
        for (dof, _) in driven.iter().enumerate().filter(|(_, &on)| on) {
            // 2D: tx, ty, rz; the angle about z of the planar rotation
            let component = if D == 2 && dof == 2 { 5 } else { dof };
            let history = PoseDof { input: input.clone(), component, order };
            self.controls[dof] = DofControl::Prescribed(Arc::new(history));
        }
    }

    /// `dof` no longer follows a [`PoseInput`].
    fn release_from_pose(&mut self, dof: usize) {
        if let Some((_, driven)) = &mut self.pose_input {
            if let Some(on) = driven.get_mut(dof) {
                *on = false;
            }
        }
    }

    /// Prescribes degree of freedom `dof` by `history` (length or radians).
    ///
    /// # Errors
    /// [`JointError::Invalid`] for a degree of freedom that does not exist.
    pub fn prescribe(mut self, dof: usize, history: impl LoadHistory + 'static) -> Result<Self, JointError> {
        self.check_dof(dof)?;
        self.controls[dof] = DofControl::Prescribed(Arc::new(history));
        self.release_from_pose(dof);
        Ok(self)
    }

    /// Loads degree of freedom `dof` by the generalised force `history` (force, or moment
    /// about the angle's axis); the degree of freedom is found from equilibrium.
    ///
    /// # Errors
    /// [`JointError::Invalid`] for a degree of freedom that does not exist.
    pub fn force(mut self, dof: usize, history: impl LoadHistory + 'static) -> Result<Self, JointError> {
        self.check_dof(dof)?;
        self.controls[dof] = DofControl::Force { load: Arc::new(history), guess: None };
        self.release_from_pose(dof);
        Ok(self)
    }

    /// [`RigidBody::force`] with a predictor `guess` of the coordinate (e.g. the measured
    /// superior–inferior translation of a force-controlled knee): each level starts from
    /// `guess(t)` plus the correction found at the previous level.
    ///
    /// # Errors
    /// [`JointError::Invalid`] for a degree of freedom that does not exist.
    pub fn force_with_guess(
        mut self,
        dof: usize,
        history: impl LoadHistory + 'static,
        guess: impl LoadHistory + 'static,
    ) -> Result<Self, JointError> {
        self.check_dof(dof)?;
        self.controls[dof] = DofControl::Force { load: Arc::new(history), guess: Some(Arc::new(guess)) };
        self.release_from_pose(dof);
        Ok(self)
    }

    /// Sets the rotation order (3D): e.g. `"zxy"` for `R = R_z R_x R_y` (the default).
    ///
    /// # Errors
    /// [`JointError::Invalid`] unless `order` is a permutation of `x`, `y`, `z`.
    pub fn with_rotation_order(mut self, order: &str) -> Result<Self, JointError> {
        let axes: Vec<usize> = order
            .chars()
            .map(|c| match c {
                'x' | 'X' => Ok(0),
                'y' | 'Y' => Ok(1),
                'z' | 'Z' => Ok(2),
                _ => Err(()),
            })
            .collect::<Result<_, _>>()
            .map_err(|()| self.bad_order(order))?;
        if axes.len() != 3 || (0..3).any(|a| !axes.contains(&a)) {
            return Err(self.bad_order(order));
        }
        self.order = [axes[0], axes[1], axes[2]];
        self.drive_by_pose();
        Ok(self)
    }

    fn bad_order(&self, order: &str) -> JointError {
        JointError::Invalid(format!(
            "rigid body `{}`: rotation order `{order}` must be a permutation of x, y, z (e.g. \"zxy\")",
            self.name
        ))
    }

    /// Indices of the force-controlled degrees of freedom.
    pub fn force_dofs(&self) -> Vec<usize> {
        (0..self.controls.len()).filter(|&k| matches!(self.controls[k], DofControl::Force { .. })).collect()
    }

    /// `q_k(t)` of the prescribed degrees of freedom, `F_k(t)` of the force-controlled ones.
    pub(crate) fn control_values(&self, t: Real) -> Vec<Real> {
        self.controls
            .iter()
            .map(|c| match c {
                DofControl::Prescribed(h) | DofControl::Force { load: h, .. } => h.value(t),
            })
            .collect()
    }

    /// The pose of the generalised coordinates `q` (see the [module documentation](self)).
    pub fn pose_of(&self, q: &[Real]) -> RigidPose<D> {
        let mut pose = RigidPose::identity(self.centre);
        for i in 0..D {
            pose.translation[i] = q.get(i).copied().unwrap_or(0.0);
        }
        if D == 2 {
            let (s, c) = q.get(2).copied().unwrap_or(0.0).sin_cos();
            pose.rotation[(0, 0)] = c;
            pose.rotation[(0, 1)] = -s;
            pose.rotation[(1, 0)] = s;
            pose.rotation[(1, 1)] = c;
        } else {
            let mut r = Tensor::<3>::identity();
            for &a in &self.order {
                r *= axis_rotation(a, q.get(3 + a).copied().unwrap_or(0.0));
            }
            for i in 0..3 {
                for j in 0..3 {
                    pose.rotation[(i, j)] = r[(i, j)];
                }
            }
        }
        pose
    }

    /// The axes `a_k` (world frame) of the rotation angles at `q`, indexed by axis
    /// (`x`, `y`, `z`); 2D: the `z` axis only.
    pub(crate) fn rotation_axes(&self, q: &[Real]) -> [[Real; 3]; 3] {
        let mut axes = [[0.0; 3]; 3];
        if D == 2 {
            axes[2] = [0.0, 0.0, 1.0];
            return axes;
        }
        let mut r = Tensor::<3>::identity();
        for &a in &self.order {
            let mut e = Vector::<3>::zeros();
            e[a] = 1.0;
            let w = r * e;
            axes[a] = [w[0], w[1], w[2]];
            r *= axis_rotation(a, q.get(3 + a).copied().unwrap_or(0.0));
        }
        axes
    }

    /// The generalised forces `Q_k = Σ f · v_k` of a force system with resultant `force` and
    /// moment `moment` about the origin (3 components each; 2D: `z` of the moment), at `q`.
    pub(crate) fn generalised(&self, q: &[Real], force: [Real; 3], moment: [Real; 3]) -> Vec<Real> {
        let mp = self.moment_about_centre(q, force, moment);
        let axes = self.rotation_axes(q);
        let mut out = Vec::with_capacity(rigid_dofs(D));
        out.extend(force.iter().take(D).copied());
        if D == 2 {
            out.push(mp[2]);
        } else {
            for a in axes {
                out.push(a[0] * mp[0] + a[1] * mp[1] + a[2] * mp[2]);
            }
        }
        out
    }

    /// The moment about the moved reference point `p = c + t`, `M_O − p × F`, of a force
    /// system with resultant `force` and moment `moment` about the origin.
    pub(crate) fn moment_about_centre(&self, q: &[Real], force: [Real; 3], moment: [Real; 3]) -> [Real; 3] {
        let pose = self.pose_of(q);
        let pxf = cross(embed(&(pose.centre + pose.translation)), force);
        [moment[0] - pxf[0], moment[1] - pxf[1], moment[2] - pxf[2]]
    }

    /// `v_k(x)`: the velocity of the body point at the place `x` for a unit rate of degree of
    /// freedom `k` at `q`.
    pub(crate) fn velocity(&self, q: &[Real], k: usize, x: &Point<D>) -> Vector<D> {
        let mut v = Vector::<D>::zeros();
        if k < D {
            v[k] = 1.0;
            return v;
        }
        let pose = self.pose_of(q);
        let r = x - pose.centre - pose.translation;
        let a = if D == 2 { [0.0, 0.0, 1.0] } else { self.rotation_axes(q)[k - 3] };
        let w = cross(a, embed(&r));
        for (vi, wi) in v.iter_mut().zip(w) {
            *vi = wi;
        }
        v
    }
}

/// Largest motion of the force-controlled coordinates from the pose the contact geometry was
/// built at (relative to the model size) for which trials run on its first-order gaps
/// (docs/model.md (10.4)); beyond it the geometry is rebuilt before the trial.
const LINEAR_REACH: Real = 2e-3;

/// Parameters of the force-control iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceControlParams {
    /// Relative tolerance of the equilibrium `|Q_k + F_k| ≤ tolerance × scale_k`
    /// (`scale` = the largest applied force of the body, × the model size for moments).
    pub tolerance: Real,
    /// Largest number of contact solves per level.
    pub max_solves: usize,
    /// Largest motion from the pose the contact geometry was built at (relative to the model
    /// size) before the geometry is rebuilt.
    pub geometry_tolerance: Real,
    /// Several force-controlled coordinates: a finite-difference Jacobian at every accepted
    /// iterate (`true`) instead of Broyden updates with a fresh one when a step did not reduce
    /// the error fourfold (`false`, default).
    pub fresh_jacobian: bool,
    /// The force-controlled coordinates (of bodies without tied parts) with a solver that takes
    /// them (`pdas`, `pdas-fallback`): solved with the contact conditions (`true`, default;
    /// docs/model.md §10, "The coordinate in the contact solve"), one solve per geometry built;
    /// `false`: the search over trial solves of given coordinates (secant and bracket for one,
    /// line searches for several). The bordered solve hands over to the search when nothing in
    /// contact holds a body yet (after one move to first contact), its solve fails or its
    /// passes do not settle.
    pub bordered: bool,
}

impl Default for ForceControlParams {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_solves: 60,
            geometry_tolerance: 1e-6,
            fresh_jacobian: false,
            bordered: true,
        }
    }
}

/// Largest number of geometries built by the bordered force control of one level before it
/// hands over to the search over trial solves.
const BORDERED_PASSES: usize = 8;

/// The state of a rigid body at one level, reported in [`StepRecord::rigid`](synovia_time::results::StepRecord).
pub use synovia_time::results::RigidRecord;

/// How a level is solved: step 0 of a new sequence (warm-started from the last solution or
/// not), or the next quasi-static level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LevelMode {
    Restart { warm: bool },
    Step,
}

/// The force-control driver of a model's rigid bodies: their current coordinates and the
/// Jacobian of the last level (the predictor of the next one).
#[derive(Debug, Clone, Default)]
pub(crate) struct RigidDriver {
    q: Vec<Vec<Real>>,
    /// `q_k − guess_k(t)` of the last level, per force-controlled coordinate with a guess.
    offset: Vec<Vec<Real>>,
    jacobian: Option<nalgebra::DMatrix<Real>>,
    /// The coordinates of the last accepted level (the slip origin of friction against the
    /// rigid bodies at the next quasi-static level).
    accepted: Option<Vec<Vec<Real>>>,
    /// Nonlinear models: the slope `dR/dw` of the last level's gap control (its first step).
    slope: Option<Real>,
}

type Level<const D: usize> = (StepRecord, StaticContactResult<D>);

/// What the trial solves of one level share.
struct LevelContext<'a, const D: usize> {
    joint: &'a JointModel<D>,
    t: Real,
    solver: &'a dyn ContactSolver,
    mode: LevelMode,
    /// The stepper's state at the start of a quasi-static level (each trial starts there).
    checkpoint: Option<StepperCheckpoint<D>>,
    /// The force-controlled coordinates `(rigid body, degree of freedom)`.
    unknowns: &'a [(usize, usize)],
}

/// The gaps of a geometry built at the coordinates `base`, followed to first order in the
/// force-controlled coordinates (docs/model.md (10.4)): `d(z) = d₀ + S (z − base)`.
struct LinearGaps {
    base: Vec<Real>,
    gaps0: Vec<Real>,
    /// `∂d_r/∂z_j` per contact node.
    sens: Vec<Vec<Real>>,
}

impl LinearGaps {
    fn at(&self, z: &[Real]) -> Vec<Real> {
        self.gaps0
            .iter()
            .zip(&self.sens)
            .map(|(g, s)| {
                g + s.iter().zip(z.iter().zip(&self.base)).map(|(sj, (zj, bj))| sj * (zj - bj)).sum::<Real>()
            })
            .collect()
    }
}

/// The motion since the last accepted level (coordinates `accepted`) of every rigid partner's
/// material point at the contact nodes of `geometry`, the partners at the coordinates `q`
/// (docs/model.md (10.5)):
///
/// ```text
/// w_r = P(q)(P(q_{i−1})⁻¹(y_r)) − y_r,    y_r = X_r + [u_{i−1}](X_r),
/// ```
///
/// `X_r` the node's reference position (in finite strain the geometry's `position` is that of
/// the deformed configuration it was built on) and `[u_{i−1}]` the jump of the last accepted
/// displacement `previous`. Zero at nodes of pairs without a rigid body; empty (no motion)
/// without an accepted level.
fn partner_motion<const D: usize>(
    joint: &JointModel<D>,
    accepted: Option<&[Vec<Real>]>,
    q: &[Vec<Real>],
    geometry: &ContactGeometry<D>,
    previous: &[Vec<Vector<D>>],
) -> Vec<Vector<D>> {
    let Some(old) = accepted else { return Vec::new() };
    let poses: Vec<(RigidPose<D>, RigidPose<D>)> = joint
        .rigid_bodies()
        .iter()
        .zip(old.iter().zip(q))
        .map(|(body, (qo, qn))| (body.pose_of(qo), body.pose_of(qn)))
        .collect();
    let owner = joint.pair_rigid_owner(geometry);
    geometry
        .nodes
        .iter()
        .enumerate()
        .map(|(r, node)| match owner.get(node.pair).copied().flatten() {
            Some(ob) => {
                let x = joint
                    .model()
                    .body(node.node.0)
                    .ok()
                    .and_then(|body| body.mesh.nodes().get(node.node.1).copied())
                    .unwrap_or(node.position);
                let y = x + geometry.jump(r, previous).unwrap_or_else(Vector::<D>::zeros);
                let (old, new) = &poses[ob];
                new.position(&old.to_body(&y)) - y
            }
            None => Vector::<D>::zeros(),
        })
        .collect()
}

/// A force system: its resultant and its moment about the origin (3 components each).
type ForceSystem = ([Real; 3], [Real; 3]);

impl RigidDriver {
    pub(crate) fn new<const D: usize>(joint: &JointModel<D>) -> Self {
        let zeros = || joint.rigid_bodies().iter().map(|_| vec![0.0; rigid_dofs(D)]).collect();
        Self { q: zeros(), offset: zeros(), jacobian: None, accepted: None, slope: None }
    }

    /// Refuses what the dynamic analyses do not take with rigid bodies, naming the body: a
    /// force-controlled coordinate (the rigid bodies have no mass, so a dynamic analysis
    /// prescribes all their coordinates) and a part tied to a rigid body (its reaction would
    /// need the part's inertial forces).
    pub(crate) fn check_dynamic<const D: usize>(joint: &JointModel<D>) -> Result<(), JointError> {
        let names = dof_names(D);
        for body in joint.rigid_bodies() {
            if let Some(k) = body.force_dofs().first() {
                return Err(JointError::Invalid(format!(
                    "rigid body `{}`: the force-controlled coordinate `{}` is not supported in dynamic analyses \
                     (rigid bodies have no mass there: prescribe every coordinate, or use a static or \
                     quasi-static analysis for force control)",
                    body.name,
                    names.get(*k).copied().unwrap_or("?")
                )));
            }
        }
        if let Some((_, part, b)) = joint.rigid_ties().first() {
            return Err(JointError::Invalid(format!(
                "part `{part}` tied to rigid body `{}`: tied parts are not supported in dynamic analyses yet \
                 (static and quasi-static analyses take them); prescribe the part's motion instead",
                joint.rigid_bodies().get(*b).map(|r| r.name.as_str()).unwrap_or("?")
            )));
        }
        Ok(())
    }

    /// Sets every rigid coordinate to its prescribed value at `t` and poses the bodies
    /// (dynamic analyses: every coordinate prescribed, [`Self::check_dynamic`]); returns the
    /// control values.
    pub(crate) fn pose_prescribed<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        t: Real,
    ) -> Result<Vec<Vec<Real>>, JointError> {
        let values = self.set_controls(joint, t)?;
        self.set_poses(joint);
        Ok(values)
    }

    /// The rigid partners' motion at the contact nodes from the last accepted coordinates to
    /// the current ones, at the nodes' deformed positions of `previous` ([`partner_motion`];
    /// empty before the first accepted level).
    pub(crate) fn motion_since_accepted<const D: usize>(
        &self,
        joint: &JointModel<D>,
        geometry: &ContactGeometry<D>,
        previous: &[Vec<Vector<D>>],
    ) -> Vec<Vector<D>> {
        partner_motion(joint, self.accepted.as_deref(), &self.q, geometry, previous)
    }

    /// Accepts the current coordinates (the origin of the next [`Self::motion_since_accepted`]).
    pub(crate) fn accept(&mut self) {
        self.accepted = Some(self.q.clone());
    }

    /// `record` with the rigid bodies' records of a level solved elsewhere (a dynamic step, every
    /// coordinate prescribed): the bodies posed at the record's time, their reactions from the
    /// contact forces of `result` on `geometry`.
    pub(crate) fn record_prescribed_level<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        geometry: &ContactGeometry<D>,
        record: StepRecord,
        result: &StaticContactResult<D>,
    ) -> Result<StepRecord, JointError> {
        let t = record.time;
        let values = self.pose_prescribed(joint, t)?;
        self.finish(joint, geometry, record, result, &values, t, 1)
    }

    /// Forgets the force-controlled coordinates and the Jacobian.
    pub(crate) fn reset<const D: usize>(&mut self, joint: &JointModel<D>) {
        *self = Self::new(joint);
    }

    fn set_poses<const D: usize>(&self, joint: &JointModel<D>) {
        for (body, q) in joint.rigid_bodies().iter().zip(&self.q) {
            body.pose.set(body.pose_of(q));
        }
    }

    /// Solves one level at `t` with the rigid bodies posed by their prescribed coordinates and
    /// their force-controlled coordinates found from equilibrium (see the
    /// [module documentation](self)).
    pub(crate) fn level<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        stepper: &mut QuasiStaticStepper<D>,
        t: Real,
        solver: &dyn ContactSolver,
        mode: LevelMode,
    ) -> Result<Level<D>, JointError> {
        let model = joint.model();
        let bodies = joint.rigid_bodies();
        let values = self.set_controls(joint, t)?;
        let unknowns = force_unknowns(bodies);
        let posed_pairs = !joint.rigid_pair_bodies().is_empty();
        let checkpoint = (mode == LevelMode::Step).then(|| stepper.checkpoint());
        let cx = LevelContext { joint, t, solver, mode, checkpoint, unknowns: &unknowns };
        let mut solves = 0usize;
        let length = joint.model_size();
        // the level without force control: pose, rebuild, solve
        if unknowns.is_empty() {
            self.set_poses(joint);
            if posed_pairs {
                stepper.contact_mut().rebuild_geometry(model, joint.pairs())?;
                self.set_partner_motion(joint, stepper, mode)?;
            }
            let (record, result) = self.solve_once(joint, stepper, t, solver, mode, &mut solves)?;
            let record = self.finish(joint, stepper.geometry(), record, &result, &values, t, solves)?;
            self.accepted = Some(self.q.clone());
            return Ok((record, result));
        }
        let params = joint.force_control_params();
        let tied = unknowns.iter().any(|&(b, _)| joint.rigid_ties().iter().any(|(_, _, rb)| *rb == b));
        if params.bordered && posed_pairs && !tied && solver.solves_border() {
            if let Some(level) = self.bordered_level(&cx, stepper, &values, &mut solves)? {
                return Ok(level);
            }
        }
        let target: Vec<Real> = unknowns.iter().map(|&(b, k)| values[b][k]).collect();
        let scales = force_scales(bodies, &values, &unknowns, length);
        let mut best: Option<(Real, Level<D>)> = None;
        let mut jac = self.jacobian.clone().filter(|j| j.nrows() == unknowns.len());
        // the Jacobian was computed at the current iterate (by finite differences)
        let mut fresh = false;
        let geometry_tolerance = params.geometry_tolerance * length;
        let moved = |a: &[Real], b: &[Real]| {
            unknowns
                .iter()
                .zip(a.iter().zip(b))
                .map(|(&(_, k), (x, y))| (x - y).abs() * if k < D { 1.0 } else { length })
                .fold(0.0, Real::max)
        };
        let mut z: Vec<Real> = unknowns.iter().map(|&(b, k)| self.q[b][k]).collect();
        let (mut geometry, mut linear) = self.linearise(joint, stepper, &unknowns, &z, posed_pairs)?;
        let mut bracket = Bracket::default();
        let mut previous: Option<(Vec<Real>, Vec<Real>, Real)> = None;
        // several unknowns: the line search under way
        let mut line: Option<LineSearch> = None;
        // converged on first-order gaps: rebuild the geometry at `z` and solve again
        let mut confirm = false;
        // the rigid body of each pair (by pair name: the same for every rebuilt geometry)
        let owner = joint.pair_rigid_owner(&geometry);
        stepper.set_record_strain_energy(false);
        let outcome = loop {
            if solves >= params.max_solves {
                break Err(self.no_convergence(joint, &unknowns, &best, solves, t));
            }
            // one unknown: the geometry is rebuilt at the pose `z` when the iteration has
            // converged on the first-order gaps of `linear` away from the pose they were built
            // at (to confirm it on the exact geometry), or when it moved so far that first
            // order is no guide; in between, trials run on the first-order gaps (docs/model.md
            // (10.4)). Several unknowns (line searches on the potential, whose bracketing
            // does not survive a change of geometry): rebuilt at every move beyond the
            // tolerance.
            let away = moved(&z, &linear.base);
            let first_order = unknowns.len() == 1 && !confirm && away <= LINEAR_REACH * length;
            if posed_pairs && away > geometry_tolerance && !first_order {
                if confirm {
                    // the residual on the exact geometry differs a little from the first-order
                    // one: brackets and secants of the first-order trials do not carry over
                    bracket = Bracket::default();
                    previous = None;
                    line = None;
                    confirm = false;
                }
                // (errors leave the loop by `break`, so the stepper records energies again)
                match self.linearise(joint, stepper, &unknowns, &z, posed_pairs) {
                    Ok(built) => (geometry, linear) = built,
                    Err(e) => break Err(e),
                }
            }
            let ((record, result), reactions) =
                match self.trial(&cx, stepper, &linear, &geometry, &z, &mut solves) {
                    Ok(v) => v,
                    Err(e) => break Err(e),
                };
            let r: Vec<Real> = unknowns.iter().zip(&target).map(|(&(b, k), f)| reactions[b][k] + f).collect();
            let error = r.iter().zip(&scales).map(|(ri, s)| ri.abs() / s).fold(0.0, Real::max);
            tracing::debug!(t, solves, ?z, ?r, error, "force-control trial");
            // pressed: a node of a pair with a force-controlled body carries a normal force
            // (frozen Tresca friction holds with no normal force at all, so the reactions
            // alone do not tell a body that lifted off from one that touches)
            let pressed = result.solution.lambda_n.iter().zip(&geometry.nodes).any(|(l, node)| {
                *l > 0.0
                    && owner
                        .get(node.pair)
                        .copied()
                        .flatten()
                        .is_some_and(|b| unknowns.iter().any(|&(ub, _)| ub == b))
            });
            // a trial on first-order gaps away from their pose is not a solution of the level
            let exact = !posed_pairs || moved(&z, &linear.base) <= geometry_tolerance;
            if error <= params.tolerance && !exact {
                confirm = true;
                continue;
            }
            let converged = error <= params.tolerance;
            if exact && (best.as_ref().is_none_or(|(e, _)| error < *e) || converged) {
                best = Some((error, (record, result)));
            }
            if converged {
                break Ok(geometry);
            }
            // not touching: move to first contact along the applied forces
            let touching = pressed
                || unknowns.iter().any(|&(b, _)| joint.rigid_ties().iter().any(|(_, _, rb)| *rb == b));
            if !touching {
                match self.approach(joint, &unknowns, &target, &z, &linear, length) {
                    Ok(next) => z = next,
                    Err(e) => break Err(e),
                }
                previous = None;
                line = None;
                continue;
            }
            if unknowns.len() > 1 {
                // several unknowns: line searches on the potential Π (docs/model.md §10)
                if let Some(mut ls) = line.take() {
                    let phi = -dot(&r, &ls.direction);
                    if let Some(alpha) = ls.next_alpha(phi, error) {
                        z = ls.at(alpha);
                        line = Some(ls);
                        continue;
                    }
                }
                update_jacobian(&mut jac, previous.as_ref(), (&z, &r, error), params.fresh_jacobian, fresh);
                fresh = false;
                if jac.is_none() {
                    match self.fd_jacobian(
                        &cx,
                        stepper,
                        &linear,
                        &geometry,
                        &z,
                        &r,
                        &target,
                        length,
                        &mut solves,
                    ) {
                        Ok(j) => {
                            jac = Some(j);
                            fresh = true;
                        }
                        Err(e) => break Err(e),
                    }
                }
                let Some(ls) =
                    jac.as_ref().and_then(|j| LineSearch::start::<D>(j, &z, &r, error, &unknowns, length))
                else {
                    break Err(self.unresisted(joint, &unknowns));
                };
                tracing::debug!(t, ?ls.direction, ls.alpha, "force control: line search");
                previous = Some((z.clone(), r.clone(), error));
                z = ls.at(ls.alpha);
                line = Some(ls);
                continue;
            }
            bracket.update(z[0], r[0]);
            // one unknown: the secant, kept safe by the bracket
            if let (Some(j), Some((zp, rp, _))) = (&mut jac, &previous) {
                broyden(j, &z, &r, zp, rp);
            }
            // a secant update without slope (the residual did not change): a fresh Jacobian
            if jac.as_ref().is_some_and(|j| newton_step(j, &r).is_none()) {
                jac = None;
            }
            if jac.is_none() {
                match self.fd_jacobian(&cx, stepper, &linear, &geometry, &z, &r, &target, length, &mut solves)
                {
                    Ok(j) => jac = Some(j),
                    Err(e) => break Err(e),
                }
            }
            let Some(dz) = jac.as_ref().and_then(|j| newton_step(j, &r)) else {
                break Err(self.unresisted(joint, &unknowns));
            };
            previous = Some((z.clone(), r.clone(), error));
            let mut next: Vec<Real> = z.iter().zip(&dz).map(|(a, d)| a + d).collect();
            limit_step::<D>(&mut next, &z, &unknowns, length);
            if let Some((lo, hi)) = bracket.interval() {
                if !(next[0] > lo && next[0] < hi) {
                    next[0] = 0.5 * (lo + hi);
                }
            }
            z = next;
        };
        stepper.set_record_strain_energy(true);
        let geometry = outcome?;
        self.jacobian = jac;
        let Some((_, level)) = best.take() else {
            return Err(JointError::Invalid("internal: no solve".into()));
        };
        self.accept_level(joint, &geometry, level, &values, t, solves)
    }

    /// Ends a level of the linear path at the accepted solve `level`: the offsets of the
    /// coordinates' guesses kept for the next level, the strain energy (switched off during the
    /// trials) and the rigid bodies' figures recorded, the coordinates accepted.
    fn accept_level<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        geometry: &ContactGeometry<D>,
        (mut record, result): Level<D>,
        values: &[Vec<Real>],
        t: Real,
        solves: usize,
    ) -> Result<Level<D>, JointError> {
        self.keep_guess_offsets(joint, t);
        record.strain_energy = synovia_fem::post::total_strain_energy(joint.model(), &result.displacement)?;
        let record = self.finish(joint, geometry, record, &result, values, t, solves)?;
        self.accepted = Some(self.q.clone());
        Ok((record, result))
    }

    /// `q_k − guess_k(t)` of every force-controlled coordinate with a guess: the offset that
    /// starts the next level.
    fn keep_guess_offsets<const D: usize>(&mut self, joint: &JointModel<D>, t: Real) {
        for (bi, body) in joint.rigid_bodies().iter().enumerate() {
            for (k, c) in body.controls.iter().enumerate() {
                if let DofControl::Force { guess: Some(g), .. } = c {
                    self.offset[bi][k] = self.q[bi][k] - g.value(t);
                }
            }
        }
    }

    /// One level with the force-controlled coordinates `z` solved with the contact conditions
    /// (docs/model.md §10, "The coordinate in the contact solve"): the geometry built at `z`,
    /// per coordinate `(b, k)` the rates of the gaps `∂d_r/∂z = n_r · v_k(x_r)` and of the
    /// partner's motion `∂w_r/∂z = v_k(x_r)` handed to the solve with the target `Q = −F`
    /// ([`CoordinateBorder`]), which returns `ζ`; then the same at `z + ζ` until `ζ` is within
    /// the geometry tolerance. `None` (the search over trial solves takes over from the
    /// coordinates reached) when nothing in contact holds a body at a geometry built, a solve
    /// fails, the passes do not settle or the accepted level's balance misses the tolerance.
    fn bordered_level<const D: usize>(
        &mut self,
        cx: &LevelContext<'_, D>,
        stepper: &mut QuasiStaticStepper<D>,
        values: &[Vec<Real>],
        solves: &mut usize,
    ) -> Result<Option<Level<D>>, JointError> {
        let joint = cx.joint;
        let unknowns = cx.unknowns;
        let length = joint.model_size();
        let params = joint.force_control_params();
        // a rotation moves the body's points by ≈ its angle × the model size
        let unit: Vec<Real> = unknowns.iter().map(|&(_, k)| if k < D { 1.0 } else { length }).collect();
        let scales = force_scales(joint.rigid_bodies(), values, unknowns, length);
        let target: Vec<Real> = unknowns.iter().map(|&(b, k)| values[b][k]).collect();
        let mut z: Vec<Real> = unknowns.iter().map(|&(b, k)| self.q[b][k]).collect();
        stepper.set_record_strain_energy(false);
        let mut accepted = None;
        let mut approached = false;
        for pass in 0..BORDERED_PASSES {
            let (geometry, linear) = self.linearise(joint, stepper, unknowns, &z, true)?;
            if let Some(c) = &cx.checkpoint {
                stepper.rollback(c.clone());
            }
            self.set_partner_motion(joint, stepper, cx.mode)?;
            let owner = joint.pair_rigid_owner(&geometry);
            let borders: Vec<CoordinateBorder<D>> = unknowns
                .iter()
                .enumerate()
                .map(|(j, &(b, k))| {
                    let body = &joint.rigid_bodies()[b];
                    CoordinateBorder {
                        gap_rate: linear.sens.iter().map(|s| s[j]).collect(),
                        motion_rate: geometry
                            .nodes
                            .iter()
                            .map(|node| match owner.get(node.pair).copied().flatten() {
                                Some(ob) if ob == b => body.velocity(&self.q[b], k, &node.position),
                                _ => Vector::<D>::zeros(),
                            })
                            .collect(),
                        target: -values[b][k],
                    }
                })
                .collect();
            stepper.contact_mut().set_coordinate_borders(borders)?;
            let solved = self.solve_once(joint, stepper, cx.t, cx.solver, cx.mode, solves);
            stepper.contact_mut().set_coordinate_borders(Vec::new())?;
            let (record, result) = match solved {
                Ok(level) => level,
                Err(e) => {
                    // apart: move to first contact along the forces once, as the search does
                    let apart = linear
                        .gaps0
                        .iter()
                        .zip(&linear.sens)
                        .all(|(g, s)| s.iter().all(|v| *v == 0.0) || *g >= 0.0);
                    if apart && !approached {
                        approached = true;
                        z = self.approach(joint, unknowns, &target, &z, &linear, length)?;
                        tracing::debug!(
                            t = cx.t,
                            pass,
                            ?z,
                            "bordered force control: apart, moved to first contact"
                        );
                        continue;
                    }
                    tracing::debug!(t = cx.t, pass, ?z, error = %e, "bordered force control: solve failed, trial solves take over");
                    break;
                }
            };
            let zeta = result.solution.report.border_values.clone();
            tracing::debug!(t = cx.t, pass, ?z, ?zeta, "bordered force control");
            if zeta.len() != z.len() || zeta.iter().any(|v| !v.is_finite()) {
                break;
            }
            let moved = zeta.iter().zip(&unit).map(|(d, u)| (d * u).abs()).fold(0.0, Real::max);
            let next: Vec<Real> = z.iter().zip(&zeta).map(|(a, d)| a + d).collect();
            if moved <= params.geometry_tolerance * length {
                // the solution is that of the gaps followed to first order to `z + ζ` (within
                // the geometry tolerance of the geometry built, as an accepted trial of the
                // search): the bodies are there, and their balance is checked there (a
                // rotation's axes and the moment's point move with the coordinates)
                for (&(b, k), &v) in unknowns.iter().zip(&next) {
                    self.q[b][k] = v;
                }
                let reactions = self.reactions(joint, &geometry, &record, &result, cx.t)?;
                let error = unknowns
                    .iter()
                    .zip(&scales)
                    .map(|(&(b, k), s)| (reactions[b][k] + values[b][k]).abs() / s)
                    .fold(0.0, Real::max);
                if error <= params.tolerance {
                    self.set_poses(joint);
                    stepper.contact_mut().set_gaps(&linear.at(&next))?;
                    accepted = Some((geometry, record, result));
                    break;
                }
                tracing::debug!(
                    t = cx.t,
                    pass,
                    error,
                    "bordered force control: balance above the tolerance, another pass"
                );
            }
            z = next;
        }
        stepper.set_record_strain_energy(true);
        let Some((geometry, record, result)) = accepted else {
            return Ok(None);
        };
        self.accept_level(joint, &geometry, (record, result), values, cx.t, *solves).map(Some)
    }

    /// The level's start: the control values `h_k(t)`, `F_k(t)` of every rigid body, the
    /// prescribed coordinates set, the force-controlled ones at their guess (with the offset of
    /// the last level) or left at the last level's value.
    fn set_controls<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        t: Real,
    ) -> Result<Vec<Vec<Real>>, JointError> {
        let bodies = joint.rigid_bodies();
        let values: Vec<Vec<Real>> = bodies.iter().map(|b| b.control_values(t)).collect();
        for (bi, body) in bodies.iter().enumerate() {
            for (k, c) in body.controls.iter().enumerate() {
                match c {
                    DofControl::Prescribed(_) => self.q[bi][k] = values[bi][k],
                    DofControl::Force { guess: Some(g), .. } => {
                        self.q[bi][k] = g.value(t) + self.offset[bi][k]
                    }
                    DofControl::Force { guess: None, .. } => {}
                }
            }
            if self.q[bi].iter().chain(&values[bi]).any(|v| !v.is_finite()) {
                return Err(JointError::Invalid(format!(
                    "rigid body `{}` at t = {t}: a control value is not finite ({:?})",
                    body.name, values[bi]
                )));
            }
        }
        Ok(values)
    }

    /// One level of a nonlinear model (nonlinear materials or finite strain, docs/model.md
    /// §12) with rigid contact partners: the prescribed coordinates set, and a force-controlled
    /// coordinate `q_k` found inside the Newton iteration ([`NonlinearContact::step_gap_controlled`]):
    /// with `σ = sign F_k` and `w = σ q_k` (the travel along the applied force), each Newton
    /// iteration chooses `w` on its linearised problem so that
    ///
    /// ```text
    /// R(w) = −σ Q_k = −σ Σ_r κ_r Λ_n,r n_r · v_k(x_r) = σ F_k   (Q_k + F_k = 0, docs/model.md (10.3)),
    /// ```
    ///
    /// the gaps followed to first order in `w` from the pose the geometry was built at,
    /// `∂d_r/∂w = σ n_r · v_k(x_r)` (10.4); a solution farther than the geometry tolerance from
    /// that pose is solved again on the geometry rebuilt at it (at most 8 times). One
    /// force-controlled coordinate, rigid bodies as contact partners. Friction (docs/model.md
    /// (10.5)): Tresca with the slip bounds of the last accepted level, the slip measured from it
    /// relative to the partners, each posed at the trial's coordinate (`GapFriction`), and the
    /// friction forces in `Q_k` (`Σ_c g_c κ_r Λ_t,c · T_r v_k(x_r)` added), as the linear path.
    /// Friction against rigid bodies whose coordinates are all prescribed: the same slip origin,
    /// the partners' motion `w_r = P(q)(P(q_{i−1})⁻¹(y_r)) − y_r` from the last accepted
    /// coordinates to the prescribed ones ([`NonlinearContact::step_with_partner_motion`], no
    /// search, no cut-back). Several force-controlled coordinates: the translation with the
    /// largest applied force inside the iteration, the others by a quasi-Newton iteration around
    /// whole Newton levels ([`Self::several_level`]).
    ///
    /// # Errors
    /// [`JointError::Unsupported`] for several force-controlled coordinates none of which is a
    /// translation with a non-zero applied force; [`JointError::Invalid`] for a force-controlled
    /// coordinate that nothing resists, or no balance within `max_solves` Newton levels; the
    /// errors of the Newton iteration (no convergence, a force-controlled body not resisted).
    pub(crate) fn nonlinear_level<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        nl: &mut NonlinearContact<D>,
        t: Real,
        solver: &dyn ContactSolver,
    ) -> Result<(StepRecord, NonlinearResult<D>), JointError> {
        let bodies = joint.rigid_bodies();
        let values = self.set_controls(joint, t)?;
        let unknowns = force_unknowns(bodies);
        let length = joint.model_size();
        self.set_poses(joint);
        let owner_of = joint.pair_rigid_owner(nl.geometry());
        // a positive coefficient or a friction law (NonlinearContact::set_friction_law) on a
        // pair with a rigid body
        let laws = nl.friction_laws();
        let rigid_friction = nl.geometry().nodes.iter().any(|n| {
            (n.friction > 0.0 || laws.is_some_and(|l| l.law(n.pair).is_some()))
                && owner_of.get(n.pair).copied().flatten().is_some()
        });
        let tied = |b: usize| joint.rigid_ties().iter().any(|(_, _, rb)| *rb == b);
        let (level, solves) = match unknowns.as_slice() {
            [] => self.prescribed_level(joint, nl, t, solver, rigid_friction)?,
            // a body with a tied part balances its tie's reactions too, which the search
            // inside the Newton iteration (contact forces only) does not see: all its
            // coordinates around whole levels
            &[(b, k)] if !tied(b) => {
                let scale = force_scales(bodies, &values, &unknowns, length)[0];
                self.gap_level(joint, nl, t, solver, &values, (b, k), scale, rigid_friction)?
            }
            _ => {
                let around = unknowns.iter().any(|&(b, _)| tied(b));
                self.several_level(joint, nl, t, solver, &values, &unknowns, rigid_friction, around)?
            }
        };
        self.set_poses(joint);
        self.keep_guess_offsets(joint, t);
        let geometry = nl.geometry();
        let record = StepRecord {
            time: t,
            pairs: synovia_time::results::pair_records(geometry, &level.contact),
            strain_energy: level.strain_energy,
            iterations: level.report.total_iterations,
            solver: level.contact.solution.report.solver.clone(),
            fallback: level.contact.solution.report.fallback.clone(),
            ..Default::default()
        };
        let record = self.finish(joint, geometry, record, &level.contact, &values, t, solves)?;
        self.accepted = Some(self.q.clone());
        Ok((record, level))
    }

    /// [`partner_motion`] from the last accepted level to the current coordinates (every
    /// coordinate prescribed), for [`NonlinearContact::step_with_partner_motion`].
    #[allow(clippy::type_complexity)]
    fn partner_motion_fn<'a, const D: usize>(
        &self,
        joint: &'a JointModel<D>,
    ) -> impl Fn(&ContactGeometry<D>, &[Vec<Vector<D>>]) -> Vec<Vector<D>> + 'a {
        let accepted = self.accepted.clone();
        let q = self.q.clone();
        move |geometry, previous| partner_motion(joint, accepted.as_deref(), &q, geometry, previous)
    }

    /// One Newton level with every rigid coordinate at its value in `self.q` (the bodies
    /// posed): with friction against a rigid body ([`NonlinearContact::step_with_partner_motion`],
    /// docs/model.md (10.5): the slip measured relative to each partner's motion since the last
    /// accepted level), else the geometry rebuilt at the poses and [`NonlinearContact::step_to`].
    /// Returns the level and its one contact-solve count.
    fn prescribed_level<const D: usize>(
        &self,
        joint: &JointModel<D>,
        nl: &mut NonlinearContact<D>,
        t: Real,
        solver: &dyn ContactSolver,
        rigid_friction: bool,
    ) -> Result<(NonlinearResult<D>, usize), JointError> {
        let model = joint.model();
        if rigid_friction {
            let motion = self.partner_motion_fn(joint);
            return Ok((nl.step_with_partner_motion(model, t, solver, &motion)?, 1));
        }
        nl.rebuild_geometry(model)?;
        Ok((nl.step_to(model, t, solver)?, 1))
    }

    /// One Newton level with the force-controlled coordinate `(b, k)` found inside the
    /// iteration ([`NonlinearContact::step_gap_controlled`], see [`Self::nonlinear_level`]),
    /// every other coordinate at its value in `self.q`; commits the level and sets
    /// `self.q[b][k]`. Returns the level and the number of trials of the search.
    #[allow(clippy::too_many_arguments)]
    fn gap_level<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        nl: &mut NonlinearContact<D>,
        t: Real,
        solver: &dyn ContactSolver,
        values: &[Vec<Real>],
        (b, k): (usize, usize),
        scale: Real,
        rigid_friction: bool,
    ) -> Result<(NonlinearResult<D>, usize), JointError> {
        let model = joint.model();
        let bodies = joint.rigid_bodies();
        let length = joint.model_size();
        let params = joint.force_control_params();
        let f = values[b][k];
        let sigma = if f < 0.0 { -1.0 } else { 1.0 };
        let body = &bodies[b];
        let q0 = self.q[b].clone();
        let current = std::cell::Cell::new(q0[k]);
        let coordinates = |z: Real| {
            let mut q = q0.clone();
            q[k] = z;
            q
        };
        let pose = |w: Real| {
            current.set(sigma * w);
            body.pose.set(body.pose_of(&coordinates(sigma * w)));
        };
        let owner = joint.pair_rigid_owner(nl.geometry());
        let owned = |pair: usize| owner.get(pair).copied().flatten() == Some(b);
        let sensitivity = |geometry: &ContactGeometry<D>| -> Vec<Real> {
            let q = coordinates(current.get());
            geometry
                .nodes
                .iter()
                .map(|node| {
                    if owned(node.pair) {
                        sigma * node.normal.dot(&body.velocity(&q, k, &node.position))
                    } else {
                        0.0
                    }
                })
                .collect()
        };
        let resultant = |geometry: &ContactGeometry<D>, lambda_n: &[Real]| -> Real {
            let q = coordinates(current.get());
            let generalised: Real = geometry
                .nodes
                .iter()
                .zip(lambda_n)
                .filter(|(node, _)| owned(node.pair))
                .map(|(node, l)| node.weight * l * node.normal.dot(&body.velocity(&q, k, &node.position)))
                .sum();
            -sigma * generalised
        };
        // friction (docs/model.md (10.5)): the motion since the last accepted level of
        // every rigid partner's material point at the nodes' deformed positions, body
        // `b` at the trial's `w`, and the friction forces' part of the generalised force
        let accepted = self.accepted.clone();
        let all_q = self.q.clone();
        let motion =
            |geometry: &ContactGeometry<D>, previous: &[Vec<Vector<D>>], w: Real| -> Vec<Vector<D>> {
                let mut q = all_q.clone();
                q[b] = coordinates(sigma * w);
                partner_motion(joint, accepted.as_deref(), &q, geometry, previous)
            };
        // the force on the body of friction cell c: g_c κ_r Σ_j Λ_t,c,j T_j (the
        // opposite of the slave side's, synovia_time::results::pair_records)
        let friction_resultant =
            |geometry: &ContactGeometry<D>, cells: &[usize], bounds: &[Real], lambda_t: &[Real]| -> Real {
                let q = coordinates(current.get());
                let comps = D - 1;
                let generalised: Real = cells
                    .iter()
                    .zip(bounds)
                    .enumerate()
                    .filter_map(|(c, (&r, &g))| {
                        let node = geometry.nodes.get(r).filter(|node| owned(node.pair))?;
                        let lt = lambda_t.get(c * comps..(c + 1) * comps)?;
                        let v = body.velocity(&q, k, &node.position);
                        Some(
                            node.tangents
                                .iter()
                                .zip(lt)
                                .map(|(t, l)| g * node.weight * l * t.dot(&v))
                                .sum::<Real>(),
                        )
                    })
                    .sum();
                -sigma * generalised
            };
        let friction =
            rigid_friction.then_some(GapFriction { motion: &motion, resultant: &friction_resultant });
        // each pass commits its solution: with friction the next pass starts again from
        // the last accepted level (the slip origin and the frozen slip bounds are that
        // level's, not the previous pass's)
        let start = rigid_friction.then(|| nl.checkpoint());
        let mut w = sigma * q0[k];
        let mut trials = 0;
        let mut passes = 0;
        let mut iterations = 0;
        let level = loop {
            if let (Some(c), true) = (&start, passes > 0) {
                nl.restore(c.clone())?;
            }
            let mut control = GapControl {
                pose: &pose,
                sensitivity: &sensitivity,
                resultant: &resultant,
                target: sigma * f,
                tolerance: params.tolerance * scale,
                slope: self.slope.unwrap_or(0.0),
                w,
                overlap: 1e-4 * length,
                max_step: 1e-2 * length,
                base: w,
                trials: 0,
                friction,
            };
            let mut level = nl.step_gap_controlled(model, t, solver, &mut control)?;
            trials += control.trials;
            iterations += level.report.total_iterations;
            level.report.total_iterations = iterations;
            passes += 1;
            if control.slope > 0.0 && control.slope.is_finite() {
                self.slope = Some(control.slope);
            }
            w = control.w;
            let moved = (w - control.base).abs() * if k < D { 1.0 } else { length };
            tracing::debug!(
                t,
                passes,
                w,
                base = control.base,
                trials = control.trials,
                "gap-controlled level"
            );
            if moved <= params.geometry_tolerance * length {
                break level;
            }
            if passes >= 8 {
                return Err(JointError::Invalid(format!(
                    "t = {t}: the force-controlled `{}`.{} moved by {moved:e} from the pose of its contact geometry after {passes} rebuilds (tolerance {:e})",
                    body.name,
                    dof_names(D)[k],
                    params.geometry_tolerance * length
                )));
            }
        };
        self.q[b][k] = sigma * w;
        Ok((level, trials))
    }

    /// A Newton level with several force-controlled coordinates (docs/model.md §12): the
    /// translation with the largest applied force, `p`, is found inside the Newton iteration
    /// ([`Self::gap_level`]), the others, `z`, by a quasi-Newton iteration around it on their
    /// balance
    ///
    /// ```text
    /// r_j(z) = Q_j(z) + F_j = 0,     z ← z − J⁻¹ r,
    /// ```
    ///
    /// each evaluation of `r` a whole Newton level (with friction from the level's start, a
    /// checkpoint restored; frictionless from the last evaluation's solution), `p` balanced in it; `J` by finite differences (a step of 1e-6 of the model size,
    /// or 1e-6 rad), carried between levels and updated by Broyden's formula, computed afresh
    /// when a step did not reduce the largest relative error fourfold (as the linear path,
    /// docs/model.md (10.3)); each step the linear path's line search on the potential
    /// (`LineSearch`): along the modified Newton direction `d`, `z(α) = z + α d` (α from the
    /// step caps, 2 % of the model size or 0.02 rad) until `φ(α) = −r(z(α))·d` has dropped to a
    /// tenth of `|φ(0)|` (regula falsi once it changed sign) or the error fourfold. Accepted when
    /// `|r_j| ≤ tolerance × scale_j` ([`ForceControlParams`]). Returns the accepted level (its
    /// iterations and contact solves summed over the evaluations) and the contact solves.
    ///
    /// With `around` (a force-controlled rigid body with a tied part, whose balance includes
    /// the tie's reactions from the internal forces, [`synovia_fem::post::
    /// part_reactions_with_kinematics`]) no coordinate is found inside the iteration: all of
    /// them are `z`, each evaluation a level with every coordinate prescribed.
    #[allow(clippy::too_many_arguments)]
    fn several_level<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        nl: &mut NonlinearContact<D>,
        t: Real,
        solver: &dyn ContactSolver,
        values: &[Vec<Real>],
        unknowns: &[(usize, usize)],
        rigid_friction: bool,
        around: bool,
    ) -> Result<(NonlinearResult<D>, usize), JointError> {
        let bodies = joint.rigid_bodies();
        let length = joint.model_size();
        let params = joint.force_control_params();
        let scales = force_scales(bodies, values, unknowns, length);
        let inside = unknowns
            .iter()
            .enumerate()
            .filter(|(_, &(b, k))| k < D && values[b][k] != 0.0)
            .max_by(|(_, &(b1, k1)), (_, &(b2, k2))| values[b1][k1].abs().total_cmp(&values[b2][k2].abs()))
            .map(|(i, _)| i);
        let p = match (around, inside) {
            (true, _) => None,
            (false, Some(p)) => Some(p),
            (false, None) => {
                return Err(JointError::Unsupported {
                solver: "nonlinear (Newton)".into(),
                feature: format!(
                    "{} force-controlled degrees of freedom of rigid bodies with nonlinear materials or finite strain, none of them a translation with a non-zero applied force at t = {t} (the Newton path finds one such translation inside the iteration and the others around it)",
                    unknowns.len()
                ),
            });
            }
        };
        let extras: Vec<(usize, usize)> =
            unknowns.iter().enumerate().filter(|(i, _)| Some(*i) != p).map(|(_, u)| *u).collect();
        let extra_scales: Vec<Real> =
            scales.iter().enumerate().filter(|(i, _)| Some(*i) != p).map(|(_, s)| *s).collect();
        let target: Vec<Real> = extras.iter().map(|&(b, k)| values[b][k]).collect();
        let m = extras.len();
        let start = nl.checkpoint();
        let mut first = true;
        let evaluations = std::cell::Cell::new(0usize);
        let solves = std::cell::Cell::new(0usize);
        let iterations = std::cell::Cell::new(0usize);
        // r(z): a whole Newton level from the level's start with the extra coordinates at `z`
        let mut evaluate = |this: &mut Self,
                            nl: &mut NonlinearContact<D>,
                            z: &[Real]|
         -> Result<(NonlinearResult<D>, Vec<Real>, Real), JointError> {
            // with friction every evaluation starts from the level's start (the slip origin and
            // the frozen slip bounds are the last accepted level's); frictionless, from the last
            // evaluation's solution (the elastic level's solution does not depend on the
            // iterate it starts from, and one near it needs fewer Newton iterations and
            // geometry passes; measured at tkr3d's poses 0, 13, 50: Newton iterations 820 -> 562,
            // contact solves 1 946 -> 1 237, the same solutions to the balance tolerance)
            // (with every coordinate prescribed, `around`: always from the level's start, so
            // that the evaluation is a level from the last accepted time to `t`)
            if !std::mem::take(&mut first) && (rigid_friction || p.is_none()) {
                nl.restore(start.clone())?;
            }
            for (&(b, k), &zj) in extras.iter().zip(z) {
                this.q[b][k] = zj;
            }
            this.set_poses(joint);
            tracing::debug!(t, ?z, "force control around the Newton level: evaluation");
            let (level, trials) = match p {
                Some(p) => {
                    this.gap_level(joint, nl, t, solver, values, unknowns[p], scales[p], rigid_friction)?
                }
                // every coordinate prescribed at `z` (as a level without force control)
                None => this.prescribed_level(joint, nl, t, solver, rigid_friction)?,
            };
            evaluations.set(evaluations.get() + 1);
            solves.set(solves.get() + trials);
            iterations.set(iterations.get() + level.report.total_iterations);
            this.set_poses(joint);
            let geometry = nl.geometry();
            let record = StepRecord {
                time: t,
                pairs: synovia_time::results::pair_records(geometry, &level.contact),
                ..Default::default()
            };
            let reactions = this.reactions(joint, geometry, &record, &level.contact, t)?;
            let r: Vec<Real> = extras.iter().zip(&target).map(|(&(b, k), f)| reactions[b][k] + f).collect();
            let error = r.iter().zip(&extra_scales).map(|(ri, s)| ri.abs() / s).fold(0.0, Real::max);
            tracing::debug!(t, ?z, ?r, error, "force control around the Newton level");
            Ok((level, r, error))
        };
        let mut z: Vec<Real> = extras.iter().map(|&(b, k)| self.q[b][k]).collect();
        let (mut level, mut r, mut error) = evaluate(self, nl, &z)?;
        let mut jac = self.jacobian.clone().filter(|j| j.nrows() == m);
        let mut fresh = false;
        let mut previous: Option<(Vec<Real>, Vec<Real>, Real)> = None;
        while error > params.tolerance {
            if evaluations.get() >= params.max_solves {
                return Err(JointError::Invalid(format!(
                    "t = {t}: the force-controlled degrees of freedom {} did not reach equilibrium in {} Newton levels (relative balance error {error:.3e}, tolerance {:.1e})",
                    dof_list(bodies, &extras),
                    evaluations.get(),
                    params.tolerance
                )));
            }
            update_jacobian(&mut jac, previous.as_ref(), (&z, &r, error), params.fresh_jacobian, fresh);
            fresh = false;
            if jac.is_none() {
                let mut j = nalgebra::DMatrix::<Real>::zeros(m, m);
                for col in 0..m {
                    let mut h = if extras[col].1 < D { 1e-6 * length } else { 1e-6 };
                    // with every coordinate around the levels, the step along the applied
                    // force (a tied block lifted off its only contact would feel nothing)
                    if p.is_none() && target[col] < 0.0 {
                        h = -h;
                    }
                    let mut zh = z.clone();
                    zh[col] += h;
                    let (_, mut rh, _) = evaluate(self, nl, &zh)?;
                    // ... and, while nothing it moves touches (a tied block held off its
                    // contact by the prescribed coordinates), tenfold steps up to 1 % of the
                    // model size: a secant to first contact
                    let unchanged =
                        |rh: &[Real]| (0..m).all(|row| (rh[row] - r[row]).abs() <= 1e-9 * extra_scales[row]);
                    while p.is_none() && unchanged(&rh) && h.abs() < 1e-2 * length {
                        h *= 10.0;
                        zh[col] = z[col] + h;
                        rh = evaluate(self, nl, &zh)?.1;
                    }
                    for row in 0..m {
                        j[(row, col)] = (rh[row] - r[row]) / h;
                    }
                    // a coordinate whose motion changes no balance beyond rounding is not
                    // resisted (e.g. a rotation of a sphere about its centre)
                    if unchanged(&rh) {
                        return Err(self.unresisted(joint, &extras[col..=col]));
                    }
                }
                jac = Some(j);
                fresh = true;
            }
            // the linear path's line search on the potential (`LineSearch`, docs/model.md
            // (10.3)): the modified Newton direction, then `α` along it until `φ = −r·d` has
            // dropped to a tenth (bracketed by regula falsi once it changed sign) or the error
            // fourfold. (The scaled norm of `r` is no merit here: with the femur of tkr3d on
            // two condyles the moment saturates at ± the load times the half distance between
            // them once one lifts off, balance lies in a window of ≈ 1e-3 rad, and steps halved
            // from the 0.02 rad cap jumped between the two saturated sides, 40 Newton levels
            // at pose 0.)
            let Some(mut ls) =
                jac.as_ref().and_then(|j| LineSearch::start::<D>(j, &z, &r, error, &extras, length))
            else {
                return Err(self.unresisted(joint, &extras));
            };
            tracing::debug!(t, ?ls.direction, ls.alpha, "force control around the Newton level: line search");
            previous = Some((z.clone(), r.clone(), error));
            loop {
                z = ls.at(ls.alpha);
                (level, r, error) = evaluate(self, nl, &z)?;
                if error <= params.tolerance || evaluations.get() >= params.max_solves {
                    break;
                }
                if ls.next_alpha(-dot(&r, &ls.direction), error).is_none() {
                    break;
                }
            }
        }
        self.jacobian = jac;
        level.report.total_iterations = iterations.get();
        level.report.sublevels = evaluations.get();
        tracing::debug!(
            t,
            evaluations = evaluations.get(),
            iterations = iterations.get(),
            solves = solves.get(),
            error,
            "several force-controlled coordinates"
        );
        Ok((level, solves.get()))
    }

    /// The rigid bodies posed at the force-controlled coordinates `z`, the contact geometry
    /// rebuilt there, and its gaps as first-order functions of `z` (docs/model.md (10.4)).
    fn linearise<const D: usize>(
        &mut self,
        joint: &JointModel<D>,
        stepper: &mut QuasiStaticStepper<D>,
        unknowns: &[(usize, usize)],
        z: &[Real],
        posed_pairs: bool,
    ) -> Result<(ContactGeometry<D>, LinearGaps), JointError> {
        for (&(b, k), &zj) in unknowns.iter().zip(z) {
            self.q[b][k] = zj;
        }
        self.set_poses(joint);
        if posed_pairs {
            stepper.contact_mut().rebuild_geometry(joint.model(), joint.pairs())?;
        }
        let geometry = stepper.geometry().clone();
        let linear = LinearGaps {
            base: z.to_vec(),
            gaps0: geometry.nodes.iter().map(|n| n.gap).collect(),
            sens: self.gap_sensitivities(joint, &geometry, unknowns),
        };
        Ok((geometry, linear))
    }

    /// The motion of the rigid partners' material points at the contact nodes since the last
    /// accepted level, `w_r = P(q)(P(q_{i−1})⁻¹(y_r)) − y_r` at the nodes' deformed positions
    /// `y_r = x_r + u_r(t_{i−1})` (docs/model.md §10): the slip of friction against a moving
    /// rigid body is measured relative to it. Zero for a static solve (no slip origin) and for
    /// nodes of pairs without a rigid body.
    fn set_partner_motion<const D: usize>(
        &self,
        joint: &JointModel<D>,
        stepper: &mut QuasiStaticStepper<D>,
        mode: LevelMode,
    ) -> Result<(), JointError> {
        let motion = match (&self.accepted, stepper.last_result(), mode) {
            (Some(old), Some(last), LevelMode::Step) => {
                let geometry = stepper.geometry();
                let owner = joint.pair_rigid_owner(geometry);
                let bodies = joint.rigid_bodies();
                let poses: Vec<(RigidPose<D>, RigidPose<D>)> = bodies
                    .iter()
                    .zip(old.iter().zip(&self.q))
                    .map(|(b, (qo, qn))| (b.pose_of(qo), b.pose_of(qn)))
                    .collect();
                geometry
                    .nodes
                    .iter()
                    .enumerate()
                    .map(|(r, node)| match owner.get(node.pair).copied().flatten() {
                        Some(b) => {
                            let y = node.position
                                + geometry.jump(r, &last.displacement).unwrap_or_else(Vector::<D>::zeros);
                            let (old, new) = &poses[b];
                            new.position(&old.to_body(&y)) - y
                        }
                        None => Vector::<D>::zeros(),
                    })
                    .collect()
            }
            _ => Vec::new(),
        };
        stepper.contact_mut().set_partner_motion(motion)?;
        Ok(())
    }

    /// One contact solve of the level.
    fn solve_once<const D: usize>(
        &self,
        joint: &JointModel<D>,
        stepper: &mut QuasiStaticStepper<D>,
        t: Real,
        solver: &dyn ContactSolver,
        mode: LevelMode,
        solves: &mut usize,
    ) -> Result<Level<D>, JointError> {
        let model = joint.model();
        *solves += 1;
        let (record, result) = match mode {
            LevelMode::Restart { warm } => stepper.restart(model, t, solver, warm || *solves > 1)?,
            LevelMode::Step => stepper.step(model, t, solver)?,
        };
        Ok((record, result.clone()))
    }

    /// `∂d_r/∂q_k = n_r · v_k(x_r)` for the nodes of the pairs of the rigid body owning
    /// unknown `j` (zero elsewhere).
    fn gap_sensitivities<const D: usize>(
        &self,
        joint: &JointModel<D>,
        geometry: &ContactGeometry<D>,
        unknowns: &[(usize, usize)],
    ) -> Vec<Vec<Real>> {
        let owner = joint.pair_rigid_owner(geometry);
        geometry
            .nodes
            .iter()
            .map(|node| {
                unknowns
                    .iter()
                    .map(|&(b, k)| match owner.get(node.pair).copied().flatten() {
                        Some(ob) if ob == b => {
                            let body = &joint.rigid_bodies()[b];
                            node.normal.dot(&body.velocity(&self.q[b], k, &node.position))
                        }
                        _ => 0.0,
                    })
                    .collect()
            })
            .collect()
    }

    /// Generalised forces `Q` on every rigid body from its contact pairs and tied parts,
    /// with the resultant and moment (about the origin).
    #[tracing::instrument(level = "debug", skip_all)]
    fn loads<const D: usize>(
        &self,
        joint: &JointModel<D>,
        geometry: &ContactGeometry<D>,
        record: &StepRecord,
        result: &StaticContactResult<D>,
        t: Real,
    ) -> Result<Vec<ForceSystem>, JointError> {
        let mut out = vec![([0.0; 3], [0.0; 3]); joint.rigid_bodies().len()];
        let owner = joint.pair_rigid_owner(geometry);
        for (pi, rec) in record.pairs.iter().enumerate() {
            if let Some(b) = owner.get(pi).copied().flatten() {
                for i in 0..3 {
                    out[b].0[i] -= rec.force[i];
                    out[b].1[i] -= rec.moment[i];
                }
            }
        }
        for (body, part, b) in joint.rigid_ties() {
            let pose = joint.rigid_bodies()[*b].pose_of(&self.q[*b]);
            let u = result
                .displacement
                .get(body.0)
                .ok_or_else(|| JointError::Invalid("internal: no displacement".into()))?;
            let mesh = &joint.model().body(*body)?.mesh;
            // a nonlinear model's reactions from its internal force (finite strain: the
            // first Piola–Kirchhoff nodal forces), a linear one's from K u
            let reactions = if joint.is_nonlinear() {
                let kinematics = joint.kinematics().get(body.0).copied().unwrap_or_default();
                synovia_fem::post::part_reactions_with_kinematics(
                    joint.model(),
                    *body,
                    part,
                    u,
                    t,
                    kinematics,
                )?
            } else {
                synovia_fem::post::part_reactions(joint.model(), *body, part, u, t)?
            };
            for (i, r) in reactions {
                let x = pose.position(&mesh.nodes()[i]);
                let f = embed(&-r);
                let m = cross(embed(&x), f);
                for c in 0..3 {
                    out[*b].0[c] += f[c];
                    out[*b].1[c] += m[c];
                }
            }
        }
        Ok(out)
    }

    fn reactions<const D: usize>(
        &self,
        joint: &JointModel<D>,
        geometry: &ContactGeometry<D>,
        record: &StepRecord,
        result: &StaticContactResult<D>,
        t: Real,
    ) -> Result<Vec<Vec<Real>>, JointError> {
        Ok(self
            .loads(joint, geometry, record, result, t)?
            .into_iter()
            .zip(joint.rigid_bodies())
            .zip(&self.q)
            .map(|(((f, m), body), q)| body.generalised(q, f, m))
            .collect())
    }

    /// The record with the rigid bodies' figures.
    #[allow(clippy::too_many_arguments)]
    fn finish<const D: usize>(
        &self,
        joint: &JointModel<D>,
        geometry: &ContactGeometry<D>,
        mut record: StepRecord,
        result: &StaticContactResult<D>,
        values: &[Vec<Real>],
        t: Real,
        solves: usize,
    ) -> Result<StepRecord, JointError> {
        let loads = self.loads(joint, geometry, &record, result, t)?;
        let length = joint.model_size();
        let bodies = joint.rigid_bodies();
        let all: Vec<(usize, usize)> = bodies
            .iter()
            .enumerate()
            .flat_map(|(bi, b)| b.force_dofs().into_iter().map(move |k| (bi, k)))
            .collect();
        let scales = force_scales(bodies, values, &all, length);
        record.rigid = bodies
            .iter()
            .enumerate()
            .map(|(b, body)| {
                let q = &self.q[b];
                let (f, m) = loads[b];
                let reaction = body.generalised(q, f, m);
                let applied: Vec<Option<Real>> = body
                    .controls
                    .iter()
                    .enumerate()
                    .map(|(k, c)| matches!(c, DofControl::Force { .. }).then_some(values[b][k]))
                    .collect();
                let balance_error = all
                    .iter()
                    .zip(&scales)
                    .filter(|((bb, _), _)| *bb == b)
                    .map(|(&(_, k), s)| (reaction[k] + values[b][k]).abs() / s)
                    .fold(0.0, Real::max);
                RigidRecord {
                    name: body.name.clone(),
                    dofs: q.clone(),
                    reaction,
                    applied,
                    force: f,
                    moment: body.moment_about_centre(q, f, m),
                    balance_error,
                    solves,
                }
            })
            .collect();
        Ok(record)
    }

    /// Moves the force-controlled coordinates to first contact along their applied forces:
    /// the smallest motion that closes a gap, with a little overlap.
    #[allow(clippy::too_many_arguments)]
    fn approach<const D: usize>(
        &self,
        joint: &JointModel<D>,
        unknowns: &[(usize, usize)],
        target: &[Real],
        z: &[Real],
        linear: &LinearGaps,
        length: Real,
    ) -> Result<Vec<Real>, JointError> {
        let gaps = linear.at(z);
        let mut next = z.to_vec();
        let mut moved = false;
        for (j, (&f, zj)) in target.iter().zip(z).enumerate() {
            if f == 0.0 {
                continue;
            }
            let s = f.signum();
            // gap at z of every node, and its rate along s
            let mut best = Real::INFINITY;
            for (g, sr) in gaps.iter().zip(&linear.sens) {
                let rate = sr[j] * s;
                if rate < 0.0 {
                    best = best.min(g.max(0.0) / -rate);
                }
            }
            if best.is_finite() {
                next[j] = zj + s * (best + 1e-4 * length);
                moved = true;
            }
        }
        if !moved {
            return Err(self.unresisted(joint, unknowns));
        }
        Ok(next)
    }

    /// One trial solve of the level at the force-controlled coordinates `z`: the rigid bodies
    /// posed, the gaps followed to first order (10.4), the stepper back at the level's start;
    /// returns the solve and the generalised forces on every rigid body.
    #[tracing::instrument(level = "debug", skip_all)]
    fn trial<const D: usize>(
        &mut self,
        cx: &LevelContext<'_, D>,
        stepper: &mut QuasiStaticStepper<D>,
        linear: &LinearGaps,
        geometry: &ContactGeometry<D>,
        z: &[Real],
        solves: &mut usize,
    ) -> Result<(Level<D>, Vec<Vec<Real>>), JointError> {
        for (&(b, k), &zj) in cx.unknowns.iter().zip(z) {
            self.q[b][k] = zj;
        }
        self.set_poses(cx.joint);
        if !cx.joint.rigid_pair_bodies().is_empty() {
            stepper.contact_mut().set_gaps(&linear.at(z))?;
        }
        if let Some(c) = &cx.checkpoint {
            stepper.rollback(c.clone());
        }
        if !cx.joint.rigid_pair_bodies().is_empty() {
            self.set_partner_motion(cx.joint, stepper, cx.mode)?;
        }
        let (record, result) = self.solve_once(cx.joint, stepper, cx.t, cx.solver, cx.mode, solves)?;
        let reactions = self.reactions(cx.joint, geometry, &record, &result, cx.t)?;
        Ok(((record, result), reactions))
    }

    /// The Jacobian `∂r/∂z` by one finite-difference trial per unknown (a step of 1e-7 of the
    /// model size, or 1e-7 rad, along the applied force); the coordinates are left at `z`.
    #[allow(clippy::too_many_arguments)]
    fn fd_jacobian<const D: usize>(
        &mut self,
        cx: &LevelContext<'_, D>,
        stepper: &mut QuasiStaticStepper<D>,
        linear: &LinearGaps,
        geometry: &ContactGeometry<D>,
        z: &[Real],
        r: &[Real],
        target: &[Real],
        length: Real,
        solves: &mut usize,
    ) -> Result<nalgebra::DMatrix<Real>, JointError> {
        let m = cx.unknowns.len();
        let mut j = nalgebra::DMatrix::<Real>::zeros(m, m);
        for col in 0..m {
            let (_, k) = cx.unknowns[col];
            // a step small enough to keep the contact sets (the derivative of the affine piece
            // at `z`), large against the rounding of the reactions (≈ 1e-12 relative)
            let h = if k < D { 1e-7 * length } else { 1e-7 } * if target[col] < 0.0 { -1.0 } else { 1.0 };
            let mut zp = z.to_vec();
            zp[col] += h;
            let (_, reactions) = self.trial(cx, stepper, linear, geometry, &zp, solves)?;
            for (row, &(b, kk)) in cx.unknowns.iter().enumerate() {
                j[(row, col)] = (reactions[b][kk] + target[row] - r[row]) / h;
            }
        }
        for (&(b, k), &zj) in cx.unknowns.iter().zip(z) {
            self.q[b][k] = zj;
        }
        Ok(j)
    }

    fn unresisted<const D: usize>(&self, joint: &JointModel<D>, unknowns: &[(usize, usize)]) -> JointError {
        JointError::Invalid(format!(
            "force-controlled degree(s) of freedom {} are not resisted: no contact pair of the rigid body closes a gap when it moves along the applied force, and no tied part holds it (add a contact pair or a tie, or prescribe the degree of freedom)",
            dof_list(joint.rigid_bodies(), unknowns)
        ))
    }

    fn no_convergence<const D: usize>(
        &self,
        joint: &JointModel<D>,
        unknowns: &[(usize, usize)],
        best: &Option<(Real, Level<D>)>,
        solves: usize,
        t: Real,
    ) -> JointError {
        JointError::Invalid(format!(
            "t = {t}: the force-controlled degrees of freedom {} did not reach equilibrium in {solves} contact solves (best relative balance error {:.3e}, tolerance {:.1e})",
            dof_list(joint.rigid_bodies(), unknowns),
            best.as_ref().map_or(Real::INFINITY, |(e, _)| *e),
            joint.force_control_params().tolerance
        ))
    }
}

/// The coordinates `(body, dof)` named for a message: "`femur`.ty, `femur`.rx".
fn dof_list<const D: usize>(bodies: &[RigidBody<D>], unknowns: &[(usize, usize)]) -> String {
    let names: Vec<String> =
        unknowns.iter().map(|&(b, k)| format!("`{}`.{}", bodies[b].name, dof_names(D)[k])).collect();
    names.join(", ")
}

/// The force-controlled coordinates of the rigid bodies, `(body, dof)`, the unknowns of a
/// level's force balance (10.3).
fn force_unknowns<const D: usize>(bodies: &[RigidBody<D>]) -> Vec<(usize, usize)> {
    bodies.iter().enumerate().flat_map(|(bi, b)| b.force_dofs().into_iter().map(move |k| (bi, k))).collect()
}

/// `scale_j`: the largest applied force of the owning body (translations), times the model
/// size for moments, or the largest applied moment, whichever is larger.
fn force_scales<const D: usize>(
    bodies: &[RigidBody<D>],
    values: &[Vec<Real>],
    unknowns: &[(usize, usize)],
    length: Real,
) -> Vec<Real> {
    unknowns
        .iter()
        .map(|&(b, k)| {
            let applied = |pred: &dyn Fn(usize) -> bool| {
                bodies[b]
                    .force_dofs()
                    .into_iter()
                    .filter(|&kk| pred(kk))
                    .map(|kk| values[b][kk].abs())
                    .fold(0.0, Real::max)
            };
            let force = applied(&|kk| kk < D);
            let moment = applied(&|kk| kk >= D);
            let s = if k < D { force.max(moment / length) } else { moment.max(force * length) };
            if s > 0.0 {
                s
            } else {
                Real::MIN_POSITIVE.sqrt()
            }
        })
        .collect()
}

fn newton_step(j: &nalgebra::DMatrix<Real>, r: &[Real]) -> Option<Vec<Real>> {
    let rhs = nalgebra::DVector::from_iterator(r.len(), r.iter().map(|v| -v));
    let lu = j.clone().lu();
    let dz = lu.solve(&rhs)?;
    dz.iter().all(|v| v.is_finite()).then(|| dz.iter().copied().collect())
}

/// Broyden's update `J += (Δr − J Δz) Δzᵀ / (Δzᵀ Δz)`.
/// The Jacobian of the quasi-Newton iteration over the force-controlled coordinates after the
/// iterate `(z, r, error)`: dropped (to be taken again by finite differences) when the last
/// step did not reduce the error fourfold or `always_fresh` asks for it — unless it was just
/// taken (`fresh`) — since the residual is piecewise affine (a contact region that lifts off
/// or closes changes its slope); otherwise updated by Broyden's formula from the previous
/// iterate `(z_p, r_p, error_p)`.
#[allow(clippy::type_complexity)]
fn update_jacobian(
    jac: &mut Option<nalgebra::DMatrix<Real>>,
    previous: Option<&(Vec<Real>, Vec<Real>, Real)>,
    (z, r, error): (&[Real], &[Real], Real),
    always_fresh: bool,
    fresh: bool,
) {
    match (jac.as_mut(), previous) {
        (Some(_), Some((_, _, ep))) if (error > 0.25 * ep || always_fresh) && !fresh => *jac = None,
        (Some(j), Some((zp, rp, _))) => broyden(j, z, r, zp, rp),
        _ => {}
    }
}

fn broyden(j: &mut nalgebra::DMatrix<Real>, z: &[Real], r: &[Real], zp: &[Real], rp: &[Real]) {
    let dz = nalgebra::DVector::from_iterator(z.len(), z.iter().zip(zp).map(|(a, b)| a - b));
    let dr = nalgebra::DVector::from_iterator(r.len(), r.iter().zip(rp).map(|(a, b)| a - b));
    let n2 = dz.norm_squared();
    if n2 > 0.0 {
        let u = (dr - &*j * &dz) / n2;
        *j += u * dz.transpose();
    }
}

/// The latest iterates of a single unknown with a positive and with a negative residual:
/// a sign-change bracket once both exist.
#[derive(Debug, Clone, Copy, Default)]
struct Bracket {
    positive: Option<Real>,
    negative: Option<Real>,
}

impl Bracket {
    fn update(&mut self, z: Real, r: Real) {
        if r > 0.0 {
            self.positive = Some(z);
        } else if r < 0.0 {
            self.negative = Some(z);
        }
    }
    /// `(lo, hi)` if the residual changes sign between two iterates.
    fn interval(&self) -> Option<(Real, Real)> {
        let (a, b) = (self.positive?, self.negative?);
        Some((a.min(b), a.max(b)))
    }
}

/// Limits a step to 2 % of the model size (translations) or 0.02 rad (rotations).
fn limit_step<const D: usize>(next: &mut [Real], z: &[Real], unknowns: &[(usize, usize)], length: Real) {
    for ((n, zj), &(_, k)) in next.iter_mut().zip(z).zip(unknowns) {
        let cap = step_cap::<D>(k, length);
        *n = zj + (*n - zj).clamp(-cap, cap);
    }
}

/// The largest step of degree of freedom `k`: 2 % of the model size (translations) or
/// 0.02 rad (rotations).
fn step_cap<const D: usize>(k: usize, length: Real) -> Real {
    if k < D {
        0.02 * length
    } else {
        0.02
    }
}

fn dot(a: &[Real], b: &[Real]) -> Real {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// A line search of the force-control iteration with several unknowns on the potential
/// `Π(z) = E(z) − F·z` (`E` the elastic energy at the contact solution for the pose `z`,
/// `F` the applied generalised forces), whose gradient is `−r = −(Q + F)`: along
/// `z(α) = base + α d`, `φ(α) = dΠ/dα = −r(z(α))·d` starts negative and grows (`Π` is convex
/// for a convex contact problem); the step ends where `|φ(α)| ≤ 0.1 |φ(0)|` (strong Wolfe),
/// bracketing by regula falsi once `φ` changed sign and doubling `α` (up to 10 % of the model
/// size) while it did not — this also walks along directions nothing resists yet (one condyle
/// in contact: the moment about it) until a new contact region takes load.
#[derive(Debug, Clone)]
struct LineSearch {
    base: Vec<Real>,
    direction: Vec<Real>,
    alpha: Real,
    phi0: Real,
    error0: Real,
    /// The largest `α` with `φ < 0` so far, and `φ` there.
    lo: (Real, Real),
    /// The smallest `α` with `φ ≥ 0`, and `φ` there.
    hi: Option<(Real, Real)>,
    /// The largest `α` (10 % of the model size in the scaled step).
    reach: Real,
    trials: usize,
}

impl LineSearch {
    /// The search from `z` (residual `r`, scaled error `error`) along the modified Newton
    /// direction of the Jacobian `j = ∂r/∂z`: with `H = −(j + jᵀ)/2` in scaled variables
    /// (angles × model size), `d = Σ_i v_i (v_iᵀ r) / max(λ_i, 10⁻² λ_max)` over its
    /// eigenpairs — Newton's step where `H` is well conditioned, a step toward the net
    /// generalised force along directions it hardly resists. `α` starts at 1, limited to the
    /// step caps (2 % of the model size, 0.02 rad). `None` if `H` has no positive eigenvalue.
    fn start<const D: usize>(
        j: &nalgebra::DMatrix<Real>,
        z: &[Real],
        r: &[Real],
        error: Real,
        unknowns: &[(usize, usize)],
        length: Real,
    ) -> Option<Self> {
        let m = z.len();
        let w: Vec<Real> = unknowns.iter().map(|&(_, k)| if k < D { 1.0 } else { length }).collect();
        let h = nalgebra::DMatrix::from_fn(m, m, |a, b| -0.5 * (j[(a, b)] + j[(b, a)]) / (w[a] * w[b]));
        let eig = h.symmetric_eigen();
        let lmax = eig.eigenvalues.iter().copied().fold(0.0, Real::max);
        if !(lmax > 0.0 && lmax.is_finite()) {
            return None;
        }
        let rs: Vec<Real> = r.iter().zip(&w).map(|(ri, wi)| ri / wi).collect();
        let mut scaled = vec![0.0; m];
        for (i, &l) in eig.eigenvalues.iter().enumerate() {
            let v = eig.eigenvectors.column(i);
            let c = v.iter().zip(&rs).map(|(a, b)| a * b).sum::<Real>() / l.max(1e-2 * lmax);
            for (s, vk) in scaled.iter_mut().zip(v.iter()) {
                *s += c * vk;
            }
        }
        let direction: Vec<Real> = scaled.iter().zip(&w).map(|(s, wi)| s / wi).collect();
        let phi0 = -dot(r, &direction);
        let longest = scaled.iter().map(|s| s.abs()).fold(0.0, Real::max);
        if !(phi0 < 0.0 && longest > 0.0 && longest.is_finite()) {
            return None;
        }
        let alpha = direction
            .iter()
            .zip(unknowns)
            .map(|(d, &(_, k))| step_cap::<D>(k, length) / d.abs())
            .fold(1.0, Real::min);
        Some(Self {
            base: z.to_vec(),
            direction,
            alpha,
            phi0,
            error0: error,
            lo: (0.0, phi0),
            hi: None,
            reach: 0.1 * length / longest,
            trials: 0,
        })
    }

    fn at(&self, alpha: Real) -> Vec<Real> {
        self.base.iter().zip(&self.direction).map(|(b, d)| b + alpha * d).collect()
    }

    /// The next `α` after a trial at `self.alpha` gave `φ` (and the scaled error `error`), or
    /// `None` when the step is accepted there.
    fn next_alpha(&mut self, phi: Real, error: Real) -> Option<Real> {
        self.trials += 1;
        let alpha = self.alpha;
        if phi.abs() <= 0.1 * self.phi0.abs()
            || (phi <= 0.0 && error <= 0.25 * self.error0)
            || self.trials >= 12
        {
            return None;
        }
        if phi < 0.0 {
            self.lo = (alpha, phi);
        } else {
            self.hi = Some((alpha, phi));
        }
        let next = match self.hi {
            Some((ah, ph)) => {
                let (al, pl) = self.lo;
                let secant = al - pl * (ah - al) / (ph - pl);
                let margin = 0.05 * (ah - al);
                if secant.is_finite() {
                    secant.clamp(al + margin, ah - margin)
                } else {
                    0.5 * (al + ah)
                }
            }
            None if alpha < self.reach => (2.0 * alpha).min(self.reach),
            // nothing along the direction resists within reach: take the step
            None => return None,
        };
        self.alpha = next;
        Some(next)
    }
}

/// The rigid bodies of a dynamic run (every coordinate prescribed) as the moving contact
/// partners of the nonlinear dynamic scheme ([`MovingPartners`]): posed at each sub-step's
/// time, their motion since the last committed sub-step from [`partner_motion`].
pub(crate) struct PrescribedPartners<'a, const D: usize> {
    pub(crate) joint: &'a JointModel<D>,
    pub(crate) driver: &'a mut RigidDriver,
}

impl<const D: usize> MovingPartners<D> for PrescribedPartners<'_, D> {
    fn pose(&mut self, t: Real) -> Result<(), synovia_time::TimeError> {
        self.driver
            .pose_prescribed(self.joint, t)
            .map(|_| ())
            .map_err(|e| synovia_time::TimeError::InvalidParameter(e.to_string()))
    }
    fn motion(&self, geometry: &ContactGeometry<D>, previous: &[Vec<Vector<D>>]) -> Vec<Vector<D>> {
        self.driver.motion_since_accepted(self.joint, geometry, previous)
    }
    fn commit(&mut self) {
        self.driver.accept();
    }
}

#[cfg(test)]
mod pose_input_tests {
    use super::*;

    const ORDERS: [[usize; 3]; 6] = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [0, 2, 1], [2, 1, 0], [1, 0, 2]];

    fn rotation(order: [usize; 3], q: [Real; 3]) -> Tensor<3> {
        order.iter().fold(Tensor::<3>::identity(), |r, &a| r * axis_rotation(a, q[a]))
    }

    #[test]
    fn euler_angles_invert_every_rotation_order() {
        for order in ORDERS {
            for (mut q, middle) in [
                ([0.3, -0.7, 1.1], -0.7),
                ([-2.9, 1.2, 3.0], 1.2),
                ([0.0; 3], 0.0),
                ([1.0, -1.5, -0.2], -1.5),
            ] {
                // the middle angle of the order lies in [−π/2, π/2], the others in (−π, π]
                q[order[1]] = middle;
                let got = euler_angles(&rotation(order, q), order);
                // the same rotation in any case
                let again = rotation(order, got);
                assert!((again - rotation(order, q)).abs().max() < 1e-12);
                for a in 0..3 {
                    assert!((got[a] - q[a]).abs() < 1e-12, "order {order:?}: {got:?} vs {q:?}");
                }
            }
            // gimbal lock (middle angle ±π/2): other angles, the same rotation
            let mut q = [0.4, 0.4, 0.4];
            q[order[1]] = std::f64::consts::FRAC_PI_2;
            let r = rotation(order, q);
            let again = rotation(order, euler_angles(&r, order));
            assert!((again - r).abs().max() < 1e-12, "order {order:?}");
        }
    }

    #[test]
    fn quaternion_axis_angle_and_matrix_give_the_same_pose() -> Result<(), JointError> {
        let (axis, angle) = ([1.0, -2.0, 0.5], 0.7_f64);
        let n = Vector::<3>::from(axis).normalize();
        let (s, c) = (0.5 * angle).sin_cos();
        let by_quaternion = PoseInput::<3>::new();
        // a quaternion off unit length is normalised
        by_quaternion
            .set_quaternion([1.0, 2.0, 3.0], [2.0 * c, 2.0 * s * n[0], 2.0 * s * n[1], 2.0 * s * n[2]])?;
        let by_axis = PoseInput::<3>::new();
        by_axis.set_axis_angle([1.0, 2.0, 3.0], axis, angle)?;
        let r = by_axis.get().1;
        let by_matrix = PoseInput::<3>::new();
        by_matrix.set_rotation_matrix(
            [1.0, 2.0, 3.0],
            std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)])),
        )?;
        for other in [&by_quaternion, &by_matrix] {
            assert!((other.get().1 - r).abs().max() < 1e-15);
            assert_eq!(other.translation(), [1.0, 2.0, 3.0]);
        }
        // Rodrigues: the axis is fixed, and a perpendicular vector turns by the angle
        assert!((r * n - n).norm() < 1e-15);
        let p = n.cross(&Vector::<3>::new(0.0, 0.0, 1.0)).normalize();
        assert!(((r * p).dot(&p) - angle.cos()).abs() < 1e-15);
        Ok(())
    }

    #[test]
    fn bad_poses_are_refused_and_leave_the_pose() -> Result<(), JointError> {
        let input = PoseInput::<3>::new();
        input.set_axis_angle([0.5, 0.0, 0.0], [0.0, 0.0, 1.0], 0.25)?;
        let before = input.get();
        assert!(input.set_quaternion([0.0; 3], [0.0; 4]).is_err());
        assert!(input.set_quaternion([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]).is_err());
        assert!(input.set_axis_angle([0.0; 3], [0.0; 3], 1.0).is_err());
        assert!(input.set_axis_angle([0.0; 3], [1.0, 0.0, 0.0], f64::INFINITY).is_err());
        let shear = [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(input.set_rotation_matrix([0.0; 3], shear).is_err());
        let mirror = [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(input.set_rotation_matrix([0.0; 3], mirror).is_err());
        assert_eq!(input.get(), before);
        assert!(PoseInput::<2>::new().set([0.0, f64::NAN], 0.0).is_err());
        Ok(())
    }

    #[test]
    fn a_posed_body_follows_its_input_in_its_rotation_order() -> Result<(), JointError> {
        let input = PoseInput::<3>::new();
        // the order set after prescribe_pose still applies; the force-controlled dof leaves it
        let body = RigidBody::<3>::new("b", Point::<3>::zeros())?
            .prescribe_pose(&input)
            .force(1, synovia_time::history::Constant(-1.0))?
            .with_rotation_order("xyz")?;
        let q = [0.2, -0.4, 0.9];
        input.set_rotation_matrix([0.1, 0.2, 0.3], {
            let r = rotation([0, 1, 2], q);
            std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)]))
        })?;
        let values: Vec<Option<Real>> = body
            .controls()
            .iter()
            .map(|c| match c {
                DofControl::Prescribed(h) => Some(h.value(0.0)),
                DofControl::Force { .. } => None,
            })
            .collect();
        assert_eq!(values[1], None);
        for (got, want) in
            [(values[0], 0.1), (values[2], 0.3), (values[3], q[0]), (values[4], q[1]), (values[5], q[2])]
        {
            assert!((got.unwrap_or(Real::NAN) - want).abs() < 1e-12, "{values:?}");
        }
        // 2D: translation and the angle
        let planar = PoseInput::<2>::new();
        let body = RigidBody::<2>::new("p", Point::<2>::zeros())?.prescribe_pose(&planar);
        planar.set([0.5, -0.25], 1.25)?;
        let values: Vec<Real> = body
            .controls()
            .iter()
            .filter_map(|c| if let DofControl::Prescribed(h) = c { Some(h.value(3.0)) } else { None })
            .collect();
        assert!(
            (values[0] - 0.5).abs() < 1e-15
                && (values[1] + 0.25).abs() < 1e-15
                && (values[2] - 1.25).abs() < 1e-12
        );
        Ok(())
    }
}
