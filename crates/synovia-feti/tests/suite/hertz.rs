//! TFETI against the direct PDAS solution of the undecomposed problem (docs/model.md §11):
//! 2D Hertz (two cylinders, node-to-node) and 3D Hertz (hemisphere on a rigid flat), each
//! frictionless and with Tresca friction (slip bounds from the frictionless pressure,
//! incremental slip from it under a tangential motion of the top). Both solvers run behind the
//! same `StaticContact::solve` on the same load and rows; `U`, `Λ_n`, `Λ_t` must agree to 1e-6
//! relative (max norm), and the TFETI solution must satisfy the KKT conditions.

use synovia_contact::{ContactSolver, StaticContact, StaticContactResult};
use synovia_feti::{CoarseConstraint, DecompositionParams, Expansion, Tfeti, TfetiParams};
use synovia_models::hertz::{hertz2d_model, hertz3d_model, Hertz2d, Hertz3d};
use synovia_pdas::Pdas;

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0_f64, |m, x| m.max(x.abs())).max(1e-300);
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

/// Frictionless and Tresca solves by PDAS and TFETI; returns the errors `(U, Λn, Λt)` of the
/// Tresca case.
fn compare<const D: usize>(
    name: &str,
    model: &synovia_fem::model::Model<D>,
    pairs: &[synovia_contact::operators::ContactPair<D>],
    subdomains: usize,
    shift: f64,
    params: TfetiParams,
) -> [f64; 3] {
    let mut sc = StaticContact::new(model, pairs, Default::default()).expect("factorise");
    sc.set_nested_iteration(None);
    let pdas = Pdas::default();
    let tfeti = Tfeti::for_model(model, &DecompositionParams::default().with_subdomains(subdomains), params)
        .expect("decomposition");
    let dec = tfeti.decomposition();
    println!(
        "{name} ({:?}, {:?} expansion): {} subdomains, primal {}, equality rows {:?}, coarse {}",
        params.coarse,
        params.expansion,
        dec.n_subdomains(),
        dec.n_primal(),
        dec.n_equality(),
        dec.coarse_dim()
    );
    assert!(dec.n_subdomains() >= subdomains);
    let normal = sc.solve(model, 0.0, &pdas, None, None, None).expect("pdas frictionless");
    let gc = sc.geometry().slip_bounds_from_pressure(&normal.solution.lambda_n);
    let mut last = [0.0; 3];
    for (case, slip, t) in [("frictionless", None, 0.0), ("tresca", Some(gc.as_slice()), shift)] {
        let prev = slip.map(|_| normal.displacement.as_slice());
        let solve = |s: &dyn ContactSolver| -> StaticContactResult<D> {
            sc.solve(model, t, s, slip, prev, None)
                .unwrap_or_else(|e| panic!("{name} {case} {}: {e}", s.name()))
        };
        let direct = solve(&pdas);
        let feti = solve(&tfeti);
        let du = rel(&direct.solution.u, &feti.solution.u);
        let dn = rel(&direct.solution.lambda_n, &feti.solution.lambda_n);
        let dt = if slip.is_some() { rel(&direct.solution.lambda_t, &feti.solution.lambda_t) } else { 0.0 };
        let r = &feti.solution.report;
        println!(
            "{name} {case}: TFETI vs PDAS: U {du:.2e}, Λn {dn:.2e}, Λt {dt:.2e}; SMALBE {} outer, {} inner, {} F products; active {}, stick {}, slip {}",
            r.iterations, r.inner_iterations, r.linear_solves, r.active, r.stick, r.slip
        );
        println!("{name} {case}: TFETI KKT {:?}", feti.kkt);
        assert!(feti.kkt.satisfied(1e-8), "{name} {case}: KKT {:?}", feti.kkt);
        if slip.is_some() {
            assert!(r.stick > 0 && r.slip > 0, "{name}: needs stick and slip cells");
        }
        assert!(du <= 1e-6 && dn <= 1e-6 && dt <= 1e-6, "{name} {case}: {du:e} {dn:e} {dt:e}");
        last = [du, dn, dt];
    }
    last
}

