//! At small loads the neo-Hookean (finite-strain) Hertz solution equals the linear one: a
//! half-disc (2D, plane strain) and a hemisphere (3D) pressed on a rigid flat by a prescribed
//! displacement of their top. The contact force and the contact width agree to 1 %; the KKT
//! residuals of the contact solution are at rounding level and Newton converges quadratically.
//! At a large push the two models differ (the check can fail).

use std::sync::Arc;

use synovia_contact::obstacle::PlaneObstacle;
use synovia_contact::operators::ContactPair;
use synovia_contact::StaticContact;
use synovia_fem::{ElasticParams, Model};
use synovia_material::{isotropic, neo_hookean, plane_strain, Material};
use synovia_mesh::generators::{half_disc_refined, hemisphere_refined};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::BoundaryKind;
use synovia_nonlinear::NewtonParams;
use synovia_pdas::Pdas;

use crate::common::{finite_strain, level_times};

const E: f64 = 10.0;
const NU: f64 = 0.3;

fn model_2d(material: Arc<dyn Material<2>>, push: f64) -> (Model<2>, Vec<ContactPair<2>>) {
    let mut mesh = half_disc_refined(Point::<2>::new(0.0, 1.0), 1.0, 8, Point::<2>::new(0.0, 0.0), 0.25, 9)
        .expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[1] < 0.3 && n[1] < 0.0)
        .expect("contact");
    let mut model = Model::new();
    let b = model.add_body("disc", mesh, material).expect("body");
    model.prescribe(b, "top", move |_, t| Vector::<2>::new(0.0, -push * t)).expect("push");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("flat");
    (model, vec![ContactPair::rigid("disc-flat", b, "contact", Arc::new(flat))])
}

fn model_3d(material: Arc<dyn Material<3>>, push: f64) -> (Model<3>, Vec<ContactPair<3>>) {
    let mut mesh = hemisphere_refined(Point::<3>::new(0.0, 0.0, 1.0), 1.0, 4, Point::<3>::zeros(), 0.15, 12)
        .expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[2] < 0.15 && n[2] < 0.0)
        .expect("contact");
    let mut model = Model::new();
    let b = model.add_body("ball", mesh, material).expect("body");
    model.prescribe(b, "top", move |_, t| Vector::<3>::new(0.0, 0.0, -push * t)).expect("push");
    let flat = PlaneObstacle::new(Point::<3>::zeros(), Vector::<3>::new(0.0, 0.0, 1.0)).expect("flat");
    (model, vec![ContactPair::rigid("ball-flat", b, "contact", Arc::new(flat))])
}

/// (force, contact radius from the second moment of the pressure) of the linear model.
fn linear<const D: usize>(model: &Model<D>, pairs: &[ContactPair<D>]) -> (f64, f64) {
    let sc = StaticContact::new(model, pairs, ElasticParams::default()).expect("set-up");
    let res = sc.solve(model, 1.0, &Pdas::default(), None, None, None).expect("solve");
    let geo = sc.geometry();
    (res.normal_force(geo, 0..geo.len()), radius(geo, &res.solution.lambda_n))
}

fn radius<const D: usize>(geo: &synovia_contact::operators::ContactGeometry<D>, lambda: &[f64]) -> f64 {
    // the contact width from the second moment of the contact forces: for the Hertz pressure
    // p ∝ √(1 − r²/a²), ⟨x²⟩ = a²/4 in 2D and ⟨r²⟩ = 2a²/5 in 3D
    let (mut m0, mut m2) = (0.0, 0.0);
    for (n, &l) in geo.nodes.iter().zip(lambda) {
        let r2: f64 = (0..D - 1).map(|i| n.position[i] * n.position[i]).sum();
        m0 += n.weight * l;
        m2 += n.weight * l * r2;
    }
    let factor = if D == 2 { 4.0 } else { 2.5 };
    (factor * m2 / m0).sqrt()
}

