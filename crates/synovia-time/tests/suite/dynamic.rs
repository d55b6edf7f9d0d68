//! Tests of the dynamic semi-implicit Kelvin–Voigt stepper (docs/model.md §7): discrete energy identity,
//! dissipation by damping and viscosity, a free block dropped on a rigid foundation (no
//! penetration, momentum = impulse), first-order convergence in time, and a block sliding with
//! slip-rate-dependent friction that stops.
#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use synovia_contact::operators::{ContactPair, PlaneObstacle};
use synovia_contact::{ContactParams, ExponentialFriction, FrictionLaw};
use synovia_fem::{Model, SymmetricMatrix};
use synovia_material::{isotropic, plane_strain, KelvinVoigt};
use synovia_mesh::generators::{box_mesh, rectangle, Grading};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::{BoundaryKind, Mesh};
use synovia_pdas::Pdas;
use synovia_time::dynamic::{DynamicBody, DynamicParams, DynamicStepper, MassKind};

type Nodal<const D: usize> = Vec<Vec<Vector<D>>>;

fn sub(a: &[Real], b: &[Real]) -> Vec<Real> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

fn pdas() -> Pdas {
    Pdas::new(ContactParams::default().with_tolerance(1e-12))
}

/// Cantilever `[0, 4] × [0, 1]`, clamped on the left, with an initial velocity
/// `u₁ = (0, v x / 4)` and an initial displacement `u₀ = (0, 0.01 (x/4)²)`.
fn cantilever(body: DynamicBody, mass: MassKind, dt: Real) -> (Model<2>, DynamicStepper<2>) {
    let mut mesh = rectangle(0.0, 4.0, 0.0, 1.0, 16, 4, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("left", BoundaryKind::Clamped).unwrap();
    let mut model = Model::<2>::new();
    model.add_body("beam", mesh, Arc::new(plane_strain(1.0e3, 0.3).unwrap())).unwrap();
    let mut params = DynamicParams::new(dt);
    params.mass = mass;
    let mut stepper = DynamicStepper::new(&model, &[body], &[], params).unwrap();
    let nodes = model.bodies()[0].mesh.nodes().to_vec();
    let u0: Nodal<2> =
        vec![nodes.iter().map(|x| Vector::<2>::new(0.0, 0.01 * (x[0] / 4.0).powi(2))).collect()];
    let u1: Nodal<2> = vec![nodes.iter().map(|x| Vector::<2>::new(0.0, 0.1 * x[0] / 4.0)).collect()];
    stepper.set_initial_state(&model, Some(&u0), Some(&u1)).unwrap();
    (model, stepper)
}

/// `½ ‖δ^i − δ^{i−1}‖²_M/Δt² + ½ ‖δ^i‖²_K` from three reduced levels, computed here from the
/// stepper's matrices (not from its energy bookkeeping).
fn numerical_dissipation(
    m: &SymmetricMatrix,
    k: &SymmetricMatrix,
    prev: &[Real],
    cur: &[Real],
    new: &[Real],
    dt: Real,
) -> Real {
    let d = sub(new, cur);
    let d2 = sub(&d, &sub(cur, prev));
    0.5 * m.quadratic_form(&d2) / (dt * dt) + 0.5 * k.quadratic_form(&d)
}

fn energy(m: &SymmetricMatrix, k: &SymmetricMatrix, prev: &[Real], cur: &[Real], dt: Real) -> Real {
    let d = sub(cur, prev);
    0.5 * m.quadratic_form(&d) / (dt * dt) + 0.5 * k.quadratic_form(cur)
}

/// Runs the cantilever and returns the energy per step, checking the discrete energy identity
/// `E^{i+1} − E^i = −D_num − D_visc` at every step (to `1e-10 E^0`).
fn run_cantilever(body: DynamicBody, mass: MassKind, steps: usize) -> Vec<Real> {
    let dt = 0.01;
    let (model, mut st) = cantilever(body, mass, dt);
    let solver = pdas();
    let (m, k) = (st.mass_matrix().clone(), st.stiffness_matrix().clone());
    let mut c = st.damping_matrix().clone();
    c.add_scaled(1.0, st.viscous_matrix()).unwrap();
    let mut e_prev = energy(&m, &k, st.previous_reduced_displacement(), st.reduced_displacement(), dt);
    assert!((e_prev - st.energy()).abs() <= 1e-12 * e_prev);
    let e0 = e_prev;
    let mut out = vec![e0];
    let mut worst: Real = 0.0;
    for _ in 0..steps {
        let prev = st.previous_reduced_displacement().to_vec();
        let cur = st.reduced_displacement().to_vec();
        let rec = st.step(&model, &solver).unwrap();
        let new = st.reduced_displacement().to_vec();
        let e = energy(&m, &k, &cur, &new, dt);
        let d_num = numerical_dissipation(&m, &k, &prev, &cur, &new, dt);
        let delta = sub(&new, &cur);
        let d_visc = c.quadratic_form(&delta) / dt;
        let residual = (e - e_prev) + d_num + d_visc;
        worst = worst.max(residual.abs() / e0);
        assert!(
            residual.abs() <= 1e-10 * e0,
            "energy identity residual {:e} at step {}",
            residual / e0,
            rec.step
        );
        // the stepper's own bookkeeping agrees
        assert!((rec.kinetic_energy + rec.strain_energy - e).abs() <= 1e-10 * e0);
        assert!((rec.viscous_dissipation - d_visc).abs() <= 1e-10 * e0);
        let b = st.energy_balance();
        assert!(b.exact);
        assert!((b.predicted_change() - (e - e_prev)).abs() <= 1e-10 * e0);
        e_prev = e;
        out.push(e);
    }
    println!("energy identity: worst relative residual {worst:.3e} over {steps} steps");
    out
}

#[test]
fn energy_identity_undamped_cantilever() {
    for mass in [MassKind::Consistent, MassKind::Lumped] {
        let e = run_cantilever(DynamicBody::elastic(1.0), mass, 150);
        for w in e.windows(2) {
            assert!(w[1] <= w[0] * (1.0 + 1e-12), "energy increased: {} → {}", w[0], w[1]);
        }
        // the scheme dissipates, but only at O(Δt): most of the energy is still there
        let last = *e.last().unwrap();
        println!("{mass:?}: E_end / E_0 = {:.4}", last / e[0]);
        assert!(last < e[0] && last > 0.2 * e[0]);
    }
}

#[test]
fn damping_and_viscosity_dissipate_faster() {
    let undamped = run_cantilever(DynamicBody::elastic(1.0), MassKind::Consistent, 150);
    let c1 = plane_strain(10.0, 0.3).unwrap().stiffness().clone();
    let kv = KelvinVoigt::<2>::from_linear(
        plane_strain(1.0e3, 0.3).unwrap(),
        plane_strain(10.0, 0.3).unwrap(),
        1.0,
        0.5,
    )
    .unwrap();
    let body = DynamicBody::from_kelvin_voigt(&kv).unwrap();
    assert_eq!(body.viscous.as_ref(), Some(&c1));
    assert_eq!(body.damping, 0.5);
    let damped = run_cantilever(body, MassKind::Consistent, 150);
    for w in damped.windows(2) {
        assert!(w[1] < w[0], "damped energy not strictly decreasing: {} → {}", w[0], w[1]);
    }
    // the first steps differ by the numerical dissipation of two different trajectories;
    // after a tenth of the run the damped energy stays below the undamped one
    for (i, (d, u)) in damped.iter().zip(&undamped).enumerate().skip(15) {
        assert!(d < u, "step {i}: damped energy {d} ≥ undamped {u}");
    }
    let (d, u) = (damped.last().unwrap() / damped[0], undamped.last().unwrap() / undamped[0]);
    println!("E_end/E_0: undamped {u:.4}, damped {d:.4}");
    assert!(d < 0.5 * u);
}

/// A free elastic block (no Dirichlet data) above the rigid plane `x_D = 0`, with contact part
/// `"bottom"`, gravity `−ρ g e_D` and an initial downward velocity.
struct Drop<const D: usize> {
    model: Model<D>,
    stepper: DynamicStepper<D>,
    volume: Real,
    rho: Real,
    g: Real,
    v0: Real,
}

fn drop_setup<const D: usize>(
    mesh: Mesh<D>,
    material: Arc<dyn synovia_material::Material<D>>,
    dt: Real,
) -> Drop<D> {
    let (rho, g, v0) = (1.0, 9.81, 1.0);
    let volume = mesh.measure();
    let mut mesh = mesh;
    mesh.set_part_kind("bottom", BoundaryKind::Contact).unwrap();
    let mut model = Model::<D>::new();
    let b = model.add_body("block", mesh, material).unwrap();
    model
        .body_force(b, move |_, _| {
            let mut f = Vector::<D>::zeros();
            f[D - 1] = -rho * g;
            f
        })
        .unwrap();
    let mut normal = Vector::<D>::zeros();
    normal[D - 1] = 1.0;
    let plane = PlaneObstacle::new(Point::<D>::zeros(), normal).unwrap();
    let pairs = vec![ContactPair::rigid("floor", b, "bottom", Arc::new(plane))];
    let mut stepper =
        DynamicStepper::new(&model, &[DynamicBody::elastic(rho)], &pairs, DynamicParams::new(dt)).unwrap();
    let n = model.bodies()[0].mesh.n_nodes();
    let mut v = Vector::<D>::zeros();
    v[D - 1] = -v0;
    stepper.set_initial_state(&model, None, Some(&[vec![v; n]])).unwrap();
    Drop { model, stepper, volume, rho, g, v0 }
}

/// Runs a drop and checks penetration, momentum = impulse, bounce and the energy identity with
/// contact. Returns (max penetration / size, momentum mismatch relative).
fn check_drop<const D: usize>(mut d: Drop<D>, steps: usize, size: Real) -> (Real, Real) {
    let solver = pdas();
    let dt = d.stepper.dt();
    let mesh = &d.model.bodies()[0].mesh;
    // nodal masses computed here from the mesh: Σ_T ρ|T|/(D+1)
    let mut mass = vec![0.0; mesh.n_nodes()];
    for c in 0..mesh.n_cells() {
        for &a in mesh.cell(c) {
            mass[a] += d.rho * mesh.cell_measure(c) / (D + 1) as Real;
        }
    }
    let total_mass: Real = mass.iter().sum();
    assert!((total_mass - d.rho * d.volume).abs() < 1e-12 * total_mass);
    let bottom: Vec<usize> = mesh.boundary_part("bottom").unwrap().nodes();
    let momentum = |st: &DynamicStepper<D>| -> Vector<D> {
        let v = st.velocity();
        v[0].iter().zip(&mass).map(|(vi, m)| vi * *m).sum()
    };
    let p0 = momentum(&d.stepper);
    assert!((p0[D - 1] + total_mass * d.v0).abs() < 1e-12 * total_mass);
    let mut gravity = Vector::<D>::zeros();
    gravity[D - 1] = -d.rho * d.g * d.volume;
    let mut impulse = Vector::<D>::zeros();
    let mut contact_impulse = Vector::<D>::zeros();
    let (mut max_pen, mut max_up, mut contact_steps): (Real, Real, usize) = (0.0, Real::NEG_INFINITY, 0);
    let mut first_contact = None;
    let e0 = d.stepper.energy();
    let mut worst_identity: Real = 0.0;
    for _ in 0..steps {
        let e_old = d.stepper.energy();
        let rec = d.stepper.step(&d.model, &solver).unwrap();
        let u = &d.stepper.displacement()[0];
        let mesh = &d.model.bodies()[0].mesh;
        for &i in &bottom {
            let h = mesh.node(i)[D - 1] + u[i][D - 1];
            max_pen = max_pen.max(-h / size);
        }
        let f = Vector::<D>::from_fn(|k, _| rec.pairs[0].force[k]);
        assert!(rec.pairs[0].normal_force >= 0.0);
        if rec.pairs[0].normal_force > 0.0 {
            contact_steps += 1;
            first_contact.get_or_insert(rec.step);
        }
        contact_impulse += f * dt;
        impulse += (f + gravity) * dt;
        let p = momentum(&d.stepper);
        if first_contact.is_some() {
            max_up = max_up.max(p[D - 1]);
        }
        // energy identity with contact: E' − E = W_ext − W_c − D_num, W_c ≥ 0
        let b = *d.stepper.energy_balance();
        assert!(b.exact);
        assert!(b.contact_work >= -1e-9 * e0, "contact produced energy: {}", b.contact_work);
        let res = (b.energy() - e_old) - b.predicted_change();
        assert!(res.abs() <= 1e-9 * e0, "energy identity with contact: residual {:e}", res / e0);
        worst_identity = worst_identity.max(res.abs() / e0);
        let kkt = d.stepper.last_contact().unwrap().kkt;
        assert!(kkt.max() < 1e-8, "KKT residuals {kkt:?}");
    }
    let p = momentum(&d.stepper);
    let dp = p - p0;
    let mismatch = (dp - impulse).norm() / contact_impulse.norm().max(gravity.norm() * dt * steps as Real);
    println!(
        "D = {D}: max penetration / size = {max_pen:.3e}, momentum mismatch = {mismatch:.3e}, contact steps {contact_steps}, \
         first contact at step {first_contact:?}, max upward momentum {max_up:.4} (initial {:.4}), \
         energy identity residual {worst_identity:.2e}",
        p0[D - 1]
    );
    assert!(max_pen < 1e-8, "penetration {max_pen:e}");
    assert!(mismatch < 1e-8, "momentum change {dp:?} vs impulse {impulse:?}");
    assert!(contact_steps > 0);
    assert!(max_up > 0.0, "the block never moved up after touching the floor (bounce)");
    // the stepper's own momentum agrees with the one computed here
    assert!((d.stepper.momentum() - p).norm() <= 1e-12 * total_mass * d.v0);
    (max_pen, mismatch)
}

#[test]
fn block_drop_2d_no_penetration_and_momentum_balance() {
    // 1 × ½ block, 0.02 above the floor, falling at 1: contact at t ≈ 0.02
    let mesh = rectangle(-0.5, 0.5, 0.02, 0.52, 12, 6, Grading::Uniform, Grading::Uniform).unwrap();
    let d = drop_setup::<2>(mesh, Arc::new(plane_strain(1.0e3, 0.3).unwrap()), 2e-3);
    check_drop(d, 150, 1.0);
}

#[test]
fn block_drop_3d_no_penetration_and_momentum_balance() {
    let mesh = box_mesh([-0.25, -0.25, 0.01], [0.25, 0.25, 0.51], [3, 3, 3], [Grading::Uniform; 3]).unwrap();
    let d = drop_setup::<3>(mesh, Arc::new(isotropic(1.0e3, 0.3).unwrap()), 2e-3);
    check_drop(d, 80, 0.5);
}

/// Cantilever `[0, 2] × [0, ½]` (8 × 2 cells) clamped on the left, loaded on the right by the
/// smooth traction `(0, −sin²(π t))`, from rest; returns `U(T)` (reduced) at `T = 1`.
fn smooth_run(dt_count: usize) -> (Vec<Real>, SymmetricMatrix) {
    let mut mesh = rectangle(0.0, 2.0, 0.0, 0.5, 8, 2, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("left", BoundaryKind::Clamped).unwrap();
    mesh.set_part_kind("right", BoundaryKind::Traction).unwrap();
    let mut model = Model::<2>::new();
    let b = model.add_body("beam", mesh, Arc::new(plane_strain(1.0e3, 0.3).unwrap())).unwrap();
    model
        .traction(b, "right", |_, _, t| Vector::<2>::new(0.0, -(std::f64::consts::PI * t).sin().powi(2)))
        .unwrap();
    let dt = 1.0 / dt_count as Real;
    let mut st =
        DynamicStepper::new(&model, &[DynamicBody::elastic(1.0)], &[], DynamicParams::new(dt)).unwrap();
    st.run(&model, &pdas(), dt_count).unwrap();
    assert!((st.time() - 1.0).abs() < 1e-12);
    (st.reduced_displacement().to_vec(), st.stiffness_matrix().clone())
}

#[test]
fn time_convergence_first_order() {
    let (reference, k) = smooth_run(80 * 256);
    let norm = |v: &[Real]| k.quadratic_form(v).sqrt();
    let errors: Vec<Real> = [80, 160, 320, 640]
        .iter()
        .map(|&n| norm(&sub(&smooth_run(n).0, &reference)) / norm(&reference))
        .collect();
    let orders: Vec<Real> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!("relative energy-norm errors at T = 1 for Δt = 1/80 … 1/640: {errors:?}, observed orders {orders:.3?}");
    for p in &orders {
        assert!(*p >= 0.9, "observed order {p}");
    }
}

#[test]
fn friction_block_decelerates_and_stops() {
    let (rho, g, v0) = (1.0, 10.0, 1.0);
    let law =
        ExponentialFriction { static_coefficient: 0.4, kinetic_coefficient: 0.25, characteristic_speed: 0.5 };
    let mut mesh = rectangle(-0.5, 0.5, 0.0, 0.25, 8, 2, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("bottom", BoundaryKind::Contact).unwrap();
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0e3, 0.3).unwrap())).unwrap();
    model.body_force(b, move |_, _| Vector::<2>::new(0.0, -rho * g)).unwrap();
    let plane = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0)).unwrap();
    let pairs = vec![ContactPair::rigid("floor", b, "bottom", Arc::new(plane)).with_friction(0.3)];
    // viscosity damps the vibrations started by switching gravity on; it does not act on the
    // rigid sliding motion
    let body = DynamicBody {
        density: rho,
        damping: 0.0,
        viscous: Some(plane_strain(20.0, 0.3).unwrap().stiffness().clone()),
    };
    let dt = 5e-3;
    let mut st = DynamicStepper::new(&model, &[body], &pairs, DynamicParams::new(dt)).unwrap();
    st.set_friction_law("floor", Arc::new(law)).unwrap();
    assert!(st.set_friction_law("nope", Arc::new(law)).is_err());
    let n = model.bodies()[0].mesh.n_nodes();
    st.set_initial_state(&model, None, Some(&[vec![Vector::<2>::new(v0, 0.0); n]])).unwrap();
    // hydrostatic pressure ρ g h on the floor at level 0, so friction acts from the first step
    st.set_initial_pressure(&vec![rho * g * 0.25; st.geometry().len()]).unwrap();
    let total_mass = rho * 0.25;
    let solver = pdas();
    let mut stop_time = None;
    let mut worst_kkt: Real = 0.0;
    let mut last_v = v0;
    let mut records = Vec::new();
    let mut speeds = Vec::new();
    for _ in 0..160 {
        let rec = st.step(&model, &solver).unwrap();
        let kkt = st.last_contact().unwrap().kkt;
        worst_kkt = worst_kkt.max(kkt.max());
        assert!(kkt.satisfied(1e-8), "step {}: KKT {kkt:?}", rec.step);
        let v = st.momentum()[0] / total_mass;
        if stop_time.is_none() {
            // sliding: the centre of mass decelerates monotonically
            assert!(v < last_v, "the block accelerated at step {}: {last_v} → {v}", rec.step);
            if rec.pairs[0].slip_area == 0.0 {
                stop_time = Some(rec.time);
            }
        } else {
            // stuck: only the elastic rebound of the body remains (COM speed ≪ v0)
            assert!(v.abs() < 0.01 * v0, "step {}: v = {v} after sticking", rec.step);
        }
        last_v = v;
        speeds.push(v);
        records.push(rec);
    }
    // rigid-body prediction: v' = −F_c(v) g, integrated finely
    let mut t_pred = 0.0;
    let mut v = v0;
    let h = 1e-6;
    while v > 0.0 {
        v -= h * law.coefficient(v) * g;
        t_pred += h;
    }
    let t_stop = stop_time.expect("the block did not stop");
    let final_v = st.momentum()[0] / total_mass;
    let last = records.last().unwrap();
    let dissipated = last.cumulative_friction_dissipation;
    let kinetic0 = 0.5 * total_mass * v0 * v0;
    println!(
        "stop time {t_stop:.4} (rigid-body prediction {t_pred:.4}), final speed {final_v:.2e}, friction work {dissipated:.5} \
         vs ½ m v0² = {kinetic0:.5}, worst KKT {worst_kkt:.2e}, final stick area {} slip area {}",
        last.pairs[0].stick_area, last.pairs[0].slip_area
    );
    assert!((t_stop - t_pred).abs() < 0.05 * t_pred, "stop time {t_stop} vs {t_pred}");
    assert!(final_v.abs() < 1e-6 * v0);
    assert!(last.pairs[0].slip_area == 0.0 && last.pairs[0].stick_area > 0.0, "not sticking at the end");
    assert!((dissipated - kinetic0).abs() < 0.05 * kinetic0, "friction work {dissipated} vs {kinetic0}");
    // while sliding fast, the friction force is F_c(v) times the normal force
    let mid = &records[10];
    let ratio = mid.pairs[0].tangential_force / mid.pairs[0].normal_force;
    // (g_c lags one level: F_c of the slip speed of the previous step)
    let expected = law.coefficient(speeds[9]);
    assert!((ratio - expected).abs() < 0.02, "friction/normal = {ratio}, F_c(v) ≈ {expected}");
}

