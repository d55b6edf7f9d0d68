//! The algebraic contact problem of docs/model.md §5 and its condensation on the contact interface
//! (docs/model.md §6.4).
//!
//! ```text
//! A U + B_hnᵀ diag(κ) Λ_n + B_Htᵀ Λ_t − F = 0
//! Λ_n − (Λ_n + ρ (B_hn U − d))⁺          = 0
//! Λ_t − π(Λ_t + ρ (B_Ht U − s))           = 0        (s = B_Ht U_prev: incremental slip)
//! ```
//!
//! All solvers work with the *force multipliers* `ν = (κ Λ_n, Λ_t)` and the stacked operator
//! `C = [B_hn; B_Ht]`: `U = A⁻¹ (F − Cᵀ ν)` and the interface values
//! `y = C U = w − S ν` with `w = C A⁻¹ F` and the interface Schur complement
//! `S = C A⁻¹ Cᵀ` (symmetric positive semi-definite). [`Interface`] evaluates `S` lazily: a
//! column costs one solve with the factorisation of `A`, computed once and cached, so a solver
//! pays only for the rows that ever become active.

use std::time::Instant;

use synovia_linalg::{FactorisedOperator, RowStack, SparseRows};

use crate::context::SolveContext;
use crate::error::ContactError;

/// Normal contact constraints `[U_n](s_r) ≤ d_r`, one row per contact node.
#[derive(Debug, Clone, PartialEq)]
pub struct NormalConstraints {
    /// `B_hn`: `(B_hn U)_r = [U_n](s_r)`.
    pub rows: SparseRows,
    /// Lumped weights `κ_r = ∫_{Γ_c} φ_r ds`.
    pub weights: Vec<f64>,
    /// Gaps `d_r` (in the reduced unknowns: the lift of prescribed displacements is already
    /// subtracted).
    pub gap: Vec<f64>,
}

/// Tangential (Tresca) constraints: one cell per row group of `components` rows (1 in 2D,
/// 2 in 3D), `(B_Ht U)_r = g_{c,r} ∫_{cell r} [U_t] ds`, `‖Λ_t,r‖ ≤ 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionConstraints {
    /// `B_Ht` (rows grouped by cell, `components` consecutive rows per cell).
    pub rows: SparseRows,
    /// Rows per cell: 1 (2D) or 2 (3D).
    pub components: usize,
    /// `s = B_Ht U_prev` (incremental slip; zero for slip measured from the reference state).
    pub shift: Vec<f64>,
}

impl FrictionConstraints {
    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.rows.nrows() / self.components.max(1)
    }
}

/// Force-controlled coordinates `z_j` of rigid partners solved together with the contact
/// conditions (docs/model.md §10, "The coordinate in the contact solve"): the offsets of the
/// interface rows move with them to first order,
///
/// ```text
/// g(ζ) = g + Σ_j σ_j ζ_j,        ζ_j = z_j − z₀_j (z₀: the coordinates the rows were built at),
/// ```
///
/// and their equilibria close the system, `σ_jᵀ ν = target_j` (`σ_j = ∂g/∂z_j`; with the
/// generalised contact force `Q_j = σ_jᵀ ν` on the partner, `target_j = −F_j` for the applied
/// generalised force `F_j`). They are the stationarity in `z` of the Lagrangian of the contact
/// problem with the work `F · z` of the applied forces added. A solver that takes them
/// ([`crate::ContactSolver::solves_border`]) returns `ζ` in
/// [`crate::SolverReport::border_values`]; the solution is that of the problem with the offsets
/// `g(ζ)`.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBorder {
    /// `σ_j`, one column per coordinate, each with one entry per interface row (the normal
    /// rows, then the tangential ones).
    pub columns: Vec<Vec<f64>>,
    /// The equilibria's right-hand sides `σ_jᵀ ν = target_j`, one per column.
    pub targets: Vec<f64>,
}

impl RigidBorder {
    /// A border of one coordinate.
    pub fn single(column: Vec<f64>, target: f64) -> Self {
        Self { columns: vec![column], targets: vec![target] }
    }

    /// `g(ζ)_r − g_r = Σ_j σ_j,r ζ_j` for interface row `r`.
    pub fn shift(&self, r: usize, zeta: &[f64]) -> f64 {
        self.columns.iter().zip(zeta).map(|(c, z)| c[r] * z).sum()
    }
}

