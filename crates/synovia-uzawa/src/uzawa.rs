//! [`UzawaMprgp`]: outer Uzawa iteration on the friction multiplier, inner MPRGP on the dual
//! of the normal contact problem (docs/model.md §6.3).

use std::time::Instant;

use synovia_contact::{
    ContactError, ContactParams, ContactProblem, ContactSolution, ContactSolver, IterationResidual,
    SolveContext, SolverReport,
};

use crate::common::{
    check_params, initial_multipliers, jacobi_scales, normal_bounds, project_unit, residuals, solution,
    Residuals,
};
use crate::qp::{estimate_norm, solve_qp, QpOptions};
use crate::schur::{ScaledBlock, SchurOperator};

/// Factor by which the normal residual must drop between outer iterations to count as still
/// converging; a residual that does not is measured by `check_kkt` (see [`UzawaMprgp`]).
const STALL_FACTOR: f64 = 0.99;

/// Uzawa's method with MPRGP inner solves (docs/model.md §6.3), in the force multipliers
/// `ν = (ν_n, Λ_t) = (κ Λ_n, Λ_t)` on the interface (`S`, `w`, `g = (d, s)` as in
/// [`DualMprgp`](crate::DualMprgp)).
///
/// **Inner problem.** For a fixed friction multiplier `Λ_t` (below: the point `Λ̂_t^k`), the
/// normal contact problem with the load `F − B_Htᵀ Λ_t` is solved through its dual
///
/// ```text
/// min_{ν_n ≥ 0} ½ ν_nᵀ S_nn ν_n − ν_nᵀ (w_n − S_nt Λ_t − d)
/// ```
///
/// by [`mprgp`](crate::mprgp) (Jacobi-scaled, warm-started from the previous outer
/// iteration; relative tolerance `inner_tolerance`, at most `max_inner` iterations), giving
/// `ν_n(Λ_t)` and the tangential interface values `y_t = w_t − S_tn ν_n − S_tt Λ_t`.
///
/// **Outer (Uzawa) step.**
///
/// ```text
/// Λ_t,c^{k+1} = π(Λ̂_t,c^k + ω D_c⁻¹ (y_t,c(Λ̂^k) − s_c))      per friction cell c,
/// ```
///
/// `π` the projection onto `[−1, 1]` (2D) or the unit disc (3D), `D_c` the mean of
/// `diag S_tt` over the cell. With `Λ̂^k = Λ^k` this is the classical Uzawa iteration, i.e. the
/// projected gradient method for the concave dual function
/// `θ(Λ_t) = min_{B_hn U ≤ d} ½ UᵀAU − FᵀU + Λ_tᵀ (B_Ht U − s)`, whose gradient `y_t − s` is Lipschitz with
/// constant `λ_max(S_tt)` (the marginal Hessians `S_tt − S_tA S_AA⁻¹ S_At` are bounded by
/// `S_tt`). In the metric `D` (constant per cell, so `π` is still the Euclidean projection per
/// cell) it converges for `0 < ω < 2 / λ_max(D^{-½} S_tt D^{-½})`. We take `ω = 1/λ̂` with `λ̂`
/// 1.05 × the power-method estimate of `λ_max(D^{-½} S_tt D^{-½})` (a lower bound converging
/// from below): the step `1/L` of the accelerated method below, with a wide margin to the limit
/// `2/L` of the plain one. The Jacobi metric equalises the very different row scales (`B_Ht`
/// carries `g_c κ`).
///
/// **Acceleration (deviation from the plain Uzawa step).** The plain iteration needs about
/// `κ · ln(1/ε)` outer iterations, `κ` the condition number of the reduced `S_tt` on the sticking
/// cells (≈ 1800 iterations for the 2D block test problem at `ε = 10⁻¹⁰`). The step is
/// therefore taken from the extrapolated point `Λ̂^k = π(Λ^k + θ_k (Λ^k − Λ^{k−1}))`
/// (FISTA, Beck & Teboulle 2009: `t_{k+1} = (1 + √(1 + 4 t_k²))/2`, `θ_k = (t_k − 1)/t_{k+1}`),
/// with the gradient-based adaptive restart of O'Donoghue & Candès 2015 (`t ← 1` when
/// `(Λ̂^k − Λ^{k+1})ᵀ D (Λ^{k+1} − Λ^k) > 0`), which brings the count to about `√κ · ln(1/ε)`
/// (≈ 250–340 in the same test). The extrapolated point is projected so that every inner solve
/// sees an admissible friction multiplier, and the returned solution is the consistent pair
/// `(ν_n(Λ̂^k), Λ̂^k)`.
///
/// Frictionless problems take one outer iteration. The iteration stops when
/// `‖Λ_t^{k+1} − Λ̂_t^k‖_∞`, the normal residual `‖Λ_n − (Λ_n + ρ(B_hn U − d))⁺‖_∞ / max Λ_n`
/// and the tangential residual `‖Λ_t − π(Λ_t + ρ (B_Ht U − s))‖_∞` (`ρ` from
/// [`ContactProblem::default_rho`]) are all at most `params.tolerance`; if the inner solves are
/// not accurate enough for that, their tolerance is tightened (by 10⁻², down to 10⁻¹⁵). If the
/// normal residual, computed from `y = w − S ν`, stalls above the tolerance at its rounding
/// level `ε κ(A) ‖w‖` (stiffness ratios ≥ 1e5, floating bodies on the stabilised `A + S`) while
/// the friction step and residual are converged, the iterate is accepted when every relative
/// residual of `synovia_contact::check_kkt` is at most the tolerance (the scale-aware test of
/// `synovia_pdas`, docs/reliability.md).
/// `params.max_iterations` bounds the outer iterations — tight tolerances need a few hundred
/// (the default of [`UzawaMprgp::default`] is 2000; that of [`ContactParams`] is 200). A
/// normal row acting on no free unknown is fixed at `ν_n = 0`, or reported as
/// [`ContactError::Infeasible`] if its gap is violated. Name: `"uzawa-mprgp"`;
/// `report.inner_iterations` counts the MPRGP iterations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UzawaMprgp {
    /// Tolerance, outer iteration limit, scale of `ρ` in the residuals (default: those of
    /// [`ContactParams`] with `max_iterations = 2000`).
    pub params: ContactParams,
    /// Relative tolerance `‖g^P‖ ≤ ε ‖b‖` of the inner MPRGP solves (default `1e-12`).
    pub inner_tolerance: f64,
    /// Iteration limit of each inner MPRGP solve (default `2000`).
    pub max_inner: usize,
}