/// Moving Dirichlet data: the left side of a viscoelastic block follows the rigid motion
/// `s(t) = v t + ½ a t²` along x, the body force is `ρ a` and the initial velocity
/// `u₁ = v − ½ a Δt` (so that `U^{−1} = s(−Δt)`). The rigid motion then solves the discrete
/// scheme exactly (its second difference is `a Δt²`, it is strain free), so every node must follow
/// it to round-off: this checks the three lift terms of the right-hand side.
#[test]
fn prescribed_rigid_motion_is_reproduced_exactly() {
    let (v, a, rho) = (0.3, 2.0, 1.5);
    let s = move |t: Real| v * t + 0.5 * a * t * t;
    for mass in [MassKind::Consistent, MassKind::Lumped] {
        let mut mesh = rectangle(0.0, 1.0, 0.0, 0.5, 6, 3, Grading::Uniform, Grading::Uniform).unwrap();
        mesh.set_part_kind("left", BoundaryKind::Prescribed).unwrap();
        let mut model = Model::<2>::new();
        let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0e3, 0.3).unwrap())).unwrap();
        model.prescribe(b, "left", move |_, t| Vector::<2>::new(s(t), 0.0)).unwrap();
        model.body_force(b, move |_, _| Vector::<2>::new(rho * a, 0.0)).unwrap();
        let body = DynamicBody {
            density: rho,
            damping: 0.0,
            viscous: Some(plane_strain(5.0, 0.3).unwrap().stiffness().clone()),
        };
        let dt = 0.01;
        let mut params = DynamicParams::new(dt);
        params.mass = mass;
        let mut st = DynamicStepper::new(&model, &[body], &[], params).unwrap();
        let n = model.bodies()[0].mesh.n_nodes();
        st.set_initial_state(&model, None, Some(&[vec![Vector::<2>::new(v - 0.5 * a * dt, 0.0); n]]))
            .unwrap();
        let mut worst: Real = 0.0;
        for _ in 0..50 {
            let rec = st.step(&model, &pdas()).unwrap();
            let exact = Vector::<2>::new(s(rec.time), 0.0);
            for u in &st.displacement()[0] {
                worst = worst.max((u - exact).norm() / exact.norm());
            }
            assert!(!st.energy_balance().exact);
            assert!(rec.strain_energy.abs() < 1e-12, "strain energy {}", rec.strain_energy);
        }
        let speed = st.momentum()[0] / (rho * 0.5);
        println!("{mass:?}: rigid motion reproduced to {worst:.2e} (relative); speed {speed:.6}");
        assert!(worst < 1e-10, "deviation {worst:e}");
        assert!((speed - (v + a * (st.time() - 0.5 * dt))).abs() < 1e-10);
    }
}