/// One contact problem of docs/model.md §5: the operator `A` (factorised), the load `F`, and
/// the contact rows with their gaps and bounds — the mathematics only. What a sequence of
/// solves reuses (warm start, kept columns of `S`, recycled load solves) lives in the
/// caller's [`SolveContext`].
#[derive(Debug, Clone, Copy)]
pub struct ContactProblem<'a> {
    /// `A` (stiffness, or the time-step matrix of docs/model.md §7), reduced unknowns,
    /// factorised.
    pub operator: &'a dyn FactorisedOperator,
    /// `F`.
    pub load: &'a [f64],
    /// Normal constraints.
    pub normal: &'a NormalConstraints,
    /// Friction constraints (`None`: frictionless).
    pub friction: Option<&'a FrictionConstraints>,
    /// A rigid partner's force-controlled coordinate solved with the contact conditions
    /// (`None`: every offset given).
    pub border: Option<&'a RigidBorder>,
}

impl<'a> ContactProblem<'a> {
    /// `C = [B_hn; B_Ht]`.
    pub fn rows(&self) -> RowStack<'a> {
        RowStack::new(&self.normal.rows, self.friction.map(|f| &f.rows))
    }

    /// A fingerprint of the rows of `C = [B_hn; B_Ht]` and the operator (for the columns of
    /// `S` kept in a [`SolveContext`]).
    pub fn rows_fingerprint(&self) -> u64 {
        self.rows().fingerprint() ^ self.operator.key().rotate_left(17)
    }

    /// A fingerprint of `F` and the operator (for the load solve kept in a [`SolveContext`]).
    fn load_fingerprint(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.operator.key().hash(&mut h);
        for f in self.load {
            f.to_bits().hash(&mut h);
        }
        h.finish()
    }

    /// Checks sizes and finiteness.
    pub fn validate(&self) -> Result<(), ContactError> {
        let n = self.operator.n();
        let bad = |m: String| Err(ContactError::InvalidParameter(m));
        if self.load.len() != n {
            return bad(format!("A is {n}×{n} and the load has {} entries", self.load.len()));
        }
        let nc = &self.normal;
        let m = nc.rows.nrows();
        if nc.rows.ncols() != n || nc.weights.len() != m || nc.gap.len() != m {
            return bad(format!(
                "B_hn has {} rows × {} columns, κ {} and d {} entries (n = {n})",
                m,
                nc.rows.ncols(),
                nc.weights.len(),
                nc.gap.len()
            ));
        }
        if let Some(i) = nc.weights.iter().position(|k| !(k.is_finite() && *k > 0.0)) {
            return bad(format!("weight κ_{i} = {} must be positive", nc.weights[i]));
        }
        if let Some(i) = nc.gap.iter().position(|d| !d.is_finite()) {
            return bad(format!("gap d_{i} is not finite"));
        }
        if self.load.iter().any(|f| !f.is_finite()) {
            return bad("load vector is not finite".into());
        }
        if let Some(fr) = self.friction {
            if !(fr.components == 1 || fr.components == 2)
                || fr.rows.nrows() % fr.components != 0
                || fr.shift.len() != fr.rows.nrows()
                || fr.rows.ncols() != n
            {
                return bad(format!(
                    "B_Ht has {} rows × {} columns with {} components per cell and {} shifts",
                    fr.rows.nrows(),
                    fr.rows.ncols(),
                    fr.components,
                    fr.shift.len()
                ));
            }
        }
        if let Some(b) = self.border {
            if b.columns.is_empty() || b.columns.len() != b.targets.len() {
                return bad(format!(
                    "the rigid border has {} columns and {} targets (one each per coordinate, at least one)",
                    b.columns.len(),
                    b.targets.len()
                ));
            }
            if let Some(c) = b.columns.iter().find(|c| c.len() != self.n_rows()) {
                return bad(format!(
                    "a rigid border column has {} sensitivities for {} interface rows",
                    c.len(),
                    self.n_rows()
                ));
            }
            if b.targets.iter().chain(b.columns.iter().flatten()).any(|v| !v.is_finite()) {
                return bad("the rigid border's sensitivities or targets are not finite".into());
            }
        }
        Ok(())
    }

    /// [`ContactError::InvalidParameter`] if the problem has a [`RigidBorder`]: for the
    /// solvers that do not take one (a border left out would solve another problem).
    pub fn refuse_border(&self, solver: &str) -> Result<(), ContactError> {
        match self.border {
            Some(_) => Err(ContactError::InvalidParameter(format!(
                "solver `{solver}` does not solve a rigid partner's force-controlled coordinate with the contact conditions (a RigidBorder); use `pdas` or `pdas-fallback`"
            ))),
            None => Ok(()),
        }
    }

    /// The offsets `g(ζ) = g + Σ_j σ_j ζ_j` of a bordered problem at `ζ` (docs/model.md §10),
    /// as constraints to check a solution against; `None` without a border.
    pub fn shifted_constraints(
        &self,
        zeta: &[f64],
    ) -> Option<(NormalConstraints, Option<FrictionConstraints>)> {
        let b = self.border?;
        let m = self.n_normal();
        let mut normal = self.normal.clone();
        for (r, d) in normal.gap.iter_mut().enumerate() {
            *d += b.shift(r, zeta);
        }
        let friction = self.friction.map(|f| {
            let mut f = f.clone();
            for (i, v) in f.shift.iter_mut().enumerate() {
                *v += b.shift(m + i, zeta);
            }
            f
        });
        Some((normal, friction))
    }

    /// Number of normal rows `m_n`.
    pub fn n_normal(&self) -> usize {
        self.normal.rows.nrows()
    }
    /// Number of tangential rows (`m_t × components`).
    pub fn n_tangential(&self) -> usize {
        self.friction.map_or(0, |f| f.rows.nrows())
    }
    /// Rows per friction cell (1 in 2D, 2 in 3D; 1 if frictionless).
    pub fn components(&self) -> usize {
        self.friction.map_or(1, |f| f.components)
    }
    /// Total interface rows `m_n + m_t × components`.
    pub fn n_rows(&self) -> usize {
        self.n_normal() + self.n_tangential()
    }

    /// Row `r` of `C = [B_hn; B_Ht]`.
    pub fn row(&self, r: usize) -> Box<dyn Iterator<Item = (usize, f64)> + 'a> {
        self.rows().row(r)
    }

    /// `C x`.
    pub fn apply(&self, x: &[f64]) -> Vec<f64> {
        self.rows().mul(x)
    }

    /// `out += Cᵀ ν`.
    pub fn apply_transpose_add(&self, nu: &[f64], out: &mut [f64]) {
        self.rows().mul_transpose_add(nu, out)
    }

    /// The right-hand sides `g = (d, s)` of the interface conditions.
    pub fn offsets(&self) -> Vec<f64> {
        let mut g = self.normal.gap.clone();
        if let Some(f) = self.friction {
            g.extend_from_slice(&f.shift);
        }
        g
    }

    /// Complementarity parameters per interface row, from the scaling of `A`:
    /// `ρ_r = scale · mean diag(A) / ‖C_r‖²` in force-multiplier units, which is docs/model.md (5.16)
    /// `ρ ≈ mean diag(A) / κ` for the normal rows. The solution does not depend on `ρ`.
    pub fn default_rho(&self, scale: f64) -> Vec<f64> {
        let diag = self.operator.diagonal();
        let mean = diag.iter().sum::<f64>() / diag.len().max(1) as f64;
        (0..self.n_rows())
            .map(|r| {
                let nr: f64 = self.row(r).map(|(_, v)| v * v).sum();
                if nr > 0.0 {
                    scale * mean / nr
                } else {
                    scale * mean
                }
            })
            .collect()
    }

    /// The multipliers of docs/model.md §5 from force multipliers: `Λ_n = ν_n / κ`, `Λ_t = ν_t`.
    pub fn split_multipliers(&self, nu: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let m = self.n_normal();
        let ln = nu[..m].iter().zip(&self.normal.weights).map(|(v, k)| v / k).collect();
        (ln, nu[m..].to_vec())
    }
}

