//! Sparse Cholesky `A = L Lᵀ` (faer) with the symbolic analysis done once and the numeric
//! factorisation repeatable for new values on the same pattern.
//!
//! Fill-reducing orderings: faer's AMD, or METIS nested dissection (through `metis-sys`) on the
//! node-group graph expanded to its dofs, which makes 3D factorisations 1.6–2.5× faster with
//! less memory (see `docs/performance.md`).

use std::sync::Arc;
use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::{Conj, MatMut, Par, Side};

use crate::error::LinalgError;
use crate::sparse::SymmetricMatrix;

/// Fill-reducing ordering of the Cholesky factorisation.
#[derive(Debug, Clone, Default, PartialEq)]
pub enum Ordering {
    /// faer's approximate minimum degree (default for 2D).
    #[default]
    Amd,
    /// METIS nested dissection of the given graph of *blocks* (node groups), each block
    /// expanded to its dofs (default for 3D). `blocks[k]` = dof range of block `k`;
    /// `adjacency[k]` its neighbour blocks.
    Metis {
        /// Dof ranges of the blocks, contiguous and increasing.
        blocks: Vec<std::ops::Range<usize>>,
        /// Neighbours of each block (without itself).
        adjacency: Vec<Vec<usize>>,
    },
    /// A given forward permutation of the dofs.
    Custom(Vec<usize>),
    /// The `base` ordering with the dofs `last` moved (in their `base` order) to the end, so
    /// that the trailing block `L₂₂` of the factor belongs to them
    /// ([`CholeskySolver::trailing`]).
    Trailing {
        /// Ordering of everything else.
        base: Box<Ordering>,
        /// Dofs to eliminate last (distinct, `< n`).
        last: Vec<usize>,
    },
}

/// The trailing block of a factorisation with [`Ordering::Trailing`]: with the dofs `c` ordered
/// last, `P A Pᵀ = L Lᵀ` gives `(A⁻¹)_cc = L₂₂⁻ᵀ L₂₂⁻¹` (docs/model.md §6.4: the interface Schur
/// complement needs no solve with the whole factor).
#[derive(Debug, Clone)]
pub struct TrailingBlock {
    /// The trailing dofs, in factor order.
    pub dofs: Vec<usize>,
    /// `position[dof]` = index of `dof` in [`Self::dofs`], or `usize::MAX`.
    pub position: Vec<usize>,
    /// The diagonal blocks of `L₂₂` with nothing below them (consecutive ranges covering
    /// `0..k`, [`diagonal_blocks`]): `L₂₂ = diag(L₁, L₂, …)`, e.g. one block per body of an
    /// interface between bodies that only contact couples. One block `0..k` is always correct.
    pub blocks: Vec<std::ops::Range<usize>>,
    /// Where the dense lower-triangular blocks `L_b` are stored.
    storage: TrailingStorage,
    /// A number no other trailing block of this process has ([`Self::generation`]).
    generation: u64,
}

/// The next [`TrailingBlock::generation`] or [`CholeskySolver::generation`].
static TRAILING_GENERATION: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

fn next_generation() -> u64 {
    TRAILING_GENERATION.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// The storage of the blocks of `L₂₂` ([`TrailingBlock::diagonal_block`]).
#[derive(Clone)]
enum TrailingStorage {
    /// A dense `k × k` copy of `L₂₂`.
    Copied(faer::Mat<f64>),
    /// Read in place from the supernodal factor's values: when every supernode holding
    /// trailing columns has nothing below its diagonal block (each is a root of the elimination
    /// forest, as the interface's dense Schur complement of one body is), block `b` is the
    /// trailing `size × size` part of one supernode's dense column-major `ncols × ncols` block —
    /// no copy of `L₂₂` (288 MB at `k = 6 000`). `(offset, ncols, first)`: the supernode's
    /// first value, its columns, and the block's first column within it.
    InFactor { values: Arc<Vec<f64>>, supernodes: Vec<(usize, usize, usize)> },
}

/// Sizes only: the values are the factor's (millions of entries).
impl std::fmt::Debug for TrailingStorage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Copied(l) => write!(f, "Copied({} × {})", l.nrows(), l.ncols()),
            Self::InFactor { values, supernodes } => {
                write!(f, "InFactor {{ factor entries: {}, supernodes: {supernodes:?} }}", values.len())
            }
        }
    }
}

/// The finest partition of `0..k` into consecutive ranges `a..b` with `l[(i, j)] = 0` for all
/// `j < b ≤ i` (nothing below a range's diagonal block), for a lower-triangular `k × k` `l`:
/// column `j` reaches down to its last non-zero row, and a block ends where no column so far
/// reaches past it.
pub fn diagonal_blocks(l: faer::MatRef<'_, f64>) -> Vec<std::ops::Range<usize>> {
    let k = l.nrows().min(l.ncols());
    let mut blocks = Vec::new();
    let (mut start, mut reach) = (0, 0);
    for j in 0..k {
        let last = (j..k).rev().find(|&i| l[(i, j)] != 0.0).unwrap_or(j);
        reach = reach.max(last);
        if reach == j {
            blocks.push(start..j + 1);
            start = j + 1;
        }
    }
    blocks
}

