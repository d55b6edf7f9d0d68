//! Building and running a joint model in one place: bodies with materials, boundary conditions
//! by part name with load histories, contact pairs with friction, the contact solver by name,
//! and a static, quasi-static or dynamic analysis.
//!
//! [`JointModel`] wraps a [`Model`] and the pieces that the lower crates take separately
//! (contact pairs, friction laws, dynamic body data, solver and analysis parameters) and runs
//! them through [`StaticContact`] / [`QuasiStaticStepper`] / [`DynamicStepper`].
//!
//! # Part kinds
//!
//! Generators and the Gmsh reader create boundary parts of kind
//! [`BoundaryKind::TractionFree`] (Gmsh parts may carry a kind from their name). Each builder
//! method that puts data on a part gives it the matching kind: [`JointModel::clamp`] →
//! `Clamped`, [`JointModel::symmetry`] → `Symmetry`, [`JointModel::prescribe`] and
//! [`JointModel::rigid_motion`] → `Prescribed`, [`JointModel::traction`] and
//! [`JointModel::pressure`] → `Traction`, contact pairs → `Contact`. A part that already has
//! another kind than `TractionFree` keeps it and the call fails with
//! [`JointError::PartKind`], so one part never gets two contradicting conditions.
//!
//! # Running
//!
//! * [`JointModel::run_static`]: one contact problem at time `t` (step 0 of the quasi-static
//!   scheme: frictionless, or with [`QuasiStaticParams::initial_friction`] a Tresca solve with
//!   `g_c` from the frictionless pressure; a body held by friction alone, whose frictionless
//!   problem has no solution, is solved with Coulomb friction, docs/model.md §7.1);
//! * [`JointModel::run_quasistatic`]: the quasi-static scheme of docs/model.md §7 over the given times;
//! * [`JointModel::run_dynamic`]: the semi-implicit Kelvin–Voigt scheme with `dt` and `steps`
//!   (every body needs a density: a [`KelvinVoigt`] material, [`JointModel::set_density`] or
//!   [`JointModel::set_dynamic`]; a model with a nonlinear material or finite strain runs the
//!   scheme of docs/model.md (12.2), each step solved by Newton's method);
//! * [`JointModel::run`] runs the [`Analysis`] set with [`JointModel::set_analysis`];
//! * [`JointModel::run_on`] runs it with the solver [`TFETI`] on the ranks of a
//!   [`Communicator`](synovia_feti::Communicator) (one process or MPI ranks): the model is
//!   decomposed into subdomains and never factorised whole (static and quasi-static analyses;
//!   `builder/tfeti.rs`, docs/scale-out.md);
//! * [`JointModel::prepare`] factorises once and returns a [`JointSession`] that re-solves
//!   the static problem or advances the quasi-static scheme level by level with new loads,
//!   warm-started, without refactorising (navigation; see [`crate::session`]).
//!
//! Every run returns a [`RunResult`] (one [`StepRecord`] per step, the final displacements, the
//! last contact solution). The `*_with` variants call an observer after every step with a
//! [`StepView`] (the record and the full contact solution), e.g. to write ParaView output with
//! [`QuasiStaticOutput`](synovia_time::quasistatic::QuasiStaticOutput) or to show progress.
//! A model without contact pairs is solved as a plain elastic problem at every time level.

use std::fmt;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use synovia_contact::operators::{ContactGeometry, ContactPair, SignedDistance};
use synovia_contact::{
    ContactError, ContactParams, ContactSolution, ContactSolver, FrictionLaw, KktReport, StaticContact,
    StaticContactResult,
};
use synovia_fem::{BodyId, ComponentMask, ElasticParams, ElasticSolver, FemError, Kinematics, Model};
use synovia_io::IoError;
use synovia_material::{KelvinVoigt, LinearElastic, Material, MaterialError};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::{BoundaryKind, Mesh, MeshError};
use synovia_nonlinear::{NewtonParams, NonlinearContact, NonlinearResult};
use synovia_time::dynamic::{DynamicBody, DynamicParams, DynamicStepper};
use synovia_time::history::{pressure, scaled, scaled_traction, LoadHistory, RigidMotion};
use synovia_time::nonlinear_dynamic::NonlinearDynamicStepper;
use synovia_time::quasistatic::{QuasiStaticParams, QuasiStaticStepper};
use synovia_time::results::StepRecord;
use synovia_time::TimeError;

use crate::rigid::{ForceControlParams, LevelMode, RigidBody, RigidDriver};
use crate::session::JointSession;

mod setup;
mod tfeti;
pub use setup::{InitialPenetration, SetupInfo, PENETRATION_TOLERANCE};
pub use tfeti::{TfetiSettings, TFETI};

/// Everything that can go wrong while building or running a [`JointModel`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum JointError {
    /// A finite-element error (bodies, parts, boundary data, assembly).
    #[error(transparent)]
    Fem(#[from] FemError),
    /// A mesh error (generators, parts).
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A material error.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// A contact error (pairs, solver).
    #[error(transparent)]
    Contact(#[from] ContactError),
    /// A time-stepping error (with the step where it happened).
    #[error(transparent)]
    Time(#[from] TimeError),
    /// An input/output error (Gmsh files, VTU output).
    #[error(transparent)]
    Io(#[from] IoError),
    /// Nonlinear solve errors (Newton without convergence after the cut-backs, ...).
    #[error(transparent)]
    Nonlinear(#[from] synovia_nonlinear::NonlinearError),
    /// A TFETI set-up or solve error (solver `"tfeti"`: decomposition, SMALBE without
    /// convergence, communication).
    #[error(transparent)]
    Feti(#[from] synovia_feti::FetiError),
    /// The chosen solver does not treat a feature of the model or analysis (e.g. `"tfeti"`
    /// with a dynamic analysis or rigid bodies with mixed control).
    #[error("the `{solver}` solver does not support {feature}")]
    Unsupported {
        /// The solver's name.
        solver: String,
        /// What it does not support, and what to do instead.
        feature: String,
    },
    /// A part already has a kind that contradicts the requested condition.
    #[error("body `{body}`, part `{part}` is already of kind {current:?}; it cannot also be {requested:?}")]
    PartKind {
        /// Body name.
        body: String,
        /// Part name.
        part: String,
        /// Its kind.
        current: BoundaryKind,
        /// The kind the call needs.
        requested: BoundaryKind,
    },
    /// Invalid input to the builder (names, sizes, missing data).
    #[error("{0}")]
    Invalid(String),
    /// Contact nodes start inside their partner and the model refuses it
    /// ([`JointModel::refuse_initial_penetration`]).
    #[error("{0}")]
    InitialPenetration(Box<InitialPenetration>),
    /// An error returned by a step observer.
    #[error("{0}")]
    Observer(Box<dyn std::error::Error + Send + Sync>),
}

/// The material of a body: elastic (`C⁽⁰⁾` only), or Kelvin–Voigt, which also carries the
/// density, damping and viscosity used by [`JointModel::run_dynamic`].
#[derive(Debug, Clone)]
pub enum BodyMaterial<const D: usize> {
    /// Any elastic material.
    Elastic(Arc<dyn Material<D>>),
    /// A Kelvin–Voigt material (`C⁽⁰⁾`, `C⁽¹⁾`, `ρ`, `α`).
    KelvinVoigt(KelvinVoigt<D>),
}

impl<const D: usize> From<LinearElastic<D>> for BodyMaterial<D> {
    fn from(m: LinearElastic<D>) -> Self {
        Self::Elastic(Arc::new(m))
    }
}

impl<const D: usize> From<KelvinVoigt<D>> for BodyMaterial<D> {
    fn from(m: KelvinVoigt<D>) -> Self {
        Self::KelvinVoigt(m)
    }
}

impl<const D: usize> From<Arc<dyn Material<D>>> for BodyMaterial<D> {
    fn from(m: Arc<dyn Material<D>>) -> Self {
        Self::Elastic(m)
    }
}

/// A reference to a body of a model: its [`BodyId`] or its name.
pub trait BodyRef {
    /// The id of the body in `model`.
    ///
    /// # Errors
    /// [`FemError::UnknownBody`] if there is no such body.
    fn resolve<const D: usize>(&self, model: &Model<D>) -> Result<BodyId, FemError>;
}

impl BodyRef for BodyId {
    fn resolve<const D: usize>(&self, model: &Model<D>) -> Result<BodyId, FemError> {
        model.body(*self).map(|_| *self)
    }
}

impl BodyRef for &str {
    fn resolve<const D: usize>(&self, model: &Model<D>) -> Result<BodyId, FemError> {
        model.body_id(self)
    }
}

impl BodyRef for String {
    fn resolve<const D: usize>(&self, model: &Model<D>) -> Result<BodyId, FemError> {
        model.body_id(self)
    }
}

impl BodyRef for &String {
    fn resolve<const D: usize>(&self, model: &Model<D>) -> Result<BodyId, FemError> {
        model.body_id(self)
    }
}

/// The analysis a [`JointModel`] runs with [`JointModel::run`].
#[derive(Debug, Clone, PartialEq)]
pub enum Analysis {
    /// One static contact problem at `time`.
    Static {
        /// The time at which loads and prescribed displacements are evaluated.
        time: Real,
    },
    /// The quasi-static scheme over `times` (finite, strictly increasing).
    QuasiStatic {
        /// The time levels.
        times: Vec<Real>,
    },
    /// The dynamic scheme: `steps` steps of `dt` from [`DynamicParams::t0`].
    Dynamic {
        /// The time step.
        dt: Real,
        /// Number of steps.
        steps: usize,
    },
}

impl Analysis {
    /// Number of step records the analysis produces (the dynamic one includes the initial
    /// state as step 0).
    pub fn n_records(&self) -> usize {
        match self {
            Self::Static { .. } => 1,
            Self::QuasiStatic { times } => times.len(),
            Self::Dynamic { steps, .. } => steps + 1,
        }
    }
    /// `"static"`, `"quasistatic"` or `"dynamic"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Static { .. } => "static",
            Self::QuasiStatic { .. } => "quasistatic",
            Self::Dynamic { .. } => "dynamic",
        }
    }
}

/// What an observer of a run sees after each step.
pub struct StepView<'a, const D: usize> {
    /// The model.
    pub model: &'a Model<D>,
    /// The contact nodes (empty without contact pairs).
    pub geometry: &'a ContactGeometry<D>,
    /// The step's figures.
    pub record: &'a StepRecord,
    /// The step's solution: nodal displacements, physical contact multipliers (empty without
    /// contact pairs), KKT residuals.
    pub result: &'a StaticContactResult<D>,
    /// Number of records the run produces in total.
    pub n_steps: usize,
}

/// The result of a run.
#[derive(Debug, Clone)]
pub struct RunResult<const D: usize> {
    /// One record per step (for a dynamic run, step 0 is the initial state).
    pub records: Vec<StepRecord>,
    /// Nodal displacements per body at the last step.
    pub displacement: Vec<Vec<Vector<D>>>,
    /// The contact solution of the last step (`None` without contact pairs).
    pub contact: Option<StaticContactResult<D>>,
    /// Reduced unknowns of the system.
    pub n_dofs: usize,
    /// Contact nodes of all pairs.
    pub contact_nodes: usize,
    /// The contact solver's name.
    pub solver: String,
    /// Set-up time (dofs, assembly, factorisation, contact geometry), s.
    pub setup_s: f64,
    /// Wall time of the whole run, s.
    pub total_s: f64,
}

/// A joint model: a [`Model`] (bodies, materials, boundary data) plus contact pairs with
/// friction, load histories, dynamic body data, the contact solver and the analysis (see the
/// [module documentation](self)).
pub struct JointModel<const D: usize> {
    model: Model<D>,
    pairs: Vec<ContactPair<D>>,
    friction_laws: Vec<(String, Arc<dyn FrictionLaw>)>,
    dynamic: Vec<Option<DynamicBody>>,
    initial_velocity: Vec<Option<Vector<D>>>,
    solver: String,
    contact_params: ContactParams,
    elastic_params: ElasticParams,
    quasistatic_params: QuasiStaticParams,
    dynamic_params: DynamicParams,
    nested: Option<usize>,
    analysis: Option<Analysis>,
    refuse_penetration: bool,
    refuse_penetration_pairs: Vec<String>,
    rigid_bodies: Vec<RigidBody<D>>,
    rigid_pairs: Vec<(String, usize)>,
    rigid_ties: Vec<(BodyId, String, usize)>,
    force_control: ForceControlParams,
    interface_block: synovia_linalg::InterfaceBlockParams,
    screening_band: Option<Real>,
    kinematics: Vec<Kinematics>,
    newton: NewtonParams,
    tfeti: TfetiSettings,
}

impl<const D: usize> fmt::Debug for JointModel<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("JointModel")
            .field("model", &self.model)
            .field("pairs", &self.pairs)
            .field("solver", &self.solver)
            .field("analysis", &self.analysis)
            .finish_non_exhaustive()
    }
}