/// `A⁻¹ F` of an [`Interface`]: whole, or the forward half `y = L⁻¹ P F` of a factor whose
/// trailing block holds every row ([`FactorisedOperator::forward_solve`]).
#[derive(Debug)]
enum LoadSolution {
    Full(std::sync::Arc<Vec<f64>>),
    Forward(std::sync::Arc<Vec<f64>>),
}

/// Tag of the kept forward half of a load solve in the [`SolveContext`] (its key is the
/// load's fingerprint with this tag, so that it is never taken for `A⁻¹ F`).
const FORWARD_KEY: u64 = 0x9e37_79b9_7f4a_7c15;

/// Lazily evaluated interface Schur complement `S = C A⁻¹ Cᵀ` and the interface load
/// `w = C A⁻¹ F` (docs/model.md §6.4). Columns of `S` come from the operator
/// ([`FactorisedOperator::interface_columns`]); those of an earlier interface of the same
/// operator and rows are taken from the [`SolveContext`] and handed back when the interface
/// is dropped.
#[derive(Debug)]
pub struct Interface<'a> {
    problem: ContactProblem<'a>,
    context: &'a SolveContext,
    /// `A⁻¹ F`, or its forward half.
    load_solution: LoadSolution,
    w: Vec<f64>,
    columns: Vec<Option<Vec<f64>>>,
    solves: usize,
    solve_s: f64,
    fingerprint: u64,
}