impl TrailingBlock {
    /// The dense lower-triangular diagonal block `L_b` of `L₂₂` on the rows and columns
    /// `self.blocks[b]` (`None` for `b` out of range).
    pub fn diagonal_block(&self, b: usize) -> Option<faer::MatRef<'_, f64>> {
        let range = self.blocks.get(b)?;
        match &self.storage {
            TrailingStorage::Copied(l) => {
                Some(l.as_ref().submatrix(range.start, range.start, range.len(), range.len()))
            }
            TrailingStorage::InFactor { values, supernodes } => {
                let &(offset, ncols, first) = supernodes.get(b)?;
                let whole = faer::MatRef::from_column_major_slice(
                    values.get(offset..offset + ncols * ncols)?,
                    ncols,
                    ncols,
                );
                Some(whole.submatrix(first, first, ncols - first, ncols - first))
            }
        }
    }

    /// The entry `(L₂₂)_ij` (zero outside the diagonal blocks and above the diagonal).
    pub fn entry(&self, i: usize, j: usize) -> f64 {
        let Some(b) = self.blocks.iter().position(|r| r.contains(&i)) else { return 0.0 };
        let range = &self.blocks[b];
        if !range.contains(&j) || j > i {
            return 0.0;
        }
        self.diagonal_block(b).map_or(0.0, |l| l[(i - range.start, j - range.start)])
    }

    /// A number that identifies this block among all blocks of the process (one per
    /// factorisation): caches keyed by it cannot mistake a refactorised block for the old one,
    /// even at the same address.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Whether `L₂₂` is read from the factor's own storage (no dense copy).
    pub fn in_factor(&self) -> bool {
        matches!(self.storage, TrailingStorage::InFactor { .. })
    }

    /// `z ← L₂₂⁻¹ z` (`transpose = false`) or `z ← L₂₂⁻ᵀ z` for one right-hand side of `k`
    /// entries, block by block (`L₂₂ = diag(L_b)`; a zero block stays zero).
    fn triangular_solve_in_place(&self, z: &mut [f64], transpose: bool) {
        for (b, range) in self.blocks.iter().enumerate() {
            let (Some(l), Some(zb)) = (self.diagonal_block(b), z.get_mut(range.clone())) else { continue };
            if zb.iter().all(|v| *v == 0.0) {
                continue;
            }
            let size = zb.len();
            let zb = MatMut::from_column_major_slice_mut(zb, size, 1);
            if transpose {
                faer::linalg::triangular_solve::solve_upper_triangular_in_place(l.transpose(), zb, Par::Seq);
            } else {
                faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, zb, Par::Seq);
            }
        }
    }

    /// Solves `(A⁻¹)_cc`-products in place: `X ← L₂₂⁻ᵀ L₂₂⁻¹ X` for the `k × r` block `x`
    /// (rows in the order of [`Self::dofs`]).
    ///
    /// Each diagonal block `L_b` of [`Self::blocks`] is solved on its own rows
    /// (`L₂₂ = diag(L_b)`, so `L₂₂⁻ᵀ L₂₂⁻¹ X = [L_b⁻ᵀ L_b⁻¹ X_b]_b`), and a block whose rows of
    /// `X` are zero is skipped. Within a block the forward half starts at its first non-zero
    /// row `f`: with `X_b = [0; X₂]` (`X₂` from row `f`), `L_b⁻¹ X_b = [0; L_ff⁻¹ X₂]` for the
    /// trailing block `L_ff` of `L_b`, so `(k_b − f)²` instead of `k_b²` work per column (the
    /// backward half `L_b⁻ᵀ` runs over all of the block's rows). Right-hand sides sorted by
    /// their first non-zero row and solved in groups ([`Self::solve_sparse_columns`]) make use
    /// of it.
    ///
    /// # Errors
    /// [`LinalgError::Length`] when `x` does not have the block's `k` rows.
    pub fn solve_in_place(&self, mut x: MatMut<'_, f64>) -> Result<(), LinalgError> {
        let k = self.dofs.len();
        if x.nrows() != k || self.blocks.last().is_some_and(|b| b.end != k) {
            return Err(LinalgError::Length {
                what: "trailing-block right-hand sides",
                expected: k,
                got: x.nrows(),
            });
        }
        for (b, block) in self.blocks.iter().enumerate() {
            let (a, size) = (block.start, block.len());
            let Some(first) = (0..size).find(|&i| (0..x.ncols()).any(|c| x[(a + i, c)] != 0.0)) else {
                continue;
            };
            let Some(l) = self.diagonal_block(b) else { continue };
            let mut xb = x.rb_mut().subrows_mut(a, size);
            faer::linalg::triangular_solve::solve_lower_triangular_in_place(
                l.submatrix(first, first, size - first, size - first),
                xb.rb_mut().subrows_mut(first, size - first),
                Par::Seq,
            );
            faer::linalg::triangular_solve::solve_upper_triangular_in_place(l.transpose(), xb, Par::Seq);
        }
        Ok(())
    }

    /// `x_j = L₂₂⁻ᵀ L₂₂⁻¹ c_j` for sparse right-hand sides `c_j` given as `(position, value)`
    /// lists in the positions of [`Self::dofs`] (repeated positions add up), returned densely
    /// in the order of `rhs`. The right-hand sides are sorted by their first position and
    /// solved in groups of [`SPARSE_GROUP`] ([`Self::solve_in_place`] starts each group's
    /// forward half at its first non-zero row), the groups alternating between two threads
    /// when `threads` is set and there are at least two groups.
    ///
    /// # Errors
    /// [`LinalgError::InvalidParameter`] for a position `≥ k`.
    pub fn solve_sparse_columns(
        &self,
        rhs: &[Vec<(usize, f64)>],
        threads: bool,
    ) -> Result<Vec<Vec<f64>>, LinalgError> {
        let k = self.dofs.len();
        if let Some(&(p, _)) = rhs.iter().flatten().find(|&&(p, _)| p >= k) {
            return Err(LinalgError::InvalidParameter(format!(
                "position {p} outside the trailing block of {k} dofs"
            )));
        }
        let mut order: Vec<usize> = (0..rhs.len()).collect();
        let first = |j: usize| rhs[j].iter().map(|&(p, _)| p).min().unwrap_or(k);
        order.sort_by_key(|&j| (first(j), j));
        let groups: Vec<&[usize]> = order.chunks(SPARSE_GROUP).collect();
        type Solved = Vec<(usize, Vec<f64>)>;
        let solve_group = |group: &[usize]| -> Result<Solved, LinalgError> {
            let mut x = faer::Mat::<f64>::zeros(k, group.len());
            for (c, &j) in group.iter().enumerate() {
                for &(p, v) in &rhs[j] {
                    x[(p, c)] += v;
                }
            }
            self.solve_in_place(x.as_mut())?;
            Ok(group.iter().enumerate().map(|(c, &j)| (j, x.col(c).iter().copied().collect())).collect())
        };
        let solve_share = |share: usize, of: usize| -> Result<Solved, LinalgError> {
            let mut out = Vec::new();
            for g in groups.iter().skip(share).step_by(of) {
                out.extend(solve_group(g)?);
            }
            Ok(out)
        };
        let solved: Solved = if threads && groups.len() >= 2 {
            std::thread::scope(|scope| {
                let other = scope.spawn(|| solve_share(1, 2));
                let mine = solve_share(0, 2);
                // a panic of the other half is re-raised here (no user input can cause one)
                let theirs = match other.join() {
                    Ok(theirs) => theirs,
                    Err(e) => std::panic::resume_unwind(e),
                };
                let mut mine = mine?;
                mine.extend(theirs?);
                Ok::<_, LinalgError>(mine)
            })?
        } else {
            solve_share(0, 1)?
        };
        let mut out = vec![Vec::new(); rhs.len()];
        for (j, x) in solved {
            out[j] = x;
        }
        Ok(out)
    }
}

/// Right-hand sides per group of [`TrailingBlock::solve_sparse_columns`]: each group streams
/// `L₂₂` twice (288 MB at `k = 6000`), so groups much smaller than this are bound by memory
/// (measured on a 6000 × 6000 block with 1 093 unit right-hand sides: 1.14 s in groups of 48,
/// 0.62 s in groups of 192, 1.30 s in one call without the sorted forward start).
pub const SPARSE_GROUP: usize = 192;

/// Timings of the stages of a factorisation, in seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CholeskyInfo {
    /// Ordering + symbolic analysis.
    pub symbolic_s: f64,
    /// Last numeric factorisation.
    pub numeric_s: f64,
    /// Number of stored entries of `L`.
    pub factor_nnz: usize,
}

/// The memory a numeric factorisation needs, from the symbolic analysis
/// ([`CholeskySolver::memory_estimate`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// Unknowns.
    pub dofs: usize,
    /// Stored entries of `L`.
    pub factor_entries: usize,
    /// Bytes of the factor's values.
    pub factor_bytes: u64,
    /// Bytes of faer's workspace of the numeric factorisation.
    pub workspace_bytes: u64,
    /// Bytes of the dense copy of the trailing block `L₂₂` of an [`Ordering::Trailing`]
    /// factorisation (zero when it is read in place from the factor).
    pub trailing_bytes: u64,
}

impl MemoryEstimate {
    /// Total bytes.
    pub fn total_bytes(&self) -> u64 {
        self.factor_bytes.saturating_add(self.workspace_bytes).saturating_add(self.trailing_bytes)
    }
    /// Total in GiB.
    pub fn total_gib(&self) -> f64 {
        self.total_bytes() as f64 / GIB
    }
}

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// The environment variable that caps the memory a factorisation may use, in MiB (overrides
/// the available memory of the system; [`memory_limit`]).
pub const MEMORY_LIMIT_ENV: &str = "SYNOVIA_MEMORY_LIMIT_MB";

/// The memory a factorisation may use, in bytes, and where the figure comes from: the
/// environment variable [`MEMORY_LIMIT_ENV`] (MiB) if set to a number, else `MemAvailable` of
/// `/proc/meminfo` (Linux), else `None` (unknown: no check).
pub fn memory_limit() -> Option<(u64, String)> {
    if let Ok(v) = std::env::var(MEMORY_LIMIT_ENV) {
        if let Ok(mb) = v.trim().parse::<f64>() {
            if mb.is_finite() && mb >= 0.0 {
                return Some((
                    (mb * 1024.0 * 1024.0) as u64,
                    format!("allowed by {MEMORY_LIMIT_ENV}={}", v.trim()),
                ));
            }
        }
    }
    available_memory().map(|b| (b, "available (MemAvailable of /proc/meminfo)".to_string()))
}

/// `MemAvailable` of `/proc/meminfo` in bytes (`None` where there is no such file).
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb.saturating_mul(1024))
}

/// A sparse Cholesky solver for a [`SymmetricMatrix`] pattern.
#[derive(Debug, Clone)]
pub struct CholeskySolver {
    symbolic: Arc<SymbolicCholesky<usize>>,
    /// The factor's values; shared with the [`TrailingBlock`] that reads `L₂₂` from them.
    factor: Arc<Vec<f64>>,
    factorized: bool,
    info: CholeskyInfo,
    trailing_dofs: Option<Vec<usize>>,
    /// The supernodes that hold the trailing block in place ([`Self::trailing_supernodes`] of
    /// the symbolic analysis, computed once in [`Self::analyse`]); `None`: the block is copied.
    trailing_layout: Option<Vec<(usize, usize, usize)>>,
    trailing: Option<Arc<TrailingBlock>>,
    memory_limit: Option<u64>,
    /// faer's workspace of the numeric factorisation (from the symbolic analysis and
    /// [`Self::numeric_par`], both fixed): computed once in [`Self::analyse`] instead of twice
    /// per factorisation (a loop over every supernode's descendants, 2.4 % of the CPU time of
    /// the `knee2d` neo-Hookean cycle's 56 refactorisations; docs/nonlinear.md, "Fourth round").
    numeric_scratch: (Par, faer::dyn_stack::StackReq),
    /// A number no other factorisation of this process has ([`Self::generation`]).
    generation: u64,
}

/// The parallelism of the numeric factorisation of `symbolic`: threads pay only for large
/// factors; below `nnz(L)² / n = 1e10` (≈ flops / 2) the sequential factorisation is faster
/// (docs/performance.md, "Parallel assembly").
fn numeric_par_of(symbolic: &SymbolicCholesky<usize>) -> Par {
    let len = symbolic.len_val();
    let work = (len as f64) * (len as f64) / (symbolic.nrows().max(1) as f64);
    if work < 1e10 {
        Par::Seq
    } else {
        faer::get_global_parallelism()
    }
}

