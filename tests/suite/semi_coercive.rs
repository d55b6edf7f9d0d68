//! Semi-coercive bodies (docs/model.md §4, issue 7): bodies without Dirichlet data, held only by
//! contact. Solved by the proximal-point iteration of `synovia_contact::floating` when the load
//! presses them into contact; rejected with a typed error when it pulls them away or slides
//! them off. References: the exact uniform-compression state (patch test) and Hertz theory.
//! Numbers printed with `--nocapture` are the ones in `docs/reliability.md`.

use synovia::contact_ops::ContactError;
use synovia::prelude::*;
use synovia::solvers::by_name;
use synovia::time::TimeError;
use synovia_mesh::generators::{half_disc_refined, hemisphere_refined};
use synovia_models::hertz::fit_elliptic;

const E: f64 = 1.0;
const NU: f64 = 0.3;
const P: f64 = 0.01;

/// A floating block `[0, 1] × [0, ½]` (no Dirichlet data) under the pressure `p` on its top,
/// with its bottom on the rigid flat `y = 0`, or (with `on_block`) on a block below that stands
/// on a roller (`u_y = 0`; free to translate in x): the exact state is uniaxial stress in both.
fn floating_block(top: Vector<2>, on_block: bool, friction: f64) -> JointModel<2> {
    let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 12, 6, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let block = joint.add_body("floating", mesh, plane_strain(E, NU).expect("material")).expect("body");
    joint.traction(block, "top", top, Constant(1.0)).expect("traction");
    if on_block {
        let base = rectangle(0.0, 1.0, -0.5, 0.0, 12, 6, Grading::Uniform, Grading::Uniform).expect("mesh");
        let lower = joint.add_body("base", base, plane_strain(2.0 * E, NU).expect("material")).expect("body");
        // a roller bottom: the base is floating too (its x translation is free)
        joint.symmetry(lower, "bottom").expect("roller");
        joint.contact_bodies("block-base", block, "bottom", lower, "top", friction).expect("pair");
    } else {
        let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
        joint.contact_rigid("block-flat", block, "bottom", flat, friction).expect("pair");
    }
    joint
}

#[test]
fn floating_block_pressed_onto_a_flat_transmits_the_pressure_exactly() {
    for on_block in [false, true] {
        for solver in ["pdas", "au-pdas", "uzawa-mprgp"] {
            let mut joint = floating_block(Vector::<2>::new(0.0, -P), on_block, 0.0);
            joint.solver(solver).expect("solver");
            let run = joint.run_static(0.0).expect("a pressed floating body is solvable");
            let res = run.contact.as_ref().expect("contact");
            let kkt = res.kkt;
            assert!(kkt.satisfied(1e-8), "{solver}: {kkt:?}");
            // every contact node carries the applied pressure
            let err = res.solution.lambda_n.iter().map(|l| (l - P).abs() / P).fold(0.0, f64::max);
            assert!(err < 1e-9, "{solver} on_block={on_block}: pressure error {err:.3e}");
            let force = run.records[0].pairs[0].normal_force;
            assert!((force - P).abs() < 1e-10 * P, "force {force}");
            // the exact displacement: uniaxial stress, plane strain, bottom on the support
            let eps_y = -P * (1.0 - NU * NU) / E;
            let u = &run.displacement[0];
            let mesh = &joint.model().bodies()[0].mesh;
            let base_u = if on_block { -P * (1.0 - NU * NU) / (2.0 * E) * 0.5 } else { 0.0 };
            let uy_err = mesh
                .nodes()
                .iter()
                .zip(u)
                .map(|(x, ui)| (ui[1] - (base_u + eps_y * x[1])).abs())
                .fold(0.0, f64::max);
            assert!(uy_err < 1e-8 * eps_y.abs(), "{solver}: u_y error {uy_err:.3e}");
            println!(
                "floating block ({}) {solver}: pressure error {err:.2e}, u_y error {:.2e}, KKT {:.2e}, proximal iterations {}",
                if on_block { "on a block on a roller" } else { "on rigid flat" },
                uy_err / eps_y.abs(),
                kkt.max(),
                res.proximal_iterations
            );
            assert!(res.proximal_iterations >= 1);
        }
    }
}

