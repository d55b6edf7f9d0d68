//! The primal–dual active set method (semismooth Newton) on the contact interface.

use std::collections::VecDeque;
use std::time::Instant;

use synovia_contact::{
    ContactError, ContactParams, ContactProblem, ContactSolution, ContactSolver, IterationResidual,
    SolveContext, SolverReport,
};

use crate::sets::{finish, stalled_but_kkt_converged, CellState, Sets, State};

/// Primal–dual active set method (PDAS) = semismooth Newton method for the contact problem of
/// docs/model.md §5 (frictionless or Tresca, 2D or 3D), condensed on the contact interface.
///
/// With the force multipliers `ν = (κ Λ_n, Λ_t)`, the interface values `y(ν) = w − S ν`
/// (`S = C A⁻¹ Cᵀ`, `w = C A⁻¹ F`, `C = [B_hn; B_Ht]`), the offsets `g = (d, s)` and the
/// complementarity parameters `ρ` (from [`ContactProblem::default_rho`] with
/// [`ContactParams::rho_scale`]), PDAS solves the nonsmooth system
///
/// ```text
/// ν_r − max(0, ν_r + ρ_r (y_r(ν) − d_r))         = 0     normal rows r
/// Λ_t,c − π(Λ_t,c + ρ_c (y_c(ν) − s_c))          = 0     friction cells c
/// ```
///
/// by Newton's method with the generalised (Clarke/slant) derivative of `max` and of the
/// projection `π`. Iteration `k` (from `(ν^k, y^k)`, `ζ_c = Λ_t,c^k + ρ_c (y_c^k − s_c)`):
///
/// 1. `𝒜_n = {r : ν_r^k + ρ_r (y_r^k − d_r) > 0}`, `ℐ_n` the rest;
///    stick `𝒜_t = {c : ‖ζ_c‖ < 1}`, slip `ℐ_t` the rest; a cell that slipped in the previous
///    iteration against its multiplier (`Λ_t,c^k · (y_c^k − s_c) < 0`) is put in `𝒜_t`
///    (slip-reversal safeguard, see the crate docs).
/// 2. Solve the linear equations for `ν^{k+1}`:
///    * `r ∈ 𝒜_n`: `(S ν)_r = w_r − d_r` (i.e. `[U_n] = d`); `r ∈ ℐ_n`: `ν_r = 0`;
///    * `c ∈ 𝒜_t`: `(S ν)_c = w_c − s_c` (i.e. `B_Ht U = s`);
///    * `c ∈ ℐ_t`, 2D: `ν_c = sign ζ_c`;
///    * `c ∈ ℐ_t`, 3D: the Newton linearisation of `Λ_t − ζ/‖ζ‖ = 0`,
///      `(I − P/‖ζ‖) ν_c − (ρ_c/‖ζ‖) P (y_c(ν) − s_c) = ζ/‖ζ‖`, `P = I − ζζᵀ/‖ζ‖²`.
///      Writing `n = ζ/‖ζ‖`, `t ⊥ n`, its `n`-component is `nᵀ ν_c = 1` and its `t`-component
///      is `tᵀ (S ν)_c + ((‖ζ‖ − 1)/ρ_c) tᵀ ν_c = tᵀ (w_c − s_c)`; hence `ν_c = n + β_c t`
///      with one unknown `β_c` per slipping cell, and the reduced system
///      `(Qᵀ S Q + D) x = Qᵀ (w − g − S ν_fixed)` (`D = diag((‖ζ_c‖ − 1)/ρ_c) ≥ 0`) is
///      symmetric positive definite. It is solved densely by Cholesky.
/// 3. `y^{k+1} = w − S ν^{k+1}` (only the columns of `S` of rows with `ν ≠ 0` are used,
///    each computed once by one solve with the factor of `A`).
/// 4. Stop when the sets computed from `(ν^{k+1}, y^{k+1})` equal those of step 1 and both
///    relative residuals (see [`IterationResidual`]) are at most `tolerance`; or, when the sets
///    were unchanged in the last two iterations and the residual stopped decreasing (it is at
///    the rounding level of `y = w − S ν`, which grows with the condition number of `A`, e.g.
///    with the stiffness ratio of the bodies), when every relative residual of
///    [`synovia_contact::check_kkt`] at `U = A⁻¹ (F − Cᵀ ν)` is at most `tolerance` (a
///    scale-aware test: equilibrium relative to the forces, gaps to the displacements).
///
/// A row whose switching quantity lies within `1e-12` (relative) of its threshold keeps its
/// state (weakly active rows, where both states solve the problem). Normal rows with an empty
/// `B_hn` row are always inactive (or [`ContactError::Infeasible`] when `d_r < 0`); friction
/// cells with empty `B_Ht` rows are fixed to `Λ_t = −s/‖s‖` (or `0`).
///
/// Initial guess: the multipliers of the warm start if given, else `ν = 0`. At the end
/// `U = A⁻¹ (F − Cᵀ ν)` (one solve).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Pdas {
    /// Tolerance, iteration limit and `ρ` scale.
    pub params: ContactParams,
}

