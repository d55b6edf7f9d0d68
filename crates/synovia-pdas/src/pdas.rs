//! The primal–dual active set method (semismooth Newton) on the contact interface.

use std::time::Instant;

use synovia_contact::{
    ContactError, ContactParams, ContactProblem, ContactSolution, ContactSolver, IterationResidual,
    SolverReport,
};

use crate::sets::{finish, Sets, State};

/// Primal–dual active set method (PDAS) = semismooth Newton method for the contact problem of
/// spec §5 (frictionless or Tresca, 2D or 3D), condensed on the contact interface.
///
/// With the force multipliers `ν = (κ Λ_n, Λ_t)`, the interface values `y(ν) = w − S ν`
/// (`S = C A⁻¹ Cᵀ`, `w = C A⁻¹ F`, `C = [B_hn; B_Ht]`), the offsets `g = (d, s)` and the
/// complementarity parameters `ρ` (from [`ContactProblem::default_rho`] with
/// [`ContactParams::rho_scale`]), PDAS solves the nonsmooth system
///
/// ```text
/// ν_r − max(0, ν_r + ρ_r (y_r(ν) − d_r))         = 0     normal rows r
/// Λ_t,c − π(Λ_t,c + ρ_c (y_c(ν) − s_c))          = 0     friction cells c
/// ```
///
/// by Newton's method with the generalised (Clarke/slant) derivative of `max` and of the
/// projection `π`. Iteration `k` (from `(ν^k, y^k)`, `ζ_c = Λ_t,c^k + ρ_c (y_c^k − s_c)`):
///
/// 1. `𝒜_n = {r : ν_r^k + ρ_r (y_r^k − d_r) > 0}`, `ℐ_n` the rest;
///    stick `𝒜_t = {c : ‖ζ_c‖ < 1}`, slip `ℐ_t` the rest; a cell that slipped in the previous
///    iteration against its multiplier (`Λ_t,c^k · (y_c^k − s_c) < 0`) is put in `𝒜_t`
///    (slip-reversal safeguard, see the crate docs).
/// 2. Solve the linear equations for `ν^{k+1}`:
///    * `r ∈ 𝒜_n`: `(S ν)_r = w_r − d_r` (i.e. `[U_n] = d`); `r ∈ ℐ_n`: `ν_r = 0`;
///    * `c ∈ 𝒜_t`: `(S ν)_c = w_c − s_c` (i.e. `B_Ht U = s`);
///    * `c ∈ ℐ_t`, 2D: `ν_c = sign ζ_c`;
///    * `c ∈ ℐ_t`, 3D: the Newton linearisation of `Λ_t − ζ/‖ζ‖ = 0`,
///      `(I − P/‖ζ‖) ν_c − (ρ_c/‖ζ‖) P (y_c(ν) − s_c) = ζ/‖ζ‖`, `P = I − ζζᵀ/‖ζ‖²`.
///      Writing `n = ζ/‖ζ‖`, `t ⊥ n`, its `n`-component is `nᵀ ν_c = 1` and its `t`-component
///      is `tᵀ (S ν)_c + ((‖ζ‖ − 1)/ρ_c) tᵀ ν_c = tᵀ (w_c − s_c)`; hence `ν_c = n + β_c t`
///      with one unknown `β_c` per slipping cell, and the reduced system
///      `(Qᵀ S Q + D) x = Qᵀ (w − g − S ν_fixed)` (`D = diag((‖ζ_c‖ − 1)/ρ_c) ≥ 0`) is
///      symmetric positive definite. It is solved densely by Cholesky.
/// 3. `y^{k+1} = w − S ν^{k+1}` (only the columns of `S` of rows with `ν ≠ 0` are used,
///    each computed once by one solve with the factor of `A`).
/// 4. Stop when the sets computed from `(ν^{k+1}, y^{k+1})` equal those of step 1 and both
///    relative residuals (see [`IterationResidual`]) are at most `tolerance`.
///
/// A row whose switching quantity lies within `1e-12` (relative) of its threshold keeps its
/// state (weakly active rows, where both states solve the problem). Normal rows with an empty
/// `B_hn` row are always inactive (or [`ContactError::Infeasible`] when `d_r < 0`); friction
/// cells with empty `B_Ht` rows are fixed to `Λ_t = −s/‖s‖` (or `0`).
///
/// Initial guess: the multipliers of the warm start if given, else `ν = 0`. At the end
/// `U = A⁻¹ (F − Cᵀ ν)` (one solve).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Pdas {
    /// Tolerance, iteration limit and `ρ` scale.
    pub params: ContactParams,
}

impl Pdas {
    /// A PDAS solver with the given parameters.
    pub fn new(params: ContactParams) -> Self {
        Self { params }
    }
}

impl ContactSolver for Pdas {
    fn name(&self) -> &str {
        "pdas"
    }

    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        warm_start: Option<&ContactSolution>,
    ) -> Result<ContactSolution, ContactError> {
        let start = Instant::now();
        let name = self.name();
        let mut st = State::new(problem, &self.params)?;
        let mut nu = st.initial_nu(problem, warm_start)?;
        let mut y = st.values(&nu)?;
        let mut sets =
            Sets { normal: st.classify_normal(&nu, &y, None), cells: st.classify_cells(&nu, &y, None) };
        let mut history = Vec::new();
        let tol = self.params.tolerance;
        for it in 1..=self.params.max_iterations {
            let zetas = st.zetas(&nu, &y);
            let mut fixed = vec![0.0; nu.len()];
            let mut unknowns = Vec::new();
            st.normal_part(&sets.normal, &mut fixed, &mut unknowns);
            st.tangential_part(&sets.cells, &zetas, true, &mut fixed, &mut unknowns);
            nu = st.solve_step(fixed, &unknowns, name, it)?;
            y = st.values(&nu)?;
            let new_sets = Sets {
                normal: st.classify_normal(&nu, &y, Some(&sets.normal)),
                cells: st.classify_cells(&nu, &y, Some(&sets.cells)),
            };
            let set_changes = new_sets.changes(&sets);
            let (normal, tangential) = st.residual(&nu, &y);
            history.push(IterationResidual { iteration: it, normal, tangential, set_changes });
            sets = new_sets;
            if set_changes == 0 && normal <= tol && tangential <= tol {
                let report =
                    SolverReport { solver: name.to_string(), iterations: it, history, ..Default::default() };
                return finish(&mut st, problem, &nu, &sets, report, start);
            }
        }
        Err(ContactError::NoConvergence {
            solver: name.to_string(),
            iterations: self.params.max_iterations,
            history,
        })
    }
}
