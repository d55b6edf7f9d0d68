//! # synovia-uzawa
//!
//! Dual (interface) solvers of the Tresca contact problem of docs/model.md §5 (docs/model.md §6.3–§6.4), and the
//! quadratic programming algorithms they rest on.
//!
//! ## The dual problem
//!
//! With the force multipliers `ν = (ν_n, ν_t) = (κ Λ_n, Λ_t)` and `C = [B_hn; B_Ht]`, the
//! displacement is `U = A⁻¹ (F − Cᵀ ν)` and the interface values are `y = C U = w − S ν` with
//! the interface Schur complement `S = C A⁻¹ Cᵀ` and `w = C A⁻¹ F`. Eliminating `U` from the
//! Lagrangian of `min ½ Uᵀ A U − Fᵀ U + j(U)` s.t. `B_hn U ≤ d` gives the dual QP
//!
//! ```text
//! min_ν ½ νᵀ S ν − νᵀ (w − g)   s.t.  ν_n ≥ 0,  ‖ν_t,c‖ ≤ 1 per friction cell,  g = (d, s),
//! ```
//!
//! whose KKT conditions are exactly the complementarity conditions of docs/model.md §5 (the gradient is
//! `S ν − (w − g) = −(y − g)`).
//!
//! ## Algorithms
//!
//! * [`mprgp`] — Dostál's *modified proportioning with reduced gradient projections* for
//!   `min ½ xᵀHx − bᵀx` s.t. `l ≤ x ≤ u`: conjugate gradients on the free set, expansion steps
//!   with the fixed length `ᾱ ∈ (0, 2/‖H‖]` and projection, proportioning steps along the
//!   chopped gradient (Γ = 1), optional Jacobi preconditioning in face. Z. Dostál and
//!   J. Schöberl, *Minimizing quadratic functions subject to bound constraints with the rate
//!   of convergence and finite termination*, Comput. Optim. Appl. 30 (2005) 23–43;
//!   Z. Dostál, *Optimal Quadratic Programming Algorithms*, Springer 2009, Ch. 5.
//! * [`mpgp`] — *modified proportioning with gradient projections* for separable convex
//!   constraints `x ∈ Ω_1 × … × Ω_s` given block by block ([`ConvexBlock`]: intervals,
//!   half-lines, discs/balls), with projected-gradient proportioning steps. Z. Dostál and
//!   T. Kozubek, *An optimal algorithm and superrelaxation for minimization of a quadratic
//!   function subject to separable convex constraints with applications*, Math. Program.
//!   135 (2012) 195–220.
//! * [`UzawaMprgp`] (`"uzawa-mprgp"`, docs/model.md §6.3) — the outer Uzawa iteration
//!   `Λ_t ← π(Λ_t + ω D⁻¹ (y_t − s))` on the friction multiplier, the inner normal contact
//!   problem solved by MPRGP on its dual in `ν_n`.
//! * [`DualMprgp`] (`"dual-mprgp"`, docs/model.md §6.3, on the condensation of §6.4) — the whole dual QP above by MPRGP (2D:
//!   `ν_n ≥ 0`, `−1 ≤ ν_t ≤ 1`) or MPGP (3D: half-lines and unit discs).
//!
//! Both contact solvers evaluate `S` through [`SchurOperator`]: all columns once (one solve
//! with the factorisation of `A` per interface row) when the interface is moderate, matrix-free
//! (one solve per product) beyond [`SchurOperator::DENSE_LIMIT`] rows; and both scale the dual
//! variables by `diag S` (the Jacobi preconditioner, cell-wise constant on friction cells so that
//! discs stay discs).
//!
//! ## Example
//!
//! ```
//! use synovia_uzawa::{mprgp, QpOptions};
//!
//! // min ½ xᵀ H x − bᵀ x, H = [[2, 1], [1, 2]], b = (−1, 3), x ≥ 0  →  x = (0, 3/2)
//! let mut h = |x: &[f64], y: &mut [f64]| {
//!     y[0] = 2.0 * x[0] + x[1];
//!     y[1] = x[0] + 2.0 * x[1];
//! };
//! let mut x = vec![1.0, 1.0];
//! let inf = f64::INFINITY;
//! let report = mprgp(&mut h, &[-1.0, 3.0], &[0.0, 0.0], &[inf, inf], &mut x, &QpOptions::default())?;
//! assert!(report.converged && x[0] == 0.0 && (x[1] - 1.5).abs() < 1e-12);
//! # Ok::<(), synovia_contact::ContactError>(())
//! ```
#![warn(missing_docs)]

mod common;
pub mod dual;
pub mod qp;
pub mod schur;
pub mod uzawa;

pub use dual::DualMprgp;
pub use qp::{
    estimate_norm, mpgp, mprgp, qp_until, ConvexBlock, DenseHessian, Expansion, Hessian, QpOptions, QpReport,
    StopTest,
};
pub use schur::SchurOperator;
pub use uzawa::UzawaMprgp;