#[test]
fn invalid_data_are_errors() {
    let mesh = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Grading::Uniform, Grading::Uniform).unwrap();
    let mut model = Model::<2>::new();
    model.add_body("b", mesh, Arc::new(plane_strain(1.0, 0.3).unwrap())).unwrap();
    let ok = DynamicBody::elastic(1.0);
    assert!(DynamicStepper::new(&model, std::slice::from_ref(&ok), &[], DynamicParams::new(0.0)).is_err());
    assert!(
        DynamicStepper::new(&model, std::slice::from_ref(&ok), &[], DynamicParams::new(Real::NAN)).is_err()
    );
    assert!(DynamicStepper::new(&model, &[], &[], DynamicParams::new(0.1)).is_err());
    assert!(DynamicStepper::new(&model, &[DynamicBody::elastic(-1.0)], &[], DynamicParams::new(0.1)).is_err());
    let bad_c1 = DynamicBody {
        density: 1.0,
        damping: 0.0,
        viscous: Some(nalgebra::DMatrix::from_element(3, 3, -1.0)),
    };
    assert!(DynamicStepper::new(&model, &[bad_c1], &[], DynamicParams::new(0.1)).is_err());
    let mut st = DynamicStepper::new(&model, &[ok], &[], DynamicParams::new(0.1)).unwrap();
    assert!(st.set_initial_state(&model, Some(&[vec![Vector::<2>::zeros(); 2]]), None).is_err());
    assert!(st.set_initial_pressure(&[1.0]).is_err());
    // a free body without contact is fine (M makes A SPD): it just flies
    let rec = st.step(&model, &pdas()).unwrap();
    assert_eq!(rec.step, 1);
}

