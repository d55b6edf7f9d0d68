//! The `tkr3d` model: the total knee replacement of the Grand Challenge subject DM (Fregly et
//! al. 2012) over one measured gait cycle (`docs/tkr3d.md`).
//!
//! The UHMWPE tibial insert (P1 tetrahedra meshed from its STL, its tray face clamped) against
//! the rigid femoral component bounded by its closed STL surface, posed from the fluoroscopic
//! kinematics; the superior–inferior translation force-controlled by the ISO 14243-1 axial
//! force (or prescribed, [`Superior::Prescribed`]), optionally the medial–lateral translation
//! and the ab/adduction freed under zero force / moment. Time is the fraction of the cycle
//! (0…1). [`Tkr3d::joint_model`] builds the [`JointModel`]; the `tkr3d` example runs it and
//! the `bench_report` case `pose_resolve_3d` re-solves it for new poses.

use std::path::PathBuf;
use std::sync::Arc;

use synovia::builder::{JointError, JointModel};
use synovia::contact_ops::operators::{PairSplit, SignedDistance};
use synovia::nonlinear::NewtonParams;
use synovia::rigid::{ForceControlParams, RigidBody};
use synovia_contact::SurfaceObstacle;
use synovia_fem::Kinematics;
use synovia_io::read_stl;
use synovia_material::{isotropic, neo_hookean, Material};
use synovia_mesh::math::{Point, Real};
use synovia_mesh::SurfaceError;
use synovia_time::history::{Constant, FnHistory, LoadHistory, PiecewiseLinear};
use synovia_time::table::{Table, TableError};

use crate::knee2d::iso14243_axial_force;

/// What can go wrong building the model: the joint (data files, meshes, options), the
/// kinematics table, the femoral surface.
#[derive(Debug)]
pub enum Tkr3dError {
    /// Building the joint model.
    Joint(JointError),
    /// Reading or using the kinematics table.
    Table(TableError),
    /// The femoral component's surface.
    Surface(SurfaceError),
}

impl std::fmt::Display for Tkr3dError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Tkr3dError::Joint(e) => write!(f, "tkr3d model: {e}"),
            Tkr3dError::Table(e) => write!(f, "tkr3d kinematics: {e}"),
            Tkr3dError::Surface(e) => write!(f, "tkr3d femoral surface: {e}"),
        }
    }
}

impl std::error::Error for Tkr3dError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Tkr3dError::Joint(e) => Some(e),
            Tkr3dError::Table(e) => Some(e),
            Tkr3dError::Surface(e) => Some(e),
        }
    }
}

macro_rules! from_error {
    ($($variant:ident($t:ty)),*) => {$(
        impl From<$t> for Tkr3dError {
            fn from(e: $t) -> Self {
                Tkr3dError::$variant(e)
            }
        }
    )*};
}
from_error!(Joint(JointError), Table(TableError), Surface(SurfaceError));

// the errors a joint model wraps, through it
macro_rules! from_joint_error {
    ($($t:ty),*) => {$(
        impl From<$t> for Tkr3dError {
            fn from(e: $t) -> Self {
                Tkr3dError::Joint(JointError::from(e))
            }
        }
    )*};
}
from_joint_error!(
    synovia_io::IoError,
    synovia_contact::ContactError,
    synovia_material::MaterialError,
    synovia_mesh::MeshError,
    synovia_time::TimeError
);

/// UHMWPE, as in the OpenSim-JAM model of subject DM (Halloran et al. 2005): E (MPa), ν.
pub const UHMWPE: (Real, Real) = (463.0, 0.46);
/// Contact candidates: insert nodes farther than this from the femoral component keep an
/// inactive row (mm).
pub const SEARCH_DISTANCE: Real = 3.0;
/// Coulomb coefficient of lubricated CoCr–UHMWPE (0.04–0.1 in pin-on-plate tests at these
/// pressures; `docs/tkr3d.md`).
pub const FRICTION: Real = 0.04;
/// Rows with a larger gap (mm) are left out of each contact solve until they come into contact.
pub const SCREENING_BAND: Real = 0.5;

/// Default levels of Loop subdivision of the femoral surface ([`Tkr3d::femur_subdivision`]).
pub const FEMUR_SUBDIVISION: usize = 0;
/// Dihedral angle above which an edge of the femoral surface stays a sharp crease under
/// subdivision (30°: the rims and the box cuts of the component, not the articular surface,
/// whose facets meet at a few degrees).
pub const FEMUR_CREASE_ANGLE: Real = std::f64::consts::PI / 6.0;
/// The largest offset (mm) of a fillet of the femur's concave edges from the faceted surface
/// ([`Tkr3d::femur_fillet`]): the radius of a sharper edge is cut to it (unbounded, fillets of
/// 0.1 mm lie up to 0.12 mm off the STL's sharpest inner corners).
pub const FEMUR_FILLET_MAX_OFFSET: Real = 2.5e-3;

