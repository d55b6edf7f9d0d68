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

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}
