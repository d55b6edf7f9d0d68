//! Choosing a contact solver by name (examples, scenario files), and the `pdas-fallback`
//! combinator.

use synovia_contact::{
    ContactError, ContactParams, ContactProblem, ContactSolution, ContactSolver, SolveContext,
};
use synovia_pdas::Pdas;
use synovia_uzawa::DualMprgp;

/// Names accepted by [`by_name`] for the four basic solvers.
pub const SOLVER_NAMES: &[&str] = &["pdas", "au-pdas", "uzawa-mprgp", "dual-mprgp"];

/// The solver a new [`crate::builder::JointModel`] uses (and so the scenario/CLI default when
/// no `solver.name` is given): [`PdasFallback`], i.e. PDAS (superlinear, usually a few
/// iterations) handing over to `dual-mprgp` if PDAS cycles, stalls or meets a singular
/// interface system. Which solver produced a solution is in its
/// [`SolverReport::solver`](synovia_contact::SolverReport) (`"pdas"` or `"dual-mprgp"`) and
/// [`SolverReport::fallback`](synovia_contact::SolverReport) (why PDAS was abandoned).
/// `examples/stiffness_ratio.rs` checks it on two stacked blocks for `E₁/E₂ = 1 … 1e6`.
pub const DEFAULT_SOLVER: &str = "pdas-fallback";

/// Further names accepted by [`by_name`]: combinators of the basic solvers ([`PdasFallback`]).
pub const COMBINATOR_NAMES: &[&str] = &["pdas-fallback"];

/// The solver called `name` (see [`SOLVER_NAMES`], [`COMBINATOR_NAMES`]) with its default
/// parameters.
pub fn by_name(name: &str) -> Result<Box<dyn ContactSolver>, ContactError> {
    Ok(match name {
        "pdas" => Box::new(synovia_pdas::Pdas::default()),
        "au-pdas" => Box::new(synovia_pdas::AuPdas::new(
            ContactParams::default().with_max_iterations(AU_PDAS_MIN_ITERATIONS),
        )),
        "uzawa-mprgp" => Box::new(synovia_uzawa::UzawaMprgp::default()),
        "dual-mprgp" => Box::new(synovia_uzawa::DualMprgp::default()),
        "pdas-fallback" => Box::new(PdasFallback::default()),
        _ => return by_name_with(name, ContactParams::default()),
    })
}

/// Least outer-iteration limit of `uzawa-mprgp` built by [`by_name_with`] (that of
/// [`synovia_uzawa::UzawaMprgp::default`]; [`ContactParams::default`] has 200).
pub const UZAWA_MIN_ITERATIONS: usize = 2000;

/// Least iteration limit of `au-pdas` built by [`by_name`] and [`by_name_with`]: AU-PDAS is a
/// block Gauss–Seidel iteration between normal and tangential rows and converges linearly (3D
/// two-body shear with the bounded step of docs/model.md §6.2: a few hundred iterations).
pub const AU_PDAS_MIN_ITERATIONS: usize = 1000;

