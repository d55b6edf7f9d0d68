//! Machinery shared by [`Pdas`](crate::Pdas) and [`AuPdas`](crate::AuPdas): the interface
//! state, the active/stick/slip classification, the complementarity residuals and the dense
//! interface solve of one active-set step.
//!
//! Notation (crate docs): force multipliers `ν = (κ Λ_n, Λ_t)`, interface values
//! `y = w − S ν`, offsets `g = (d, s)`, complementarity parameters `ρ`.

use faer::linalg::solvers::Solve;
use synovia_contact::{
    ContactError, ContactParams, ContactProblem, ContactSolution, Interface, SolveContext,
};

/// Relative width of the switching band: a row whose switching quantity lies within
/// `SWITCH_BAND × scale` of its threshold keeps its previous state. Both states are then
/// solutions up to rounding (a weakly active row), and keeping the state prevents the set
/// from flickering on round-off.
const SWITCH_BAND: f64 = 1e-12;

/// Smallest admissible Cholesky pivot `L_ii²`, relative to the diagonal entry `K_ii`.
const PIVOT_TOL: f64 = 1e-12;

/// A dense `L Lᵀ` factorisation computed in the place of its matrix — the algorithm and
/// parallelism of faer's `Mat::llt` (blocked, `faer::get_global_parallelism()`), without the
/// copy of the matrix that `Llt` keeps besides the caller's: the active-set systems reach a few
/// thousand unknowns (4 000² × 8 B = 128 MB per copy).
struct DenseCholesky {
    /// `L` in the lower triangle, zeros above.
    l: faer::Mat<f64>,
}

impl DenseCholesky {
    /// Factorises the symmetric `a` (its lower triangle is read); `None` when it is not
    /// positive definite or the workspace cannot be allocated.
    fn factor(mut a: faer::Mat<f64>) -> Option<Self> {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::linalg::cholesky::llt::factor;
        let par = faer::get_global_parallelism();
        let n = a.nrows();
        let mut mem =
            MemBuffer::try_new(factor::cholesky_in_place_scratch::<f64>(n, par, Default::default())).ok()?;
        factor::cholesky_in_place(
            a.as_mut(),
            Default::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .ok()?;
        for j in 1..n {
            for i in 0..j {
                a[(i, j)] = 0.0;
            }
        }
        Some(Self { l: a })
    }

    fn l(&self) -> faer::MatRef<'_, f64> {
        self.l.as_ref()
    }

    /// `A⁻¹ B`.
    fn solve(&self, b: &faer::Mat<f64>) -> faer::Mat<f64> {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::linalg::cholesky::llt::solve;
        let par = faer::get_global_parallelism();
        let mut x = b.clone();
        let mut mem = MemBuffer::new(solve::solve_in_place_scratch::<f64>(self.l.nrows(), x.ncols(), par));
        solve::solve_in_place_with_conj(
            self.l.as_ref(),
            faer::Conj::No,
            x.as_mut(),
            par,
            MemStack::new(&mut mem),
        );
        x
    }
}

/// State of one friction cell in an active-set step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum CellState {
    /// `‖ζ_c‖ < 1`: `y_c = s_c`.
    Stick,
    /// `‖ζ_c‖ ≥ 1`: `Λ_t,c = π(ζ_c)` (linearised in 3D).
    Slip,
    /// The cell's rows of `B_Ht` are all zero (no slip bound there): `y_c = 0` whatever `U`,
    /// and `Λ_t,c` is fixed to `−s_c/‖s_c‖` (or `0` if `s_c = 0`), the solution of its NCP.
    Pinned,
}

/// One unknown of the reduced interface system: `ν = ν_fixed + Σ_a x_a q_a`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Unknown {
    /// `q = e_r`: an active normal row or a sticking tangential row; equation `(S ν)_r = w_r − g_r`.
    Row(usize),
    /// `q = t` on the two rows of a slipping 3D cell (`t ⊥ ζ_c`); equation
    /// `tᵀ (S ν)_c + diag · x = tᵀ (w_c − s_c)` with `diag = (‖ζ_c‖ − 1)/ρ_c ≥ 0`.
    Direction {
        /// The cell's two interface rows.
        rows: [usize; 2],
        /// Unit vector orthogonal to `ζ_c`.
        t: [f64; 2],
        /// `(‖ζ_c‖ − 1)/ρ_c`.
        diag: f64,
    },
}

/// The active sets of one iteration.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Sets {
    /// `true`: normal row in `𝒜_n`.
    pub normal: Vec<bool>,
    /// State of each friction cell.
    pub cells: Vec<CellState>,
}

impl Sets {
    /// Number of rows/cells whose state differs from `other`.
    pub fn changes(&self, other: &Sets) -> usize {
        let n = self.normal.iter().zip(&other.normal).filter(|(a, b)| a != b).count();
        let c = self.cells.iter().zip(&other.cells).filter(|(a, b)| a != b).count();
        n + c
    }

