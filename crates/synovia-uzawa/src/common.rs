//! Shared pieces of the two contact solvers: parameter checks, warm starts, the Jacobi scaling
//! of the dual variables, the residuals of docs/model.md §5 and the final solution.

use synovia_contact::{ContactError, ContactParams, ContactProblem, ContactSolution, SolverReport};

use crate::qp::{norm, ConvexBlock};
use crate::schur::SchurOperator;

pub(crate) fn check_params(p: &ContactParams) -> Result<(), ContactError> {
    if !(p.tolerance.is_finite() && p.tolerance > 0.0) {
        return Err(ContactError::InvalidParameter(format!("tolerance {} must be positive", p.tolerance)));
    }
    if p.max_iterations == 0 {
        return Err(ContactError::InvalidParameter("max_iterations must be at least 1".into()));
    }
    if !(p.rho_scale.is_finite() && p.rho_scale > 0.0) {
        return Err(ContactError::InvalidParameter(format!("rho_scale {} must be positive", p.rho_scale)));
    }
    Ok(())
}

/// Force multipliers `ν = (κ Λ_n, Λ_t)` from a warm start (`Λ_n⁺`, `Λ_t` projected onto the
/// friction set), or zeros.
pub(crate) fn initial_multipliers(
    problem: &ContactProblem<'_>,
    warm: Option<&ContactSolution>,
) -> Result<Vec<f64>, ContactError> {
    let (mn, mt, c) = (problem.n_normal(), problem.n_tangential(), problem.components());
    let mut nu = vec![0.0; mn + mt];
    if let Some(w) = warm {
        if w.lambda_n.len() != mn || w.lambda_t.len() != mt {
            return Err(ContactError::InvalidParameter(format!(
                "warm start has {} normal and {} tangential multipliers, the problem {mn} and {mt}",
                w.lambda_n.len(),
                w.lambda_t.len()
            )));
        }
        for (r, (l, k)) in w.lambda_n.iter().zip(&problem.normal.weights).enumerate() {
            nu[r] = if l.is_finite() { (l * k).max(0.0) } else { 0.0 };
        }
        for (r, l) in w.lambda_t.iter().enumerate() {
            nu[mn + r] = if l.is_finite() { *l } else { 0.0 };
        }
        for cell in nu[mn..].chunks_mut(c) {
            project_unit(cell);
        }
    }
    Ok(nu)
}

/// Projection `π` onto `[−1, 1]` (one component) or the unit disc (two):
/// [`synovia_contact::project_on_disc`] with radius 1 (docs/model.md §3).
pub(crate) fn project_unit(v: &mut [f64]) {
    synovia_contact::project_on_disc(v, 1.0);
}

/// Jacobi scales `D` of the interface rows: `S_rr` for the normal rows, the mean of `S_rr` over
/// a friction cell for its components (so that discs stay discs), `1` where `S_rr ≤ 0`.
pub(crate) fn jacobi_scales(problem: &ContactProblem<'_>, diag: &[f64]) -> Vec<f64> {
    let (mn, c) = (problem.n_normal(), problem.components());
    let fix = |d: f64| if d.is_finite() && d > 0.0 { d } else { 1.0 };
    let mut s: Vec<f64> = diag[..mn].iter().map(|&d| fix(d)).collect();
    for cell in diag[mn..].chunks(c) {
        let mean = cell.iter().sum::<f64>() / cell.len() as f64;
        s.extend(std::iter::repeat_n(fix(mean), cell.len()));
    }
    s
}

