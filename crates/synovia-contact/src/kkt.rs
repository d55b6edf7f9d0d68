//! A checker of the KKT (complementarity) conditions of docs/model.md §5 for any returned solution.

use crate::problem::ContactProblem;

/// Residuals of the contact conditions, each relative to its natural scale.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct KktReport {
    /// `‖A U + B_hnᵀ κ Λ_n + B_Htᵀ Λ_t − F‖_∞ / max(‖F‖_∞, ‖B_hnᵀ κ Λ_n‖_∞, ‖B_Htᵀ Λ_t‖_∞)`.
    pub equilibrium: f64,
    /// Largest penetration `max_r (B_hn U − d)_r⁺`, relative to the displacement scale.
    pub penetration: f64,
    /// Largest negative pressure `max_r (−Λ_n,r)⁺`, relative to `max Λ_n`.
    pub negative_pressure: f64,
    /// `max_r |Λ_n,r (B_hn U − d)_r|` relative to `max Λ_n ×` displacement scale.
    pub complementarity: f64,
    /// `max_r ‖Λ_t,r − π(Λ_t,r)‖ = max_r (‖Λ_t,r‖ − 1)⁺` (`π` = [`crate::project_on_disc`]).
    pub friction_bound: f64,
    /// Sticking cells (`‖Λ_t,r‖ < 1 − 1e-6`) must not slip: `max ‖(B_Ht U − s)_r‖`, relative.
    pub stick_slip: f64,
    /// Slipping cells must slip along `Λ_t`: `max (‖y_r‖ − Λ_t,r · y_r)`, `y = B_Ht U − s`, relative.
    pub slip_direction: f64,
    /// Displacement scale used (`max(‖U‖_∞, ‖d‖_∞)`).
    pub displacement_scale: f64,
}

impl KktReport {
    /// The largest of all residuals.
    pub fn max(&self) -> f64 {
        [
            self.equilibrium,
            self.penetration,
            self.negative_pressure,
            self.complementarity,
            self.friction_bound,
            self.stick_slip,
            self.slip_direction,
        ]
        .into_iter()
        .fold(0.0, f64::max)
    }
    /// `true` if every residual is at most `tol`.
    pub fn satisfied(&self, tol: f64) -> bool {
        self.max() <= tol
    }
}

/// `‖v‖_∞`.
pub(crate) fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, b| a.max(b.abs()))
}

/// [`check_kkt`] of a solution of a problem with a [`crate::RigidBorder`] at the offsets
/// `g + Σ_j σ_j ζ_j` of the coordinates `ζ` it found ([`ContactProblem::shifted_constraints`]);
/// without a border or with an empty `ζ`, [`check_kkt`] of the problem as given.
pub fn check_kkt_at_border(
    problem: &ContactProblem<'_>,
    zeta: &[f64],
    u: &[f64],
    lambda_n: &[f64],
    lambda_t: &[f64],
) -> KktReport {
    let shifted = if zeta.is_empty() { None } else { problem.shifted_constraints(zeta) };
    match &shifted {
        Some((normal, friction)) => {
            let p = ContactProblem { normal, friction: friction.as_ref(), border: None, ..*problem };
            check_kkt(&p, u, lambda_n, lambda_t)
        }
        None => check_kkt(problem, u, lambda_n, lambda_t),
    }
}

/// Evaluates the KKT conditions of docs/model.md §5 for `(U, Λ_n, Λ_t)`.
///
/// A solution whose vectors do not fit the problem (e.g. the empty `U` of a multipliers-only
/// solve, or multipliers of another row set) cannot satisfy the conditions: every residual is
/// then `+∞`.
#[tracing::instrument(level = "debug", skip_all)]
pub fn check_kkt(problem: &ContactProblem<'_>, u: &[f64], lambda_n: &[f64], lambda_t: &[f64]) -> KktReport {
    let n = problem.operator.n();
    if u.len() != n || lambda_n.len() != problem.n_normal() || lambda_t.len() != problem.n_tangential() {
        let inf = f64::INFINITY;
        return KktReport {
            equilibrium: inf,
            penetration: inf,
            negative_pressure: inf,
            complementarity: inf,
            friction_bound: inf,
            stick_slip: inf,
            slip_direction: inf,
            displacement_scale: 0.0,
        };
    }
    let mut r = problem.operator.apply(u);
    let mut bn = vec![0.0; n];
    let kl: Vec<f64> = lambda_n.iter().zip(&problem.normal.weights).map(|(l, k)| l * k).collect();
    problem.normal.rows.mul_transpose_add(&kl, &mut bn);
    let mut bt = vec![0.0; n];
    if let Some(f) = problem.friction {
        f.rows.mul_transpose_add(lambda_t, &mut bt);
    }
    for i in 0..n {
        r[i] += bn[i] + bt[i] - problem.load[i];
    }
    let fscale = inf_norm(problem.load).max(inf_norm(&bn)).max(inf_norm(&bt)).max(f64::MIN_POSITIVE);
    let yn: Vec<f64> =
        problem.normal.rows.mul(u).iter().zip(&problem.normal.gap).map(|(y, d)| y - d).collect();
    let dscale = inf_norm(u).max(inf_norm(&problem.normal.gap)).max(f64::MIN_POSITIVE);
    let lscale = lambda_n.iter().fold(0.0_f64, |a, &b| a.max(b)).max(f64::MIN_POSITIVE);
    let mut rep = KktReport {
        equilibrium: inf_norm(&r) / fscale,
        penetration: yn.iter().fold(0.0_f64, |a, &b| a.max(b)) / dscale,
        negative_pressure: lambda_n.iter().fold(0.0_f64, |a, &b| a.max(-b)) / lscale,
        complementarity: lambda_n.iter().zip(&yn).fold(0.0_f64, |a, (l, y)| a.max((l * y).abs()))
            / (lscale * dscale),
        displacement_scale: dscale,
        ..Default::default()
    };
    if let Some(f) = problem.friction {
        let c = f.components;
        let yt: Vec<f64> = f.rows.mul(u).iter().zip(&f.shift).map(|(y, s)| y - s).collect();
        // scale of the tangential rows: ‖row‖ × displacement scale
        let row_scale = (0..f.rows.nrows()).map(|r| f.rows.row_norm_squared(r).sqrt()).fold(0.0, f64::max);
        let tscale = (row_scale * dscale).max(f64::MIN_POSITIVE);
        for cell in 0..f.n_cells() {
            let l = &lambda_t[cell * c..(cell + 1) * c];
            let y = &yt[cell * c..(cell + 1) * c];
            let ln = l.iter().map(|v| v * v).sum::<f64>().sqrt();
            let yn2 = y.iter().map(|v| v * v).sum::<f64>().sqrt();
            // distance to the unit disc, ‖Λ_t,r − π(Λ_t,r)‖ = (‖Λ_t,r‖ − 1)⁺
            let mut p = l.to_vec();
            crate::friction::project_on_disc(&mut p, 1.0);
            let dist = l.iter().zip(&p).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
            rep.friction_bound = rep.friction_bound.max(dist);
            if ln < 1.0 - 1e-6 {
                rep.stick_slip = rep.stick_slip.max(yn2 / tscale);
            } else {
                let dot: f64 = l.iter().zip(y).map(|(a, b)| a * b).sum();
                rep.slip_direction = rep.slip_direction.max((yn2 - dot) / tscale);
            }
        }
    }
    rep
}