/// The optional Coulomb fixed point (docs/model.md §3): with `g_c` from the new level, friction acts from
/// the first step without an initial pressure, and on a uniformly slipping block the friction /
/// normal force ratio is `F_c` of the current slip speed.
#[test]
fn coulomb_fixed_point_uses_the_new_level() {
    let (rho, g, v0) = (1.0, 10.0, 1.0);
    let law =
        ExponentialFriction { static_coefficient: 0.4, kinetic_coefficient: 0.25, characteristic_speed: 0.5 };
    let mut mesh = rectangle(-0.5, 0.5, 0.0, 0.25, 8, 2, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("bottom", BoundaryKind::Contact).unwrap();
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0e3, 0.3).unwrap())).unwrap();
    model.body_force(b, move |_, _| Vector::<2>::new(0.0, -rho * g)).unwrap();
    let plane = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0)).unwrap();
    let pairs = vec![ContactPair::rigid("floor", b, "bottom", Arc::new(plane)).with_friction(0.3)];
    let mut params = DynamicParams::new(5e-3);
    params.coulomb_iterations = 100;
    params.coulomb_tolerance = 1e-10;
    let mut st = DynamicStepper::new(&model, &[DynamicBody::elastic(rho)], &pairs, params).unwrap();
    st.set_friction_law("floor", Arc::new(law)).unwrap();
    let n = model.bodies()[0].mesh.n_nodes();
    st.set_initial_state(&model, None, Some(&[vec![Vector::<2>::new(v0, 0.0); n]])).unwrap();
    let mut checked = 0;
    for _ in 0..10 {
        let rec = st.step(&model, &pdas()).unwrap();
        let p = &rec.pairs[0];
        assert!(p.tangential_force > 0.0 && p.slip_area > 0.0, "step {}: no friction", rec.step);
        // Σ_r F_c(s_r) λ_r κ_r over the nodes of the new level, all slipping
        let geo = st.geometry();
        let lambda = st.pressure();
        let expected: Real = geo
            .nodes
            .iter()
            .enumerate()
            .map(|(r, node)| law.coefficient(st.slip_speed()[r]) * lambda[r] * node.weight)
            .sum();
        if p.stick_area == 0.0 {
            assert!(
                (p.tangential_force - expected).abs() <= 1e-8 * expected,
                "step {}: friction {} vs Σ F_c(s) λ κ = {expected}",
                rec.step,
                p.tangential_force
            );
            checked += 1;
        }
        assert!(st.last_contact().unwrap().kkt.satisfied(1e-8));
        assert!(rec.iterations >= 1);
    }
    assert!(checked >= 5, "only {checked} fully slipping steps");
}

