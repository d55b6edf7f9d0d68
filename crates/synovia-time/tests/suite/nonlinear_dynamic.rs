//! Tests of the semi-implicit Kelvin–Voigt scheme with a nonlinear elastic part
//! (docs/model.md (12.2), docs/dynamics.md §8), against exact references: the linear scheme
//! for a linear material sent through the Newton iteration, the linear scheme at small
//! amplitude, the scheme's energy identity with `D_Π` from an independent quadrature of the
//! tangent, a neo-Hookean impact on a rigid floor checked on its deformed configuration,
//! first-order convergence in time, and typed errors.
#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use synovia_contact::operators::{ContactPair, PlaneObstacle};
use synovia_contact::{ContactParams, ExponentialFriction};
use synovia_fem::nonlinear::assemble_tangent;
use synovia_fem::{Kinematics, Model, SymmetricMatrix};
use synovia_material::{neo_hookean, plane_strain, Material};
use synovia_mesh::generators::{rectangle, Grading};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::BoundaryKind;
use synovia_nonlinear::NewtonParams;
use synovia_pdas::Pdas;
use synovia_time::dynamic::{DynamicBody, DynamicParams, DynamicStepper, MassKind};
use synovia_time::nonlinear_dynamic::NonlinearDynamicStepper;
use synovia_time::TimeError;

type Nodal = Vec<Vec<Vector<2>>>;

fn pdas() -> Pdas {
    Pdas::new(ContactParams::default().with_tolerance(1e-12))
}

fn newton() -> NewtonParams {
    NewtonParams::default().with_tolerance(1e-12)
}

fn max_norm(u: &Nodal) -> Real {
    u.iter().flatten().map(|v| v.norm()).fold(0.0, Real::max)
}

fn max_diff(a: &Nodal, b: &Nodal) -> Real {
    a.iter().flatten().zip(b.iter().flatten()).map(|(x, y)| (x - y).norm()).fold(0.0, Real::max)
}

fn kv_body(density: Real) -> DynamicBody {
    DynamicBody { density, damping: 0.5, viscous: Some(plane_strain(10.0, 0.3).unwrap().stiffness().clone()) }
}