/// (force, radius, max KKT, Newton iterations of the last level) of the neo-Hookean model.
fn nonlinear<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    levels: usize,
) -> (f64, f64, f64, usize) {
    let mut nl = finite_strain(model, pairs, NewtonParams::default());
    let results = nl.run(model, &level_times(levels), &Pdas::default(), |_| Ok(())).expect("converges");
    let last = results.last().expect("levels");
    let it = &last.report.iterations;
    // quadratic convergence: the last residual is below the square of the one before (scaled)
    if it.len() >= 3 {
        let (r1, r2) = (it[it.len() - 3].residual, it[it.len() - 2].residual);
        assert!(r2 <= 10.0 * r1 * r1.max(1e-6) || r2 < 1e-8, "not quadratic: {it:?}");
    }
    let geo = nl.geometry();
    let kkt = last.contact.kkt.max();
    (
        last.contact.normal_force(geo, 0..geo.len()),
        radius(geo, &last.contact.solution.lambda_n),
        kkt,
        it.len(),
    )
}

#[test]
fn neo_hookean_hertz_2d_equals_linear_at_small_load() {
    let push = 1e-3;
    let (m_lin, p_lin) = model_2d(Arc::new(plane_strain(E, NU).expect("law")), push);
    let (f_lin, a_lin) = linear(&m_lin, &p_lin);
    let (m_nh, p_nh) = model_2d(Arc::new(neo_hookean(E, NU).expect("law")), push);
    let (f_nh, a_nh, kkt, iterations) = nonlinear(&m_nh, &p_nh, 1);
    println!("2D: force {f_lin:.6e} vs {f_nh:.6e}, a {a_lin:.5} vs {a_nh:.5}, kkt {kkt:.1e}, {iterations} Newton iterations");
    assert!(f_lin > 0.0 && (f_nh / f_lin - 1.0).abs() < 0.01, "force {f_nh} vs {f_lin}");
    assert!((a_nh / a_lin - 1.0).abs() < 0.01, "a {a_nh} vs {a_lin}");
    assert!(kkt < 1e-8, "KKT {kkt}");
    // a large push (strain ~ 20 %) separates the two models
    let (m_lin, p_lin) = model_2d(Arc::new(plane_strain(E, NU).expect("law")), 0.1);
    let (f_lin, _) = linear(&m_lin, &p_lin);
    let (m_nh, p_nh) = model_2d(Arc::new(neo_hookean(E, NU).expect("law")), 0.1);
    let (f_nh, _, kkt, _) = nonlinear(&m_nh, &p_nh, 5);
    println!("2D push 0.1: force linear {f_lin:.6e}, neo-Hookean {f_nh:.6e}, kkt {kkt:.1e}");
    assert!((f_nh / f_lin - 1.0).abs() > 0.02, "force {f_nh} vs {f_lin}");
    assert!(kkt < 1e-8, "KKT {kkt}");
}

#[test]
fn neo_hookean_hertz_3d_equals_linear_at_small_load() {
    let push = 3e-3;
    let (m_lin, p_lin) = model_3d(Arc::new(isotropic(E, NU).expect("law")), push);
    let (f_lin, a_lin) = linear(&m_lin, &p_lin);
    let (m_nh, p_nh) = model_3d(Arc::new(neo_hookean(E, NU).expect("law")), push);
    let (f_nh, a_nh, kkt, iterations) = nonlinear(&m_nh, &p_nh, 1);
    println!("3D: force {f_lin:.6e} vs {f_nh:.6e}, a {a_lin:.5} vs {a_nh:.5}, kkt {kkt:.1e}, {iterations} Newton iterations");
    assert!(f_lin > 0.0 && (f_nh / f_lin - 1.0).abs() < 0.01, "force {f_nh} vs {f_lin}");
    assert!((a_nh / a_lin - 1.0).abs() < 0.01, "a {a_nh} vs {a_lin}");
    assert!(kkt < 1e-8, "KKT {kkt}");
}
