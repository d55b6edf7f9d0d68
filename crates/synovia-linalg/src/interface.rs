//! Columns of the interface Schur complement `S = C A⁻¹ Cᵀ` (docs/model.md §6.4): by batched
//! solves for any [`FactorisedOperator`], and from the dense trailing block `L₂₂` of a
//! Cholesky factor with the interface dofs ordered last.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use crate::cholesky::{CholeskySolver, TrailingBlock};
use crate::error::LinalgError;
use crate::operator::{CholeskyOperator, FactorisedOperator, RowStack};

/// Solves of single interface rows kept between interfaces that share rows (the coarse levels
/// of a nested iteration, a frictionless and a Tresca solve, the passes of a screened solve):
/// `x_c = L₂₂⁻ᵀ L₂₂⁻¹ c` for the rows `c` on the trailing block of a Cholesky factor, keyed by
/// the block and the row's *direction* `d = c / s` (`s`: the entry of largest magnitude), so
/// rows that differ only by a factor share one solve `x_c = s x_d` — the friction rows
/// `g_c,r κ_r T_rᵀ` of docs/model.md (5.6) change their scale `g_c,r` at every time level but
/// not their direction. Holds at most [`BlockSolveStore::budget_bytes`]; a solve that would
/// exceed it empties the store first, so it never grows without bound.
#[derive(Debug)]
pub struct BlockSolveStore {
    inner: Mutex<BlockSolves>,
    budget_bytes: usize,
    /// Whole-factor interfaces: keep unit solves restricted to the interface dofs (see
    /// [`BlockSolveStore::set_unit_solves`]).
    unit_solves: std::sync::atomic::AtomicBool,
}

#[derive(Debug, Default)]
struct BlockSolves {
    block: usize,
    solves: HashMap<u64, StoredSolve>,
    bytes: usize,
    /// Counts the uses of the store (the age of a kept solve is the tick of its last use).
    tick: u64,
    /// Whole-factor unit solves: the dofs they are restricted to (sorted).
    support: Arc<Vec<usize>>,
    /// The last interface rows' entries as `(position in support, value)`, with the rows'
    /// fingerprint.
    row_positions: Option<(u64, RowPositions)>,
}

type RowPositions = Arc<Vec<Vec<(usize, f64)>>>;

/// A kept solve `x_d` of the row direction `d`.
#[derive(Debug)]
struct StoredSolve {
    direction: Vec<(usize, f64)>,
    solve: Arc<Vec<f64>>,
    /// The store's tick when it was last kept or used.
    last_use: u64,
}

impl StoredSolve {
    /// Bytes it holds (the solve and the direction's index–value pairs).
    fn bytes(&self) -> usize {
        (self.solve.len() + 2 * self.direction.len()) * std::mem::size_of::<f64>()
    }
}

/// A row in trailing positions as `s · d`: `s` its entry of largest magnitude (the first of
/// equal ones; 1 for an empty or zero row) and `d = row / s`.
#[derive(Debug)]
pub(crate) struct RowDirection {
    scale: f64,
    direction: Vec<(usize, f64)>,
    key: u64,
}

impl RowDirection {
    /// Relative agreement of two directions for a kept solve to be reused.
    const SAME: f64 = 1e-13;

    pub(crate) fn new(row: &[(usize, f64)]) -> Self {
        use std::hash::{Hash, Hasher};
        let mut scale = 0.0_f64;
        for &(_, v) in row {
            if v.abs() > scale.abs() {
                scale = v;
            }
        }
        if scale == 0.0 || !scale.is_finite() {
            scale = 1.0;
        }
        let direction: Vec<(usize, f64)> = row.iter().map(|&(p, v)| (p, v / scale)).collect();
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for &(p, v) in &direction {
            p.hash(&mut h);
            // coarse enough that rounding of `(g a) / (g b)` against `a / b` rarely changes it;
            // a hit is confirmed entry by entry (`SAME`)
            ((v * (1u64 << 32) as f64).round() as i64).hash(&mut h);
        }
        Self { scale, direction, key: h.finish() }
    }

    fn matches(&self, other: &[(usize, f64)]) -> bool {
        self.direction.len() == other.len()
            && self
                .direction
                .iter()
                .zip(other)
                .all(|(&(p, a), &(q, b))| p == q && (a - b).abs() <= Self::SAME)
    }
}

impl Default for BlockSolveStore {
    fn default() -> Self {
        Self::with_budget(Self::DEFAULT_BUDGET_BYTES)
    }
}

impl BlockSolveStore {
    /// Default budget: 512 MiB.
    pub const DEFAULT_BUDGET_BYTES: usize = 512 << 20;

