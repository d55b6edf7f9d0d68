//! The contact geometry rebuilt on a deformed configuration with the factorisation kept
//! ([`StaticContact::update_geometry`]: the geometry passes of a finite-strain Newton iteration
//! while modified Newton keeps its tangent) keeps the solves that stay valid on that factor:
//! the unit solves `P A⁻¹ e_p` of the contact nodes' dofs, from which every row on a node is
//! combined whatever its normal and tangents (docs/model.md §10). So the passes after the first
//! cost no new solves for the nodes already seen, and a refactorisation drops them.
//!
//! A block clamped at its bottom, its top pressed by a rigid ball, on the whole-factor path
//! (no dense interface block), with Tresca friction: after each of three deformed
//! configurations the solve of the contact problem on the rows rebuilt there equals the solve
//! of a fresh `StaticContact` given only that configuration (multipliers and displacements to
//! 1e-10 relative), with fewer linear solves from the second configuration on; after a
//! refactorisation (the stiffness doubled) it equals a fresh solve on the doubled stiffness.
#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use synovia_contact::obstacle::SphereObstacle;
use synovia_contact::operators::ContactPair;
use synovia_contact::{StaticContact, StaticContactResult};
use synovia_fem::nonlinear::assemble_tangent;
use synovia_fem::{ElasticParams, Kinematics, Model};
use synovia_linalg::InterfaceBlockParams;
use synovia_material::isotropic;
use synovia_mesh::generators::{box_mesh, Grading};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::BoundaryKind;
use synovia_pdas::Pdas;

fn model() -> (Model<3>, Vec<ContactPair<3>>) {
    let mut mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [8, 8, 4], [Grading::Uniform; 3]).unwrap();
    mesh.set_part_kind("bottom", BoundaryKind::Prescribed).unwrap();
    mesh.set_part_kind("top", BoundaryKind::Contact).unwrap();
    let mut model = Model::new();
    let b = model.add_body("block", mesh, Arc::new(isotropic(10.0, 0.3).unwrap())).unwrap();
    model.prescribe(b, "bottom", |_, _| Vector::<3>::zeros()).unwrap();
    // the ball reaches 0.05 below the block's top
    let ball = SphereObstacle::new(Point::<3>::new(0.1, -0.05, 1.45), 0.5, false).unwrap();
    let pairs = vec![ContactPair::rigid("block-ball", b, "top", Arc::new(ball)).with_friction(0.3)];
    (model, pairs)
}

/// A smooth deformation of the block, growing with `k` (the configurations the rows are built on).
fn configuration(model: &Model<3>, k: Real) -> Vec<Vec<Vector<3>>> {
    vec![model.bodies()[0]
        .mesh
        .nodes()
        .iter()
        .map(|x| Vector::<3>::new(0.02 * k * x[0] * x[2], -0.015 * k * x[1] * x[2], -0.01 * k * x[2] * x[2]))
        .collect()]
}

/// A contact solver on the whole factor of `scale × K` (the small-strain stiffness).
fn contact(model: &Model<3>, pairs: &[ContactPair<3>], scale: Real) -> StaticContact<3> {
    let block = InterfaceBlockParams::default().with_max_dofs(0).with_screened_dofs(0);
    let zero: Vec<Vec<Vector<3>>> = vec![vec![Vector::<3>::zeros(); model.bodies()[0].mesh.n_nodes()]];
    StaticContact::with_system_matrix_block(model, pairs, ElasticParams::default(), block, |dofs, m| {
        assemble_tangent(model, dofs, &[Kinematics::SmallStrain], &zero, m)?;
        m.values_mut().iter_mut().for_each(|v| *v *= scale);
        Ok(())
    })
    .unwrap()
}

/// The Tresca solve with slip bound 0.02 at every contact node and no load but the ball.
fn solve(contact: &StaticContact<3>) -> StaticContactResult<3> {
    let n = contact.geometry().nodes.len();
    let dofs = contact.elastic().dofs();
    let load = vec![0.0; dofs.n_dofs()];
    let lifts = vec![Vector::<3>::zeros(); dofs.groups().len()];
    contact.solve_load(&load, &lifts, &Pdas::default(), Some(&vec![0.02; n]), None, None).unwrap()
}