impl<const D: usize> Default for JointModel<D> {
    fn default() -> Self {
        Self::new()
    }
}

/// A contact result without contact forces (`n_contact` zero pressures).
pub(crate) fn zero_result<const D: usize>(
    displacement: Vec<Vec<Vector<D>>>,
    n_contact: usize,
) -> StaticContactResult<D> {
    StaticContactResult {
        displacement,
        solution: ContactSolution {
            u: Vec::new(),
            lambda_n: vec![0.0; n_contact],
            lambda_t: Vec::new(),
            report: Default::default(),
        },
        cell_node: Vec::new(),
        slip_bound: Vec::new(),
        kkt: KktReport::default(),
        coarse_iterations: 0,
        proximal_iterations: 0,
    }
}

fn empty_geometry<const D: usize>() -> ContactGeometry<D> {
    ContactGeometry::default()
}

/// Message of an observer failure carried through the stepper's error type.
const OBSERVER_FAILED: &str = "the step observer failed";

impl<const D: usize> JointModel<D> {
    /// An empty model: no bodies, solver [`crate::solvers::DEFAULT_SOLVER`] (`"pdas-fallback"`),
    /// default parameters, no analysis.
    pub fn new() -> Self {
        Self {
            model: Model::new(),
            pairs: Vec::new(),
            friction_laws: Vec::new(),
            dynamic: Vec::new(),
            initial_velocity: Vec::new(),
            solver: crate::solvers::DEFAULT_SOLVER.to_string(),
            contact_params: ContactParams::default(),
            elastic_params: ElasticParams::default(),
            quasistatic_params: QuasiStaticParams::default(),
            dynamic_params: DynamicParams::new(1.0),
            nested: Some(32),
            analysis: None,
            refuse_penetration: false,
            refuse_penetration_pairs: Vec::new(),
            rigid_bodies: Vec::new(),
            rigid_pairs: Vec::new(),
            rigid_ties: Vec::new(),
            force_control: ForceControlParams::default(),
            interface_block: synovia_linalg::InterfaceBlockParams::default(),
            screening_band: None,
            kinematics: Vec::new(),
            newton: NewtonParams::default(),
            tfeti: TfetiSettings::default(),
        }
    }

    // ----- rigid bodies -----

    /// Adds a rigid body with mixed control ([`crate::rigid`]); returns its index.
    ///
    /// # Errors
    /// [`JointError::Invalid`] for a duplicate name.
    pub fn add_rigid_body(&mut self, body: RigidBody<D>) -> Result<usize, JointError> {
        if self.rigid_bodies.iter().any(|b| b.name == body.name) {
            return Err(JointError::Invalid(format!("two rigid bodies are called `{}`", body.name)));
        }
        self.rigid_bodies.push(body);
        Ok(self.rigid_bodies.len() - 1)
    }

    fn rigid_index(&self, rigid: &str) -> Result<usize, JointError> {
        self.rigid_bodies.iter().position(|b| b.name == rigid).ok_or_else(|| {
            let names: Vec<&str> = self.rigid_bodies.iter().map(|b| b.name.as_str()).collect();
            JointError::Invalid(format!("unknown rigid body `{rigid}` (rigid bodies: {})", names.join(", ")))
        })
    }

    /// Adds a contact pair between `part` of `body` and the shape of rigid body `rigid`
    /// (`shape`: a signed distance in the rigid body's own frame, e.g. a
    /// [`SurfaceObstacle`](synovia_contact::SurfaceObstacle)), placed by the rigid body's
    /// pose at every level ([`crate::rigid::PosedObstacle`]); Coulomb coefficient `friction`.
    /// The contact forces of the pair load the rigid body.
    ///
    /// # Errors
    /// Unknown rigid body; see [`JointModel::add_contact`].
    pub fn contact_rigid_body(
        &mut self,
        name: &str,
        body: impl BodyRef,
        part: &str,
        rigid: &str,
        shape: Arc<dyn SignedDistance<D>>,
        friction: Real,
    ) -> Result<&mut Self, JointError> {
        let r = self.rigid_index(rigid)?;
        let id = body.resolve(&self.model)?;
        let posed = crate::rigid::PosedObstacle::new(shape, self.rigid_bodies[r].pose.clone());
        self.add_contact(ContactPair::rigid(name, id, part, Arc::new(posed)).with_friction(friction))?;
        self.rigid_pairs.push((name.to_string(), r));
        Ok(self)
    }

    /// Ties `part` of `body` to rigid body `rigid` (a rigid plate): the part moves with the
    /// rigid body's pose, `u(X) = c + t + R (X − c) − X` (all components), and its reactions
    /// load the rigid body.
    ///
    /// # Errors
    /// Unknown rigid body, body or part; [`JointError::PartKind`].
    pub fn tie_to_rigid_body(
        &mut self,
        body: impl BodyRef,
        part: &str,
        rigid: &str,
    ) -> Result<&mut Self, JointError> {
        let r = self.rigid_index(rigid)?;
        let id = body.resolve(&self.model)?;
        let pose = self.rigid_bodies[r].pose.clone();
        self.prescribe_field(id, part, ComponentMask::ALL, move |x, _t| pose.get().position(x) - x)?;
        self.rigid_ties.push((id, part.to_string(), r));
        Ok(self)
    }

