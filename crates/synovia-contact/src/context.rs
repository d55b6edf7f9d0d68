//! The caller-owned state of contact solves: warm start, kept interface columns, recycled
//! load solves, under a memory budget.
//!
//! A [`crate::ContactProblem`] holds only the mathematics of docs/model.md §5 (the operator
//! `A`, the load `F`, the rows, gaps and bounds). Everything a sequence of solves can reuse
//! lives here, in one object the caller owns and passes to
//! [`crate::ContactSolver::solve`]:
//! - the **warm start**: a previous solution of a nearby problem with the same rows;
//! - the **columns of `S = C A⁻¹ Cᵀ`** of the last interface (docs/model.md §6.4), reused when
//!   the next problem has the same operator and rows (only `F` and the gaps changed);
//! - the **load solve** `A⁻¹ F` of the last load, and recycled load solves in the span of the
//!   loads solved before ([`synovia_linalg::LoadSubspace`]);
//! - **row solves** of the dense interface block shared between interfaces with rows in
//!   common ([`BlockSolveStore`]).
//!
//! Caches never grow without bound: the columns kept between solves hold at most half of the
//! context's memory budget and the row solves a quarter ([`SolveContext::with_memory_budget`],
//! default [`SolveContext::DEFAULT_MEMORY_BUDGET`]: 1 GiB and 512 MiB); the load subspace
//! keeps a fixed number of directions. A navigation loop may call a solve millions of times on one context.

use std::sync::{Arc, Mutex};

use synovia_linalg::{BlockSolveStore, FactorisedOperator, LoadSubspace};

use crate::error::ContactError;
use crate::solver::ContactSolution;

/// Columns of `S` by row index (`None`: not computed), with the fingerprint of the operator
/// and rows they belong to.
type KeptColumns = Arc<Mutex<Option<(u64, Vec<Option<Vec<f64>>>)>>>;
/// `A⁻¹ F` with the fingerprint of `F` and the operator.
type KeptLoadSolve = Arc<Mutex<Option<(u64, Arc<Vec<f64>>)>>>;

/// The caller-owned context of contact solves (see the [module documentation](self)).
///
/// Cloning with [`SolveContext::with_start`] or [`SolveContext::sharing_solves`] gives a
/// handle that shares the caches; the warm start and the `multipliers_only` flag belong to
/// each handle.
#[derive(Debug)]
pub struct SolveContext {
    warm_start: Option<ContactSolution>,
    multipliers_only: bool,
    load_solution: Option<Arc<Vec<f64>>>,
    columns: KeptColumns,
    load: KeptLoadSolve,
    row_solves: Arc<BlockSolveStore>,
    recycled: Arc<Mutex<LoadSubspace>>,
    forward: Arc<Mutex<ForwardSpan>>,
    memory_budget: usize,
}

impl Default for SolveContext {
    fn default() -> Self {
        Self::with_memory_budget(Self::DEFAULT_MEMORY_BUDGET)
    }
}

impl SolveContext {
    /// Default memory budget of the caches: 2 GiB.
    pub const DEFAULT_MEMORY_BUDGET: usize = 2 << 30;
    /// Directions kept by the recycled load solves.
    pub const RECYCLED_LOADS: usize = 6;