fn max_abs(x: &[Real]) -> Real {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

fn max_diff(x: &[Real], y: &[Real]) -> Real {
    assert_eq!(x.len(), y.len());
    x.iter().zip(y).fold(0.0, |m, (a, b)| m.max((a - b).abs()))
}

fn flat(u: &[Vec<Vector<3>>]) -> Vec<Real> {
    u.iter().flatten().flat_map(|v| v.iter().copied().collect::<Vec<_>>()).collect()
}

/// Multipliers and displacements of `a` equal those of `b` to 1e-10 relative.
fn assert_same(a: &StaticContactResult<3>, b: &StaticContactResult<3>, what: &str) {
    let scale = max_abs(&b.solution.lambda_n);
    assert!(scale > 0.0, "{what}: the ball must press the block");
    let dn = max_diff(&a.solution.lambda_n, &b.solution.lambda_n);
    assert!(dn <= 1e-10 * scale, "{what}: Λ_n differ by {dn:e} (max {scale:e})");
    let dt = max_diff(&a.solution.lambda_t, &b.solution.lambda_t);
    assert!(dt <= 1e-10 * max_abs(&b.solution.lambda_t).max(1.0), "{what}: Λ_t differ by {dt:e}");
    let (ua, ub) = (flat(&a.displacement), flat(&b.displacement));
    let du = max_diff(&ua, &ub);
    assert!(du <= 1e-10 * max_abs(&ub), "{what}: u differs by {du:e}");
    assert!(a.kkt.max() < 1e-9, "{what}: KKT {:e}", a.kkt.max());
}

#[test]
fn rebuilt_rows_on_a_kept_factor_reuse_the_unit_solves_and_equal_fresh_solves() {
    let (model, pairs) = model();
    let mut kept = contact(&model, &pairs, 1.0);
    let mut solves_kept = Vec::new();
    let mut solves_fresh = Vec::new();
    for k in [1.0, 2.0, 3.0] {
        let at = configuration(&model, k);
        kept.update_geometry(&model, &pairs, &at).unwrap();
        let a = solve(&kept);
        let mut fresh = contact(&model, &pairs, 1.0);
        fresh.update_geometry(&model, &pairs, &at).unwrap();
        let b = solve(&fresh);
        assert_same(&a, &b, &format!("configuration {k}"));
        assert!(b.solution.report.slip > 0 || b.solution.report.stick > 0, "friction rows");
        solves_kept.push(a.solution.report.linear_solves);
        solves_fresh.push(b.solution.report.linear_solves);
    }
    eprintln!("linear solves: kept factor {solves_kept:?}, fresh {solves_fresh:?}");
    // the first configuration solves its nodes' unit solves as a fresh solver does; later ones
    // reuse them (the active nodes change little between the configurations)
    assert_eq!(solves_kept[0], solves_fresh[0]);
    for k in 1..3 {
        assert!(
            2 * solves_kept[k] < solves_fresh[k],
            "configuration {}: {} solves on the kept factor against {} fresh",
            k + 1,
            solves_kept[k],
            solves_fresh[k]
        );
    }
    // a refactorisation drops the kept solves: the doubled stiffness gives the fresh answer
    let zero: Vec<Vec<Vector<3>>> = vec![vec![Vector::<3>::zeros(); model.bodies()[0].mesh.n_nodes()]];
    kept.refactorise(|dofs, m| {
        assemble_tangent(&model, dofs, &[Kinematics::SmallStrain], &zero, m)?;
        m.values_mut().iter_mut().for_each(|v| *v *= 2.0);
        Ok(())
    })
    .unwrap();
    let at = configuration(&model, 3.0);
    kept.update_geometry(&model, &pairs, &at).unwrap();
    let a = solve(&kept);
    let mut fresh = contact(&model, &pairs, 2.0);
    fresh.update_geometry(&model, &pairs, &at).unwrap();
    let b = solve(&fresh);
    assert_same(&a, &b, "doubled stiffness");
    let mut soft = contact(&model, &pairs, 1.0);
    soft.update_geometry(&model, &pairs, &at).unwrap();
    let soft = solve(&soft);
    // (and it is not the answer of the first stiffness)
    let diff = max_diff(&flat(&a.displacement), &flat(&soft.displacement));
    assert!(diff > 1e-3 * max_abs(&flat(&soft.displacement)), "the stiffness changed the answer");
}
