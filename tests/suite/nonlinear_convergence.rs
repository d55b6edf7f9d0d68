//! The finite-strain manufactured solution converges at the P1 rates: energy (`H¹` seminorm)
//! error `O(h)`, `L²` error `O(h²)` (docs/model.md §2.3, §8), with strains of tens of per cent.

use synovia_models::verification::{finite_strain_mms, rates, ConvergenceRow};

#[test]
fn neo_hookean_manufactured_solution_converges_at_p1_rates_in_2d_and_3d() {
    let rows2: Vec<ConvergenceRow> =
        [8, 16, 32].iter().map(|&n| finite_strain_mms::<2>(n).expect("2D solve").row).collect();
    let rows3: Vec<ConvergenceRow> =
        [4, 8].iter().map(|&n| finite_strain_mms::<3>(n).expect("3D solve").row).collect();
    for (dim, rows) in [(2, &rows2), (3, &rows3)] {
        let e = rates(rows, |r| r.energy_error);
        let l = rates(rows, |r| r.l2_error);
        let (e, l) = (e[e.len() - 1], l[l.len() - 1]);
        println!("{dim}D: energy rate {e:.3}, L2 rate {l:.3}");
        assert!(e > 0.95 && e < 1.1, "{dim}D energy rate {e}");
        assert!(l > 1.85 && l < 2.2, "{dim}D L2 rate {l}");
    }
    let big = finite_strain_mms::<2>(8).expect("2D solve");
    assert!(big.max_gradient > 0.3, "the manufactured field is a finite strain");
    assert!(big.residual < 1e-10);
}