impl Default for UzawaMprgp {
    fn default() -> Self {
        Self {
            params: ContactParams::default().with_max_iterations(2000),
            inner_tolerance: 1e-12,
            max_inner: 2000,
        }
    }
}

impl UzawaMprgp {
    /// The solver with the given outer parameters and the default inner ones
    /// (`inner_tolerance = 1e-12`, `max_inner = 2000`).
    pub fn new(params: ContactParams) -> Self {
        Self { params, ..Self::default() }
    }
}

impl ContactSolver for UzawaMprgp {
    fn name(&self) -> &str {
        "uzawa-mprgp"
    }

    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
    ) -> Result<ContactSolution, ContactError> {
        let t0 = Instant::now();
        check_params(&self.params)?;
        problem.refuse_border(self.name())?;
        if !(self.inner_tolerance.is_finite() && self.inner_tolerance > 0.0) || self.max_inner == 0 {
            return Err(ContactError::InvalidParameter(format!(
                "inner tolerance {} must be positive and max_inner {} at least 1",
                self.inner_tolerance, self.max_inner
            )));
        }
        let mut op = SchurOperator::new(*problem, context)?;
        let (mn, m, c) = (problem.n_normal(), problem.n_rows(), problem.components());
        let mut nu = initial_multipliers(problem, context.warm_start())?;
        let rho = problem.default_rho(self.params.rho_scale);
        let offsets = problem.offsets();
        let diag = op.diagonal();
        let scales = jacobi_scales(problem, &diag);
        let sq: Vec<f64> = scales.iter().map(|d| d.sqrt()).collect();
        let isq: Vec<f64> = sq.iter().map(|s| 1.0 / s).collect();
        let w = op.w().to_vec();
        let bounds = normal_bounds(problem, &diag, &w)?;

        // ‖D_n^{-½} S_nn D_n^{-½}‖ once for all inner solves, and the Uzawa step ω
        let hn = {
            let mut h = ScaledBlock::new(&mut op, 0..mn, &isq[..mn]);
            let (l, _) = estimate_norm(&mut h, mn, 20)?;
            1.05 * l
        };
        let omega = if m > mn {
            let mut h = ScaledBlock::new(&mut op, mn..m, &isq[mn..]);
            let (l, _) = estimate_norm(&mut h, m - mn, 30)?;
            if l > 0.0 {
                1.0 / (1.05 * l)
            } else {
                1.0
            }
        } else {
            0.0
        };
        let inner = QpOptions {
            tolerance: self.inner_tolerance,
            max_iterations: self.max_inner,
            hessian_norm: (hn > 0.0).then_some(hn),
            precondition: false,
            ..QpOptions::default()
        };

        let mut history: Vec<IterationResidual> = Vec::new();
        let mut last = Residuals::default();
        let mut inner = inner;
        let mut inner_iterations = 0;
        let mt = m - mn;
        let mut snt = vec![0.0; mn];
        let mut b = vec![0.0; mn];
        let mut x = vec![0.0; mn];
        let mut y = vec![0.0; m];
        let mut ymg = vec![0.0; m];
        // Λ^k (current), Λ^{k−1}, the new iterate, and the FISTA momentum t_k
        let mut lam: Vec<f64> = nu[mn..].to_vec();
        let mut lam_prev = lam.clone();
        let mut lam_new = vec![0.0; mt];
        let mut t = 1.0_f64;
        let tol = self.params.tolerance;
        let mut done = 0;
        for k in 1..=self.params.max_iterations {
            // extrapolated point Λ̂ = π(Λ^k + θ_k (Λ^k − Λ^{k−1}))
            let t_next = 0.5 * (1.0 + (1.0 + 4.0 * t * t).sqrt());
            let theta = (t - 1.0) / t_next;
            for q in 0..mt {
                nu[mn + q] = lam[q] + theta * (lam[q] - lam_prev[q]);
            }
            for cell in nu[mn..].chunks_mut(c) {
                project_unit(cell);
            }
            // inner: normal contact with the load F − B_tᵀ Λ̂
            op.apply_block(0..mn, mn..m, &nu[mn..], &mut snt)?;
            for i in 0..mn {
                b[i] = (w[i] - offsets[i] - snt[i]) * isq[i];
                x[i] = nu[i] * sq[i];
            }
            let (qrep, _) = {
                let mut h = ScaledBlock::new(&mut op, 0..mn, &isq[..mn]);
                solve_qp(&mut h, &b, &bounds, &mut x, &inner, true, None)?
            };
            inner_iterations += qrep.iterations;
            for i in 0..mn {
                nu[i] = x[i] * isq[i];
            }
            // interface values y = w − S ν and the residuals of docs/model.md §5 at (ν_n, Λ̂)
            op.apply(&nu, &mut y)?;
            for i in 0..m {
                ymg[i] = w[i] - y[i] - offsets[i];
            }
            let res = residuals(problem, &rho, &nu, &ymg);
            // Uzawa step from Λ̂: Λ^{k+1} = π(Λ̂ + ω D⁻¹ (y_t − s))
            let mut delta = 0.0_f64;
            let mut restart = 0.0;
            for (ci, start) in (mn..m).step_by(c).enumerate() {
                let l0 = ci * c;
                for q in 0..c {
                    lam_new[l0 + q] = nu[start + q] + omega / scales[start] * ymg[start + q];
                }
                project_unit(&mut lam_new[l0..l0 + c]);
                for q in 0..c {
                    let step = lam_new[l0 + q] - nu[start + q];
                    delta = delta.max(step.abs());
                    restart += scales[start] * (-step) * (lam_new[l0 + q] - lam[l0 + q]);
                }
            }
            history.push(IterationResidual {
                iteration: k,
                normal: res.normal.max(if qrep.converged { 0.0 } else { qrep.relative_residual }),
                tangential: res.tangential.max(delta),
                set_changes: res.changes(&last),
            });
            let inner_ok = qrep.converged && res.normal <= tol;
            // scale-aware test (as in synovia_pdas): the normal residual, computed from
            // y = w − S ν, stalls at the rounding level ε κ(A) ‖w‖ above the tolerance on
            // ill-conditioned problems (stiffness ratios ≥ 1e5, floating bodies); the iterate
            // is then measured by check_kkt, relative to the force and displacement scales
            let stalled = qrep.converged
                && res.normal > tol
                && delta <= tol
                && res.tangential <= tol
                && history.len() >= 2
                && res.normal >= STALL_FACTOR * history[history.len() - 2].normal;
            if (inner_ok && delta <= tol && res.tangential <= tol) || stalled {
                let report = SolverReport {
                    solver: self.name().to_string(),
                    iterations: k,
                    inner_iterations,
                    history: history.clone(),
                    ..SolverReport::default()
                };
                let mut sol = solution(&mut op, &nu, &res, report)?;
                // The multiplier-scale test above is absolute in Λ_t; on nearly unloaded
                // problems the displacements are tiny and the stick condition must also hold
                // relative to them (the scale of `check_kkt`): otherwise keep iterating.
                // (a multipliers-only solve has no U to check: its multiplier test above holds)
                let accept = if stalled {
                    !sol.u.is_empty()
                        && synovia_contact::check_kkt(problem, &sol.u, &sol.lambda_n, &sol.lambda_t).max()
                            <= tol
                } else {
                    mt == 0
                        || sol.u.is_empty()
                        || synovia_contact::check_kkt(problem, &sol.u, &sol.lambda_n, &sol.lambda_t).max()
                            <= 100.0 * tol
                };
                if accept {
                    sol.report.time_s = t0.elapsed().as_secs_f64();
                    return Ok(sol);
                }
            }
            done = k;
            if mt == 0 && !qrep.converged {
                break;
            }
            if qrep.converged && res.normal > tol {
                // the inner solve was not accurate enough for the outer tolerance: tighten it
                inner.tolerance = (inner.tolerance * 1e-2).max(1e-15);
            }
            last = res;
            // adaptive restart of the momentum (O'Donoghue & Candès 2015)
            t = if restart > 0.0 { 1.0 } else { t_next };
            std::mem::swap(&mut lam_prev, &mut lam);
            lam.copy_from_slice(&lam_new);
        }
        Err(ContactError::NoConvergence { solver: self.name().to_string(), iterations: done, history })
    }
}