/// Initial data from a static contact problem (docs/model.md §7): a block pressed by its prescribed top
/// onto a rigid flat is in static equilibrium; started from that state (`u₀` and the pressure
/// from `StaticContact`, `u₁ = 0`) with constant data, the dynamic scheme stays at rest: with
/// `U^i = U^{i−1} = u₀` the step equation reduces to the static one.
#[test]
fn initial_data_from_a_static_contact_problem_is_an_equilibrium() {
    let mut mesh = rectangle(0.0, 1.0, 0.0, 0.5, 12, 6, Grading::Uniform, Grading::Uniform).unwrap();
    mesh.set_part_kind("top", BoundaryKind::Prescribed).unwrap();
    mesh.set_part_kind("bottom", BoundaryKind::Contact).unwrap();
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3).unwrap())).unwrap();
    model.prescribe(b, "top", |_, _| Vector::<2>::new(0.0, -0.01)).unwrap();
    let curved = synovia_contact::operators::FnObstacle::new(|x: &Point<2>| {
        // a shallow bump: φ = y + 0.05 (x − ½)²
        let g = 0.1 * (x[0] - 0.5);
        let n = (1.0 + g * g).sqrt();
        ((x[1] + 0.05 * (x[0] - 0.5).powi(2)) / n, Vector::<2>::new(g / n, 1.0 / n))
    });
    let pairs = vec![ContactPair::rigid("floor", b, "bottom", Arc::new(curved))];
    let sc = synovia_contact::StaticContact::new(&model, &pairs, Default::default()).unwrap();
    let statics = sc.solve(&model, 0.0, &pdas(), None, None, None).unwrap();
    assert!(statics.kkt.satisfied(1e-10));
    let active = statics.solution.lambda_n.iter().filter(|&&l| l > 0.0).count();
    assert!(active > 0 && active < statics.solution.lambda_n.len());

    let mut stepper =
        DynamicStepper::new(&model, &[DynamicBody::elastic(1.0)], &pairs, DynamicParams::new(1e-2)).unwrap();
    stepper.set_initial_state(&model, Some(&statics.displacement), None).unwrap();
    stepper.set_initial_pressure(&statics.solution.lambda_n).unwrap();
    let scale = statics.displacement[0].iter().fold(0.0_f64, |m, u| m.max(u.norm()));
    for _ in 0..5 {
        stepper.step(&model, &pdas()).unwrap();
        let drift = stepper.displacement()[0]
            .iter()
            .zip(&statics.displacement[0])
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).norm()));
        assert!(drift < 1e-9 * scale, "the static state drifts by {drift:e}");
        let p = stepper.pressure();
        let pmax = statics.solution.lambda_n.iter().fold(0.0_f64, |m, &l| m.max(l));
        for (a, b) in p.iter().zip(&statics.solution.lambda_n) {
            assert!((a - b).abs() < 1e-8 * pmax, "pressure {a} vs static {b}");
        }
    }
}