#[test]
fn load_pulling_a_floating_body_away_is_rejected() {
    for (what, load) in
        [("pulled up", Vector::<2>::new(0.0, P)), ("pushed sideways", Vector::<2>::new(P, -P))]
    {
        let joint = floating_block(load, false, 0.0);
        match joint.run_static(0.0) {
            Err(JointError::Time(TimeError::Contact {
                source: ContactError::Unbalanced { bodies, residual, load: rigid_load, force },
                ..
            })) => {
                let load = rigid_load;
                assert_eq!(bodies, vec!["floating".to_string()]);
                // the unbalanced net force in newtons: the traction on the unit-wide top that
                // no contact force holds (all of it pulled up; its sideways part pushed
                // sideways, frictionless)
                let expected = if what == "pulled up" { [0.0, P] } else { [P, 0.0] };
                assert_eq!(force.len(), 2, "{what}: {force:?}");
                for (f, e) in force.iter().zip(expected) {
                    assert!(
                        (f - e).abs() < 1e-9 * P,
                        "{what}: unbalanced force {force:?}, expected {expected:?}"
                    );
                }
                assert!(residual > 0.1 * load, "{what}: {residual} of {load}");
                println!("{what}: rejected, unbalanced rigid load {residual:.3e} of {load:.3e}");
            }
            other => panic!("{what}: expected ContactError::Unbalanced, got {other:?}"),
        }
    }
}

#[test]
fn pure_elastic_solve_of_a_floating_body_is_still_refused() {
    let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 4, 2, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut model = Model::<2>::new();
    model.add_body("floating", mesh, std::sync::Arc::new(plane_strain(E, NU).expect("m"))).expect("body");
    match ElasticSolver::new(&model, ElasticParams::default()) {
        Err(FemError::SemiCoercive { free_modes, .. }) => assert_eq!(free_modes, 3),
        other => panic!("expected SemiCoercive, got {other:?}"),
    }
    let mut s = ElasticSolver::new_semi_coercive(&model, ElasticParams::default()).expect("stabilised");
    assert!(matches!(s.solve(&model, 0.0), Err(FemError::SemiCoercive { .. })));
}

#[test]
fn friction_holds_a_floating_block_below_its_capacity_and_not_above() {
    // pressure P from t = 0, a tangential traction q t on the top; μ = 0.3
    for (q, holds) in [(0.2 * P, true), (0.45 * P, false)] {
        let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 12, 6, Grading::Uniform, Grading::Uniform).expect("mesh");
        let mut joint = JointModel::<2>::new();
        let block = joint.add_body("floating", mesh, plane_strain(E, NU).expect("m")).expect("body");
        joint.traction_field(block, "top", move |_, _, t| Vector::<2>::new(q * t, -P)).expect("traction");
        let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
        joint.contact_rigid("block-flat", block, "bottom", flat, 0.3).expect("pair");
        let out = joint.run_quasistatic(&[0.0, 0.5, 1.0]);
        if holds {
            let run = out.expect("friction holds the block");
            let last = &run.records[2].pairs[0];
            assert!((last.tangential_force - q).abs() < 1e-8 * P, "{last:?}");
            assert!((last.normal_force - P).abs() < 1e-8 * P, "{last:?}");
            let kkt = run.contact.as_ref().expect("contact").kkt;
            assert!(kkt.satisfied(1e-7), "{kkt:?}");
            println!(
                "Q/μP = {:.3}: held, T = {:.6e}, KKT {:.2e}",
                q / (0.3 * P),
                last.tangential_force,
                kkt.max()
            );
        } else {
            let err = out.expect_err("a tangential load above μP cannot be held");
            let msg = err.to_string();
            // the level falls back to Coulomb at t = 1 and reports the forces (docs/model.md §7.1)
            match &err {
                JointError::Time(TimeError::Slides { tangential, capacity, .. }) => {
                    assert!(
                        (tangential - q).abs() < 1e-8 * P && (capacity - 0.3 * P).abs() < 1e-8 * P,
                        "{msg}"
                    );
                }
                other => panic!("expected TimeError::Slides, got {other:?}"),
            }
            assert!(msg.contains("exceeds the friction capacity"), "{msg}");
            println!("Q/μP = {:.3}: rejected: {msg}", q / (0.3 * P));
        }
    }
}

