//! Row screening of `StaticContact` (issue 6): with a trailing block too small for the whole
//! contact interface (`InterfaceBlockParams::max_dofs`), the solver runs on the contact rows
//! whose dofs the block holds, the other rows are checked afterwards and added when they
//! penetrate. The result must be the one of the unscreened problem (every row, the whole
//! interface in the trailing block) and satisfy the KKT conditions of the full problem.

use synovia::contact::{StaticContact, StaticContactResult};
use synovia::contact_ops::operators::ContactPair;
use synovia::fem::{ElasticParams, Model};
use synovia::solvers::by_name;
use synovia_models::hertz::{hertz2d_model, hertz3d_model, Hertz2d, Hertz3d};

/// The frictionless solve at `t = 0`, the Tresca solve at `t = shift` with the slip bounds
/// of the normal solve and slip measured from its displacements (both from the reference when
/// given, so that both runs have the same friction cells), and a warm-started re-solve.
struct Run<const D: usize> {
    sc: StaticContact<D>,
    normal: StaticContactResult<D>,
    tresca: StaticContactResult<D>,
    /// The Tresca solve again at `t = 1.5 shift`, warm-started from `tresca`.
    resolve: StaticContactResult<D>,
}

fn run<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    max_trailing_dofs: usize,
    shift: f64,
    reference: Option<&Run<D>>,
) -> Run<D> {
    let block = synovia::linalg::InterfaceBlockParams::default().with_max_dofs(max_trailing_dofs);
    let sc = StaticContact::with_interface_block(model, pairs, ElasticParams::default(), block)
        .expect("factorise");
    three_solves(sc, model, shift, reference)
}

/// The three solves of a [`Run`] on `sc` (slip bounds and slip origin from the reference's
/// normal solve when given, else from its own).
fn three_solves<const D: usize>(
    sc: StaticContact<D>,
    model: &Model<D>,
    shift: f64,
    reference: Option<&Run<D>>,
) -> Run<D> {
    let solver = by_name("pdas").expect("solver");
    let normal = sc.solve(model, 0.0, solver.as_ref(), None, None, None).expect("normal solve");
    let base = reference.map_or(&normal, |r| &r.normal);
    let gc = sc.geometry().slip_bounds_from_pressure(&base.solution.lambda_n);
    let tresca = sc
        .solve(model, shift, solver.as_ref(), Some(&gc), Some(&base.displacement), None)
        .expect("Tresca solve");
    let resolve = sc
        .solve(
            model,
            1.5 * shift,
            solver.as_ref(),
            Some(&gc),
            Some(&base.displacement),
            Some(&tresca.solution),
        )
        .expect("warm re-solve");
    Run { sc, normal, tresca, resolve }
}

/// For each contact row: are all its dofs (node, partner, master nodes) in the trailing block?
fn rows_in_block<const D: usize>(sc: &StaticContact<D>) -> Vec<bool> {
    let dofs = sc.elastic().dofs();
    let Some(block) = sc.elastic().cholesky().trailing() else {
        return vec![false; sc.geometry().len()];
    };
    sc.geometry()
        .nodes
        .iter()
        .map(|n| {
            let others = n.partner.iter().copied().chain(n.master.iter().map(|&(b, j, _)| (b, j)));
            std::iter::once(n.node)
                .chain(others)
                .all(|(b, i)| dofs.node_dofs(b, i).all(|d| block.position[d] != usize::MAX))
        })
        .collect()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, b| a.max(b.abs()))
}

fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    max_abs(&d) / max_abs(b).max(f64::MIN_POSITIVE)
}

/// Compares a screened run with the reference: `U`, `Λ_n` (one per contact node), `Λ_t`, and
/// the KKT residuals of the full problem.
fn assert_matches<const D: usize>(screened: &Run<D>, reference: &Run<D>) {
    for (s, r, what) in [
        (&screened.normal, &reference.normal, "normal"),
        (&screened.tresca, &reference.tresca, "Tresca"),
        (&screened.resolve, &reference.resolve, "re-solve"),
    ] {
        assert_eq!(s.solution.lambda_n.len(), reference.sc.geometry().len(), "{what}: one Λ_n per node");
        let du = relative_difference(&s.solution.u, &r.solution.u);
        let dl = relative_difference(&s.solution.lambda_n, &r.solution.lambda_n);
        // Λ_t is dimensionless with ‖Λ_t‖ ≤ 1: compared absolutely (it is ≈ 0 without slip)
        assert_eq!(s.solution.lambda_t.len(), r.solution.lambda_t.len());
        let dt = s
            .solution
            .lambda_t
            .iter()
            .zip(&r.solution.lambda_t)
            .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()));
        println!(
            "{what}: ΔU {du:.2e}, ΔΛ_n {dl:.2e}, ΔΛ_t {dt:.2e}, KKT {:.2e}, max Λ_t {:.2e}",
            s.kkt.max(),
            max_abs(&r.solution.lambda_t)
        );
        assert!(du < 1e-9, "{what}: U differs by {du:e}");
        assert!(dl < 1e-9, "{what}: Λ_n differs by {dl:e}");
        assert!(dt < 1e-9, "{what}: Λ_t differs by {dt:e}");
        assert!(s.kkt.satisfied(1e-9), "{what}: KKT of the full problem {:?}", s.kkt);
        assert_eq!(s.cell_node, r.cell_node, "{what}: friction cells");
    }
}

