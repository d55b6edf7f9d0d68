//! The interface Schur complement `S = C A⁻¹ Cᵀ` (docs/model.md §6.4) as an operator: dense (all columns
//! computed once, one solve with the factorisation of `A` each, cached by
//! [`synovia_contact::Interface`]) for moderate interface sizes, matrix-free
//! (`S v = C A⁻¹ (Cᵀ v)`, one solve per product) beyond [`SchurOperator::DENSE_LIMIT`] rows.

use std::ops::Range;
use std::time::Instant;

use synovia_contact::{ContactError, ContactProblem, Interface, SolveContext};

use crate::qp::Hessian;

/// `S = C A⁻¹ Cᵀ` with `C = [B_hn; B_Ht]` and the interface load `w = C A⁻¹ F`.
#[derive(Debug)]
pub struct SchurOperator<'p> {
    problem: ContactProblem<'p>,
    interface: Interface<'p>,
    dense: bool,
    extra_solves: usize,
    extra_s: f64,
    products: usize,
}

impl<'p> SchurOperator<'p> {
    /// Interfaces with at most this many rows are stored densely (`m` solves once, then
    /// `O(m²)` per product); larger ones are applied matrix-free (one solve per product).
    pub const DENSE_LIMIT: usize = 3000;

    /// Validates the problem, computes `w` and, if `m ≤ DENSE_LIMIT`, all columns of `S`.
    pub fn new(problem: ContactProblem<'p>, context: &'p SolveContext) -> Result<Self, ContactError> {
        let dense = problem.n_rows() <= Self::DENSE_LIMIT;
        Self::with_storage(problem, context, dense)
    }

    /// As [`SchurOperator::new`] with the storage chosen explicitly (`dense = false`:
    /// matrix-free).
    pub fn with_storage(
        problem: ContactProblem<'p>,
        context: &'p SolveContext,
        dense: bool,
    ) -> Result<Self, ContactError> {
        let mut interface = Interface::new(problem, context)?;
        if dense {
            let all: Vec<usize> = (0..problem.n_rows()).collect();
            interface.ensure_columns(&all)?;
        }
        Ok(Self { problem, interface, dense, extra_solves: 0, extra_s: 0.0, products: 0 })
    }

