//! Sparse constraint rows (CSR) acting on the reduced unknowns.

/// A sparse matrix stored by rows (CSR): the contact operators `B_hn`, `B_Ht`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SparseRows {
    ncols: usize,
    row_ptr: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
}

impl SparseRows {
    /// An empty operator with `ncols` columns.
    pub fn new(ncols: usize) -> Self {
        Self { ncols, row_ptr: vec![0], cols: Vec::new(), vals: Vec::new() }
    }
    /// Appends a row given as `(column, value)` entries (duplicates are summed when applied).
    pub fn push_row(&mut self, entries: impl IntoIterator<Item = (usize, f64)>) {
        for (c, v) in entries {
            debug_assert!(c < self.ncols);
            if v != 0.0 {
                self.cols.push(c);
                self.vals.push(v);
            }
        }
        self.row_ptr.push(self.cols.len());
    }
    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.row_ptr.len() - 1
    }
    /// Number of columns.
    pub fn ncols(&self) -> usize {
        self.ncols
    }
    /// Entries of row `r`.
    pub fn row(&self, r: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let (a, b) = (self.row_ptr[r], self.row_ptr[r + 1]);
        self.cols[a..b].iter().copied().zip(self.vals[a..b].iter().copied())
    }
    /// `Σ v²` of row `r`.
    pub fn row_norm_squared(&self, r: usize) -> f64 {
        self.row(r).map(|(_, v)| v * v).sum()
    }
    /// `(B x)_r`.
    pub fn row_dot(&self, r: usize, x: &[f64]) -> f64 {
        self.row(r).map(|(c, v)| v * x[c]).sum()
    }
    /// `B x`.
    pub fn mul(&self, x: &[f64]) -> Vec<f64> {
        (0..self.nrows()).map(|r| self.row_dot(r, x)).collect()
    }
    /// `y += Bᵀ v`.
    pub fn mul_transpose_add(&self, v: &[f64], y: &mut [f64]) {
        for (r, &vr) in v.iter().enumerate().take(self.nrows()) {
            if vr != 0.0 {
                for (c, b) in self.row(r) {
                    y[c] += b * vr;
                }
            }
        }
    }
    /// Adds `alpha · e_r` of row `r` into the dense column `y` (`y += alpha Bᵀ e_r`).
    pub fn add_row_to(&self, r: usize, alpha: f64, y: &mut [f64]) {
        for (c, b) in self.row(r) {
            y[c] += alpha * b;
        }
    }
    /// Stacks `other` below `self` (same column count).
    pub fn stacked(&self, other: &SparseRows) -> SparseRows {
        let mut out = self.clone();
        for r in 0..other.nrows() {
            out.push_row(other.row(r));
        }
        out
    }
}
