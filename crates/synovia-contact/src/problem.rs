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

use synovia_fem::{CholeskySolver, SymmetricMatrix};

use crate::error::ContactError;
use crate::rows::SparseRows;

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

/// One contact problem of docs/model.md §5: `A`, its factorisation, `F`, and the contact operators.
#[derive(Debug, Clone, Copy)]
pub struct ContactProblem<'a> {
    /// `A` (stiffness, or the time-step matrix), reduced unknowns.
    pub matrix: &'a SymmetricMatrix,
    /// A numeric factorisation of `matrix`.
    pub factor: &'a CholeskySolver,
    /// `F`.
    pub load: &'a [f64],
    /// Normal constraints.
    pub normal: &'a NormalConstraints,
    /// Friction constraints (`None`: frictionless).
    pub friction: Option<&'a FrictionConstraints>,
    /// Columns of `S` kept from an earlier [`Interface`] of the same `A` and the same rows
    /// (e.g. a re-solve with new loads, or the next time level on an unchanged geometry);
    /// `None`: no reuse.
    pub schur_cache: Option<&'a SchurCache>,
    /// `A⁻¹ F` when the caller already has it (e.g. from a
    /// [`synovia_fem::LoadSubspace`]); `None`: [`Interface::new`] solves for it.
    pub load_solution: Option<&'a [f64]>,
    /// Skip the final displacement `U = A⁻¹ (F − Cᵀ ν)` of the solvers (the returned
    /// solution's `u` is empty): for callers that need only the multipliers, e.g. the
    /// iterates of a load search, and complete `U` for the accepted one
    /// ([`crate::StaticContact::complete`]). The solvers use `U` only to return it.
    pub multipliers_only: bool,
}

/// Columns of the interface Schur complement `S = C A⁻¹ Cᵀ` kept between solves that share
/// `A` and `C` (only `F` and the gaps change). An [`Interface`] takes the columns when the
/// rows of `C` are identical to those they were computed for (compared by a fingerprint of
/// `C`'s entries) and hands them back, with any new ones, when it is dropped.
///
/// It also keeps the load solve `A⁻¹ F` of the last load (keyed by `F` and the factor) and the
/// trailing-block solves `L₂₂⁻ᵀ L₂₂⁻¹ c` of the rows `c` of `C` that live on the trailing dofs
/// (keyed by the row's entries and the block; up to [`MAX_KEPT_SOLVE_ENTRIES`] entries), which
/// every [`Interface`] shares, also through the caches made by [`SchurCache::sharing_solves`]:
/// the coarse levels of the nested iteration, the frictionless and the Tresca solve, and the
/// passes of a screened solve all have rows in common.
#[derive(Debug, Default)]
pub struct SchurCache {
    inner: std::sync::Mutex<Option<(u64, ColumnStore)>>,
    load: SharedLoadSolve,
    solves: std::sync::Arc<std::sync::Mutex<TrailingSolves>>,
}

/// `A⁻¹ F` with the fingerprint of `F` and the factor, shared between caches.
type SharedLoadSolve = std::sync::Arc<std::sync::Mutex<Option<(u64, std::sync::Arc<Vec<f64>>)>>>;

/// Trailing-block solves by row fingerprint, for one trailing block (its address).
#[derive(Debug, Default)]
struct TrailingSolves {
    block: usize,
    solves: std::collections::HashMap<u64, std::sync::Arc<Vec<f64>>>,
    entries: usize,
}

/// Largest number of entries of trailing-block solves a [`SchurCache`] keeps (512 MB); the
/// store is emptied when a new solve would exceed it.
pub const MAX_KEPT_SOLVE_ENTRIES: usize = 1 << 26;

/// Columns of `S` by row index (`None`: not computed).
type ColumnStore = Vec<Option<Vec<f64>>>;