    /// `(active, stick, slip)` counts; pinned cells count as stick when `Λ_t,c = 0`, else slip.
    pub fn counts(&self, pinned: &[Option<[f64; 2]>]) -> (usize, usize, usize) {
        let active = self.normal.iter().filter(|a| **a).count();
        let (mut stick, mut slip) = (0, 0);
        for (c, s) in self.cells.iter().enumerate() {
            match s {
                CellState::Stick => stick += 1,
                CellState::Slip => slip += 1,
                CellState::Pinned => {
                    if pinned.get(c).copied().flatten().is_some_and(|v| v[0] != 0.0 || v[1] != 0.0) {
                        slip += 1;
                    } else {
                        stick += 1;
                    }
                }
            }
        }
        (active, stick, slip)
    }
}

/// Interface state of a solve: the lazily evaluated Schur complement and the data of the NCPs.
#[derive(Debug)]
pub(crate) struct State<'p> {
    /// `S`, `w`.
    pub iface: Interface<'p>,
    /// Number of normal rows `m_n`.
    pub m: usize,
    /// Rows per friction cell (1 or 2).
    pub comps: usize,
    /// Number of friction cells.
    pub n_cells: usize,
    /// `ρ` per interface row; the rows of a friction cell all carry the cell's `ρ_c`.
    pub rho: Vec<f64>,
    /// `g = (d, s)`.
    pub g: Vec<f64>,
    /// Normal rows whose `B_hn` row is zero (with `d_r ≥ 0`): always inactive.
    pub normal_empty: Vec<bool>,
    /// Friction cells whose `B_Ht` rows are all zero, with their fixed multiplier.
    pub pinned: Vec<Option<[f64; 2]>>,
    /// [`ContactParams::rho_scale`].
    pub rho_scale: f64,
    /// Whether `ρ` of the normal rows has been scaled to the interface (see `update_rho`).
    pub rho_initialised: bool,
    /// A rigid partner's coordinate solved with the contact conditions
    /// ([`synovia_contact::RigidBorder`]): `g = g₀ + σ ζ` with `ζ` from the last step.
    pub border: Option<Border>,
}

/// The bordered unknowns of a [`State`]: the columns `σ_j`, the targets of `σ_jᵀ ν =
/// target_j`, the offsets `g₀` at `ζ = 0` and the current `ζ`.
#[derive(Debug, Clone)]
pub(crate) struct Border {
    pub columns: Vec<Vec<f64>>,
    pub targets: Vec<f64>,
    pub g0: Vec<f64>,
    pub zeta: Vec<f64>,
}

/// `ζ / max(1, ‖ζ‖)`: the projection `π` onto `[−1, 1]` (2D) or the unit disc (3D).
/// [`synovia_contact::project_on_disc`] with radius 1 (an unused second component is 0 and
/// stays 0).
pub(crate) fn project(z: [f64; 2]) -> [f64; 2] {
    let mut p = z;
    synovia_contact::project_on_disc(&mut p, 1.0);
    p
}

fn norm2(z: [f64; 2]) -> f64 {
    (z[0] * z[0] + z[1] * z[1]).sqrt()
}

/// Checks the solver parameters.
pub(crate) fn check_params(params: &ContactParams) -> Result<(), ContactError> {
    if !(params.tolerance.is_finite() && params.tolerance > 0.0) {
        return Err(ContactError::InvalidParameter(format!(
            "tolerance must be positive and finite, got {}",
            params.tolerance
        )));
    }
    if params.max_iterations == 0 {
        return Err(ContactError::InvalidParameter("max_iterations must be at least 1".into()));
    }
    if !(params.rho_scale.is_finite() && params.rho_scale > 0.0) {
        return Err(ContactError::InvalidParameter(format!(
            "rho_scale must be positive and finite, got {}",
            params.rho_scale
        )));
    }
    Ok(())
}

