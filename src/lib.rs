//! # synovia
//!
//! Finite-element simulation of human joints (knee, hip, their total replacements) as
//! multi-body contact problems under time-varying loads. This facade re-exports the workspace
//! crates:
//!
//! | crate | concern |
//! |---|---|
//! | [`mesh`] (`synovia-mesh`) | simplicial meshes, boundary parts, generators, local refinement |
//! | [`material`] (`synovia-material`) | constitutive laws `C⁽⁰⁾`, `C⁽¹⁾` (isotropic, transversely isotropic, anisotropic, Kelvin–Voigt) |
//! | [`linalg`] (`synovia-linalg`) | sparse matrices, the `FactorisedOperator` seam, faer sparse Cholesky (orderings, interface block, recycled solves) |
//! | [`fem`] (`synovia-fem`) | P1 elements, constraints, assembly, the elastic solve, post-processing |
//! | [`io`] (`synovia-io`) | VTU/PVD output for ParaView |
//! | [`contact_ops`] (`synovia-contact`) | contact pairs, `B_hn`/`B_Ht`, the contact problem, `ContactSolver`, KKT checker |
//! | [`pdas`] (`synovia-pdas`) | semismooth Newton / PDAS and AU-PDAS |
//! | [`uzawa`] (`synovia-uzawa`) | Uzawa with MPRGP, and the dual QP on the interface |
//! | [`time`] (`synovia-time`) | load histories, rigid motions, quasi-static and dynamic time stepping |
//!
//! The demonstration and verification models (Hertz, Cattaneo–Mindlin, the 2D knee, the 3D
//! hip, manufactured solutions) are in the crate `synovia-models`; TOML scenario files and
//! array inputs are turned into models by the crate `synovia-scenario`.
//!
//! See `docs/architecture.md` for the crate graph and the path of data from mesh to solution,
//! and `docs/model.md`, the project's statement of the model and algorithms, for the equations.
//!
//! ## A complete small model
//!
//! A plane-strain block (2 × 1) rests on a rigid floor; its top is pushed down by 1 % of its
//! height over two load steps, then sheared sideways with Coulomb friction `μ = 0.3`. The
//! [`builder::JointModel`] holds the bodies, the boundary conditions by part name with their
//! load histories, the contact pair and the solver, and runs the quasi-static analysis:
//!
//! ```
//! use synovia::prelude::*;
//!
//! let mesh = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4, Grading::Uniform, Grading::Uniform)?;
//! let mut joint = JointModel::<2>::new();
//! let block = joint.add_body("block", mesh, plane_strain(1.0e3, 0.3)?)?;
//! // the top moves down by 0.01 (times 0 → 1), then sideways by 0.002 (times 1 → 2)
//! let down = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, 1.0)])?;
//! let side = PiecewiseLinear::new(&[(1.0, 0.0), (2.0, 1.0)])?;
//! joint.prescribe_field(block, "top", ComponentMask::ALL, move |_x, t| {
//!     Vector::<2>::new(0.002 * side.value(t), -0.01 * down.value(t))
//! })?;
//! // the bottom touches the floor y = 0, with friction
//! let floor = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0))?;
//! joint.contact_rigid("floor", block, "bottom", floor, 0.3)?;
//! joint.solver("pdas")?;
//!
//! let result = joint.run_quasistatic(&[0.5, 1.0, 1.5, 2.0])?;
//! assert_eq!(result.records.len(), 4);
//! let pushed = &result.records[1].pairs[0];
//! assert!(pushed.normal_force > 0.0 && pushed.contact_area > 1.99);
//! let sheared = &result.records[3].pairs[0];
//! assert!(sheared.tangential_force <= 0.3 * sheared.normal_force * (1.0 + 1e-6));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The same model can be written as a TOML scenario and run with the `synovia` command
//! (crate `synovia-cli`; format and translation in the crate `synovia-scenario`, documented in
//! `docs/scenario.md`).
#![warn(missing_docs)]

pub use synovia_contact as contact_ops;
pub use synovia_fem as fem;
pub use synovia_feti as feti;
pub use synovia_io as io;
pub use synovia_linalg as linalg;
pub use synovia_material as material;
pub use synovia_mesh as mesh;
pub use synovia_nonlinear as nonlinear;
pub use synovia_pdas as pdas;
pub use synovia_time as time;
pub use synovia_uzawa as uzawa;

/// Static contact problems of a model (re-exported from `synovia-contact`).
pub mod contact {
    pub use synovia_contact::static_contact::*;
}
pub mod builder;
pub mod output;
pub mod rigid;
pub mod session;
pub mod solvers;
pub mod units;

/// The types most programs need.
pub mod prelude {
    pub use crate::builder::{Analysis, BodyMaterial, BodyRef, JointError, JointModel, RunResult, StepView};
    pub use crate::session::{JointSession, SolveReport};
    pub use synovia_contact::operators::{
        CylinderObstacle, FnObstacle, PairSplit, PlaneObstacle, SphereObstacle,
    };
    pub use synovia_contact::SurfaceObstacle;
    pub use synovia_contact::{ConstantFriction, ContactParams, ExponentialFriction, FrictionLaw};
    pub use synovia_fem::{
        solve_elastic, BodyFields, BodyId, ComponentMask, ElasticParams, ElasticSolution, ElasticSolver,
        FemError, Model,
    };
    pub use synovia_material::{
        anisotropic, isotropic, plane_strain, plane_stress, transversely_isotropic, KelvinVoigt,
        LinearElastic, Material, MaterialError, TransverseIsotropy,
    };
    pub use synovia_mesh::generators::{box_mesh, rectangle, Grading};
    pub use synovia_mesh::math::{Point, Real, Vector};
    pub use synovia_mesh::TriangleSurface;
    pub use synovia_mesh::{BoundaryKind, Mesh, MeshError};
    pub use synovia_time::history::{
        Constant, LoadHistory, Periodic, PiecewiseLinear, RigidMotion, SharedValue,
    };
    pub use synovia_time::results::StepRecord;
}