impl CholeskySolver {
    /// Symbolic analysis of the pattern of `a` with the given ordering.
    pub fn analyse(a: &SymmetricMatrix, ordering: &Ordering) -> Result<Self, LinalgError> {
        let t0 = Instant::now();
        let n = a.n();
        let (perm, trailing_dofs) = match ordering {
            Ordering::Trailing { base, last } => {
                let base_perm = match base.as_ref() {
                    Ordering::Trailing { .. } => {
                        return Err(LinalgError::InvalidParameter("nested trailing orderings".into()))
                    }
                    other => match explicit_order(n, other)? {
                        Some(p) => p,
                        None => amd_order(a)?,
                    },
                };
                inverse_permutation(&base_perm, n)?;
                let mut is_last = vec![false; n];
                for &d in last {
                    if d >= n || is_last[d] {
                        return Err(LinalgError::InvalidParameter(format!(
                            "trailing dofs must be distinct and < {n} (dof {d})"
                        )));
                    }
                    is_last[d] = true;
                }
                let (mut fwd, tail): (Vec<usize>, Vec<usize>) = base_perm.iter().partition(|&&d| !is_last[d]);
                fwd.extend_from_slice(&tail);
                (Some(fwd), Some(tail))
            }
            other => (explicit_order(n, other)?, None),
        };
        // METIS's nested dissection and a trailing block leave the elimination tree out of
        // postorder; a postorder of the leading columns gives the same factor with each
        // subtree contiguous, so that faer's supernodes can merge (postorder_leading)
        let perm = match perm {
            Some(fwd) if matches!(ordering, Ordering::Metis { .. } | Ordering::Trailing { .. }) => {
                let lead = n - trailing_dofs.as_ref().map_or(0, Vec::len);
                Some(postorder_leading(a, fwd, lead)?)
            }
            other => other,
        };
        let symbolic = match &perm {
            None => factorize_symbolic_cholesky(
                a.pattern().as_ref(),
                Side::Lower,
                SymmetricOrdering::Amd,
                CholeskySymbolicParams::default(),
            ),
            Some(fwd) => {
                let inv = inverse_permutation(fwd, n)?;
                let perm = PermRef::new_checked(fwd, &inv, n);
                factorize_symbolic_cholesky(
                    a.pattern().as_ref(),
                    Side::Lower,
                    SymmetricOrdering::Custom(perm),
                    CholeskySymbolicParams::default(),
                )
            }
        }
        .map_err(|e| LinalgError::Sparse(format!("symbolic Cholesky: {e:?}")))?;
        let trailing_layout = trailing_dofs
            .as_ref()
            .filter(|d| !d.is_empty() && d.len() <= n)
            .and_then(|d| Self::trailing_supernodes(&symbolic, n - d.len()));
        let len = symbolic.len_val();
        let info = CholeskyInfo { symbolic_s: t0.elapsed().as_secs_f64(), numeric_s: 0.0, factor_nnz: len };
        let par = numeric_par_of(&symbolic);
        let numeric_scratch = (par, symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
        Ok(Self {
            symbolic: Arc::new(symbolic),
            factor: Arc::new(Vec::new()),
            factorized: false,
            info,
            trailing_layout,
            trailing_dofs,
            trailing: None,
            memory_limit: None,
            numeric_scratch,
            generation: next_generation(),
        })
    }

    /// The parallelism of the numeric factorisation: threads pay only for large factors;
    /// below `nnz(L)² / n = 1e10` (≈ flops / 2) the sequential factorisation is faster
    /// (docs/performance.md, "Parallel assembly").
    fn numeric_par(&self) -> Par {
        numeric_par_of(&self.symbolic)
    }

    /// faer's workspace of the numeric factorisation with `par`: the one kept from the analysis
    /// unless the global parallelism changed since.
    fn numeric_scratch_for(&self, par: Par) -> faer::dyn_stack::StackReq {
        match self.numeric_scratch {
            (p, req) if p == par => req,
            _ => self.symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
        }
    }

    /// The memory the numeric factorisation needs (factor values, faer's workspace, the dense
    /// trailing block), from the symbolic analysis.
    pub fn memory_estimate(&self) -> MemoryEstimate {
        let entries = self.symbolic.len_val();
        let req = self.numeric_scratch_for(self.numeric_par());
        let k = self.trailing_dofs.as_ref().map_or(0, Vec::len);
        let n = self.symbolic.nrows();
        // a block read in place from the factor costs nothing besides it
        let copied = k > 0 && k <= n && self.trailing_layout.is_none();
        let k = if copied { k as u64 } else { 0 };
        MemoryEstimate {
            dofs: n,
            factor_entries: entries,
            factor_bytes: (entries as u64).saturating_mul(8),
            workspace_bytes: req.size_bytes() as u64,
            trailing_bytes: k.saturating_mul(k).saturating_mul(8),
        }
    }

    /// Caps the memory of the numeric factorisation at `bytes` (instead of [`memory_limit`]:
    /// [`MEMORY_LIMIT_ENV`] or the available memory); `None` restores the default.
    pub fn set_memory_limit(&mut self, bytes: Option<u64>) {
        self.memory_limit = bytes;
    }

    /// Checks that the numeric factorisation fits in memory: the [`Self::memory_estimate`]
    /// against the limit of [`Self::set_memory_limit`], else [`memory_limit`] (no check when
    /// the available memory is unknown). Returns the estimate.
    ///
    /// # Errors
    /// [`LinalgError::OutOfMemory`] with the bytes needed and available.
    pub fn check_memory(&self) -> Result<MemoryEstimate, LinalgError> {
        let estimate = self.memory_estimate();
        let limit = match self.memory_limit {
            Some(b) => Some((b, "allowed by the memory limit".to_string())),
            None => memory_limit(),
        };
        // what is already allocated for the factor is not needed again
        let held = (self.factor.capacity() as u64).saturating_mul(8);
        if let Some((available, origin)) = limit {
            if estimate.total_bytes().saturating_sub(held) > available {
                return Err(LinalgError::OutOfMemory {
                    needed: estimate.total_bytes(),
                    available,
                    origin,
                    dofs: estimate.dofs,
                    factor_entries: estimate.factor_entries,
                });
            }
        }
        Ok(estimate)
    }

    /// Numeric factorisation of `a` (same pattern as analysed), reusing the symbolic analysis.
    pub fn factorize(&mut self, a: &SymmetricMatrix) -> Result<(), LinalgError> {
        let t0 = Instant::now();
        if a.n() != self.symbolic.nrows() {
            return Err(LinalgError::Length { what: "matrix", expected: self.symbolic.nrows(), got: a.n() });
        }
        self.factorized = false;
        // the values change from here on (also when the factorisation fails): a new generation,
        // so that no solve kept under the old one is taken for this factorisation's
        self.generation = next_generation();
        // the trailing block may read the old values in place: dropped first, so that the
        // values can be refactorised where they are
        self.trailing = None;
        self.check_memory()?;
        let len = self.symbolic.len_val();
        // the supernodal factorisation sets every value of the factor to zero itself before
        // it scatters `a` (faer 0.24), so a factor of the right length is refactorised in
        // place; the simplicial one expects zeros
        let supernodal =
            matches!(self.symbolic.raw(), faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(_));
        let par = self.numeric_par();
        let req = self.numeric_scratch_for(par);
        let mut mem =
            MemBuffer::try_new(req).map_err(|_| LinalgError::Sparse("out of memory (scratch)".into()))?;
        if Arc::get_mut(&mut self.factor).is_none() {
            // a trailing block handed out before still reads the old values: new storage
            self.factor = Arc::new(Vec::new());
        }
        // the storage is not shared now (replaced just above if it was), so this never copies
        let values = Arc::make_mut(&mut self.factor);
        if !(supernodal && values.len() == len) {
            values.clear();
            values.try_reserve_exact(len).map_err(|_| {
                LinalgError::Sparse(format!("out of memory for a Cholesky factor of {len} entries"))
            })?;
            values.resize(len, 0.0);
        }
        self.symbolic
            .factorize_numeric_llt::<f64>(
                values,
                a.as_faer(),
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| match e {
                faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } => {
                    LinalgError::NotPositiveDefinite { index }
                }
            })?;
        self.factorized = true;
        self.trailing = match &self.trailing_dofs {
            Some(dofs) if !dofs.is_empty() => Some(Arc::new(self.extract_trailing(dofs)?)),
            _ => None,
        };
        self.info.numeric_s = t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// A number that identifies the present factorisation among all factorisations of the
    /// process (a new one at every [`Self::factorize`]; clones share it with their values):
    /// caches of solves keyed by it cannot mistake a refactorised solver, or a new solver
    /// allocated where a dropped one was, for the old one.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The trailing block `L₂₂` of an [`Ordering::Trailing`] factorisation (after
    /// [`CholeskySolver::factorize`]).
    pub fn trailing(&self) -> Option<&Arc<TrailingBlock>> {
        self.trailing.as_ref()
    }

    /// The supernodes holding the trailing columns `t0..n` as `(offset of the values, columns,
    /// first trailing column within it)`, when each has nothing below its diagonal block and
    /// they cover `t0..n` (then `L₂₂` is block diagonal with one block per supernode, stored
    /// densely in the factor); `None` otherwise (simplicial factors included).
    fn trailing_supernodes(
        symbolic: &SymbolicCholesky<usize>,
        t0: usize,
    ) -> Option<Vec<(usize, usize, usize)>> {
        use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
        let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw() else { return None };
        let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
        let (row_ptr, val_ptr) = (sym.col_ptr_for_row_idx(), sym.col_ptr_for_val());
        let mut out = Vec::new();
        let mut covered = t0;
        for s in 0..sym.n_supernodes() {
            if end[s] <= t0 {
                continue;
            }
            let ncols = end[s] - begin[s];
            let pattern = row_ptr[s + 1] - row_ptr[s];
            if pattern != 0 || begin[s].max(t0) != covered || val_ptr[s + 1] - val_ptr[s] != ncols * ncols {
                return None;
            }
            out.push((val_ptr[s], ncols, t0.saturating_sub(begin[s])));
            covered = end[s];
        }
        (covered == symbolic.nrows() && !out.is_empty()).then_some(out)
    }

    /// The trailing block `L₂₂` of the last `k = dofs.len()` columns of `L` (rows ≥ `n − k`):
    /// read in place from the factor when its supernodes allow
    /// ([`Self::trailing_supernodes`]), else copied into a dense `k × k` matrix.
    fn extract_trailing(&self, dofs: &[usize]) -> Result<TrailingBlock, LinalgError> {
        use faer::sparse::linalg::cholesky::{supernodal::SupernodalLltRef, SymbolicCholeskyRaw};
        let n = self.symbolic.nrows();
        let k = dofs.len();
        let t0 = n - k;
        let mut position = vec![usize::MAX; n];
        for (p, &d) in dofs.iter().enumerate() {
            position[d] = p;
        }
        // the layout belongs to the analysed trailing dofs (the only caller's `dofs`)
        let layout = self.trailing_layout.as_ref().filter(|_| Some(dofs) == self.trailing_dofs.as_deref());
        if let Some(supernodes) = layout {
            let mut blocks = Vec::with_capacity(supernodes.len());
            let mut start = 0;
            for &(_, ncols, first) in supernodes {
                blocks.push(start..start + ncols - first);
                start += ncols - first;
            }
            return Ok(TrailingBlock {
                dofs: dofs.to_vec(),
                position,
                blocks,
                storage: TrailingStorage::InFactor {
                    values: self.factor.clone(),
                    supernodes: supernodes.clone(),
                },
                generation: next_generation(),
            });
        }
        let mut l22 = faer::Mat::<f64>::zeros(k, k);
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(sym) => {
                let col_ptr = sym.col_ptr();
                let row_idx = sym.row_idx();
                for j in t0..n {
                    let range = col_ptr[j]..col_ptr[j + 1];
                    for (&i, &v) in row_idx[range.clone()].iter().zip(&self.factor.as_slice()[range]) {
                        if i >= j {
                            l22[(i - t0, j - t0)] = v;
                        }
                    }
                }
            }
            SymbolicCholeskyRaw::Supernodal(sym) => {
                let llt = SupernodalLltRef::new(sym, self.factor.as_slice());
                for s in 0..sym.n_supernodes() {
                    let node = llt.supernode(s);
                    let start = node.start();
                    let val = node.val();
                    let ncols = val.ncols();
                    let end = start + ncols;
                    if end <= t0 {
                        continue;
                    }
                    let pattern = node.pattern();
                    for c in 0..ncols {
                        let j = start + c;
                        if j < t0 {
                            continue;
                        }
                        for r in c..ncols {
                            l22[(start + r - t0, j - t0)] = val[(r, c)];
                        }
                        for (pi, &i) in pattern.iter().enumerate() {
                            l22[(i - t0, j - t0)] = val[(ncols + pi, c)];
                        }
                    }
                }
            }
        }
        let blocks = diagonal_blocks(l22.as_ref());
        Ok(TrailingBlock {
            dofs: dofs.to_vec(),
            position,
            blocks,
            storage: TrailingStorage::Copied(l22),
            generation: next_generation(),
        })
    }

