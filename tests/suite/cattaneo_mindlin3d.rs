//! 3D partial slip against Cattaneo–Mindlin (issue 15): two identical elastic hemispheres
//! (Dundurs `β = 0`, `ν = 0`, contact radius `a ≈ 0.05 R`), pressed together and sheared to
//! `Q/(μP) = 0.3, 0.6, 0.9`; the stick radius of the moments of the computed stick deficit
//! `μ p − |q|` must approach `c = a (1 − Q/(μP))^{1/3}` (`a` the Hertz radius of the computed
//! force) as the mesh is refined. The coarse two of the three refinements of
//! `examples/cattaneo_mindlin3d.rs` (levels 15 and 17; the table in docs/contact.md); the bounds
//! are the measured errors with a margin.

use synovia_models::hertz::{cattaneo_mindlin_3d, Hertz3d};

#[test]
fn stick_radius_converges_to_cattaneo_mindlin_in_3d() {
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let ratios = [0.3, 0.6, 0.9];
    let runs: Vec<_> = [15, 17]
        .iter()
        .map(|&levels| {
            let p = Hertz3d { levels, push: 0.005, refine_radius: 0.075, nu: 0.0, ..Default::default() };
            cattaneo_mindlin_3d(&p, 0.3, &ratios, solver.as_ref()).expect("solve")
        })
        .collect();
    let (coarse, fine) = (&runs[0], &runs[1]);
    // refined: measured h 5.36e-3 → 3.79e-3, nodes in contact 137 → 293
    assert!(fine[0].h < 0.75 * coarse[0].h, "refined: h {} → {}", coarse[0].h, fine[0].h);
    assert!(
        fine[0].active_nodes as f64 > 1.8 * coarse[0].active_nodes as f64,
        "nodes in contact {} → {}",
        coarse[0].active_nodes,
        fine[0].active_nodes
    );
    // measured on the development machine: coarse 1.5e-2, 2.9e-2, 4.8e-2; fine 3.6e-3, 8.8e-3, 1.9e-2
    let bounds = [6.0e-3, 1.3e-2, 2.6e-2];
    for (k, &target) in ratios.iter().enumerate() {
        let (c, f) = (&coarse[k], &fine[k]);
        println!(
            "Q/μP = {:.4}: h {:.3e} → {:.3e}, c err {:.2e} → {:.2e} (c {:.5} / {:.5}, exact {:.5} / {:.5}; \
             fit {:.5} / {:.5}), KKT {:.1e}",
            f.q_ratio,
            c.h,
            f.h,
            c.c_rel_err(),
            f.c_rel_err(),
            c.c,
            f.c,
            c.c_exact,
            f.c_exact,
            c.c_fit,
            f.c_fit,
            f.kkt
        );
        for r in [c, f] {
            assert!((r.q_ratio - target).abs() < 5e-3 * target, "Q/μP {} for {target}", r.q_ratio);
            assert!(r.kkt < 1e-8, "KKT {}", r.kkt);
            // Coulomb: |q| ≤ μ p at every node
            assert!(r.coulomb_excess < 1e-10 * r.p0_exact, "excess {}", r.coulomb_excess);
            // the exact stick radius uses the measured Q/(μP) and the Hertz radius of the measured force
            let a_hertz = (3.0 * r.force * 0.5 / (4.0 * 0.5)).cbrt();
            assert!((r.c_exact - a_hertz * (1.0 - r.q_ratio).cbrt()).abs() < 1e-12, "{r:?}");
        }
        assert!(
            f.c_rel_err() < c.c_rel_err(),
            "Q/μP = {target}: error does not decrease: {} → {}",
            c.c_rel_err(),
            f.c_rel_err()
        );
        assert!(f.c_rel_err() < bounds[k], "Q/μP = {target}: c error {} above {}", f.c_rel_err(), bounds[k]);
        // the fit of the nodal traction ratio (reported beside c) stays within 2 % (measured ≤ 1.1e-2)
        assert!(
            (f.c_fit - f.c_exact).abs() < 2e-2 * f.c_exact,
            "Q/μP = {target}: fitted stick radius {} vs {}",
            f.c_fit,
            f.c_exact
        );
        assert!(
            f.traction_l2_err < c.traction_l2_err,
            "traction error {} → {}",
            c.traction_l2_err,
            f.traction_l2_err
        );
    }
}