impl Pdas {
    /// A PDAS solver with the given parameters.
    pub fn new(params: ContactParams) -> Self {
        Self { params }
    }
}

/// Length of the window in which [`Pdas`] looks for recurring active-set configurations and
/// for progress of the residual.
pub const CYCLE_WINDOW: usize = 8;

/// What [`Pdas::solve_traced`] observed besides its result: the last iterate and the
/// failure modes detected.
#[derive(Debug)]
pub struct PdasTrace {
    /// The result, as returned by [`ContactSolver::solve`] (with `stop_on_cycling`, a
    /// detected cycle ends the iteration early with [`ContactError::NoConvergence`]).
    pub result: Result<ContactSolution, ContactError>,
    /// The last iterate `(U, Λ_n, Λ_t)` reached (also on failure), e.g. to warm-start another
    /// solver; `None` if the iteration failed before the first step.
    pub last_iterate: Option<ContactSolution>,
    /// Period (in iterations) of a detected active-set cycle.
    pub cycle_period: Option<usize>,
    /// The residual did not decrease (by at least 0.1 %) over the last [`CYCLE_WINDOW`]
    /// iterations.
    pub stagnation: bool,
}

impl Pdas {
    /// Solves like [`ContactSolver::solve`] and also returns the last iterate and the
    /// failure modes detected:
    ///
    /// * **cycling** — the sets `(𝒜_n, stick/slip)` (and, in 2D, the signs of `ζ_c` on the
    ///   slipping cells) computed after iteration `k` equal those
    ///   after an iteration `j ∈ [k − CYCLE_WINDOW, k − 1]` although they changed in
    ///   iteration `k`, and the residual `max(normal, tangential)` at `k` is not below
    ///   0.999 × that at `j`. In 2D the step depends on the sets and those signs only, so such
    ///   a recurrence repeats for ever; in 3D (slip directions vary continuously) it is a
    ///   heuristic;
    /// * **stagnation** — after `2 · CYCLE_WINDOW` iterations, the smallest residual of the
    ///   last `CYCLE_WINDOW` iterations is not below 0.999 × the smallest one before.
    ///
    /// With `stop_on_cycling` a detected cycle ends the iteration at once with
    /// [`ContactError::NoConvergence`] (its history up to that iteration), so that a caller
    /// can switch to another method (the `pdas-fallback` solver of the `synovia` facade hands
    /// over to `dual-mprgp`). Otherwise the iteration continues to `max_iterations` as in
    /// [`ContactSolver::solve`]. A converged solution records the detections in
    /// [`SolverReport::cycling_detected`] and [`SolverReport::stagnation_detected`].
    pub fn solve_traced(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
        stop_on_cycling: bool,
    ) -> PdasTrace {
        let mut trace = PdasTrace::empty();
        let mut last_nu = None;
        trace.result =
            self.iterate(problem, context, stop_on_cycling, Mode::Converge, &mut trace, &mut last_nu);
        if let Some((nu, u)) = last_nu {
            let (lambda_n, lambda_t) = problem.split_multipliers(&nu);
            trace.last_iterate =
                Some(ContactSolution { u, lambda_n, lambda_t, report: SolverReport::default() });
        }
        trace
    }