    /// Solves `A x = b` in place for a right-hand side that vanishes outside the trailing
    /// dofs `c` of an [`Ordering::Trailing`] factorisation (e.g. contact forces `Cᵀ ν`), at
    /// about half the cost of [`CholeskySolver::solve_in_place`]: with `P A Pᵀ = L Lᵀ` and
    /// `P b = (0, b_c)`, the forward substitution is `y = (0, L₂₂⁻¹ b_c)` (dense, size
    /// `k = |c|`), and only the backward substitution `Lᵀ P x = y` runs over the whole factor
    /// (docs/model.md §6.4). Without a trailing block, or for a `b` with entries outside `c`, a
    /// whole solve (for a `b` with few non-zeros, its forward half on their elimination-tree
    /// paths only: [`CholeskySolver::solve_sparse_on`]).
    ///
    /// # Errors
    /// As [`CholeskySolver::solve_in_place`].
    pub fn solve_trailing_supported_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        let n = self.symbolic.nrows();
        let (Some(block), Some(perm), true) = (self.trailing.as_ref(), self.symbolic.perm(), self.factorized)
        else {
            return self.solve_sparse_in_place(b);
        };
        if b.len() != n {
            return Err(LinalgError::Length { what: "right-hand side", expected: n, got: b.len() });
        }
        let (fwd, inv) = perm.arrays();
        let k = block.dofs.len();
        let t0 = n - k;
        if fwd[..t0].iter().any(|&i| b[i] != 0.0) {
            return self.solve_sparse_in_place(b);
        }
        let mut z = vec![0.0; n];
        for (p, zp) in z[t0..].iter_mut().enumerate() {
            *zp = b[fwd[t0 + p]];
        }
        block.triangular_solve_in_place(&mut z[t0..], false);
        self.sparse_half_solve(MatMut::from_column_major_slice_mut(&mut z, n, 1), true)?;
        for (i, bi) in b.iter_mut().enumerate() {
            *bi = z[inv[i]];
        }
        Ok(())
    }

    /// Solves `A x = b` in place; a `b` with at most `n / 8` non-zeros (contact forces `Cᵀ ν`
    /// on the active nodes) through [`CholeskySolver::solve_sparse_on`], whose forward half
    /// visits only the supernodes on the elimination-tree paths of those dofs.
    fn solve_sparse_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        let n = self.symbolic.nrows();
        let supernodal =
            matches!(self.symbolic.raw(), faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(_));
        let entries: Vec<(usize, f64)> =
            b.iter().enumerate().filter(|(_, v)| **v != 0.0).map(|(i, &v)| (i, v)).collect();
        if !supernodal || b.len() != n || entries.len() > n / 8 {
            return self.solve_in_place(b);
        }
        let all: Vec<usize> = (0..n).collect();
        let x = self.solve_sparse_on(&[entries], &all)?;
        if let Some(x) = x.first() {
            b.copy_from_slice(x);
        }
        Ok(())
    }

    /// One triangular half of a solve with the sparse factor, in factor order and in place:
    /// `x ← L⁻¹ x` (`transpose = false`) or `x ← L⁻ᵀ x` (`transpose = true`).
    fn sparse_half_solve(&self, x: MatMut<'_, f64>, transpose: bool) -> Result<(), LinalgError> {
        use faer::sparse::linalg::cholesky::{supernodal::SupernodalLltRef, SymbolicCholeskyRaw};
        use faer::sparse::linalg::triangular_solve::{
            solve_lower_triangular_in_place, solve_lower_triangular_transpose_in_place,
        };
        use faer::sparse::SparseColMatRef;
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(sym) => {
                let l = SparseColMatRef::<'_, usize, f64>::new(sym.factor(), self.factor.as_slice());
                if transpose {
                    solve_lower_triangular_transpose_in_place(l, Conj::No, x, Par::Seq);
                } else {
                    solve_lower_triangular_in_place(l, Conj::No, x, Par::Seq);
                }
            }
            SymbolicCholeskyRaw::Supernodal(sym) => {
                let req = self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq);
                let mut mem = MemBuffer::try_new(req)
                    .map_err(|_| LinalgError::Sparse("out of memory (scratch)".into()))?;
                let llt = SupernodalLltRef::new(sym, self.factor.as_slice());
                if transpose {
                    llt.l_transpose_solve_with_conj(Conj::No, x, Par::Seq, MemStack::new(&mut mem));
                } else {
                    llt.l_solve_with_conj(Conj::No, x, Par::Seq, MemStack::new(&mut mem));
                }
            }
        }
        Ok(())
    }

    /// The forward half of a solve with an [`Ordering::Trailing`] factorisation: with
    /// `P A Pᵀ = L Lᵀ`, returns `y = L⁻¹ P b` (in factor order), from which
    /// [`CholeskySolver::trailing_of_forward`] gives `(A⁻¹ b)_c = L₂₂⁻ᵀ y₂` on the trailing
    /// dofs `c` (a dense solve of size `k = |c|`) and [`CholeskySolver::complete_forward`] the
    /// whole `A⁻¹ (b − s)` for any `s` supported on `c` (the backward half). About half the
    /// cost of [`CholeskySolver::solve_in_place`]: for loads whose solution is needed only on
    /// the contact interface (docs/model.md §6.4, the trials of a search over loads). `None`
    /// without a trailing block.
    ///
    /// # Errors
    /// A wrong length, or no successful factorisation.
    pub fn forward_trailing(&self, b: &[f64]) -> Result<Option<Vec<f64>>, LinalgError> {
        let n = self.symbolic.nrows();
        let (Some(_), Some(perm), true) = (self.trailing.as_ref(), self.symbolic.perm(), self.factorized)
        else {
            return Ok(None);
        };
        if b.len() != n {
            return Err(LinalgError::Length { what: "right-hand side", expected: n, got: b.len() });
        }
        let (fwd, _) = perm.arrays();
        let mut y: Vec<f64> = fwd.iter().map(|&i| b[i]).collect();
        self.sparse_half_solve(MatMut::from_column_major_slice_mut(&mut y, n, 1), false)?;
        Ok(Some(y))
    }

    /// `x = A⁻¹ b` on the trailing dofs `c` from the forward half `y = L⁻¹ P b` of
    /// [`CholeskySolver::forward_trailing`]: `x̃₂ = L₂₂⁻ᵀ y₂` (the trailing rows of
    /// `Lᵀ x̃ = y`, `x̃ = P x`), returned as a vector of length `n` that is zero outside `c`.
    ///
    /// # Errors
    /// [`LinalgError::InvalidParameter`] without a trailing block; a wrong length.
    pub fn trailing_of_forward(&self, y: &[f64]) -> Result<Vec<f64>, LinalgError> {
        let n = self.symbolic.nrows();
        let (Some(block), true) = (self.trailing.as_ref(), self.factorized) else {
            return Err(LinalgError::InvalidParameter("no trailing block of the factorisation".into()));
        };
        if y.len() != n {
            return Err(LinalgError::Length { what: "forward solution", expected: n, got: y.len() });
        }
        let k = block.dofs.len();
        let mut z = y[n - k..].to_vec();
        block.triangular_solve_in_place(&mut z, true);
        let mut x = vec![0.0; n];
        for (&d, v) in block.dofs.iter().zip(z) {
            x[d] = v;
        }
        Ok(x)
    }

    /// `x = A⁻¹ (b − s)` from the forward half `y = L⁻¹ P b` of
    /// [`CholeskySolver::forward_trailing`] and an `s` that vanishes outside the trailing dofs
    /// `c` (e.g. contact forces `Cᵀ ν`): `P x = L⁻ᵀ (y − (0, L₂₂⁻¹ s_c))`, a dense forward
    /// solve of size `k` and the backward half over the whole factor. An `s` with entries
    /// outside `c` is solved whole and subtracted.
    ///
    /// # Errors
    /// [`LinalgError::InvalidParameter`] without a trailing block; wrong lengths; a failed solve.
    pub fn complete_forward(&self, y: &[f64], s: &[f64]) -> Result<Vec<f64>, LinalgError> {
        let n = self.symbolic.nrows();
        let (Some(block), Some(perm), true) = (self.trailing.as_ref(), self.symbolic.perm(), self.factorized)
        else {
            return Err(LinalgError::InvalidParameter("no trailing block of the factorisation".into()));
        };
        if y.len() != n || s.len() != n {
            return Err(LinalgError::Length {
                what: "forward solution",
                expected: n,
                got: y.len().min(s.len()),
            });
        }
        let (fwd, inv) = perm.arrays();
        let k = block.dofs.len();
        let t0 = n - k;
        let mut z = y.to_vec();
        let outside = fwd[..t0].iter().any(|&i| s[i] != 0.0);
        if !outside {
            let mut sc: Vec<f64> = (0..k).map(|p| s[fwd[t0 + p]]).collect();
            block.triangular_solve_in_place(&mut sc, false);
            for (zp, v) in z[t0..].iter_mut().zip(&sc) {
                *zp -= v;
            }
        }
        self.sparse_half_solve(MatMut::from_column_major_slice_mut(&mut z, n, 1), true)?;
        let mut x: Vec<f64> = (0..n).map(|i| z[inv[i]]).collect();
        if outside {
            let mut sx = s.to_vec();
            self.solve_in_place(&mut sx)?;
            x.iter_mut().zip(&sx).for_each(|(a, b)| *a -= b);
        }
        Ok(x)
    }

    /// `X = A⁻¹ B` on the dofs `support` only, for right-hand sides `B` with few non-zeros
    /// (the unit vectors `e_p` of interface dofs): with `P A Pᵀ = L Lᵀ` (supernodal `L`), the
    /// forward half `Y = L⁻¹ P B` visits only the supernodes where `Y` is non-zero — those on
    /// the elimination-tree paths from the right-hand sides' dofs to the root — and in each
    /// only the right-hand sides non-zero there; the backward half `Lᵀ P X = Y` visits only
    /// the supernodes that hold a dof of `support` and their ancestors (the rows `x_s` of a
    /// supernode `s` depend on the rows of its pattern, which lie in its ancestors). The
    /// result equals [`Self::solve_many_in_place`] on `support` up to rounding; the work of
    /// the forward half follows the paths instead of the factor. `out[c][k] = (A⁻¹ b_c)_{support[k]}`
    /// for `rhs[c] = b_c` given as `(dof, value)` entries (repeated dofs add up). A simplicial
    /// factor is solved whole.
    ///
    /// # Errors
    /// No successful factorisation; a dof `≥ n`.
    pub fn solve_sparse_on(
        &self,
        rhs: &[Vec<(usize, f64)>],
        support: &[usize],
    ) -> Result<Vec<Vec<f64>>, LinalgError> {
        use faer::sparse::linalg::cholesky::{supernodal::SupernodalLltRef, SymbolicCholeskyRaw};
        if !self.factorized {
            return Err(LinalgError::Sparse("solve called before a successful factorisation".into()));
        }
        let n = self.symbolic.nrows();
        let k = rhs.len();
        if let Some(&d) = rhs.iter().flatten().map(|(d, _)| d).chain(support).find(|&&d| d >= n) {
            return Err(LinalgError::InvalidParameter(format!("dof {d} out of range (n = {n})")));
        }
        let SymbolicCholeskyRaw::Supernodal(sym) = self.symbolic.raw() else {
            let mut b = faer::Mat::<f64>::zeros(n, k);
            for (c, col) in rhs.iter().enumerate() {
                for &(d, v) in col {
                    b[(d, c)] += v;
                }
            }
            self.solve_many_in_place(b.as_mut())?;
            return Ok((0..k).map(|c| support.iter().map(|&d| b[(d, c)]).collect()).collect());
        };
        let identity: Vec<usize>;
        let inv: &[usize] = match self.symbolic.perm() {
            Some(perm) => perm.arrays().1,
            None => {
                identity = (0..n).collect();
                &identity
            }
        };
        // X in factor order, column-major (column c at x[c n..(c + 1) n])
        let mut x = vec![0.0; n * k];
        for (c, col) in rhs.iter().enumerate() {
            for &(d, v) in col {
                x[c * n + inv[d]] += v;
            }
        }
        let llt = SupernodalLltRef::new(sym, self.factor.as_slice());
        let ns = sym.n_supernodes();
        let mut nonzero = Vec::with_capacity(k);
        let (mut xs, mut update) = (Vec::new(), Vec::new());
        // forward: Y = L⁻¹ P B, supernodes and right-hand sides where Y is non-zero only
        for s in 0..ns {
            let node = llt.supernode(s);
            let (start, val, pattern) = (node.start(), node.val(), node.pattern());
            let size = val.ncols();
            nonzero.clear();
            nonzero
                .extend((0..k).filter(|&c| x[c * n + start..c * n + start + size].iter().any(|&v| v != 0.0)));
            if nonzero.is_empty() {
                continue;
            }
            let r = nonzero.len();
            let (top, bottom) = val.split_at_row(size);
            xs.clear();
            for &c in &nonzero {
                xs.extend_from_slice(&x[c * n + start..c * n + start + size]);
            }
            faer::linalg::triangular_solve::solve_lower_triangular_in_place(
                top,
                MatMut::from_column_major_slice_mut(&mut xs, size, r),
                Par::Seq,
            );
            update.clear();
            update.resize(pattern.len() * r, 0.0);
            faer::linalg::matmul::matmul(
                MatMut::from_column_major_slice_mut(&mut update, pattern.len(), r),
                faer::Accum::Replace,
                bottom,
                faer::MatRef::from_column_major_slice(&xs, size, r),
                1.0,
                Par::Seq,
            );
            for (j, &c) in nonzero.iter().enumerate() {
                let col = &mut x[c * n..(c + 1) * n];
                col[start..start + size].copy_from_slice(&xs[j * size..(j + 1) * size]);
                for (&i, u) in pattern.iter().zip(&update[j * pattern.len()..(j + 1) * pattern.len()]) {
                    col[i] -= u;
                }
            }
        }
        // the supernodes the backward half needs: those holding a dof of `support`, and
        // their ancestors (the parent of `s` holds the first row of its pattern)
        let mut supernode_of = vec![0usize; n];
        for s in 0..ns {
            let node = llt.supernode(s);
            supernode_of[node.start()..node.start() + node.val().ncols()].fill(s);
        }
        let mut needed = vec![false; ns];
        for &d in support {
            needed[supernode_of[inv[d]]] = true;
        }
        for s in 0..ns {
            if needed[s] {
                if let Some(&first) = llt.supernode(s).pattern().first() {
                    needed[supernode_of[first]] = true;
                }
            }
        }
        // backward: Lᵀ P X = Y on the needed supernodes
        let mut below = Vec::new();
        for s in (0..ns).rev().filter(|&s| needed[s]) {
            let node = llt.supernode(s);
            let (start, val, pattern) = (node.start(), node.val(), node.pattern());
            let size = val.ncols();
            let (top, bottom) = val.split_at_row(size);
            below.clear();
            for c in 0..k {
                let col = &x[c * n..(c + 1) * n];
                below.extend(pattern.iter().map(|&i| col[i]));
            }
            xs.clear();
            for c in 0..k {
                xs.extend_from_slice(&x[c * n + start..c * n + start + size]);
            }
            let mut top_rows = MatMut::from_column_major_slice_mut(&mut xs, size, k);
            faer::linalg::matmul::matmul(
                top_rows.rb_mut(),
                faer::Accum::Add,
                bottom.transpose(),
                faer::MatRef::from_column_major_slice(&below, pattern.len(), k),
                -1.0,
                Par::Seq,
            );
            faer::linalg::triangular_solve::solve_upper_triangular_in_place(
                top.transpose(),
                top_rows,
                Par::Seq,
            );
            for c in 0..k {
                x[c * n + start..c * n + start + size].copy_from_slice(&xs[c * size..(c + 1) * size]);
            }
        }
        Ok((0..k).map(|c| support.iter().map(|&d| x[c * n + inv[d]]).collect()).collect())
    }

    /// Solves `A x = b` in place for one right-hand side.
    pub fn solve_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        let n = b.len();
        self.solve_many_in_place(MatMut::from_column_major_slice_mut(b, n, 1))
    }

    /// Solves `A X = B` in place for several right-hand sides (columns of `b`).
    pub fn solve_many_in_place(&self, b: MatMut<'_, f64>) -> Result<(), LinalgError> {
        if !self.factorized {
            return Err(LinalgError::Sparse("solve called before a successful factorisation".into()));
        }
        if b.nrows() != self.symbolic.nrows() {
            return Err(LinalgError::Length {
                what: "right-hand side",
                expected: self.symbolic.nrows(),
                got: b.nrows(),
            });
        }
        let par = Par::Seq;
        let req = self.symbolic.solve_in_place_scratch::<f64>(b.ncols(), par);
        let mut mem =
            MemBuffer::try_new(req).map_err(|_| LinalgError::Sparse("out of memory (scratch)".into()))?;
        LltRef::new(&self.symbolic, self.factor.as_slice()).solve_in_place_with_conj(
            Conj::No,
            b,
            par,
            MemStack::new(&mut mem),
        );
        Ok(())
    }

    /// Dimension.
    pub fn n(&self) -> usize {
        self.symbolic.nrows()
    }
    /// Timings and size.
    pub fn info(&self) -> CholeskyInfo {
        self.info
    }
    /// The shared symbolic factorisation.
    pub fn symbolic(&self) -> &Arc<SymbolicCholesky<usize>> {
        &self.symbolic
    }
}