    /// An empty context with the default budget, no warm start.
    pub fn new() -> Self {
        Self::default()
    }
    /// An empty context whose caches hold at most `bytes` (half for the kept columns of `S`,
    /// a quarter for the row solves; the recycled load solves keep
    /// [`Self::RECYCLED_LOADS`] directions besides).
    pub fn with_memory_budget(bytes: usize) -> Self {
        Self {
            warm_start: None,
            multipliers_only: false,
            load_solution: None,
            columns: Arc::default(),
            load: Arc::default(),
            row_solves: Arc::new(BlockSolveStore::with_budget(bytes / 4)),
            recycled: Arc::new(Mutex::new(LoadSubspace::new(Self::RECYCLED_LOADS))),
            forward: Arc::default(),
            memory_budget: bytes,
        }
    }
    /// A context with the warm start `warm` (and the default budget).
    pub fn warm(warm: ContactSolution) -> Self {
        let mut c = Self::new();
        c.warm_start = Some(warm);
        c
    }
    /// A handle sharing every cache of `self`, with its own warm start and
    /// `multipliers_only` flag.
    pub fn with_start(&self, warm_start: Option<ContactSolution>, multipliers_only: bool) -> Self {
        Self {
            warm_start,
            multipliers_only,
            load_solution: self.load_solution.clone(),
            columns: self.columns.clone(),
            load: self.load.clone(),
            row_solves: self.row_solves.clone(),
            recycled: self.recycled.clone(),
            forward: self.forward.clone(),
            memory_budget: self.memory_budget,
        }
    }
    /// A handle for problems with other rows: shares the load solve, the row solves and the
    /// recycled loads of `self`, with columns of its own and no warm start.
    pub fn sharing_solves(&self) -> Self {
        Self { columns: Arc::default(), ..self.with_start(None, false) }
    }
    /// The memory budget in bytes.
    pub fn memory_budget(&self) -> usize {
        self.memory_budget
    }
    /// Bytes held by the kept columns and row solves now.
    pub fn bytes(&self) -> usize {
        let columns = lock(&self.columns)
            .as_ref()
            .map_or(0, |(_, c)| c.iter().flatten().map(|c| c.len() * 8).sum::<usize>());
        columns + self.row_solves.bytes()
    }
    /// The warm start (a previous solution of a nearby problem with the same rows).
    pub fn warm_start(&self) -> Option<&ContactSolution> {
        self.warm_start.as_ref()
    }
    /// Sets the warm start.
    pub fn set_warm_start(&mut self, warm_start: Option<ContactSolution>) {
        self.warm_start = warm_start;
    }
    /// `true`: the solvers skip the final displacement `U = A⁻¹ (F − Cᵀ ν)` (the returned
    /// solution's `u` is empty), for callers that need only the multipliers (the iterates of
    /// a load search).
    pub fn multipliers_only(&self) -> bool {
        self.multipliers_only
    }
    /// Sets [`Self::multipliers_only`].
    pub fn set_multipliers_only(&mut self, multipliers_only: bool) {
        self.multipliers_only = multipliers_only;
    }
    /// `A⁻¹ F` given by the caller for the next problems (e.g. from
    /// [`SolveContext::recycled_load_solve`]); `None`: the interface solves for it.
    pub fn set_load_solution(&mut self, x: Option<Vec<f64>>) {
        self.load_solution = x.map(Arc::new);
    }
    /// Forgets every kept column, load solve, row solve and recycled load (after the
    /// operator or the geometry changed). The warm start stays.
    pub fn clear(&self) {
        *lock(&self.columns) = None;
        *lock(&self.load) = None;
        self.row_solves.clear();
        lock(&self.recycled).clear();
        lock(&self.forward).clear();
    }
    /// Forgets the kept columns of `S`, the load solve and the row solves, keeping the
    /// recycled load solves (new rows on the same operator: a new geometry or pose).
    pub fn clear_rows(&self) {
        *lock(&self.columns) = None;
        *lock(&self.load) = None;
        self.row_solves.clear();
    }
    /// Forgets the kept columns of `S` and the load solve, keeping the row solves (keyed by
    /// the factor and the rows' directions or dofs, so they stay valid on the same operator)
    /// and the recycled load solves, and keeps unit solves from now on
    /// ([`BlockSolveStore::set_unit_solves`]): the rows of a moving rigid partner, rebuilt at
    /// every pose.
    pub fn clear_moved_rows(&self) {
        *lock(&self.columns) = None;
        *lock(&self.load) = None;
        self.row_solves.set_unit_solves(true);
    }
    /// Forgets the kept columns of `S`, the load solve and the row solves of directions on
    /// more than one dof, keeping the unit solves and the recycled load solves, and keeps unit
    /// solves from now on ([`BlockSolveStore::set_unit_solves`]): rows rebuilt on a deformed
    /// configuration with the factorisation kept (the geometry passes of a finite-strain Newton
    /// iteration while its tangent is kept, re-pairing between time levels). A node's rows,
    /// whatever their new normal and tangents, combine its kept unit solves; solves of other
    /// directions are dropped, as they would not recur.
    pub fn clear_deformed_rows(&self) {
        *lock(&self.columns) = None;
        *lock(&self.load) = None;
        self.row_solves.retain_unit_solves();
        self.row_solves.set_unit_solves(true);
    }
    /// Number of columns of `S` kept.
    pub fn kept_columns(&self) -> usize {
        lock(&self.columns).as_ref().map_or(0, |(_, c)| c.iter().filter(|c| c.is_some()).count())
    }
    /// `(reused, solved)` counts of the recycled load solves.
    pub fn recycled_counts(&self) -> (usize, usize) {
        lock(&self.recycled).counts()
    }
    /// `A⁻¹ F` through the recycled load solves: from the span of the loads solved before
    /// when the residual bound allows it, else one solve (docs/model.md §6.4).
    ///
    /// # Errors
    /// Sizes, or a failed solve.
    pub fn recycled_load_solve(
        &self,
        operator: &dyn FactorisedOperator,
        load: &[f64],
    ) -> Result<Vec<f64>, ContactError> {
        Ok(lock(&self.recycled).solve(operator, load)?)
    }
    /// The forward half `y = L⁻¹ P F` of `load` from the forward halves of the loads solved
    /// before on this factorisation ([`ForwardSpan`]), when `load` lies in their span; `None`
    /// otherwise.
    pub(crate) fn forward_from_span(&self, load: &[f64]) -> Option<Vec<f64>> {
        lock(&self.forward).combine(load)
    }
    /// Keeps the forward half `y` of `load` (solved) for [`Self::forward_from_span`].
    pub(crate) fn put_forward(&self, load: &[f64], y: &Arc<Vec<f64>>) {
        lock(&self.forward).push(load, y);
    }
    /// `(recycled, solved)` counts of the forward halves since the last [`Self::clear`].
    pub fn forward_counts(&self) -> (usize, usize) {
        let f = lock(&self.forward);
        (f.recycled, f.solved)
    }
    pub(crate) fn given_load_solution(&self, n: usize) -> Option<Arc<Vec<f64>>> {
        self.load_solution.clone().filter(|x| x.len() == n)
    }
    pub(crate) fn row_solves(&self) -> &BlockSolveStore {
        &self.row_solves
    }
    pub(crate) fn load_solve(&self, key: u64) -> Option<Arc<Vec<f64>>> {
        match &*lock(&self.load) {
            Some((k, x)) if *k == key => Some(x.clone()),
            _ => None,
        }
    }
    pub(crate) fn put_load_solve(&self, key: u64, x: Arc<Vec<f64>>) {
        *lock(&self.load) = Some((key, x));
    }
    pub(crate) fn take_columns(&self, fingerprint: u64, m: usize) -> Vec<Option<Vec<f64>>> {
        match lock(&self.columns).take() {
            Some((f, cols)) if f == fingerprint && cols.len() == m => cols,
            _ => vec![None; m],
        }
    }
    /// Keeps `columns` for the next interface, within half the memory budget (columns beyond
    /// it are dropped, the lowest rows kept first).
    pub(crate) fn put_columns(&self, fingerprint: u64, mut columns: Vec<Option<Vec<f64>>>) {
        let budget = self.memory_budget / 2;
        let mut bytes = 0usize;
        for c in columns.iter_mut() {
            if let Some(col) = c {
                let b = col.len() * std::mem::size_of::<f64>();
                if bytes + b > budget {
                    *c = None;
                } else {
                    bytes += b;
                }
            }
        }
        *lock(&self.columns) = Some((fingerprint, columns));
    }
}