impl<'p> State<'p> {
    /// Validates the problem and parameters, detects empty rows (an empty normal row with
    /// `d_r < 0` is infeasible) and computes `w` (one solve).
    #[tracing::instrument(level = "debug", skip_all)]
    pub fn new(
        problem: &ContactProblem<'p>,
        context: &'p SolveContext,
        params: &ContactParams,
    ) -> Result<Self, ContactError> {
        check_params(params)?;
        problem.validate()?;
        let m = problem.n_normal();
        let comps = problem.components();
        let g = problem.offsets();
        let mut normal_empty = vec![false; m];
        for (r, empty) in normal_empty.iter_mut().enumerate() {
            if problem.normal.rows.row_norm_squared(r) == 0.0 {
                let d = problem.normal.gap[r];
                if d < 0.0 {
                    return Err(ContactError::Infeasible(format!(
                        "normal row {r} has an empty constraint row (B_hn row {r} = 0, e.g. a contact \
                         node whose displacement is fully prescribed) but gap d_{r} = {d:e} < 0: \
                         [U_n] = 0 > d_{r} for every U"
                    )));
                }
                *empty = true;
            }
        }
        let mut rho = problem.default_rho(params.rho_scale);
        let mut pinned = Vec::new();
        let mut n_cells = 0;
        if let Some(fr) = problem.friction {
            n_cells = fr.n_cells();
            pinned = vec![None; n_cells];
            for (c, pin) in pinned.iter_mut().enumerate() {
                let rows = m + c * comps..m + (c + 1) * comps;
                // one scalar ρ per cell: the disc projection needs an isotropic ρ
                let rc = rho[rows.clone()].iter().sum::<f64>() / comps as f64;
                rho[rows.clone()].iter_mut().for_each(|v| *v = rc);
                let empty = (0..comps).all(|k| fr.rows.row_norm_squared(c * comps + k) == 0.0);
                if empty {
                    let mut s = [0.0; 2];
                    s[..comps].copy_from_slice(&fr.shift[c * comps..(c + 1) * comps]);
                    let ns = norm2(s);
                    *pin = Some(if ns > 0.0 { [-s[0] / ns, -s[1] / ns] } else { [0.0; 2] });
                }
            }
        }
        if let Some(r) = rho.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(ContactError::InvalidParameter(format!(
                "complementarity parameter ρ_{r} = {} is not positive (is diag A positive?)",
                rho[r]
            )));
        }
        let iface = Interface::new(*problem, context)?;
        Ok(Self {
            iface,
            m,
            comps,
            n_cells,
            rho,
            normal_empty,
            pinned,
            rho_scale: params.rho_scale,
            rho_initialised: false,
            border: problem.border.map(|b| Border {
                columns: b.columns.clone(),
                targets: b.targets.clone(),
                g0: g.clone(),
                zeta: vec![0.0; b.columns.len()],
            }),
            g,
        })
    }

    /// The initial multipliers: `ν = (κ Λ_n, Λ_t)` of `warm` if given, else `ν = 0`; fixed
    /// entries (empty rows, pinned cells) are set to their values.
    pub fn initial_nu(
        &self,
        problem: &ContactProblem<'_>,
        warm: Option<&ContactSolution>,
    ) -> Result<Vec<f64>, ContactError> {
        let mut nu = vec![0.0; self.iface.n_rows()];
        if let Some(ws) = warm {
            let nt = problem.n_tangential();
            if ws.lambda_n.len() != self.m || ws.lambda_t.len() != nt {
                return Err(ContactError::InvalidParameter(format!(
                    "warm start has {} normal and {} tangential multipliers, the problem {} and {nt}",
                    ws.lambda_n.len(),
                    ws.lambda_t.len(),
                    self.m
                )));
            }
            if ws.lambda_n.iter().chain(&ws.lambda_t).any(|v| !v.is_finite()) {
                return Err(ContactError::InvalidParameter("warm start multipliers are not finite".into()));
            }
            for (r, (l, k)) in ws.lambda_n.iter().zip(&problem.normal.weights).enumerate() {
                nu[r] = l * k;
            }
            nu[self.m..].copy_from_slice(&ws.lambda_t);
        }
        self.fix_entries(&mut nu);
        Ok(nu)
    }

    /// Sets the entries of empty normal rows to 0 and of pinned cells to their fixed values.
    fn fix_entries(&self, nu: &mut [f64]) {
        for (r, e) in self.normal_empty.iter().enumerate() {
            if *e {
                nu[r] = 0.0;
            }
        }
        for (c, p) in self.pinned.iter().enumerate() {
            if let Some(v) = p {
                for k in 0..self.comps {
                    nu[self.m + c * self.comps + k] = v[k];
                }
            }
        }
    }

    /// Bounds `ρ_c` of the friction cells by the step length of a convergent projected
    /// gradient step (AU-PDAS, docs/model.md §6.2):
    ///
    /// ```text
    /// ρ_c ← min(ρ_c, 1.8 / (λ̂ D_c)),   D_c = mean of diag S_tt over cell c,
    /// λ̂ = power-method estimate of λ_max(D^{-½} S_tt D^{-½}) (non-pinned cells).
    /// ```
    ///
    /// AU-PDAS updates the slipping cells by `Λ_t,c ← π(Λ_t,c + ρ_c (y_c − s_c))` with the
    /// normal multipliers frozen, a projected-gradient (Uzawa) step on the dual function whose
    /// gradient `y_t − s` is Lipschitz with constant `λ_max(S_tt)`; it converges only for
    /// `ρ < 2 / λ_max` in the metric `D`. The automatic `ρ` of
    /// [`ContactProblem::default_rho`] does not know `S_tt` and was 3–10× above that limit on
    /// 3D problems (two touching blocks, two-body shear, a floating block held by friction),
    /// where AU-PDAS then oscillated for ever. The solution does not depend on `ρ`.
    /// Columns of `S` for every friction row are computed (`m_t` solves, once).
    pub fn bound_tangential_rho(&mut self) -> Result<(), ContactError> {
        let rows: Vec<usize> = (0..self.n_cells)
            .filter(|&c| self.pinned.get(c).is_none_or(|p| p.is_none()))
            .flat_map(|c| (0..self.comps).map(move |k| (c, k)))
            .map(|(c, k)| self.cell_row(c, k))
            .collect();
        if rows.is_empty() {
            return Ok(());
        }
        self.iface.ensure_columns(&rows)?;
        let diag_of = |r: usize| self.iface.column(r).map_or(0.0, |col| col[r]);
        // D per row: the cell mean of diag S_tt (discs stay discs)
        let mut d = vec![0.0; rows.len()];
        for (chunk, dc) in rows.chunks(self.comps).zip(d.chunks_mut(self.comps)) {
            let mean = chunk.iter().map(|&r| diag_of(r)).sum::<f64>() / self.comps as f64;
            dc.iter_mut().for_each(|v| *v = mean);
        }
        if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Ok(()); // a degenerate row: keep the automatic ρ
        }
        let isq: Vec<f64> = d.iter().map(|v| 1.0 / v.sqrt()).collect();
        // power method on H = D^{-½} S_tt D^{-½}
        let mut v: Vec<f64> = (0..rows.len()).map(|i| 1.0 + 0.1 * ((i % 7) as f64)).collect();
        let mut lambda = 0.0_f64;
        for _ in 0..30 {
            let nv = v.iter().map(|a| a * a).sum::<f64>().sqrt();
            if !(nv > 0.0 && nv.is_finite()) {
                break;
            }
            v.iter_mut().for_each(|a| *a /= nv);
            let mut hv = vec![0.0; rows.len()];
            for (j, &rj) in rows.iter().enumerate() {
                let col = self.iface.column(rj).ok_or_else(|| {
                    ContactError::InvalidParameter(format!("internal: column {rj} of S not computed"))
                })?;
                let xj = v[j] * isq[j];
                for (i, &ri) in rows.iter().enumerate() {
                    hv[i] += col[ri] * xj;
                }
            }
            hv.iter_mut().zip(&isq).for_each(|(a, s)| *a *= s);
            lambda = lambda.max(v.iter().zip(&hv).map(|(a, b)| a * b).sum::<f64>());
            v = hv;
        }
        if !(lambda.is_finite() && lambda > 0.0) {
            return Ok(());
        }
        for (&r, dr) in rows.iter().zip(&d) {
            let bound = RHO_STEP / (lambda * dr);
            if bound < self.rho[r] {
                self.rho[r] = bound;
            }
        }
        Ok(())
    }

    /// Interface row of component `k` of cell `c`.
    pub fn cell_row(&self, c: usize, k: usize) -> usize {
        self.m + c * self.comps + k
    }

    /// `ζ_c = Λ_t,c + ρ_c (y_c − s_c)` (second entry 0 in 2D).
    pub fn zeta(&self, c: usize, nu: &[f64], y: &[f64]) -> [f64; 2] {
        let mut z = [0.0; 2];
        for (k, zk) in z.iter_mut().enumerate().take(self.comps) {
            let i = self.cell_row(c, k);
            *zk = nu[i] + self.rho[i] * (y[i] - self.g[i]);
        }
        z
    }

    /// The scale of the normal NCP terms `ν_r` and `ρ_r (y_r − d_r)`,
    /// `max_r max(|ν_r|, ρ_r (|y_r| + |d_r|))` over the loaded rows (`ν_r ≠ 0`), or over every
    /// row before any is loaded. Unloaded rows far from the
    /// contact have a large `ρ_r` (they hardly move under the loaded zone's forces) and gaps up
    /// to the search distance; counted in the scale, they made the relative residual of a
    /// slightly penetrating row nearer the contact look converged (measured: 1.9e-6 mm
    /// penetration accepted at a tolerance of 1e-10 on the tkr3d insert).
    fn normal_scale(&self, nu: &[f64], y: &[f64]) -> f64 {
        let term = |r: usize| nu[r].abs().max(self.rho[r] * (y[r].abs() + self.g[r].abs()));
        let loaded = (0..self.m).filter(|&r| nu[r] != 0.0).map(term).fold(0.0, f64::max);
        if loaded > 0.0 {
            loaded
        } else {
            (0..self.m).map(term).fold(f64::MIN_POSITIVE, f64::max)
        }
    }

    /// `𝒜_n = {r : ν_r + ρ_r (y_r − d_r) > 0}`; rows within the switching band keep `prev`.
    pub fn classify_normal(&self, nu: &[f64], y: &[f64], prev: Option<&[bool]>) -> Vec<bool> {
        let scale = self.normal_scale(nu, y);
        (0..self.m)
            .map(|r| {
                if self.normal_empty[r] {
                    return false;
                }
                let q = nu[r] + self.rho[r] * (y[r] - self.g[r]);
                match prev {
                    Some(p) if q.abs() <= SWITCH_BAND * scale => p[r],
                    _ => q > 0.0,
                }
            })
            .collect()
    }

    /// Stick `‖ζ_c‖ < 1`, slip otherwise; cells within the switching band keep `prev`.
    /// Slip-reversal safeguard: a cell that was slipping (`prev`) and whose slip now opposes
    /// its multiplier, `Λ_t,c · (y_c − s_c) < 0`, is moved to the stick set (the plain rule
    /// evaluated with `ρ_c → 0⁺` in 2D; see the crate docs).
    pub fn classify_cells(&self, nu: &[f64], y: &[f64], prev: Option<&[CellState]>) -> Vec<CellState> {
        (0..self.n_cells)
            .map(|c| {
                if self.pinned[c].is_some() {
                    return CellState::Pinned;
                }
                let nz = norm2(self.zeta(c, nu, y));
                if prev.is_some_and(|p| p[c] == CellState::Slip) {
                    // slip-reversal safeguard: Λ_t,c · ρ_c (y_c − s_c) < 0
                    let dot: f64 = (0..self.comps)
                        .map(|k| {
                            let i = self.cell_row(c, k);
                            nu[i] * self.rho[i] * (y[i] - self.g[i])
                        })
                        .sum();
                    if dot < -SWITCH_BAND {
                        return CellState::Stick;
                    }
                }
                match prev {
                    Some(p) if (nz - 1.0).abs() <= SWITCH_BAND => p[c],
                    _ if nz < 1.0 => CellState::Stick,
                    _ => CellState::Slip,
                }
            })
            .collect()
    }

    /// Relative NCP residuals `(normal, tangential)`:
    /// `max_r |ν_r − (ν_r + ρ_r (y_r − d_r))⁺| / max_r max(|ν_r|, ρ_r(|y_r| + |d_r|))` and
    /// `max_c ‖Λ_t,c − π(ζ_c)‖`.
    pub fn residual(&self, nu: &[f64], y: &[f64]) -> (f64, f64) {
        let scale = self.normal_scale(nu, y);
        let rn = (0..self.m)
            .map(|r| (nu[r] - (nu[r] + self.rho[r] * (y[r] - self.g[r])).max(0.0)).abs())
            .fold(0.0, f64::max)
            / scale;
        let rt = (0..self.n_cells)
            .map(|c| {
                let p = project(self.zeta(c, nu, y));
                let mut e = [0.0; 2];
                for (k, ek) in e.iter_mut().enumerate().take(self.comps) {
                    *ek = nu[self.cell_row(c, k)] - p[k];
                }
                norm2(e)
            })
            .fold(0.0, f64::max);
        (rn.max(self.border_residual(nu)), rt)
    }

    /// `max_j |σ_jᵀ ν − target_j| / max(|target_j|, Σ_r |σ_j,r ν_r|)`: the relative residual of
    /// the bordered coordinates' equilibria (0 without a border).
    pub fn border_residual(&self, nu: &[f64]) -> f64 {
        let Some(b) = &self.border else { return 0.0 };
        b.columns
            .iter()
            .zip(&b.targets)
            .map(|(col, &target)| {
                let q: f64 = col.iter().zip(nu).map(|(s, v)| s * v).sum();
                let scale = col.iter().zip(nu).map(|(s, v)| (s * v).abs()).sum::<f64>().max(target.abs());
                if scale > 0.0 {
                    (q - target).abs() / scale
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max)
    }

    /// `y = w − S ν`.
    #[tracing::instrument(level = "debug", skip_all)]
    pub fn values(&mut self, nu: &[f64]) -> Result<Vec<f64>, ContactError> {
        let y = self.iface.interface_values(nu)?;
        self.update_rho(nu)?;
        Ok(y)
    }

    /// Scales `ρ` of the normal rows to the interface on the first evaluation from a warm
    /// start: `ρ_r = scale / (S χ)_r`, `χ` the indicator of the rows with `ν ≠ 0` — the force
    /// per unit gap of the whole loaded zone seen from row `r`. With this scaling
    /// `ν + ρ (y − d)` weighs the warm-start multipliers and its gaps consistently, so a good
    /// warm start (e.g. from nested iteration) is kept rather than overridden by the gap term.
    /// From a cold start (`ν = 0`) the normal sets do not depend on `ρ` at all (active rows
    /// have `y = d`, inactive ones `ν = 0`), and the fallback of
    /// [`ContactProblem::default_rho`] is kept.
    fn update_rho(&mut self, nu: &[f64]) -> Result<(), ContactError> {
        if self.rho_initialised {
            return Ok(());
        }
        self.rho_initialised = true;
        let chi: Vec<f64> =
            (0..nu.len()).map(|r| if r < self.m && nu[r] != 0.0 { 1.0 } else { 0.0 }).collect();
        if chi.iter().all(|&c| c == 0.0) {
            return Ok(());
        }
        let z = self.iface.apply_s(&chi)?;
        for (rho, &zr) in self.rho.iter_mut().zip(&z).take(self.m) {
            if zr > 0.0 && zr.is_finite() {
                *rho = self.rho_scale / zr;
            }
        }
        Ok(())
    }

    /// Solves one active-set step: `ν = ν_fixed + Σ_a x_a q_a` with
    /// `(Qᵀ S Q + D) x = Qᵀ (w − g − S ν_fixed)`, `D` the `diag` of the
    /// [`Unknown::Direction`] unknowns (zero otherwise). The matrix is symmetric positive
    /// (semi-)definite; it is factorised by Cholesky and a failed or tiny pivot is reported as
    /// [`ContactError::Singular`].
    #[tracing::instrument(level = "debug", skip_all)]
    pub fn solve_step(
        &mut self,
        mut nu: Vec<f64>,
        unknowns: &[Unknown],
        solver: &str,
        iteration: usize,
    ) -> Result<Vec<f64>, ContactError> {
        let n = unknowns.len();
        let mut need: Vec<usize> = (0..nu.len()).filter(|&j| nu[j] != 0.0).collect();
        for u in unknowns {
            match u {
                Unknown::Row(r) => need.push(*r),
                Unknown::Direction { rows, .. } => need.extend_from_slice(rows),
            }
        }
        self.iface.ensure_columns(&need)?;
        let singular = || ContactError::Singular { solver: solver.to_string(), iteration, size: n };
        if n == 0 {
            if self.border.is_some() {
                // nothing in contact holds the rigid partner's coordinate
                return Err(singular());
            }
            return Ok(nu);
        }
        let s_fixed = self.iface.apply_s(&nu)?;
        let w = self.iface.w();
        // the offsets at ζ = 0 for a bordered step (ζ is one of its unknowns)
        let g = self.border.as_ref().map_or(&self.g, |b| &b.g0);
        let rhs_full: Vec<f64> = (0..nu.len()).map(|i| w[i] - g[i] - s_fixed[i]).collect();
        // sparse representation of the q_a
        let q: Vec<([usize; 2], [f64; 2], usize, f64)> = unknowns
            .iter()
            .map(|u| match *u {
                Unknown::Row(r) => ([r, r], [1.0, 0.0], 1, 0.0),
                Unknown::Direction { rows, t, diag } => (rows, t, 2, diag),
            })
            .collect();
        let mut cols: Vec<[&[f64]; 2]> = Vec::with_capacity(n);
        for (rows, _, len, _) in &q {
            let mut pair: [&[f64]; 2] = [&[], &[]];
            for k in 0..*len {
                pair[k] = self.iface.column(rows[k]).ok_or_else(|| {
                    ContactError::InvalidParameter(format!("internal: column {} of S not computed", rows[k]))
                })?;
            }
            cols.push(pair);
        }
        let mut k_mat = faer::Mat::<f64>::zeros(n, n);
        for b in 0..n {
            let (_, tb, lb, db) = q[b];
            for a in b..n {
                let (ra, ta, la, _) = q[a];
                let mut v = 0.0;
                for i in 0..la {
                    for j in 0..lb {
                        v += ta[i] * tb[j] * cols[b][j][ra[i]];
                    }
                }
                k_mat[(a, b)] = v;
                k_mat[(b, a)] = v;
            }
            k_mat[(b, b)] += db;
        }
        let rhs = faer::Mat::<f64>::from_fn(n, 1, |a, _| {
            let (r, t, l, _) = &q[a];
            (0..*l).map(|i| t[i] * rhs_full[r[i]]).sum::<f64>()
        });
        let diag: Vec<f64> = (0..n).map(|a| k_mat[(a, a)]).collect();
        if diag.iter().any(|d| !(d.is_finite() && *d > 0.0)) {
            return Err(singular());
        }
        // faer's blocked dense Cholesky (the active systems reach a few thousand unknowns), in
        // the place of the matrix: one n × n array at a time, not two
        let chol = DenseCholesky::factor(k_mat).ok_or_else(singular)?;
        let l = chol.l();
        if (0..n).any(|a| l[(a, a)] * l[(a, a)] <= PIVOT_TOL * diag[a]) {
            return Err(singular());
        }
        let mut x = chol.solve(&rhs);
        if let Some(border) = &mut self.border {
            // the bordered system [K B; Bᵀ 0] [x; ζ] = [rhs; c], B = Qᵀ [σ_j],
            // c_j = target_j − σ_jᵀ ν_fixed: with M = Bᵀ K⁻¹ B,
            // ζ = M⁻¹ (Bᵀ K⁻¹ rhs − c), x = K⁻¹ rhs − K⁻¹ B ζ
            let m = border.columns.len();
            let b = faer::Mat::<f64>::from_fn(n, m, |a, j| {
                let (r, t, l, _) = &q[a];
                (0..*l).map(|i| t[i] * border.columns[j][r[i]]).sum::<f64>()
            });
            let kb = chol.solve(&b);
            let mut mm = faer::Mat::<f64>::zeros(m, m);
            let mut rz = faer::Mat::<f64>::zeros(m, 1);
            for i in 0..m {
                for j in 0..m {
                    mm[(i, j)] = (0..n).map(|a| b[(a, i)] * kb[(a, j)]).sum::<f64>();
                }
                let c =
                    border.targets[i] - border.columns[i].iter().zip(&nu).map(|(s, v)| s * v).sum::<f64>();
                rz[(i, 0)] = (0..n).map(|a| b[(a, i)] * x[(a, 0)]).sum::<f64>() - c;
            }
            // a coordinate that no unknown of the step moves (nothing in contact holds it), or
            // two that move the same rows alike
            let scale: Vec<f64> =
                (0..m).map(|j| (0..n).map(|a| b[(a, j)] * b[(a, j)] / diag[a]).sum::<f64>()).collect();
            if scale.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(singular());
            }
            let mchol = mm.llt(faer::Side::Lower).map_err(|_| singular())?;
            let lm = mchol.L();
            if (0..m).any(|j| lm[(j, j)] * lm[(j, j)] <= PIVOT_TOL * scale[j]) {
                return Err(singular());
            }
            let zeta = mchol.solve(&rz);
            for a in 0..n {
                x[(a, 0)] -= (0..m).map(|j| kb[(a, j)] * zeta[(j, 0)]).sum::<f64>();
            }
            border.zeta = (0..m).map(|j| zeta[(j, 0)]).collect();
            for (r, (gi, g0)) in self.g.iter_mut().zip(&border.g0).enumerate() {
                *gi = g0 + border.columns.iter().zip(&border.zeta).map(|(c, z)| c[r] * z).sum::<f64>();
            }
        }
        if (0..n).any(|a| !x[(a, 0)].is_finite()) {
            return Err(singular());
        }
        for (a, (r, t, l, _)) in q.iter().enumerate() {
            for i in 0..*l {
                nu[r[i]] += t[i] * x[(a, 0)];
            }
        }
        Ok(nu)
    }

    /// Fixed part and unknowns of the normal half of a step: `ν_r` unknown on `𝒜_n`, `0` on `ℐ_n`.
    pub fn normal_part(&self, active: &[bool], nu: &mut [f64], unknowns: &mut Vec<Unknown>) {
        for (r, a) in active.iter().enumerate() {
            nu[r] = 0.0;
            if *a {
                unknowns.push(Unknown::Row(r));
            }
        }
    }

    /// Fixed part and unknowns of the tangential half of a step. Stick: `ν_c` unknown
    /// (`y_c = s_c`). Pinned: fixed. Slip with `linearise == false` or in 2D: `ν_c = π(ζ_c)`.
    /// Slip in 3D with `linearise == true`: the semismooth Newton step
    /// `ν_c = n + β t`, `n = ζ_c/‖ζ_c‖`, `t ⊥ n`, `β` unknown
    /// ([`Unknown::Direction`] with `diag = (‖ζ_c‖ − 1)/ρ_c`).
    pub fn tangential_part(
        &self,
        cells: &[CellState],
        zetas: &[[f64; 2]],
        linearise: bool,
        nu: &mut [f64],
        unknowns: &mut Vec<Unknown>,
    ) {
        for (c, st) in cells.iter().enumerate() {
            let rows = [self.cell_row(c, 0), self.cell_row(c, self.comps - 1)];
            match st {
                CellState::Pinned => {
                    let v = self.pinned[c].unwrap_or([0.0; 2]);
                    for k in 0..self.comps {
                        nu[rows[k]] = v[k];
                    }
                }
                CellState::Stick => {
                    for k in 0..self.comps {
                        nu[rows[k]] = 0.0;
                        unknowns.push(Unknown::Row(rows[k]));
                    }
                }
                CellState::Slip => {
                    let z = zetas[c];
                    let nz = norm2(z);
                    if nz == 0.0 {
                        // cannot happen for a slip cell (‖ζ‖ ≥ 1 − band); treat as stick
                        for k in 0..self.comps {
                            nu[rows[k]] = 0.0;
                            unknowns.push(Unknown::Row(rows[k]));
                        }
                        continue;
                    }
                    let n = [z[0] / nz, z[1] / nz];
                    if self.comps == 1 {
                        nu[rows[0]] = n[0];
                    } else if !linearise {
                        let p = project(z);
                        nu[rows[0]] = p[0];
                        nu[rows[1]] = p[1];
                    } else {
                        nu[rows[0]] = n[0];
                        nu[rows[1]] = n[1];
                        let diag = ((nz - 1.0) / self.rho[rows[0]]).max(0.0);
                        unknowns.push(Unknown::Direction { rows, t: [-n[1], n[0]], diag });
                    }
                }
            }
        }
    }

    /// `ζ_c` of every cell.
    pub fn zetas(&self, nu: &[f64], y: &[f64]) -> Vec<[f64; 2]> {
        (0..self.n_cells).map(|c| self.zeta(c, nu, y)).collect()
    }
}

