//! Nested iteration on the contact interface: a warm start from coarser sets of contact rows.
//!
//! Active-set (semismooth Newton) iterations started from `Λ = 0` first see the unconstrained
//! displacement, whose penetration zone overshoots the true contact zone; each iteration then
//! removes part of the overshoot, so the count grows like `log(overshoot / h)` under mesh
//! refinement. Nested iteration removes that growth: the contact rows are coarsened by maximal
//! independent sets of the contact-node graph (halving the rows in 2D, quartering them in 3D)
//! until a few dozen remain; the frictionless problem restricted to the coarsest rows is solved
//! from `Λ = 0`, its pressures are interpolated to the next finer row set (each dropped row takes
//! the mean pressure of its retained neighbours) as that level's warm start, and so on up to the
//! full problem, whose solve starts from an almost correct active set.
//!
//! The coarse problems keep `A` and `F`; a coarse row keeps its `B_hn` row and gap and carries
//! the weights `κ` of the dropped rows assigned to it, so that its `Λ_n` is a pressure.

use crate::context::SolveContext;
use crate::error::ContactError;
use crate::problem::{ContactProblem, NormalConstraints};
use crate::solver::{ContactSolution, ContactSolver, SolverReport};
use synovia_linalg::SparseRows;

/// A hierarchy level: the retained rows (indices into the finest rows) and their graph.
struct Level {
    rows: Vec<usize>,
    adjacency: Vec<Vec<usize>>,
}

/// Greedy maximal independent set of a graph (in index order), with the coarse graph of the
/// retained vertices (connected when within three edges) and the assignment of every vertex
/// to a retained one.
fn coarsen(adjacency: &[Vec<usize>]) -> (Vec<usize>, Vec<Vec<usize>>, Vec<usize>) {
    let n = adjacency.len();
    let mut state = vec![0u8; n]; // 0 undecided, 1 retained, 2 dropped
    for v in 0..n {
        if state[v] == 0 {
            state[v] = 1;
            for &w in &adjacency[v] {
                if state[w] == 0 {
                    state[w] = 2;
                }
            }
        }
    }
    let retained: Vec<usize> = (0..n).filter(|&v| state[v] == 1).collect();
    let mut index = vec![usize::MAX; n];
    for (i, &v) in retained.iter().enumerate() {
        index[v] = i;
    }
    // assignment: retained → itself; dropped → its first retained neighbour
    let assign: Vec<usize> = (0..n)
        .map(|v| {
            if state[v] == 1 {
                index[v]
            } else {
                adjacency[v].iter().find(|&&w| state[w] == 1).map_or(usize::MAX, |&w| index[w])
            }
        })
        .collect();
    // coarse graph: retained vertices within 3 hops
    let mut coarse = vec![Vec::new(); retained.len()];
    let mut mark = vec![usize::MAX; n];
    for (i, &v) in retained.iter().enumerate() {
        let mut frontier = vec![v];
        mark[v] = i;
        for _ in 0..3 {
            let mut next = Vec::new();
            for &x in &frontier {
                for &y in &adjacency[x] {
                    if mark[y] != i {
                        mark[y] = i;
                        next.push(y);
                        if state[y] == 1 {
                            coarse[i].push(index[y]);
                        }
                    }
                }
            }
            frontier = next;
        }
        coarse[i].sort_unstable();
    }
    (retained, coarse, assign)
}

