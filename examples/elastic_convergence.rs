//! # Elastic convergence study with a manufactured solution (docs/model.md §8)
//!
//! Two bodies bonded along `x = ½` — one isotropic, one fully anisotropic — are loaded so that
//! `u_k = a_k sin(b_k · x + c_k)` is the exact solution (see `synovia_models::verification`). P1
//! elements converge with rate 1 in the energy norm and rate 2 in `L²`; this example measures
//! both in 2D and 3D over successive refinements and prints one JSON line at the end.
//!
//! Run: `cargo run --release --example elastic_convergence`

use synovia_models::verification::{bonded_mms, fitted_rate, rates, ConvergenceRow};

fn table(dim: usize, rows: &[ConvergenceRow]) {
    println!("\n{dim}D bonded iso/aniso manufactured solution");
    println!(
        "{:>5} {:>10} {:>9} {:>12} {:>7} {:>12} {:>7} {:>9}",
        "n", "h", "dofs", "energy err", "rate", "L2 err", "rate", "time s"
    );
    let re = rates(rows, |r| r.energy_error);
    let rl = rates(rows, |r| r.l2_error);
    for (i, r) in rows.iter().enumerate() {
        let (a, b) = if i == 0 {
            (String::from("-"), String::from("-"))
        } else {
            (format!("{:.3}", re[i - 1]), format!("{:.3}", rl[i - 1]))
        };
        println!(
            "{:>5} {:>10.4e} {:>9} {:>12.4e} {:>7} {:>12.4e} {:>7} {:>9.3}",
            r.n, r.h, r.dofs, r.energy_error, a, r.l2_error, b, r.solve_s
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // ## Step 1: 2D, four refinements
    let rows2: Vec<ConvergenceRow> =
        [8, 16, 32, 64, 128].iter().map(|&n| bonded_mms::<2>(n)).collect::<Result<_, _>>()?;
    table(2, &rows2);
    // ## Step 2: 3D, four refinements
    let rows3: Vec<ConvergenceRow> =
        [4, 8, 12, 16, 24].iter().map(|&n| bonded_mms::<3>(n)).collect::<Result<_, _>>()?;
    table(3, &rows3);
    // ## Step 3: rates on the finest pair and the fit over all meshes
    let last = |v: Vec<f64>| v.last().copied().unwrap_or(f64::NAN);
    let e2 = last(rates(&rows2, |r| r.energy_error));
    let l2 = last(rates(&rows2, |r| r.l2_error));
    let e3 = last(rates(&rows3, |r| r.energy_error));
    let l3 = last(rates(&rows3, |r| r.l2_error));
    println!(
        "\nfitted rates: 2D energy {:.3}, L2 {:.3}; 3D energy {:.3}, L2 {:.3}",
        fitted_rate(&rows2, |r| r.energy_error),
        fitted_rate(&rows2, |r| r.l2_error),
        fitted_rate(&rows3, |r| r.energy_error),
        fitted_rate(&rows3, |r| r.l2_error)
    );
    assert!(e2 >= 0.95 && l2 >= 1.9 && e3 >= 0.95 && l3 >= 1.9, "convergence rates below the P1 theory");
    let f2 = rows2.last().copied().ok_or("no rows")?;
    let f3 = rows3.last().copied().ok_or("no rows")?;
    println!(
        "{{\"problem\":\"elastic_convergence\",\"energy_rate_2d\":{e2:.4},\"l2_rate_2d\":{l2:.4},\"energy_rate_3d\":{e3:.4},\"l2_rate_3d\":{l3:.4},\"dofs_2d\":{},\"dofs_3d\":{},\"energy_error_2d\":{:.4e},\"l2_error_2d\":{:.4e},\"energy_error_3d\":{:.4e},\"l2_error_3d\":{:.4e},\"time_2d_s\":{:.3},\"time_3d_s\":{:.3}}}",
        f2.dofs, f3.dofs, f2.energy_error, f2.l2_error, f3.energy_error, f3.l2_error, f2.solve_s, f3.solve_s
    );
    Ok(())
}