    /// Sets the search distance of contact pair `pair`
    /// ([`ContactPair::with_search_distance`]: node-to-segment, mortar and rigid pairs).
    ///
    /// # Errors
    /// [`JointError::Invalid`] for an unknown pair or a distance that is not positive.
    pub fn search_distance(&mut self, pair: &str, distance: Real) -> Result<&mut Self, JointError> {
        if !(distance.is_finite() && distance > 0.0) {
            return Err(JointError::Invalid(format!("search distance {distance} must be finite and > 0")));
        }
        let p = self
            .pairs
            .iter_mut()
            .find(|p| p.name == pair)
            .ok_or_else(|| JointError::Invalid(format!("no contact pair `{pair}`")))?;
        *p = p.clone().with_search_distance(distance);
        Ok(self)
    }

    /// Sets how many interface dofs are ordered last in the factorisation (the dense block of
    /// the interface Schur complement, [`synovia_linalg::InterfaceBlockParams`]; e.g.
    /// `with_max_dofs(0)` for a large candidate surface whose contact patches move, where
    /// whole-factor solves of the few active rows are cheaper than a large dense block).
    pub fn interface_block(&mut self, params: synovia_linalg::InterfaceBlockParams) -> &mut Self {
        self.interface_block = params;
        self
    }

    /// Screens the contact rows of whole-factor solves by their gap: each solve runs on the
    /// rows with gap at most `band` (model length unit) and adds the others only if they come
    /// into contact ([`StaticContact::set_screening_band`]; exact, the result is the full
    /// problem's). For a large candidate surface without a dense interface block, where the
    /// cost of the interface follows its rows. `None` (default): no screening.
    ///
    /// # Errors
    /// [`JointError::Contact`] for a band that is negative or not finite
    /// ([`synovia_contact::static_contact::check_screening_band`]).
    pub fn screening_band(&mut self, band: Option<Real>) -> Result<&mut Self, JointError> {
        synovia_contact::static_contact::check_screening_band(band)?;
        self.screening_band = band;
        Ok(self)
    }

    /// The screening band ([`JointModel::screening_band`]).
    pub fn screening_band_value(&self) -> Option<Real> {
        self.screening_band
    }

    /// The interface block parameters ([`JointModel::interface_block`]).
    pub fn interface_block_params(&self) -> synovia_linalg::InterfaceBlockParams {
        self.interface_block
    }

    /// Sets the parameters of the force-control iteration ([`ForceControlParams`]).
    pub fn force_control(&mut self, params: ForceControlParams) -> &mut Self {
        self.force_control = params;
        self
    }

    /// The parameters of the force-control iteration.
    pub fn force_control_params(&self) -> ForceControlParams {
        self.force_control
    }

    /// The rigid bodies.
    pub fn rigid_bodies(&self) -> &[RigidBody<D>] {
        &self.rigid_bodies
    }

    /// The parts tied to rigid bodies: `(body, part, rigid body index)`.
    pub fn rigid_ties(&self) -> &[(BodyId, String, usize)] {
        &self.rigid_ties
    }

    /// The contact pairs with a rigid body's shape: `(pair name, rigid body index)`.
    pub fn rigid_pair_bodies(&self) -> &[(String, usize)] {
        &self.rigid_pairs
    }

    /// For each pair of `geometry` (in its order), the rigid body whose shape it touches.
    pub(crate) fn pair_rigid_owner(&self, geometry: &ContactGeometry<D>) -> Vec<Option<usize>> {
        geometry
            .pairs
            .iter()
            .map(|(name, _)| self.rigid_pairs.iter().find(|(p, _)| p == name).map(|(_, r)| *r))
            .collect()
    }

    /// The diagonal of the bounding box of all bodies' nodes (the model's size, for relative
    /// tolerances); 1 for an empty model.
    pub fn model_size(&self) -> Real {
        let mut lo = [Real::INFINITY; 3];
        let mut hi = [Real::NEG_INFINITY; 3];
        for b in self.model.bodies() {
            for x in b.mesh.nodes() {
                for i in 0..D {
                    lo[i] = lo[i].min(x[i]);
                    hi[i] = hi[i].max(x[i]);
                }
            }
        }
        let d = (0..D).map(|i| (hi[i] - lo[i]).powi(2)).sum::<Real>().sqrt();
        if d.is_finite() && d > 0.0 {
            d
        } else {
            1.0
        }
    }

    // ----- bodies -----

    /// Adds a body `name` with its mesh and material (a [`LinearElastic`], a [`KelvinVoigt`],
    /// or any `Arc<dyn Material<D>>`); a Kelvin–Voigt material also sets the body's dynamic
    /// data.
    ///
    /// # Errors
    /// [`FemError::DuplicateBody`]; [`JointError::Time`] for a Kelvin–Voigt material with a
    /// nonlinear viscosity.
    pub fn add_body(
        &mut self,
        name: &str,
        mesh: Mesh<D>,
        material: impl Into<BodyMaterial<D>>,
    ) -> Result<BodyId, JointError> {
        let (material, dynamic): (Arc<dyn Material<D>>, _) = match material.into() {
            BodyMaterial::Elastic(m) => (m, None),
            BodyMaterial::KelvinVoigt(kv) => {
                let d = DynamicBody::from_kelvin_voigt(&kv)?;
                (Arc::new(kv), Some(d))
            }
        };
        let id = self.model.add_body(name, mesh, material)?;
        self.dynamic.push(dynamic);
        self.initial_velocity.push(None);
        self.kinematics.push(Kinematics::SmallStrain);
        Ok(id)
    }

    /// Adds the bodies of a Gmsh file ([`synovia_io::gmsh`]: physical groups of dimension `D`
    /// are bodies, those of dimension `D − 1` boundary parts) whose name `material_of` gives a
    /// material for; bodies for which it returns `None` are left out. Returns the ids of the
    /// bodies added, in file order.
    ///
    /// # Errors
    /// [`JointError::Io`] for unreadable or malformed files; [`JointError::Invalid`] if no body
    /// was added; the errors of [`JointModel::add_body`].
    pub fn add_gmsh_bodies(
        &mut self,
        path: impl AsRef<Path>,
        mut material_of: impl FnMut(&str) -> Option<BodyMaterial<D>>,
    ) -> Result<Vec<BodyId>, JointError> {
        let path = path.as_ref();
        let bodies = synovia_io::gmsh::read_msh(path)?.bodies::<D>()?;
        let names: Vec<String> = bodies.iter().map(|(n, _)| n.clone()).collect();
        let mut ids = Vec::new();
        for (name, mesh) in bodies {
            if let Some(material) = material_of(&name) {
                ids.push(self.add_body(&name, mesh, material)?);
            }
        }
        if ids.is_empty() {
            return Err(JointError::Invalid(format!(
                "`{}`: no material given for any of its bodies {names:?}",
                path.display()
            )));
        }
        Ok(ids)
    }

    /// Sets the density `ρ` of a body for dynamics (no damping, no viscosity).
    ///
    /// # Errors
    /// Unknown body; [`JointError::Invalid`] unless `ρ` is finite and positive.
    pub fn set_density(&mut self, body: impl BodyRef, density: Real) -> Result<&mut Self, JointError> {
        if !(density.is_finite() && density > 0.0) {
            return Err(JointError::Invalid(format!("density must be finite and > 0, got {density}")));
        }
        let id = body.resolve(&self.model)?;
        self.dynamic[id.0] = Some(DynamicBody::elastic(density));
        Ok(self)
    }

