//! The seam between the contact solvers and the linear algebra: a factorised symmetric
//! positive definite operator `A` (docs/model.md §5, §6.4).
//!
//! Every contact solver works on the condensed interface problem of docs/model.md §6.4,
//!
//! ```text
//! U = A⁻¹ (F − Cᵀ ν),   y = C U = w − S ν,   w = C A⁻¹ F,   S = C A⁻¹ Cᵀ,
//! ```
//!
//! so all it needs from `A` is: products `A x`, its diagonal (to scale `ρ`), solves with one
//! or many right-hand sides, solves whose right-hand side lives on the interface dofs, and
//! columns of `S` for a set of rows `C`. [`FactorisedOperator`] is exactly that list; a
//! back-end (another sparse direct solver, an iterative solver with a preconditioner, a
//! domain decomposition) implements it and the solvers run unchanged. The default methods
//! derive the interface operations from plain solves; [`CholeskyOperator`] (faer's sparse
//! Cholesky) overrides them with its dense interface block.

use std::fmt;

use crate::cholesky::CholeskySolver;
use crate::error::LinalgError;
use crate::interface::{columns_by_solves, in_two_halves, missing_columns, BlockSolveStore};
use crate::rows::SparseRows;
use crate::sparse::SymmetricMatrix;

/// A symmetric positive definite operator `A` with a factorisation (or any other way of
/// solving `A x = b` accurately), as the contact solvers use it (docs/model.md §6.4).
///
/// Object safe: problems hold a `&dyn FactorisedOperator`.
pub trait FactorisedOperator: Send + Sync + fmt::Debug {
    /// Dimension `n`.
    fn n(&self) -> usize;
    /// `A x`.
    fn apply(&self, x: &[f64]) -> Vec<f64>;
    /// `diag(A)` (the complementarity parameter `ρ` is scaled by its mean, docs/model.md §5).
    fn diagonal(&self) -> Vec<f64>;
    /// The entry `A_ij` when the back-end stores it (`None`: matrix-free); used by
    /// preconditioners of the interface problem.
    fn entry(&self, i: usize, j: usize) -> Option<f64> {
        let _ = (i, j);
        None
    }
    /// A key identifying the operator's numbers (equal keys: equal operators), for caches of
    /// solves kept between problems.
    fn key(&self) -> u64;
    /// `b ← A⁻¹ b`.
    ///
    /// # Errors
    /// A wrong length, or a failed solve.
    fn solve_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError>;
    /// `B ← A⁻¹ B` for `ncols` right-hand sides stored column by column in `b`
    /// (`b.len() = n · ncols`). Default: one [`FactorisedOperator::solve_in_place`] each.
    ///
    /// # Errors
    /// A wrong length, or a failed solve.
    fn solve_many_in_place(&self, b: &mut [f64], ncols: usize) -> Result<(), LinalgError> {
        let n = self.n();
        if b.len() != n * ncols {
            return Err(LinalgError::Length { what: "right-hand sides", expected: n * ncols, got: b.len() });
        }
        for col in b.chunks_mut(n.max(1)) {
            self.solve_in_place(col)?;
        }
        Ok(())
    }
    /// `b ← A⁻¹ b` for a right-hand side that is zero outside the dofs of the contact
    /// interface (e.g. `Cᵀ ν`). Back-ends with the interface dofs eliminated last do half the
    /// work; the default is a plain solve.
    ///
    /// # Errors
    /// A wrong length, or a failed solve.
    fn solve_supported_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        self.solve_in_place(b)
    }
    /// `true` if every dof of the interface `rows` lies in a dense trailing block of the
    /// factor, so that [`FactorisedOperator::forward_solve`] serves them (default `false`).
    fn forward_covers(&self, rows: RowStack<'_>) -> bool {
        let _ = rows;
        false
    }
    /// The forward half of a solve `A x = b` for interfaces whose rows the operator covers
    /// ([`FactorisedOperator::forward_covers`]; docs/model.md §6.4): `Some(y)`, from which
    /// [`FactorisedOperator::interface_of_forward`] gives `x` on the interface dofs and
    /// [`FactorisedOperator::complete_forward`] the whole `A⁻¹ (b − Cᵀ ν)`, each about half a
    /// solve. Default `None` (no dense trailing block: solve whole).
    ///
    /// # Errors
    /// A wrong length, or a failed solve.
    fn forward_solve(&self, b: &[f64]) -> Result<Option<Vec<f64>>, LinalgError> {
        let _ = b;
        Ok(None)
    }
    /// `x = A⁻¹ b` on the interface dofs (zero elsewhere) from `y` of
    /// [`FactorisedOperator::forward_solve`].
    ///
    /// # Errors
    /// Operators without [`FactorisedOperator::forward_solve`]; a wrong length.
    fn interface_of_forward(&self, y: &[f64]) -> Result<Vec<f64>, LinalgError> {
        let _ = y;
        Err(LinalgError::InvalidParameter("this operator has no forward solve".into()))
    }
    /// `x = A⁻¹ (b − s)` from `y` of [`FactorisedOperator::forward_solve`] of `b` and an `s`
    /// that vanishes outside the interface dofs (e.g. `Cᵀ ν`).
    ///
    /// # Errors
    /// Operators without [`FactorisedOperator::forward_solve`]; wrong lengths; a failed solve.
    fn complete_forward(&self, y: &[f64], s: &[f64]) -> Result<Vec<f64>, LinalgError> {
        let _ = (y, s);
        Err(LinalgError::InvalidParameter("this operator has no forward solve".into()))
    }
    /// Computes the columns `j ∈ wanted` of the interface Schur complement
    /// `S = C A⁻¹ Cᵀ` of the rows `C` into `columns[j]` (entries already `Some` are kept; an
    /// implementation may fill other columns too). `kept` holds solves of single rows shared
    /// between interfaces (its budget bounds it). Returns the number of right-hand sides
    /// solved. Default: batched solves `A⁻¹ c_j` and products with `C`.
    ///
    /// # Errors
    /// Wrong sizes, or a failed solve.
    fn interface_columns(
        &self,
        rows: RowStack<'_>,
        wanted: &[usize],
        columns: &mut [Option<Vec<f64>>],
        kept: &BlockSolveStore,
    ) -> Result<usize, LinalgError> {
        let _ = kept;
        let missing = missing_columns(wanted, columns);
        let computed = in_two_halves(&missing, true, |cols| columns_by_solves(self, rows, cols))?;
        let solved = computed.len();
        for (j, col) in computed {
            columns[j] = Some(col);
        }
        Ok(solved)
    }
    /// Announces that the interfaces of the coming solves take their rows from `rows` (e.g.
    /// the sub-problems of a screened solve, each on some of the candidate rows): a back-end
    /// that keeps row solves restricted to the interface dofs in `kept` sizes them for all of
    /// `rows` at once, so that interfaces on other subsets reuse them instead of emptying the
    /// store. Default: nothing.
    fn reserve_interface(&self, rows: RowStack<'_>, kept: &BlockSolveStore) {
        let _ = (rows, kept);
    }
    /// `true` if [`FactorisedOperator::interface_columns`] of these rows uses a dense block of
    /// the factor instead of whole solves (reported by the solvers; default `false`).
    fn dense_interface_block(&self, rows: RowStack<'_>) -> bool {
        let _ = rows;
        false
    }
}