/// The rows in contact (`Λ_n > 0`) of a result.
fn in_contact<const D: usize>(result: &StaticContactResult<D>) -> Vec<usize> {
    (0..result.solution.lambda_n.len()).filter(|&r| result.solution.lambda_n[r] > 0.0).collect()
}

/// Runs the reference (whole interface in the trailing block) and a screened run with a
/// trailing block of `budget(rows in contact)` dofs; returns both and the rows in the block.
fn screened_against_reference<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    shift: f64,
    budget: impl Fn(usize) -> usize,
) -> (Run<D>, Run<D>, Vec<bool>) {
    let reference = run(model, pairs, usize::MAX, shift, None);
    assert!(rows_in_block(&reference.sc).iter().all(|&b| b), "the reference holds the whole interface");
    let n_contact = in_contact(&reference.normal).len();
    let k = budget(n_contact);
    let screened = run(model, pairs, k, shift, Some(&reference));
    let inside = rows_in_block(&screened.sc);
    let k_used = screened.sc.elastic().cholesky().trailing().map_or(0, |b| b.dofs.len());
    println!(
        "{} contact nodes, {n_contact} in contact; budget {k} dofs: {k_used} ordered last, {} rows in the block",
        inside.len(),
        inside.iter().filter(|&&b| b).count()
    );
    assert!(k_used > 0 && k_used <= k, "trailing block of {k_used} dofs for a budget of {k}");
    assert!(inside.iter().any(|&b| !b), "the screening must exclude rows");
    (reference, screened, inside)
}

fn hemisphere() -> (Model<3>, Vec<ContactPair<3>>, f64) {
    let p = Hertz3d { levels: 9, ..Default::default() };
    let (model, mut pairs) = hertz3d_model(&p).expect("model");
    pairs[0].friction = 0.3;
    (model, pairs, 2e-4 * p.radius)
}

fn two_discs() -> (Model<2>, Vec<ContactPair<2>>, f64) {
    let p = Hertz2d { e2: Some(2.0), levels: 9, ..Default::default() };
    let (model, mut pairs) = hertz2d_model(&p).expect("model");
    pairs[0].friction = 0.3;
    (model, pairs, 2e-4 * p.radius)
}

/// Trailing block for about twice the contact zone: the excluded rows stay open.
#[test]
fn hemisphere_screening_that_covers_the_contact_zone_is_exact() {
    let (model, pairs, shift) = hemisphere();
    let (reference, screened, inside) = screened_against_reference(&model, &pairs, shift, |n| 3 * 2 * n);
    for r in in_contact(&reference.normal).into_iter().chain(in_contact(&screened.tresca)) {
        assert!(inside[r], "row {r} in contact lies outside the trailing block");
    }
    assert_matches(&screened, &reference);
}

/// Trailing block for a third of the contact zone: rows outside it come into contact and must
/// be added to the solve.
#[test]
fn hemisphere_screening_adds_rows_that_come_into_contact() {
    let (model, pairs, shift) = hemisphere();
    let (reference, screened, inside) = screened_against_reference(&model, &pairs, shift, |n| n);
    let added: Vec<usize> = in_contact(&screened.normal).into_iter().filter(|&r| !inside[r]).collect();
    println!("{} rows in contact outside the block", added.len());
    assert!(!added.is_empty(), "rows outside the block must come into contact");
    assert_matches(&screened, &reference);
}

/// Trailing block for most of the contact zone: the few rows added on its rim get their
/// columns of `S` from whole-factor solves, the others from the block.
#[test]
fn hemisphere_screening_adds_the_rim_of_the_contact_zone() {
    let (model, pairs, shift) = hemisphere();
    let (reference, screened, inside) = screened_against_reference(&model, &pairs, shift, |n| 3 * n * 9 / 10);
    let added = in_contact(&screened.normal).into_iter().filter(|&r| !inside[r]).count();
    println!("{added} rows in contact outside the block");
    assert!(added > 0, "rows outside the block must come into contact");
    assert_matches(&screened, &reference);
}

/// Two elastic half-discs (node-to-segment: each row also holds master nodes), block for a
/// third of the contact zone.
#[test]
fn two_body_screening_adds_rows_that_come_into_contact() {
    let (model, pairs, shift) = two_discs();
    let (reference, screened, inside) = screened_against_reference(&model, &pairs, shift, |n| 2 * n);
    let added = in_contact(&screened.normal).into_iter().filter(|&r| !inside[r]).count();
    println!("{added} rows in contact outside the block");
    assert!(added > 0, "rows outside the block must come into contact");
    assert_matches(&screened, &reference);
}