/// Cantilever `[0, 4] × [0, 1]` (16 × 4): the left side moves vertically by
/// `0.05 sin(3t)` (a moving lift), the right side carries `(0, −2 sin²(πt))`.
fn cantilever(material: Arc<dyn Material<2>>, amplitude: Real, nx: usize) -> Model<2> {
    let mut mesh = rectangle(0.0, 4.0, 0.0, 1.0, nx, nx / 4, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("left", BoundaryKind::Prescribed).unwrap();
    mesh.set_part_kind("right", BoundaryKind::Traction).unwrap();
    let mut model = Model::<2>::new();
    let b = model.add_body("beam", mesh, material).unwrap();
    model
        .prescribe(b, "left", move |_, t| Vector::<2>::new(0.0, 0.05 * amplitude * (3.0 * t).sin()))
        .unwrap();
    model
        .traction(b, "right", move |_, _, t| {
            Vector::<2>::new(0.0, -2.0 * amplitude * (std::f64::consts::PI * t).sin().powi(2))
        })
        .unwrap();
    model
}

fn initial_fields(model: &Model<2>, amplitude: Real) -> (Nodal, Nodal) {
    let nodes = model.bodies()[0].mesh.nodes();
    let u0 =
        vec![nodes.iter().map(|x| Vector::<2>::new(0.0, amplitude * 0.01 * (x[0] / 4.0).powi(2))).collect()];
    let u1 = vec![nodes.iter().map(|x| Vector::<2>::new(0.0, amplitude * 0.1 * x[0] / 4.0)).collect()];
    (u0, u1)
}

/// (a) A linear material sent through the Newton iteration: the nonlinear scheme is the
/// linear scheme (7.3) — moving lift, traction, damping and viscosity, initial data, both
/// mass kinds.
#[test]
fn linear_material_through_newton_equals_the_linear_scheme() {
    for mass in [MassKind::Consistent, MassKind::Lumped] {
        let model = cantilever(Arc::new(plane_strain(1.0e3, 0.3).unwrap()), 1.0, 16);
        let params = DynamicParams::new(0.01).with_mass(mass);
        let mut lin = DynamicStepper::new(&model, &[kv_body(1.0)], &[], params.clone()).unwrap();
        let mut nl = NonlinearDynamicStepper::new(
            &model,
            &[kv_body(1.0)],
            &[],
            &[Kinematics::SmallStrain],
            params,
            newton(),
        )
        .unwrap();
        let (u0, u1) = initial_fields(&model, 1.0);
        lin.set_initial_state(&model, Some(&u0), Some(&u1)).unwrap();
        nl.set_initial_state(&model, Some(&u0), Some(&u1)).unwrap();
        let mut worst: Real = 0.0;
        for _ in 0..80 {
            let a = lin.step(&model, &pdas()).unwrap();
            let b = nl.step(&model, &pdas()).unwrap();
            let d = max_diff(&lin.displacement().to_vec(), &nl.displacement().to_vec())
                / max_norm(&lin.displacement().to_vec());
            worst = worst.max(d);
            assert!((a.kinetic_energy - b.kinetic_energy).abs() <= 1e-9 * a.kinetic_energy.max(1e-12));
            assert!((a.strain_energy - b.strain_energy).abs() <= 1e-9 * a.strain_energy.max(1e-12));
            assert!(
                (a.viscous_dissipation - b.viscous_dissipation).abs()
                    <= 1e-9 * a.viscous_dissipation.max(1e-12)
            );
            assert_eq!(nl.last_report().cutbacks, 0);
        }
        println!("(a) {mass:?}: linear material through Newton vs the linear scheme: max relative difference {worst:.2e}");
        assert!(worst <= 1e-10, "difference {worst:e}");
    }
}

/// (a) The same with contact and slip-rate-dependent friction: a block thrown onto a rigid
/// floor (gravity, initial velocity `(1, −1)`), Tresca frozen per step from the previous
/// level with the exponential law.
#[test]
fn linear_material_with_contact_and_friction_equals_the_linear_scheme() {
    let (rho, g) = (1.0, 9.81);
    let mut mesh = rectangle(-0.5, 0.5, 0.02, 0.52, 12, 6, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("bottom", BoundaryKind::Contact).unwrap();
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0e3, 0.3).unwrap())).unwrap();
    model.body_force(b, move |_, _| Vector::<2>::new(0.0, -rho * g)).unwrap();
    let plane = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0)).unwrap();
    let pairs = vec![ContactPair::rigid("floor", b, "bottom", Arc::new(plane)).with_friction(0.3)];
    let law =
        ExponentialFriction { static_coefficient: 0.4, kinetic_coefficient: 0.25, characteristic_speed: 0.5 };
    let params = DynamicParams::new(2e-3);
    let body = kv_body(rho);
    let mut lin = DynamicStepper::new(&model, std::slice::from_ref(&body), &pairs, params.clone()).unwrap();
    let mut nl = NonlinearDynamicStepper::new(
        &model,
        std::slice::from_ref(&body),
        &pairs,
        &[Kinematics::SmallStrain],
        params,
        newton(),
    )
    .unwrap();
    lin.set_friction_law("floor", Arc::new(law)).unwrap();
    nl.set_friction_law("floor", Arc::new(law)).unwrap();
    let n = model.bodies()[0].mesh.n_nodes();
    let v = vec![vec![Vector::<2>::new(1.0, -1.0); n]];
    lin.set_initial_state(&model, None, Some(&v)).unwrap();
    nl.set_initial_state(&model, None, Some(&v)).unwrap();
    let (mut worst, mut worst_p, mut contact_steps, mut friction): (Real, Real, usize, Real) =
        (0.0, 0.0, 0, 0.0);
    for _ in 0..100 {
        let a = lin.step(&model, &pdas()).unwrap();
        let b = nl.step(&model, &pdas()).unwrap();
        let scale = max_norm(&lin.displacement().to_vec());
        worst = worst.max(max_diff(&lin.displacement().to_vec(), &nl.displacement().to_vec()) / scale);
        let pl = lin.pressure();
        let pmax = pl.iter().fold(0.0_f64, |m, p| m.max(p.abs()));
        if pmax > 0.0 {
            contact_steps += 1;
            let dp = pl.iter().zip(nl.pressure()).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            worst_p = worst_p.max(dp / pmax);
        }
        friction += b.friction_dissipation;
        assert!(
            (a.friction_dissipation - b.friction_dissipation).abs()
                <= 1e-8 * a.friction_dissipation.max(1e-9)
        );
    }
    println!(
        "(a) contact + friction: displacement difference {worst:.2e}, pressure difference {worst_p:.2e} over {contact_steps} contact steps, friction work {friction:.4e}"
    );
    assert!(contact_steps > 10 && friction > 0.0);
    assert!(worst <= 1e-10 && worst_p <= 1e-9, "{worst:e} {worst_p:e}");
}