/// The forward permutation of an ordering that is given or computed outside faer (`None`:
/// faer's AMD inside the symbolic analysis). Not for [`Ordering::Trailing`].
fn explicit_order(n: usize, ordering: &Ordering) -> Result<Option<Vec<usize>>, LinalgError> {
    match ordering {
        Ordering::Amd | Ordering::Trailing { .. } => Ok(None),
        Ordering::Custom(p) => Ok(Some(p.clone())),
        Ordering::Metis { blocks, adjacency } => Ok(Some(metis_order(n, blocks, adjacency)?)),
    }
}

/// faer's AMD ordering of the pattern of `a`, as a forward permutation.
fn amd_order(a: &SymmetricMatrix) -> Result<Vec<usize>, LinalgError> {
    use faer::sparse::linalg::amd;
    let n = a.n();
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    let req = amd::order_scratch::<usize>(n, a.nnz());
    let mut mem =
        MemBuffer::try_new(req).map_err(|_| LinalgError::Sparse("out of memory (AMD scratch)".into()))?;
    amd::order(&mut fwd, &mut inv, a.pattern().as_ref(), amd::Control::default(), MemStack::new(&mut mem))
        .map_err(|e| LinalgError::Sparse(format!("AMD ordering: {e:?}")))?;
    Ok(fwd)
}

