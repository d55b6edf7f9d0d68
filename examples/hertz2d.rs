//! # 2D Hertz contact: a cylinder on a rigid flat, and two cylinders of different stiffness
//!
//! Spec §9: for a cylinder of radius `R` pressed with a force `P` per unit thickness onto a
//! flat, the contact half-width is `a = sqrt(4 P R*/(π E*))` and the pressure
//! `p(x) = p₀ sqrt(1 − x²/a²)`, `p₀ = 2P/(π a)`, with `1/E* = Σ (1 − ν_i²)/E_i` and
//! `1/R* = Σ 1/R_i`. The indenter is a half-disc whose top is pushed down; its contact part is
//! refined toward the contact point by longest-edge bisection. The contact problem
//! (docs/model.md §5) is solved by the chosen solver (default: PDAS, the semismooth Newton method).
//!
//! For four refinements the example prints `a`, `p₀` and the L² error of the pressure
//! profile against the analytic values for the measured `P`, and the solver's iteration
//! counts: from a cold start (`Λ = 0`) the PDAS count grows like `log(1/h)` (each iteration
//! removes about half of the initial overshoot of the contact zone); with nested iteration on
//! the contact rows (`synovia_contact::nested`, the default) the final solve needs 1–3
//! iterations on every mesh, and the coarse levels a few more each. Each run ends with one
//! JSON line.
//!
//! Run: `cargo run --release --example hertz2d [pdas|au-pdas|uzawa-mprgp|dual-mprgp]`

use synovia_models::hertz::{hertz2d, hertz2d_write, ContactRun, Hertz2d};

fn table(title: &str, runs: &[ContactRun]) {
    println!("\n{title}");
    println!(
        "{:>6} {:>10} {:>8} {:>7} {:>6} {:>5} {:>6} {:>10} {:>10} {:>10} {:>10} {:>8} {:>8}",
        "level",
        "h",
        "dofs",
        "active",
        "across",
        "iter",
        "coarse",
        "a",
        "a err",
        "p0 err",
        "L2 err",
        "solve s",
        "A s"
    );
    for r in runs {
        println!(
            "{:>6} {:>10.3e} {:>8} {:>7} {:>6.0} {:>5} {:>6} {:>10.5} {:>10.2e} {:>10.2e} {:>10.2e} {:>8.3} {:>8.3}",
            r.level,
            r.h,
            r.dofs,
            r.active_nodes,
            2.0 * r.a_exact / r.h,
            r.iterations,
            r.coarse_iterations,
            r.a,
            r.a_rel_err(),
            r.p0_rel_err(),
            r.pressure_l2_err,
            r.solve_s,
            r.linear_solve_s
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "pdas".to_string());
    let solver = synovia::solvers::by_name(&name)?;

    // ## Step 1: half-disc on a rigid flat, four refinements
    std::fs::create_dir_all("out/hertz2d")?;
    let vtu = std::path::Path::new("out/hertz2d/hertz2d_rigid.vtu");
    let mut rigid = Vec::new();
    for levels in [8, 10, 12, 14] {
        // the finest run also writes its contact state (pressure, active set) for ParaView
        let out = (levels == 14).then_some(vtu);
        rigid.push(hertz2d_write(&Hertz2d { levels, ..Default::default() }, solver.as_ref(), out)?);
    }
    println!("wrote {} (colour by contact_pressure / contact_active)", vtu.display());
    table("cylinder on a rigid flat (E = 1, ν = 0.3, R = 1)", &rigid);
    let mut cold = Vec::new();
    for levels in [8, 10, 12, 14] {
        cold.push(hertz2d(&Hertz2d { levels, nested: false, ..Default::default() }, solver.as_ref())?);
    }
    table("the same from a cold start (no nested iteration)", &cold);

    // ## Step 2: two cylinders, E₁ = 1 and E₂ = 3
    let mut pair = Vec::new();
    for levels in [8, 10, 12] {
        pair.push(hertz2d(&Hertz2d { levels, e2: Some(3.0), ..Default::default() }, solver.as_ref())?);
    }
    table("two cylinders (E₁ = 1, E₂ = 3, ν = 0.3, R₁ = R₂ = 1)", &pair);

    // ## Step 3: checks (docs/model.md §9 tolerances) on the resolved meshes (≥ 40 nodes across 2a)
    for r in rigid.iter().chain(&pair).filter(|r| 2.0 * r.a_exact / r.h >= 40.0) {
        assert!(r.a_rel_err() < 0.02 && r.p0_rel_err() < 0.02 && r.pressure_l2_err < 0.03, "{r:?}");
    }
    let (first, last) = (rigid[0].iterations, rigid[rigid.len() - 1].iterations);
    println!("\n{name} iterations over refinement (levels 8, 10, 12, 14; h halves per step):");
    println!("  nested, final solve: {:?}", rigid.iter().map(|r| r.iterations).collect::<Vec<_>>());
    println!("  nested, coarse levels: {:?}", rigid.iter().map(|r| r.coarse_iterations).collect::<Vec<_>>());
    println!("  cold start: {:?}", cold.iter().map(|r| r.iterations).collect::<Vec<_>>());
    assert!(name != "pdas" || last <= first + 3, "PDAS iterations grow with refinement");
    let svg = std::path::Path::new("out/hertz2d/pressure.svg");
    plot_pressure(svg, &rigid[rigid.len() - 1])?;
    println!("wrote {} (computed nodal pressure vs the Hertz curve)", svg.display());
    for r in rigid.iter().chain(&cold).chain(&pair) {
        println!("{}", r.json());
    }
    Ok(())
}

/// The computed nodal pressures of `run` against the Hertz curve `p₀ sqrt(1 − x²/a²)` (exact
/// `a`, `p₀` for the computed force), as an SVG.
fn plot_pressure(path: &std::path::Path, run: &ContactRun) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let (a, p0) = (run.a_exact, run.p0_exact);
    let xmax = 1.5 * a;
    let root = SVGBackend::new(path, (800, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("2D Hertz, cylinder on a rigid flat (level {})", run.level), ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(-xmax..xmax, 0.0..1.15 * p0)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("x / R")
        .y_desc("contact pressure / E")
        .draw()
        .map_err(|e| e.to_string())?;
    let n = 400;
    let curve = (0..=n).map(|i| {
        let x = -xmax + 2.0 * xmax * i as f64 / n as f64;
        (x, if x.abs() < a { p0 * (1.0 - (x / a).powi(2)).sqrt() } else { 0.0 })
    });
    chart
        .draw_series(LineSeries::new(curve, &RED))
        .map_err(|e| e.to_string())?
        .label("Hertz: p0 sqrt(1 - x²/a²)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    chart
        .draw_series(
            run.profile
                .iter()
                .filter(|(x, _)| x.abs() <= xmax)
                .map(|&(x, p)| Circle::new((x, p), 2, BLUE.filled())),
        )
        .map_err(|e| e.to_string())?
        .label("computed nodal pressure")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, BLUE.filled()));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())?;
    Ok(())
}