/// One run of the cantilever (neo-Hookean in finite strain or linear) at load amplitude `a`;
/// returns `U(T)`.
fn amplitude_run(a: Real, neo: bool, steps: usize, dt: Real, nx: usize) -> Nodal {
    let material: Arc<dyn Material<2>> = if neo {
        Arc::new(neo_hookean(1.0e3, 0.3).unwrap())
    } else {
        Arc::new(plane_strain(1.0e3, 0.3).unwrap())
    };
    let model = cantilever(material, a, nx);
    let (u0, u1) = initial_fields(&model, a);
    let params = DynamicParams::new(dt);
    if neo {
        let mut st = NonlinearDynamicStepper::new(
            &model,
            &[kv_body(1.0)],
            &[],
            &[Kinematics::FiniteStrain],
            params,
            newton(),
        )
        .unwrap();
        st.set_initial_state(&model, Some(&u0), Some(&u1)).unwrap();
        for _ in 0..steps {
            st.step(&model, &pdas()).unwrap();
            assert_eq!(st.last_report().cutbacks, 0, "amplitude {a}: cut-back at step {}", st.step_index());
        }
        st.displacement().to_vec()
    } else {
        let mut st = DynamicStepper::new(&model, &[kv_body(1.0)], &[], params).unwrap();
        st.set_initial_state(&model, Some(&u0), Some(&u1)).unwrap();
        st.run(&model, &pdas(), steps).unwrap();
        st.displacement().to_vec()
    }
}

/// (b) Neo-Hookean in finite strain at small amplitude equals the linear scheme, with a
/// relative difference of first order in the amplitude — down to amplitudes where the stress
/// of the neo-Hookean law is at its rounding floor (`1e-4`: strains of ≈ 1e-7).
#[test]
fn neo_hookean_at_small_amplitude_tends_to_the_linear_scheme() {
    let amplitudes = [2.0, 1.0, 0.5, 0.25, 0.125, 1e-2, 1e-4];
    let diffs: Vec<Real> = amplitudes
        .iter()
        .map(|&a| {
            let nh = amplitude_run(a, true, 60, 0.01, 16);
            let lin = amplitude_run(a, false, 60, 0.01, 16);
            max_diff(&nh, &lin) / max_norm(&lin)
        })
        .collect();
    let rates: Vec<Real> = diffs
        .windows(2)
        .zip(amplitudes.windows(2))
        .map(|(d, a)| (d[0] / d[1]).ln() / (a[0] / a[1]).ln())
        .collect();
    println!("(b) amplitudes {amplitudes:?}: relative difference neo-Hookean vs linear {diffs:?}, rates {rates:.3?}");
    assert!(diffs[diffs.len() - 1] < 1e-5);
    for r in &rates {
        assert!((r - 1.0).abs() < 0.05, "rate {r}");
    }
}