    /// Sets the dynamic data (density, damping, viscosity) of a body.
    ///
    /// # Errors
    /// Unknown body.
    pub fn set_dynamic(&mut self, body: impl BodyRef, data: DynamicBody) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        self.dynamic[id.0] = Some(data);
        Ok(self)
    }

    /// Sets a uniform initial velocity of a body (dynamic runs; default rest).
    ///
    /// # Errors
    /// Unknown body; [`JointError::Invalid`] for a non-finite velocity.
    pub fn initial_velocity(
        &mut self,
        body: impl BodyRef,
        velocity: Vector<D>,
    ) -> Result<&mut Self, JointError> {
        if velocity.iter().any(|v| !v.is_finite()) {
            return Err(JointError::Invalid(format!(
                "initial velocity {} is not finite",
                synovia_fem::error::fmt_point(velocity.as_slice())
            )));
        }
        let id = body.resolve(&self.model)?;
        self.initial_velocity[id.0] = Some(velocity);
        Ok(self)
    }

    /// Adds a boundary part `name` to a body: the boundary facets whose centroid `x` and outward
    /// unit normal `n` satisfy `select(x, n)` (kind `TractionFree` until a condition uses it).
    ///
    /// # Errors
    /// Unknown body; [`MeshError::DuplicatePart`] or [`MeshError::EmptyPart`].
    pub fn define_part(
        &mut self,
        body: impl BodyRef,
        name: &str,
        select: impl Fn(&Point<D>, &Vector<D>) -> bool,
    ) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        let b = self.model.body_mut(id)?;
        let body_name = b.name.clone();
        b.mesh
            .add_boundary_part(name, BoundaryKind::TractionFree, select)
            .map_err(|source| FemError::Mesh { body: body_name, source })?;
        Ok(self)
    }

    /// Gives `part` of `body` the kind `kind` (see the module docs: allowed from
    /// `TractionFree` or when it already has that kind).
    fn assign_kind(&mut self, body: BodyId, part: &str, kind: BoundaryKind) -> Result<(), JointError> {
        let b = self.model.body_mut(body)?;
        let name = b.name.clone();
        let current = b
            .mesh
            .boundary_part(part)
            .map_err(|source| FemError::Mesh { body: name.clone(), source })?
            .kind();
        if current == kind {
            return Ok(());
        }
        if current != BoundaryKind::TractionFree {
            return Err(JointError::PartKind {
                body: name,
                part: part.to_string(),
                current,
                requested: kind,
            });
        }
        b.mesh.set_part_kind(part, kind).map_err(|source| FemError::Mesh { body: name, source })?;
        Ok(())
    }

    // ----- boundary conditions -----

    /// Clamps a part (`u = 0`).
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn clamp(&mut self, body: impl BodyRef, part: &str) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        self.assign_kind(id, part, BoundaryKind::Clamped)?;
        Ok(self)
    }

    /// Makes a part a symmetry plane / bilateral sliding support (`u · n = 0`).
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn symmetry(&mut self, body: impl BodyRef, part: &str) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        self.assign_kind(id, part, BoundaryKind::Symmetry)?;
        Ok(self)
    }

    /// Prescribes the displacement `u₂(x, t) = h(t) value` on a part (all components).
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn prescribe(
        &mut self,
        body: impl BodyRef,
        part: &str,
        value: Vector<D>,
        history: impl LoadHistory + 'static,
    ) -> Result<&mut Self, JointError> {
        self.prescribe_components(body, part, ComponentMask::ALL, value, history)
    }

    /// Prescribes the components in `mask` of `u₂(x, t) = h(t) value` on a part; the other
    /// components stay free.
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn prescribe_components(
        &mut self,
        body: impl BodyRef,
        part: &str,
        mask: ComponentMask,
        value: Vector<D>,
        history: impl LoadHistory + 'static,
    ) -> Result<&mut Self, JointError> {
        self.prescribe_field(body, part, mask, scaled(history, value))
    }

    /// Prescribes the components in `mask` of any displacement field `u₂(x, t)` on a part.
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn prescribe_field(
        &mut self,
        body: impl BodyRef,
        part: &str,
        mask: ComponentMask,
        field: impl Fn(&Point<D>, Real) -> Vector<D> + Send + Sync + 'static,
    ) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        self.assign_kind(id, part, BoundaryKind::Prescribed)?;
        self.model.prescribe_components(id, part, mask, field)?;
        Ok(self)
    }

    /// Moves a part rigidly: `u₂(x, t)` = the displacement of `motion` (all components).
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn rigid_motion(
        &mut self,
        body: impl BodyRef,
        part: &str,
        motion: RigidMotion<D>,
    ) -> Result<&mut Self, JointError> {
        self.prescribe_field(body, part, ComponentMask::ALL, move |x, t| motion.displacement(x, t))
    }

    /// Prescribes the traction `τ n = h(t) value` on a part.
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn traction(
        &mut self,
        body: impl BodyRef,
        part: &str,
        value: Vector<D>,
        history: impl LoadHistory + 'static,
    ) -> Result<&mut Self, JointError> {
        self.traction_field(body, part, scaled_traction(history, value))
    }

    /// Prescribes a normal pressure `p(t) = h(t) value` on a part (`τ n = −p n`, `p > 0` pushes
    /// into the body).
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn pressure(
        &mut self,
        body: impl BodyRef,
        part: &str,
        value: Real,
        history: impl LoadHistory + 'static,
    ) -> Result<&mut Self, JointError> {
        let h = synovia_time::history::FnHistory::new(move |t| value * history.value(t));
        self.traction_field(body, part, pressure(h))
    }

    /// Prescribes any traction field `P(x, n, t)` on a part.
    ///
    /// # Errors
    /// Unknown body or part; [`JointError::PartKind`].
    pub fn traction_field(
        &mut self,
        body: impl BodyRef,
        part: &str,
        field: impl Fn(&Point<D>, &Vector<D>, Real) -> Vector<D> + Send + Sync + 'static,
    ) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        self.assign_kind(id, part, BoundaryKind::Traction)?;
        self.model.traction(id, part, field)?;
        Ok(self)
    }

    /// Sets the body force `F(x, t) = h(t) value` (per unit volume) of a body.
    ///
    /// # Errors
    /// Unknown body.
    pub fn body_force(
        &mut self,
        body: impl BodyRef,
        value: Vector<D>,
        history: impl LoadHistory + 'static,
    ) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        self.model.body_force(id, scaled(history, value))?;
        Ok(self)
    }

    /// Bonds `part_a` of `body_a` to `part_b` of `body_b` (nodes at equal positions share their
    /// displacement).
    ///
    /// # Errors
    /// Unknown bodies or parts.
    pub fn tie(
        &mut self,
        body_a: impl BodyRef,
        part_a: &str,
        body_b: impl BodyRef,
        part_b: &str,
    ) -> Result<&mut Self, JointError> {
        let a = body_a.resolve(&self.model)?;
        let b = body_b.resolve(&self.model)?;
        self.model.tie(a, part_a, b, part_b)?;
        Ok(self)
    }

    // ----- contact -----

    /// Adds a body–body node-to-node contact pair between `part_k` of `body_k` and `part_l` of
    /// `body_l` (matching node positions, normal of body `k`) with Coulomb coefficient
    /// `friction` (0: frictionless).
    ///
    /// # Errors
    /// See [`JointModel::add_contact`].
    pub fn contact_bodies(
        &mut self,
        name: &str,
        body_k: impl BodyRef,
        part_k: &str,
        body_l: impl BodyRef,
        part_l: &str,
        friction: Real,
    ) -> Result<&mut Self, JointError> {
        let k = body_k.resolve(&self.model)?;
        let l = body_l.resolve(&self.model)?;
        self.add_contact(ContactPair::node_to_node(name, k, part_k, l, part_l).with_friction(friction))
    }

    /// Adds a contact pair between `part` of `body` and a rigid obstacle (e.g.
    /// [`PlaneObstacle`](synovia_contact::operators::PlaneObstacle),
    /// [`SphereObstacle`](synovia_contact::operators::SphereObstacle)) with Coulomb coefficient
    /// `friction`.
    ///
    /// # Errors
    /// See [`JointModel::add_contact`].
    pub fn contact_rigid(
        &mut self,
        name: &str,
        body: impl BodyRef,
        part: &str,
        obstacle: impl SignedDistance<D> + 'static,
        friction: Real,
    ) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        self.add_contact(ContactPair::rigid(name, id, part, Arc::new(obstacle)).with_friction(friction))
    }

    /// Adds any contact pair (e.g. with a fixed normal, [`ContactPair::with_fixed_normal`]);
    /// its parts get the kind `Contact`.
    ///
    /// # Errors
    /// [`JointError::Invalid`] for a duplicate pair name or a friction coefficient that is not
    /// finite and ≥ 0; unknown bodies or parts; [`JointError::PartKind`].
    pub fn add_contact(&mut self, pair: ContactPair<D>) -> Result<&mut Self, JointError> {
        if self.pairs.iter().any(|p| p.name == pair.name) {
            return Err(JointError::Invalid(format!("two contact pairs are called `{}`", pair.name)));
        }
        if !(pair.friction.is_finite() && pair.friction >= 0.0) {
            return Err(JointError::Invalid(format!(
                "contact pair `{}`: friction coefficient {} must be finite and ≥ 0",
                pair.name, pair.friction
            )));
        }
        self.check_pair_conflict(&pair)?;
        self.assign_kind(pair.body, &pair.part, BoundaryKind::Contact)?;
        if let Some((body, part)) = pair.partner_part() {
            self.assign_kind(body, part, BoundaryKind::Contact)?;
        }
        self.pairs.push(pair);
        Ok(self)
    }

    /// Replaces the friction law of a contact pair in quasi-static and dynamic runs, linear or
    /// nonlinear (default: its constant coefficient; docs/model.md §3,
    /// [`QuasiStaticStepper::set_friction_law`], [`DynamicStepper::set_friction_law`],
    /// [`NonlinearContact::set_friction_law`]).
    ///
    /// # Errors
    /// [`JointError::Invalid`] for an unknown pair.
    pub fn friction_law(&mut self, pair: &str, law: Arc<dyn FrictionLaw>) -> Result<&mut Self, JointError> {
        if !self.pairs.iter().any(|p| p.name == pair) {
            return Err(JointError::Invalid(format!("no contact pair `{pair}`")));
        }
        self.friction_laws.retain(|(n, _)| n != pair);
        self.friction_laws.push((pair.to_string(), law));
        Ok(self)
    }

    // ----- solver and analysis -----

    /// Chooses the contact solver by name (one of [`crate::solvers::SOLVER_NAMES`],
    /// [`crate::solvers::COMBINATOR_NAMES`], or [`TFETI`]: the model decomposed into
    /// subdomains, parameters by [`JointModel::tfeti`], run by [`JointModel::run_on`]).
    ///
    /// # Errors
    /// [`JointError::Contact`] for an unknown name.
    pub fn solver(&mut self, name: &str) -> Result<&mut Self, JointError> {
        if name != TFETI {
            crate::solvers::by_name_with(name, self.contact_params)?;
        }
        self.solver = name.to_string();
        Ok(self)
    }
    /// Sets the contact solver's parameters.
    pub fn contact_params(&mut self, params: ContactParams) -> &mut Self {
        self.contact_params = params;
        self
    }
    /// Sets the elastic solve's parameters (ordering, load quadrature).
    pub fn elastic_params(&mut self, params: ElasticParams) -> &mut Self {
        self.elastic_params = params;
        self
    }
    /// Sets the quasi-static stepper's parameters (also used by [`JointModel::run_static`]).
    pub fn quasistatic_params(&mut self, params: QuasiStaticParams) -> &mut Self {
        self.quasistatic_params = params;
        self
    }
    /// Sets the dynamic stepper's parameters (its `dt` is replaced by the one given to
    /// [`JointModel::run_dynamic`]).
    pub fn dynamic_params(&mut self, params: DynamicParams) -> &mut Self {
        self.dynamic_params = params;
        self
    }
    /// The kinematics of a body's strain (docs/model.md §2.3): [`Kinematics::SmallStrain`]
    /// (default) or [`Kinematics::FiniteStrain`] (total Lagrangian, the contact geometry on
    /// the deformed configuration). A model with a finite-strain body or a nonlinear material
    /// (no [`Material::linear_stiffness`], e.g. [`synovia_material::neo_hookean`]) is solved by
    /// the Newton iteration of [`synovia_nonlinear`] (static, quasi-static and dynamic analyses;
    /// the dynamic one by [`synovia_time::nonlinear_dynamic::NonlinearDynamicStepper`]).
    ///
    /// # Errors
    /// Unknown body.
    pub fn set_kinematics(
        &mut self,
        body: impl BodyRef,
        kinematics: Kinematics,
    ) -> Result<&mut Self, JointError> {
        let id = body.resolve(&self.model)?;
        self.kinematics[id.0] = kinematics;
        Ok(self)
    }

    /// The kinematics of every body.
    pub fn kinematics(&self) -> &[Kinematics] {
        &self.kinematics
    }

    /// Parameters of the Newton iteration of nonlinear models ([`NewtonParams`]).
    pub fn newton_params(&mut self, params: NewtonParams) -> &mut Self {
        self.newton = params;
        self
    }

    /// The parameters of the Newton iteration of nonlinear models (set by
    /// [`JointModel::newton_params`]).
    pub fn newton_parameters(&self) -> NewtonParams {
        self.newton
    }

    /// `true` if a body has a nonlinear material or finite-strain kinematics: the model is then
    /// solved by the Newton iteration of [`synovia_nonlinear`].
    pub fn is_nonlinear(&self) -> bool {
        self.kinematics.contains(&Kinematics::FiniteStrain)
            || self.model.bodies().iter().any(|b| b.material.linear_stiffness().is_none())
    }

    /// Nested iteration for cold starts of static and quasi-static contact solves
    /// ([`StaticContact::set_nested_iteration`]; default `Some(32)`).
    pub fn nested_iteration(&mut self, min_rows: Option<usize>) -> &mut Self {
        self.nested = min_rows;
        self
    }
    /// Sets the analysis run by [`JointModel::run`].
    pub fn set_analysis(&mut self, analysis: Analysis) -> &mut Self {
        self.analysis = Some(analysis);
        self
    }

    // ----- access -----

    /// The underlying model.
    pub fn model(&self) -> &Model<D> {
        &self.model
    }
    /// Mutable access to the underlying model (for data the builder has no method for).
    pub fn model_mut(&mut self) -> &mut Model<D> {
        &mut self.model
    }
    /// The contact pairs.
    pub fn pairs(&self) -> &[ContactPair<D>] {
        &self.pairs
    }
    /// The contact solver's name.
    pub fn solver_name(&self) -> &str {
        &self.solver
    }
    /// The analysis set with [`JointModel::set_analysis`].
    pub fn analysis(&self) -> Option<&Analysis> {
        self.analysis.as_ref()
    }
    /// The contact solver with its parameters.
    ///
    /// # Errors
    /// [`JointError::Contact`] for an unknown solver name; [`JointError::Unsupported`] for
    /// [`TFETI`], which is not a solver on the assembled operator (it runs through
    /// [`JointModel::run_on`], [`JointModel::run`], [`JointModel::run_static`] and
    /// [`JointModel::run_quasistatic`]).
    pub fn build_solver(&self) -> Result<Box<dyn ContactSolver>, JointError> {
        if self.uses_tfeti() {
            return Err(JointError::Unsupported {
                solver: TFETI.into(),
                feature: "use as a contact solver on the assembled, factorised stiffness (dynamic analyses, re-solve sessions, the C API); it solves static and quasi-static analyses of the decomposed model (run, run_static, run_quasistatic, run_on)".into(),
            });
        }
        Ok(crate::solvers::by_name_with(&self.solver, self.contact_params)?)
    }

    // ----- running -----

    /// Runs the analysis set with [`JointModel::set_analysis`].
    ///
    /// # Errors
    /// [`JointError::Invalid`] if none was set; the errors of the run.
    pub fn run(&self) -> Result<RunResult<D>, JointError> {
        self.run_with(|_| Ok(()))
    }

    /// As [`JointModel::run`], calling `observer` after every step.
    ///
    /// # Errors
    /// As [`JointModel::run`]; whatever `observer` returns.
    pub fn run_with(
        &self,
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        if self.uses_tfeti() {
            return self.run_on(&synovia_feti::SingleProcess, observer);
        }
        self.check_penetration_policy()?;
        let solver = self.solver.clone();
        // one log line per step (`tracing`, level debug; the library installs no subscriber)
        let observer = move |v: &StepView<'_, D>| {
            let ran = &v.result.solution.report.solver;
            tracing::debug!(
                step = v.record.step,
                time = v.record.time,
                iterations = v.record.iterations,
                kkt = if v.geometry.is_empty() { 0.0 } else { v.result.kkt.max() },
                step_s = v.record.step_s,
                solver = if ran.is_empty() { solver.as_str() } else { ran.as_str() },
                "step {} of {} done",
                v.record.step + 1,
                v.n_steps
            );
            observer(v)
        };
        match self.analysis.clone() {
            None => Err(JointError::Invalid("no analysis set (use set_analysis)".into())),
            Some(Analysis::Static { time }) => self.run_levels(&[time], observer),
            Some(Analysis::QuasiStatic { times }) => self.run_levels(&times, observer),
            Some(Analysis::Dynamic { dt, steps }) => self.run_dynamic_with(dt, steps, observer),
        }
    }

    /// One static contact problem at time `t` (see the module docs).
    ///
    /// # Errors
    /// Invalid model (missing boundary data, semi-coercive bodies, …), contact set-up and
    /// solver errors.
    pub fn run_static(&self, t: Real) -> Result<RunResult<D>, JointError> {
        self.run_levels(&[t], |_| Ok(()))
    }

    /// The quasi-static scheme over `times` (docs/model.md §7).
    ///
    /// # Errors
    /// As [`JointModel::run_static`]; bad `times`.
    pub fn run_quasistatic(&self, times: &[Real]) -> Result<RunResult<D>, JointError> {
        self.run_levels(times, |_| Ok(()))
    }

    /// As [`JointModel::run_quasistatic`], calling `observer` after every level.
    ///
    /// # Errors
    /// As [`JointModel::run_quasistatic`]; whatever `observer` returns.
    pub fn run_quasistatic_with(
        &self,
        times: &[Real],
        observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        self.run_levels(times, observer)
    }

    /// Prepares the model for repeated solves (navigation, interactive tools): validates it,
    /// assembles and factorises the stiffness and builds the contact geometry once, and
    /// returns a [`JointSession`] whose [`JointSession::solve_static`] (the problem of
    /// [`JointModel::run_static`]) and [`JointSession::step`] (one quasi-static level with the
    /// friction state) reuse that factorisation and warm-start from the previous solution.
    ///
    /// New loads or prescribed displacements are given between solves through the model's
    /// closures: build it with [`SharedValue`](synovia_time::history::SharedValue) histories
    /// and set them, or solve at another time `t` of its histories (see
    /// [`crate::session`]).
    ///
    /// ```
    /// use synovia::prelude::*;
    ///
    /// let mesh = rectangle(-1.0, 1.0, 0.0, 1.0, 8, 4, Grading::Uniform, Grading::Uniform)?;
    /// let mut joint = JointModel::<2>::new();
    /// let block = joint.add_body("block", mesh, plane_strain(1.0e3, 0.3)?)?;
    /// // the tool: the top is pushed down by a depth the user changes between frames
    /// let depth = SharedValue::new(0.005);
    /// joint.prescribe(block, "top", Vector::<2>::new(0.0, -1.0), depth.clone())?;
    /// let ball = SphereObstacle::new(Point::<2>::new(0.0, -2.0), 2.0, false)?;
    /// joint.contact_rigid("ball", block, "bottom", ball, 0.0)?;
    ///
    /// let mut session = joint.prepare()?; // factorises once
    /// let first = session.solve_static(0.0)?;
    /// assert!(!first.warm_started);
    /// let f1 = session.record().map(|r| r.pairs[0].normal_force).unwrap_or(0.0);
    ///
    /// depth.set(0.01); // next frame: deeper push, no rebuild
    /// let second = session.solve_static(0.0)?;
    /// assert!(second.warm_started && second.kkt < 1e-8);
    /// let f2 = session.record().map(|r| r.pairs[0].normal_force).unwrap_or(0.0);
    /// assert!(f2 > f1 && f1 > 0.0);
    /// assert_eq!(session.factorizations(), 1);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As [`JointModel::run_static`] for the set-up: invalid model, contact set-up, unknown
    /// solver.
    pub fn prepare(&self) -> Result<JointSession<'_, D>, JointError> {
        self.check_penetration_policy()?;
        JointSession::new(self)
    }

    /// The parameters a [`JointSession`] needs (elastic, quasi-static, nested iteration).
    /// The friction laws set with [`JointModel::friction_law`], by pair name.
    pub(crate) fn pair_friction_laws(&self) -> &[(String, Arc<dyn FrictionLaw>)] {
        &self.friction_laws
    }

    pub(crate) fn session_params(&self) -> (ElasticParams, QuasiStaticParams, Option<usize>) {
        (self.elastic_params, self.quasistatic_params, self.nested)
    }

    /// The dynamic scheme: `steps` steps of `dt` (records: the initial state and each step).
    /// Linear models run the semi-implicit Kelvin–Voigt scheme of docs/model.md (7.3) on one
    /// factorisation; a model with a nonlinear material or finite strain
    /// ([`JointModel::is_nonlinear`]) runs the same scheme with the internal force `F_int(U)`
    /// in place of `A⁽⁰⁾ U`, docs/model.md (12.2): every step a nonlinear contact problem
    /// solved by the Newton iteration with [`JointModel::newton_params`], cut back into half
    /// steps on failure; the Kelvin–Voigt viscosity stays the linear `C⁽¹⁾ ε(u')`.
    ///
    /// # Errors
    /// [`JointError::Invalid`] for a body without density, or rigid bodies with mixed control
    /// in a nonlinear model; the stepper's errors ([`JointError::Time`], e.g. a step whose
    /// Newton iteration fails after the cut-backs).
    pub fn run_dynamic(&self, dt: Real, steps: usize) -> Result<RunResult<D>, JointError> {
        self.run_dynamic_with(dt, steps, |_| Ok(()))
    }

    fn run_levels(
        &self,
        times: &[Real],
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        if self.uses_tfeti() {
            self.check_penetration_policy()?;
            return self.run_tfeti_levels(times, &synovia_feti::SingleProcess, observer);
        }
        let start = Instant::now();
        self.model.validate()?;
        let solver = self.build_solver()?;
        let n_steps = times.len();
        if self.is_nonlinear() {
            return self.run_nonlinear_levels(times, solver.as_ref(), start, observer);
        }
        if self.pairs.is_empty() {
            return self.run_elastic(times, solver.name(), start, observer);
        }
        let mut contact = StaticContact::with_interface_block(
            &self.model,
            &self.pairs,
            self.elastic_params,
            self.interface_block,
        )?;
        contact.set_nested_iteration(self.nested);
        contact.set_screening_band(self.screening_band)?;
        let n_dofs = contact.elastic().info().n_dofs;
        let mut stepper = QuasiStaticStepper::from_contact(&self.model, contact, self.quasistatic_params)?;
        for (pair, law) in &self.friction_laws {
            stepper.set_friction_law(pair, law.clone())?;
        }
        let geometry = stepper.geometry().clone();
        let setup_s = start.elapsed().as_secs_f64();
        if !self.rigid_bodies.is_empty() {
            return self.run_rigid_levels(times, stepper, solver.as_ref(), n_dofs, start, setup_s, observer);
        }
        let mut failure: Option<JointError> = None;
        let run = stepper.run(&self.model, times, solver.as_ref(), |record, result| {
            let view = StepView { model: &self.model, geometry: &geometry, record, result, n_steps };
            observer(&view).map_err(|e| {
                failure = Some(e);
                TimeError::InvalidParameter(OBSERVER_FAILED.into())
            })
        });
        let records = match (run, failure) {
            (Ok(r), _) => r,
            (Err(_), Some(e)) => return Err(e),
            (Err(e), None) => return Err(e.into()),
        };
        let last = stepper.last_result().cloned();
        Ok(RunResult {
            records,
            displacement: last.as_ref().map(|r| r.displacement.clone()).unwrap_or_default(),
            contact: last,
            n_dofs,
            contact_nodes: geometry.len(),
            solver: solver.name().to_string(),
            setup_s,
            total_s: start.elapsed().as_secs_f64(),
        })
    }

    /// The Newton iteration of a nonlinear model ([`NonlinearContact`]) with the model's
    /// parameters, interface block, screening band and friction laws (friction laws `F_c(v)`:
    /// the slip bounds of a level from the slip speed over the two converged levels before it,
    /// as the linear quasi-static scheme's), at the unloaded reference configuration.
    pub(crate) fn nonlinear_contact(&self) -> Result<NonlinearContact<D>, JointError> {
        let mut nl = NonlinearContact::with_interface_block(
            &self.model,
            &self.pairs,
            &self.kinematics,
            self.elastic_params,
            self.newton,
            self.interface_block,
        )?;
        for (pair, law) in &self.friction_laws {
            nl.set_friction_law(pair, law.clone())?;
        }
        nl.set_screening_band(self.screening_band)?;
        Ok(nl)
    }

    /// One level `t` (index `step`) of a nonlinear model from the converged state of `nl`: with
    /// rigid bodies posed and their force-controlled coordinates found by `driver`
    /// ([`RigidDriver::nonlinear_level`]), else [`NonlinearContact::step_to`]; its record.
    pub(crate) fn nonlinear_level(
        &self,
        nl: &mut NonlinearContact<D>,
        driver: Option<&mut RigidDriver>,
        step: usize,
        t: Real,
        solver: &dyn ContactSolver,
    ) -> Result<(StepRecord, NonlinearResult<D>), JointError> {
        Ok(match driver {
            Some(driver) => {
                let (mut record, level) = driver.nonlinear_level(self, nl, t, solver)?;
                record.step = step;
                (record, level)
            }
            None => {
                let level = nl.step_to(&self.model, t, solver)?;
                let record = StepRecord {
                    step,
                    time: t,
                    pairs: synovia_time::results::pair_records(nl.geometry(), &level.contact),
                    strain_energy: level.strain_energy,
                    iterations: level.report.total_iterations,
                    solver: level.contact.solution.report.solver.clone(),
                    fallback: level.contact.solution.report.fallback.clone(),
                    ..Default::default()
                };
                (record, level)
            }
        })
    }

    /// The levels of a nonlinear model (nonlinear materials or finite strain): the Newton
    /// iteration of [`synovia_nonlinear::NonlinearContact`] with load stepping and cut-back,
    /// Tresca friction frozen per level (docs/model.md §2.3, §8).
    fn run_nonlinear_levels(
        &self,
        times: &[Real],
        solver: &dyn ContactSolver,
        start: Instant,
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        check_levels(times)?;
        let mut nl = self.nonlinear_contact()?;
        // the reference configuration before the first level (the same start as the linear
        // quasi-static scheme's first level, which is solved from the undeformed body)
        let t0 = times.first().copied().unwrap_or(0.0).min(0.0);
        nl.reset(t0);
        let setup_s = start.elapsed().as_secs_f64();
        let n_dofs = nl.dofs().n_dofs();
        let mut records = Vec::with_capacity(times.len());
        let mut last = None;
        // rigid bodies with mixed control: posed per level, a force-controlled coordinate found
        // inside the Newton iteration (crate::rigid)
        let mut driver = (!self.rigid_bodies.is_empty()).then(|| RigidDriver::new(self));
        for (step, &t) in times.iter().enumerate() {
            let t_step = Instant::now();
            let (record, level) = self.nonlinear_level(&mut nl, driver.as_mut(), step, t, solver)?;
            let record = StepRecord { step_s: t_step.elapsed().as_secs_f64(), ..record };
            let geometry = nl.geometry();
            tracing::debug!(
                newton = level.report.iterations.len(),
                cutbacks = level.report.cutbacks,
                residual = level.report.residual(),
                "nonlinear level"
            );
            observer(&StepView {
                model: &self.model,
                geometry,
                record: &record,
                result: &level.contact,
                n_steps: times.len(),
            })?;
            records.push(record);
            last = Some(level.contact);
        }
        Ok(RunResult {
            records,
            displacement: last.as_ref().map(|r| r.displacement.clone()).unwrap_or_default(),
            contact: if self.pairs.is_empty() { None } else { last },
            n_dofs,
            contact_nodes: nl.geometry().len(),
            solver: solver.name().to_string(),
            setup_s,
            total_s: start.elapsed().as_secs_f64(),
        })
    }

    /// The levels of a model with rigid bodies: each level poses them and finds their
    /// force-controlled coordinates ([`crate::rigid`]).
    #[allow(clippy::too_many_arguments)]
    fn run_rigid_levels(
        &self,
        times: &[Real],
        mut stepper: QuasiStaticStepper<D>,
        solver: &dyn ContactSolver,
        n_dofs: usize,
        start: Instant,
        setup_s: f64,
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        check_levels(times)?;
        let mut driver = RigidDriver::new(self);
        let mut records = Vec::with_capacity(times.len());
        let mut last = None;
        for (i, &t) in times.iter().enumerate() {
            let mode = if i == 0 { LevelMode::Restart { warm: false } } else { LevelMode::Step };
            let (record, result) = driver.level(self, &mut stepper, t, solver, mode)?;
            let view = StepView {
                model: &self.model,
                geometry: stepper.geometry(),
                record: &record,
                result: &result,
                n_steps: times.len(),
            };
            observer(&view)?;
            records.push(record);
            last = Some(result);
        }
        Ok(RunResult {
            records,
            displacement: last.as_ref().map(|r| r.displacement.clone()).unwrap_or_default(),
            contact: last,
            n_dofs,
            contact_nodes: stepper.geometry().len(),
            solver: solver.name().to_string(),
            setup_s,
            total_s: start.elapsed().as_secs_f64(),
        })
    }

    fn run_elastic(
        &self,
        times: &[Real],
        solver: &str,
        start: Instant,
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        check_levels(times)?;
        let mut elastic = ElasticSolver::new(&self.model, self.elastic_params)?;
        let setup_s = start.elapsed().as_secs_f64();
        let geometry = empty_geometry::<D>();
        let mut records = Vec::with_capacity(times.len());
        let mut displacement = Vec::new();
        for (step, &time) in times.iter().enumerate() {
            let t0 = Instant::now();
            let sol = elastic.solve(&self.model, time)?;
            let strain_energy = synovia_fem::post::total_strain_energy(&self.model, &sol.displacement)?;
            let record = StepRecord {
                step,
                time,
                strain_energy,
                step_s: t0.elapsed().as_secs_f64(),
                ..Default::default()
            };
            let result = zero_result(sol.displacement, 0);
            observer(&StepView {
                model: &self.model,
                geometry: &geometry,
                record: &record,
                result: &result,
                n_steps: times.len(),
            })?;
            records.push(record);
            displacement = result.displacement;
        }
        Ok(RunResult {
            records,
            displacement,
            contact: None,
            n_dofs: elastic.info().n_dofs,
            contact_nodes: 0,
            solver: solver.to_string(),
            setup_s,
            total_s: start.elapsed().as_secs_f64(),
        })
    }

    /// As [`JointModel::run_dynamic`], calling `observer` after the initial state and every
    /// step.
    ///
    /// # Errors
    /// As [`JointModel::run_dynamic`]; whatever `observer` returns.
    pub fn run_dynamic_with(
        &self,
        dt: Real,
        steps: usize,
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        let start = Instant::now();
        self.model.validate()?;
        // rigid bodies: massless, every coordinate prescribed; posed at t₀ before the stepper
        // builds its contact rows, then at the end of every step (sub-step)
        let mut driver = if self.rigid_bodies.is_empty() {
            None
        } else {
            RigidDriver::check_dynamic(self)?;
            let mut driver = RigidDriver::new(self);
            driver.pose_prescribed(self, self.dynamic_params.t0)?;
            driver.accept();
            Some(driver)
        };
        let solver = self.build_solver()?;
        let bodies = self.dynamic_bodies()?;
        if self.is_nonlinear() {
            return self.run_nonlinear_dynamic(dt, steps, &bodies, solver.as_ref(), start, driver, observer);
        }
        let posed_pairs = !self.rigid_pair_bodies().is_empty();
        let params = self.dynamic_params.clone().with_dt(dt);
        let mut stepper = DynamicStepper::new(&self.model, &bodies, &self.pairs, params)?;
        for (pair, law) in &self.friction_laws {
            stepper.set_friction_law(pair, law.clone())?;
        }
        if let Some(v) = self.initial_velocity_field() {
            stepper.set_initial_state(&self.model, None, Some(&v))?;
        }
        let setup_s = start.elapsed().as_secs_f64();
        let n_steps = steps + 1;
        let mut records = Vec::with_capacity(n_steps);
        let mut initial = stepper.initial_record();
        let result = zero_result(stepper.displacement().to_vec(), stepper.geometry().len());
        if let Some(driver) = driver.as_mut() {
            initial = driver.record_prescribed_level(self, stepper.geometry(), initial, &result)?;
        }
        observer(&StepView {
            model: &self.model,
            geometry: stepper.geometry(),
            record: &initial,
            result: &result,
            n_steps,
        })?;
        records.push(initial);
        let mut last = None;
        for _ in 0..steps {
            // the rigid partners at the end of the step: the step's constraints are those of
            // their position there, the slip measured relative to their motion over the step
            let t_next = stepper.params().t0 + (stepper.step_index() + 1) as Real * stepper.dt();
            if let Some(driver) = driver.as_mut() {
                driver.pose_prescribed(self, t_next)?;
                if posed_pairs {
                    stepper.rebuild_geometry(&self.model, &self.pairs)?;
                    let motion =
                        driver.motion_since_accepted(self, stepper.geometry(), stepper.displacement());
                    stepper.set_partner_motion(motion)?;
                }
            }
            let mut record = stepper.step(&self.model, solver.as_ref())?;
            let result = match stepper.last_contact() {
                Some(r) => r.clone(),
                None => zero_result(stepper.displacement().to_vec(), stepper.geometry().len()),
            };
            if let Some(driver) = driver.as_mut() {
                driver.accept();
                record = driver.record_prescribed_level(self, stepper.geometry(), record, &result)?;
            }
            observer(&StepView {
                model: &self.model,
                geometry: stepper.geometry(),
                record: &record,
                result: &result,
                n_steps,
            })?;
            records.push(record);
            last = Some(result);
        }
        Ok(RunResult {
            records,
            displacement: stepper.displacement().to_vec(),
            contact: last.filter(|_| !self.pairs.is_empty()),
            n_dofs: stepper.info().n_dofs,
            contact_nodes: stepper.geometry().len(),
            solver: solver.name().to_string(),
            setup_s,
            total_s: start.elapsed().as_secs_f64(),
        })
    }

    /// The nodal initial velocity of every body (each body's uniform velocity, zero for bodies
    /// without one), or `None` when no body has one.
    fn initial_velocity_field(&self) -> Option<Vec<Vec<Vector<D>>>> {
        self.initial_velocity.iter().any(Option::is_some).then(|| {
            self.model
                .bodies()
                .iter()
                .zip(&self.initial_velocity)
                .map(|(b, v)| vec![v.unwrap_or_else(Vector::<D>::zeros); b.mesh.n_nodes()])
                .collect()
        })
    }

    /// The dynamic data of every body.
    fn dynamic_bodies(&self) -> Result<Vec<DynamicBody>, JointError> {
        let mut bodies = Vec::with_capacity(self.dynamic.len());
        for (body, data) in self.model.bodies().iter().zip(&self.dynamic) {
            match data {
                Some(d) => bodies.push(d.clone()),
                None => {
                    return Err(JointError::Invalid(format!(
                        "body `{}` has no density for the dynamic analysis (give it a Kelvin-Voigt material or a density)",
                        body.name
                    )))
                }
            }
        }
        Ok(bodies)
    }

    /// The dynamic scheme of a nonlinear model (nonlinear materials or finite strain): each
    /// step the nonlinear contact problem of docs/model.md (12.2) solved by the Newton
    /// iteration with the model's [`NewtonParams`], cut back into halves on failure
    /// ([`synovia_time::nonlinear_dynamic::NonlinearDynamicStepper`]).
    #[allow(clippy::too_many_arguments)]
    fn run_nonlinear_dynamic(
        &self,
        dt: Real,
        steps: usize,
        bodies: &[DynamicBody],
        solver: &dyn ContactSolver,
        start: Instant,
        mut driver: Option<RigidDriver>,
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        let params = self.dynamic_params.clone().with_dt(dt);
        let mut stepper = NonlinearDynamicStepper::new(
            &self.model,
            bodies,
            &self.pairs,
            &self.kinematics,
            params,
            self.newton,
        )?;
        for (pair, law) in &self.friction_laws {
            stepper.set_friction_law(pair, law.clone())?;
        }
        if let Some(v) = self.initial_velocity_field() {
            stepper.set_initial_state(&self.model, None, Some(&v))?;
        }
        let setup_s = start.elapsed().as_secs_f64();
        let n_steps = steps + 1;
        let mut records = Vec::with_capacity(n_steps);
        let mut initial = stepper.initial_record();
        let result = zero_result(stepper.displacement().to_vec(), stepper.geometry().len());
        if let Some(driver) = driver.as_mut() {
            initial = driver.record_prescribed_level(self, stepper.geometry(), initial, &result)?;
        }
        observer(&StepView {
            model: &self.model,
            geometry: stepper.geometry(),
            record: &initial,
            result: &result,
            n_steps,
        })?;
        records.push(initial);
        let mut last = None;
        let posed_pairs = !self.rigid_pair_bodies().is_empty();
        for _ in 0..steps {
            // the rigid partners posed at the end of every sub-step, the contact rows rebuilt
            // there, the slip of friction measured relative to their motion
            let mut record = match driver.as_mut().filter(|_| posed_pairs) {
                Some(driver) => {
                    let mut partners = crate::rigid::PrescribedPartners { joint: self, driver };
                    stepper.step_posing(&self.model, solver, Some(&mut partners))?
                }
                None => stepper.step(&self.model, solver)?,
            };
            let report = stepper.last_report();
            tracing::debug!(
                step = record.step,
                newton = report.newton_iterations,
                cutbacks = report.cutbacks,
                "nonlinear dynamic step"
            );
            let result = match stepper.last_contact() {
                Some(r) if !self.pairs.is_empty() => r.clone(),
                _ => zero_result(stepper.displacement().to_vec(), stepper.geometry().len()),
            };
            if let Some(driver) = driver.as_mut() {
                driver.accept();
                record = driver.record_prescribed_level(self, stepper.geometry(), record, &result)?;
            }
            observer(&StepView {
                model: &self.model,
                geometry: stepper.geometry(),
                record: &record,
                result: &result,
                n_steps,
            })?;
            records.push(record);
            last = Some(result);
        }
        Ok(RunResult {
            records,
            displacement: stepper.displacement().to_vec(),
            contact: last.filter(|_| !self.pairs.is_empty()),
            n_dofs: stepper.dofs().n_dofs(),
            contact_nodes: stepper.geometry().len(),
            solver: solver.name().to_string(),
            setup_s,
            total_s: start.elapsed().as_secs_f64(),
        })
    }

    // ----- reporting (issue 16 item 5) -----

    /// Reports the figures of contact pair `pair` also split by a plane into two sides (e.g.
    /// medial and lateral, [`PairSplit`](synovia_contact::operators::PairSplit)): every step
    /// record's [`PairRecord::sides`](synovia_time::results::PairRecord::sides) then holds
    /// the force, moment, areas, peak and mean pressure and centre of pressure of each side.
    /// Reporting only: the solution does not change. A second call replaces the split.
    ///
    /// # Errors
    /// [`JointError::Invalid`] for an unknown pair.
    pub fn split_pair_report(
        &mut self,
        pair: &str,
        split: synovia_contact::operators::PairSplit,
    ) -> Result<&mut Self, JointError> {
        let p = self
            .pairs
            .iter_mut()
            .find(|p| p.name == pair)
            .ok_or_else(|| JointError::Invalid(format!("no contact pair `{pair}`")))?;
        p.report_split = Some(split);
        Ok(self)
    }
}