/// Builds the returned solution: `U = A⁻¹ (F − Cᵀ ν)` (one solve), `(Λ_n, Λ_t)` from `ν`,
/// and the report.
pub(crate) fn finish(
    state: &mut State<'_>,
    problem: &ContactProblem<'_>,
    nu: &[f64],
    sets: &Sets,
    mut report: synovia_contact::SolverReport,
    start: std::time::Instant,
) -> Result<ContactSolution, ContactError> {
    let u = state.iface.displacement(nu)?;
    let (lambda_n, lambda_t) = problem.split_multipliers(nu);
    let (active, stick, slip) = sets.counts(&state.pinned);
    report.active = active;
    report.stick = stick;
    report.slip = slip;
    report.linear_solves = state.iface.solves();
    report.border_values = state.border.as_ref().map_or_else(Vec::new, |b| b.zeta.clone());
    report.time_s = start.elapsed().as_secs_f64();
    tracing::debug!(
        solves = report.linear_solves,
        solve_s = state.iface.solve_seconds(),
        rows = state.iface.n_rows(),
        iterations = report.iterations,
        time_s = report.time_s,
        "pdas finished"
    );
    Ok(ContactSolution { u, lambda_n, lambda_t, report })
}

/// Factor by which the residual must drop from one iteration to the next (with unchanged
/// sets) for the iteration to count as still converging; see [`stalled_but_kkt_converged`].
/// Close to 1 so that a slowly (linearly) converging iteration — AU-PDAS in 3D contracts by
/// ≈ 0.6 per iteration — is never cut short: only an iteration that makes no progress at all
/// is measured with `check_kkt` (whose tangential residuals are scaled by the whole
/// displacement field and accept a less accurate `Λ_t`).
pub(crate) const STALL_FACTOR: f64 = 0.99;