/// The rows `C = [C₁; C₂]` of an interface: one or two stacked [`SparseRows`] (the normal
/// rows `B_hn` and the friction rows `B_Ht` of docs/model.md §5).
#[derive(Debug, Clone, Copy)]
pub struct RowStack<'a> {
    first: &'a SparseRows,
    second: Option<&'a SparseRows>,
}

impl<'a> RowStack<'a> {
    /// `C = [first; second]`.
    pub fn new(first: &'a SparseRows, second: Option<&'a SparseRows>) -> Self {
        Self { first, second }
    }
    /// Number of rows.
    pub fn n_rows(&self) -> usize {
        self.first.nrows() + self.second.map_or(0, |s| s.nrows())
    }
    /// Number of columns (the operator's dimension).
    pub fn ncols(&self) -> usize {
        self.first.ncols()
    }
    /// Row `r` as `(column, value)` entries.
    pub fn row(&self, r: usize) -> Box<dyn Iterator<Item = (usize, f64)> + 'a> {
        let m = self.first.nrows();
        if r < m {
            Box::new(self.first.row(r))
        } else {
            match self.second {
                Some(s) => Box::new(s.row(r - m)),
                None => Box::new(std::iter::empty()),
            }
        }
    }
    /// `C x`.
    pub fn mul(&self, x: &[f64]) -> Vec<f64> {
        let mut y = self.first.mul(x);
        if let Some(s) = self.second {
            y.extend(s.mul(x));
        }
        y
    }
    /// `out += Cᵀ ν`.
    pub fn mul_transpose_add(&self, nu: &[f64], out: &mut [f64]) {
        let m = self.first.nrows();
        self.first.mul_transpose_add(&nu[..m], out);
        if let Some(s) = self.second {
            s.mul_transpose_add(&nu[m..], out);
        }
    }
    /// A fingerprint of the rows' entries (equal fingerprints: equal rows, up to hash
    /// collisions), for caches of columns kept between solves.
    pub fn fingerprint(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.ncols().hash(&mut h);
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
}