    /// An empty store holding at most `budget_bytes` of solves.
    pub fn with_budget(budget_bytes: usize) -> Self {
        Self {
            inner: Mutex::new(BlockSolves::default()),
            budget_bytes,
            unit_solves: std::sync::atomic::AtomicBool::new(false),
        }
    }
    /// With `on`, interfaces solved with the whole factor (no dense trailing block) build the
    /// columns of rows on at most three dofs (a node's normal or tangent) from kept unit
    /// solves `P A⁻¹ e_p` restricted to the interface dofs `P` — three solves per node instead
    /// of one per row, but reused by every later row on that node whatever its direction: for
    /// rows rebuilt at every pose of a moving rigid partner (docs/model.md §10). Off (default),
    /// each column is one solve, kept only while the rows stay the same.
    pub fn set_unit_solves(&self, on: bool) {
        self.unit_solves.store(on, std::sync::atomic::Ordering::Relaxed);
    }
    /// Whether [`BlockSolveStore::set_unit_solves`] is on.
    pub fn unit_solves(&self) -> bool {
        self.unit_solves.load(std::sync::atomic::Ordering::Relaxed)
    }
    /// The budget in bytes.
    pub fn budget_bytes(&self) -> usize {
        self.budget_bytes
    }
    /// Forgets the kept solves of row directions on more than one dof and the kept row
    /// positions, keeping the unit solves `x_p` (single-dof directions) and their support:
    /// for rows rebuilt with new directions on the same factor, which combine the unit solves
    /// of their nodes while the other directions would not recur.
    pub fn retain_unit_solves(&self) {
        let mut store = self.lock();
        store.solves.retain(|_, s| s.direction.len() == 1);
        store.bytes = store.solves.values().map(StoredSolve::bytes).sum();
        store.row_positions = None;
    }
    /// Bytes held now.
    pub fn bytes(&self) -> usize {
        self.lock().bytes
    }
    /// Forgets every solve.
    pub fn clear(&self) {
        *self.lock() = BlockSolves::default();
    }
    fn lock(&self) -> std::sync::MutexGuard<'_, BlockSolves> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
    /// The solve of `row` (`s x_d` from the kept `x_d`), if its direction is kept.
    fn get(&self, block: usize, row: &RowDirection) -> Option<Vec<f64>> {
        self.get_shared(block, row).map(|(s, x)| x.iter().map(|v| s * v).collect())
    }
    /// The kept `x_d` of `row`'s direction with the row's scale `s` (its solve is `s x_d`),
    /// shared rather than copied.
    fn get_shared(&self, block: usize, row: &RowDirection) -> Option<(f64, Arc<Vec<f64>>)> {
        let mut store = self.lock();
        if store.block != block {
            return None;
        }
        store.tick += 1;
        let tick = store.tick;
        let kept = store.solves.get_mut(&row.key).filter(|k| row.matches(&k.direction))?;
        kept.last_use = tick;
        Some((row.scale, kept.solve.clone()))
    }
    /// Keeps the solve `x` of `row` as `x_d = x / s`.
    fn put(&self, block: usize, row: &RowDirection, x: &[f64]) {
        let mut stored = StoredSolve {
            direction: row.direction.clone(),
            solve: Arc::new(x.iter().map(|v| v / row.scale).collect()),
            last_use: 0,
        };
        let bytes = stored.bytes();
        let mut store = self.lock();
        if store.block != block {
            *store = BlockSolves { block, ..Default::default() };
        } else if store.bytes + bytes > self.budget_bytes {
            // the least recently used solves go, down to three quarters of the budget (a
            // contact zone that travels over a large surface keeps the solves of where it is)
            let mut ages: Vec<(u64, u64)> = store.solves.iter().map(|(k, v)| (v.last_use, *k)).collect();
            ages.sort_unstable();
            let target = (self.budget_bytes / 4 * 3).saturating_sub(bytes);
            for (_, key) in ages {
                if store.bytes <= target {
                    break;
                }
                if let Some(old) = store.solves.remove(&key) {
                    store.bytes -= old.bytes().min(store.bytes);
                }
            }
        }
        store.tick += 1;
        stored.last_use = store.tick;
        if bytes <= self.budget_bytes {
            if let Some(old) = store.solves.insert(row.key, stored) {
                store.bytes -= old.bytes().min(store.bytes);
            }
            store.bytes += bytes;
        }
    }
    /// The dofs the kept unit solves of the factor `block` are restricted to, made to contain
    /// `dofs` (sorted): a store for another factor, or one whose dofs miss some of `dofs`, is
    /// emptied and restricted to the union.
    fn unit_support(&self, block: usize, dofs: &[usize]) -> Arc<Vec<usize>> {
        let mut store = self.lock();
        let covered = store.block == block && dofs.iter().all(|p| store.support.binary_search(p).is_ok());
        if !covered {
            let mut union: Vec<usize> =
                if store.block == block { store.support.iter().copied().collect() } else { Vec::new() };
            union.extend_from_slice(dofs);
            union.sort_unstable();
            union.dedup();
            *store = BlockSolves { block, support: Arc::new(union), ..Default::default() };
        }
        store.support.clone()
    }
    /// The kept support and row positions of the rows with fingerprint `rows` on the factor
    /// `block`, if kept.
    fn unit_rows(&self, block: usize, rows: u64) -> Option<(Arc<Vec<usize>>, RowPositions)> {
        let store = self.lock();
        match &store.row_positions {
            Some((fp, pos)) if store.block == block && *fp == rows => {
                Some((store.support.clone(), pos.clone()))
            }
            _ => None,
        }
    }
    fn keep_unit_rows(&self, block: usize, support: &Arc<Vec<usize>>, rows: u64, positions: RowPositions) {
        let mut store = self.lock();
        if store.block == block && Arc::ptr_eq(&store.support, support) {
            store.row_positions = Some((rows, positions));
        }
    }
    /// Number of kept solves.
    pub fn len(&self) -> usize {
        self.lock().solves.len()
    }
    /// `true` if no solve is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The columns of `wanted` not yet in `columns`, sorted and without repeats.
pub(crate) fn missing_columns(wanted: &[usize], columns: &[Option<Vec<f64>>]) -> Vec<usize> {
    let mut v: Vec<usize> = wanted.iter().copied().filter(|&j| columns[j].is_none()).collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// Runs `columns` on the two halves of `cols` on two threads when there is enough work (at
/// least 64 columns and `worth_splitting`), else on all of them at once: triangular solves with
/// many right-hand sides do not parallelise well inside faer, so the right-hand sides are
/// split instead.
pub(crate) fn in_two_halves(
    cols: &[usize],
    worth_splitting: bool,
    columns: impl Fn(&[usize]) -> Result<Vec<(usize, Vec<f64>)>, LinalgError> + Sync,
) -> Result<Vec<(usize, Vec<f64>)>, LinalgError> {
    if cols.len() < 64 || !worth_splitting {
        return columns(cols);
    }
    let (a, b) = cols.split_at(cols.len() / 2);
    let (ra, rb) = std::thread::scope(|scope| {
        let ha = scope.spawn(|| columns(a));
        let rb = columns(b);
        (ha.join(), rb)
    });
    let mut ra = ra.map_err(|_| LinalgError::Sparse("a column worker panicked".into()))??;
    ra.extend(rb?);
    Ok(ra)
}

/// Columns `j ∈ cols` of `S = C A⁻¹ Cᵀ`: batched solves, 32 right-hand sides at a time.
pub(crate) fn columns_by_solves<O: FactorisedOperator + ?Sized>(
    op: &O,
    rows: RowStack<'_>,
    cols: &[usize],
) -> Result<Vec<(usize, Vec<f64>)>, LinalgError> {
    let n = op.n();
    if rows.ncols() != n {
        return Err(LinalgError::Length { what: "interface rows (columns)", expected: n, got: rows.ncols() });
    }
    let mut out = Vec::with_capacity(cols.len());
    for chunk in cols.chunks(32) {
        let k = chunk.len();
        let mut rhs = vec![0.0; n * k];
        for (c, &j) in chunk.iter().enumerate() {
            for (i, v) in rows.row(j) {
                rhs[c * n + i] += v;
            }
        }
        op.solve_many_in_place(&mut rhs, k)?;
        for (c, &j) in chunk.iter().enumerate() {
            out.push((j, rows.mul(&rhs[c * n..(c + 1) * n])));
        }
    }
    Ok(out)
}

/// Rows of `C` as `(trailing position, value)` lists (`None`: a row with a dof outside the
/// trailing block).
type TrailingRows = Vec<Option<Vec<(usize, f64)>>>;

/// The rows of `C` in the positions of the factor's trailing block, with the block, when at
/// most a fifth of the rows (and not all) have a dof outside it; `None` otherwise.
pub(crate) fn trailing_rows(
    factor: &CholeskySolver,
    rows: RowStack<'_>,
) -> Option<(Arc<TrailingBlock>, TrailingRows)> {
    let block = factor.trailing()?;
    let m = rows.n_rows();
    let mapped: TrailingRows = (0..m)
        .map(|r| {
            rows.row(r)
                .map(|(i, v)| match block.position.get(i).copied() {
                    Some(p) if p != usize::MAX => Some((p, v)),
                    _ => None,
                })
                .collect::<Option<Vec<_>>>()
        })
        .collect();
    let outside = mapped.iter().filter(|r| r.is_none()).count();
    (outside * 5 <= m && outside < m).then(|| (block.clone(), mapped))
}

/// [`FactorisedOperator::interface_columns`] of a Cholesky factor: with a trailing block,
/// whole-factor columns for the rows outside the block (all of them as soon as a trailing
/// column is needed), then the trailing columns `S_ij = c_i · L₂₂⁻ᵀ L₂₂⁻¹ c_j`, completed in
/// the outside rows by symmetry `S_ij = S_ji`; without one, batched whole solves.
pub(crate) fn cholesky_interface_columns(
    op: &CholeskyOperator<'_>,
    rows: RowStack<'_>,
    wanted: &[usize],
    columns: &mut [Option<Vec<f64>>],
    kept: &BlockSolveStore,
) -> Result<usize, LinalgError> {
    let missing = missing_columns(wanted, columns);
    if missing.is_empty() {
        return Ok(0);
    }
    let Some((block, mapped)) = trailing_rows(op.factor(), rows) else {
        if kept.unit_solves() {
            return whole_factor_unit_columns(op, rows, &missing, columns, kept);
        }
        return solve_columns_into(op, rows, &missing, columns);
    };
    let mut solved = 0;
    let (inside, mut outside): (Vec<usize>, Vec<usize>) = missing.iter().partition(|&&j| mapped[j].is_some());
    if !inside.is_empty() {
        outside = (0..mapped.len()).filter(|&j| mapped[j].is_none() && columns[j].is_none()).collect();
    }
    if !outside.is_empty() {
        solved += solve_columns_into(op, rows, &outside, columns)?;
    }
    if inside.is_empty() {
        return Ok(solved);
    }
    // trailing solves kept in the store (rows shared with earlier interfaces), the others
    let block_id = block_fingerprint(&block);
    let directions: Vec<RowDirection> =
        inside.iter().map(|&j| RowDirection::new(mapped[j].as_deref().unwrap_or(&[]))).collect();
    let mut solves: Vec<Option<Vec<f64>>> = directions.iter().map(|d| kept.get(block_id, d)).collect();
    // rows on one node (a few entries, e.g. a node against a rigid obstacle): combinations of
    // kept unit solves `x_c = Σ_p c_p L₂₂⁻ᵀ L₂₂⁻¹ e_p`, shared by every row on that node
    // whatever its normal or tangent (a rigid partner that moves changes the normals)
    let few: Vec<usize> = (0..inside.len())
        .filter(|&a| solves[a].is_none() && mapped[inside[a]].as_ref().is_some_and(|r| r.len() <= UNIT_SPLIT))
        .collect();
    let mut solved_units = 0;
    if !few.is_empty() {
        let mut positions: Vec<usize> =
            few.iter().flat_map(|&a| mapped[inside[a]].iter().flatten().map(|&(p, _)| p)).collect();
        positions.sort_unstable();
        positions.dedup();
        let unit_dirs: Vec<RowDirection> =
            positions.iter().map(|&p| RowDirection::new(&[(p, 1.0)])).collect();
        let mut units: Vec<Option<Vec<f64>>> = unit_dirs.iter().map(|d| kept.get(block_id, d)).collect();
        let missing_units: Vec<usize> = (0..positions.len()).filter(|&u| units[u].is_none()).collect();
        if !missing_units.is_empty() {
            let rhs: Vec<Vec<(usize, f64)>> =
                missing_units.iter().map(|&u| vec![(positions[u], 1.0)]).collect();
            let solved = block.solve_sparse_columns(&rhs, block.dofs.len() >= 256)?;
            for (&u, x) in missing_units.iter().zip(solved) {
                kept.put(block_id, &unit_dirs[u], &x);
                units[u] = Some(x);
            }
            solved_units = missing_units.len();
        }
        for &a in &few {
            let mut x = vec![0.0; block.dofs.len()];
            for &(p, v) in mapped[inside[a]].iter().flatten() {
                let Ok(u) = positions.binary_search(&p) else { continue };
                if let Some(unit) = &units[u] {
                    for (xi, ui) in x.iter_mut().zip(unit) {
                        *xi += v * ui;
                    }
                }
            }
            solves[a] = Some(x);
        }
    }
    let todo: Vec<usize> = (0..inside.len()).filter(|&a| solves[a].is_none()).collect();
    let todo_rows: Vec<usize> = todo.iter().map(|&a| inside[a]).collect();
    let computed = trailing_solves(&block, &mapped, &todo_rows)?;
    for (&a, (_, x)) in todo.iter().zip(computed) {
        kept.put(block_id, &directions[a], &x);
        solves[a] = Some(x);
    }
    for (&j, x) in inside.iter().zip(&solves) {
        let Some(x) = x else { continue };
        let col = mapped
            .iter()
            .enumerate()
            .map(|(i, row)| match row {
                Some(row) => row.iter().map(|&(p, v)| v * x[p]).sum(),
                // outside the block: S_ij = S_ji from the whole-factor column i
                None => columns[i].as_ref().map_or(0.0, |c| c[j]),
            })
            .collect();
        columns[j] = Some(col);
    }
    Ok(solved + todo.len() + solved_units)
}

/// Rows with at most this many entries in the trailing block are combined from unit solves.
const UNIT_SPLIT: usize = 3;

/// Unit solves of the whole factor per call of [`CholeskySolver::solve_sparse_on`].
const UNIT_CHUNK: usize = 32;

/// The columns `cols` of `S` by whole solves (two halves in parallel), stored in `columns`;
/// returns the number of solves.
fn solve_columns_into(
    op: &CholeskyOperator<'_>,
    rows: RowStack<'_>,
    cols: &[usize],
    columns: &mut [Option<Vec<f64>>],
) -> Result<usize, LinalgError> {
    let computed = in_two_halves(cols, true, |c| columns_by_solves(op, rows, c))?;
    let solved = computed.len();
    for (j, col) in computed {
        columns[j] = Some(col);
    }
    Ok(solved)
}

/// The columns `missing` of `S = C A⁻¹ Cᵀ` with the whole factor, rows on at most
/// [`UNIT_SPLIT`] dofs from kept unit solves: `x_p = P A⁻¹ e_p` restricted to the interface
/// dofs `P` (the union of the rows' dofs), `S_ij = Σ_{(q,w) ∈ c_i} w Σ_{(p,v) ∈ c_j} v x_p[q]`.
/// The store keys them by the factor and the interface dofs. Other rows: one solve each.
fn whole_factor_unit_columns(
    op: &CholeskyOperator<'_>,
    rows: RowStack<'_>,
    missing: &[usize],
    columns: &mut [Option<Vec<f64>>],
    kept: &BlockSolveStore,
) -> Result<usize, LinalgError> {
    let n = op.n();
    if rows.ncols() != n {
        return Err(LinalgError::Length { what: "interface rows (columns)", expected: n, got: rows.ncols() });
    }
    let id = whole_factor_id(op);
    let fingerprint = rows.fingerprint();
    let (support, row_positions) = match kept.unit_rows(id, fingerprint) {
        Some(kept_rows) => kept_rows,
        None => {
            let row_entries: Vec<Vec<(usize, f64)>> =
                (0..rows.n_rows()).map(|r| rows.row(r).collect()).collect();
            // the store's dofs (a superset of these rows' dofs: rows whose normals gain or lose
            // a zero component, coarse levels of a nested iteration)
            let support = kept.unit_support(id, &dofs_of(&row_entries));
            let positions: RowPositions = Arc::new(
                row_entries
                    .iter()
                    .map(|row| {
                        row.iter()
                            .filter_map(|&(q, w)| support.binary_search(&q).ok().map(|k| (k, w)))
                            .collect()
                    })
                    .collect(),
            );
            kept.keep_unit_rows(id, &support, fingerprint, positions.clone());
            (support, positions)
        }
    };
    let (few, many): (Vec<usize>, Vec<usize>) =
        missing.iter().partition(|&&j| row_positions[j].len() <= UNIT_SPLIT);
    let mut solved = 0;
    if !many.is_empty() {
        solved += solve_columns_into(op, rows, &many, columns)?;
    }
    if few.is_empty() {
        return Ok(solved);
    }
    let mut dofs: Vec<usize> =
        few.iter().flat_map(|&j| row_positions[j].iter().map(|&(k, _)| support[k])).collect();
    dofs.sort_unstable();
    dofs.dedup();
    let unit_dirs: Vec<RowDirection> = dofs.iter().map(|&p| RowDirection::new(&[(p, 1.0)])).collect();
    // unit directions have scale 1: the kept solves are used as they are
    let mut units: Vec<Option<Arc<Vec<f64>>>> =
        unit_dirs.iter().map(|d| kept.get_shared(id, d).map(|(_, x)| x)).collect();
    let absent: Vec<usize> = (0..dofs.len()).filter(|&u| units[u].is_none()).collect();
    if !absent.is_empty() {
        // sparse right-hand sides: the forward halves follow the elimination-tree paths of
        // the dofs, the backward halves the supernodes of the support
        let t_units = std::time::Instant::now();
        let computed = in_two_halves(&absent, true, |list| {
            let mut out = Vec::with_capacity(list.len());
            for chunk in list.chunks(UNIT_CHUNK) {
                let rhs: Vec<Vec<(usize, f64)>> = chunk.iter().map(|&u| vec![(dofs[u], 1.0)]).collect();
                let solved = op.factor().solve_sparse_on(&rhs, &support)?;
                out.extend(chunk.iter().copied().zip(solved));
            }
            Ok(out)
        })?;
        solved += computed.len();
        tracing::debug!(n = computed.len(), ms = t_units.elapsed().as_secs_f64() * 1e3, "unit solves");
        for (u, x) in computed {
            kept.put(id, &unit_dirs[u], &x);
            units[u] = Some(Arc::new(x));
        }
    }
    tracing::debug!(
        missing = missing.len(),
        many = many.len(),
        units = dofs.len(),
        absent = absent.len(),
        support = support.len(),
        kept = kept.len(),
        kept_mb = kept.bytes() >> 20,
        "whole-factor unit columns"
    );
    for &j in &few {
        // S_ij = Σ_{(q,w) ∈ c_i} w Σ_{(p,v) ∈ c_j} v x_p[q]: work per column follows the rows,
        // not the interface dofs the unit solves are kept on
        let parts: Vec<(&[f64], f64)> = row_positions[j]
            .iter()
            .filter_map(|&(k, v)| {
                let u = dofs.binary_search(&support[k]).ok()?;
                units[u].as_deref().map(|unit| (unit.as_slice(), v))
            })
            .collect();
        let col = row_positions
            .iter()
            .map(|row| {
                row.iter().map(|&(k, w)| w * parts.iter().map(|&(unit, v)| v * unit[k]).sum::<f64>()).sum()
            })
            .collect();
        columns[j] = Some(col);
    }
    Ok(solved)
}

/// The key of the whole-factor unit solves of `op` in a [`BlockSolveStore`]: the operator's
/// own [`FactorisedOperator::key`] (its factorisation's generation and size).
fn whole_factor_id(op: &CholeskyOperator<'_>) -> usize {
    op.key() as usize
}

/// [`FactorisedOperator::reserve_interface`] of the Cholesky back-end: the kept whole-factor
/// unit solves are restricted to a support that covers the dofs of every row of `rows`
/// (nothing to do with a trailing block, whose solves are kept per block).
pub(crate) fn reserve_unit_support(op: &CholeskyOperator<'_>, rows: RowStack<'_>, kept: &BlockSolveStore) {
    if rows.ncols() != op.n() || !kept.unit_solves() || trailing_rows(op.factor(), rows).is_some() {
        return;
    }
    let row_entries: Vec<Vec<(usize, f64)>> = (0..rows.n_rows()).map(|r| rows.row(r).collect()).collect();
    kept.unit_support(whole_factor_id(op), &dofs_of(&row_entries));
}

/// The dofs of rows given by their `(dof, value)` entries, sorted, without repeats.
fn dofs_of(row_entries: &[Vec<(usize, f64)>]) -> Vec<usize> {
    let mut dofs: Vec<usize> = row_entries.iter().flatten().map(|&(p, _)| p).collect();
    dofs.sort_unstable();
    dofs.dedup();
    dofs
}

/// The trailing-block solves `x_j = L₂₂⁻ᵀ L₂₂⁻¹ c_j` (in trailing positions) of the rows
/// `j ∈ cols` (`rows`: the rows of `C` in trailing positions; every `j ∈ cols` must be one):
/// dense triangular solves in groups sorted by first position, on two threads for blocks of
/// at least 256 dofs ([`TrailingBlock::solve_sparse_columns`]).
fn trailing_solves(
    block: &TrailingBlock,
    rows: &[Option<Vec<(usize, f64)>>],
    cols: &[usize],
) -> Result<Vec<(usize, Vec<f64>)>, LinalgError> {
    let rhs: Vec<Vec<(usize, f64)>> = cols.iter().map(|&j| rows[j].clone().unwrap_or_default()).collect();
    let solved = block.solve_sparse_columns(&rhs, block.dofs.len() >= 256)?;
    Ok(cols.iter().copied().zip(solved).collect())
}

/// A fingerprint of a trailing block: its generation (one per factorisation, never reused in
/// the process). (Its address is not enough: a refactorisation may allocate the new block
/// where the old one was.)
fn block_fingerprint(block: &TrailingBlock) -> usize {
    block.generation() as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Ordering, SparseCholesky, SparseRows, SymmetricMatrix};

    /// The SPD tridiagonal matrix `tridiag(−1, 2.5, −1)` of size `n`.
    fn tridiagonal(n: usize) -> SymmetricMatrix {
        let columns = (0..n).map(|j| if j + 1 < n { vec![j, j + 1] } else { vec![j] }).collect();
        let mut a = SymmetricMatrix::from_columns(n, columns).expect("pattern");
        for j in 0..n {
            a.add(j, j, 2.5).expect("diagonal");
            if j + 1 < n {
                a.add(j + 1, j, -1.0).expect("off-diagonal");
            }
        }
        a
    }

    /// The key of a Cholesky operator (what kept solves are filed under) is that of its
    /// factorisation: it changes when the same solver is refactorised in place (same
    /// address, new values), and so does the key of its whole-factor unit solves; a clone
    /// (same values) keeps it.
    #[test]
    fn operator_keys_follow_the_factorisation_not_the_address() {
        let a = tridiagonal(30);
        let mut a2 = a.clone();
        a2.values_mut().iter_mut().for_each(|v| *v *= 2.0);
        let mut solver = crate::CholeskySolver::analyse(&a, &Ordering::Amd).expect("analyse");
        solver.factorize(&a).expect("factorize");
        let (key1, unit1) = {
            let op = CholeskyOperator::new(&a, &solver).expect("operator");
            (op.key(), whole_factor_id(&op))
        };
        let clone = solver.clone();
        let address = std::ptr::addr_of!(solver) as usize;
        solver.factorize(&a2).expect("refactorize");
        assert_eq!(std::ptr::addr_of!(solver) as usize, address);
        let op2 = CholeskyOperator::new(&a2, &solver).expect("operator");
        assert_ne!(op2.key(), key1, "a refactorised solver kept its key");
        assert_ne!(whole_factor_id(&op2), unit1, "a refactorised solver kept its unit-solve key");
        let op_clone = CholeskyOperator::new(&a, &clone).expect("operator");
        assert_eq!(op_clone.key(), key1, "a clone of the factorisation has another key");
        // a failed factorisation (−A is not positive definite) overwrote the values: new key
        let key2 = op2.key();
        let mut negative = a.clone();
        negative.values_mut().iter_mut().for_each(|v| *v = -*v);
        assert!(solver.factorize(&negative).is_err());
        let op3 = CholeskyOperator::new(&negative, &solver).expect("operator");
        assert_ne!(op3.key(), key2, "a failed factorisation kept the key of the one before");
    }

    /// Every column of `S` of `rows` through the Cholesky back-end with `store`, and the
    /// number of solves it took.
    fn all_columns(
        op: &SparseCholesky,
        rows: &SparseRows,
        store: &BlockSolveStore,
    ) -> (Vec<Option<Vec<f64>>>, usize) {
        let mut columns = vec![None; rows.nrows()];
        let all: Vec<usize> = (0..rows.nrows()).collect();
        let solved = op
            .view()
            .interface_columns(RowStack::new(rows, None), &all, &mut columns, store)
            .expect("columns");
        (columns, solved)
    }

    /// `S = C A⁻¹ Cᵀ` by dense whole solves, the reference.
    fn reference_columns(op: &SparseCholesky, rows: &SparseRows) -> Vec<Vec<f64>> {
        (0..rows.nrows())
            .map(|j| {
                let mut x = vec![0.0; op.n()];
                rows.add_row_to(j, 1.0, &mut x);
                op.solve_in_place(&mut x).expect("solve");
                rows.mul(&x)
            })
            .collect()
    }

    /// The 5-point Laplacian (+ 0.1 I) of an `m × m` grid.
    fn grid(m: usize) -> SymmetricMatrix {
        let n = m * m;
        let columns = (0..n)
            .map(|j| {
                let mut c = vec![j];
                if (j + 1) % m != 0 {
                    c.push(j + 1);
                }
                if j + m < n {
                    c.push(j + m);
                }
                c
            })
            .collect();
        let mut a = SymmetricMatrix::from_columns(n, columns).expect("pattern");
        for j in 0..n {
            a.add(j, j, 4.1).expect("diagonal");
            if (j + 1) % m != 0 {
                a.add(j + 1, j, -1.0).expect("off-diagonal");
            }
            if j + m < n {
                a.add(j + m, j, -1.0).expect("off-diagonal");
            }
        }
        a
    }

    /// The two halves of a solve with a trailing block: `L₂₂⁻ᵀ y₂` of the forward half is
    /// `A⁻¹ b` on the trailing dofs, and the completion is `A⁻¹ (b − s)` for an `s` on them
    /// (and for one with entries outside them, solved whole), to 1e-13 — on a tridiagonal and
    /// a 2D grid matrix; rows outside the block are not covered.
    #[test]
    fn forward_half_and_completion_equal_the_whole_solve() {
        for (a, last) in [(tridiagonal(60), (45..60).collect::<Vec<_>>()), (grid(24), (0..24).collect())] {
            let n = a.n();
            let op = SparseCholesky::new(
                a,
                &Ordering::Trailing { base: Box::new(Ordering::Amd), last: last.clone() },
            )
            .expect("factor");
            let b: Vec<f64> = (0..n).map(|i| ((i * 7 % 13) as f64 - 6.0) * 0.3 + 1.0).collect();
            let mut x = b.clone();
            op.solve_in_place(&mut x).expect("solve");
            let scale = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let mut rows = SparseRows::new(n);
            rows.push_row([(last[1], 1.0), (last[2], -0.5)]);
            rows.push_row([(last[4], 0.25)]);
            assert!(op.forward_covers(RowStack::new(&rows, None)));
            let y = op.forward_solve(&b).expect("forward").expect("a trailing block");
            let xc = op.interface_of_forward(&y).expect("trailing values");
            for i in 0..n {
                let want = if last.contains(&i) { x[i] } else { 0.0 };
                assert!((xc[i] - want).abs() <= 1e-13 * scale, "x_{i}: {} vs {want}", xc[i]);
            }
            let mut s_in = vec![0.0; n];
            s_in[last[1]] = 0.7;
            s_in[last[4]] = -1.3;
            let mut s_out = s_in.clone();
            s_out[n / 2] = 0.4;
            assert!(!last.contains(&(n / 2)));
            for s in [s_in, s_out] {
                let mut want: Vec<f64> = b.iter().zip(&s).map(|(b, s)| b - s).collect();
                op.solve_in_place(&mut want).expect("solve");
                let got = op.complete_forward(&y, &s).expect("completion");
                for i in 0..n {
                    assert!((got[i] - want[i]).abs() <= 1e-13 * scale, "u_{i}: {} vs {}", got[i], want[i]);
                }
            }
            let mut outside = SparseRows::new(n);
            outside.push_row([(n / 2, 1.0)]);
            assert!(!op.forward_covers(RowStack::new(&outside, None)));
        }
        // without a trailing block: no forward half
        let plain = SparseCholesky::new(tridiagonal(20), &Ordering::Amd).expect("factor");
        assert!(plain.forward_solve(&[1.0; 20]).expect("no error").is_none());
        assert!(plain.interface_of_forward(&[1.0; 20]).is_err());
    }

    /// The 7-point Laplacian (+ I) of an `m × m × m` grid with `c` components per grid
    /// point coupled by a small symmetric term (3 for a 3D displacement field): large enough
    /// for faer to factorise it supernodally.
    fn grid3(m: usize, c: usize) -> SymmetricMatrix {
        let n = m * m * m * c;
        let idx = |x: usize, y: usize, z: usize, d: usize| ((z * m + y) * m + x) * c + d;
        let mut columns = vec![Vec::new(); n];
        for z in 0..m {
            for y in 0..m {
                for x in 0..m {
                    for d in 0..c {
                        let j = idx(x, y, z, d);
                        let col = &mut columns[j];
                        col.extend((d..c).map(|e| idx(x, y, z, e)));
                        if x + 1 < m {
                            col.push(idx(x + 1, y, z, d));
                        }
                        if y + 1 < m {
                            col.push(idx(x, y + 1, z, d));
                        }
                        if z + 1 < m {
                            col.push(idx(x, y, z + 1, d));
                        }
                    }
                }
            }
        }
        let mut a = SymmetricMatrix::from_columns(n, columns).expect("pattern");
        for z in 0..m {
            for y in 0..m {
                for x in 0..m {
                    for d in 0..c {
                        let j = idx(x, y, z, d);
                        a.add(j, j, 7.0).expect("diagonal");
                        for e in d + 1..c {
                            a.add(idx(x, y, z, e), j, 0.3).expect("coupling");
                        }
                        if x + 1 < m {
                            a.add(idx(x + 1, y, z, d), j, -1.0).expect("off-diagonal");
                        }
                        if y + 1 < m {
                            a.add(idx(x, y + 1, z, d), j, -1.0).expect("off-diagonal");
                        }
                        if z + 1 < m {
                            a.add(idx(x, y, z + 1, d), j, -1.0).expect("off-diagonal");
                        }
                    }
                }
            }
        }
        a
    }

    /// `true` if the factor of `op` is supernodal (the path of
    /// [`CholeskySolver::solve_sparse_on`] that skips supernodes).
    fn supernodal(op: &SparseCholesky) -> bool {
        matches!(
            op.view().factor().symbolic().raw(),
            faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(_)
        )
    }

    /// Sparse right-hand sides solved on a support (`solve_sparse_on`: forward half on the
    /// elimination-tree paths, backward half on the support's supernodes) equal whole solves
    /// there to 1e-13, on a supernodal factor (AMD and METIS-like custom orderings), for unit
    /// vectors and rows with several entries, with a support that is a face of the grid and
    /// one that is everything.
    #[test]
    fn sparse_right_hand_sides_on_a_support_equal_whole_solves() {
        let (m, c) = (14, 3);
        let a = grid3(m, c);
        let n = a.n();
        let op = SparseCholesky::new(a, &Ordering::Amd).expect("factor");
        assert!(supernodal(&op), "the test needs a supernodal factor");
        // the top face z = m − 1 (the "contact surface") and all dofs
        let face: Vec<usize> = (n - m * m * c..n).collect();
        let all: Vec<usize> = (0..n).collect();
        let rhs: Vec<Vec<(usize, f64)>> = vec![
            vec![(face[5], 1.0)],
            vec![(face[100], 1.0)],
            vec![(face[101], -0.5), (face[102], 2.0), (face[140], 0.25)],
            vec![(n / 2, 1.0)],
            vec![(0, 0.3), (7, 0.3), (7, 0.4)],
        ];
        let mut dense = faer::Mat::<f64>::zeros(n, rhs.len());
        for (col, entries) in rhs.iter().enumerate() {
            for &(d, v) in entries {
                dense[(d, col)] += v;
            }
        }
        op.view().factor().solve_many_in_place(dense.as_mut()).expect("solve");
        for support in [&face, &all] {
            let got = op.view().factor().solve_sparse_on(&rhs, support).expect("sparse solve");
            for (col, x) in got.iter().enumerate() {
                let scale = (0..n).fold(0.0_f64, |s, i| s.max(dense[(i, col)].abs()));
                assert!(scale > 0.0);
                for (k, &d) in support.iter().enumerate() {
                    let want = dense[(d, col)];
                    assert!((x[k] - want).abs() <= 1e-13 * scale, "x[{d}] of rhs {col}: {} vs {want}", x[k]);
                }
            }
        }
        // a sparse right-hand side of a whole solve (contact forces `Cᵀ ν`): the same
        for (col, entries) in rhs.iter().enumerate() {
            let mut b = vec![0.0; n];
            for &(d, v) in entries {
                b[d] += v;
            }
            op.view().factor().solve_trailing_supported_in_place(&mut b).expect("solve");
            let scale = (0..n).fold(0.0_f64, |s, i| s.max(dense[(i, col)].abs()));
            for (i, x) in b.iter().enumerate() {
                assert!((x - dense[(i, col)]).abs() <= 1e-13 * scale, "x[{i}] of rhs {col}");
            }
        }
        assert!(op.view().factor().solve_sparse_on(&[vec![(n, 1.0)]], &face).is_err());
        assert!(op.view().factor().solve_sparse_on(&rhs, &[n]).is_err());
    }

    /// The whole-factor unit columns on a supernodal factor (unit solves by
    /// `solve_sparse_on`): rows on the nodes of a face with normals that change from call to
    /// call give the columns of fresh whole solves to 1e-12, and reuse the kept unit solves.
    #[test]
    fn unit_columns_on_a_supernodal_factor_equal_whole_solves() {
        let (m, c) = (12, 3);
        let a = grid3(m, c);
        let n = a.n();
        let op = SparseCholesky::new(a, &Ordering::Amd).expect("factor");
        assert!(supernodal(&op), "the test needs a supernodal factor");
        let top = n / c - m * m;
        let nodes: Vec<usize> = (0..40).map(|i| top + (i * 7) % (m * m)).collect();
        let rows_at = |angle: f64| {
            let mut rows = SparseRows::new(n);
            for (i, &node) in nodes.iter().enumerate() {
                let (s, co) = (angle + 0.05 * i as f64).sin_cos();
                rows.push_row([(c * node, 0.3 * s), (c * node + 1, co), (c * node + 2, 0.2)]);
            }
            rows
        };
        let store = BlockSolveStore::default();
        store.set_unit_solves(true);
        let mut solves = Vec::new();
        for angle in [0.1, 0.4, 0.9] {
            let rows = rows_at(angle);
            let (columns, solved) = all_columns(&op, &rows, &store);
            solves.push(solved);
            let reference = reference_columns(&op, &rows);
            for (j, col) in columns.iter().enumerate() {
                let col = col.as_ref().expect("column computed");
                let diagonal = reference[j][j].abs();
                for (i, (&x, &y)) in col.iter().zip(&reference[j]).enumerate() {
                    assert!((x - y).abs() <= 1e-12 * diagonal, "S[{i},{j}] at {angle}: {x} vs {y}");
                }
            }
        }
        assert_eq!(solves, vec![3 * 40, 0, 0], "unit solves per call");
    }

    /// Rows on the trailing block that differ only by a factor (the friction rows
    /// `g_c,r κ_r T_rᵀ` of successive time levels) share one kept solve, and the columns of `S`
    /// built from it agree with fresh solves; a row of another direction is solved anew.
    #[test]
    fn rescaled_rows_share_a_kept_solve() {
        let n = 40;
        let last: Vec<usize> = (30..n).collect();
        let op =
            SparseCholesky::new(tridiagonal(n), &Ordering::Trailing { base: Box::new(Ordering::Amd), last })
                .expect("factor");
        let rows_scaled = |g: &[f64]| {
            let mut rows = SparseRows::new(n);
            // more entries than UNIT_SPLIT: kept by direction
            rows.push_row([(31, g[0] * 1.0), (32, g[0] * -0.5), (33, g[0] * 0.2), (34, g[0] * 0.1)]);
            rows.push_row([(35, g[1] * 0.25), (36, g[1] * 0.75), (37, g[1] * -0.1), (38, g[1] * 0.3)]);
            rows
        };
        let store = BlockSolveStore::default();
        let mut solved = 0;
        for g in [[1.0, 2.0], [0.37, 1e-3], [5.5e4, 0.9]] {
            let rows = rows_scaled(&g);
            let stack = RowStack::new(&rows, None);
            let mut columns = vec![None; rows.nrows()];
            solved += op.view().interface_columns(stack, &[0, 1], &mut columns, &store).expect("columns");
            let reference = reference_columns(&op, &rows);
            for (j, col) in columns.iter().enumerate() {
                let col = col.as_ref().expect("column computed");
                for (i, (&x, &y)) in col.iter().zip(&reference[j]).enumerate() {
                    let scale = reference[j].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                    assert!((x - y).abs() <= 1e-13 * scale, "S[{i},{j}] at g = {g:?}: {x} vs {y}");
                }
            }
        }
        assert_eq!(store.len(), 2, "one kept solve per row direction");
        // another direction of the first row: a new solve
        let mut rows = SparseRows::new(n);
        rows.push_row([(31, 1.0), (32, -0.4), (33, 0.2), (34, 0.1)]);
        let mut columns = vec![None; 1];
        op.view().interface_columns(RowStack::new(&rows, None), &[0], &mut columns, &store).expect("columns");
        assert_eq!(store.len(), 3);
        assert!(solved >= 2);
    }

    /// Rows on one node (at most `UNIT_SPLIT` entries) with changing normals share the kept
    /// unit solves of that node's dofs, and their columns agree with fresh solves.
    #[test]
    fn node_rows_share_unit_solves_whatever_their_normal() {
        let n = 40;
        let last: Vec<usize> = (30..n).collect();
        let op =
            SparseCholesky::new(tridiagonal(n), &Ordering::Trailing { base: Box::new(Ordering::Amd), last })
                .expect("factor");
        let store = BlockSolveStore::default();
        for angle in [0.0_f64, 0.3, 1.1] {
            let (s, c) = angle.sin_cos();
            let mut rows = SparseRows::new(n);
            rows.push_row([(31, c), (32, s)]);
            rows.push_row([(35, -s), (36, c), (37, 0.5)]);
            let mut columns = vec![None; rows.nrows()];
            op.view()
                .interface_columns(RowStack::new(&rows, None), &[0, 1], &mut columns, &store)
                .expect("columns");
            let reference = reference_columns(&op, &rows);
            for (j, col) in columns.iter().enumerate() {
                let col = col.as_ref().expect("column computed");
                let diagonal = reference[j][j].abs();
                for (i, (&x, &y)) in col.iter().zip(&reference[j]).enumerate() {
                    assert!((x - y).abs() <= 1e-13 * diagonal, "S[{i},{j}] at {angle}: {x} vs {y}");
                }
            }
        }
        assert_eq!(store.len(), 5, "one kept solve per dof of the two nodes");
    }

    #[test]
    fn row_direction_normalises_by_the_largest_entry() {
        let a = RowDirection::new(&[(3, 2.0), (4, -6.0)]);
        let b = RowDirection::new(&[(3, -0.1), (4, 0.3)]);
        assert_eq!(a.key, b.key);
        assert!(a.matches(&b.direction));
        assert_eq!(a.scale, -6.0);
        let zero = RowDirection::new(&[(1, 0.0)]);
        assert_eq!(zero.scale, 1.0);
        let c = RowDirection::new(&[(3, 2.0), (4, -6.0 * (1.0 + 1e-9))]);
        assert!(!a.matches(&c.direction) || a.key != c.key);
    }

    /// Whole-factor interfaces with unit solves on: rows on one node (≤ `UNIT_SPLIT` dofs)
    /// with normals that change from call to call (a moving rigid partner) cost no solve
    /// once their dofs are kept, rows that lose a dof keep the store, and every column agrees
    /// with fresh solves; a budget too small for them empties the store instead of growing.
    #[test]
    fn moving_normals_on_the_whole_factor_reuse_unit_solves() {
        let n = 150;
        let op = SparseCholesky::new(tridiagonal(n), &Ordering::Amd).expect("factor");
        let node_rows = |angle: f64| {
            let mut rows = SparseRows::new(n);
            for node in [3usize, 10, 20, 40] {
                let (c, s) = (angle.cos(), angle.sin());
                if s == 0.0 {
                    rows.push_row([(3 * node, c)]);
                } else {
                    rows.push_row([(3 * node, c), (3 * node + 1, s), (3 * node + 2, 0.5 * s)]);
                }
            }
            // a row on many dofs: one whole solve
            rows.push_row([(1, 1.0), (5, 0.5), (7, 0.25), (9, 0.125)]);
            rows
        };
        let check = |rows: &SparseRows, columns: &[Option<Vec<f64>>]| {
            let reference = reference_columns(&op, rows);
            for (j, col) in columns.iter().enumerate() {
                let col = col.as_ref().expect("column computed");
                let scale = reference[j].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                for (i, (&x, &y)) in col.iter().zip(&reference[j]).enumerate() {
                    assert!((x - y).abs() <= 1e-13 * scale, "S[{i},{j}]: {x} vs {y}");
                }
            }
        };
        let store = BlockSolveStore::default();
        store.set_unit_solves(true);
        let mut solves = Vec::new();
        for angle in [0.3, 0.5, 0.0, 0.7] {
            let rows = node_rows(angle);
            let (columns, solved) = all_columns(&op, &rows, &store);
            solves.push(solved);
            check(&rows, &columns);
        }
        // 12 unit solves and the long row at first, then only the long row
        assert_eq!(solves, vec![13, 1, 1, 1], "solves per call");
        assert_eq!(store.len(), 12, "one kept unit solve per node dof");
        // a budget below one unit solve: nothing is kept, the columns are still right
        let small = BlockSolveStore::with_budget(8);
        small.set_unit_solves(true);
        let rows = node_rows(0.3);
        let mut columns = vec![None; rows.nrows()];
        let all: Vec<usize> = (0..rows.nrows()).collect();
        op.view().interface_columns(RowStack::new(&rows, None), &all, &mut columns, &small).expect("columns");
        check(&rows, &columns);
        assert!(small.bytes() <= 8);
    }

    /// A store over its budget drops its least recently used solves (down to three quarters
    /// of the budget), not all of them: of three unit solves used in the order 1, 2, 0, a
    /// fourth one pushes out 1 and then 2, and 0 stays.
    #[test]
    fn a_full_store_drops_the_least_recently_used_solves() {
        let row = |p: usize| RowDirection::new(&[(p, 1.0)]);
        let x = vec![1.0; 100];
        let one = StoredSolve { direction: vec![(0, 1.0)], solve: Arc::new(x.clone()), last_use: 0 }.bytes();
        let store = BlockSolveStore::with_budget(3 * one);
        for p in 0..3 {
            store.put(7, &row(p), &x);
        }
        assert!(store.get(7, &row(2)).is_some() && store.get(7, &row(0)).is_some());
        store.put(7, &row(3), &x);
        assert_eq!(store.len(), 2);
        assert!(store.get(7, &row(0)).is_some() && store.get(7, &row(3)).is_some(), "recent solves kept");
        assert!(store.get(7, &row(1)).is_none() && store.get(7, &row(2)).is_none(), "older ones dropped");
        assert!(store.bytes() <= 3 * one);
    }

    /// Interfaces on subsets of reserved rows keep the store's unit solves: after
    /// `reserve_interface` with all rows, a subset and then another subset solve only the
    /// unit solves they have not met, and the columns equal fresh solves.
    #[test]
    fn reserved_rows_keep_unit_solves_across_subsets() {
        let n = 120;
        let op = SparseCholesky::new(tridiagonal(n), &Ordering::Amd).expect("factor");
        let rows_of = |nodes: &[usize]| {
            let mut rows = SparseRows::new(n);
            for &node in nodes {
                rows.push_row([(3 * node, 0.6), (3 * node + 1, 0.8)]);
            }
            rows
        };
        let store = BlockSolveStore::default();
        store.set_unit_solves(true);
        op.view().reserve_interface(RowStack::new(&rows_of(&[2, 9, 17, 30]), None), &store);
        let mut solves = Vec::new();
        for nodes in [&[2usize, 9][..], &[9, 30][..], &[2, 30][..]] {
            let rows = rows_of(nodes);
            let (columns, solved) = all_columns(&op, &rows, &store);
            solves.push(solved);
            let reference = reference_columns(&op, &rows);
            for (j, col) in columns.iter().enumerate() {
                for (a, b) in col.as_ref().expect("column").iter().zip(&reference[j]) {
                    assert!((a - b).abs() <= 1e-13, "{a} vs {b}");
                }
            }
        }
        assert_eq!(solves, vec![4, 2, 0], "unit solves per call");
    }

    /// Sparse right-hand sides on the trailing block, in groups sorted by first position on
    /// two threads ([`TrailingBlock::solve_sparse_columns`]), equal `A⁻¹ c` of whole solves on
    /// the trailing dofs to 1e-12 (unit and two-entry vectors in shuffled order, a repeated
    /// position, more than two groups); a position outside the block is an error.
    #[test]
    fn sparse_trailing_columns_equal_whole_solves() {
        let a = grid(40);
        let n = a.n();
        let last: Vec<usize> = (0..n).filter(|i| i % 5 == 0).take(300).collect();
        let op = SparseCholesky::new(a, &Ordering::Trailing { base: Box::new(Ordering::Amd), last })
            .expect("factor");
        let block = op.view().factor().trailing().expect("trailing block").clone();
        let k = block.dofs.len();
        assert_eq!(k, 300);
        let rhs: Vec<Vec<(usize, f64)>> = (0..150)
            .map(|j| {
                let p = (j * 97 + 13) % k;
                match j % 3 {
                    0 => vec![(p, 1.0)],
                    1 => vec![(p, 0.5), ((p * 7 + 3) % k, -2.0)],
                    _ => vec![(p, 1.0), (p, 0.25)],
                }
            })
            .collect();
        let got = block.solve_sparse_columns(&rhs, true).expect("solves");
        assert_equal_whole_solves(&op, &block, &rhs, &got, "sparse trailing solve");
        assert!(block.solve_sparse_columns(&[vec![(k, 1.0)]], false).is_err());
    }

    /// Each column `x` of `got` equals the trailing rows of the whole solve `A⁻¹ c` of its
    /// right-hand side `c` (`(trailing position, value)` pairs) to 1e-12 relative.
    fn assert_equal_whole_solves(
        op: &SparseCholesky,
        block: &crate::cholesky::TrailingBlock,
        rhs: &[Vec<(usize, f64)>],
        got: &[Vec<f64>],
        what: &str,
    ) {
        let n = op.view().n();
        for (c, x) in rhs.iter().zip(got) {
            let mut b = vec![0.0; n];
            for &(p, v) in c {
                b[block.dofs[p]] += v;
            }
            op.solve_in_place(&mut b).expect("solve");
            let want: Vec<f64> = block.dofs.iter().map(|&d| b[d]).collect();
            let scale = want.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let err = x.iter().zip(&want).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs())) / scale;
            assert!(err < 1e-12, "{what} differs by {err:e}");
        }
    }

    /// Two grids that nothing couples (two bodies touching only through contact), trailing
    /// dofs from both: `L₂₂` splits into one diagonal block per grid
    /// ([`crate::cholesky::diagonal_blocks`]), and right-hand sides on one grid or on both,
    /// solved block by block, equal `A⁻¹ c` of whole solves to 1e-12 (zero on a grid they do
    /// not touch).
    #[test]
    fn block_diagonal_trailing_factor_is_solved_per_block() {
        let (g, m) = (grid(20), 400);
        let n = 2 * m;
        let pattern = g.pattern();
        let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
        let mut columns = vec![Vec::new(); n];
        for j in 0..m {
            for &i in &ri[cp[j]..cp[j + 1]] {
                columns[j].push(i);
                columns[j + m].push(i + m);
            }
        }
        let mut a = SymmetricMatrix::from_columns(n, columns).expect("pattern");
        for j in 0..m {
            for &i in &ri[cp[j]..cp[j + 1]] {
                let v = g.get(i, j);
                a.add(i, j, v).expect("entry");
                a.add(i + m, j + m, (1.0 + 0.5 * (i % 3) as f64 / 3.0) * v).expect("entry");
            }
        }
        // the last row of each grid, interleaved
        let last: Vec<usize> = (0..20).flat_map(|c| [m - 20 + c, n - 20 + c]).collect();
        let op = SparseCholesky::new(a, &Ordering::Trailing { base: Box::new(Ordering::Amd), last })
            .expect("factor");
        let block = op.view().factor().trailing().expect("trailing block").clone();
        let k = block.dofs.len();
        assert_eq!(block.blocks.len(), 2, "one diagonal block per grid: {:?}", block.blocks);
        assert_eq!(block.blocks.first().map(|b| b.start), Some(0));
        assert_eq!(block.blocks.last().map(|b| b.end), Some(k));
        let rhs: Vec<Vec<(usize, f64)>> = (0..k)
            .map(|p| vec![(p, 1.0)])
            .chain((0..k / 2).map(|p| vec![(p, 1.0), (k - 1 - p, -0.5)]))
            .collect();
        let got = block.solve_sparse_columns(&rhs, true).expect("solves");
        assert_equal_whole_solves(&op, &block, &rhs, &got, "per-block solve");
    }

    /// [`crate::cholesky::diagonal_blocks`] of small lower-triangular matrices: a dense one is
    /// one block, a diagonal one `k` blocks, and a coupling below the diagonal joins the blocks
    /// it spans.
    #[test]
    fn diagonal_blocks_of_lower_triangular_matrices() {
        use crate::cholesky::diagonal_blocks;
        let dense = faer::Mat::<f64>::from_fn(4, 4, |i, j| if i >= j { 1.0 } else { 0.0 });
        assert_eq!(diagonal_blocks(dense.as_ref()), vec![0..4]);
        let diag = faer::Mat::<f64>::from_fn(3, 3, |i, j| if i == j { 2.0 } else { 0.0 });
        assert_eq!(diagonal_blocks(diag.as_ref()), vec![0..1, 1..2, 2..3]);
        // l[(3, 1)] couples rows 1..=3; row 0 and rows 4..6 stand alone or together
        let mut l = faer::Mat::<f64>::from_fn(6, 6, |i, j| if i == j { 1.0 } else { 0.0 });
        l[(3, 1)] = 0.5;
        l[(5, 4)] = 0.25;
        assert_eq!(diagonal_blocks(l.as_ref()), vec![0..1, 1..4, 4..6]);
        assert!(diagonal_blocks(faer::Mat::<f64>::zeros(0, 0).as_ref()).is_empty());
    }
}
