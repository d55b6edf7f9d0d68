//! # synovia-linalg
//!
//! The linear algebra of synovia, behind one seam: the contact solvers are written against
//! the [`FactorisedOperator`] trait (a factorised symmetric positive definite `A`: products,
//! solves with one or many right-hand sides, solves supported on the interface dofs, and
//! columns of the interface Schur complement `S = C A⁻¹ Cᵀ`, docs/model.md §6.4), not against
//! a particular factorisation.
//!
//! The first implementation is faer's sparse Cholesky:
//! - [`SymmetricMatrix`]: the lower triangle of a sparse symmetric matrix in CSC, filled in
//!   place on a fixed pattern;
//! - [`CholeskySolver`]: symbolic analysis once, numeric factorisation repeatable, with the
//!   fill-reducing [`Ordering`]s (AMD, METIS nested dissection, custom, and
//!   [`Ordering::Trailing`], which orders given dofs last and keeps the dense block `L₂₂` of
//!   the factor that belongs to them);
//! - [`CholeskyOperator`]: the two as a [`FactorisedOperator`], whose interface columns come
//!   from `L₂₂` (`(A⁻¹)_cc = L₂₂⁻ᵀ L₂₂⁻¹`) and whose interface-supported solves are half solves;
//! - [`InterfaceBlockParams`]: which interface dofs a contact problem orders last;
//! - [`LoadSubspace`]: recycled solves `A⁻¹ F` for loads in the span of loads solved before;
//! - [`SparseRows`], [`RowStack`]: the constraint rows `C` acting on the unknowns.
//!
//! To add a back-end (another direct solver, an iterative solver, a domain decomposition),
//! implement [`FactorisedOperator`] for it; see `docs/architecture.md`.
#![warn(missing_docs)]

pub mod cholesky;
pub mod error;
pub mod interface;
pub mod operator;
pub mod recycling;
pub mod rows;
pub mod sparse;

pub use cholesky::{
    available_memory, memory_limit, metis_lock, CholeskyInfo, CholeskySolver, InterfaceBlockParams,
    MemoryEstimate, Ordering, TrailingBlock, MEMORY_LIMIT_ENV,
};
pub use error::LinalgError;
pub use interface::BlockSolveStore;
pub use operator::{CholeskyOperator, FactorisedOperator, RowStack, SparseCholesky};
pub use recycling::LoadSubspace;
pub use rows::SparseRows;
pub use sparse::SymmetricMatrix;