/// How the femur's superior–inferior translation (degree of freedom 1) is set.
#[derive(Debug, Clone)]
pub enum Superior {
    /// Force-controlled by the ISO 14243-1 axial force, starting from the measured translation.
    IsoForce,
    /// Prescribed (mm, over the cycle fraction), e.g. the translations a force-controlled run
    /// found, for re-solving poses without the force iteration.
    Prescribed(Arc<dyn LoadHistory>),
}

/// The constitutive law of the insert.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InsertLaw {
    /// Linear elasticity in small strain with `E`, `ν` of [`Tkr3d::insert_material`] (the main
    /// job).
    #[default]
    Linear,
    /// Compressible neo-Hookean `W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²` in total Lagrangian
    /// finite strain (docs/model.md §12), with the Lamé constants of the same `E`, `ν`:
    /// `μ = E / (2(1 + ν))`, `λ = E ν / ((1 + ν)(1 − 2ν))` (so linear elasticity at `e = 0`;
    /// UHMWPE: μ = 158.6 MPa, λ = 1 824 MPa). Solved by the Newton iteration of
    /// `synovia-nonlinear`, the superior–inferior force found inside it, with the other five
    /// coordinates prescribed; friction as the linear insert's (Coulomb frozen to Tresca per
    /// pose, the slip relative to the femur) or none with `friction = 0` (docs/tkr3d.md).
    NeoHookean,
}

/// The contraction bound of modified Newton for the neo-Hookean insert
/// (`NewtonParams::with_tangent_reuse`).
pub const NH_TANGENT_REUSE: Real = 0.5;

/// The relative residual at which a geometry pass of the neo-Hookean insert ends while its
/// geometry still moves ([`NewtonParams::geometry_pass_tolerance`]).
pub const NH_PASS_TOLERANCE: Real = 1e-3;

/// Options of the model (the defaults are the main job's).
#[derive(Debug, Clone)]
pub struct Tkr3d {
    /// Folder with the data (`femoral_component.stl`, `fluoroscopic_gait_kinematics.sto`,
    /// `mesh/`); default `data/tka-grand-challenge-dm` relative to the working directory.
    pub data_dir: PathBuf,
    /// The 0.5 mm articular mesh (`tibial_insert_h05.msh.gz`) instead of the 1 mm one.
    pub fine: bool,
    /// Coulomb coefficient against the femoral component (0: frictionless).
    pub friction: Real,
    /// Medial–lateral translation free under zero force instead of prescribed.
    pub free_ml: bool,
    /// Ab/adduction free under zero moment instead of prescribed.
    pub free_adduction: bool,
    /// Contact candidates: boundary facets above the tray with `n_y` above this (0.5: at most
    /// 60° from horizontal).
    pub contact_min_ny: Real,
    /// Gap screening band (mm; `None`: every candidate in every solve).
    pub screening_band: Option<Real>,
    /// A dense interface block instead of whole-factor solves of the active rows.
    pub dense_interface: bool,
    /// The superior–inferior degree of freedom.
    pub superior: Superior,
    /// Force-control parameters (tolerances; with freed degrees of freedom the example uses
    /// fresh Jacobians, 500 solves and 1e-8).
    pub control: ForceControlParams,
    /// Levels of Loop subdivision of the femoral surface before it is used (0: the STL as it
    /// is). The decimated STL has facets of 1.25 mm (median edge, up to 2.9 mm), creases of a
    /// few degrees at each edge; two levels (0.31 mm) make it smooth on the scale of the
    /// insert's meshes (docs/tkr3d.md, "Mesh convergence"; `synovia_mesh::subdivision`).
    pub femur_subdivision: usize,
    /// Radius (mm) of the fillets that round the femoral surface's concave edges (0: none,
    /// the default; [`synovia_contact::SurfaceObstacle::with_concave_fillet`], each within
    /// [`FEMUR_FILLET_MAX_OFFSET`] of the STL). A contact node
    /// pressed into such an edge has no fixed point of the geometry passes on the deformed
    /// configuration with one row against the faceted surface (its normal jumps between the
    /// two faces): the neo-Hookean cycle with friction stopped at its 14 % pose that way
    /// (docs/tkr3d.md, "Neo-Hookean insert").
    pub femur_fillet: Real,
    /// Young's modulus (MPa) and Poisson's ratio of the insert (default [`UHMWPE`]).
    pub insert_material: (Real, Real),
    /// The insert's law (default [`InsertLaw::Linear`]).
    pub insert_law: InsertLaw,
}

