//! Coulomb friction on bodies held by friction alone (issue 15): the quasi-static levels fall
//! back to the Coulomb fixed point when the slip bound frozen from the previous level cannot hold
//! the new load, and static solves with friction start from the normal problem
//! (docs/model.md §7.1). References: the exact Coulomb limit `Q = μ P` of a block pressed on a
//! foundation, and the KKT conditions of every solution. Numbers printed with `--nocapture` are
//! the ones in docs/model.md §7.1.

use synovia::prelude::*;
use synovia::time::TimeError;

const E: f64 = 1.0;
const NU: f64 = 0.3;
const P0: f64 = 0.01;
const MU: f64 = 0.3;

/// A floating block `[0, 1] × [0, ½]` (no Dirichlet data) on an elastic foundation
/// `[0, 1] × [−½, 0]` clamped at its bottom (node-to-node, friction `μ`), with the normal
/// traction `−P0 (1 + growth t)` and the tangential traction `q(t)` on its top (unit width, so
/// tractions are forces).
fn block_on_foundation(growth: f64, q: impl Fn(f64) -> f64 + Send + Sync + 'static) -> JointModel<2> {
    let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 12, 6, Grading::Uniform, Grading::Uniform).expect("mesh");
    let base = rectangle(0.0, 1.0, -0.5, 0.0, 12, 6, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let block = joint.add_body("block", mesh, plane_strain(E, NU).expect("m")).expect("body");
    let lower = joint.add_body("foundation", base, plane_strain(2.0 * E, NU).expect("m")).expect("body");
    joint.clamp(lower, "bottom").expect("clamp");
    joint
        .traction_field(block, "top", move |_, _, t| Vector::<2>::new(q(t), -P0 * (1.0 + growth * t)))
        .expect("traction");
    joint.contact_bodies("block-foundation", block, "bottom", lower, "top", MU).expect("pair");
    joint
}

/// The normal load grows by 10 % while the tangential load ramps: `P(t) = P0 (1 + t/10)`,
/// `Q(t) = s μ P(1) t`, so `Q/(μP)` increases with `t` and reaches `s` at `t = 1`. Gross sliding
/// starts at the last level exactly when `s = 1`.
fn ramp(s: f64) -> JointModel<2> {
    block_on_foundation(0.1, move |t| s * MU * P0 * 1.1 * t)
}

fn levels(n: usize) -> Vec<f64> {
    (0..=n).map(|i| i as f64 / n as f64).collect()
}

#[test]
fn force_ramp_onset_of_sliding_is_the_coulomb_value_for_any_number_of_steps() {
    for n in [4usize, 8, 16] {
        let times = levels(n);
        // bisection on s for the largest ramp that the run holds to t = 1
        let (mut lo, mut hi) = (0.9, 1.1);
        for _ in 0..14 {
            let s = 0.5 * (lo + hi);
            match ramp(s).run_quasistatic(&times) {
                Ok(_) => lo = s,
                Err(JointError::Time(TimeError::Slides { step, .. })) => {
                    assert_eq!(step, n, "n = {n}, s = {s}: slides before the last level");
                    hi = s;
                }
                Err(e) => panic!("n = {n}, s = {s}: expected success or TimeError::Slides, got {e}"),
            }
        }
        let onset = 0.5 * (lo + hi);
        println!(
            "force ramp, {n} steps: onset of gross sliding at Q/(μP) = {onset:.6} (error {:+.2e})",
            onset - 1.0
        );
        // the frozen bound alone stopped at 1 − 0.1/(1.1 n): −2.3 % with 4 steps
        assert!((onset - 1.0).abs() < 1e-4, "{n} steps: onset {onset}");

        // just below the limit: held, equilibrium exact, KKT satisfied
        let run = ramp(0.999).run_quasistatic(&times).expect("held below μP");
        let last = &run.records[n].pairs[0];
        let (q, p) = (0.999 * MU * P0 * 1.1, P0 * 1.1);
        assert!((last.tangential_force.abs() - q).abs() < 1e-8 * p, "{last:?}");
        assert!((last.normal_force - p).abs() < 1e-8 * p, "{last:?}");
        let kkt = run.contact.as_ref().expect("contact").kkt;
        assert!(kkt.satisfied(1e-7), "{kkt:?}");
        // just above: the typed error with the forces
        match ramp(1.001).run_quasistatic(&times) {
            Err(JointError::Time(TimeError::Slides { tangential, capacity, normal, bodies, .. })) => {
                assert_eq!(bodies, vec!["block".to_string()]);
                assert!((tangential - 1.001 * MU * p).abs() < 1e-6 * p, "{tangential}");
                assert!((capacity - MU * normal).abs() < 1e-6 * p && (normal - p).abs() < 1e-6 * p);
            }
            other => panic!("{n} steps: expected TimeError::Slides, got {other:?}"),
        }
    }
}

