//! # synovia-fem
//!
//! P1 finite elements for multi-body linear elasticity (docs/model.md §1–§2, §4–§5): element kernels,
//! constraints, assembly into a fixed sparse pattern, and the sparse Cholesky solve.
//!
//! The bilinear form is `a(u, v) = Σ_ι ∫_{Ω^ι} C e(u) : e(v) dx` and the load
//! `(f, v) = ∫ F · v dx + ∫_{¹Γ_τ} P · v ds`. The unknowns are reduced by the constraints of the
//! boundary parts (Dirichlet `u = u₂(t)`, clamped, symmetry `u · n = 0` along any normal) and by
//! bonded interfaces, `u = u_p(t) + P ũ` ([`dofs`]), so the system `K̃ ũ = F̃` stays symmetric
//! positive definite and is factorised once by [`CholeskySolver`] (faer, AMD or METIS ordering;
//! crate `synovia-linalg`) and reused for every load case.
//!
//! Data path: [`Model`] (bodies, materials, boundary data) → [`DofMap`] (reduced unknowns,
//! coercivity check) → [`assembly::pattern`] (fixed pattern) → [`assembly::assemble_matrix`]
//! → [`CholeskySolver`] → [`ElasticSolution`] → [`post::body_fields`].
#![warn(missing_docs)]

pub mod assembly;
pub mod dofs;
pub mod elastic;
pub mod element;
pub mod error;
pub mod linear_bodies;
pub mod model;
pub mod nonlinear;
pub mod post;
pub mod quadrature;

pub use dofs::{DofMap, FloatingComponent};
pub use elastic::{
    solve_elastic, ElasticEstimate, ElasticInfo, ElasticParams, ElasticSolution, ElasticSolver,
    OrderingChoice, Reorder, Stabilisation,
};
pub use error::FemError;
pub use model::{Body, BodyId, ComponentMask, Model, TractionField, VectorField};
pub use nonlinear::Kinematics;
pub use post::BodyFields;
pub use quadrature::QuadratureRule;
/// The linear algebra the elastic solve uses (re-exported from `synovia-linalg`).
pub use synovia_linalg::{CholeskyInfo, CholeskySolver, LinalgError, Ordering, SymmetricMatrix};
