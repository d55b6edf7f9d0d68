//! Manufactured-solution convergence of the bonded two-body (isotropic + anisotropic) elastic
//! problem over four refinements in 2D and 3D (docs/model.md §8): energy-norm rate ≥ 0.95, L² rate ≥ 1.9
//! between every pair of consecutive meshes.

use synovia_models::verification::{bonded_mms, rates, ConvergenceRow};

fn check(dim: usize, rows: &[ConvergenceRow]) {
    let re = rates(rows, |r| r.energy_error);
    let rl = rates(rows, |r| r.l2_error);
    for (i, (e, l)) in re.iter().zip(&rl).enumerate() {
        assert!(*e >= 0.95, "{dim}D energy rate {e:.3} between meshes {i} and {}", i + 1);
        assert!(*l >= 1.9, "{dim}D L2 rate {l:.3} between meshes {i} and {}", i + 1);
    }
    // errors must actually be small on the finest mesh (not just decreasing)
    let last = rows.last().expect("rows");
    assert!(last.energy_error < 0.1 && last.l2_error < 0.01, "{dim}D finest errors {last:?}");
}

#[test]
fn bonded_anisotropic_2d_converges_at_p1_rates() {
    let rows: Vec<ConvergenceRow> =
        [8, 16, 32, 64, 128].iter().map(|&n| bonded_mms::<2>(n).expect("solve")).collect();
    check(2, &rows);
}

#[test]
fn bonded_anisotropic_3d_converges_at_p1_rates() {
    let rows: Vec<ConvergenceRow> =
        [4, 8, 12, 16, 20].iter().map(|&n| bonded_mms::<3>(n).expect("solve")).collect();
    check(3, &rows);
}