/// The bounds of the normal force multipliers: `ν_n,r ≥ 0`, except for rows whose column of `S`
/// vanishes (`S_rr = c_rᵀ A⁻¹ c_r = 0`: the row acts on no free unknown, so `y_r = w_r` whatever
/// `ν`): there `ν_n,r = 0` if `w_r ≤ d_r`, and the problem is infeasible otherwise.
pub(crate) fn normal_bounds(
    problem: &ContactProblem<'_>,
    diag: &[f64],
    w: &[f64],
) -> Result<Vec<ConvexBlock>, ContactError> {
    let mn = problem.n_normal();
    let dmax = diag[..mn].iter().fold(0.0_f64, |a, &b| a.max(b));
    let gap = &problem.normal.gap;
    let scale = w[..mn].iter().chain(gap).fold(0.0_f64, |a, b| a.max(b.abs()));
    let mut blocks = Vec::with_capacity(mn);
    for r in 0..mn {
        if diag[r] > 1e-14 * dmax {
            blocks.push(ConvexBlock::Interval { lower: 0.0, upper: f64::INFINITY });
        } else if w[r] - gap[r] <= 1e-12 * scale {
            blocks.push(ConvexBlock::Interval { lower: 0.0, upper: 0.0 });
        } else {
            return Err(ContactError::Infeasible(format!(
                "normal constraint {r} acts on no free unknown and is violated by {:.3e} (B_hn U = {:.3e} > d = {:.3e} for every admissible U)",
                w[r] - gap[r],
                w[r] + 0.0,
                gap[r]
            )));
        }
    }
    Ok(blocks)
}

/// Residuals of docs/model.md §5 at force multipliers `ν` with interface values `y = C U`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Residuals {
    /// `max_r |Λ_n,r − (Λ_n,r + ρ_r (y_r − d_r))⁺| / max Λ_n`.
    pub normal: f64,
    /// `max_c ‖Λ_t,c − π(Λ_t,c + ρ_c (y_c − s_c))‖`.
    pub tangential: f64,
    /// Per normal row: active (`Λ_n + ρ (y − d) > 0`); per cell: stick
    /// (`‖Λ_t + ρ (y − s)‖ < 1`).
    pub active: Vec<bool>,
    pub stick: Vec<bool>,
}

impl Residuals {
    pub fn changes(&self, prev: &Residuals) -> usize {
        if prev.active.len() != self.active.len() || prev.stick.len() != self.stick.len() {
            return self.active.len() + self.stick.len();
        }
        self.active.iter().zip(&prev.active).filter(|(a, b)| a != b).count()
            + self.stick.iter().zip(&prev.stick).filter(|(a, b)| a != b).count()
    }
}

/// `y_minus_g = y − (d, s)`; `rho` in force-multiplier units (`ContactProblem::default_rho`).
pub(crate) fn residuals(
    problem: &ContactProblem<'_>,
    rho: &[f64],
    nu: &[f64],
    y_minus_g: &[f64],
) -> Residuals {
    let (mn, c) = (problem.n_normal(), problem.components());
    let kappa = &problem.normal.weights;
    let mut r = Residuals::default();
    let mut lmax = 0.0_f64;
    let mut worst = 0.0_f64;
    for i in 0..mn {
        let t = nu[i] + rho[i] * y_minus_g[i];
        r.active.push(t > 0.0);
        worst = worst.max((nu[i] - t.max(0.0)).abs() / kappa[i]);
        lmax = lmax.max(nu[i] / kappa[i]);
    }
    r.normal = if worst == 0.0 { 0.0 } else { worst / lmax.max(f64::MIN_POSITIVE) };
    let mut buf = vec![0.0; c];
    for start in (mn..nu.len()).step_by(c.max(1)) {
        for k in 0..c {
            buf[k] = nu[start + k] + rho[start + k] * y_minus_g[start + k];
        }
        r.stick.push(norm(&buf) < 1.0);
        project_unit(&mut buf);
        let d: f64 = (0..c).map(|k| (nu[start + k] - buf[k]).powi(2)).sum::<f64>().sqrt();
        r.tangential = r.tangential.max(d);
    }
    r
}

/// The solution from the final force multipliers.
pub(crate) fn solution(
    op: &mut SchurOperator<'_>,
    nu: &[f64],
    res: &Residuals,
    mut report: SolverReport,
) -> Result<ContactSolution, ContactError> {
    let u = op.displacement(nu)?;
    let (lambda_n, lambda_t) = op.problem().split_multipliers(nu);
    report.active = res.active.iter().filter(|&&a| a).count();
    report.stick = res.stick.iter().filter(|&&a| a).count();
    report.slip = res.stick.len() - report.stick;
    report.linear_solves = op.solves();
    Ok(ContactSolution { u, lambda_n, lambda_t, report })
}