/// Two elastic half-discs, block for about three times the contact zone.
#[test]
fn two_body_screening_that_covers_the_contact_zone_is_exact() {
    let (model, pairs, shift) = two_discs();
    let (reference, screened, inside) = screened_against_reference(&model, &pairs, shift, |n| 2 * 2 * 2 * n);
    for r in in_contact(&reference.normal) {
        assert!(inside[r], "row {r} in contact lies outside the trailing block");
    }
    assert_matches(&screened, &reference);
}

/// A floating block (no Dirichlet data: proximal-point iteration) pressed onto a rigid flat:
/// every bottom row comes into contact, the block holds two of them.
#[test]
fn semi_coercive_screening_adds_rows_that_come_into_contact() {
    use synovia::prelude::*;
    let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 12, 6, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let block = joint.add_body("floating", mesh, plane_strain(1.0, 0.3).expect("material")).expect("body");
    joint.traction(block, "top", Vector::<2>::new(0.0, -0.01), Constant(1.0)).expect("traction");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
    joint.contact_rigid("block-flat", block, "bottom", flat, 0.3).expect("pair");
    let (model, pairs) = (joint.model(), joint.pairs());
    let (reference, screened, inside) = screened_against_reference(model, pairs, 0.0, |_| 4);
    let added = in_contact(&screened.normal).into_iter().filter(|&r| !inside[r]).count();
    println!(
        "{added} rows in contact outside the block, proximal iterations {}",
        screened.normal.proximal_iterations
    );
    assert!(added > 0 && screened.normal.proximal_iterations >= 1);
    assert_matches(&screened, &reference);
}

/// A run without a dense interface block (`max_dofs = 0`: whole-factor solves), the rows
/// screened by their gap (`StaticContact::set_screening_band`), with `unit_solves` on (the
/// columns of `S` from kept unit solves, as for a moving rigid partner) or off.
fn run_banded<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    band: f64,
    unit_solves: bool,
    shift: f64,
    reference: &Run<D>,
) -> Run<D> {
    let block = synovia::linalg::InterfaceBlockParams::default().with_max_dofs(0).with_screened_dofs(0);
    let mut sc = StaticContact::with_interface_block(model, pairs, ElasticParams::default(), block)
        .expect("factorise");
    assert!(sc.elastic().cholesky().trailing().is_none(), "no interface block");
    sc.set_screening_band(Some(band)).expect("band");
    if unit_solves {
        sc.context().clear_moved_rows();
    }
    three_solves(sc, model, shift, Some(reference))
}

/// Gap screening of whole-factor solves (the tkr3d insert's path, docs/tkr3d.md): a band that
/// holds the contact zone, and a band of zero (only the touching rows at first) whose rows
/// that come into contact are added, both with and without kept unit solves, equal the
/// unscreened solution and satisfy the KKT conditions of the full problem.
#[test]
fn gap_band_screening_of_whole_factor_solves_is_exact() {
    let (model, pairs, shift) = hemisphere();
    let reference = run(&model, &pairs, usize::MAX, shift, None);
    let contact = in_contact(&reference.normal);
    let gaps: Vec<f64> = reference.sc.geometry().nodes.iter().map(|n| n.gap).collect();
    let widest = contact.iter().map(|&r| gaps[r]).fold(0.0_f64, f64::max);
    let rows = gaps.len();
    for (band, unit_solves) in [(2.0 * widest, true), (0.0, true), (0.0, false)] {
        let screened = run_banded(&model, &pairs, band, unit_solves, shift, &reference);
        let outside: Vec<usize> = contact.iter().copied().filter(|&r| gaps[r] > band).collect();
        let near = gaps.iter().filter(|&&d| d <= band).count();
        println!(
            "band {band:.3e} (unit solves {unit_solves}): {near} of {rows} rows near, {} rows in contact from outside the band",
            outside.len()
        );
        assert!(near < rows, "the band must leave rows out");
        if band == 0.0 {
            assert!(!outside.is_empty(), "rows outside the band must come into contact");
        } else {
            assert!(outside.is_empty());
        }
        assert_matches(&screened, &reference);
    }
}

/// A screening band that is negative or not finite is a typed error naming the value.
#[test]
fn a_bad_screening_band_is_refused() {
    let (model, pairs, _) = hemisphere();
    let mut sc = StaticContact::new(&model, &pairs, ElasticParams::default()).expect("factorise");
    for band in [-1.0, f64::NAN, f64::INFINITY] {
        let e = sc.set_screening_band(Some(band)).expect_err("refused");
        assert!(e.to_string().contains("screening band"), "{e}");
    }
    let mut joint = synovia::prelude::JointModel::<3>::new();
    assert!(joint.screening_band(Some(-0.5)).is_err());
    assert!(joint.screening_band(Some(0.5)).is_ok() && joint.screening_band_value() == Some(0.5));
}
