//! # 2D Cattaneo–Mindlin partial slip
//!
//! Two identical cylinders (so normal and tangential problems decouple, Dundurs `β = 0`) are
//! pressed together, then sheared by a tangential displacement of the upper one's top with
//! Tresca friction `g_c = μ p` frozen from the normal state and slip measured from it (docs/model.md §3,
//! §9). For `Q/(μP) = 0.5` the centre sticks over `|x| ≤ c = a sqrt(1 − Q/(μP))` and the
//! tangential traction is
//! `q(x) = μ p₀ sqrt(1 − x²/a²) − (c/a) μ p₀ sqrt(1 − x²/c²)` (second term only for `|x| ≤ c`).
//! The example prints `c`, the traction error and the Coulomb check `|q| ≤ μ p` over
//! refinements, and one JSON line per run.
//!
//! Run: `cargo run --release --example cattaneo_mindlin [pdas|au-pdas|uzawa-mprgp|dual-mprgp]`

use synovia_models::hertz::{cattaneo_mindlin_2d, Hertz2d};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "pdas".to_string());
    let solver = synovia::solvers::by_name(&name)?;
    let mu = 0.3;
    let mut runs = Vec::new();
    for levels in [8, 10, 12] {
        let p = Hertz2d { levels, push: 0.02, ..Default::default() };
        runs.push(cattaneo_mindlin_2d(&p, mu, 0.5, solver.as_ref())?);
    }
    println!(
        "{:>6} {:>10} {:>8} {:>6} {:>7} {:>10} {:>10} {:>10} {:>12} {:>10} {:>8}",
        "level", "h", "dofs", "iter", "Q/μP", "c", "c exact", "c err", "q L2 err", "max|q|-μp", "solve s"
    );
    for r in &runs {
        println!(
            "{:>6} {:>10.3e} {:>8} {:>6} {:>7.4} {:>10.5} {:>10.5} {:>10.2e} {:>12.2e} {:>10.1e} {:>8.3}",
            r.level,
            r.h,
            r.dofs,
            r.iterations,
            r.q_ratio,
            r.c,
            r.c_exact,
            r.c_rel_err(),
            r.traction_l2_err,
            r.coulomb_excess,
            r.solve_s
        );
    }
    let finest = runs.last().ok_or("no runs")?;
    assert!(finest.c_rel_err() < 0.05 && finest.traction_l2_err < 0.05, "{finest:?}");
    for r in &runs {
        println!("{}", r.json());
    }
    Ok(())
}
