//! Measures the active-set strategies of the Newton iteration (`ActiveSetStrategy::Nested`,
//! `::Combined` and `::Outer`) on the neo-Hookean Hertz problems of `tests/hertz_small_load.rs`: a
//! half-disc (2D, plane strain) or a hemisphere (3D) in finite strain pressed on a rigid flat
//! by a prescribed displacement of its top, in `levels` equal levels, frictionless or with
//! Coulomb friction 0.3 (frozen per level; the top then also moves sideways by 0.3 × the push).
//!
//! `cargo run --release -p synovia-nonlinear --example active_set_strategies -- DIM PUSH LEVELS FRICTION`
//! prints one JSON line per strategy (Newton iterations, factorisations, contact-solver
//! iterations and linear solves, wall time, the final KKT residual and Newton residual) and
//! one per other strategy with the largest differences of its solution from the Nested one.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

use synovia_contact::obstacle::PlaneObstacle;
use synovia_contact::operators::ContactPair;
use synovia_contact::{ContactError, ContactProblem, ContactSolution, ContactSolver, SolveContext};
use synovia_fem::{ElasticParams, Kinematics, Model};
use synovia_material::neo_hookean;
use synovia_mesh::generators::{half_disc_refined, hemisphere_refined};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::BoundaryKind;
use synovia_nonlinear::{ActiveSetStrategy, NewtonParams, NonlinearContact, NonlinearError, NonlinearResult};
use synovia_pdas::Pdas;

type Failure = Box<dyn std::error::Error>;

/// Counts the contact solves, their iterations and linear solves of the wrapped solver (and
/// of its active-set step).
#[derive(Clone)]
struct Counting {
    inner: Arc<dyn ContactSolver + Send + Sync>,
    solves: Arc<AtomicUsize>,
    iterations: Arc<AtomicUsize>,
    linear_solves: Arc<AtomicUsize>,
}

struct CountingStep {
    inner: Box<dyn ContactSolver>,
    counts: Counting,
}

fn count(c: &Counting, r: &Result<ContactSolution, ContactError>) {
    if let Ok(s) = r {
        c.solves.fetch_add(1, Ordering::Relaxed);
        c.iterations.fetch_add(s.report.iterations, Ordering::Relaxed);
        c.linear_solves.fetch_add(s.report.linear_solves, Ordering::Relaxed);
    }
}

impl ContactSolver for Counting {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn solve(&self, p: &ContactProblem<'_>, ctx: &SolveContext) -> Result<ContactSolution, ContactError> {
        let r = self.inner.solve(p, ctx);
        count(self, &r);
        r
    }
    fn active_set_step(&self) -> Option<Box<dyn ContactSolver>> {
        let inner = self.inner.active_set_step()?;
        Some(Box::new(CountingStep { inner, counts: self.clone() }))
    }
}

impl ContactSolver for CountingStep {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn solve(&self, p: &ContactProblem<'_>, ctx: &SolveContext) -> Result<ContactSolution, ContactError> {
        let r = self.inner.solve(p, ctx);
        count(&self.counts, &r);
        r
    }
}

fn model_2d(push: f64, friction: bool) -> Result<(Model<2>, Vec<ContactPair<2>>), Failure> {
    let mut mesh = half_disc_refined(Point::<2>::new(0.0, 1.0), 1.0, 8, Point::<2>::new(0.0, 0.0), 0.25, 9)?;
    mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[1] < 0.3 && n[1] < 0.0)?;
    let mut model = Model::new();
    let b = model.add_body("disc", mesh, Arc::new(neo_hookean(10.0, 0.3)?))?;
    let side = if friction { 0.3 * push } else { 0.0 };
    model.prescribe(b, "top", move |_, t| Vector::<2>::new(side * t, -push * t))?;
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0))?;
    let mut pair = ContactPair::rigid("disc-flat", b, "contact", Arc::new(flat));
    if friction {
        pair = pair.with_friction(0.3);
    }
    Ok((model, vec![pair]))
}

fn model_3d(push: f64, friction: bool) -> Result<(Model<3>, Vec<ContactPair<3>>), Failure> {
    let mut mesh = hemisphere_refined(Point::<3>::new(0.0, 0.0, 1.0), 1.0, 4, Point::<3>::zeros(), 0.15, 12)?;
    mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[2] < 0.15 && n[2] < 0.0)?;
    let mut model = Model::new();
    let b = model.add_body("ball", mesh, Arc::new(neo_hookean(10.0, 0.3)?))?;
    let side = if friction { 0.3 * push } else { 0.0 };
    model.prescribe(b, "top", move |_, t| Vector::<3>::new(side * t, 0.5 * side * t, -push * t))?;
    let flat = PlaneObstacle::new(Point::<3>::zeros(), Vector::<3>::new(0.0, 0.0, 1.0))?;
    let mut pair = ContactPair::rigid("ball-flat", b, "contact", Arc::new(flat));
    if friction {
        pair = pair.with_friction(0.3);
    }
    Ok((model, vec![pair]))
}