/// Step factor of [`State::bound_tangential_rho`]: `ρ_c ≤ RHO_STEP / (λ̂ D_c)`, below the limit
/// `2 / λ_max` of a convergent projected-gradient step (`λ̂` from the power method is a lower
/// bound of `λ_max`, accurate to a few per cent after 30 steps).
const RHO_STEP: f64 = 1.8;

/// The scale-aware stopping test used when the interface residuals stall above the tolerance.
///
/// The interface residuals of [`State::residual`] are computed from `y = w − S ν`, a difference
/// of two vectors obtained by solves with `A`; its absolute rounding error is about
/// `ε κ(A) ‖w‖`, and `κ(A)` grows with the stiffness ratio of the bodies (two stacked blocks:
/// the residual stalls at `2e-10` for `E₁/E₂ = 1e5`, with unchanged sets, for ever). With the
/// sets unchanged for two iterations and the residual no longer decreasing (by more than 1 %,
/// [`STALL_FACTOR`]), the active-set system has been solved to rounding and further
/// iterations repeat the same step. The iterate is then measured as [`check_kkt`] measures any
/// solution — `U = A⁻¹ (F − Cᵀ ν)` from one solve, equilibrium relative to the forces,
/// penetration and complementarity relative to the displacement and multiplier scales — and
/// accepted when every one of those relative residuals is at most `tolerance`. Returns `false`
/// (iterate on) otherwise.
pub(crate) fn stalled_but_kkt_converged(
    state: &mut State<'_>,
    problem: &ContactProblem<'_>,
    nu: &[f64],
    history: &[synovia_contact::IterationResidual],
    tolerance: f64,
) -> Result<bool, ContactError> {
    let n = history.len();
    if n < 2 {
        return Ok(false);
    }
    let (prev, last) = (&history[n - 2], &history[n - 1]);
    let r_prev = prev.normal.max(prev.tangential);
    let r_last = last.normal.max(last.tangential);
    if prev.set_changes != 0 || last.set_changes != 0 || r_last < STALL_FACTOR * r_prev {
        return Ok(false);
    }
    let u = state.iface.displacement(nu)?;
    let (lambda_n, lambda_t) = problem.split_multipliers(nu);
    if state.border_residual(nu) > tolerance {
        return Ok(false);
    }
    let zeta = state.border.as_ref().map_or(&[][..], |b| &b.zeta[..]);
    Ok(synovia_contact::check_kkt_at_border(problem, zeta, &u, &lambda_n, &lambda_t).max() <= tolerance)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The in-place factorisation is faer's `Mat::llt` without the copy: the same `L` and the
    /// same solutions bit for bit, on an SPD matrix larger than faer's blocking size; and an
    /// indefinite matrix is refused.
    #[test]
    fn in_place_cholesky_equals_faer_llt_bit_for_bit() {
        let n = 300;
        // A = Bᵀ B + n I with a fixed pseudo-random B
        let b =
            faer::Mat::<f64>::from_fn(n, n, |i, j| (((i * 7919 + j * 104_729) % 1009) as f64 / 1009.0) - 0.5);
        let mut a = b.transpose() * &b;
        for i in 0..n {
            a[(i, i)] += n as f64;
        }
        let rhs = faer::Mat::<f64>::from_fn(n, 3, |i, j| ((i + 3 * j) % 17) as f64 - 8.0);
        let reference = a.llt(faer::Side::Lower).expect("SPD");
        let ours = DenseCholesky::factor(a.clone()).expect("SPD");
        for j in 0..n {
            for i in 0..n {
                assert_eq!(ours.l()[(i, j)].to_bits(), reference.L()[(i, j)].to_bits(), "L[{i}, {j}]");
            }
        }
        let (x, y) = (ours.solve(&rhs), reference.solve(&rhs));
        for j in 0..3 {
            for i in 0..n {
                assert_eq!(x[(i, j)].to_bits(), y[(i, j)].to_bits(), "x[{i}, {j}]");
            }
        }
        // residual of the solve, so that the comparison is not of two wrong answers
        let r = &a * &x - &rhs;
        let err = (0..3)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .fold(0.0_f64, |m, (i, j)| m.max(r[(i, j)].abs()));
        assert!(err < 1e-10, "residual {err}");
        let mut indefinite = a;
        indefinite[(0, 0)] = -1.0;
        assert!(DenseCholesky::factor(indefinite).is_none());
    }
}