/// `∫₀¹ τ δᵀ K_T(U + τ δ) δ dτ` by 6-point Gauss–Legendre quadrature of the tangent
/// (assembled here, independently of the stepper's energy bookkeeping).
fn elastic_dissipation_by_quadrature(
    model: &Model<2>,
    st: &NonlinearDynamicStepper<2>,
    from: &Nodal,
    to: &Nodal,
) -> Real {
    let nodes = [
        (-0.932_469_514_203_152, 0.171_324_492_379_170),
        (-0.661_209_386_466_265, 0.360_761_573_048_139),
        (-0.238_619_186_083_197, 0.467_913_934_572_691),
        (0.238_619_186_083_197, 0.467_913_934_572_691),
        (0.661_209_386_466_265, 0.360_761_573_048_139),
        (0.932_469_514_203_152, 0.171_324_492_379_170),
    ];
    let dofs = st.dofs();
    // δ in reduced unknowns (no lifts in this test)
    let delta: Vec<Real> = dofs
        .groups()
        .iter()
        .flat_map(|grp| {
            let (b, i) = grp.origin;
            let d = to[b.0][i] - from[b.0][i];
            (0..grp.n_dofs).map(move |k| grp.basis[k].dot(&d))
        })
        .collect();
    let mut k: SymmetricMatrix = st.mass_matrix().clone();
    let mut total = 0.0;
    for (x, w) in nodes {
        let tau = 0.5 * (x + 1.0);
        let at: Nodal = from
            .iter()
            .zip(to)
            .map(|(f, t)| f.iter().zip(t).map(|(a, b)| a + (b - a) * tau).collect())
            .collect();
        assemble_tangent(model, dofs, st.kinematics(), &at, &mut k).unwrap();
        total += 0.5 * w * tau * k.quadratic_form(&delta);
    }
    total
}