#[test]
fn floating_half_disc_pressed_onto_a_flat_matches_hertz() {
    // a half-disc of radius 1 with the pressure p on its flat top, no Dirichlet data
    let force = std::f64::consts::PI * E / (1.0 - NU * NU) * 0.1_f64.powi(2) / 4.0; // a ≈ 0.1
    let mesh = half_disc_refined(Point::<2>::new(0.0, 1.0), 1.0, 8, Point::<2>::new(0.0, 0.0), 0.16, 10)
        .expect("mesh");
    let mut joint = JointModel::<2>::new();
    let disc = joint.add_body("indenter", mesh, plane_strain(E, NU).expect("m")).expect("body");
    joint.pressure(disc, "top", force / 2.0, Constant(1.0)).expect("pressure");
    joint.define_part(disc, "contact", |x, n| x[1] < 0.3 && n[1] < 0.0).expect("part");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
    joint.contact_rigid("indenter-flat", disc, "contact", flat, 0.0).expect("pair");
    let run = joint.run_static(0.0).expect("solvable");
    let res = run.contact.as_ref().expect("contact");
    assert!(res.kkt.satisfied(1e-8), "{:?}", res.kkt);
    let total = run.records[0].pairs[0].normal_force;
    assert!((total - force).abs() < 1e-8 * force, "{total} vs {force}");
    let e_star = E / (1.0 - NU * NU);
    let a_exact = (4.0 * force / (std::f64::consts::PI * e_star)).sqrt();
    let p0_exact = 2.0 * force / (std::f64::consts::PI * a_exact);
    let geometry = contact_geometry_2d(&joint);
    let pts: Vec<(f64, f64)> = geometry.iter().zip(&res.solution.lambda_n).map(|(x, l)| (x[0], *l)).collect();
    let (a, p0) = fit_elliptic(&pts);
    let (ea, ep) = ((a - a_exact).abs() / a_exact, (p0 - p0_exact).abs() / p0_exact);
    println!(
        "floating Hertz 2D: {} dofs, a {a:.5} (exact {a_exact:.5}, err {ea:.2e}), p0 {p0:.5} (exact {p0_exact:.5}, err {ep:.2e}), proximal iterations {}, PDAS iterations {}",
        run.n_dofs, res.proximal_iterations, res.solution.report.iterations
    );
    assert!(ea < 0.02 && ep < 0.02, "a err {ea}, p0 err {ep}");
}

#[test]
fn floating_hemisphere_pressed_onto_a_flat_matches_hertz() {
    let e_star = E / (1.0 - NU * NU);
    let force = 4.0 * e_star * 0.12_f64.powi(3) / 3.0; // a ≈ 0.12
    let mesh = hemisphere_refined(Point::<3>::new(0.0, 0.0, 1.0), 1.0, 4, Point::<3>::zeros(), 0.15, 12)
        .expect("mesh");
    let mut joint = JointModel::<3>::new();
    let ball = joint.add_body("hemisphere", mesh, isotropic(E, NU).expect("m")).expect("body");
    joint.pressure(ball, "top", force / std::f64::consts::PI, Constant(1.0)).expect("pressure");
    joint.define_part(ball, "contact", |x, n| x[2] < 0.15 && n[2] < 0.0).expect("part");
    let flat = PlaneObstacle::new(Point::<3>::zeros(), Vector::<3>::new(0.0, 0.0, 1.0)).expect("plane");
    joint.contact_rigid("hemisphere-flat", ball, "contact", flat, 0.0).expect("pair");
    let solver = by_name("pdas").expect("solver");
    assert_eq!(solver.name(), "pdas");
    let run = joint.run_static(0.0).expect("solvable");
    let res = run.contact.as_ref().expect("contact");
    assert!(res.kkt.satisfied(1e-8), "{:?}", res.kkt);
    let total = run.records[0].pairs[0].normal_force;
    // the facet quadrature of the pressure on the polygonal top is exact for the polygon's area
    let top_area = joint.model().bodies()[0].mesh.boundary_part("top").expect("top").facets().count();
    assert!(top_area > 0);
    let a_exact = (3.0 * total / (4.0 * e_star)).cbrt();
    let p0_exact = 3.0 * total / (2.0 * std::f64::consts::PI * a_exact * a_exact);
    let nodes = contact_geometry_3d(&joint);
    let pts: Vec<(f64, f64)> = nodes
        .iter()
        .zip(&res.solution.lambda_n)
        .map(|(x, l)| ((x[0] * x[0] + x[1] * x[1]).sqrt(), *l))
        .collect();
    let (a, p0) = fit_elliptic(&pts);
    let (ea, ep) = ((a - a_exact).abs() / a_exact, (p0 - p0_exact).abs() / p0_exact);
    println!(
        "floating Hertz 3D: {} dofs, force {total:.4e} (applied {force:.4e}), a err {ea:.2e}, p0 err {ep:.2e}, proximal iterations {}, KKT {:.2e}",
        run.n_dofs, res.proximal_iterations, res.kkt.max()
    );
    assert!(ea < 0.05 && ep < 0.05, "a err {ea}, p0 err {ep}");
}

fn contact_geometry_2d(joint: &JointModel<2>) -> Vec<Point<2>> {
    let geo =
        synovia::contact_ops::operators::ContactGeometry::new(joint.model(), joint.pairs()).expect("geo");
    geo.nodes.iter().map(|n| n.position).collect()
}

fn contact_geometry_3d(joint: &JointModel<3>) -> Vec<Point<3>> {
    let geo =
        synovia::contact_ops::operators::ContactGeometry::new(joint.model(), joint.pairs()).expect("geo");
    geo.nodes.iter().map(|n| n.position).collect()
}
