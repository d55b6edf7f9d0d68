//! # synovia-contact
//!
//! Unilateral contact with Coulomb friction frozen to Tresca friction at each time level
//! (docs/model.md §3–§5): the discrete operators `B_hn` (normal, one row per contact node) and `B_Ht`
//! (tangential, per friction cell), the lumped weights `κ`, the gaps `d` and the slip bounds
//! `g_c`; the algebraic [`ContactProblem`] of docs/model.md §5
//!
//! ```text
//! A U + B_hnᵀ diag(κ) Λ_n + B_Htᵀ Λ_t − F = 0
//! Λ_n − (Λ_n + ρ (B_hn U − d))⁺          = 0
//! Λ_t − π(Λ_t + ρ B_Ht (U − U_prev))      = 0
//! ```
//!
//! Contact pairs are node-to-node (matching meshes), node-to-segment / node-to-facet or dual
//! mortar (non-matching meshes, with the R*-tree contact search of [`search`]; [`mortar`]) or
//! body-to-obstacle, each a [`ContactDiscretisation`] (one open trait, one file per kind in
//! [`discretisation`]; new kinds can be added from outside the crate);
//! the geometry can be rebuilt at every pose ([`operators::ContactGeometry::new_deformed`],
//! [`StaticContact::update_geometry`]).
//!
//! its condensation on the contact interface ([`Interface`], docs/model.md §6.4) on any
//! [`synovia_linalg::FactorisedOperator`], the caller-owned [`SolveContext`] (warm start,
//! kept columns, recycled solves, memory budget), the [`ContactSolver`] trait implemented by
//! `synovia-pdas` and `synovia-uzawa`, and the KKT checker [`check_kkt`].
#![warn(missing_docs)]

pub mod context;
pub mod discretisation;
pub mod error;
pub mod floating;
pub mod friction;
pub mod kkt;
pub mod mortar;
pub mod nested;
pub mod obstacle;
pub mod operators;
pub mod problem;
pub mod search;
pub mod solver;
pub mod static_contact;
pub mod surface_obstacle;
pub mod testing;
pub mod warm;

pub use context::SolveContext;
pub use discretisation::{ContactDiscretisation, ContactRow, PairContext};
pub use error::{ContactError, IterationResidual};
pub use friction::{
    project_on_disc, slip_speeds, ConstantFriction, ExponentialFriction, FrictionLaw, PairFrictionLaws,
};
pub use kkt::{check_kkt, check_kkt_at_border, KktReport};
pub use problem::{ContactProblem, FrictionConstraints, Interface, NormalConstraints, RigidBorder};
pub use solver::{ContactParams, ContactSolution, ContactSolver, SolverReport};
pub use static_contact::{CoordinateBorder, StaticContact, StaticContactResult};
pub use surface_obstacle::{SurfaceObstacle, SurfacePoint};
pub use synovia_linalg::SparseRows;