/// Undamped free vibration of a clamped neo-Hookean cantilever in finite strain (no load, no
/// contact, from a large initial velocity).
fn free_cantilever(body: DynamicBody, dt: Real) -> (Model<2>, NonlinearDynamicStepper<2>) {
    let mut mesh = rectangle(0.0, 4.0, 0.0, 1.0, 16, 4, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("left", BoundaryKind::Clamped).unwrap();
    let mut model = Model::<2>::new();
    model.add_body("beam", mesh, Arc::new(neo_hookean(1.0e3, 0.3).unwrap())).unwrap();
    let mut st = NonlinearDynamicStepper::new(
        &model,
        &[body],
        &[],
        &[Kinematics::FiniteStrain],
        DynamicParams::new(dt),
        newton(),
    )
    .unwrap();
    let nodes = model.bodies()[0].mesh.nodes().to_vec();
    let u1: Nodal = vec![nodes.iter().map(|x| Vector::<2>::new(0.0, 4.0 * (x[0] / 4.0).powi(2))).collect()];
    st.set_initial_state(&model, None, Some(&u1)).unwrap();
    (model, st)
}

/// (c) The energy of the scheme without load and contact: `E^{i+1} − E^i = −D_kin − D_Π`
/// (undamped) and `… − D_visc` (Kelvin–Voigt), with `D_Π` equal to the quadrature of the
/// tangent, `D_Π ≥ 0`, the energy non-increasing; viscosity dissipates faster.
#[test]
fn energy_identity_and_dissipation_without_load_and_contact() {
    let mut ends = Vec::new();
    for body in [DynamicBody::elastic(1.0), kv_body(1.0)] {
        let viscous = body.viscous.is_some();
        let (model, mut st) = free_cantilever(body, 0.01);
        let e0 = st.energy();
        let (mut worst_identity, mut worst_quadrature, mut min_d_pi, mut max_strain): (
            Real,
            Real,
            Real,
            Real,
        ) = (0.0, 0.0, Real::INFINITY, 0.0);
        let mut e_prev = e0;
        for _ in 0..100 {
            let from = st.displacement().to_vec();
            let rec = st.step(&model, &pdas()).unwrap();
            let to = st.displacement().to_vec();
            let b = *st.energy_balance();
            let r = st.last_report().clone();
            assert!(b.exact);
            let e = st.energy();
            // the identity with its terms from independent pieces: kinetic from the mass
            // form, Π from the energy density, D_Π = δᵀF_int − ΔΠ, D_visc from M_α + A⁽¹⁾
            let residual =
                (e - e_prev) + r.kinetic_dissipation + r.elastic_dissipation + b.viscous_dissipation;
            worst_identity = worst_identity.max(residual.abs() / e0);
            let quadrature = elastic_dissipation_by_quadrature(&model, &st, &from, &to);
            worst_quadrature = worst_quadrature
                .max((quadrature - r.elastic_dissipation).abs() / quadrature.abs().max(1e-300));
            min_d_pi = min_d_pi.min(r.elastic_dissipation);
            assert!(b.viscous_dissipation >= 0.0 && rec.viscous_dissipation >= 0.0);
            assert!(!viscous || b.viscous_dissipation > 0.0);
            assert!(e <= e_prev * (1.0 + 1e-10), "energy increased {e_prev} → {e}");
            max_strain = max_strain.max(max_norm(&to));
            e_prev = e;
        }
        println!(
            "(c) viscous = {viscous}: identity residual {worst_identity:.2e} E0, D_Π vs quadrature {worst_quadrature:.2e}, min D_Π {min_d_pi:.3e}, E_end/E0 = {:.4}, max |u| = {max_strain:.3}",
            e_prev / e0
        );
        assert!(worst_identity < 1e-9);
        assert!(worst_quadrature < 1e-6);
        assert!(min_d_pi >= 0.0);
        assert!(max_strain > 0.3, "not a large deformation: max |u| {max_strain}");
        ends.push(e_prev / e0);
    }
    assert!(ends[1] < 0.8 * ends[0], "viscosity did not dissipate more: {ends:?}");
}

/// (d) A neo-Hookean block (finite strain, contact on the deformed configuration) thrown onto
/// a rigid floor: at every step the contact conditions hold on the deformed configuration
/// (no penetration, non-negative pressure, pressure only where the gap is closed) and the
/// equilibrium residual is at the Newton tolerance.
#[test]
fn neo_hookean_impact_on_a_rigid_floor() {
    let (rho, g) = (1.0, 9.81);
    let mut mesh = rectangle(-0.5, 0.5, 0.02, 0.52, 16, 8, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("bottom", BoundaryKind::Contact).unwrap();
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(neo_hookean(50.0, 0.3).unwrap())).unwrap();
    model.body_force(b, move |_, _| Vector::<2>::new(0.0, -rho * g)).unwrap();
    let plane = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0)).unwrap();
    let pairs = vec![ContactPair::rigid("floor", b, "bottom", Arc::new(plane)).with_friction(0.2)];
    let mut st = NonlinearDynamicStepper::new(
        &model,
        &[DynamicBody::elastic(rho)],
        &pairs,
        &[Kinematics::FiniteStrain],
        DynamicParams::new(2e-3),
        newton(),
    )
    .unwrap();
    let n = model.bodies()[0].mesh.n_nodes();
    st.set_initial_state(&model, None, Some(&[vec![Vector::<2>::new(0.5, -2.0); n]])).unwrap();
    let bottom = model.bodies()[0].mesh.boundary_part("bottom").unwrap().nodes();
    let nodes = model.bodies()[0].mesh.nodes().to_vec();
    let (mut max_pen, mut max_neg, mut max_compl, mut max_res, mut max_kkt, mut peak, mut max_strain) =
        (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    let mut contact_steps = 0;
    let e0 = st.energy();
    for _ in 0..120 {
        let rec = st.step(&model, &pdas()).unwrap();
        let u = &st.displacement()[0];
        // the deformed configuration: heights of the contact nodes above the floor
        let geometry = st.geometry();
        let pressure = st.pressure();
        let pmax = pressure.iter().fold(0.0_f64, |m, p| m.max(*p));
        for &i in &bottom {
            max_pen = max_pen.max(-(nodes[i][1] + u[i][1]));
        }
        for (r, node) in geometry.nodes.iter().enumerate() {
            let i = node.node.1;
            let gap = nodes[i][1] + u[i][1];
            max_neg = max_neg.max(-pressure[r] / pmax.max(1e-300));
            if pmax > 0.0 {
                max_compl = max_compl.max((pressure[r] * gap).abs() / pmax);
            }
        }
        if pmax > 0.0 {
            contact_steps += 1;
            peak = peak.max(pmax);
            max_kkt = max_kkt.max(st.last_contact().unwrap().kkt.max());
        }
        max_res = max_res.max(st.last_report().last.residual());
        assert!(rec.pairs[0].normal_force >= 0.0);
        max_strain = max_strain.max(u.iter().map(|v| v.norm()).fold(0.0, Real::max));
    }
    println!(
        "(d) neo-Hookean impact: {contact_steps} contact steps, peak pressure {peak:.3}, max penetration {max_pen:.2e}, \
         negative pressure {max_neg:.2e}, complementarity {max_compl:.2e}, KKT of the linearised solves {max_kkt:.2e}, \
         Newton residual {max_res:.2e}, E_end/E0 = {:.3}",
        st.energy() / e0
    );
    assert!(contact_steps > 10);
    assert!(max_pen <= 1e-10, "penetration {max_pen:e}");
    assert!(max_neg <= 1e-10 && max_compl <= 1e-9, "{max_neg:e} {max_compl:e}");
    assert!(max_kkt <= 1e-8 && max_res <= 1e-12, "{max_kkt:e} {max_res:e}");
}