impl SchurCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }
    /// Forgets every column, the load solve and the trailing-block solves (e.g. after the
    /// geometry or `A` changed).
    pub fn clear(&self) {
        *self.inner.lock().unwrap_or_else(|e| e.into_inner()) = None;
        *self.load.lock().unwrap_or_else(|e| e.into_inner()) = None;
        *self.solves.lock().unwrap_or_else(|e| e.into_inner()) = TrailingSolves::default();
    }
    /// An empty cache for problems with other rows that shares the load solve `A⁻¹ F` and the
    /// trailing-block solves of rows with `self` (computed once for all of them).
    pub fn sharing_solves(&self) -> Self {
        Self { inner: Default::default(), load: self.load.clone(), solves: self.solves.clone() }
    }
    fn trailing_solve(&self, block: usize, key: u64) -> Option<std::sync::Arc<Vec<f64>>> {
        let store = self.solves.lock().unwrap_or_else(|e| e.into_inner());
        if store.block != block {
            return None;
        }
        store.solves.get(&key).cloned()
    }
    fn put_trailing_solve(&self, block: usize, key: u64, x: std::sync::Arc<Vec<f64>>) {
        let mut store = self.solves.lock().unwrap_or_else(|e| e.into_inner());
        if store.block != block || store.entries + x.len() > MAX_KEPT_SOLVE_ENTRIES {
            *store = TrailingSolves { block, ..Default::default() };
        }
        store.entries += x.len();
        store.solves.insert(key, x);
    }
    fn load_solve(&self, key: u64) -> Option<std::sync::Arc<Vec<f64>>> {
        match &*self.load.lock().unwrap_or_else(|e| e.into_inner()) {
            Some((k, x)) if *k == key => Some(x.clone()),
            _ => None,
        }
    }
    fn put_load_solve(&self, key: u64, x: std::sync::Arc<Vec<f64>>) {
        *self.load.lock().unwrap_or_else(|e| e.into_inner()) = Some((key, x));
    }
    /// Number of columns held.
    pub fn len(&self) -> usize {
        self.inner
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .as_ref()
            .map_or(0, |(_, c)| c.iter().filter(|c| c.is_some()).count())
    }
    /// `true` if no column is held.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn take(&self, fingerprint: u64, m: usize) -> Vec<Option<Vec<f64>>> {
        let mut guard = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        match guard.take() {
            Some((f, cols)) if f == fingerprint && cols.len() == m => cols,
            _ => vec![None; m],
        }
    }
    fn put(&self, fingerprint: u64, columns: Vec<Option<Vec<f64>>>) {
        *self.inner.lock().unwrap_or_else(|e| e.into_inner()) = Some((fingerprint, columns));
    }
}

impl<'a> ContactProblem<'a> {
    /// A fingerprint of the rows of `C = [B_hn; B_Ht]` and the size of `A` (for [`SchurCache`]).
    pub fn rows_fingerprint(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.matrix.n().hash(&mut h);
        (self.factor as *const CholeskySolver as usize).hash(&mut h);
        self.n_rows().hash(&mut h);
        for r in 0..self.n_rows() {
            for (i, v) in self.row(r) {
                i.hash(&mut h);
                v.to_bits().hash(&mut h);
            }
            usize::MAX.hash(&mut h);
        }
        h.finish()
    }

    /// A fingerprint of `F`, the size of `A` and its factorisation (for the load solve kept
    /// in a [`SchurCache`]).
    fn load_fingerprint(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.matrix.n().hash(&mut h);
        (self.factor as *const CholeskySolver as usize).hash(&mut h);
        for f in self.load {
            f.to_bits().hash(&mut h);
        }
        h.finish()
    }