/// Time levels must be finite, strictly increasing, at least one.
fn check_levels(times: &[Real]) -> Result<(), JointError> {
    if times.is_empty() {
        return Err(JointError::Invalid("no time levels".into()));
    }
    for (i, &t) in times.iter().enumerate() {
        if !t.is_finite() || (i > 0 && t <= times[i - 1]) {
            return Err(JointError::Invalid(format!(
                "time levels must be finite and increase strictly (level {i}: {t})"
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use synovia_contact::operators::PlaneObstacle;
    use synovia_material::plane_strain;
    use synovia_mesh::generators::{rectangle, Grading};
    use synovia_time::history::{Constant, PiecewiseLinear};

    fn block() -> Mesh<2> {
        rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Grading::Uniform, Grading::Uniform).unwrap()
    }

    #[test]
    fn part_kinds_are_assigned_once() {
        let mut jm = JointModel::<2>::new();
        jm.add_body("b", block(), plane_strain(1.0, 0.3).unwrap()).unwrap();
        jm.clamp("b", "bottom").unwrap();
        jm.clamp("b", "bottom").unwrap();
        let e = jm.traction("b", "bottom", Vector::<2>::new(0.0, 1.0), Constant(1.0)).unwrap_err();
        assert!(matches!(e, JointError::PartKind { current: BoundaryKind::Clamped, .. }), "{e}");
        let e = jm.clamp("b", "nope").unwrap_err();
        assert!(e.to_string().contains("nope"), "{e}");
        assert!(jm.clamp("c", "bottom").is_err());
        assert!(jm.solver("newton").is_err());
    }

    #[test]
    fn quasistatic_block_on_a_flat_balances_the_push() {
        let mut jm = JointModel::<2>::new();
        let b = jm.add_body("b", block(), plane_strain(1.0, 0.3).unwrap()).unwrap();
        let h = PiecewiseLinear::new(&[(0.0, 0.5), (1.0, 1.0)]).unwrap();
        jm.prescribe(b, "top", Vector::<2>::new(0.0, -0.01), h).unwrap();
        jm.contact_rigid(
            "floor",
            b,
            "bottom",
            PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::y()).unwrap(),
            0.2,
        )
        .unwrap();
        let mut seen = 0;
        let res = jm
            .run_quasistatic_with(&[0.0, 1.0], |v| {
                seen += 1;
                assert_eq!(v.n_steps, 2);
                Ok(())
            })
            .unwrap();
        assert_eq!(seen, 2);
        assert_eq!(res.records.len(), 2);
        let f0 = res.records[0].pairs[0].normal_force;
        let f1 = res.records[1].pairs[0].normal_force;
        // a unit block squeezed by 1 %: between plane-strain uniaxial stress E/(1 − ν²) and
        // uniaxial strain E (1 − ν)/((1 + ν)(1 − 2ν)) (top held sideways, bottom sliding)
        let (lo, hi) = (0.01 / 0.91, 0.01 * 0.7 / (1.3 * 0.4));
        assert!(lo < f1 && f1 < hi, "{f1}");
        assert!((f0 - 0.5 * f1).abs() < 0.05 * f1, "{f0} {f1}");
        // the observer's error comes back unchanged
        let e = jm.run_quasistatic_with(&[0.0], |_| Err(JointError::Invalid("stop".into()))).unwrap_err();
        assert_eq!(e.to_string(), "stop");
    }

    #[test]
    fn gmsh_bodies_get_their_materials_by_name() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/block2d.msh");
        let mut jm = JointModel::<2>::new();
        let ids = jm
            .add_gmsh_bodies(&path, |name| (name == "block").then(|| plane_strain(5.0, 0.4).unwrap().into()))
            .unwrap();
        assert_eq!(ids.len(), 1);
        jm.clamp("block", "bottom").unwrap().pressure("block", "top", 0.1, Constant(1.0)).unwrap();
        let res = jm.run_static(0.0).unwrap();
        assert!(res.displacement[0].iter().any(|u| u[1] < 0.0));
        let e = JointModel::<2>::new().add_gmsh_bodies(&path, |_| None).unwrap_err();
        assert!(e.to_string().contains("block"), "{e}");
    }

    #[test]
    fn elastic_model_without_pairs_and_dynamic_needs_density() {
        let mut jm = JointModel::<2>::new();
        let b = jm.add_body("b", block(), plane_strain(1.0, 0.3).unwrap()).unwrap();
        jm.clamp(b, "bottom").unwrap();
        jm.pressure(b, "top", 0.01, Constant(1.0)).unwrap();
        let res = jm.run_static(0.0).unwrap();
        assert!(res.contact.is_none());
        let top = res.displacement[0].iter().map(|u| u[1]).fold(0.0, f64::min);
        assert!(top < 0.0);
        let e = jm.run_dynamic(1e-3, 2).unwrap_err();
        assert!(e.to_string().contains("density"), "{e}");
        jm.set_density(b, 1.0).unwrap();
        let res = jm.run_dynamic(1e-2, 3).unwrap();
        assert_eq!(res.records.len(), 4);
    }
}