    #[tracing::instrument(level = "debug", skip_all)]
    fn iterate(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
        stop_on_cycling: bool,
        mode: Mode,
        trace: &mut PdasTrace,
        last_nu: &mut Option<(Vec<f64>, Vec<f64>)>,
    ) -> Result<ContactSolution, ContactError> {
        let start = Instant::now();
        let name = match mode {
            Mode::Converge => "pdas",
            Mode::Step => "pdas-step",
        };
        let mut st = State::new(problem, context, &self.params)?;
        let mut nu = st.initial_nu(problem, context.warm_start())?;
        let mut y = st.values(&nu)?;
        if mode == Mode::Step {
            // the sets of the step from the warm start's own interface values `C U`
            if let Some(u) = context.warm_start().map(|w| &w.u).filter(|u| u.len() == problem.load.len()) {
                y = problem.apply(u);
            }
        }
        // a step: the states of the warm start (loaded rows active, cells with ‖Λ_t‖ = 1
        // slipping) are the previous sets, so the switching band and the slip-reversal
        // safeguard apply to its classification as to a PDAS iteration's
        let warm_sets = (mode == Mode::Step && context.warm_start().is_some()).then(|| Sets {
            normal: (0..st.m).map(|r| nu[r] > 0.0).collect(),
            cells: (0..st.n_cells)
                .map(|c| {
                    let z: f64 = (0..st.comps).map(|k| nu[st.cell_row(c, k)].powi(2)).sum();
                    if z.sqrt() >= 1.0 - 1e-12 {
                        CellState::Slip
                    } else {
                        CellState::Stick
                    }
                })
                .collect(),
        });
        let mut sets = Sets {
            normal: st.classify_normal(&nu, &y, warm_sets.as_ref().map(|s| &s.normal[..])),
            cells: st.classify_cells(&nu, &y, warm_sets.as_ref().map(|s| &s.cells[..])),
        };
        let mut history = Vec::new();
        let mut recent: VecDeque<(Sets, Vec<bool>, f64)> = VecDeque::with_capacity(CYCLE_WINDOW + 1);
        let mut best_before = f64::INFINITY;
        let tol = self.params.tolerance;
        let outcome = 'outer: {
            for it in 1..=self.params.max_iterations {
                let zetas = st.zetas(&nu, &y);
                let mut fixed = vec![0.0; nu.len()];
                let mut unknowns = Vec::new();
                st.normal_part(&sets.normal, &mut fixed, &mut unknowns);
                st.tangential_part(&sets.cells, &zetas, true, &mut fixed, &mut unknowns);
                let step = st.solve_step(fixed, &unknowns, name, it);
                nu = match step {
                    Ok(v) => v,
                    Err(e) => break 'outer Err(e),
                };
                y = st.values(&nu)?;
                let new_sets = Sets {
                    normal: st.classify_normal(&nu, &y, Some(&sets.normal)),
                    cells: st.classify_cells(&nu, &y, Some(&sets.cells)),
                };
                let set_changes = new_sets.changes(&sets);
                let (normal, tangential) = st.residual(&nu, &y);
                history.push(IterationResidual { iteration: it, normal, tangential, set_changes });
                let r = normal.max(tangential);
                // failure modes: recurring sets without progress, and stagnation
                // In 2D the next step is fixed by the sets and the signs of ζ on the slipping
                // cells, so a recurrence of both repeats the whole sequence.
                let signs: Vec<bool> = if st.comps == 1 {
                    (0..st.n_cells)
                        .map(|c| new_sets.cells[c] == CellState::Slip && st.zeta(c, &nu, &y)[0] > 0.0)
                        .collect()
                } else {
                    Vec::new()
                };
                if set_changes > 0 {
                    let back = recent
                        .iter()
                        .rev()
                        .position(|(s, sg, rj)| *s == new_sets && *sg == signs && r >= 0.999 * rj);
                    if let Some(k) = back {
                        trace.cycle_period.get_or_insert(k + 1);
                    }
                }
                if it > CYCLE_WINDOW {
                    let (old, _) = history.split_at(it - CYCLE_WINDOW);
                    if let Some(h) = old.last() {
                        best_before = best_before.min(h.normal.max(h.tangential));
                    }
                    let best_recent = history[it - CYCLE_WINDOW..]
                        .iter()
                        .map(|h| h.normal.max(h.tangential))
                        .fold(f64::INFINITY, f64::min);
                    if it >= 2 * CYCLE_WINDOW && best_recent >= 0.999 * best_before && best_recent > tol {
                        trace.stagnation = true;
                    }
                }
                recent.push_back((new_sets.clone(), signs, r));
                if recent.len() > CYCLE_WINDOW {
                    recent.pop_front();
                }
                sets = new_sets;
                let converged = mode == Mode::Step
                    || (set_changes == 0 && normal <= tol && tangential <= tol)
                    || stalled_but_kkt_converged(&mut st, problem, &nu, &history, tol)?;
                if converged {
                    let report = SolverReport {
                        solver: name.to_string(),
                        iterations: it,
                        history,
                        cycling_detected: trace.cycle_period.is_some(),
                        stagnation_detected: trace.stagnation,
                        ..Default::default()
                    };
                    let sol = finish(&mut st, problem, &nu, &sets, report, start)?;
                    *last_nu = Some((nu, sol.u.clone()));
                    return Ok(sol);
                }
                if stop_on_cycling && trace.cycle_period.is_some() {
                    break 'outer Err(ContactError::NoConvergence {
                        solver: name.to_string(),
                        iterations: it,
                        history,
                    });
                }
            }
            Err(ContactError::NoConvergence {
                solver: name.to_string(),
                iterations: self.params.max_iterations,
                history,
            })
        };
        let u = st.iface.displacement(&nu)?;
        *last_nu = Some((nu, u));
        outcome
    }
}