    /// Checks sizes and finiteness.
    pub fn validate(&self) -> Result<(), ContactError> {
        let n = self.matrix.n();
        let bad = |m: String| Err(ContactError::InvalidParameter(m));
        if self.factor.n() != n || self.load.len() != n {
            return bad(format!("A is {n}×{n}, factor {} and load {}", self.factor.n(), self.load.len()));
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
        Ok(())
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
    pub fn row(&self, r: usize) -> Box<dyn Iterator<Item = (usize, f64)> + '_> {
        let m = self.n_normal();
        if r < m {
            Box::new(self.normal.rows.row(r))
        } else {
            match self.friction {
                Some(f) => Box::new(f.rows.row(r - m)),
                None => Box::new(std::iter::empty()),
            }
        }
    }

    /// `C x`.
    pub fn apply(&self, x: &[f64]) -> Vec<f64> {
        let mut y = self.normal.rows.mul(x);
        if let Some(f) = self.friction {
            y.extend(f.rows.mul(x));
        }
        y
    }

    /// `out += Cᵀ ν`.
    pub fn apply_transpose_add(&self, nu: &[f64], out: &mut [f64]) {
        let m = self.n_normal();
        self.normal.rows.mul_transpose_add(&nu[..m], out);
        if let Some(f) = self.friction {
            f.rows.mul_transpose_add(&nu[m..], out);
        }
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
    /// `ρ_r = scale · mean diag(A) / ‖C_r‖²` in force-multiplier units, which is the spec's
    /// `ρ ≈ mean diag(A) / κ` for the normal rows. The solution does not depend on `ρ`.
    pub fn default_rho(&self, scale: f64) -> Vec<f64> {
        let diag = self.matrix.diagonal();
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

/// Lazily evaluated interface Schur complement `S = C A⁻¹ Cᵀ` and the interface load
/// `w = C A⁻¹ F` (docs/model.md §6.4).
#[derive(Debug)]
pub struct Interface<'a> {
    problem: ContactProblem<'a>,
    /// `A⁻¹ F`.
    load_solution: std::sync::Arc<Vec<f64>>,
    w: Vec<f64>,
    columns: Vec<Option<Vec<f64>>>,
    solves: usize,
    solve_s: f64,
    /// The rows of `C` in the positions of the factor's trailing block
    /// ([`synovia_fem::TrailingBlock`]), `None` for a row with a dof outside it; kept when at
    /// most a fifth of the rows are outside. Columns of `S` of trailing rows then cost two
    /// dense triangular solves with `L₂₂` instead of a solve with the whole factor; their
    /// entries in the other rows `i` are taken from the (whole-factor) columns `i` by symmetry.
    trailing: Option<(std::sync::Arc<synovia_fem::TrailingBlock>, TrailingRows)>,
    /// Where the columns go back when the interface is dropped.
    cache: Option<(&'a SchurCache, u64)>,
}

impl Drop for Interface<'_> {
    fn drop(&mut self) {
        if let Some((cache, fingerprint)) = self.cache {
            cache.put(fingerprint, std::mem::take(&mut self.columns));
        }
    }
}

/// Rows of `C` as `(trailing position, value)` lists (`None`: a row with a dof outside the
/// trailing block).
type TrailingRows = Vec<Option<Vec<(usize, f64)>>>;

impl<'a> Interface<'a> {
    /// Validates the problem and computes `w = C A⁻¹ F` (one solve, unless the problem's
    /// [`SchurCache`] holds `A⁻¹ F` for the same `F` and factor).
    pub fn new(problem: ContactProblem<'a>) -> Result<Self, ContactError> {
        problem.validate()?;
        let t0 = Instant::now();
        let load_key = problem.schur_cache.map(|c| (c, problem.load_fingerprint()));
        let given = problem.load_solution.filter(|x| x.len() == problem.load.len());
        let (x, solves) = match given.map(|x| std::sync::Arc::new(x.to_vec())) {
            Some(x) => (x, 0),
            None => match load_key.and_then(|(c, k)| c.load_solve(k)) {
                Some(x) => (x, 0),
                None => {
                    let mut x = problem.load.to_vec();
                    problem.factor.solve_in_place(&mut x)?;
                    let x = std::sync::Arc::new(x);
                    if let Some((c, k)) = load_key {
                        c.put_load_solve(k, x.clone());
                    }
                    (x, 1)
                }
            },
        };
        let w = problem.apply(&x);
        let m = problem.n_rows();
        let trailing = problem.factor.trailing().and_then(|block| {
            let rows: TrailingRows = (0..m)
                .map(|r| {
                    problem
                        .row(r)
                        .map(|(i, v)| match block.position.get(i).copied() {
                            Some(p) if p != usize::MAX => Some((p, v)),
                            _ => None,
                        })
                        .collect::<Option<Vec<_>>>()
                })
                .collect();
            let outside = rows.iter().filter(|r| r.is_none()).count();
            (outside * 5 <= m && outside < m).then(|| (block.clone(), rows))
        });
        let cache = problem.schur_cache.map(|c| (c, problem.rows_fingerprint()));
        let columns = match cache {
            Some((c, f)) => c.take(f, m),
            None => vec![None; m],
        };
        Ok(Self {
            problem,
            load_solution: x,
            w,
            columns,
            solves,
            solve_s: t0.elapsed().as_secs_f64(),
            trailing,
            cache,
        })
    }

    /// `true` if the columns of `S` come from the trailing block of the factor.
    pub fn uses_trailing_block(&self) -> bool {
        self.trailing.is_some()
    }

    /// The problem.
    pub fn problem(&self) -> &ContactProblem<'a> {
        &self.problem
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

    /// Makes sure the columns `cols` of `S` are computed (batched solves, 32 right-hand sides
    /// at a time).
    pub fn ensure_columns(&mut self, cols: &[usize]) -> Result<(), ContactError> {
        let missing: Vec<usize> = {
            let mut v: Vec<usize> = cols.iter().copied().filter(|&j| self.columns[j].is_none()).collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        if missing.is_empty() {
            return Ok(());
        }
        let t0 = Instant::now();
        let problem = self.problem;
        let Some((block, rows)) = self.trailing.take() else {
            let computed = in_two_halves(&missing, true, |cols| schur_columns(&problem, cols))?;
            self.store(computed, t0);
            return Ok(());
        };
        let result = self.mixed_columns(&block, &rows, &missing);
        self.trailing = Some((block, rows));
        result
    }

    /// [`Interface::ensure_columns`] with a trailing block: whole-factor columns for the rows
    /// outside the block (all of them as soon as a trailing column is needed), then the
    /// trailing columns, completed in the outside rows by symmetry `S_ij = S_ji`.
    fn mixed_columns(
        &mut self,
        block: &synovia_fem::TrailingBlock,
        rows: &[Option<Vec<(usize, f64)>>],
        missing: &[usize],
    ) -> Result<(), ContactError> {
        let problem = self.problem;
        let (inside, mut outside): (Vec<usize>, Vec<usize>) =
            missing.iter().partition(|&&j| rows[j].is_some());
        if !inside.is_empty() {
            outside = (0..rows.len()).filter(|&j| rows[j].is_none() && self.columns[j].is_none()).collect();
        }
        if !outside.is_empty() {
            let t0 = Instant::now();
            let computed = in_two_halves(&outside, true, |cols| schur_columns(&problem, cols))?;
            self.store(computed, t0);
        }
        if !inside.is_empty() {
            let t0 = Instant::now();
            // trailing solves kept in the cache (rows shared with earlier interfaces), the others
            let cache = self.cache.map(|(c, _)| c);
            let block_id = block_fingerprint(block);
            let keys: Vec<u64> = inside.iter().map(|&j| row_fingerprint(rows[j].as_deref())).collect();
            let mut solves: Vec<Option<std::sync::Arc<Vec<f64>>>> =
                keys.iter().map(|&key| cache.and_then(|c| c.trailing_solve(block_id, key))).collect();
            let todo: Vec<usize> = (0..inside.len()).filter(|&a| solves[a].is_none()).collect();
            let todo_rows: Vec<usize> = todo.iter().map(|&a| inside[a]).collect();
            let solved = in_two_halves(&todo_rows, block.dofs.len() >= 256, |cols| {
                Ok(trailing_solves(block, rows, cols))
            })?;
            for (&a, (_, x)) in todo.iter().zip(solved) {
                let x = std::sync::Arc::new(x);
                if let Some(c) = cache {
                    c.put_trailing_solve(block_id, keys[a], x.clone());
                }
                solves[a] = Some(x);
            }
            for (&j, x) in inside.iter().zip(&solves) {
                let Some(x) = x else { continue };
                let col = rows
                    .iter()
                    .enumerate()
                    .map(|(i, row)| match row {
                        Some(row) => row.iter().map(|&(p, v)| v * x[p]).sum(),
                        // outside the block: S_ij = S_ji from the whole-factor column i
                        None => self.columns[i].as_ref().map_or(0.0, |c| c[j]),
                    })
                    .collect();
                self.columns[j] = Some(col);
            }
            self.solves += todo.len();
            self.solve_s += t0.elapsed().as_secs_f64();
        }
        Ok(())
    }

    fn store(&mut self, computed: Vec<(usize, Vec<f64>)>, t0: Instant) {
        self.solves += computed.len();
        for (j, col) in computed {
            self.columns[j] = Some(col);
        }
        self.solve_s += t0.elapsed().as_secs_f64();
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

    /// The displacement `U = A⁻¹ (F − Cᵀ ν)` (one solve; half a solve when every row lies on
    /// the trailing dofs, [`synovia_fem::CholeskySolver::solve_trailing_supported_in_place`]);
    /// empty for a [`ContactProblem::multipliers_only`] problem.
    pub fn displacement(&mut self, nu: &[f64]) -> Result<Vec<f64>, ContactError> {
        if self.problem.multipliers_only {
            return Ok(Vec::new());
        }
        let t0 = Instant::now();
        // U = A⁻¹F − A⁻¹(Cᵀν) with A⁻¹F from `new`: when every row lies on the trailing dofs
        // the right-hand side Cᵀν vanishes outside them and the solve is half a solve; it falls
        // back to a full solve otherwise (no block, or rows outside it)
        let mut rhs = vec![0.0; self.load_solution.len()];
        self.problem.apply_transpose_add(nu, &mut rhs);
        self.problem.factor.solve_trailing_supported_in_place(&mut rhs)?;
        rhs.iter_mut().zip(self.load_solution.iter()).for_each(|(y, x)| *y = x - *y);
        self.solves += 1;
        self.solve_s += t0.elapsed().as_secs_f64();
        Ok(rhs)
    }
}

/// Runs `columns` on the two halves of `cols` on two threads when there is enough work (at
/// least 64 columns and `worth_splitting`), else on all of them at once: triangular solves with
/// many right-hand sides do not parallelise well inside faer (notes: faer-0.24.md), so the
/// right-hand sides are split instead.
fn in_two_halves(
    cols: &[usize],
    worth_splitting: bool,
    columns: impl Fn(&[usize]) -> Result<Vec<(usize, Vec<f64>)>, ContactError> + Sync,
) -> Result<Vec<(usize, Vec<f64>)>, ContactError> {
    if cols.len() < 64 || !worth_splitting {
        return columns(cols);
    }
    let (a, b) = cols.split_at(cols.len() / 2);
    let (ra, rb) = std::thread::scope(|scope| {
        let ha = scope.spawn(|| columns(a));
        let rb = columns(b);
        (ha.join(), rb)
    });
    let mut ra = ra.map_err(|_| ContactError::InvalidParameter("a column worker panicked".into()))??;
    ra.extend(rb?);
    Ok(ra)
}

/// The trailing-block solves `x_j = L₂₂⁻ᵀ L₂₂⁻¹ c_j` (in trailing positions) of the rows
/// `j ∈ cols` (`rows`: the rows of `C` in trailing positions; every `j ∈ cols` must be one):
/// dense triangular solves with all right-hand sides at once. `S_ij = c_i · x_j` for the rows
/// `i` in the block.
fn trailing_solves(
    block: &synovia_fem::TrailingBlock,
    rows: &[Option<Vec<(usize, f64)>>],
    cols: &[usize],
) -> Vec<(usize, Vec<f64>)> {
    let mut rhs = faer::Mat::<f64>::zeros(block.dofs.len(), cols.len());
    for (c, &j) in cols.iter().enumerate() {
        for &(p, v) in rows[j].iter().flatten() {
            rhs[(p, c)] += v;
        }
    }
    block.solve_in_place(rhs.as_mut());
    cols.iter().enumerate().map(|(c, &j)| (j, rhs.col(c).iter().copied().collect())).collect()
}

/// A fingerprint of a trailing block: its address, size and corner entries.
fn block_fingerprint(block: &synovia_fem::TrailingBlock) -> usize {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (block as *const synovia_fem::TrailingBlock as usize).hash(&mut h);
    let k = block.dofs.len();
    k.hash(&mut h);
    if k > 0 {
        block.factor[(0, 0)].to_bits().hash(&mut h);
        block.factor[(k - 1, k - 1)].to_bits().hash(&mut h);
    }
    h.finish() as usize
}

/// A fingerprint of a row in trailing positions (for the trailing solves of [`SchurCache`]).
fn row_fingerprint(row: Option<&[(usize, f64)]>) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for &(p, v) in row.into_iter().flatten() {
        p.hash(&mut h);
        v.to_bits().hash(&mut h);
    }
    h.finish()
}

/// Columns `j ∈ cols` of `S = C A⁻¹ Cᵀ`: batched solves, 32 right-hand sides at a time.
fn schur_columns(
    problem: &ContactProblem<'_>,
    cols: &[usize],
) -> Result<Vec<(usize, Vec<f64>)>, ContactError> {
    let n = problem.matrix.n();
    let mut out = Vec::with_capacity(cols.len());
    for chunk in cols.chunks(32) {
        let k = chunk.len();
        let mut rhs = faer::Mat::<f64>::zeros(n, k);
        for (c, &j) in chunk.iter().enumerate() {
            for (i, v) in problem.row(j) {
                rhs[(i, c)] += v;
            }
        }
        problem.factor.solve_many_in_place(rhs.as_mut())?;
        for (c, &j) in chunk.iter().enumerate() {
            let col: Vec<f64> = rhs.col(c).iter().copied().collect();
            out.push((j, problem.apply(&col)));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::BlockOnFoundation;
    use synovia_fem::Ordering;

    /// A trailing block that holds the dofs of all rows but those of two contact nodes: the
    /// columns of `S` (trailing ones completed by symmetry) equal those of the whole factor.
    #[test]
    fn mixed_trailing_columns_match_whole_factor_columns() {
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
        let mut factor = CholeskySolver::analyse(&owned.matrix, &ordering).expect("analyse");
        factor.factorize(&owned.matrix).expect("factorise");
        let mut mixed = Interface::new(ContactProblem { factor: &factor, ..whole }).expect("interface");
        let mut plain = Interface::new(whole).expect("interface");
        assert!(mixed.uses_trailing_block() && !plain.uses_trailing_block());
        let outside =
            mixed.trailing.as_ref().map_or(0, |(_, rows)| rows.iter().filter(|r| r.is_none()).count());
        assert_eq!(outside, 4, "two normal and two tangential rows outside the block");
        let all: Vec<usize> = (0..whole.n_rows()).collect();
        // trailing columns first (the outside columns are computed on the way), then the rest
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

        // the same through a cache whose trailing solves come from an earlier interface with
        // other rows (the normal rows only): the shared solves give the same columns
        let cache = SchurCache::new();
        let normal_only =
            ContactProblem { factor: &factor, friction: None, schur_cache: Some(&cache), ..whole };
        let mut first = Interface::new(normal_only).expect("interface");
        first.ensure_columns(&(0..m).collect::<Vec<_>>()).expect("columns");
        let first_solves = first.solves();
        drop(first);
        let shared = cache.sharing_solves();
        let mut cached =
            Interface::new(ContactProblem { factor: &factor, schur_cache: Some(&shared), ..whole })
                .expect("interface");
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
}
