//! A body in its own frame, placed in space (`NonlinearContact::place_bodies`), solves the
//! frictional finite-strain problem of its mesh moved to that place: the neo-Hookean half-disc
//! (2D) and hemisphere (3D) of `active_set_strategies.rs`, pressed on a rigid flat with
//! Coulomb friction 0.3 frozen per level and moved sideways so that part of the contact slips,
//! are built once with their meshes where the flat expects them and once with the meshes in
//! a body frame turned and shifted away from it (`y = Rᵀ (x − t)`, prescribed motion
//! `Rᵀ u(t)`) and placed back by `x = R y + t`. The placed body's displacements turned into
//! space (`R u`), its normal multipliers and its friction multipliers equal those of the moved
//! mesh to 1e-8, and both satisfy the KKT conditions to 1e-8: the slip of the friction law
//! is measured on the placed configuration (docs/model.md (12.0)).

use std::sync::Arc;

use synovia_contact::obstacle::PlaneObstacle;
use synovia_contact::operators::{BodyPlacement, ContactPair};
use synovia_fem::Model;
use synovia_material::neo_hookean;
use synovia_mesh::generators::{half_disc_refined, hemisphere_refined};
use synovia_mesh::math::{Point, Tensor, Vector};
use synovia_mesh::{BoundaryKind, Mesh};
use synovia_nonlinear::{NewtonParams, NonlinearResult};
use synovia_pdas::Pdas;

use crate::common::{finite_strain, level_times, max_rel};

/// The model of `mesh` (its `top` part prescribed to `motion`) on the flat `z = 0` (2D: `y = 0`)
/// with friction 0.3, its mesh moved into the body frame of `placement` (the identity: as it is).
fn model<const D: usize>(
    mut mesh: Mesh<D>,
    placement: &BodyPlacement<D>,
    motion: Vector<D>,
) -> (Model<D>, Vec<ContactPair<D>>) {
    let (r, t) = (*placement.rotation(), *placement.translation());
    mesh.map_nodes(|x| r.transpose() * (x - t)).expect("body frame");
    let mut model = Model::new();
    let b = model.add_body("body", mesh, Arc::new(neo_hookean(10.0, 0.3).expect("law"))).expect("body");
    // the prescribed motion in the body frame
    let local = r.transpose() * motion;
    model.prescribe(b, "top", move |_, time| local * time).expect("motion");
    let mut normal = Vector::<D>::zeros();
    normal[D - 1] = 1.0;
    let flat = PlaneObstacle::new(Point::<D>::zeros(), normal).expect("flat");
    (model, vec![ContactPair::rigid("body-flat", b, "contact", Arc::new(flat)).with_friction(0.3)])
}

fn solve<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    placement: &BodyPlacement<D>,
    levels: usize,
) -> NonlinearResult<D> {
    let mut nl = finite_strain(model, pairs, NewtonParams::default());
    nl.place_bodies(model, std::slice::from_ref(placement)).expect("placed");
    let results = nl.run(model, &level_times(levels), &Pdas::default(), |_| Ok(())).expect("converges");
    for r in &results {
        assert!(r.contact.kkt.max() <= 1e-8, "KKT {:e}", r.contact.kkt.max());
        assert!(r.report.residual() <= 1e-10, "residual {:e}", r.report.residual());
    }
    results.into_iter().last().expect("levels")
}

/// Solves the moved mesh (identity placement) and the placed body frame; compares.
fn placed_equals_moved<const D: usize>(
    mesh: Mesh<D>,
    placement: BodyPlacement<D>,
    motion: Vector<D>,
    levels: usize,
) {
    let identity = BodyPlacement::<D>::identity();
    let (moved_model, moved_pairs) = model(mesh.clone(), &identity, motion);
    let (placed_model, placed_pairs) = model(mesh, &placement, motion);
    let moved = solve(&moved_model, &moved_pairs, &identity, levels);
    let placed = solve(&placed_model, &placed_pairs, &placement, levels);
    let m = &moved.contact.solution;
    let p = &placed.contact.solution;
    assert!(m.report.slip > 0 && m.report.slip < m.report.active, "stick and slip: {:?}", m.report);
    let flat = |u: &[Vector<D>]| u.iter().flat_map(|v| v.iter().copied()).collect::<Vec<f64>>();
    let u_moved = flat(&moved.contact.displacement[0]);
    let u_placed: Vec<Vector<D>> =
        placed.contact.displacement[0].iter().map(|u| placement.to_global(u)).collect();
    let du = max_rel(&flat(&u_placed), &u_moved);
    let dn = max_rel(&p.lambda_n, &m.lambda_n);
    let dt = max_rel(&p.lambda_t, &m.lambda_t);
    println!(
        "{D}D: active {} (slip {}), Newton iterations moved {} / placed {}, |Δu| {du:.1e}, |ΔΛ_n| {dn:.1e}, |ΔΛ_t| {dt:.1e}",
        m.report.active,
        m.report.slip,
        moved.report.total_iterations,
        placed.report.total_iterations
    );
    assert_eq!(placed.contact.cell_node, moved.contact.cell_node, "friction cells");
    assert!(du <= 1e-8 && dn <= 1e-8 && dt <= 1e-8, "{D}D: {du:e} {dn:e} {dt:e}");
}

#[test]
fn placed_half_disc_with_friction_equals_the_moved_mesh() {
    let mut mesh = half_disc_refined(Point::<2>::new(0.0, 1.0), 1.0, 8, Point::<2>::new(0.0, 0.0), 0.25, 9)
        .expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[1] < 0.3 && n[1] < 0.0)
        .expect("contact");
    let (c, s) = (0.4_f64.cos(), 0.4_f64.sin());
    let turn = Tensor::<2>::new(c, -s, s, c);
    let placement = BodyPlacement::new(turn, Vector::<2>::new(0.7, -0.2)).expect("placement");
    let push = 0.02;
    placed_equals_moved(mesh, placement, Vector::<2>::new(0.3 * push, -push), 3);
}

#[test]
fn placed_hemisphere_with_friction_equals_the_moved_mesh() {
    let mut mesh = hemisphere_refined(Point::<3>::new(0.0, 0.0, 1.0), 1.0, 4, Point::<3>::zeros(), 0.15, 12)
        .expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[2] < 0.15 && n[2] < 0.0)
        .expect("contact");
    let axis = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(1.0, -2.0, 0.5));
    let turn = nalgebra::Rotation3::from_axis_angle(&axis, 0.6).into_inner();
    let placement = BodyPlacement::new(turn, Vector::<3>::new(0.3, 0.5, -0.4)).expect("placement");
    let push = 0.01;
    placed_equals_moved(mesh, placement, Vector::<3>::new(0.3 * push, 0.15 * push, -push), 2);
}
