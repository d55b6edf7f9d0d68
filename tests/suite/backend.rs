//! The linear-algebra seam (`synovia_linalg::FactorisedOperator`): a back-end written outside
//! the crates — a dense Cholesky factorisation that implements only the required methods and
//! relies on the trait's default interface operations (batched solves for the columns of
//! `S = C A⁻¹ Cᵀ`) — runs every contact solver unchanged and gives the solution of the sparse
//! Cholesky back-end (with its dense interface block) to rounding; both satisfy the KKT
//! conditions of docs/model.md §5.

use synovia::contact_ops::testing::BlockOnFoundation;
use synovia::contact_ops::{check_kkt, ContactProblem, SolveContext};
use synovia::linalg::{FactorisedOperator, LinalgError, Ordering, SparseCholesky, SymmetricMatrix};
use synovia::solvers::by_name;

/// `A` stored densely and factorised by faer's dense Cholesky `A = L Lᵀ`.
#[derive(Debug)]
struct DenseCholesky {
    a: faer::Mat<f64>,
    llt: faer::linalg::solvers::Llt<f64>,
}

impl DenseCholesky {
    fn new(matrix: &SymmetricMatrix) -> Self {
        let n = matrix.n();
        let a = faer::Mat::<f64>::from_fn(n, n, |i, j| matrix.get(i, j));
        let llt = a.llt(faer::Side::Lower).expect("SPD");
        Self { a, llt }
    }
}

impl FactorisedOperator for DenseCholesky {
    fn n(&self) -> usize {
        self.a.nrows()
    }
    fn apply(&self, x: &[f64]) -> Vec<f64> {
        (0..self.n()).map(|i| (0..self.n()).map(|j| self.a[(i, j)] * x[j]).sum()).collect()
    }
    fn diagonal(&self) -> Vec<f64> {
        (0..self.n()).map(|i| self.a[(i, i)]).collect()
    }
    fn key(&self) -> u64 {
        self as *const Self as u64
    }
    fn solve_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
        use faer::linalg::solvers::Solve;
        if b.len() != self.n() {
            return Err(LinalgError::Length { what: "right-hand side", expected: self.n(), got: b.len() });
        }
        let n = self.n();
        self.llt.solve_in_place(faer::MatMut::from_column_major_slice_mut(b, n, 1));
        Ok(())
    }
}

#[test]
fn a_dense_back_end_written_outside_the_crates_gives_the_sparse_solution() {
    for (d, friction) in [(2, None), (2, Some(0.05)), (3, Some(0.05))] {
        let case =
            BlockOnFoundation { n: if d == 2 { 10 } else { 4 }, slip_bound: friction, ..Default::default() };
        let owned = if d == 2 { case.build::<2>() } else { case.build::<3>() }.expect("problem");
        let sparse = owned.problem();
        // the sparse back-end with the interface dofs ordered last (dense block L₂₂)
        let mut last: Vec<usize> = (0..sparse.n_rows()).flat_map(|r| sparse.row(r).map(|(i, _)| i)).collect();
        last.sort_unstable();
        last.dedup();
        let blocked = SparseCholesky::new(
            owned.system.matrix.clone(),
            &Ordering::Trailing { base: Box::new(Ordering::Amd), last },
        )
        .expect("factorise");
        let dense = DenseCholesky::new(&owned.system.matrix);
        for name in ["pdas", "au-pdas", "uzawa-mprgp", "dual-mprgp"] {
            let solver = by_name(name).expect("solver");
            let a = solver
                .solve(&ContactProblem { operator: &blocked, ..sparse }, &SolveContext::new())
                .unwrap_or_else(|e| panic!("{name}, sparse: {e}"));
            let b = solver
                .solve(&ContactProblem { operator: &dense, ..sparse }, &SolveContext::new())
                .unwrap_or_else(|e| panic!("{name}, dense: {e}"));
            for (label, sol, op) in
                [("sparse", &a, &blocked as &dyn FactorisedOperator), ("dense", &b, &dense)]
            {
                let p = ContactProblem { operator: op, ..sparse };
                let kkt = check_kkt(&p, &sol.u, &sol.lambda_n, &sol.lambda_t);
                assert!(kkt.satisfied(1e-8), "{name}, {label}, {d}D: {kkt:?}");
            }
            let scale = a.u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let du = a.u.iter().zip(&b.u).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale;
            let ln = a.lambda_n.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let dl = a.lambda_n.iter().zip(&b.lambda_n).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / ln;
            assert!(a.lambda_n.iter().any(|&l| l > 0.0), "{name}: no contact");
            assert!(
                du < 1e-7 && dl < 1e-6,
                "{name}, {d}D, friction {friction:?}: U differs by {du:e}, Λ_n by {dl:e}"
            );
        }
    }
}