/// The forward permutation `fwd` (`P`, with `(P A Pᵀ)_pq = A_{fwd[p], fwd[q]}`) with its first
/// `lead` positions reordered in a postorder of the elimination forest of `P A Pᵀ` restricted
/// to them; positions `≥ lead` (a trailing block) are kept. A postorder is a topological order
/// of the elimination tree, so the factor has the same pattern and the same flops; what
/// changes is that every subtree's columns are contiguous and each parent follows its last
/// child — the only merges faer's supernode relaxation makes are of consecutive columns. On the
/// `knee2d` neo-Hookean tangent (METIS, 16 528 dofs, 764 trailing) the supernodes go from 4 594
/// (3 604 of them a single node's two columns) to 1 845, the numeric factorisation is 19–22 %
/// and a triangular solve 10–15 % faster, at 10 % more stored entries (the relaxed supernodes'
/// explicit zeros); docs/performance.md, "Postordered elimination trees".
///
/// Elimination tree by Liu's algorithm with path compression (as in CSparse's `cs_etree`),
/// postorder by an iterative depth-first search visiting children in increasing order.
fn postorder_leading(a: &SymmetricMatrix, fwd: Vec<usize>, lead: usize) -> Result<Vec<usize>, LinalgError> {
    const NONE: usize = usize::MAX;
    let n = a.n();
    if lead > n {
        return Err(LinalgError::InvalidParameter(format!("{lead} leading dofs of {n}")));
    }
    let inv = inverse_permutation(&fwd, n)?;
    let inv = &inv;
    // the strictly upper part of P A Pᵀ by columns: for column k the rows r < k (from the stored
    // lower triangle of A, each off-diagonal entry once)
    let pattern = a.pattern();
    let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
    let entries = || {
        (0..n).flat_map(move |j| {
            row_idx[col_ptr[j]..col_ptr[j + 1]]
                .iter()
                .filter(move |&&i| i != j)
                .map(move |&i| (inv[i].min(inv[j]), inv[i].max(inv[j])))
        })
    };
    let mut start = vec![0usize; n + 1];
    for (_, hi) in entries() {
        start[hi + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut above = vec![0usize; start[n]];
    let mut fill = start.clone();
    for (lo, hi) in entries() {
        above[fill[hi]] = lo;
        fill[hi] += 1;
    }
    let mut parent = vec![NONE; n];
    let mut ancestor = vec![NONE; n];
    for k in 0..n {
        for &r in &above[start[k]..start[k + 1]] {
            let mut i = r;
            while i != NONE && i < k {
                let up = ancestor[i];
                ancestor[i] = k;
                if up == NONE {
                    parent[i] = k;
                }
                i = up;
            }
        }
    }
    // the forest of the leading positions (a parent in the trailing block makes a root),
    // children listed in increasing order
    let mut first_child = vec![NONE; lead];
    let mut next_sibling = vec![NONE; lead];
    let mut roots = Vec::new();
    for i in (0..lead).rev() {
        if parent[i] < lead {
            next_sibling[i] = first_child[parent[i]];
            first_child[parent[i]] = i;
        } else {
            roots.push(i);
        }
    }
    let mut order = Vec::with_capacity(n);
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for &root in roots.iter().rev() {
        stack.push((root, first_child[root]));
        while let Some((node, child)) = stack.pop() {
            if child == NONE {
                order.push(node);
            } else {
                stack.push((node, next_sibling[child]));
                stack.push((child, first_child[child]));
            }
        }
    }
    order.extend(lead..n);
    if order.len() != n {
        return Err(LinalgError::InvalidParameter("internal: postorder of the elimination forest".into()));
    }
    Ok(order.into_iter().map(|p| fwd[p]).collect())
}

/// The inverse of the forward permutation `fwd` of `0..n`; an error if it is not one.
fn inverse_permutation(fwd: &[usize], n: usize) -> Result<Vec<usize>, LinalgError> {
    if fwd.len() != n {
        return Err(LinalgError::Length { what: "ordering", expected: n, got: fwd.len() });
    }
    let mut inv = vec![usize::MAX; n];
    for (i, &p) in fwd.iter().enumerate() {
        if p >= n || inv[p] != usize::MAX {
            return Err(LinalgError::InvalidParameter("ordering is not a permutation".into()));
        }
        inv[p] = i;
    }
    Ok(inv)
}

/// METIS nested-dissection ordering of a block graph, expanded to a dof permutation.
fn metis_order(
    n: usize,
    blocks: &[std::ops::Range<usize>],
    adjacency: &[Vec<usize>],
) -> Result<Vec<usize>, LinalgError> {
    // keep only blocks with dofs
    let live: Vec<usize> = (0..blocks.len()).filter(|&k| !blocks[k].is_empty()).collect();
    let mut new_id = vec![usize::MAX; blocks.len()];
    for (i, &k) in live.iter().enumerate() {
        new_id[k] = i;
    }
    let nv = live.len();
    if nv == 0 {
        return Ok(Vec::new());
    }
    let too_big = |_| LinalgError::InvalidParameter("graph too large for METIS' 32-bit indices".into());
    let mut xadj: Vec<i32> = Vec::with_capacity(nv + 1);
    let mut adjncy: Vec<i32> = Vec::new();
    xadj.push(0);
    for &k in &live {
        for &m in &adjacency[k] {
            if m != k && new_id[m] != usize::MAX {
                adjncy.push(i32::try_from(new_id[m]).map_err(too_big)?);
            }
        }
        xadj.push(i32::try_from(adjncy.len()).map_err(too_big)?);
    }
    let mut nvtxs = i32::try_from(nv).map_err(too_big)?;
    let mut perm = vec![0i32; nv];
    let mut iperm = vec![0i32; nv];
    let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
    let status = metis_node_nd(&mut nvtxs, &mut xadj, &mut adjncy, &mut options, &mut perm, &mut iperm);
    if status != metis_sys::rstatus_et_METIS_OK {
        return Err(LinalgError::Sparse(format!("METIS_NodeND failed with status {status}")));
    }
    let mut fwd = Vec::with_capacity(n);
    for &p in &perm {
        let k = live[usize::try_from(p)
            .map_err(|_| LinalgError::Sparse("METIS returned a negative index".into()))?];
        fwd.extend(blocks[k].clone());
    }
    if fwd.len() != n {
        return Err(LinalgError::Sparse(format!("block ranges cover {} of {n} dofs", fwd.len())));
    }
    Ok(fwd)
}

/// The lock every call into METIS in this process holds ([`metis_lock`]).
static METIS_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Serialises calls into METIS: hold the guard for the whole call.
///
/// METIS draws random numbers (in the coarsening and refinement of its graph bisections) from
/// one generator whose state is a process-wide static of its GKlib (`random.c`: `mt[NN]`,
/// `mti`), reseeded at the start of every call (`InitRandom`, seed 4321 by default). Two calls
/// running at the same time on two threads therefore race on that state: a data race in C, and
/// orderings that depend on the threads' timing — measured: the same 3D model solved 60 times
/// in one process while other tests ran beside it got a different METIS permutation, and so
/// different last bits of its contact forces (1e-15 relative), in 1–5 of the 60 runs. With every call
/// holding this lock, each call runs alone from its reseeded state and returns the same
/// ordering for the same graph (test `metis_orderings_are_equal_when_threads_order_at_once`).
/// Code that calls METIS in the same process outside synovia (e.g. through the `metis` crate)
/// should hold it too; `synovia-feti`'s partitioning does.
pub fn metis_lock() -> std::sync::MutexGuard<'static, ()> {
    // a poisoned lock guards nothing (METIS's state is reseeded by the next call)
    METIS_LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// Calls `METIS_NodeND` after setting the default options, holding [`metis_lock`].
#[allow(unsafe_code)]
fn metis_node_nd(
    nvtxs: &mut i32,
    xadj: &mut [i32],
    adjncy: &mut [i32],
    options: &mut [i32; metis_sys::METIS_NOPTIONS as usize],
    perm: &mut [i32],
    iperm: &mut [i32],
) -> i32 {
    debug_assert!(
        xadj.len() == *nvtxs as usize + 1 && perm.len() == *nvtxs as usize && iperm.len() == perm.len()
    );
    // SAFETY: `options` has METIS_NOPTIONS entries, as METIS_SetDefaultOptions requires.
    // METIS_NodeND reads `nvtxs` vertices from the CSR graph `xadj` (nvtxs + 1 entries, checked
    // above and built by the caller) and `adjncy` (xadj[nvtxs] entries, all in 0..nvtxs by
    // construction); it writes exactly nvtxs entries into `perm` and `iperm`, whose lengths are
    // nvtxs; `vwgt` is null (unit weights, allowed by the METIS API). All pointers come from
    // live exclusive borrows, so nothing aliases, and METIS keeps no pointer after returning.
    // METIS's process-wide random-number state is only touched under `metis_lock`, held for
    // the whole call, so no other call into METIS runs at the same time.
    let _guard = metis_lock();
    unsafe {
        metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
        metis_sys::METIS_NodeND(
            nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    }
}

/// Which dofs of a contact interface a factorisation orders last ([`Ordering::Trailing`]), so
/// that the interface Schur complement comes from the dense trailing block `L₂₂`
/// (docs/model.md §6.4). The block is dense: `k²` entries (512 MB at `k = 8000`) and `k³/3`
/// flops in the factorisation (measured in `docs/performance.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct InterfaceBlockParams {
    /// Largest number of interface dofs ordered last all together (default 8000; 0 switches
    /// the dense interface block off).
    pub max_dofs: usize,
    /// For an interface with more than [`Self::max_dofs`] dofs: the number of dofs of its
    /// leading groups (in priority order; for a contact problem the contact nodes of smallest
    /// initial gap) that are ordered last instead (default 6000, capped at
    /// [`Self::max_dofs`]; 0: no block for such an interface). The contact solve then screens
    /// its rows against this block (exactly: rows outside it are added when they come into
    /// contact).
    pub screened_dofs: usize,
}

impl Default for InterfaceBlockParams {
    fn default() -> Self {
        Self { max_dofs: 8000, screened_dofs: 6000 }
    }
}

impl InterfaceBlockParams {
    /// Sets [`Self::max_dofs`].
    pub fn with_max_dofs(mut self, max_dofs: usize) -> Self {
        self.max_dofs = max_dofs;
        self
    }
    /// Sets [`Self::screened_dofs`].
    pub fn with_screened_dofs(mut self, screened_dofs: usize) -> Self {
        self.screened_dofs = screened_dofs;
        self
    }
    /// The dofs to order last, from the interface's dof groups in priority order (repeated
    /// groups count once): all of them if they fit in [`Self::max_dofs`], else the longest
    /// prefix of whole groups within [`Self::screened_dofs`].
    pub fn select(&self, groups: &[std::ops::Range<usize>]) -> Vec<usize> {
        let mut seen = std::collections::HashSet::new();
        let unique: Vec<&std::ops::Range<usize>> = groups.iter().filter(|g| seen.insert(g.start)).collect();
        let total: usize = unique.iter().map(|g| g.len()).sum();
        let budget = if total <= self.max_dofs { total } else { self.screened_dofs.min(self.max_dofs) };
        let mut last = Vec::new();
        for g in unique {
            if last.len() + g.len() > budget {
                break;
            }
            last.extend(g.clone());
        }
        last
    }
    /// `base` with the [`Self::select`]ed dofs of `groups` ordered last, or `base` itself when
    /// none (or all `n`) are selected.
    pub fn ordering(&self, base: Ordering, groups: &[std::ops::Range<usize>], n: usize) -> Ordering {
        let last = self.select(groups);
        if last.is_empty() || last.len() >= n {
            base
        } else {
            Ordering::Trailing { base: Box::new(base), last }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::linalg::SupernodalThreshold;

    /// The 5-point Laplacian (+ 0.1 I) of an `m × m` grid with two unknowns per node (a 2D
    /// displacement field, the components coupled by a small symmetric term), and its node
    /// blocks for METIS.
    #[allow(clippy::type_complexity)]
    fn grid2(m: usize) -> (SymmetricMatrix, Vec<std::ops::Range<usize>>, Vec<Vec<usize>>) {
        let nodes = m * m;
        let n = 2 * nodes;
        let neighbours = |k: usize| {
            let (x, y) = (k % m, k / m);
            let mut v = Vec::new();
            if x + 1 < m {
                v.push(k + 1);
            }
            if y + 1 < m {
                v.push(k + m);
            }
            if x > 0 {
                v.push(k - 1);
            }
            if y > 0 {
                v.push(k - m);
            }
            v
        };
        let mut columns = vec![Vec::new(); n];
        for k in 0..nodes {
            for c in 0..2 {
                let j = 2 * k + c;
                columns[j].push(j);
                if c == 0 {
                    columns[j].push(j + 1);
                }
                for l in neighbours(k).into_iter().filter(|&l| l > k) {
                    columns[j].push(2 * l + c);
                }
            }
        }
        let mut a = SymmetricMatrix::from_columns(n, columns).expect("pattern");
        for k in 0..nodes {
            for c in 0..2 {
                let j = 2 * k + c;
                a.add(j, j, 4.1).expect("diagonal");
                if c == 0 {
                    a.add(j + 1, j, 0.05).expect("coupling");
                }
                for l in neighbours(k).into_iter().filter(|&l| l > k) {
                    a.add(2 * l + c, j, -1.0).expect("off-diagonal");
                }
            }
        }
        let blocks = (0..nodes).map(|k| 2 * k..2 * k + 2).collect();
        let adjacency = (0..nodes).map(neighbours).collect();
        (a, blocks, adjacency)
    }

    /// `(stored entries, supernodes)` of the symbolic factorisation of `a` in the order `fwd`:
    /// simplicial (the exact fill) or supernodal with faer's default relaxation.
    fn symbolic_of(a: &SymmetricMatrix, fwd: &[usize], simplicial: bool) -> (usize, usize) {
        let n = a.n();
        let inv = inverse_permutation(fwd, n).expect("permutation");
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: if simplicial {
                SupernodalThreshold::FORCE_SIMPLICIAL
            } else {
                SupernodalThreshold::FORCE_SUPERNODAL
            },
            ..Default::default()
        };
        let symbolic = factorize_symbolic_cholesky(
            a.pattern().as_ref(),
            Side::Lower,
            SymmetricOrdering::Custom(PermRef::new_checked(fwd, &inv, n)),
            params,
        )
        .expect("symbolic");
        let supernodes = match symbolic.raw() {
            faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(s) => s.n_supernodes(),
            faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Simplicial(_) => 0,
        };
        (symbolic.len_val(), supernodes)
    }

    /// METIS's random-number state is process-wide ([`metis_lock`]): orderings computed on
    /// four threads at once equal the one computed alone, every time. (Without the lock, 40
    /// of 40 concurrent orderings of this graph differed from it, in each of three runs.)
    #[test]
    fn metis_orderings_are_equal_when_threads_order_at_once() {
        // a 3D grid of 14³ blocks of 3 dofs (a P1 mesh's node graph with its 26 neighbours)
        let m = 14usize;
        let id = |i: usize, j: usize, k: usize| (i * m + j) * m + k;
        let blocks: Vec<std::ops::Range<usize>> = (0..m * m * m).map(|b| 3 * b..3 * b + 3).collect();
        let mut adjacency = vec![Vec::new(); m * m * m];
        for i in 0..m {
            for j in 0..m {
                for k in 0..m {
                    for (di, dj, dk) in (0..27).map(|c| (c / 9, (c / 3) % 3, c % 3)) {
                        let (a, b, c) =
                            ((i + di).wrapping_sub(1), (j + dj).wrapping_sub(1), (k + dk).wrapping_sub(1));
                        if a < m && b < m && c < m && (a, b, c) != (i, j, k) {
                            adjacency[id(i, j, k)].push(id(a, b, c));
                        }
                    }
                }
            }
        }
        let n = 3 * m * m * m;
        let alone = metis_order(n, &blocks, &adjacency).expect("metis");
        let together: Vec<Vec<usize>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..4)
                .map(|_| {
                    scope.spawn(|| {
                        (0..10)
                            .map(|_| metis_order(n, &blocks, &adjacency).expect("metis"))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            handles.into_iter().flat_map(|h| h.join().expect("thread")).collect()
        });
        assert_eq!(together.len(), 40);
        let differing = together.iter().filter(|o| **o != alone).count();
        assert_eq!(
            differing, 0,
            "{differing} of 40 concurrent METIS orderings differ from the one computed alone"
        );
    }

    /// The postorder of a METIS order with a trailing block (one grid edge's dofs last): a
    /// permutation that keeps the trailing positions, gives the same fill (a topological order
    /// of the elimination tree: equal simplicial factor sizes) and fewer supernodes after faer's
    /// relaxation; and `analyse` (which applies it) factorises `A` correctly.
    #[test]
    fn postordered_elimination_tree_keeps_the_fill_and_merges_supernodes() {
        let m = 40;
        let (a, blocks, adjacency) = grid2(m);
        let n = a.n();
        let base = metis_order(n, &blocks, &adjacency).expect("METIS");
        let last: Vec<usize> = (0..2 * m).collect();
        let (mut fwd, tail): (Vec<usize>, Vec<usize>) = base.iter().partition(|&&d| d >= 2 * m);
        fwd.extend_from_slice(&tail);
        let lead = n - last.len();
        let post = postorder_leading(&a, fwd.clone(), lead).expect("postorder");
        assert_eq!(&post[lead..], &fwd[lead..], "the trailing block moved");
        let mut sorted = post.clone();
        sorted.sort_unstable();
        assert!(sorted.iter().enumerate().all(|(i, &d)| i == d), "not a permutation");
        assert_ne!(post, fwd, "METIS's order was already postordered: the test checks nothing");
        let (fill_before, _) = symbolic_of(&a, &fwd, true);
        let (fill_after, _) = symbolic_of(&a, &post, true);
        assert_eq!(fill_before, fill_after, "the postorder changed the fill");
        let (_, supernodes_before) = symbolic_of(&a, &fwd, false);
        let (_, supernodes_after) = symbolic_of(&a, &post, false);
        assert!(supernodes_after < supernodes_before, "supernodes {supernodes_before} → {supernodes_after}");
        // the whole path: analyse with the trailing ordering, factorise, solve
        let mut solver = CholeskySolver::analyse(
            &a,
            &Ordering::Trailing { base: Box::new(Ordering::Metis { blocks, adjacency }), last },
        )
        .expect("analyse");
        solver.factorize(&a).expect("factorise");
        let x: Vec<f64> = (0..n).map(|i| ((i * 37 % 101) as f64 - 50.0) / 50.0).collect();
        let mut b = vec![0.0; n];
        a.mul_vec(&x, &mut b);
        solver.solve_in_place(&mut b).expect("solve");
        let error = b.iter().zip(&x).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max);
        assert!(error < 1e-12, "solve error {error}");
    }

    /// The trailing block of one body is read in place from the factor (no copy of `L₂₂`):
    /// its entries reproduce `(A⁻¹)_cc = L₂₂⁻ᵀ L₂₂⁻¹` of whole solves, the memory estimate
    /// counts no copy, and a block kept by a caller across a refactorisation keeps the old
    /// values (the factor gets new storage) while the solver's new block has the new ones.
    #[test]
    fn trailing_block_is_read_in_place_and_survives_a_refactorisation() {
        // (large enough for faer's supernodal factorisation; smaller grids are simplicial, and
        // their `L₂₂` is copied)
        let m = 100;
        let (a, blocks, adjacency) = grid2(m);
        let n = a.n();
        let last: Vec<usize> = (0..2 * m).collect();
        let ordering = Ordering::Trailing { base: Box::new(Ordering::Metis { blocks, adjacency }), last };
        let mut solver = CholeskySolver::analyse(&a, &ordering).expect("analyse");
        assert_eq!(solver.memory_estimate().trailing_bytes, 0, "a copy of L22 is counted");
        solver.factorize(&a).expect("factorise");
        let block = solver.trailing().expect("trailing block").clone();
        assert!(block.in_factor(), "L22 was copied");
        let k = block.dofs.len();
        // columns of (A⁻¹)_cc: by the block, and by whole solves
        let inverse_column = |s: &CholeskySolver, p: usize, dofs: &[usize]| -> Vec<f64> {
            let mut e = vec![0.0; n];
            e[dofs[p]] = 1.0;
            s.solve_in_place(&mut e).expect("solve");
            dofs.iter().map(|&d| e[d]).collect()
        };
        let by_block = |b: &TrailingBlock, p: usize| -> Vec<f64> {
            b.solve_sparse_columns(&[vec![(p, 1.0)]], false).expect("block solve").remove(0)
        };
        for p in [0, k / 2, k - 1] {
            let (x, y) = (by_block(&block, p), inverse_column(&solver, p, &block.dofs));
            let err = x.iter().zip(&y).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max);
            assert!(err < 1e-12, "column {p}: {err}");
        }
        // refactorise 2 A while the caller still holds the old block
        let mut a2 = a.clone();
        a2.add_scaled(1.0, &a).expect("2 A");
        solver.factorize(&a2).expect("refactorise");
        let new_block = solver.trailing().expect("trailing block").clone();
        assert_ne!(new_block.generation(), block.generation());
        for p in [0, k - 1] {
            let (old, new) = (by_block(&block, p), by_block(&new_block, p));
            // (2 A)⁻¹ = A⁻¹ / 2: the old block still answers for A, the new one for 2 A
            let err = old.iter().zip(&new).map(|(u, v)| (u - 2.0 * v).abs()).fold(0.0, f64::max);
            assert!(err < 1e-12, "column {p}: old and new blocks {err}");
            let whole = inverse_column(&solver, p, &new_block.dofs);
            let err = new.iter().zip(&whole).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max);
            assert!(err < 1e-12, "column {p}: new block against whole solves {err}");
        }
    }
}
