//! A rigid partner's force-controlled coordinate solved with the contact conditions
//! (`RigidBorder`, docs/model.md §10): the bordered PDAS solve equals the plain solve at the
//! offsets `g + σ ζ` it finds, meets `σᵀ ν = target`, and is refused where it cannot be solved.

use crate::common;

use common::{assert_kkt, assert_same, frictionless, tresca_2d, tresca_3d};
use synovia_contact::testing::OwnedProblem;
use synovia_contact::{ContactError, ContactProblem, ContactSolver, RigidBorder, SolveContext};
use synovia_pdas::{AuPdas, Pdas};

/// `σ`: the foundation translated along the normal (every gap grows by `ζ`), and in the
/// tangential rows a drift of the slip origin proportional to the row's scale (`‖B_Ht row‖`).
fn translation_border(p: &ContactProblem<'_>, tangential: f64, target: f64) -> RigidBorder {
    let mut sensitivity = vec![1.0; p.n_normal()];
    if let Some(f) = p.friction {
        for r in 0..f.rows.nrows() {
            let norm: f64 = f.rows.row(r).map(|(_, v)| v * v).sum::<f64>().sqrt();
            sensitivity.push(if r % f.components == 0 { tangential * norm } else { 0.0 });
        }
    }
    RigidBorder::single(sensitivity, target)
}

/// Solves the plain problem, then the bordered one whose target is `fraction` of the plain
/// solution's `σᵀν`; checks the bordered solution against the plain solve at `g + σ ζ`.
fn bordered_equals_shifted(owned: &OwnedProblem, tangential: f64, fraction: f64, label: &str) -> f64 {
    let plain = owned.problem();
    let pdas = Pdas::default();
    let base = pdas.solve(&plain, &SolveContext::new()).expect("plain solve");
    assert!(base.report.border_values.is_empty());
    let probe = translation_border(&plain, tangential, 0.0);
    let mut nu: Vec<f64> = base.lambda_n.iter().zip(&plain.normal.weights).map(|(l, k)| l * k).collect();
    nu.extend_from_slice(&base.lambda_t);
    let q0: f64 = probe.columns[0].iter().zip(&nu).map(|(s, v)| s * v).sum();
    assert!(q0 > 0.0, "{label}: the plain solution presses the foundation ({q0})");
    let border = RigidBorder { targets: vec![fraction * q0], ..probe };
    let bordered_problem = ContactProblem { border: Some(&border), ..plain };
    let sol = pdas.solve(&bordered_problem, &SolveContext::new()).expect("bordered solve");
    assert_eq!(sol.report.border_values.len(), 1);
    let zeta = sol.report.border_values[0];
    // σᵀ ν = target
    let mut nu: Vec<f64> = sol.lambda_n.iter().zip(&plain.normal.weights).map(|(l, k)| l * k).collect();
    nu.extend_from_slice(&sol.lambda_t);
    let q: f64 = border.columns[0].iter().zip(&nu).map(|(s, v)| s * v).sum();
    let target = border.targets[0];
    println!(
        "{label}: ζ = {zeta:.6e}, σᵀν = {q:.12e}, target {target:.12e}, {} iterations",
        sol.report.iterations
    );
    assert!((q - target).abs() <= 1e-10 * target.abs(), "{label}: σᵀν {q} ≠ {target}");
    // the plain problem at the offsets g + σ ζ has the same solution, and it satisfies its KKT
    let (normal, friction) = bordered_problem.shifted_constraints(&[zeta]).expect("shifted");
    let shifted = ContactProblem { normal: &normal, friction: friction.as_ref(), border: None, ..plain };
    assert_kkt(&shifted, &sol, label);
    let again = pdas.solve(&shifted, &SolveContext::new()).expect("shifted solve");
    assert_same(&sol, &again, 1e-9, label);
    zeta
}

#[test]
fn frictionless_bordered_solve_equals_the_plain_solve_at_its_offset() {
    let owned = frictionless(16).build::<2>().expect("2D frictionless");
    // less force: the foundation moves away (ζ > 0); more force: it moves in
    let away = bordered_equals_shifted(&owned, 0.0, 0.6, "2D frictionless, 60 %");
    let into = bordered_equals_shifted(&owned, 0.0, 1.5, "2D frictionless, 150 %");
    assert!(away > 0.0 && into < 0.0, "ζ {away} (60 %), {into} (150 %)");
    let owned3 = frictionless(6).build::<3>().expect("3D frictionless");
    assert!(bordered_equals_shifted(&owned3, 0.0, 0.5, "3D frictionless, 50 %") > 0.0);
}