impl Default for Tkr3d {
    fn default() -> Self {
        Self {
            data_dir: PathBuf::from("data/tka-grand-challenge-dm"),
            fine: false,
            friction: FRICTION,
            free_ml: false,
            free_adduction: false,
            contact_min_ny: 0.5,
            screening_band: Some(SCREENING_BAND),
            dense_interface: false,
            superior: Superior::IsoForce,
            control: ForceControlParams::default(),
            femur_subdivision: FEMUR_SUBDIVISION,
            femur_fillet: 0.0,
            insert_material: UHMWPE,
            insert_law: InsertLaw::Linear,
        }
    }
}

impl Tkr3d {
    /// The mesh file of the insert in `data_dir/mesh/`.
    pub fn mesh_file(&self) -> &'static str {
        if self.fine {
            "tibial_insert_h05.msh.gz"
        } else {
            "tibial_insert_h1.msh"
        }
    }

    /// The measured superior–inferior translation of the femur (mm) over the cycle fraction.
    ///
    /// # Errors
    /// [`Tkr3dError::Table`] when the kinematics table cannot be read.
    pub fn measured_si(&self) -> Result<PiecewiseLinear, Tkr3dError> {
        Ok(self.kinematics()?.history("knee_sup_r", 1000.0, 0.01)?)
    }

    fn kinematics(&self) -> Result<Table, Tkr3dError> {
        Ok(Table::read(self.data_dir.join("fluoroscopic_gait_kinematics.sto"))?)
    }

    /// Builds the joint: the insert (UHMWPE, tray clamped, contact part `contact` by geometry),
    /// the femur `femur` (rigid, rotation order `zxy`, degrees of freedom 0–5: anterior,
    /// superior, lateral translation (mm), rotations about x, y, z (rad) from the table's
    /// `knee_ant_r`, `knee_sup_r`, `knee_lat_r`, `knee_flex_r`, `knee_add_r`, `knee_rot_r`), the
    /// pair `femur-insert` split into `lateral` (+z) and `medial`, solver `pdas-fallback`.
    ///
    /// # Errors
    /// [`Tkr3dError`] for missing or bad data files and invalid options (`contact_min_ny`
    /// outside `[−1, 1)`, `friction` outside `[0, 1)`, a negative screening band).
    pub fn joint_model(&self) -> Result<JointModel<3>, Tkr3dError> {
        if !(-1.0..1.0).contains(&self.contact_min_ny) {
            return Err(JointError::Invalid(format!(
                "contact_min_ny must be in [-1, 1), got {}",
                self.contact_min_ny
            ))
            .into());
        }
        if !(0.0..1.0).contains(&self.friction) {
            return Err(
                JointError::Invalid(format!("friction must be in [0, 1), got {}", self.friction)).into()
            );
        }
        let mut joint = JointModel::<3>::new();
        let (e, nu) = self.insert_material;
        let uhmwpe: Arc<dyn Material<3>> = match self.insert_law {
            InsertLaw::Linear => Arc::new(isotropic(e, nu)?),
            InsertLaw::NeoHookean => Arc::new(neo_hookean(e, nu)?),
        };
        joint.add_gmsh_bodies(self.data_dir.join("mesh").join(self.mesh_file()), |_| {
            Some(uhmwpe.clone().into())
        })?;
        if self.insert_law == InsertLaw::NeoHookean {
            joint.set_kinematics("insert", Kinematics::FiniteStrain)?;
            // modified Newton: the factorised tangent (and the unit solves of the contact nodes
            // on it) kept while full steps contract the residual by half, also from pose to pose
            // (docs/tkr3d.md, "Neo-Hookean insert": 2–3 × less time than fresh tangents); the
            // geometry passes relaxed by Aitken's rule with friction (half the Newton iterations of
            // the fixed relaxation 0.5 over the cycle; frictionless the fixed one needs fewer,
            // docs/nonlinear.md "Friction and the geometry passes")
            // a geometry pass whose geometry still moves ends at the relative residual
            // `NH_PASS_TOLERANCE` instead of converging to the Newton tolerance on a geometry
            // about to be rebuilt (whole frictional cycle: 715 Newton iterations against 1 271,
            // the JSON line's per-pose figures the same to every digit printed; docs/tkr3d.md)
            joint.newton_params(
                NewtonParams::default()
                    .with_tangent_reuse(Some(NH_TANGENT_REUSE))
                    .with_geometry_aitken(self.friction > 0.0)
                    .with_geometry_pass_tolerance(Some(NH_PASS_TOLERANCE)),
            );
        }
        joint.clamp("insert", "tray")?;
        // the contact candidates: every upward-facing facet above the tray (the meshes'
        // `articular` part starts at y = 6 mm and misses the bottom of the dishes, at 5.9 mm;
        // docs/meshing.md)
        let min_ny = self.contact_min_ny;
        joint.define_part("insert", "contact", move |x, n| n[1] > min_ny && x[1] > 1.0)?;

        // the femoral component: rigid, bounded by its closed surface (metres → mm)
        // (Loop-subdivided: its edges stay sharp where its facets meet at more than 30°)
        let femur_surface = read_stl(self.data_dir.join("femoral_component.stl"))?.scaled(1000.0)?;
        let shape: Arc<dyn SignedDistance<3>> = Arc::new(
            SurfaceObstacle::smoothed_solid(femur_surface, self.femur_subdivision, FEMUR_CREASE_ANGLE)?
                .with_concave_fillet(self.femur_fillet, FEMUR_FILLET_MAX_OFFSET)?,
        );

        // the pose over the cycle: time = fraction of the cycle (the table's time is in percent)
        let table = self.kinematics()?;
        let column = |name: &str, factor: Real| table.history(name, factor, 0.01);
        let femur = RigidBody::<3>::new("femur", Point::<3>::zeros())?
            .with_rotation_order("zxy")?
            .prescribe(0, column("knee_ant_r", 1000.0)?)?;
        let femur = match &self.superior {
            Superior::IsoForce => {
                let force = iso14243_axial_force().map_err(|e| JointError::Invalid(e.to_string()))?;
                let down = FnHistory::new(move |t| -force.value(t));
                femur.force_with_guess(1, down, column("knee_sup_r", 1000.0)?)?
            }
            Superior::Prescribed(si) => femur.prescribe(1, si.clone())?,
        };
        // column 4: the medial–lateral translation, prescribed as measured or free under zero
        // force (a load-controlled knee simulator leaves it free)
        let femur = if self.free_ml {
            femur.force_with_guess(2, Constant(0.0), column("knee_lat_r", 1000.0)?)?
        } else {
            femur.prescribe(2, column("knee_lat_r", 1000.0)?)?
        };
        // column 5: ab/adduction (rotation about the anterior axis), prescribed as measured or
        // free under zero moment about the femoral origin (docs/tkr3d.md)
        let femur = if self.free_adduction {
            femur.force_with_guess(3, Constant(0.0), column("knee_flex_r", 1.0)?)?
        } else {
            femur.prescribe(3, column("knee_flex_r", 1.0)?)?
        };
        let femur = femur
            .prescribe(4, column("knee_add_r", 1.0)?)? // column 6: rotation about y
            .prescribe(5, column("knee_rot_r", 1.0)?)?; // column 7: rotation about z
        joint.add_rigid_body(femur)?;
        // Coulomb friction (frozen to Tresca per pose) against the moving femoral component,
        // the slip measured relative to it (docs/model.md (10.5))
        joint.contact_rigid_body("femur-insert", "insert", "contact", "femur", shape, self.friction)?;
        joint.search_distance("femur-insert", SEARCH_DISTANCE)?;
        // medial (−z, right knee) and lateral (+z) sides of the insert
        joint.split_pair_report(
            "femur-insert",
            PairSplit::new("lateral", "medial", [0.0; 3], [0.0, 0.0, 1.0])?,
        )?;
        joint.solver("pdas-fallback")?;
        joint.force_control(self.control);
        // the candidate surface is large and the contact patches move: whole-factor solves of
        // the active rows instead of a dense interface block (docs/tkr3d.md, performance)
        if !self.dense_interface {
            joint.interface_block(
                synovia::linalg::InterfaceBlockParams::default().with_max_dofs(0).with_screened_dofs(0),
            );
        }
        // gap screening: each solve runs on the insert nodes within the band of the femur and
        // adds others only if they come into contact (exact; docs/tkr3d.md, performance)
        joint.screening_band(self.screening_band)?;
        Ok(joint)
    }
}