/// Forward halves `y_j = L⁻¹ P F_j` of the last loads `F_j` solved on one factorisation, for
/// loads in their span: a load `F = Σ_j a_j F_j + r` with `‖r‖ ≤ 10⁻¹³ ‖F‖` has the forward
/// half `Σ_j a_j y_j` (the forward half is linear in the load), no solve. The case it is for:
/// the trials of a load control on one factorisation (`synovia-nonlinear`), whose loads are
/// affine in the control, `F(δ) = F(δ₀) + (δ − δ₀) d` — with the direction `d` in the span of
/// two earlier trials, every trial after the first of a Newton iteration is recycled. The
/// loads are kept as an orthonormal basis `Q` (modified Gram–Schmidt, twice) with `F_j = Σ_i
/// R_ij q_i`; `a = R⁻¹ Qᵀ F`. A combination whose coefficients would amplify rounding
/// (`Σ |a_j| ‖F_j‖ > 10³ ‖F‖`) is solved instead; a load nearly dependent on the basis
/// (`‖r‖ < 10⁻¹⁰ ‖F‖` but above the bound) is solved and not added; when
/// [`ForwardSpan::CAPACITY`] loads are kept the basis restarts from the new one.
#[derive(Debug, Default)]
pub(crate) struct ForwardSpan {
    /// Orthonormal directions of the kept loads.
    q: Vec<Vec<f64>>,
    /// `R` by columns: `F_j = Σ_{i ≤ j} r[j][i] q_i`.
    r: Vec<Vec<f64>>,
    /// The kept loads' norms and forward halves.
    norms: Vec<f64>,
    y: Vec<Arc<Vec<f64>>>,
    recycled: usize,
    solved: usize,
}