/// Whether [`Pdas`] iterates to convergence or takes one active-set step ([`PdasStep`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Converge,
    Step,
}

/// One active-set update of [`Pdas`]: a single semismooth Newton step of the contact
/// conditions, for a caller that iterates on the sets itself (the `Combined` active-set
/// strategy of `synovia-nonlinear`, where one Newton iteration updates the material and the
/// contact sets together).
///
/// From the warm start `(U⁰, ν⁰)` (or `U⁰ = A⁻¹ F`, `ν⁰ = 0` without one) it computes the
/// sets of [`Pdas`] step 1 from the warm start's **own** interface values `y⁰ = C U⁰` —
/// `𝒜_n = {r : ν⁰_r + ρ_r (y⁰_r − d_r) > 0}`, stick/slip from
/// `ζ_c = Λ⁰_t,c + ρ_c (y⁰_c − s_c)`, with the warm start's own states (rows with `ν⁰_r > 0`
/// active, cells with `‖Λ⁰_t,c‖ = 1` slipping) as the previous sets of the switching band and
/// the slip-reversal safeguard — solves the linear interface system of [`Pdas`] step 2
/// for those sets once (the 3D slip rows linearised at `ζ_c`), and returns
/// `ν¹`, `U¹ = A⁻¹ (F − Cᵀ ν¹)` whether or not it solves the contact problem. Its report has
/// `iterations = 1` and one history entry: the sets computed from `(ν¹, C U¹)` differ from
/// the step's in `set_changes` rows/cells, and `normal`, `tangential` are the relative NCP
/// residuals of [`Pdas`] at `(ν¹, C U¹)`. `U¹` solves the problem exactly when
/// `set_changes = 0` and both residuals vanish (in 2D `set_changes = 0` suffices; in 3D the
/// slip rows are linearised and need further steps).
///
/// With `U⁰ = A⁻¹ (F − Cᵀ ν⁰)` (the warm start a previous [`Pdas`] step on the same
/// problem returns) this is exactly one iteration of [`Pdas`]. In a Newton iteration on a
/// nonlinear material the warm start is the current iterate, `C U⁰ − d` its gap, and the
/// step is a semismooth Newton step of the whole nonsmooth system.
///
/// Only `params.tolerance` and `params.rho_scale` are used (the iteration limit is 1).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PdasStep {
    /// The parameters of the [`Pdas`] iteration the step is taken from.
    pub params: ContactParams,
}

impl PdasStep {
    /// The step of [`Pdas`] with the given parameters.
    pub fn new(params: ContactParams) -> Self {
        Self { params }
    }
}

impl ContactSolver for PdasStep {
    fn name(&self) -> &str {
        "pdas-step"
    }

    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
    ) -> Result<ContactSolution, ContactError> {
        let mut params = self.params;
        params.max_iterations = 1;
        let pdas = Pdas::new(params);
        let mut trace = PdasTrace::empty();
        let mut last_nu = None;
        pdas.iterate(problem, context, false, Mode::Step, &mut trace, &mut last_nu)
    }

    fn active_set_step(&self) -> Option<Box<dyn ContactSolver>> {
        Some(Box::new(*self))
    }

    fn solves_border(&self) -> bool {
        true
    }
}

impl PdasTrace {
    /// A trace before the first iteration (an empty successful result, nothing detected).
    fn empty() -> Self {
        Self { result: Ok(empty_solution()), last_iterate: None, cycle_period: None, stagnation: false }
    }
}

fn empty_solution() -> ContactSolution {
    ContactSolution {
        u: Vec::new(),
        lambda_n: Vec::new(),
        lambda_t: Vec::new(),
        report: SolverReport::default(),
    }
}

impl ContactSolver for Pdas {
    fn name(&self) -> &str {
        "pdas"
    }

    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
    ) -> Result<ContactSolution, ContactError> {
        self.solve_traced(problem, context, false).result
    }

    fn active_set_step(&self) -> Option<Box<dyn ContactSolver>> {
        Some(Box::new(PdasStep::new(self.params)))
    }

    fn solves_border(&self) -> bool {
        true
    }
}