#[test]
fn tresca_bordered_solve_equals_the_plain_solve_at_its_offset() {
    bordered_equals_shifted(&tresca_2d(), 0.3, 0.8, "2D Tresca, 80 %");
    bordered_equals_shifted(&tresca_2d(), -0.2, 1.2, "2D Tresca, 120 %");
    bordered_equals_shifted(&tresca_3d(), 0.3, 0.7, "3D Tresca, 70 %");
}

#[test]
fn a_border_that_nothing_holds_or_that_does_not_fit_is_refused() {
    let owned = frictionless(8).build::<2>().expect("2D");
    let p = owned.problem();
    // σ = 0: no row moves with the coordinate, so nothing balances the target
    let zero = RigidBorder::single(vec![0.0; p.n_rows()], 1.0);
    let r = Pdas::default().solve(&ContactProblem { border: Some(&zero), ..p }, &SolveContext::new());
    assert!(matches!(r, Err(ContactError::Singular { .. })), "{r:?}");
    // a wrong length
    let short = RigidBorder::single(vec![1.0; p.n_rows() - 1], 1.0);
    let r = Pdas::default().solve(&ContactProblem { border: Some(&short), ..p }, &SolveContext::new());
    assert!(matches!(r, Err(ContactError::InvalidParameter(ref m)) if m.contains("sensitivities")), "{r:?}");
    // a solver without the border refuses it instead of solving another problem
    let ok = RigidBorder::single(vec![1.0; p.n_rows()], 1.0);
    let r = AuPdas::default().solve(&ContactProblem { border: Some(&ok), ..p }, &SolveContext::new());
    assert!(
        matches!(r, Err(ContactError::InvalidParameter(ref m)) if m.contains("force-controlled")),
        "{r:?}"
    );
    assert!(Pdas::default().solves_border() && !AuPdas::default().solves_border());
}

/// Two coordinates: a translation of the foundation (every gap) and a tilt (gaps growing
/// linearly along the rows), with targets off the plain solution's: both equilibria met and the
/// plain solve at `g + σ₁ ζ₁ + σ₂ ζ₂` equal to the bordered one.
#[test]
fn two_coordinates_are_solved_together() {
    for (owned, label) in [
        (frictionless(16).build::<2>().expect("2D"), "2D frictionless"),
        (tresca_2d(), "2D Tresca"),
        (tresca_3d(), "3D Tresca"),
    ] {
        let plain = owned.problem();
        let pdas = Pdas::default();
        let base = pdas.solve(&plain, &SolveContext::new()).expect("plain solve");
        let (m, rows) = (plain.n_normal(), plain.n_rows());
        let lift: Vec<f64> = (0..rows).map(|r| if r < m { 1.0 } else { 0.0 }).collect();
        let tilt: Vec<f64> = (0..rows).map(|r| if r < m { r as f64 / m as f64 - 0.5 } else { 0.0 }).collect();
        let mut nu: Vec<f64> = base.lambda_n.iter().zip(&plain.normal.weights).map(|(l, k)| l * k).collect();
        nu.extend_from_slice(&base.lambda_t);
        let dot = |c: &[f64], v: &[f64]| c.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let (q1, q2) = (dot(&lift, &nu), dot(&tilt, &nu));
        let border = RigidBorder { columns: vec![lift, tilt], targets: vec![0.8 * q1, q2 + 0.02 * q1] };
        let bordered = ContactProblem { border: Some(&border), ..plain };
        let sol = pdas.solve(&bordered, &SolveContext::new()).expect("bordered solve");
        let zeta = sol.report.border_values.clone();
        assert_eq!(zeta.len(), 2);
        let mut nu: Vec<f64> = sol.lambda_n.iter().zip(&plain.normal.weights).map(|(l, k)| l * k).collect();
        nu.extend_from_slice(&sol.lambda_t);
        for (c, t) in border.columns.iter().zip(&border.targets) {
            let q = dot(c, &nu);
            assert!((q - t).abs() <= 1e-10 * q1.abs(), "{label}: σᵀν {q} ≠ {t}");
        }
        println!("{label}: ζ = {zeta:?}, {} iterations", sol.report.iterations);
        let (normal, friction) = bordered.shifted_constraints(&zeta).expect("shifted");
        let shifted = ContactProblem { normal: &normal, friction: friction.as_ref(), border: None, ..plain };
        assert_kkt(&shifted, &sol, label);
        let again = pdas.solve(&shifted, &SolveContext::new()).expect("shifted solve");
        assert_same(&sol, &again, 1e-9, label);
    }
}