impl Drop for Interface<'_> {
    fn drop(&mut self) {
        self.context.put_columns(self.fingerprint, std::mem::take(&mut self.columns));
    }
}

impl<'a> Interface<'a> {
    /// Validates the problem and computes `w = C A⁻¹ F` (one solve, unless the context holds
    /// `A⁻¹ F` for the same `F` and operator, or was given it). When every row lies in a
    /// dense trailing block of the factor ([`FactorisedOperator::forward_solve`]) the solve is
    /// its forward half `y = L⁻¹ P F` with `w = C L₂₂⁻ᵀ y₂`; the backward half runs only if
    /// the displacement is asked for ([`Interface::displacement`]).
    #[tracing::instrument(level = "debug", skip_all)]
    pub fn new(problem: ContactProblem<'a>, context: &'a SolveContext) -> Result<Self, ContactError> {
        problem.validate()?;
        let t0 = Instant::now();
        let n = problem.load.len();
        let (x, solves) = match context.given_load_solution(n) {
            Some(x) => (LoadSolution::Full(x), 0),
            None => {
                let key = problem.load_fingerprint();
                let forward_key = key ^ FORWARD_KEY;
                let covered = problem.operator.forward_covers(problem.rows());
                match (context.load_solve(key), context.load_solve(forward_key).filter(|_| covered)) {
                    (Some(x), _) => (LoadSolution::Full(x), 0),
                    (None, Some(y)) => (LoadSolution::Forward(y), 0),
                    (None, None) => {
                        match covered.then(|| context.forward_from_span(problem.load)).flatten() {
                            // a load in the span of the loads solved before on this factorisation
                            Some(y) => {
                                let y = std::sync::Arc::new(y);
                                context.put_load_solve(forward_key, y.clone());
                                (LoadSolution::Forward(y), 0)
                            }
                            None => match covered
                                .then(|| problem.operator.forward_solve(problem.load))
                                .transpose()?
                                .flatten()
                            {
                                Some(y) => {
                                    let y = std::sync::Arc::new(y);
                                    context.put_load_solve(forward_key, y.clone());
                                    context.put_forward(problem.load, &y);
                                    (LoadSolution::Forward(y), 1)
                                }
                                None => {
                                    let mut x = problem.load.to_vec();
                                    problem.operator.solve_in_place(&mut x)?;
                                    let x = std::sync::Arc::new(x);
                                    context.put_load_solve(key, x.clone());
                                    (LoadSolution::Full(x), 1)
                                }
                            },
                        }
                    }
                }
            }
        };
        let w = match &x {
            LoadSolution::Full(x) => problem.apply(x),
            LoadSolution::Forward(y) => problem.apply(&problem.operator.interface_of_forward(y)?),
        };
        let m = problem.n_rows();
        let fingerprint = problem.rows_fingerprint();
        let columns = context.take_columns(fingerprint, m);
        Ok(Self {
            problem,
            context,
            load_solution: x,
            w,
            columns,
            solves,
            solve_s: t0.elapsed().as_secs_f64(),
            fingerprint,
        })
    }

    /// `true` if the columns of `S` come from a dense interface block of the operator.
    pub fn uses_dense_block(&self) -> bool {
        self.problem.operator.dense_interface_block(self.problem.rows())
    }