/// Runs the nested iteration for `problem` with `solver` on the contact-row graph `adjacency`
/// (one list per normal row) and returns a warm start for the full problem (tangential
/// multipliers zero) together with the iterations spent on the coarse levels.
///
/// Returns `None` when the problem has at most `min_rows` normal rows (no coarsening needed).
pub fn nested_warm_start(
    problem: &ContactProblem<'_>,
    solver: &dyn ContactSolver,
    context: &SolveContext,
    adjacency: &[Vec<usize>],
    min_rows: usize,
) -> Result<Option<(ContactSolution, usize)>, ContactError> {
    let m = problem.n_normal();
    if adjacency.len() != m {
        return Err(ContactError::InvalidParameter(format!(
            "{} adjacency lists for {m} contact rows",
            adjacency.len()
        )));
    }
    if m <= min_rows.max(2) {
        return Ok(None);
    }
    // hierarchy: levels[0] = all rows
    let mut levels = vec![Level { rows: (0..m).collect(), adjacency: adjacency.to_vec() }];
    let mut assigns: Vec<Vec<usize>> = Vec::new();
    while let Some(last) = levels.last() {
        if last.rows.len() <= min_rows.max(2) {
            break;
        }
        let (keep, coarse, assign) = coarsen(&last.adjacency);
        if keep.len() * 10 > last.rows.len() * 9 {
            break; // not coarsening any more (disconnected rows)
        }
        let rows = keep.iter().map(|&i| last.rows[i]).collect();
        assigns.push(assign);
        levels.push(Level { rows, adjacency: coarse });
    }
    if levels.len() < 2 {
        return Ok(None);
    }
    // solve from the coarsest level up to level 1; interpolate to the next finer level. The
    // levels share the load solve A⁻¹ F and the trailing solves of their rows with the problem's
    // context (not its columns: other rows).
    let shared = context.sharing_solves();
    let mut coarse_iterations = 0;
    let mut warm: Option<Vec<f64>> = None; // Λ_n on the current level's rows
    for lvl in (1..levels.len()).rev() {
        let level = &levels[lvl];
        // weights: sum over the finest rows assigned (through all finer levels) to each row
        let mut weight = vec![0.0; level.rows.len()];
        let mut owner: Vec<usize> = (0..m).collect(); // finest row -> index at current level
        for assign in assigns.iter().take(lvl) {
            for o in owner.iter_mut() {
                *o = assign.get(*o).copied().unwrap_or(usize::MAX);
            }
        }
        for (r, &o) in owner.iter().enumerate() {
            if o < weight.len() {
                weight[o] += problem.normal.weights[r];
            }
        }
        let mut rows = SparseRows::new(problem.normal.rows.ncols());
        let mut gap = Vec::with_capacity(level.rows.len());
        for &r in &level.rows {
            rows.push_row(problem.normal.rows.row(r));
            gap.push(problem.normal.gap[r]);
        }
        let normal = NormalConstraints { rows, weights: weight, gap };
        let sub = ContactProblem { normal: &normal, friction: None, ..*problem };
        let ws = warm.take().map(|ln| ContactSolution {
            u: Vec::new(),
            lambda_n: ln,
            lambda_t: Vec::new(),
            report: SolverReport::default(),
        });
        // only Λ_n of a coarse level is used: no displacement
        let sol = solver.solve(&sub, &shared.with_start(ws, true))?;
        coarse_iterations += sol.report.iterations;
        // interpolate to level lvl − 1
        let finer = &levels[lvl - 1];
        let assign = &assigns[lvl - 1];
        let mut next = vec![0.0; finer.rows.len()];
        let mut is_kept = vec![usize::MAX; finer.rows.len()];
        for (i, a) in assign.iter().enumerate() {
            if *a < sol.lambda_n.len() && level.rows[*a] == finer.rows[i] {
                is_kept[i] = *a;
            }
        }
        for i in 0..finer.rows.len() {
            next[i] = if is_kept[i] != usize::MAX {
                sol.lambda_n[is_kept[i]]
            } else {
                let nb: Vec<f64> = finer.adjacency[i]
                    .iter()
                    .filter(|&&j| is_kept[j] != usize::MAX)
                    .map(|&j| sol.lambda_n[is_kept[j]])
                    .collect();
                if nb.is_empty() {
                    0.0
                } else {
                    nb.iter().sum::<f64>() / nb.len() as f64
                }
            };
        }
        warm = Some(next);
    }
    let lambda_n = warm.unwrap_or_else(|| vec![0.0; m]);
    Ok(Some((
        ContactSolution {
            u: Vec::new(),
            lambda_n,
            lambda_t: vec![0.0; problem.n_tangential()],
            report: SolverReport::default(),
        },
        coarse_iterations,
    )))
}