    /// The problem.
    pub fn problem(&self) -> &ContactProblem<'p> {
        &self.problem
    }
    /// Number of interface rows `m`.
    pub fn n_rows(&self) -> usize {
        self.interface.n_rows()
    }
    /// `true` if `S` is stored densely.
    pub fn is_dense(&self) -> bool {
        self.dense
    }
    /// `w = C A⁻¹ F`.
    pub fn w(&self) -> &[f64] {
        self.interface.w()
    }
    /// Linear solves with the factorisation of `A` so far.
    pub fn solves(&self) -> usize {
        self.interface.solves() + self.extra_solves
    }
    /// Seconds spent in those solves.
    pub fn solve_seconds(&self) -> f64 {
        self.interface.solve_seconds() + self.extra_s
    }
    /// Products with (blocks of) `S` so far.
    pub fn products(&self) -> usize {
        self.products
    }

    /// `out = S v` (all rows and columns).
    pub fn apply(&mut self, v: &[f64], out: &mut [f64]) -> Result<(), ContactError> {
        let m = self.n_rows();
        self.apply_block(0..m, 0..m, v, out)
    }

    /// `out = S[rows, cols] v` (`v` has `cols.len()` entries, `out` `rows.len()`).
    pub fn apply_block(
        &mut self,
        rows: Range<usize>,
        cols: Range<usize>,
        v: &[f64],
        out: &mut [f64],
    ) -> Result<(), ContactError> {
        let m = self.n_rows();
        if rows.end > m || cols.end > m || v.len() != cols.len() || out.len() != rows.len() {
            return Err(ContactError::InvalidParameter(format!(
                "S[{rows:?}, {cols:?}] applied to {} entries into {} (m = {m})",
                v.len(),
                out.len()
            )));
        }
        self.products += 1;
        out.iter_mut().for_each(|o| *o = 0.0);
        if self.dense {
            for (j, &vj) in cols.clone().zip(v) {
                if vj == 0.0 {
                    continue;
                }
                let col = self.interface.column(j).ok_or_else(|| {
                    ContactError::InvalidParameter(format!("column {j} of S was not computed"))
                })?;
                for (o, c) in out.iter_mut().zip(&col[rows.clone()]) {
                    *o += vj * c;
                }
            }
            return Ok(());
        }
        if v.iter().all(|&a| a == 0.0) {
            return Ok(());
        }
        let t0 = Instant::now();
        let mut full = vec![0.0; m];
        full[cols].copy_from_slice(v);
        let mut x = vec![0.0; self.problem.operator.n()];
        self.problem.apply_transpose_add(&full, &mut x);
        self.problem.operator.solve_in_place(&mut x)?;
        self.extra_solves += 1;
        for (o, r) in out.iter_mut().zip(rows) {
            *o = self.problem.row(r).map(|(c, a)| a * x[c]).sum();
        }
        self.extra_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// `diag S`: exact when dense; matrix-free, the Cauchy–Schwarz lower bound
    /// `S_rr = c_rᵀ A⁻¹ c_r ≥ ‖c_r‖⁴ / (c_rᵀ A c_r)` (exact up to the spread of `A` on the row's
    /// support; used only for scaling).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n_rows())
            .map(|r| {
                if self.dense {
                    self.interface.column(r).map_or(0.0, |c| c[r])
                } else {
                    let row: Vec<(usize, f64)> = self.problem.row(r).collect();
                    let cc: f64 = row.iter().map(|(_, a)| a * a).sum();
                    let op = self.problem.operator;
                    let cac = if row.iter().all(|&(i, _)| op.entry(i, i).is_some()) {
                        let mut cac = 0.0;
                        for &(i, a) in &row {
                            for &(k, b) in &row {
                                cac += a * b * op.entry(i, k).unwrap_or(0.0);
                            }
                        }
                        cac
                    } else {
                        // a matrix-free operator: c_rᵀ A c_r by one product
                        let mut c = vec![0.0; op.n()];
                        row.iter().for_each(|&(i, a)| c[i] += a);
                        let ac = op.apply(&c);
                        row.iter().map(|&(i, a)| a * ac[i]).sum()
                    };
                    if cac > 0.0 {
                        cc * cc / cac
                    } else {
                        0.0
                    }
                }
            })
            .collect()
    }

    /// `U = A⁻¹ (F − Cᵀ ν)` (one solve).
    pub fn displacement(&mut self, nu: &[f64]) -> Result<Vec<f64>, ContactError> {
        self.interface.displacement(nu)
    }
}

/// The symmetrically scaled diagonal block `D^{-½} S[R, R] D^{-½}` (`R` a range of rows,
/// `D^{-½}` given by `inv_sqrt`) as a [`Hessian`].
#[derive(Debug)]
pub(crate) struct ScaledBlock<'a, 'p> {
    pub op: &'a mut SchurOperator<'p>,
    pub rows: Range<usize>,
    pub inv_sqrt: &'a [f64],
    pub tmp: Vec<f64>,
}

impl<'a, 'p> ScaledBlock<'a, 'p> {
    pub fn new(op: &'a mut SchurOperator<'p>, rows: Range<usize>, inv_sqrt: &'a [f64]) -> Self {
        let n = rows.len();
        Self { op, rows, inv_sqrt, tmp: vec![0.0; n] }
    }
}

impl Hessian for ScaledBlock<'_, '_> {
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), ContactError> {
        for ((t, a), s) in self.tmp.iter_mut().zip(x).zip(self.inv_sqrt) {
            *t = a * s;
        }
        self.op.apply_block(self.rows.clone(), self.rows.clone(), &self.tmp, y)?;
        for (a, s) in y.iter_mut().zip(self.inv_sqrt) {
            *a *= s;
        }
        Ok(())
    }
    fn diagonal(&mut self) -> Option<Vec<f64>> {
        let d = self.op.diagonal();
        Some(self.rows.clone().zip(self.inv_sqrt).map(|(r, s)| d[r] * s * s).collect())
    }
}