/// The faer sparse Cholesky factorisation of a [`SymmetricMatrix`] as a
/// [`FactorisedOperator`]: a view of the matrix and its [`CholeskySolver`].
///
/// With the interface dofs ordered last ([`crate::Ordering::Trailing`]) the columns of `S` of
/// rows on those dofs come from the dense trailing block `L₂₂`,
/// `(A⁻¹)_cc = L₂₂⁻ᵀ L₂₂⁻¹` (two dense triangular solves instead of a solve with the whole
/// factor), and solves of right-hand sides on them are half solves.
#[derive(Debug, Clone, Copy)]
pub struct CholeskyOperator<'a> {
    matrix: &'a SymmetricMatrix,
    factor: &'a CholeskySolver,
}

impl<'a> CholeskyOperator<'a> {
    /// The operator of `matrix` factorised by `factor`.
    ///
    /// # Errors
    /// [`LinalgError::Length`] if their dimensions differ.
    pub fn new(matrix: &'a SymmetricMatrix, factor: &'a CholeskySolver) -> Result<Self, LinalgError> {
        if matrix.n() != factor.n() {
            return Err(LinalgError::Length { what: "factorisation", expected: matrix.n(), got: factor.n() });
        }
        Ok(Self { matrix, factor })
    }
    /// The matrix.
    pub fn matrix(&self) -> &'a SymmetricMatrix {
        self.matrix
    }
    /// The factorisation.
    pub fn factor(&self) -> &'a CholeskySolver {
        self.factor
    }
}

impl FactorisedOperator for CholeskyOperator<'_> {
    fn n(&self) -> usize {
        self.matrix.n()
    }
    fn apply(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.matrix.n()];
        self.matrix.mul_vec(x, &mut y);
        y
    }
    fn diagonal(&self) -> Vec<f64> {
        self.matrix.diagonal()
    }
    fn entry(&self, i: usize, j: usize) -> Option<f64> {
        Some(self.matrix.get(i, j))
    }
    fn key(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        // the factorisation's generation, not the solver's address: a refactorised solver, or
        // a new one where a dropped one was, must not find the old one's kept solves
        self.factor.generation().hash(&mut h);
        self.matrix.n().hash(&mut h);
        h.finish()
    }
    fn solve_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        self.factor.solve_in_place(b)
    }
    fn solve_many_in_place(&self, b: &mut [f64], ncols: usize) -> Result<(), LinalgError> {
        let n = self.n();
        if b.len() != n * ncols {
            return Err(LinalgError::Length { what: "right-hand sides", expected: n * ncols, got: b.len() });
        }
        self.factor.solve_many_in_place(faer::MatMut::from_column_major_slice_mut(b, n, ncols))
    }
    fn solve_supported_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        self.factor.solve_trailing_supported_in_place(b)
    }
    fn forward_covers(&self, rows: RowStack<'_>) -> bool {
        self.factor.trailing().is_some_and(|block| {
            (0..rows.n_rows())
                .all(|r| rows.row(r).all(|(i, _)| block.position.get(i).is_some_and(|&p| p != usize::MAX)))
        })
    }
    fn forward_solve(&self, b: &[f64]) -> Result<Option<Vec<f64>>, LinalgError> {
        self.factor.forward_trailing(b)
    }
    fn interface_of_forward(&self, y: &[f64]) -> Result<Vec<f64>, LinalgError> {
        self.factor.trailing_of_forward(y)
    }
    fn complete_forward(&self, y: &[f64], s: &[f64]) -> Result<Vec<f64>, LinalgError> {
        self.factor.complete_forward(y, s)
    }
    fn interface_columns(
        &self,
        rows: RowStack<'_>,
        wanted: &[usize],
        columns: &mut [Option<Vec<f64>>],
        kept: &BlockSolveStore,
    ) -> Result<usize, LinalgError> {
        crate::interface::cholesky_interface_columns(self, rows, wanted, columns, kept)
    }
    fn reserve_interface(&self, rows: RowStack<'_>, kept: &BlockSolveStore) {
        crate::interface::reserve_unit_support(self, rows, kept);
    }
    fn dense_interface_block(&self, rows: RowStack<'_>) -> bool {
        crate::interface::trailing_rows(self.factor, rows).is_some()
    }
}

