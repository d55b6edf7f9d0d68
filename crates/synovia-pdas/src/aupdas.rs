//! The alternating Uzawa–PDAS method (AU-PDAS) of docs/model.md §6.2.

use std::time::Instant;

use synovia_contact::{
    ContactError, ContactParams, ContactProblem, ContactSolution, ContactSolver, IterationResidual,
    SolveContext, SolverReport,
};

use crate::sets::{finish, CellState, Sets, State};

/// Alternating Uzawa–PDAS (AU-PDAS) of docs/model.md §6.2 for the contact problem of docs/model.md §5:
/// a PDAS step on the normal part with the friction multiplier frozen, then a PDAS/Uzawa step
/// on the tangential part with the normal multiplier frozen.
///
/// Iteration `j` (from `(U^j, Λ_n^j, Λ_t^j)`, in the interface notation of the crate docs,
/// `ν = (κ Λ_n, Λ_t)`, `y = w − S ν = C U`):
///
/// 1. **STEP 1 (normal, `Λ_t = Λ_t^j` fixed).** Sets from `(U^j, Λ_n^j)`:
///    `𝒜_n = {r : ν_r^j + ρ_r (y_r^j − d_r) > 0}`, `ℐ_n` the rest. Solve
///    `A U + B_hnᵀ diag(κ) Λ_n = F − B_Htᵀ Λ_t^j` with `[U_n]_r = d_r` on `𝒜_n` and
///    `Λ_n,r = 0` on `ℐ_n`, i.e. `(S ν)_r = w_r − d_r` for `r ∈ 𝒜_n`. This gives
///    `Λ_n^{j+½}` and `U^{j+½}`.
/// 2. **STEP 2 (tangential, `Λ_n = Λ_n^{j+½}` fixed).** Sets from `(U^{j+½}, Λ_t^j)`:
///    `ζ_c = Λ_t,c^j + ρ_c (B_Ht U^{j+½} − s)_c`, stick `𝒜_t = {c : ‖ζ_c‖ < 1}`, slip `ℐ_t`.
///    Solve `A U + B_Htᵀ Λ_t = F − B_hnᵀ diag(κ) Λ_n^{j+½}` with `(B_Ht U)_c = s_c` on `𝒜_t`
///    and `Λ_t,c = π(ζ_c)` on `ℐ_t` (an Uzawa/projection update of the slip multipliers; in
///    2D it is `sign ζ_c`). This gives `Λ_t^{j+1}`, `U^{j+1}`, `Λ_n^{j+1} = Λ_n^{j+½}`.
/// 3. Stop when the sets computed from `(U^{j+1}, Λ^{j+1})` equal those used in steps 1–2 and
///    both relative NCP residuals (see [`IterationResidual`]) are at most `tolerance`.
///
/// Frictionless problems skip STEP 2, so AU-PDAS then coincides with [`Pdas`](crate::Pdas).
///
/// The STEP-2 sets use the slip-reversal safeguard of the crate docs (a cell that slipped in
/// the previous STEP 2 and now slips against `Λ_t,c^j` sticks), evaluated against the states
/// that produced `Λ_t^j`. Convergence is linear: with fixed sets the two steps are a block
/// Gauss–Seidel iteration between the normal and tangential rows, and in 3D
/// `Λ_t ← π(Λ_t + ρ (y − s))` is a projected-gradient (Uzawa) step on the slip directions,
/// which converges only for `ρ` below roughly `2/λ_max(S_tt)`. AU-PDAS is therefore
/// `ρ`-sensitive (unlike [`Pdas`](crate::Pdas)): the automatic `ρ` made it oscillate on 3D
/// problems (touching blocks, two-body shear), so the friction cells' `ρ_c` is bounded by the
/// step of a convergent projected-gradient step, `ρ_c ≤ 1.8/(λ̂ D_c)` (docs/model.md §6.2;
/// `λ̂ ≈ λ_max(D^{-½} S_tt D^{-½})` by the power method, `D_c` the cell mean of `diag S_tt`).
/// On badly conditioned `S_tt` (a floating body on its stabilised operator) convergence is then
/// slow and the solver may return [`ContactError::NoConvergence`].
///
/// [`SolverReport::inner_iterations`] counts the dense interface solves (two per iteration
/// with friction).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AuPdas {
    /// Tolerance, iteration limit and `ρ` scale.
    pub params: ContactParams,
}

impl AuPdas {
    /// An AU-PDAS solver with the given parameters.
    pub fn new(params: ContactParams) -> Self {
        Self { params }
    }
}

impl ContactSolver for AuPdas {
    fn name(&self) -> &str {
        "au-pdas"
    }

    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
    ) -> Result<ContactSolution, ContactError> {
        let start = Instant::now();
        let name = self.name();
        problem.refuse_border(name)?;
        let mut st = State::new(problem, context, &self.params)?;
        // a convergent step length for the projected-gradient update of the slipping cells
        st.bound_tangential_rho()?;
        let mut nu = st.initial_nu(problem, context.warm_start())?;
        let mut y = st.values(&nu)?;
        let mut sets =
            Sets { normal: st.classify_normal(&nu, &y, None), cells: st.classify_cells(&nu, &y, None) };
        // the tangential states that produced Λ_t^j (prev. states of the STEP-2 classification)
        let mut cells_used: Option<Vec<CellState>> = None;
        let mut history = Vec::new();
        let mut inner = 0;
        let tol = self.params.tolerance;
        for it in 1..=self.params.max_iterations {
            // STEP 1: normal PDAS step with Λ_t^j fixed.
            let mut fixed = nu.clone();
            let mut unknowns = Vec::new();
            st.normal_part(&sets.normal, &mut fixed, &mut unknowns);
            nu = st.solve_step(fixed, &unknowns, name, it)?;
            inner += 1;
            y = st.values(&nu)?;
            // STEP 2: tangential step with Λ_n^{j+½} fixed.
            let mut used = sets.clone();
            if st.n_cells > 0 {
                used.cells = st.classify_cells(&nu, &y, cells_used.as_deref());
                let zetas = st.zetas(&nu, &y);
                let mut fixed = nu.clone();
                let mut unknowns = Vec::new();
                st.tangential_part(&used.cells, &zetas, false, &mut fixed, &mut unknowns);
                nu = st.solve_step(fixed, &unknowns, name, it)?;
                inner += 1;
                y = st.values(&nu)?;
            }
            let new_sets = Sets {
                normal: st.classify_normal(&nu, &y, Some(&used.normal)),
                cells: st.classify_cells(&nu, &y, Some(&used.cells)),
            };
            let set_changes = new_sets.changes(&used);
            let (normal, tangential) = st.residual(&nu, &y);
            history.push(IterationResidual { iteration: it, normal, tangential, set_changes });
            sets = new_sets;
            cells_used = Some(used.cells);
            let converged = (set_changes == 0 && normal <= tol && tangential <= tol)
                || crate::sets::stalled_but_kkt_converged(&mut st, problem, &nu, &history, tol)?;
            if converged {
                let report = SolverReport {
                    solver: name.to_string(),
                    iterations: it,
                    inner_iterations: inner,
                    history,
                    ..Default::default()
                };
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