/// (e) First order in time: the cantilever (neo-Hookean, finite strain, viscous, moving
/// lift, traction) at `T = 0.6` against a reference with `Δt = 0.6/15360`.
#[test]
fn time_convergence_first_order() {
    let t_end = 0.6;
    let run = |n: usize| amplitude_run(8.0, true, n, t_end / n as Real, 8);
    let reference = run(15360);
    let scale = max_norm(&reference);
    let counts = [60usize, 120, 240, 480];
    let errors: Vec<Real> = counts.iter().map(|&n| max_diff(&run(n), &reference) / scale).collect();
    let orders: Vec<Real> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!("(e) Δt = 0.6/{counts:?}: relative max-norm errors {errors:?}, orders {orders:.3?}");
    for p in &orders {
        assert!((0.85..1.2).contains(p), "order {p}");
    }
}

/// (f) Bad input gives typed errors; a step that cannot converge reports its step and time.
#[test]
fn bad_input_gives_typed_errors() {
    let mesh = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Grading::Uniform, Grading::Uniform).unwrap();
    let mut model = Model::<2>::new();
    model.add_body("b", mesh, Arc::new(neo_hookean(1.0, 0.3).unwrap())).unwrap();
    let fs = [Kinematics::FiniteStrain];
    let ok = DynamicBody::elastic(1.0);
    let make = |body: DynamicBody, kin: &[Kinematics], dt: Real, nt: NewtonParams| {
        NonlinearDynamicStepper::new(&model, &[body], &[], kin, DynamicParams::new(dt), nt)
    };
    assert!(
        matches!(make(ok.clone(), &fs, 0.0, newton()), Err(TimeError::InvalidParameter(m)) if m.contains("time step"))
    );
    assert!(
        matches!(make(DynamicBody::elastic(0.0), &fs, 0.1, newton()), Err(TimeError::InvalidParameter(m)) if m.contains("density"))
    );
    assert!(
        matches!(make(ok.clone(), &[], 0.1, newton()), Err(TimeError::InvalidParameter(m)) if m.contains("kinematics"))
    );
    assert!(matches!(
        make(ok.clone(), &fs, 0.1, newton().with_tolerance(2.0)),
        Err(TimeError::NonlinearSetup(synovia_nonlinear::NonlinearError::InvalidParameter(_)))
    ));
    let bad_c1 = DynamicBody {
        density: 1.0,
        damping: 0.0,
        viscous: Some(nalgebra::DMatrix::from_element(3, 3, -1.0)),
    };
    assert!(
        matches!(make(bad_c1, &fs, 0.1, newton()), Err(TimeError::InvalidParameter(m)) if m.contains("viscosity"))
    );
    let coulomb = NonlinearDynamicStepper::new(
        &model,
        std::slice::from_ref(&ok),
        &[],
        &fs,
        DynamicParams::new(0.1).with_coulomb_iterations(3),
        newton(),
    );
    assert!(matches!(coulomb, Err(TimeError::InvalidParameter(m)) if m.contains("Coulomb")));
    let mut st = make(ok, &fs, 0.1, newton()).unwrap();
    assert!(matches!(
        st.set_initial_state(&model, Some(&[vec![Vector::<2>::zeros(); 2]]), None),
        Err(TimeError::InvalidParameter(_))
    ));
    // a velocity that inverts elements within a step, with the cut-back off: a typed step error
    let n = model.bodies()[0].mesh.n_nodes();
    let crush: Nodal =
        vec![model.bodies()[0].mesh.nodes().iter().map(|x| Vector::<2>::new(0.0, -100.0 * x[1])).collect()];
    assert_eq!(crush[0].len(), n);
    st.set_initial_state(&model, None, Some(&crush)).unwrap();
    st.set_max_cutbacks(0);
    match st.step(&model, &pdas()) {
        Err(e @ TimeError::Nonlinear { step: 1, .. }) => println!("(f) {e}"),
        other => panic!("expected a step error, got {other:?}"),
    }
    assert_eq!(st.step_index(), 0);
}

