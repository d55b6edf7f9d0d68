//! # synovia-pdas
//!
//! Primal–dual active set solvers (docs/model.md §6.1–§6.2) for the contact problem of docs/model.md §5,
//! frictionless or with Tresca friction, in 2D and 3D:
//!
//! * [`Pdas`] — the primal–dual active set method, i.e. a semismooth Newton method applied
//!   to the complementarity (NCP) formulation (Hintermüller, Ito & Kunisch, *SIAM J. Optim.*
//!   13 (2003); Hüeber & Wohlmuth, *CMAME* 194 (2005)); in 3D the slip condition on the disc is
//!   linearised as in Hüeber, Stadler & Wohlmuth, *SIAM J. Sci. Comput.* 30 (2008);
//! * [`AuPdas`] — the alternating Uzawa–PDAS of docs/model.md §6.2 (normal PDAS step with the friction
//!   multiplier frozen, then tangential step with the pressure frozen).
//!
//! Both implement [`synovia_contact::ContactSolver`].
//!
//! ## The problem
//!
//! ```text
//! A U + B_hnᵀ diag(κ) Λ_n + B_Htᵀ Λ_t − F = 0
//! Λ_n − (Λ_n + ρ (B_hn U − d))⁺          = 0
//! Λ_t − π(Λ_t + ρ (B_Ht U − s))           = 0
//! ```
//!
//! with `(·)⁺ = max(·, 0)` and `π` the projection onto `[−1, 1]` (2D) or the unit disc (3D).
//! Both solvers work on the contact interface (docs/model.md §6.4): with the force multipliers
//! `ν = (κ Λ_n, Λ_t)` and `C = [B_hn; B_Ht]`,
//!
//! ```text
//! U = A⁻¹ (F − Cᵀ ν),     y := C U = w − S ν,     w = C A⁻¹ F,     S = C A⁻¹ Cᵀ,
//! ```
//!
//! and the NCPs read, per normal row `r` and friction cell `c` (rows `R_c`, one in 2D and two
//! in 3D),
//!
//! ```text
//! ν_r − max(0, ν_r + ρ_r (y_r − d_r)) = 0,        Λ_t,c − π(ζ_c) = 0,   ζ_c = Λ_t,c + ρ_c (y_c − s_c).
//! ```
//!
//! `ρ` comes from [`synovia_contact::ContactProblem::default_rho`] scaled by
//! [`ContactParams::rho_scale`]; the rows of a friction cell share one `ρ_c` (the mean of
//! their automatic values), because the disc projection needs an isotropic parameter. The
//! solution does not depend on `ρ`, only the iteration path does. `S` is never formed: its
//! columns are computed lazily, one solve with the factorisation of `A` each, and only for
//! rows that become active, sticking or slipping.
//!
//! ## The algorithm (PDAS)
//!
//! 1. Initialise `ν⁰` (warm start `(κ Λ_n, Λ_t)` or `0`) and `y⁰ = w − S ν⁰`; set `k = 0`.
//! 2. Active sets from `(ν^k, y^k)`:
//!    `𝒜_n = {r : ν_r + ρ_r (y_r − d_r) > 0}` (contact), `ℐ_n` the rest;
//!    stick `𝒜_t = {c : ‖ζ_c‖ < 1}`, slip `ℐ_t` the rest (with the slip-reversal safeguard
//!    below).
//! 3. Solve the linear interface system fixed by the sets:
//!    `(S ν)_r = w_r − d_r` on `𝒜_n`, `ν_r = 0` on `ℐ_n`, `(S ν)_c = w_c − s_c` on `𝒜_t`,
//!    `ν_c = sign ζ_c` on `ℐ_t` (2D), and in 3D on `ℐ_t` the semismooth Newton linearisation
//!    `(I − P/‖ζ_c‖) ν_c − (ρ_c/‖ζ_c‖) P (y_c(ν) − s_c) = ζ_c/‖ζ_c‖`,
//!    `P = I − ζ_c ζ_cᵀ/‖ζ_c‖²`. The fixed entries are eliminated; the remaining dense
//!    symmetric positive definite system (see [`Pdas`]) is solved by Cholesky.
//! 4. `y^{k+1} = w − S ν^{k+1}`; compute the residuals and the new sets.
//! 5. If the sets did not change and both relative residuals are `≤ tolerance`, stop. If the
//!    sets did not change in the last two iterations and the residual made no progress (it is
//!    at the rounding level of `y = w − S ν`, `≈ ε κ(A) ‖w‖`, which grows with the stiffness
//!    ratio of the bodies: `2e-10` for two stacked blocks with `E₁/E₂ = 1e5`), stop if every
//!    relative residual of [`synovia_contact::check_kkt`] at `U = A⁻¹ (F − Cᵀ ν)` is
//!    `≤ tolerance` (scale-aware: the same problem in other units stops at the same
//!    iteration). Otherwise `k ← k + 1` and go to 3 with the new sets.
//! 6. `U = A⁻¹ (F − Cᵀ ν)`, `Λ_n = ν_n / κ`, `Λ_t = ν_t`.
//!
//! ### The 3D slip linearisation
//!
//! Hüeber–Stadler–Wohlmuth (2008) write the slip condition as `max(1, ‖ζ‖) Λ_t − ζ = 0` and
//! linearise it; its Newton matrix contains `Λ_t^k ζᵀ/‖ζ‖`, which they replace by
//! `v^k ζᵀ/‖ζ‖` with `v^k = Λ_t^k / max(1, ‖Λ_t^k‖)` to keep the iteration stable. The
//! linearisation used here is that of the normalised form `Λ_t − ζ/‖ζ‖ = 0`, which equals the
//! HSW step with `v^k = ζ^k/‖ζ^k‖` (the other unit vector available). It fixes the component
//! of `Λ_t,c` along `ζ_c` to `1` and leaves the orthogonal component `β_c` as an unknown with
//! the equation `tᵀ y_c − tᵀ s_c = ((‖ζ_c‖ − 1)/ρ_c) β_c` — a stick condition regularised
//! by a non-negative compliance — so the interface system remains symmetric positive definite
//! and no damping was needed in the tests. At convergence `β_c → 0` and `‖Λ_t,c‖ → 1`.
//!
//! ### Slip-reversal safeguard
//!
//! For a bilateral bound (`|Λ_t| ≤ 1`) the set rule depends on `ρ`: a slipping cell with
//! `Λ_t,c = σ` whose computed slip points the other way, `σ (y_c − s_c) < 0`, gets
//! `ζ_c = σ + ρ_c (y_c − s_c)`, which for `ρ_c |y_c − s_c| > 2` lands in the *opposite* slip
//! set instead of the stick set. With the automatic `ρ` (for which `ρ_r S_rr ≳ 1`) plain PDAS
//! then cycles `slip+ ↔ slip−` for ever on cells that should stick (observed on
//! `BlockOnFoundation` in 2D and 3D for every `rho_scale ≥ 1`). Both solvers therefore move a
//! previously slipping cell with `Λ_t,c · (y_c − s_c) < 0` to the stick set. In 2D this is
//! exactly the set rule evaluated for that cell with a smaller `ρ_c` (`ρ_c → 0⁺`), i.e. still a
//! semismooth Newton step of an equivalent NCP, and it makes the friction sets independent of
//! `ρ` after the first iteration. It does not change the fixed points: at a solution slip is
//! along `Λ_t`.
//!
//! ### Convergence observed (tests of this crate, `BlockOnFoundation`)
//!
//! PDAS: frictionless 2D 1–4 iterations for `n = 8 … 64`, 3D 2; Tresca 2D 4, Tresca 3D 7
//! (superlinear at the end: tangential residual `8e-2 → 6e-4 → 2e-7 → 8e-14`). Its iterates
//! do not depend on `ρ` in the frictionless case. AU-PDAS converges linearly (with fixed sets
//! it is a block Gauss–Seidel iteration between the normal and tangential rows, and in 3D
//! the slip direction is updated by a projected-gradient step): Tresca 2D 11 iterations,
//! Tresca 3D 50 iterations with `rho_scale = 0.2`; it needs a moderate `ρ` (in 3D it cycles on
//! the test problem for `rho_scale ≥ 0.5`, in 2D for `rho_scale ≥ 10`).
//!
//! ## Errors
//!
//! [`ContactError::InvalidParameter`] for bad parameters, sizes or warm starts;
//! [`ContactError::Infeasible`] for a normal row with an empty `B_hn` row and `d_r < 0`;
//! [`ContactError::Singular`] when the dense interface system is singular (e.g. linearly
//! dependent active constraints); [`ContactError::NoConvergence`] with the residual history
//! after `max_iterations`.
//!
//! ## Failure modes
//!
//! Plain PDAS (Newton-min) can cycle: on interface problems whose `S` is not an M-matrix, and
//! rarely on 2D Tresca problems despite the slip-reversal safeguard (≈ 1 random case in
//! 20 000 of the property tests). [`Pdas::solve_traced`] detects recurring active-set
//! configurations without residual decrease (cycling, window [`CYCLE_WINDOW`]) and stagnation,
//! reports them in [`SolverReport::cycling_detected`]/[`SolverReport::stagnation_detected`]
//! and returns the last iterate, so that a caller can hand over to a dual solver (the
//! `pdas-fallback` solver of the `synovia` facade; `docs/reliability.md`).
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod aupdas;
mod pdas;
mod sets;

pub use aupdas::AuPdas;
pub use pdas::{Pdas, PdasStep, PdasTrace, CYCLE_WINDOW};
pub use synovia_contact::{ContactError, ContactParams, ContactSolution, ContactSolver, SolverReport};
