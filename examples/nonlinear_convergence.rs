//! # Finite-strain convergence study with a manufactured solution (docs/model.md §2.3, §8)
//!
//! A compressible neo-Hookean block in total Lagrangian kinematics with the exact displacement
//! `u = 2 · SineField::standard()` (displacement gradients up to ≈ 0.3, i.e. strains of tens of
//! per cent) and the body force `−Div P(F(u))` derived from it
//! (`synovia_models::verification::finite_strain_mms`), solved by the Newton iteration of
//! `synovia::nonlinear` on successive meshes. P1 elements converge with rate 1 in the energy
//! (`H¹`-seminorm) error and rate 2 in `L²`; the example measures both in 2D (plane strain) and
//! 3D and prints one JSON line at the end.
//!
//! Run: `cargo run --release --example nonlinear_convergence`

use synovia_models::verification::{finite_strain_mms, fitted_rate, rates, ConvergenceRow, FiniteStrainRow};

fn table(dim: usize, rows: &[FiniteStrainRow]) -> Vec<ConvergenceRow> {
    let plain: Vec<ConvergenceRow> = rows.iter().map(|r| r.row).collect();
    println!("\n{dim}D neo-Hookean manufactured solution (finite strain)");
    println!(
        "{:>4} {:>9} {:>8} {:>11} {:>6} {:>11} {:>6} {:>7} {:>8} {:>9} {:>7}",
        "n", "h", "dofs", "H1 err", "rate", "L2 err", "rate", "|grad u|", "Newton", "residual", "time s"
    );
    let re = rates(&plain, |r| r.energy_error);
    let rl = rates(&plain, |r| r.l2_error);
    for (i, r) in rows.iter().enumerate() {
        let (a, b) = if i == 0 {
            ("-".to_string(), "-".to_string())
        } else {
            (format!("{:.3}", re[i - 1]), format!("{:.3}", rl[i - 1]))
        };
        println!(
            "{:>4} {:>9.3e} {:>8} {:>11.4e} {:>6} {:>11.4e} {:>6} {:>7.3} {:>8} {:>9.1e} {:>7.2}",
            r.row.n,
            r.row.h,
            r.row.dofs,
            r.row.energy_error,
            a,
            r.row.l2_error,
            b,
            r.max_gradient,
            r.newton_iterations,
            r.residual,
            r.row.solve_s
        );
    }
    plain
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // ## Step 1: 2D plane strain, five meshes
    let rows2: Vec<FiniteStrainRow> =
        [8, 16, 32, 64, 128].iter().map(|&n| finite_strain_mms::<2>(n)).collect::<Result<_, _>>()?;
    let p2 = table(2, &rows2);
    // ## Step 2: 3D, four meshes
    let rows3: Vec<FiniteStrainRow> =
        [4, 8, 12, 16].iter().map(|&n| finite_strain_mms::<3>(n)).collect::<Result<_, _>>()?;
    let p3 = table(3, &rows3);
    // ## Step 3: rates on the finest pair and fitted over all meshes
    let last = |v: Vec<f64>| v.last().copied().unwrap_or(f64::NAN);
    let e2 = last(rates(&p2, |r| r.energy_error));
    let l2 = last(rates(&p2, |r| r.l2_error));
    let e3 = last(rates(&p3, |r| r.energy_error));
    let l3 = last(rates(&p3, |r| r.l2_error));
    println!(
        "\nfitted rates: 2D energy {:.3}, L2 {:.3}; 3D energy {:.3}, L2 {:.3}",
        fitted_rate(&p2, |r| r.energy_error),
        fitted_rate(&p2, |r| r.l2_error),
        fitted_rate(&p3, |r| r.energy_error),
        fitted_rate(&p3, |r| r.l2_error)
    );
    let f2 = rows2.last().copied().ok_or("no rows")?;
    let f3 = rows3.last().copied().ok_or("no rows")?;
    let newton = rows2.iter().chain(&rows3).map(|r| r.newton_iterations).max().unwrap_or(0);
    println!(
        "{{\"problem\":\"nonlinear_convergence\",\"law\":\"neo-Hookean\",\"kinematics\":\"finite\",\"energy_rate_2d\":{e2:.4},\"l2_rate_2d\":{l2:.4},\"energy_rate_3d\":{e3:.4},\"l2_rate_3d\":{l3:.4},\"max_displacement_gradient\":{:.3},\"dofs_2d\":{},\"dofs_3d\":{},\"energy_error_2d\":{:.4e},\"l2_error_2d\":{:.4e},\"energy_error_3d\":{:.4e},\"l2_error_3d\":{:.4e},\"max_newton_iterations_last_level\":{newton},\"time_2d_s\":{:.3},\"time_3d_s\":{:.3}}}",
        f2.max_gradient.max(f3.max_gradient),
        f2.row.dofs,
        f3.row.dofs,
        f2.row.energy_error,
        f2.row.l2_error,
        f3.row.energy_error,
        f3.row.l2_error,
        f2.row.solve_s,
        f3.row.solve_s
    );
    Ok(())
}
