//! Friction laws `F_c(|[u'_t]|)` in quasi-static runs (docs/model.md §3, §7): a block pressed onto a
//! rigid flat and dragged at a prescribed rate `v` slides with the friction force
//! `F_c(v) · N` (exact reference: in steady sliding every contact node slips at `v` and carries
//! the traction `F_c(v) λ_n`); the constant law reproduces the default (pair coefficient)
//! results bit for bit; a law on a frictionless pair gives it friction.
#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use synovia_contact::operators::{ContactPair, PlaneObstacle};
use synovia_contact::{ConstantFriction, ContactParams, ExponentialFriction, FrictionLaw};
use synovia_fem::{ElasticParams, Model};
use synovia_material::plane_strain;
use synovia_mesh::generators::{rectangle, Grading};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::BoundaryKind;
use synovia_pdas::Pdas;
use synovia_time::quasistatic::{QuasiStaticParams, QuasiStaticStepper};
use synovia_time::results::StepRecord;

fn pdas() -> Pdas {
    Pdas::new(ContactParams::default().with_tolerance(1e-13).with_max_iterations(200))
}

/// Block `[0, 1] × [0, 0.25]` on the rigid flat `y = 0` (pair `"floor"`, coefficient `mu`), its
/// top prescribed to `(v t, −δ)`.
fn dragged_block(v: Real, delta: Real, mu: Real) -> (Model<2>, Vec<ContactPair<2>>) {
    let mut mesh = rectangle(0.0, 1.0, 0.0, 0.25, 8, 2, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("top", BoundaryKind::Prescribed).unwrap();
    mesh.set_part_kind("bottom", BoundaryKind::Contact).unwrap();
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3).unwrap())).unwrap();
    model.prescribe(b, "top", move |_, t| Vector::<2>::new(v * t, -delta)).unwrap();
    let plane = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0)).unwrap();
    let pairs = vec![ContactPair::rigid("floor", b, "bottom", Arc::new(plane)).with_friction(mu)];
    (model, pairs)
}

fn run(
    model: &Model<2>,
    pairs: &[ContactPair<2>],
    params: QuasiStaticParams,
    law: Option<Arc<dyn FrictionLaw>>,
    levels: usize,
) -> (Vec<StepRecord>, QuasiStaticStepper<2>) {
    let mut st = QuasiStaticStepper::new(model, pairs, ElasticParams::default(), params).unwrap();
    if let Some(law) = law {
        st.set_friction_law("floor", law).unwrap();
    }
    let times: Vec<Real> = (0..levels).map(|i| i as Real).collect();
    let records = st
        .run(model, &times, &pdas(), |rec, res| {
            assert!(res.kkt.satisfied(1e-9), "level {}: KKT {:?}", rec.step, res.kkt);
            Ok(())
        })
        .unwrap();
    (records, st)
}

#[test]
fn slip_rate_dependent_law_gives_the_friction_force_of_the_sliding_speed() {
    let (v, delta) = (0.1, 1e-3);
    let law =
        ExponentialFriction { static_coefficient: 0.5, kinetic_coefficient: 0.2, characteristic_speed: 0.05 };
    let expected = law.coefficient(v);
    assert!((expected - (0.2 + 0.3 * (-2.0_f64).exp())).abs() < 1e-15);
    let (model, pairs) = dragged_block(v, delta, 0.0);
    for coulomb in [true, false] {
        let params =
            QuasiStaticParams::default().with_coulomb_fixed_point(coulomb).with_fixed_point_tolerance(1e-13);
        let (records, st) = run(&model, &pairs, params, Some(Arc::new(law)), 16);
        let last = records.last().unwrap();
        let p = &last.pairs[0];
        let ratio = p.tangential_force / p.normal_force;
        eprintln!(
            "coulomb {coulomb}: T/N = {ratio:.12}, F_c(v) = {expected:.12}, N = {:.6e}",
            p.normal_force
        );
        assert!(p.normal_force > 0.0 && p.slip_area > 0.0 && p.stick_area == 0.0);
        assert!((ratio - expected).abs() <= 1e-8, "coulomb {coulomb}: T/N = {ratio}, F_c(v) = {expected}");
        // the slip rate of every loaded node is the drag speed
        let res = st.last_result().unwrap();
        for (r, (&l, &rate)) in res.solution.lambda_n.iter().zip(st.slip_rate()).enumerate() {
            if l > 0.0 {
                assert!((rate - v).abs() <= 1e-8 * v, "node {r}: slip rate {rate}, drag speed {v}");
            }
        }
        // the friction force resists the drag (−x on the block)
        assert!(p.force[0] < 0.0);
        // and the law matters: F_c(0) and F_c(∞) are far from F_c(v)
        assert!((ratio - 0.5).abs() > 0.1 && (ratio - 0.2).abs() > 0.02);
    }
}

#[test]
fn constant_law_reproduces_the_pair_coefficient_bit_for_bit() {
    let mu = 0.3;
    let (model, pairs) = dragged_block(0.002, 2e-3, mu);
    for coulomb in [false, true] {
        let params = QuasiStaticParams::default().with_coulomb_fixed_point(coulomb);
        let (plain, a) = run(&model, &pairs, params, None, 6);
        let (with_law, b) = run(&model, &pairs, params, Some(Arc::new(ConstantFriction(mu))), 6);
        // partial slip then sliding: friction is active
        assert!(plain.iter().skip(1).any(|r| r.pairs[0].tangential_force > 0.0));
        for (x, y) in plain.iter().zip(&with_law) {
            assert_eq!(x.pairs, y.pairs, "level {}", x.step);
            assert_eq!(x.friction_dissipation, y.friction_dissipation);
        }
        let (ra, rb) = (a.last_result().unwrap(), b.last_result().unwrap());
        assert_eq!(ra.displacement, rb.displacement);
        assert_eq!(ra.solution.lambda_n, rb.solution.lambda_n);
        assert_eq!(ra.solution.lambda_t, rb.solution.lambda_t);
    }
}

#[test]
fn a_law_on_a_frictionless_pair_gives_it_friction_and_unknown_pairs_are_errors() {
    let (model, pairs) = dragged_block(0.05, 1e-3, 0.0);
    let (plain, _) = run(&model, &pairs, QuasiStaticParams::default(), None, 4);
    assert!(plain.iter().all(|r| r.pairs[0].tangential_force == 0.0));
    let params =
        QuasiStaticParams::default().with_coulomb_fixed_point(true).with_fixed_point_tolerance(1e-13);
    let (with_law, _) = run(&model, &pairs, params, Some(Arc::new(ConstantFriction(0.4))), 6);
    let last = &with_law.last().unwrap().pairs[0];
    // sliding with Coulomb friction of a constant law: T = 0.4 N
    assert!((last.tangential_force / last.normal_force - 0.4).abs() < 1e-8, "{last:?}");
    let mut st =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), Default::default()).unwrap();
    assert!(st.set_friction_law("nope", Arc::new(ConstantFriction(0.1))).is_err());
}