#[test]
fn tfeti_equals_pdas_on_2d_hertz_with_friction() {
    let p = Hertz2d { levels: 6, e2: Some(1.0), push: 0.02, ..Default::default() };
    let (model, mut pairs) = hertz2d_model(&p).expect("model");
    pairs[0].friction = 0.3;
    compare("hertz2d", &model, &pairs, 8, 0.004, TfetiParams::default());
}

/// The coarse condition eliminated by the oblique projector (`CoarseConstraint::Projector`,
/// one MPRGP run, no SMALBE loop) gives the same solution as PDAS (and so as SMALBE).
#[test]
fn tfeti_projector_equals_pdas_on_2d_hertz_with_friction() {
    let p = Hertz2d { levels: 6, e2: Some(1.0), push: 0.02, ..Default::default() };
    let (model, mut pairs) = hertz2d_model(&p).expect("model");
    pairs[0].friction = 0.3;
    let params = TfetiParams::default().with_coarse(CoarseConstraint::Projector);
    compare("hertz2d", &model, &pairs, 8, 0.004, params);
}

#[test]
fn tfeti_equals_pdas_on_3d_hertz_with_friction() {
    let p = Hertz3d { n: 3, levels: 7, ..Default::default() };
    let (model, mut pairs) = hertz3d_model(&p).expect("model");
    pairs[0].friction = 0.3;
    compare("hertz3d", &model, &pairs, 8, 0.002, TfetiParams::default());
}

/// As the 2D projector test, in 3D (MPGP with discs).
#[test]
fn tfeti_projector_equals_pdas_on_3d_hertz_with_friction() {
    let p = Hertz3d { n: 3, levels: 7, ..Default::default() };
    let (model, mut pairs) = hertz3d_model(&p).expect("model");
    pairs[0].friction = 0.3;
    let params = TfetiParams::default().with_coarse(CoarseConstraint::Projector);
    compare("hertz3d", &model, &pairs, 8, 0.002, params);
}

/// The longer expansion steps of MPRGP/MPGP (`Expansion::ProjectedCg`,
/// `Expansion::Preconditioned`) with the projector: the same solution as PDAS in 2D and 3D,
/// with friction (and so the same as the fixed step, both within 1e-6 of PDAS).
#[test]
fn tfeti_projector_with_longer_expansion_steps_equals_pdas_on_hertz() {
    let p2 = Hertz2d { levels: 6, e2: Some(1.0), push: 0.02, ..Default::default() };
    let (model2, mut pairs2) = hertz2d_model(&p2).expect("model");
    pairs2[0].friction = 0.3;
    let p3 = Hertz3d { n: 3, levels: 7, ..Default::default() };
    let (model3, mut pairs3) = hertz3d_model(&p3).expect("model");
    pairs3[0].friction = 0.3;
    for expansion in [Expansion::ProjectedCg, Expansion::Preconditioned] {
        let params =
            TfetiParams::default().with_coarse(CoarseConstraint::Projector).with_expansion(expansion);
        compare("hertz2d", &model2, &pairs2, 8, 0.004, params);
        compare("hertz3d", &model3, &pairs3, 8, 0.002, params);
    }
}

/// SMALBE (the default coarse treatment) with the projected CG expansion step: same solution.
#[test]
fn tfeti_smalbe_with_projected_cg_expansion_equals_pdas_on_2d_hertz() {
    let p = Hertz2d { levels: 6, e2: Some(1.0), push: 0.02, ..Default::default() };
    let (model, mut pairs) = hertz2d_model(&p).expect("model");
    pairs[0].friction = 0.3;
    compare(
        "hertz2d",
        &model,
        &pairs,
        8,
        0.004,
        TfetiParams::default().with_expansion(Expansion::ProjectedCg),
    );
}