struct Run {
    u: Vec<f64>,
    lambda_n: Vec<f64>,
    lambda_t: Vec<f64>,
    force: f64,
}

fn run<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    levels: usize,
    strategy: ActiveSetStrategy,
    label: &str,
) -> Result<Run, Failure> {
    let params = NewtonParams::default().with_active_sets(strategy);
    let counting = Counting {
        inner: Arc::new(Pdas::default()),
        solves: Arc::default(),
        iterations: Arc::default(),
        linear_solves: Arc::default(),
    };
    let start = Instant::now();
    let mut nl =
        NonlinearContact::new(model, pairs, &[Kinematics::FiniteStrain], ElasticParams::default(), params)?;
    let times: Vec<f64> = (1..=levels).map(|k| k as f64 / levels as f64).collect();
    let results: Vec<NonlinearResult<D>> =
        nl.run(model, &times, &counting, |_| Ok::<(), NonlinearError>(()))?;
    let wall = start.elapsed().as_secs_f64();
    if std::env::var_os("ASM_TRACE").is_some() {
        // the Newton iterations of each level's last solve: (residual, step α, active rows)
        for (k, r) in results.iter().enumerate() {
            let it: Vec<String> = r
                .report
                .iterations
                .iter()
                .map(|i| format!("{:.1e}/{}/{}", i.residual, i.step, i.active))
                .collect();
            eprintln!("{label} level {k}: {}", it.join(" "));
        }
    }
    let newton: usize = results.iter().map(|r| r.report.total_iterations).sum();
    let factorisations: usize = results.iter().map(|r| r.report.factorisations).sum();
    let cutbacks: usize = results.iter().map(|r| r.report.cutbacks).sum();
    let per_level: Vec<usize> = results.iter().map(|r| r.report.iterations.len()).collect();
    let last = results.last().ok_or("no level")?;
    let kkt = results.iter().map(|r| r.contact.kkt.max()).fold(0.0, f64::max);
    let residual = last.report.residual();
    let geo = nl.geometry();
    let force = last.contact.normal_force(geo, 0..geo.len());
    let r = &last.contact;
    let (active, stick, slip) = (r.solution.report.active, r.solution.report.stick, r.solution.report.slip);
    println!(
        "{{\"dim\":{D},\"strategy\":\"{label}\",\"levels\":{levels},\"newton_iterations\":{newton},\"per_level\":{per_level:?},\"cutbacks\":{cutbacks},\"factorisations\":{factorisations},\"contact_solves\":{},\"contact_iterations\":{},\"linear_solves\":{},\"wall_s\":{wall:.3},\"max_kkt\":{kkt:.2e},\"last_residual\":{residual:.2e},\"force\":{force:.10e},\"active\":{active},\"stick\":{stick},\"slip\":{slip}}}",
        counting.solves.load(Ordering::Relaxed),
        counting.iterations.load(Ordering::Relaxed),
        counting.linear_solves.load(Ordering::Relaxed),
    );
    Ok(Run {
        u: r.solution.u.clone(),
        lambda_n: r.solution.lambda_n.clone(),
        lambda_t: r.solution.lambda_t.clone(),
        force,
    })
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

fn compare<const D: usize>(model: &Model<D>, pairs: &[ContactPair<D>], levels: usize) -> Result<(), Failure> {
    let nested = run(model, pairs, levels, ActiveSetStrategy::Nested, "nested")?;
    for (label, strategy) in [("combined", ActiveSetStrategy::Combined), ("outer", ActiveSetStrategy::Outer)]
    {
        let other = run(model, pairs, levels, strategy, label)?;
        println!(
            "{{\"dim\":{D},\"{label}_vs_nested\":{{\"u\":{:.2e},\"lambda_n\":{:.2e},\"lambda_t\":{:.2e},\"force\":{:.2e}}}}}",
            rel_diff(&other.u, &nested.u),
            rel_diff(&other.lambda_n, &nested.lambda_n),
            if nested.lambda_t.is_empty() { 0.0 } else { rel_diff(&other.lambda_t, &nested.lambda_t) },
            (other.force / nested.force - 1.0).abs(),
        );
    }
    Ok(())
}

fn main() -> Result<(), Failure> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dim: usize = args.first().map_or(Ok(2), |s| s.parse())?;
    let push: f64 = args.get(1).map_or(Ok(1e-3), |s| s.parse())?;
    let levels: usize = args.get(2).map_or(Ok(1), |s| s.parse())?;
    let friction = args.get(3).is_some_and(|s| s == "friction");
    println!("{{\"case\":{{\"dim\":{dim},\"push\":{push},\"levels\":{levels},\"friction\":{friction}}}}}");
    match dim {
        2 => {
            let (m, p) = model_2d(push, friction)?;
            compare(&m, &p, levels)
        }
        3 => {
            let (m, p) = model_3d(push, friction)?;
            compare(&m, &p, levels)
        }
        _ => Err("DIM must be 2 or 3".into()),
    }
}