/// A context's kept columns are reused by the next solve of the same operator and rows, and
/// the caches respect the budget however many solves run on it.
#[test]
fn a_context_reuses_columns_and_stays_within_its_budget() {
    let owned = BlockOnFoundation { n: 16, slip_bound: Some(0.05), ..Default::default() }
        .build::<2>()
        .expect("problem");
    let p = owned.problem();
    let solver = by_name("pdas").expect("solver");
    let context = SolveContext::new();
    let first = solver.solve(&p, &context).expect("first");
    let kept = context.kept_columns();
    assert!(kept > 0, "the interface's columns are kept");
    let second = solver.solve(&p, &context.with_start(Some(first.clone()), false)).expect("second");
    // columns and the load solve reused: only the final displacement U = A⁻¹F − A⁻¹Cᵀν
    assert!(first.report.linear_solves > 2, "{:?}", first.report);
    assert!(second.report.linear_solves <= 1, "{:?}", second.report);
    let close = |a: &[f64], b: &[f64]| {
        let s = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-10 * s)
    };
    assert!(close(&first.lambda_n, &second.lambda_n));
    // a tiny budget: nothing above it is kept, and every solve still succeeds
    let small = SolveContext::with_memory_budget(4 * 8 * p.n_rows());
    for _ in 0..20 {
        let s = solver.solve(&p, &small).expect("solve");
        assert!(close(&s.lambda_n, &first.lambda_n));
        assert!(small.bytes() <= small.memory_budget(), "{} > {}", small.bytes(), small.memory_budget());
    }
}

/// Multipliers-only solves (`SolveContext::set_multipliers_only`) of every solver give the
/// multipliers of the full solve and an empty `U`; the KKT check of a solution without `U`
/// reports infinite residuals instead of panicking.
#[test]
fn multipliers_only_solves_of_every_solver_match_full_solves() {
    for friction in [None, Some(0.05)] {
        let owned = BlockOnFoundation { n: 12, slip_bound: friction, ..Default::default() }
            .build::<2>()
            .expect("problem");
        let p = owned.problem();
        for name in ["pdas", "au-pdas", "uzawa-mprgp", "dual-mprgp", "pdas-fallback"] {
            let solver = by_name(name).expect("solver");
            let full = solver.solve(&p, &SolveContext::new()).unwrap_or_else(|e| panic!("{name}: {e}"));
            let mut context = SolveContext::new();
            context.set_multipliers_only(true);
            let only = solver.solve(&p, &context).unwrap_or_else(|e| panic!("{name}, multipliers only: {e}"));
            assert!(only.u.is_empty() && !full.u.is_empty(), "{name}");
            let scale = full.lambda_n.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let d = full.lambda_n.iter().zip(&only.lambda_n).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(d <= 1e-8 * scale, "{name}, friction {friction:?}: Λ_n differs by {d:e}");
            let kkt = check_kkt(&p, &only.u, &only.lambda_n, &only.lambda_t);
            assert!(kkt.max().is_infinite(), "{name}: {kkt:?}");
        }
    }
}