impl ForwardSpan {
    /// Loads kept at most.
    pub(crate) const CAPACITY: usize = 8;
    const IN_SPAN: f64 = 1e-13;
    const NEW_DIRECTION: f64 = 1e-10;
    const AMPLIFICATION: f64 = 1e3;

    fn clear(&mut self) {
        *self = Self::default();
    }

    /// `Qᵀ F` (two passes of modified Gram–Schmidt) and the residual `F − Q Qᵀ F`.
    fn project(&self, load: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut r = load.to_vec();
        let mut c = vec![0.0; self.q.len()];
        for _ in 0..2 {
            for (cj, q) in c.iter_mut().zip(&self.q) {
                let d: f64 = q.iter().zip(&r).map(|(a, b)| a * b).sum();
                r.iter_mut().zip(q).for_each(|(ri, qi)| *ri -= d * qi);
                *cj += d;
            }
        }
        (c, r)
    }

    fn combine(&mut self, load: &[f64]) -> Option<Vec<f64>> {
        let k = self.q.len();
        if k == 0 || self.y.iter().any(|y| y.len() != load.len()) {
            return None;
        }
        let norm = load.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            return None;
        }
        let (c, r) = self.project(load);
        let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        if rn > Self::IN_SPAN * norm {
            return None;
        }
        // R a = c (R upper triangular, by columns)
        let mut a = c;
        for j in (0..k).rev() {
            let d = self.r[j][j];
            if d == 0.0 {
                return None;
            }
            a[j] /= d;
            let aj = a[j];
            for (i, ai) in a.iter_mut().enumerate().take(j) {
                *ai -= self.r[j][i] * aj;
            }
        }
        let weight: f64 = a.iter().zip(&self.norms).map(|(a, n)| a.abs() * n).sum();
        if !weight.is_finite() || weight > Self::AMPLIFICATION * norm {
            return None;
        }
        let mut y = vec![0.0; load.len()];
        for (aj, yj) in a.iter().zip(&self.y) {
            y.iter_mut().zip(yj.iter()).for_each(|(o, v)| *o += aj * v);
        }
        self.recycled += 1;
        Some(y)
    }

    fn push(&mut self, load: &[f64], y: &Arc<Vec<f64>>) {
        self.solved += 1;
        let norm = load.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() || y.len() != load.len() {
            return;
        }
        if self.q.len() >= Self::CAPACITY || self.y.iter().any(|v| v.len() != load.len()) {
            let (recycled, solved) = (self.recycled, self.solved);
            *self = Self { recycled, solved, ..Self::default() };
        }
        let (mut c, r) = self.project(load);
        let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        if rn < Self::NEW_DIRECTION * norm {
            return;
        }
        c.push(rn);
        self.q.push(r.into_iter().map(|v| v / rn).collect());
        self.r.push(c);
        self.norms.push(norm);
        self.y.push(y.clone());
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}