/// The solver called `name` with the given parameters (`au-pdas`: at least
/// [`AU_PDAS_MIN_ITERATIONS`] iterations; `uzawa-mprgp`: at least
/// [`UZAWA_MIN_ITERATIONS`] outer iterations; `pdas-fallback`: at least 10 000 iterations of
/// its `dual-mprgp` phase).
pub fn by_name_with(name: &str, params: ContactParams) -> Result<Box<dyn ContactSolver>, ContactError> {
    Ok(match name {
        "pdas" => Box::new(synovia_pdas::Pdas::new(params)),
        // AU-PDAS converges linearly (docs/model.md §6.2): at least AU_PDAS_MIN_ITERATIONS
        "au-pdas" => Box::new(synovia_pdas::AuPdas::new(
            params.with_max_iterations(params.max_iterations.max(AU_PDAS_MIN_ITERATIONS)),
        )),
        // outer Uzawa iterations: at least those of UzawaMprgp::default (its accelerated
        // projected-gradient iteration needs hundreds where PDAS needs a handful)
        "uzawa-mprgp" => Box::new(synovia_uzawa::UzawaMprgp::new(
            params.with_max_iterations(params.max_iterations.max(UZAWA_MIN_ITERATIONS)),
        )),
        "dual-mprgp" => Box::new(synovia_uzawa::DualMprgp::new(params)),
        "pdas-fallback" => Box::new(PdasFallback::new(params)),
        crate::builder::TFETI => {
            return Err(ContactError::InvalidParameter(format!(
                "`{name}` is not a solver on the assembled, factorised stiffness: choose it with JointModel::solver(\"{name}\") (scenario `solver.name`), which runs static and quasi-static analyses of the model decomposed into subdomains (JointModel::run_on)"
            )))
        }
        _ => {
            return Err(ContactError::InvalidParameter(format!(
                "unknown contact solver `{name}`; choose one of {SOLVER_NAMES:?} or {COMBINATOR_NAMES:?}"
            )))
        }
    })
}

/// PDAS with a safeguard against its failure modes (name `"pdas-fallback"`).
///
/// Runs [`Pdas::solve_traced`] with `stop_on_cycling = true`. If PDAS converges, its solution
/// is returned (with [`SolverReport::cycling_detected`](synovia_contact::SolverReport) and
/// `stagnation_detected` as observed). If it fails with [`ContactError::NoConvergence`] (a
/// detected active-set cycle ends it early, otherwise the iteration limit) or
/// [`ContactError::Singular`] (linearly dependent active constraints), the problem is handed to
/// [`DualMprgp`] warm-started from the last PDAS iterate: the dual QP is convex, so its
/// projected-gradient iteration cannot cycle and it tolerates a semi-definite `S`. The returned
/// report is that of `dual-mprgp` with `cycling_detected`/`stagnation_detected` from the PDAS
/// phase and `fallback = Some(…)` naming the PDAS failure. Other errors (invalid input,
/// infeasibility) are returned unchanged, as are the fallback's own errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PdasFallback {
    /// The PDAS phase.
    pub pdas: Pdas,
    /// The fallback (default: the PDAS parameters with at least 10 000 QP iterations).
    pub fallback: DualMprgp,
}

impl PdasFallback {
    /// PDAS with `params`, the fallback with `params` and at least 10 000 QP iterations.
    pub fn new(params: ContactParams) -> Self {
        let fb = params.with_max_iterations(params.max_iterations.max(10_000));
        Self { pdas: Pdas::new(params), fallback: DualMprgp::new(fb) }
    }
}

impl Default for PdasFallback {
    fn default() -> Self {
        Self::new(ContactParams::default())
    }
}

impl ContactSolver for PdasFallback {
    fn name(&self) -> &str {
        "pdas-fallback"
    }

    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
    ) -> Result<ContactSolution, ContactError> {
        let trace = self.pdas.solve_traced(problem, context, true);
        // the fallback does not take a rigid border: PDAS's own result (the caller's
        // force-control iteration falls back to trial solves)
        if problem.border.is_some() {
            return trace.result;
        }
        let failure = match trace.result {
            Ok(sol) => return Ok(sol),
            Err(e @ (ContactError::NoConvergence { .. } | ContactError::Singular { .. })) => e,
            Err(e) => return Err(e),
        };
        let warm = trace.last_iterate.or_else(|| context.warm_start().cloned());
        let mut sol = self.fallback.solve(problem, &context.with_start(warm, context.multipliers_only()))?;
        sol.report.cycling_detected = trace.cycle_period.is_some();
        sol.report.stagnation_detected = trace.stagnation;
        let why = match trace.cycle_period {
            Some(p) => format!("active-set cycle of period {p} detected; {failure}"),
            None => failure.to_string(),
        };
        sol.report.fallback =
            Some(format!("pdas failed ({why}); dual-mprgp warm-started from its last iterate"));
        Ok(sol)
    }

    fn solves_border(&self) -> bool {
        true
    }
}
