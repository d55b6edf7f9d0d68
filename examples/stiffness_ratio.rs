//! # Stiffness ratios: does every solver converge when one body is much stiffer?
//!
//! Two stacked elastic blocks in plane strain: the lower `[0, 1] × [−½, 0]` (Young's modulus
//! `E₁`) is clamped at its bottom, the upper `[0, 1] × [0, ½]` (`E₂`) is pressed from above by
//! moving its top down by `δ`; both have side rollers (`u_x = 0`), and a node-to-node contact
//! pair joins the upper block's bottom (slave) to the lower block's top (master). The exact
//! solution is the uniaxial strain state with the uniform contact pressure
//! `p = δ / (H₁/M₁ + H₂/M₂)`, `M = λ + 2μ` (linear elements reproduce it exactly), so the
//! transmitted force must equal `p · 1`.
//!
//! For `E₁/E₂ ∈ {1, 1e2, 1e4, 1e5, 1e6}` the example solves the problem with every basic solver
//! (`synovia::solvers::SOLVER_NAMES`), the `pdas-fallback` combinator and the default solver
//! of a new model ([`synovia::solvers::DEFAULT_SOLVER`]), and prints for each the KKT residual
//! of the returned solution (`check_kkt`, through `StaticContact::solve(..).kkt`), the
//! iterations, the solver that actually produced the solution (`SolverReport::solver`, and the
//! fallback if one was used) and the relative force error. It asserts that the default solver
//! converges with KKT ≤ 1e-8 and the exact force in every case, and ends with one JSON line.
//!
//! Run with `cargo run --release --example stiffness_ratio`.

use std::sync::Arc;

use synovia::contact::StaticContact;
use synovia::contact_ops::operators::ContactPair;
use synovia::fem::ComponentMask;
use synovia::prelude::*;
use synovia::solvers::{by_name, COMBINATOR_NAMES, DEFAULT_SOLVER, SOLVER_NAMES};

const DELTA: f64 = 1e-3;
const NU: f64 = 0.3;
const RATIOS: [f64; 5] = [1.0, 1e2, 1e4, 1e5, 1e6];

/// `M = λ + 2μ` of plane strain `(E, ν)`.
fn oedometer(e: f64) -> f64 {
    e * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU))
}

/// The two stacked blocks with `E₁ = ratio` (lower) and `E₂ = 1` (upper), `n` cells across.
fn stacked_blocks(
    ratio: f64,
    n: usize,
) -> Result<(Model<2>, Vec<ContactPair<2>>), Box<dyn std::error::Error>> {
    let mut model = Model::<2>::new();
    let mut lower = rectangle(0.0, 1.0, -0.5, 0.0, n, n / 2, Grading::Uniform, Grading::Uniform)?;
    lower.set_part_kind("bottom", BoundaryKind::Clamped)?;
    lower.set_part_kind("top", BoundaryKind::Contact)?;
    let mut upper = rectangle(0.0, 1.0, 0.0, 0.5, n, n / 2, Grading::Uniform, Grading::Uniform)?;
    upper.set_part_kind("bottom", BoundaryKind::Contact)?;
    upper.set_part_kind("top", BoundaryKind::Prescribed)?;
    for m in [&mut lower, &mut upper] {
        m.set_part_kind("left", BoundaryKind::Prescribed)?;
        m.set_part_kind("right", BoundaryKind::Prescribed)?;
    }
    let lo = model.add_body("lower", lower, Arc::new(plane_strain(ratio, NU)?))?;
    let up = model.add_body("upper", upper, Arc::new(plane_strain(1.0, NU)?))?;
    for b in [lo, up] {
        for side in ["left", "right"] {
            model.prescribe_components(b, side, ComponentMask::only(0), |_, _| Vector::<2>::zeros())?;
        }
    }
    model.prescribe(up, "top", |_, _| Vector::<2>::new(0.0, -DELTA))?;
    Ok((model, vec![ContactPair::node_to_node("upper-lower", up, "bottom", lo, "top")]))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n = 16;
    let mut names: Vec<&str> = SOLVER_NAMES.to_vec();
    names.extend_from_slice(COMBINATOR_NAMES);
    let mut default_worst_kkt = 0.0_f64;
    let mut default_max_iterations = 0;
    let mut default_worst_force = 0.0_f64;
    let mut rows = Vec::new();
    println!(
        "{:>8} {:>24} {:>6} {:>10} {:>10}  solver that ran",
        "E1/E2", "solver", "iters", "KKT", "force err"
    );
    for ratio in RATIOS {
        let (model, pairs) = stacked_blocks(ratio, n)?;
        let p_exact = DELTA / (0.5 / oedometer(ratio) + 0.5 / oedometer(1.0));
        let sc = StaticContact::new(&model, &pairs, Default::default())?;
        let candidates = names
            .iter()
            .map(|s| (s.to_string(), *s))
            .chain([(format!("default ({DEFAULT_SOLVER})"), DEFAULT_SOLVER)]);
        for (label, name) in candidates {
            let solver = by_name(name)?;
            let (iters, kkt, force_err, ran) = match sc.solve(&model, 0.0, solver.as_ref(), None, None, None)
            {
                Ok(res) => {
                    let force = res.normal_force(sc.geometry(), 0..sc.geometry().len());
                    let rep = &res.solution.report;
                    let ran = match &rep.fallback {
                        Some(f) => format!("{} (fallback: {f})", rep.solver),
                        None => rep.solver.clone(),
                    };
                    (rep.iterations, res.kkt.max(), (force - p_exact).abs() / p_exact, ran)
                }
                Err(e) => (0, f64::INFINITY, f64::INFINITY, format!("failed: {e}")),
            };
            println!("{ratio:>8.0e} {label:>24} {iters:>6} {kkt:>10.2e} {force_err:>10.2e}  {ran}");
            rows.push(format!(
                "{{\"ratio\":{ratio:e},\"solver\":\"{name}\",\"iterations\":{iters},\"kkt\":{}}}",
                if kkt.is_finite() { format!("{kkt:e}") } else { "null".to_string() }
            ));
            if name == DEFAULT_SOLVER && label.starts_with("default") {
                assert!(kkt <= 1e-8, "default solver at E1/E2 = {ratio:e}: KKT {kkt:e} ({ran})");
                assert!(force_err <= 1e-8, "default solver at E1/E2 = {ratio:e}: force error {force_err:e}");
                default_worst_kkt = default_worst_kkt.max(kkt);
                default_worst_force = default_worst_force.max(force_err);
                default_max_iterations = default_max_iterations.max(iters);
            }
        }
    }
    println!(
        "{{\"example\":\"stiffness_ratio\",\"default_solver\":\"{DEFAULT_SOLVER}\",\"default_max_kkt\":{default_worst_kkt:e},\
         \"default_max_force_error\":{default_worst_force:e},\"default_max_iterations\":{default_max_iterations},\"runs\":[{}]}}",
        rows.join(",")
    );
    Ok(())
}