/// An owned matrix with its Cholesky factorisation, as a [`FactorisedOperator`] (the owned
/// form of [`CholeskyOperator`]).
#[derive(Debug, Clone)]
pub struct SparseCholesky {
    /// `A`.
    pub matrix: SymmetricMatrix,
    /// Its factorisation.
    pub factor: CholeskySolver,
}

impl SparseCholesky {
    /// Analyses `matrix` with `ordering` and factorises it.
    ///
    /// # Errors
    /// The factorisation's errors (e.g. [`LinalgError::NotPositiveDefinite`]).
    pub fn new(matrix: SymmetricMatrix, ordering: &crate::Ordering) -> Result<Self, LinalgError> {
        let mut factor = CholeskySolver::analyse(&matrix, ordering)?;
        factor.factorize(&matrix)?;
        Ok(Self { matrix, factor })
    }
    /// The borrowed view.
    pub fn view(&self) -> CholeskyOperator<'_> {
        CholeskyOperator { matrix: &self.matrix, factor: &self.factor }
    }
}

impl FactorisedOperator for SparseCholesky {
    fn n(&self) -> usize {
        self.view().n()
    }
    fn apply(&self, x: &[f64]) -> Vec<f64> {
        self.view().apply(x)
    }
    fn diagonal(&self) -> Vec<f64> {
        self.view().diagonal()
    }
    fn entry(&self, i: usize, j: usize) -> Option<f64> {
        self.view().entry(i, j)
    }
    fn key(&self) -> u64 {
        self.view().key()
    }
    fn solve_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        self.view().solve_in_place(b)
    }
    fn solve_many_in_place(&self, b: &mut [f64], ncols: usize) -> Result<(), LinalgError> {
        self.view().solve_many_in_place(b, ncols)
    }
    fn solve_supported_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        self.view().solve_supported_in_place(b)
    }
    fn forward_covers(&self, rows: RowStack<'_>) -> bool {
        self.view().forward_covers(rows)
    }
    fn forward_solve(&self, b: &[f64]) -> Result<Option<Vec<f64>>, LinalgError> {
        self.view().forward_solve(b)
    }
    fn interface_of_forward(&self, y: &[f64]) -> Result<Vec<f64>, LinalgError> {
        self.view().interface_of_forward(y)
    }
    fn complete_forward(&self, y: &[f64], s: &[f64]) -> Result<Vec<f64>, LinalgError> {
        self.view().complete_forward(y, s)
    }
    fn interface_columns(
        &self,
        rows: RowStack<'_>,
        wanted: &[usize],
        columns: &mut [Option<Vec<f64>>],
        kept: &BlockSolveStore,
    ) -> Result<usize, LinalgError> {
        self.view().interface_columns(rows, wanted, columns, kept)
    }
    fn reserve_interface(&self, rows: RowStack<'_>, kept: &BlockSolveStore) {
        self.view().reserve_interface(rows, kept);
    }
    fn dense_interface_block(&self, rows: RowStack<'_>) -> bool {
        self.view().dense_interface_block(rows)
    }
}
