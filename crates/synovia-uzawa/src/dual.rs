//! [`DualMprgp`]: the whole dual QP of the Tresca problem on the interface Schur complement
//! (docs/model.md §6.3–§6.4).

use std::time::Instant;

use synovia_contact::{
    ContactError, ContactParams, ContactProblem, ContactSolution, ContactSolver, IterationResidual,
    SolveContext, SolverReport,
};

use crate::common::{
    check_params, initial_multipliers, jacobi_scales, normal_bounds, residuals, solution, Residuals,
};
use crate::qp::{solve_qp, ConvexBlock, QpOptions, QpState};
use crate::schur::{ScaledBlock, SchurOperator};

/// Solves the Tresca (or frictionless) contact problem through its dual in the force
/// multipliers `ν = (κ Λ_n, Λ_t)` on the interface (docs/model.md §6.3, with `S` and `w` of §6.4):
///
/// ```text
/// min_ν ½ νᵀ S ν − νᵀ (w − g)   s.t.  ν_n ≥ 0,  ‖ν_t,c‖ ≤ 1 per friction cell,
/// S = C A⁻¹ Cᵀ,  w = C A⁻¹ F,  g = (d, s),  C = [B_hn; B_Ht],
/// ```
///
/// whose gradient is `S ν − (w − g) = −(y − g)` with `y = C U`, `U = A⁻¹ (F − Cᵀ ν)`. The
/// variables are Jacobi-scaled, `x = D^{½} ν` with `D = diag S` (averaged over the components
/// of a 3D friction cell, so discs stay discs of radius `√D_c`), and the scaled QP is solved by
/// [`mprgp`](crate::mprgp) with the bounds `x_n ≥ 0`, `|x_t| ≤ √D_t` in 2D (and frictionless
/// problems), and by [`mpgp`](crate::mpgp) with half-lines and discs in 3D. `S` is assembled
/// densely (one solve per interface row, once) up to [`SchurOperator::DENSE_LIMIT`] rows and
/// applied matrix-free (one solve per product) beyond.
///
/// The iteration stops when both the QP test `‖g^P‖ ≤ ε ‖b‖` (in the scaled variables) and the
/// residuals of docs/model.md §5, `‖Λ_n − (Λ_n + ρ(B_hn U − d))⁺‖_∞ / max Λ_n` and
/// `‖Λ_t − π(Λ_t + ρ (B_Ht U − s))‖_∞` (`ρ` from [`ContactProblem::default_rho`]), are at most
/// `ε = params.tolerance`; `params.max_iterations` bounds the QP iterations (CG, expansion and
/// proportioning steps), the history records the residuals of docs/model.md §5 after each of them, and
/// `report.inner_iterations` counts the products with `S`. Name: `"dual-mprgp"`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DualMprgp {
    /// Tolerance, iteration limit (QP iterations), and the scale of `ρ` used in the reported
    /// residuals.
    pub params: ContactParams,
}

impl DualMprgp {
    /// The solver with the given parameters.
    pub fn new(params: ContactParams) -> Self {
        Self { params }
    }
}

impl ContactSolver for DualMprgp {
    fn name(&self) -> &str {
        "dual-mprgp"
    }

    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
    ) -> Result<ContactSolution, ContactError> {
        let t0 = Instant::now();
        check_params(&self.params)?;
        problem.refuse_border(self.name())?;
        let mut op = SchurOperator::new(*problem, context)?;
        let (mn, m, c) = (problem.n_normal(), problem.n_rows(), problem.components());
        let nu0 = initial_multipliers(problem, context.warm_start())?;
        let rho = problem.default_rho(self.params.rho_scale);
        let offsets = problem.offsets();
        let diag = op.diagonal();
        let scales = jacobi_scales(problem, &diag);
        let sq: Vec<f64> = scales.iter().map(|d| d.sqrt()).collect();
        let isq: Vec<f64> = sq.iter().map(|s| 1.0 / s).collect();

        let b: Vec<f64> = op.w().iter().zip(&offsets).zip(&isq).map(|((w, g), s)| (w - g) * s).collect();
        let mut x: Vec<f64> = nu0.iter().zip(&sq).map(|(v, s)| v * s).collect();
        let mut blocks = normal_bounds(problem, &diag, op.w())?;
        for start in (mn..m).step_by(c) {
            if c == 1 {
                blocks.push(ConvexBlock::Interval { lower: -sq[start], upper: sq[start] });
            } else {
                blocks.push(ConvexBlock::Ball { dim: c, radius: sq[start] });
            }
        }
        let options = QpOptions {
            tolerance: self.params.tolerance,
            max_iterations: self.params.max_iterations,
            precondition: false,
            ..QpOptions::default()
        };

        // docs/model.md §5 residuals after every QP iteration, from the gradient: y − g = −D^{½} ĝ
        let mut history: Vec<IterationResidual> = Vec::new();
        let mut last = Residuals::default();
        let mut nu = vec![0.0; m];
        let mut ymg = vec![0.0; m];
        let tol = self.params.tolerance;
        let mut monitor = |s: &QpState<'_>| {
            for k in 0..m {
                nu[k] = s.x[k] * isq[k];
                ymg[k] = -s.g[k] * sq[k];
            }
            let r = residuals(problem, &rho, &nu, &ymg);
            let ok = r.normal <= tol && r.tangential <= tol;
            if s.iteration > 0 {
                history.push(IterationResidual {
                    iteration: s.iteration,
                    normal: r.normal,
                    tangential: r.tangential,
                    set_changes: r.changes(&last),
                });
            }
            last = r;
            ok
        };
        let (qrep, _) = {
            let mut h = ScaledBlock::new(&mut op, 0..m, &isq);
            solve_qp(&mut h, &b, &blocks, &mut x, &options, c == 1, Some(&mut monitor))?
        };
        if !qrep.converged {
            return Err(ContactError::NoConvergence {
                solver: self.name().to_string(),
                iterations: qrep.iterations,
                history,
            });
        }
        let nu: Vec<f64> = x.iter().zip(&isq).map(|(a, s)| a * s).collect();
        let mut y = vec![0.0; m];
        op.apply(&nu, &mut y)?;
        let ymg: Vec<f64> = op.w().iter().zip(&y).zip(&offsets).map(|((w, sv), g)| w - sv - g).collect();
        let res = residuals(problem, &rho, &nu, &ymg);
        let report = SolverReport {
            solver: self.name().to_string(),
            iterations: qrep.iterations,
            inner_iterations: qrep.hessian_products,
            history,
            time_s: 0.0,
            ..SolverReport::default()
        };
        let mut sol = solution(&mut op, &nu, &res, report)?;
        sol.report.time_s = t0.elapsed().as_secs_f64();
        Ok(sol)
    }
}
