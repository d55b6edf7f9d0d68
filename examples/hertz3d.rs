//! # 3D Hertz contact: a hemisphere on a rigid flat
//!
//! Spec §9: a sphere of radius `R` pressed with force `P` onto a flat has the contact radius
//! `a = (3 P R*/(4 E*))^{1/3}` and the pressure `p(r) = p₀ sqrt(1 − r²/a²)`,
//! `p₀ = 3P/(2π a²)`. The hemisphere (P1 tetrahedra, refined toward the pole by longest-edge
//! bisection) is pushed down at its flat top; the contact problem is solved by the chosen
//! solver (default: PDAS). Prints `a`, `p₀` and their errors over refinements and one JSON line
//! per run.
//!
//! Run: `cargo run --release --example hertz3d [pdas|au-pdas|uzawa-mprgp|dual-mprgp]`

use synovia_models::hertz::{hertz3d, Hertz3d};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "pdas".to_string());
    let solver = synovia::solvers::by_name(&name)?;
    let mut runs = Vec::new();
    for levels in [10, 12, 14] {
        runs.push(hertz3d(&Hertz3d { levels, ..Default::default() }, solver.as_ref())?);
    }
    println!(
        "{:>6} {:>10} {:>8} {:>7} {:>5} {:>10} {:>10} {:>10} {:>10} {:>8} {:>8}",
        "level", "h", "dofs", "active", "iter", "a", "a err", "p0 err", "L2 err", "solve s", "A s"
    );
    for r in &runs {
        println!(
            "{:>6} {:>10.3e} {:>8} {:>7} {:>5} {:>10.5} {:>10.2e} {:>10.2e} {:>10.2e} {:>8.3} {:>8.3}",
            r.level,
            r.h,
            r.dofs,
            r.active_nodes,
            r.iterations,
            r.a,
            r.a_rel_err(),
            r.p0_rel_err(),
            r.pressure_l2_err,
            r.solve_s,
            r.linear_solve_s
        );
    }
    let finest = runs.last().ok_or("no runs")?;
    assert!(finest.a_rel_err() < 0.05 && finest.p0_rel_err() < 0.05, "{finest:?}");
    for r in &runs {
        println!("{}", r.json());
    }
    Ok(())
}