    /// The problem.
    pub fn problem(&self) -> &ContactProblem<'a> {
        &self.problem
    }
    /// The context.
    pub fn context(&self) -> &'a SolveContext {
        self.context
    }
    /// `w = C A⁻¹ F`.
    pub fn w(&self) -> &[f64] {
        &self.w
    }
    /// Number of interface rows.
    pub fn n_rows(&self) -> usize {
        self.columns.len()
    }
    /// Linear solves with `A` so far.
    pub fn solves(&self) -> usize {
        self.solves
    }
    /// Seconds spent in those solves (and the products with `C`).
    pub fn solve_seconds(&self) -> f64 {
        self.solve_s
    }

    /// Makes sure the columns `cols` of `S` are computed.
    #[tracing::instrument(level = "debug", skip_all)]
    pub fn ensure_columns(&mut self, cols: &[usize]) -> Result<(), ContactError> {
        if cols.iter().all(|&j| self.columns[j].is_some()) {
            return Ok(());
        }
        let t0 = Instant::now();
        let rows = self.problem.rows();
        self.solves += self.problem.operator.interface_columns(
            rows,
            cols,
            &mut self.columns,
            self.context.row_solves(),
        )?;
        self.solve_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Column `j` of `S` (must have been ensured).
    pub fn column(&self, j: usize) -> Option<&[f64]> {
        self.columns[j].as_deref()
    }

    /// `S ν`, computing the columns of the non-zero entries of `ν` if needed.
    pub fn apply_s(&mut self, nu: &[f64]) -> Result<Vec<f64>, ContactError> {
        let nz: Vec<usize> = (0..nu.len()).filter(|&j| nu[j] != 0.0).collect();
        self.ensure_columns(&nz)?;
        let mut out = vec![0.0; self.n_rows()];
        for j in nz {
            if let Some(col) = self.columns[j].as_deref() {
                for (o, c) in out.iter_mut().zip(col) {
                    *o += nu[j] * c;
                }
            }
        }
        Ok(out)
    }

    /// Interface values `y = C U = w − S ν`.
    pub fn interface_values(&mut self, nu: &[f64]) -> Result<Vec<f64>, ContactError> {
        let s = self.apply_s(nu)?;
        Ok(self.w.iter().zip(&s).map(|(w, s)| w - s).collect())
    }

    /// The displacement `U = A⁻¹ F − A⁻¹ (Cᵀ ν)` (one solve supported on the interface dofs,
    /// [`FactorisedOperator::solve_supported_in_place`]); empty when the context asks for
    /// the multipliers only ([`SolveContext::multipliers_only`]).
    #[tracing::instrument(level = "debug", skip_all)]
    pub fn displacement(&mut self, nu: &[f64]) -> Result<Vec<f64>, ContactError> {
        if self.context.multipliers_only() {
            return Ok(Vec::new());
        }
        let t0 = Instant::now();
        let mut rhs = vec![0.0; self.problem.load.len()];
        self.problem.apply_transpose_add(nu, &mut rhs);
        let u = match &self.load_solution {
            LoadSolution::Full(x) => {
                self.problem.operator.solve_supported_in_place(&mut rhs)?;
                rhs.iter_mut().zip(x.iter()).for_each(|(y, x)| *y = x - *y);
                rhs
            }
            // the backward half of the load's solve with the interface forces: one solve
            LoadSolution::Forward(y) => self.problem.operator.complete_forward(y, &rhs)?,
        };
        self.solves += 1;
        self.solve_s += t0.elapsed().as_secs_f64();
        Ok(u)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::BlockOnFoundation;
    use synovia_linalg::{Ordering, SparseCholesky};

    /// A dense interface block that holds the dofs of all rows but those of two contact nodes:
    /// the columns of `S` (block ones completed by symmetry) equal those of the whole factor.
    #[test]
    fn mixed_block_columns_match_whole_factor_columns() {
        let owned = BlockOnFoundation { n: 12, slip_bound: Some(0.1), ..Default::default() }
            .build::<2>()
            .expect("problem");
        let whole = owned.problem();
        let m = whole.n_normal();
        let excluded_dofs: std::collections::HashSet<usize> =
            [0, m / 2, m, m + m / 2].iter().flat_map(|&r| whole.row(r).map(|(i, _)| i)).collect();
        let mut last: Vec<usize> = (0..whole.n_rows())
            .flat_map(|r| whole.row(r).map(|(i, _)| i).collect::<Vec<_>>())
            .filter(|i| !excluded_dofs.contains(i))
            .collect();
        last.sort_unstable();
        last.dedup();
        let ordering = Ordering::Trailing { base: Box::new(Ordering::Amd), last };
        let blocked = SparseCholesky::new(owned.system.matrix.clone(), &ordering).expect("factorise");
        let (ctx_mixed, ctx_plain) = (SolveContext::new(), SolveContext::new());
        let mut mixed =
            Interface::new(ContactProblem { operator: &blocked, ..whole }, &ctx_mixed).expect("interface");
        let mut plain = Interface::new(whole, &ctx_plain).expect("interface");
        assert!(mixed.uses_dense_block() && !plain.uses_dense_block());
        let all: Vec<usize> = (0..whole.n_rows()).collect();
        // block columns first (the outside columns are computed on the way), then the rest
        mixed.ensure_columns(&[1, 2, m + 3]).expect("columns");
        mixed.ensure_columns(&all).expect("columns");
        plain.ensure_columns(&all).expect("columns");
        let scale =
            all.iter().filter_map(|&j| plain.column(j)).flatten().fold(0.0_f64, |a, b| a.max(b.abs()));
        for &j in &all {
            let (a, b) = (mixed.column(j).expect("mixed column"), plain.column(j).expect("column"));
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                assert!((x - y).abs() <= 1e-12 * scale, "S[{i}, {j}]: {x} vs {y}");
            }
        }
        let dw = mixed.w().iter().zip(plain.w()).fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(dw <= 1e-12 * crate::kkt::inf_norm(plain.w()));

        // the same through a context whose row solves come from an earlier interface with
        // other rows (the normal rows only): the shared solves give the same columns
        let context = SolveContext::new();
        let normal_only = ContactProblem { operator: &blocked, friction: None, ..whole };
        let mut first = Interface::new(normal_only, &context).expect("interface");
        first.ensure_columns(&(0..m).collect::<Vec<_>>()).expect("columns");
        let first_solves = first.solves();
        drop(first);
        let shared = context.sharing_solves();
        let mut cached =
            Interface::new(ContactProblem { operator: &blocked, ..whole }, &shared).expect("interface");
        assert_eq!(cached.solves(), 0, "the load solve is shared");
        cached.ensure_columns(&all).expect("columns");
        // the normal rows in the block were solved before: only the tangential rows and the
        // rows outside the block cost solves now
        assert!(cached.solves() < whole.n_rows() && first_solves > 0, "{} solves", cached.solves());
        for &j in &all {
            let (a, b) = (cached.column(j).expect("cached column"), plain.column(j).expect("column"));
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                assert!((x - y).abs() <= 1e-12 * scale, "cached S[{i}, {j}]: {x} vs {y}");
            }
        }
    }

    /// The columns kept between solves respect the memory budget.
    #[test]
    fn kept_columns_stay_within_the_memory_budget() {
        let owned = BlockOnFoundation { n: 12, slip_bound: Some(0.1), ..Default::default() }
            .build::<2>()
            .expect("problem");
        let p = owned.problem();
        let all: Vec<usize> = (0..p.n_rows()).collect();
        let column_bytes = p.n_rows() * 8;
        // room for 5 columns in the column half of the budget
        let context = SolveContext::with_memory_budget(2 * 5 * column_bytes);
        for _ in 0..3 {
            let mut i = Interface::new(p, &context).expect("interface");
            i.ensure_columns(&all).expect("columns");
        }
        assert_eq!(context.kept_columns(), 5);
        assert!(context.bytes() <= context.memory_budget());
        let unbounded = SolveContext::new();
        let mut i = Interface::new(p, &unbounded).expect("interface");
        i.ensure_columns(&all).expect("columns");
        drop(i);
        assert_eq!(unbounded.kept_columns(), p.n_rows());
        // a second interface of the same rows reuses them all: no column solves
        let mut again = Interface::new(p, &unbounded).expect("interface");
        again.ensure_columns(&all).expect("columns");
        assert_eq!(again.solves(), 0);
    }
}