/// Cut-back: a step whose Newton iteration fails (here: at most `k` iterations per step) is
/// replaced by halves; with one halving the step equals two steps of `Δt/2` from the same
/// state (the variable-step form (12.2) with `r = ½`, then `r = 1`).
#[test]
fn a_failing_step_is_cut_into_halves() {
    let mut mesh = rectangle(0.0, 4.0, 0.0, 1.0, 16, 4, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("left", BoundaryKind::Clamped).unwrap();
    let mut model = Model::<2>::new();
    model.add_body("beam", mesh, Arc::new(neo_hookean(1.0e3, 0.3).unwrap())).unwrap();
    let nodes = model.bodies()[0].mesh.nodes().to_vec();
    let u1: Nodal = vec![nodes.iter().map(|x| Vector::<2>::new(0.0, 4.0 * (x[0] / 4.0).powi(2))).collect()];
    let stepper = |dt: Real, max_it: usize| {
        let mut st = NonlinearDynamicStepper::new(
            &model,
            &[kv_body(1.0)],
            &[],
            &[Kinematics::SmallStrain],
            DynamicParams::new(dt),
            newton().with_max_iterations(max_it),
        )
        .unwrap();
        st.set_initial_state(&model, None, Some(&u1)).unwrap();
        st
    };
    // at most 3 Newton iterations: Δt = 0.2 fails, and so does Δt/2; Δt/4 converges
    let (dt, max_it) = (0.2, 3);
    let mut cut = stepper(dt, max_it);
    cut.step(&model, &pdas()).unwrap();
    let report = cut.last_report().clone();
    assert!(report.cutbacks >= 1, "no cut-back");
    assert_eq!(report.substeps, 1 << report.cutbacks);
    assert!((cut.time() - dt).abs() < 1e-15);
    // the reference: steps of Δt/2^k with a Newton iteration free to converge
    let k = report.cutbacks;
    let mut fine = stepper(dt / (1 << k) as Real, 30);
    for _ in 0..report.substeps {
        fine.step(&model, &pdas()).unwrap();
        assert_eq!(fine.last_report().cutbacks, 0);
    }
    let d = max_diff(&cut.displacement().to_vec(), &fine.displacement().to_vec())
        / max_norm(&fine.displacement().to_vec());
    let dv = max_diff(&cut.velocity(), &fine.velocity()) / max_norm(&fine.velocity());
    println!(
        "(cut-back) Δt = {dt} with at most {max_it} Newton iterations: {k} halvings, {} sub-steps; vs {} steps of Δt/{}: displacement {d:.2e}, velocity {dv:.2e}",
        report.substeps,
        report.substeps,
        1 << k
    );
    assert!(d < 1e-10 && dv < 1e-10, "{d:e} {dv:e}");
    assert_eq!(cut.step_index(), 1);
}