/// A floating block pressed on the foundation with a constant tangential force `r μ P` from the
/// start (static solve): held (friction balances the load, KKT) for `r < 1`, the typed error
/// with the forces in its message for `r > 1`.
#[test]
fn static_solve_of_a_block_held_by_friction() {
    for r in [0.42, 0.9, 1.1] {
        let q = r * MU * P0;
        let joint = block_on_foundation(0.0, move |_| q);
        let out = joint.run_static(0.0);
        // the same through a prepared session
        let mut session = joint.prepare().expect("session");
        let session_out = session.solve_static(0.0);
        if r < 1.0 {
            let run = out.expect("held by friction");
            let res = run.contact.as_ref().expect("contact");
            let rec = &run.records[0].pairs[0];
            assert!((rec.tangential_force.abs() - q).abs() < 1e-9 * P0, "{rec:?}");
            assert!((rec.normal_force - P0).abs() < 1e-9 * P0, "{rec:?}");
            assert!(res.kkt.satisfied(1e-8), "{:?}", res.kkt);
            // friction acts (cells built on the pressed nodes) and some of them stick
            let cells = res.cell_node.len();
            let comps = 1;
            let stick = (0..cells).filter(|&c| res.solution.lambda_t[c * comps].abs() < 1.0 - 1e-6).count();
            assert!(cells > 0 && stick > 0, "{cells} cells, {stick} stick");
            // Coulomb: ‖λ_t‖ ≤ μ λ_n at every node, with the bound taken from the solution
            for (c, (&node, &g)) in res.cell_node.iter().zip(&res.slip_bound).enumerate() {
                let ln = res.solution.lambda_n[node];
                assert!((g - MU * ln).abs() <= 1e-7 * MU * P0, "cell {c}: g {g} vs μλ_n {}", MU * ln);
            }
            let s = session_out.expect("session: held by friction");
            assert!(s.kkt < 1e-8, "{s:?}");
            println!(
                "static, Q/(μP) = {r}: held, T = {:.6e} (load {q:.6e}), N = {:.6e}, {stick}/{cells} cells stick, KKT {:.2e}",
                rec.tangential_force,
                rec.normal_force,
                res.kkt.max()
            );
        } else {
            for (what, out) in [("run_static", out.map(|_| ())), ("session", session_out.map(|_| ()))] {
                let err = out.expect_err("above μP the block slides");
                let msg = err.to_string();
                match &err {
                    JointError::Time(TimeError::Slides { tangential, capacity, .. }) => {
                        assert!((tangential - q).abs() < 1e-6 * q, "{tangential} vs {q}");
                        assert!((capacity - MU * P0).abs() < 1e-6 * P0, "{capacity}");
                    }
                    other => panic!("{what}: expected TimeError::Slides, got {other:?}"),
                }
                assert!(msg.contains("exceeds the friction capacity μ·P") && msg.contains("slides"), "{msg}");
                assert!(msg.contains(&format!("{q:.6e} N")), "{msg}");
                assert!(!msg.contains("add Dirichlet"), "{msg}");
                println!("static, Q/(μP) = {r} ({what}): {msg}");
            }
        }
    }
}
