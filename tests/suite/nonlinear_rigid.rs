//! Rigid bodies with mixed control in the nonlinear path of `JointModel` (docs/nonlinear.md,
//! "Rigid bodies"): a rigid spherical indenter on a clamped block, posed in five coordinates
//! (two translations and three rotations prescribed) and pushed down by a force history along
//! its vertical translation, the force-controlled coordinate found inside the Newton iteration.
//!
//! * a linear law routed through the Newton path (a material that hides its constant stiffness)
//!   gives the linear path's solution (rigid coordinates, displacements, pressures) to 1e-8;
//! * a neo-Hookean block (finite strain) at a small load equals the linear one to 1 %;
//! * the contact resultant equals the applied force (balance) and the KKT residual of the
//!   contact solution is small;
//! * with Tresca friction against the moving indenter (Coulomb frozen per level), the linear law
//!   through the Newton path equals the linear path (travel, reactions, displacements, normal
//!   and tangential multipliers), the Tresca conditions hold with the slip measured relative to
//!   the indenter, and the force-controlled coordinate balances the applied force including
//!   the friction forces.

use std::sync::Arc;

use synovia::fem::Kinematics;
use synovia::material::{neo_hookean, VoigtMatrix, VoigtVector};
use synovia::prelude::*;
use synovia::rigid::{ForceControlParams, RigidBody};
use synovia::time::history::FnHistory;

type Error = Box<dyn std::error::Error>;

const E: f64 = 1.0e3;
const NU: f64 = 0.3;
const RADIUS: f64 = 2.0;

/// A linear material without a constant stiffness: the model goes through the Newton path.
#[derive(Debug)]
struct Hidden(LinearElastic<3>);

impl Material<3> for Hidden {
    fn stress(&self, strain: &VoigtVector) -> VoigtVector {
        self.0.stress(strain)
    }
    fn tangent(&self, strain: &VoigtVector) -> VoigtMatrix {
        self.0.tangent(strain)
    }
    fn energy_density(&self, strain: &VoigtVector) -> f64 {
        self.0.energy_density(strain)
    }
    fn name(&self) -> String {
        "linear (hidden stiffness)".into()
    }
}

/// The block `[-1, 1]² × [0, 1]` (clamped bottom) with `material`, and the indenter: a rigid
/// sphere of radius 2 touching the top at `(0.15, −0.1, 1)` in its own frame, its reference
/// point `c = (0, 0, 3)`; `tx`, `ty` and the three rotations prescribed (small, so the sphere
/// moves and tilts about a point that is not its centre), `tz` loaded by `−force · t`.
fn model(material: Arc<dyn Material<3>>, force: f64) -> Result<JointModel<3>, Error> {
    model_with_friction(material, force, 0.0)
}

/// [`model`] with the Coulomb coefficient `mu` on the pair with the indenter.
fn model_with_friction(material: Arc<dyn Material<3>>, force: f64, mu: f64) -> Result<JointModel<3>, Error> {
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [12, 12, 6], [Grading::Uniform; 3])?;
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, material)?;
    joint.clamp("block", "bottom")?;
    let centre = Point::<3>::new(0.0, 0.0, 3.0);
    let indenter = RigidBody::<3>::new("indenter", centre)?
        .prescribe(0, FnHistory::new(|t| 0.02 * t))?
        .prescribe(1, Constant(-0.01))?
        .force_with_guess(2, FnHistory::new(move |t| -force * t), Constant(0.0))?
        .prescribe(3, FnHistory::new(|t| 0.01 * t))?
        .prescribe(4, Constant(-0.005))?
        .prescribe(5, Constant(0.02))?;
    joint.add_rigid_body(indenter)?;
    let shape = Arc::new(SphereObstacle::new(Point::<3>::new(0.15, -0.1, 1.0 + RADIUS), RADIUS, false)?);
    joint.contact_rigid_body("indent", "block", "top", "indenter", shape, mu)?;
    // both paths accept a solution whose contact geometry was built within the geometry
    // tolerance of its pose (the rows' normals are those of that pose: first order in the
    // distance): a tight one, so that the two agree to 1e-8 and not to the default 1e-6
    joint.force_control(ForceControlParams { geometry_tolerance: 1e-10, ..ForceControlParams::default() });
    Ok(joint)
}

fn max_abs(u: &[Vec<Vector<3>>]) -> f64 {
    u.iter().flatten().map(|v| v.amax()).fold(0.0, f64::max)
}

/// The largest pressure `Λ_n` of `a` and the largest difference of `b` from it relative to it:
/// `(max a, max |a − b| / max a)`.
fn pressure_difference(a: &[f64], b: &[f64]) -> (f64, f64) {
    let lmax = a.iter().copied().fold(0.0, f64::max);
    (lmax, a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / lmax)
}

fn max_diff(a: &[Vec<Vector<3>>], b: &[Vec<Vector<3>>]) -> f64 {
    a.iter().flatten().zip(b.iter().flatten()).map(|(x, y)| (x - y).amax()).fold(0.0, f64::max)
}

/// The linear law through the Newton path equals the linear path, level by level.
#[test]
fn linear_law_through_newton_equals_the_linear_path() -> Result<(), Error> {
    let force = 20.0;
    let times = [0.5, 1.0];
    let linear = model(Arc::new(isotropic(E, NU)?), force)?;
    assert!(!linear.is_nonlinear());
    let routed = model(Arc::new(Hidden(isotropic(E, NU)?)), force)?;
    assert!(routed.is_nonlinear());
    let mut runs = Vec::new();
    for joint in [&linear, &routed] {
        let mut fields = Vec::new();
        let run = joint.run_quasistatic_with(&times, |view| {
            fields.push((view.result.displacement.clone(), view.result.solution.lambda_n.clone()));
            Ok(())
        })?;
        runs.push((run, fields));
    }
    let ((lin, lin_fields), (nl, nl_fields)) = (&runs[0], &runs[1]);
    for (level, (a, b)) in lin.records.iter().zip(&nl.records).enumerate() {
        let (ra, rb) = (&a.rigid[0], &b.rigid[0]);
        // the force-controlled travel, relative to itself; the prescribed coordinates exactly
        let travel = (ra.dofs[2] - rb.dofs[2]).abs() / ra.dofs[2].abs();
        assert!(travel < 1e-8, "level {level}: tz {} vs {} ({travel:e})", ra.dofs[2], rb.dofs[2]);
        for k in [0, 1, 3, 4, 5] {
            assert_eq!(ra.dofs[k], rb.dofs[k], "level {level}, dof {k}");
        }
        for k in 0..6 {
            let d = (ra.reaction[k] - rb.reaction[k]).abs() / force;
            assert!(d < 1e-8, "level {level}: reaction {k}: {:?} vs {:?}", ra.reaction, rb.reaction);
        }
        let (ua, la) = &lin_fields[level];
        let (ub, lb) = &nl_fields[level];
        let du = max_diff(ua, ub) / max_abs(ua);
        assert!(du < 1e-8, "level {level}: displacements differ by {du:e}");
        let (_, dl) = pressure_difference(la, lb);
        assert!(dl < 1e-8, "level {level}: pressures differ by {dl:e}");
        assert!(a.pairs[0].peak_pressure > 0.0 && b.pairs[0].contact_area > 0.0);
        eprintln!("level {level}: linear law through Newton vs linear path: travel {travel:.1e}, displacements {du:.1e}, pressures {dl:.1e}");
    }
    Ok(())
}

/// Balance and KKT of the Newton path's solution, and neo-Hookean (finite strain) at a small
/// load against linear: the same travel, force and pressures to 1 %.
#[test]
fn neo_hookean_at_a_small_load_equals_linear_and_balances() -> Result<(), Error> {
    // a strain of about 1e-3 under the indenter
    let force = 2.0;
    let linear = model(Arc::new(isotropic(E, NU)?), force)?;
    let mut hyper = model(Arc::new(neo_hookean(E, NU)?), force)?;
    hyper.set_kinematics("block", Kinematics::FiniteStrain)?;
    assert!(hyper.is_nonlinear());
    let lin = linear.run_static(1.0)?;
    let mut kkt = Vec::new();
    let nh = hyper.run_quasistatic_with(&[0.5, 1.0], |view| {
        kkt.push(view.result.kkt.max());
        Ok(())
    })?;
    for (level, rec) in nh.records.iter().enumerate() {
        let rigid = &rec.rigid[0];
        let applied = force * rec.time;
        // the force-controlled coordinate balances the applied force: the generalised reaction
        // and the contact resultant along z
        assert!(rigid.balance_error < 1e-9, "level {level}: {rigid:?}");
        assert!((rigid.reaction[2] - applied).abs() < 1e-9 * force, "level {level}: {rigid:?}");
        assert!((rec.pairs[0].force[2] + applied).abs() < 1e-9 * force, "level {level}: {:?}", rec.pairs[0]);
        assert!(kkt[level] < 1e-8, "level {level}: KKT {:e}", kkt[level]);
        assert!(rigid.solves > 0);
    }
    let (a, b) = (&lin.records[0], &nh.records[1]);
    let travel = (a.rigid[0].dofs[2] - b.rigid[0].dofs[2]).abs() / a.rigid[0].dofs[2].abs();
    assert!(travel < 0.01, "travel: linear {} vs neo-Hookean {}", a.rigid[0].dofs[2], b.rigid[0].dofs[2]);
    let peak = (a.pairs[0].peak_pressure - b.pairs[0].peak_pressure).abs() / a.pairs[0].peak_pressure;
    assert!(
        peak < 0.01,
        "peak pressure: linear {} vs neo-Hookean {}",
        a.pairs[0].peak_pressure,
        b.pairs[0].peak_pressure
    );
    let normal = (a.pairs[0].normal_force - b.pairs[0].normal_force).abs() / a.pairs[0].normal_force;
    assert!(normal < 0.01, "normal force: {} vs {}", a.pairs[0].normal_force, b.pairs[0].normal_force);
    eprintln!("neo-Hookean vs linear at F = {force}: travel {travel:.2e}, peak pressure {peak:.2e}, normal force {normal:.2e}");
    // and the run is not the linear one: the finite-strain solution differs (a test that can fail)
    assert!(travel > 0.0);
    Ok(())
}

/// What the nonlinear path does not take is refused with a typed error: a force-controlled
/// coordinate that nothing resists.
#[test]
fn unsupported_rigid_cases_are_refused() -> Result<(), Error> {
    let shape = Arc::new(SphereObstacle::new(Point::<3>::new(0.0, 0.0, 3.0), RADIUS, false)?);
    // two force-controlled coordinates, one a rotation of the sphere about its own centre under
    // a moment: nothing resists it (the contact forces pass through the centre)
    let mut two = JointModel::<3>::new();
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [4, 4, 2], [Grading::Uniform; 3])?;
    two.add_body("block", mesh, Arc::new(neo_hookean(E, NU)?) as Arc<dyn Material<3>>)?;
    two.clamp("block", "bottom")?;
    let indenter = RigidBody::<3>::new("indenter", Point::<3>::new(0.0, 0.0, 3.0))?
        .force(2, Constant(-1.0))?
        .force(3, Constant(0.5))?;
    two.add_rigid_body(indenter)?;
    two.contact_rigid_body("indent", "block", "top", "indenter", shape, 0.0)?;
    let err = two.run_static(1.0).err().ok_or("an unresisted force-controlled coordinate accepted")?;
    assert!(matches!(err, JointError::Invalid(_)) && err.to_string().contains("not resisted"), "{err}");
    assert!(err.to_string().contains(".rx"), "{err}");

    Ok(())
}

/// One level's fields: displacement, `Λ_n`, friction cells with `(node, g, Λ_t)`.
type Fields = (Vec<Vec<Vector<3>>>, Vec<f64>, Vec<(usize, f64, Vec<f64>)>);

fn fields_of(view: &StepView<'_, 3>) -> Fields {
    let r = view.result;
    let cells = r
        .cell_node
        .iter()
        .zip(&r.slip_bound)
        .enumerate()
        .map(|(c, (&node, &g))| (node, g, r.solution.lambda_t[2 * c..2 * c + 2].to_vec()))
        .collect();
    (r.displacement.clone(), r.solution.lambda_n.clone(), cells)
}

/// Tresca friction against the moving indenter: the linear law through the Newton path equals
/// the linear path level by level; the Tresca conditions (`‖Λ_t‖ ≤ 1`, the slip relative to the
/// indenter zero where it sticks and along `Λ_t` where it slips) and the balance of the
/// force-controlled coordinate (friction forces included) hold.
#[test]
fn friction_against_the_rigid_body_equals_the_linear_path() -> Result<(), Error> {
    let force = 20.0;
    let mu = 0.3;
    let linear = model_with_friction(Arc::new(isotropic(E, NU)?), force, mu)?;
    let routed = model_with_friction(Arc::new(Hidden(isotropic(E, NU)?)), force, mu)?;
    compare_friction_runs(&linear, &routed, &[0.4, 0.7, 1.0], mu, Some(force))?;
    Ok(())
}

/// The indenter of [`model_with_friction`] with every coordinate prescribed: pressed down by
/// `0.03 t` while it slides by `0.006 t` along x and tilts by `0.002 t` about x (friction
/// against a rigid body without force control: cells stick and slip).
fn model_prescribed(material: Arc<dyn Material<3>>, mu: f64) -> Result<JointModel<3>, Error> {
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [12, 12, 6], [Grading::Uniform; 3])?;
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, material)?;
    joint.clamp("block", "bottom")?;
    let indenter = RigidBody::<3>::new("indenter", Point::<3>::new(0.0, 0.0, 3.0))?
        .prescribe(0, FnHistory::new(|t| 0.006 * t))?
        .prescribe(1, Constant(-0.01))?
        .prescribe(2, FnHistory::new(|t| -0.03 * t))?
        .prescribe(3, FnHistory::new(|t| 0.002 * t))?
        .prescribe(4, Constant(-0.005))?
        .prescribe(5, Constant(0.02))?;
    joint.add_rigid_body(indenter)?;
    let shape = Arc::new(SphereObstacle::new(Point::<3>::new(0.15, -0.1, 1.0 + RADIUS), RADIUS, false)?);
    joint.contact_rigid_body("indent", "block", "top", "indenter", shape, mu)?;
    Ok(joint)
}

/// Tresca friction against a rigid body whose coordinates are all prescribed (it slides and
/// tilts on the block): the linear law through the Newton path equals the linear path level by
/// level (displacements, `Λ_n`, `Λ_t`, reactions to 1e-10), the slip measured relative to the
/// body's prescribed motion since the last level; the Tresca and KKT conditions hold.
#[test]
fn friction_against_a_prescribed_rigid_body_equals_the_linear_path() -> Result<(), Error> {
    let mu = 0.3;
    let linear = model_prescribed(Arc::new(isotropic(E, NU)?), mu)?;
    let routed = model_prescribed(Arc::new(Hidden(isotropic(E, NU)?)), mu)?;
    assert!(routed.is_nonlinear() && !linear.is_nonlinear());
    let sticking = compare_friction_runs(&linear, &routed, &[0.3, 0.55, 0.8, 1.0], mu, None)?;
    // both branches of the Tresca check: cells slipped (checked above) and stuck
    assert!(sticking > 0, "no cell stuck");
    Ok(())
}

/// Runs `linear` and `routed` (the same model, the second through the Newton path) at `times`
/// and compares them level by level: rigid coordinates and reactions, displacements, `Λ_n`,
/// friction cells, slip bounds and `g Λ_t`, tangential forces (1e-10 for all-prescribed bodies,
/// 1e-8 with a force-controlled coordinate: the iteration's tolerance); checks Tresca
/// (`‖Λ_t‖ ≤ 1`, the slip relative to the rigid body zero where it sticks and along `Λ_t` where
/// it slips) and KKT of the Newton path's solution, and the balance of the force-controlled
/// `tz` under `force · t` if there is one. Returns the number of sticking cells (all levels).
fn compare_friction_runs(
    linear: &JointModel<3>,
    routed: &JointModel<3>,
    times: &[f64],
    mu: f64,
    force: Option<f64>,
) -> Result<usize, Error> {
    let tol = if force.is_some() { 1e-8 } else { 1e-10 };
    let mut runs = Vec::new();
    for joint in [linear, routed] {
        let mut fields: Vec<Fields> = Vec::new();
        let mut checks = Vec::new();
        let run = joint.run_quasistatic_with(times, |view| {
            let f = fields_of(view);
            // Tresca at the friction cells, the slip relative to the indenter
            // (`ContactGeometry::slip_origin`: the previous level's jump plus the indenter's
            // motion since then)
            let (mut bound, mut stick, mut slip_dir, mut slip_max) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
            let (mut sticking, mut slipping) = (0usize, 0usize);
            if let Some((previous, _, _)) = fields.last() {
                for (r, g, lt) in &f.2 {
                    assert!(*g > 0.0);
                    let node = &view.geometry.nodes[*r];
                    let du =
                        view.geometry.jump(*r, &f.0).ok_or_else(|| JointError::Invalid("jump".into()))?
                            - view
                                .geometry
                                .slip_origin(*r, previous)
                                .ok_or_else(|| JointError::Invalid("slip origin".into()))?;
                    let s = [node.tangents[0].dot(&du), node.tangents[1].dot(&du)];
                    let s_norm = s[0].hypot(s[1]);
                    let l_norm = lt[0].hypot(lt[1]);
                    slip_max = slip_max.max(s_norm);
                    bound = bound.max(l_norm - 1.0);
                    if l_norm < 1.0 - 1e-6 {
                        stick = stick.max(s_norm);
                        sticking += 1;
                    } else {
                        slipping += 1;
                        // slipping: the slip along Λ_t, ‖s‖ − s·Λ_t = 0
                        slip_dir = slip_dir.max(s_norm - (s[0] * lt[0] + s[1] * lt[1]));
                    }
                }
            }
            checks.push((bound, stick, slip_dir, slip_max, view.result.kkt.max(), sticking, slipping));
            fields.push(f);
            Ok(())
        })?;
        runs.push((run, fields, checks));
    }
    let ((lin, lin_fields, _), (nl, nl_fields, nl_checks)) = (&runs[0], &runs[1]);
    assert_eq!(lin.records.len(), times.len());
    assert_eq!(nl.records.len(), times.len());
    let mut tangential = 0.0_f64;
    for (level, (a, b)) in lin.records.iter().zip(&nl.records).enumerate() {
        let (ra, rb) = (&a.rigid[0], &b.rigid[0]);
        let travel = (ra.dofs[2] - rb.dofs[2]).abs() / ra.dofs[2].abs();
        assert!(travel < tol, "level {level}: tz {} vs {} ({travel:e})", ra.dofs[2], rb.dofs[2]);
        let scale = force.unwrap_or_else(|| ra.reaction.iter().map(|v| v.abs()).fold(0.0, f64::max));
        assert!(scale > 0.0, "level {level}: no reaction");
        let mut dr = 0.0_f64;
        for k in 0..6 {
            let d = (ra.reaction[k] - rb.reaction[k]).abs() / scale;
            assert!(d < tol, "level {level}: reaction {k}: {:?} vs {:?}", ra.reaction, rb.reaction);
            dr = dr.max(d);
        }
        let (ua, la, ca) = &lin_fields[level];
        let (ub, lb, cb) = &nl_fields[level];
        let du = max_diff(ua, ub) / max_abs(ua);
        assert!(du < tol, "level {level}: displacements differ by {du:e}");
        let (lmax, dl) = pressure_difference(la, lb);
        assert!(dl < tol, "level {level}: pressures differ by {dl:e}");
        // the same friction cells, slip bounds and tangential multipliers
        assert_eq!(ca.len(), cb.len(), "level {level}: friction cells");
        let mut dt = 0.0_f64;
        for ((na, ga, lta), (nb, gb, ltb)) in ca.iter().zip(cb) {
            assert_eq!(na, nb, "level {level}");
            assert!((ga - gb).abs() <= tol * mu * lmax, "level {level}: g {ga} vs {gb}");
            dt = dt.max((ga * lta[0] - gb * ltb[0]).abs()).max((ga * lta[1] - gb * ltb[1]).abs());
        }
        let dt = dt / (mu * lmax);
        assert!(dt < tol, "level {level}: friction tractions differ by {dt:e}");
        let (ta, tb) = (a.pairs[0].tangential_force, b.pairs[0].tangential_force);
        let dft = (ta - tb).abs() / scale;
        assert!(dft < tol, "level {level}: tangential force {ta} vs {tb}");
        tangential = tangential.max(tb / scale);
        // Tresca and KKT of the Newton path's solution
        let (bound, stick, slip_dir, slip_max, kkt, sticking, slipping) = nl_checks[level];
        assert!(bound <= 1e-10, "level {level}: ‖Λ_t‖ − 1 = {bound:e}");
        assert!(stick <= 1e-9 * max_abs(ub), "level {level}: slip {stick:e} at a sticking cell");
        assert!(slip_dir <= 1e-9 * max_abs(ub), "level {level}: slip not along Λ_t ({slip_dir:e})");
        assert!(kkt < 1e-8, "level {level}: KKT {kkt:e}");
        if let Some(force) = force {
            // the force-controlled coordinate balances the applied force, friction included
            let applied = force * b.time;
            assert!(rb.balance_error < 1e-9, "level {level}: {rb:?}");
            assert!((rb.reaction[2] - applied).abs() < 1e-9 * force, "level {level}: {rb:?}");
            assert!((b.pairs[0].force[2] + applied).abs() < 1e-9 * force, "level {level}: {:?}", b.pairs[0]);
        }
        eprintln!(
            "friction level {level}: travel {travel:.1e}, reactions {dr:.1e}, displacements {du:.1e}, pressures {dl:.1e}, friction tractions {dt:.1e}, tangential force {tb:.4} N ({dft:.1e}); Tresca: ‖Λ_t‖−1 {bound:.1e}, stick slip {stick:.1e}, slip direction {slip_dir:.1e}, slip max {slip_max:.1e} ({sticking} cells sticking, {slipping} slipping), KKT {kkt:.1e}, balance {:.1e}",
            rb.balance_error
        );
    }
    // friction acted (the tangential forces are not zero) and some cells slipped
    assert!(tangential > 1e-3, "tangential force {tangential} of the reaction");
    assert!(nl_checks.iter().any(|c| c.3 > 0.0));
    assert!(nl_checks.iter().any(|c| c.6 > 0), "no cell slipped");
    Ok(nl_checks.iter().map(|c| c.5).sum())
}

/// The normal of a posed triangle surface at points within rounding reach of it (the contact
/// nodes of a converged finite-strain geometry lie on the rigid surface): the gradient of the
/// signed distance equals the facet's normal (rotated by the pose) to 1e-9, not to the
/// `ε |X| / |φ|` of `(X − c)/|X − c|` (measured before `PosedObstacle` took it `h = 1e-6 |X|`
/// outside: 2.6e-6 at |φ| = 1e-9 on this patch; on the tkr3d femur, the normal of one contact node
/// moved by 1.6e-6 between geometry passes at φ = 1.3e-9 mm and the passes of the 6 % pose with
/// friction did not settle, docs/nonlinear.md).
#[test]
fn posed_surface_normal_is_exact_at_the_surface() -> Result<(), Error> {
    use synovia::contact_ops::operators::SignedDistance;
    use synovia::rigid::{PosedObstacle, SharedPose};
    // a tilted planar patch of 4 × 4 squares of 10 mm, 50 mm from the origin
    let origin = Point::<3>::new(40.0, 30.0, -20.0);
    let (a, b) = (Vector::<3>::new(0.8, 0.1, 0.3).normalize(), Vector::<3>::new(-0.2, 0.9, 0.4));
    let b = (b - a * a.dot(&b)).normalize();
    let normal = a.cross(&b);
    let n = 4;
    let vertices: Vec<Point<3>> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| origin + a * (10.0 * i as f64) + b * (10.0 * j as f64)))
        .collect();
    let id = |i: usize, j: usize| i * (n + 1) + j;
    let triangles: Vec<[usize; 3]> = (0..n)
        .flat_map(|i| {
            (0..n).flat_map(move |j| {
                [[id(i, j), id(i + 1, j), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i, j + 1)]]
            })
        })
        .collect();
    let surface = SurfaceObstacle::new(TriangleSurface::new(vertices, triangles)?)?;
    let pose = RigidBody::<3>::new("femur", Point::<3>::new(1.0, 2.0, 3.0))?
        .pose_of(&[3.0, -2.0, 5.0, 0.3, -0.2, 0.5]);
    let posed = PosedObstacle::new(Arc::new(surface), SharedPose::new(pose));
    let expected = pose.rotation * normal;
    let mut worst: f64 = 0.0;
    // the centroids of the 32 facets (on a facet's edge or vertex the direction from the feature
    // is the gradient, and the offset point lies on the same ray: the rounding stays there)
    let centroids = (0..n).flat_map(|i| {
        (0..n).flat_map(move |j| {
            let (i, j) = (10.0 * i as f64, 10.0 * j as f64);
            [(i + 20.0 / 3.0, j + 10.0 / 3.0), (i + 10.0 / 3.0, j + 20.0 / 3.0)]
        })
    });
    for (s, t) in centroids {
        for phi in [1e-8, 3e-9, 1e-9, 2e-10, -1e-9, -1e-8, 0.5] {
            let x = pose.position(&(origin + a * s + b * t + normal * phi));
            let (d, g) = posed.distance_and_gradient(&x);
            assert!((d - phi).abs() <= 1e-11, "distance {d} for {phi}");
            let (_, gw) = posed.distance_and_gradient_within(&x, 1.0);
            worst = worst
                .max((g - expected).norm())
                .max((gw - expected).norm())
                .max((posed.gradient(&x) - expected).norm());
        }
    }
    assert!(worst <= 1e-9, "the normal at the surface is off by {worst:e}");
    Ok(())
}

/// The indenter with its reference point `c = (0, 0, 0)` below the sphere (centre `(0, 0, 3)`,
/// radius 2, touching the top of the block): `tx`, `ty`, `rz` prescribed, `tz` loaded by
/// `−force · t`, and the moments `mx · t`, `my · t` about `x` and `y` on `rx`, `ry` when given
/// (force-controlled: the contact point settles where the contact force balances them, ≈ 3
/// length units below `c`'s rotation).
fn model_several(
    material: Arc<dyn Material<3>>,
    force: f64,
    mx: Option<f64>,
    my: Option<f64>,
) -> Result<JointModel<3>, Error> {
    model_several_with_friction(material, force, mx, my, 0.0)
}

/// [`model_several`] with the Coulomb coefficient `mu` on the pair with the indenter.
fn model_several_with_friction(
    material: Arc<dyn Material<3>>,
    force: f64,
    mx: Option<f64>,
    my: Option<f64>,
    mu: f64,
) -> Result<JointModel<3>, Error> {
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [12, 12, 6], [Grading::Uniform; 3])?;
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, material)?;
    joint.clamp("block", "bottom")?;
    let mut indenter = RigidBody::<3>::new("indenter", Point::<3>::new(0.0, 0.0, 0.0))?
        .prescribe(0, FnHistory::new(|t| 0.01 * t))?
        .prescribe(1, Constant(-0.005))?
        .force_with_guess(2, FnHistory::new(move |t| -force * t), Constant(0.0))?
        .prescribe(5, Constant(0.02))?;
    indenter = match mx {
        Some(m) => indenter.force(3, FnHistory::new(move |t| m * t))?,
        None => indenter.prescribe(3, Constant(0.0))?,
    };
    indenter = match my {
        Some(m) => indenter.force(4, FnHistory::new(move |t| m * t))?,
        None => indenter.prescribe(4, Constant(0.0))?,
    };
    joint.add_rigid_body(indenter)?;
    let shape = Arc::new(SphereObstacle::new(Point::<3>::new(0.0, 0.0, 1.0 + RADIUS), RADIUS, false)?);
    joint.contact_rigid_body("indent", "block", "top", "indenter", shape, mu)?;
    // a tight balance: the rotations' coordinates are known to `tolerance × scale / stiffness`
    // (1e-10 × 56 N mm / ≈ 60 N mm/rad ≈ 1e-10 rad, 2e-8 of the angles); and the geometry
    // tolerance of `model`
    joint.force_control(ForceControlParams {
        tolerance: 1e-12,
        geometry_tolerance: 1e-10,
        max_solves: 200,
        ..ForceControlParams::default()
    });
    Ok(joint)
}

/// Two and three force-controlled coordinates (`tz` and `ry`; `tz`, `rx` and `ry`): the linear
/// law through the Newton path (`tz` inside the iteration, the rotations by the quasi-Newton
/// iteration around it) equals the linear path level by level (coordinates, reactions,
/// displacements, pressures to 1e-8), and every force-controlled coordinate balances its load.
#[test]
fn several_force_controlled_coordinates_equal_the_linear_path() -> Result<(), Error> {
    let force = 20.0;
    for (mx, my) in [(None, Some(-0.3)), (Some(0.2), Some(-0.3))] {
        let linear = model_several(Arc::new(isotropic(E, NU)?), force, mx, my)?;
        let routed = model_several(Arc::new(Hidden(isotropic(E, NU)?)), force, mx, my)?;
        assert!(routed.is_nonlinear() && !linear.is_nonlinear());
        let times = [0.5, 1.0];
        let mut runs = Vec::new();
        for joint in [&linear, &routed] {
            let mut fields = Vec::new();
            let clock = std::time::Instant::now();
            let run = joint.run_quasistatic_with(&times, |view| {
                fields.push((view.result.displacement.clone(), view.result.solution.lambda_n.clone()));
                Ok(())
            })?;
            runs.push((run, fields, clock.elapsed().as_secs_f64()));
        }
        let ((lin, lin_fields, lin_s), (nl, nl_fields, nl_s)) = (&runs[0], &runs[1]);
        let free: Vec<usize> = [Some(2), mx.map(|_| 3), my.map(|_| 4)].into_iter().flatten().collect();
        for (level, (a, b)) in lin.records.iter().zip(&nl.records).enumerate() {
            let (ra, rb) = (&a.rigid[0], &b.rigid[0]);
            let mut dq = 0.0_f64;
            for k in 0..6 {
                if free.contains(&k) {
                    let d = (ra.dofs[k] - rb.dofs[k]).abs() / ra.dofs[k].abs();
                    assert!(d < 1e-8, "level {level}: dof {k}: {:?} vs {:?}", ra.dofs, rb.dofs);
                    dq = dq.max(d);
                } else {
                    assert_eq!(ra.dofs[k], rb.dofs[k], "level {level}, dof {k}");
                }
            }
            let mut dr = 0.0_f64;
            for k in 0..6 {
                let d = (ra.reaction[k] - rb.reaction[k]).abs() / force;
                assert!(d < 1e-8, "level {level}: reaction {k}: {:?} vs {:?}", ra.reaction, rb.reaction);
                dr = dr.max(d);
            }
            // every force-controlled coordinate balances its load
            assert!(rb.balance_error <= 1e-12, "level {level}: {rb:?}");
            assert!(ra.balance_error <= 1e-12, "level {level}: {ra:?}");
            let (ua, la) = &lin_fields[level];
            let (ub, lb) = &nl_fields[level];
            let du = max_diff(ua, ub) / max_abs(ua);
            assert!(du < 1e-8, "level {level}: displacements differ by {du:e}");
            let (_, dl) = pressure_difference(la, lb);
            assert!(dl < 1e-8, "level {level}: pressures differ by {dl:e}");
            eprintln!(
                "{} force-controlled, level {level}: q {:?}; coordinates {dq:.1e}, reactions {dr:.1e}, displacements {du:.1e}, pressures {dl:.1e}, balance {:.1e}; Newton path: {} Newton iterations, {} contact solves; linear path: {} contact solves",
                free.len(),
                rb.dofs,
                rb.balance_error,
                b.iterations,
                rb.solves,
                ra.solves
            );
        }
        // the rotations moved (the moments are carried by the contact point's offset)
        assert!(nl.records[1].rigid[0].dofs[4].abs() > 1e-4, "{:?}", nl.records[1].rigid[0].dofs);
        eprintln!("{} force-controlled: linear path {lin_s:.3} s, Newton path {nl_s:.3} s", free.len());
    }
    Ok(())
}

/// Three force-controlled coordinates with a neo-Hookean block (finite strain) at a small load
/// (force 10, moments 1.0 and −1.5) equal the linear path: travel and normal force to 1 %, the
/// rotations to 2 % and the peak pressure to 2.5 %; each coordinate balanced to its tolerance.
#[test]
fn several_force_controlled_coordinates_neo_hookean_at_a_small_load() -> Result<(), Error> {
    let force = 10.0;
    let linear = model_several(Arc::new(isotropic(E, NU)?), force, Some(1.0), Some(-1.5))?;
    let mut hyper = model_several(Arc::new(neo_hookean(E, NU)?), force, Some(1.0), Some(-1.5))?;
    hyper.set_kinematics("block", Kinematics::FiniteStrain)?;
    let lin = linear.run_static(1.0)?;
    let clock = std::time::Instant::now();
    let nh = hyper.run_quasistatic(&[0.5, 1.0])?;
    let seconds = clock.elapsed().as_secs_f64();
    for (level, rec) in nh.records.iter().enumerate() {
        let rigid = &rec.rigid[0];
        assert!(rigid.balance_error <= 1e-10, "level {level}: {rigid:?}");
        eprintln!(
            "neo-Hookean, level {level}: q {:?}, balance {:.1e}, {} Newton iterations, {} contact solves",
            rigid.dofs, rigid.balance_error, rec.iterations, rigid.solves
        );
    }
    let (a, b) = (&lin.records[0], &nh.records[1]);
    // the travel to 1 %; the rotations to 2 %: they place the contact centroid where the
    // contact force balances the moments (0.1 and 0.15 from the centre), and finite strain
    // moves the contact region sideways by ≈ 1.7e-3 against small strain (measured: the
    // rotations differ by 17 % and 7 % with moments of 0.1, 0.15 at this force, offsets 0.01, 0.015)
    for (k, tolerance) in [(2, 0.01), (3, 0.02), (4, 0.02)] {
        let d = (a.rigid[0].dofs[k] - b.rigid[0].dofs[k]).abs() / a.rigid[0].dofs[k].abs();
        assert!(d < tolerance, "dof {k}: linear {:?} vs neo-Hookean {:?}", a.rigid[0].dofs, b.rigid[0].dofs);
        eprintln!("neo-Hookean vs linear, dof {k}: {d:.2e}");
    }
    let normal = (a.pairs[0].normal_force - b.pairs[0].normal_force).abs() / a.pairs[0].normal_force;
    let peak = (a.pairs[0].peak_pressure - b.pairs[0].peak_pressure).abs() / a.pairs[0].peak_pressure;
    // the peak pressure (one node's value) to 2.5 %: it follows the contact region's position
    assert!(normal < 0.01 && peak < 0.025, "normal force {normal:e}, peak pressure {peak:e}");
    eprintln!("neo-Hookean vs linear: normal force {normal:.2e}, peak pressure {peak:.2e}; {seconds:.2} s");
    Ok(())
}

/// Three force-controlled coordinates with Tresca friction (μ = 0.05) against the indenter: the
/// linear law through the Newton path equals the linear path (coordinates, reactions,
/// displacements, `Λ_n`, `g Λ_t` to 1e-8), Tresca and KKT hold, `tz` balances its load with
/// the friction forces.
#[test]
fn several_force_controlled_coordinates_with_friction_equal_the_linear_path() -> Result<(), Error> {
    let (force, mu) = (20.0, 0.05);
    let linear = model_several_with_friction(Arc::new(isotropic(E, NU)?), force, Some(0.2), Some(-0.3), mu)?;
    let routed =
        model_several_with_friction(Arc::new(Hidden(isotropic(E, NU)?)), force, Some(0.2), Some(-0.3), mu)?;
    compare_friction_runs(&linear, &routed, &[0.4, 0.7, 1.0], mu, Some(force))?;
    Ok(())
}

/// The exponential static-to-kinetic law of the friction-law tests: `μ_s = 0.4`, `μ_k = 0.1`,
/// `v_c = 2·10⁻³` (the sliding here is ≈ 6·10⁻³ per unit time): `(μ_s, μ_k, F_c)`.
fn exponential_law() -> (f64, f64, Arc<ExponentialFriction>) {
    let (mu_s, mu_k) = (0.4, 0.1);
    let law = ExponentialFriction {
        static_coefficient: mu_s,
        kinetic_coefficient: mu_k,
        characteristic_speed: 2e-3,
    };
    (mu_s, mu_k, Arc::new(law))
}

/// A slip-speed dependent friction law in the nonlinear path (`JointModel::friction_law`,
/// `NonlinearContact::set_friction_law`): the exponential static-to-kinetic law
/// `F_c(v) = μ_k + (μ_s − μ_k) exp(−v / v_c)` against the sliding, prescribed rigid body, on a
/// pair built frictionless. The linear law through the Newton path equals the linear
/// quasi-static path with the same law level by level (displacements, `Λ_n`, slip bounds,
/// `Λ_t`, reactions to 1e-10; the Tresca and KKT conditions hold), and the law acts: every slip
/// bound lies in `[μ_k, μ_s] |Λ_n|` of the level before, some well below `μ_s`, and the
/// tangential force at the last level is below the constant `μ_s`'s.
#[test]
fn friction_law_against_a_prescribed_rigid_body_equals_the_linear_path() -> Result<(), Error> {
    let (mu_s, mu_k, law) = exponential_law();
    let times = [0.3, 0.55, 0.8, 1.0];
    let mut linear = model_prescribed(Arc::new(isotropic(E, NU)?), 0.0)?;
    linear.friction_law("indent", law.clone())?;
    let mut routed = model_prescribed(Arc::new(Hidden(isotropic(E, NU)?)), 0.0)?;
    routed.friction_law("indent", law)?;
    assert!(routed.is_nonlinear());
    compare_friction_runs(&linear, &routed, &times, mu_s, None)?;
    // the bounds against the pressures of the level before: g_c / |Λ_n| = F_c(v) ∈ [μ_k, μ_s]
    let mut ratios: Vec<f64> = Vec::new();
    let mut previous: Option<Vec<f64>> = None;
    let with_law = routed.run_quasistatic_with(&times, |view| {
        let r = view.result;
        if let Some(p) = &previous {
            for (&node, &g) in r.cell_node.iter().zip(&r.slip_bound) {
                ratios.push(g / p[node].abs());
            }
        }
        previous = Some(r.solution.lambda_n.clone());
        Ok(())
    })?;
    assert!(!ratios.is_empty(), "no friction cells");
    let (lo, hi) = ratios.iter().fold((f64::MAX, 0.0_f64), |(a, b), &x| (a.min(x), b.max(x)));
    assert!(lo >= mu_k * (1.0 - 1e-12) && hi <= mu_s * (1.0 + 1e-12), "F_c in [{lo}, {hi}]");
    assert!(lo < 0.9 * mu_s, "the law never left μ_s (smallest F_c {lo})");
    let constant = model_prescribed(Arc::new(Hidden(isotropic(E, NU)?)), mu_s)?.run_quasistatic(&times)?;
    let tangential = |run: &RunResult<3>| run.records.last().map_or(0.0, |r| r.pairs[0].tangential_force);
    let (t_law, t_const) = (tangential(&with_law), tangential(&constant));
    eprintln!("friction law: F_c / |Λ_n| in [{lo:.4}, {hi:.4}]; tangential force {t_law:.5} (law) vs {t_const:.5} (μ_s)");
    assert!(t_law < 0.95 * t_const, "tangential force {t_law} with the law vs {t_const} with μ_s");
    Ok(())
}

/// The same law on a pair with a fixed rigid obstacle (no rigid body: the Newton path's
/// `NonlinearContact::step_to`, slip from the committed state): the block's top pushed down and
/// sheared by a prescribed displacement onto a rigid sphere under its bottom. The linear law
/// through the Newton path equals the linear quasi-static path with the law level by level
/// (displacements, `Λ_n`, friction cells, slip bounds, `g Λ_t` to 1e-10), and the law acts
/// (`F_c = g_c / |Λ_n|` of the level before below `0.9 μ_s` somewhere).
#[test]
fn friction_law_on_a_fixed_obstacle_equals_the_linear_path() -> Result<(), Error> {
    let (mu_s, mu_k, law) = exponential_law();
    let times = [0.3, 0.55, 0.8, 1.0];
    let build = |material: Arc<dyn Material<3>>| -> Result<JointModel<3>, Error> {
        let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [12, 12, 6], [Grading::Uniform; 3])?;
        let mut joint = JointModel::<3>::new();
        joint.add_body("block", mesh, material)?;
        joint.prescribe("block", "top", Vector::<3>::new(0.006, -0.002, -0.03), FnHistory::new(|t| t))?;
        let sphere = SphereObstacle::new(Point::<3>::new(0.1, 0.05, -RADIUS), RADIUS, false)?;
        joint.contact_rigid("bump", "block", "bottom", sphere, 0.0)?;
        joint.friction_law("bump", law.clone())?;
        Ok(joint)
    };
    let mut runs = Vec::new();
    for joint in [build(Arc::new(isotropic(E, NU)?))?, build(Arc::new(Hidden(isotropic(E, NU)?)))?] {
        let mut fields: Vec<Fields> = Vec::new();
        let mut kkt = 0.0_f64;
        joint.run_quasistatic_with(&times, |view| {
            kkt = kkt.max(view.result.kkt.max());
            fields.push(fields_of(view));
            Ok(())
        })?;
        runs.push((fields, kkt));
    }
    let ((lin, _), (nl, nl_kkt)) = (&runs[0], &runs[1]);
    assert_eq!(lin.len(), times.len());
    assert_eq!(nl.len(), times.len());
    assert!(*nl_kkt < 1e-8, "KKT {nl_kkt:e}");
    let mut smallest = f64::MAX;
    for (level, ((ua, la, ca), (ub, lb, cb))) in lin.iter().zip(nl).enumerate() {
        let du = max_diff(ua, ub) / max_abs(ua);
        let (lmax, dl) = pressure_difference(la, lb);
        assert!(lmax > 0.0, "level {level}: no contact");
        assert_eq!(ca.len(), cb.len(), "level {level}: friction cells");
        let mut dg = 0.0_f64;
        for ((na, ga, lta), (nb, gb, ltb)) in ca.iter().zip(cb) {
            assert_eq!(na, nb, "level {level}");
            dg = dg
                .max((ga - gb).abs())
                .max((ga * lta[0] - gb * ltb[0]).abs())
                .max((ga * lta[1] - gb * ltb[1]).abs());
            if level > 0 {
                smallest = smallest.min(gb / nl[level - 1].1[*nb].abs());
            }
        }
        let dg = dg / (mu_s * lmax);
        eprintln!("fixed obstacle, level {level}: displacements {du:.1e}, pressures {dl:.1e}, slip bounds and g Λ_t {dg:.1e}, {} cells", cb.len());
        assert!(du < 1e-10 && dl < 1e-10 && dg < 1e-10, "level {level}: {du:e} {dl:e} {dg:e}");
    }
    assert!(nl.iter().skip(1).any(|f| !f.2.is_empty()), "no friction cells");
    assert!(smallest >= mu_k * (1.0 - 1e-12) && smallest < 0.9 * mu_s, "smallest F_c {smallest}");
    Ok(())
}

/// The block `[-1, 1]² × [0, 1]` with `material` on a rigid sphere under its bottom (Coulomb
/// 0.2), its top tied to a rigid plate whose coordinates are all prescribed: pushed down by
/// `0.03 t`, moved sideways by `0.004 t` and tilted by `0.01 t` about `x`.
fn tied_plate_model(material: Arc<dyn Material<3>>, finite: bool) -> Result<JointModel<3>, Error> {
    tied_plate_model_with(material, finite, None)
}

/// [`tied_plate_model`], with `force = Some(F)` the plate's vertical translation loaded by
/// `−F t` instead of prescribed.
fn tied_plate_model_with(
    material: Arc<dyn Material<3>>,
    finite: bool,
    force: Option<f64>,
) -> Result<JointModel<3>, Error> {
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [8, 8, 4], [Grading::Uniform; 3])?;
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, material)?;
    if finite {
        joint.set_kinematics("block", Kinematics::FiniteStrain)?;
    }
    let plate = RigidBody::<3>::new("plate", Point::<3>::new(0.0, 0.0, 1.0))?
        .prescribe(0, FnHistory::new(|t| 0.004 * t))?
        .prescribe(1, Constant(0.0))?;
    let plate = match force {
        Some(f) => plate.force(2, FnHistory::new(move |t| -f * t))?,
        None => plate.prescribe(2, FnHistory::new(|t| -0.03 * t))?,
    };
    let plate = plate
        .prescribe(3, FnHistory::new(|t| 0.01 * t))?
        .prescribe(4, Constant(0.0))?
        .prescribe(5, Constant(0.0))?;
    joint.add_rigid_body(plate)?;
    joint.tie_to_rigid_body("block", "top", "plate")?;
    let sphere = SphereObstacle::new(Point::<3>::new(0.1, 0.05, -RADIUS), RADIUS, false)?;
    joint.contact_rigid("bump", "block", "bottom", sphere, 0.2)?;
    Ok(joint)
}

/// A part tied to a rigid body whose coordinates are all prescribed, in the nonlinear path
/// (no longer refused): the linear law through the Newton path equals the linear path level by
/// level (the plate's reactions, displacements, `Λ_n` to 1e-10); with the neo-Hookean block in
/// finite strain the plate's force (from the tied nodes' internal forces,
/// `part_reactions_with_kinematics`) balances the contact force on the block to 1e-9 of it
/// (the element forces sum to zero, so it is exact up to the Newton residual), and differs from
/// the linear one's.
#[test]
fn tied_plate_with_prescribed_coordinates_in_the_nonlinear_path() -> Result<(), Error> {
    let times = [0.4, 0.7, 1.0];
    let linear = tied_plate_model(Arc::new(isotropic(E, NU)?), false)?.run_quasistatic(&times)?;
    let routed = tied_plate_model(Arc::new(Hidden(isotropic(E, NU)?)), false)?;
    assert!(routed.is_nonlinear());
    let mut fields = Vec::new();
    let routed = routed.run_quasistatic_with(&times, |view| {
        fields.push((view.result.displacement.clone(), view.result.solution.lambda_n.clone()));
        Ok(())
    })?;
    let mut lin_fields = Vec::new();
    tied_plate_model(Arc::new(isotropic(E, NU)?), false)?.run_quasistatic_with(&times, |view| {
        lin_fields.push((view.result.displacement.clone(), view.result.solution.lambda_n.clone()));
        Ok(())
    })?;
    for (level, (a, b)) in linear.records.iter().zip(&routed.records).enumerate() {
        let (ra, rb) = (&a.rigid[0], &b.rigid[0]);
        let scale = ra.reaction.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let dr = ra.reaction.iter().zip(&rb.reaction).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale;
        let du = max_diff(&lin_fields[level].0, &fields[level].0) / max_abs(&lin_fields[level].0);
        let (_, dl) = pressure_difference(&lin_fields[level].1, &fields[level].1);
        eprintln!("tied plate, level {level}: reactions {dr:.1e}, displacements {du:.1e}, pressures {dl:.1e}; plate force {:?}", rb.force);
        assert!(dr < 1e-10 && du < 1e-10 && dl < 1e-10, "level {level}: {dr:e} {du:e} {dl:e}");
    }
    // neo-Hookean, finite strain: the plate's force balances the contact force on the block
    let hyper = tied_plate_model(Arc::new(neo_hookean(E, NU)?), true)?.run_quasistatic(&times)?;
    for (level, r) in hyper.records.iter().enumerate() {
        let (plate, contact) = (r.rigid[0].force, r.pairs[0].force);
        let size = contact.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(size > 0.0, "level {level}: no contact");
        // the force the block exerts on the plate is the one the sphere exerts on the block
        let balance = (0..3).map(|i| (plate[i] - contact[i]).abs()).fold(0.0, f64::max) / size;
        let change = (plate[2] / linear.records[level].rigid[0].force[2] - 1.0).abs();
        eprintln!(
            "tied plate, neo-Hookean level {level}: plate force {plate:?}, contact force {contact:?}, balance {balance:.1e}, vs linear {change:.2e}"
        );
        assert!(balance < 1e-9, "level {level}: plate {plate:?} vs contact {contact:?}");
        assert!(change > 1e-4, "level {level}: the neo-Hookean plate force equals the linear one");
    }
    Ok(())
}

/// A part tied to a rigid body whose vertical translation is force-controlled, in the nonlinear
/// path: the coordinate is found around whole Newton levels (the tie's reactions come from the
/// internal forces after each level). The linear law through the Newton path equals the linear
/// path (travel, reactions to 1e-8: the balance tolerance); the neo-Hookean block in finite
/// strain balances the applied force (`balance_error` within the tolerance) and the plate's force
/// equals the contact force on the block.
#[test]
fn tied_plate_with_a_force_controlled_coordinate_in_the_nonlinear_path() -> Result<(), Error> {
    let force = 15.0;
    let times = [0.4, 0.7, 1.0];
    let linear =
        tied_plate_model_with(Arc::new(isotropic(E, NU)?), false, Some(force))?.run_quasistatic(&times)?;
    let routed = tied_plate_model_with(Arc::new(Hidden(isotropic(E, NU)?)), false, Some(force))?
        .run_quasistatic(&times)?;
    let hyper =
        tied_plate_model_with(Arc::new(neo_hookean(E, NU)?), true, Some(force))?.run_quasistatic(&times)?;
    for (level, ((a, b), c)) in linear.records.iter().zip(&routed.records).zip(&hyper.records).enumerate() {
        let (ra, rb, rc) = (&a.rigid[0], &b.rigid[0], &c.rigid[0]);
        let travel = (ra.dofs[2] - rb.dofs[2]).abs() / ra.dofs[2].abs();
        let dr = ra.reaction.iter().zip(&rb.reaction).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / force;
        let applied = force * c.time;
        let size = c.pairs[0].force.iter().map(|v| v * v).sum::<f64>().sqrt();
        let balance = (0..3).map(|i| (rc.force[i] - c.pairs[0].force[i]).abs()).fold(0.0, f64::max) / size;
        eprintln!(
            "tied force-controlled plate, level {level}: travel {travel:.1e}, reactions {dr:.1e} (linear law); neo-Hookean tz {:.6} vs linear {:.6}, reaction {:.6} for {applied}, balance error {:.1e}, plate vs contact force {balance:.1e}, {} solves",
            rc.dofs[2], ra.dofs[2], rc.reaction[2], rc.balance_error, rc.solves
        );
        assert!(travel < 1e-8 && dr < 1e-8, "level {level}: {travel:e} {dr:e}");
        assert!(rc.balance_error < 1e-9, "level {level}: {rc:?}");
        assert!((rc.reaction[2] - applied).abs() < 1e-9 * force, "level {level}: {rc:?}");
        assert!(balance < 1e-9, "level {level}: plate {:?} vs contact {:?}", rc.force, c.pairs[0].force);
        assert!((rc.dofs[2] / ra.dofs[2] - 1.0).abs() > 1e-4, "level {level}: neo-Hookean travel = linear");
    }
    Ok(())
}

/// A hyperelastic block pressed by a rigid sphere whose coordinates are all prescribed, without
/// friction (the partner's motion changes only the gaps: the level starts in equilibrium, so its
/// first Newton step is taken whole), equals the same block pushed up against the same sphere
/// held fixed as an obstacle: the two differ by the rigid translation `d(t) e_z`, under which the
/// neo-Hookean stress (finite strain) and the gaps are invariant, and which the small-strain law
/// does not see either. Displacements (less the translation), `Λ_n` and the normal force agree
/// level by level; the rigid body's reaction balances the contact resultant; KKT holds. (Before
/// the fix the rigid-body run stopped at the first level: "the line search found no decrease".)
#[test]
fn neo_hookean_under_a_prescribed_rigid_body_equals_the_fixed_obstacle() -> Result<(), Error> {
    let press = 0.03;
    let times = [0.25, 0.5, 0.75, 1.0];
    for finite in [false, true] {
        let mesh = || box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [6, 6, 3], [Grading::Uniform; 3]);
        let law = || -> Result<Arc<dyn Material<3>>, Error> { Ok(Arc::new(neo_hookean(E, NU)?)) };
        let kinematics = if finite { Kinematics::FiniteStrain } else { Kinematics::SmallStrain };
        let mut moving = JointModel::<3>::new();
        moving.add_body("block", mesh()?, law()?)?;
        moving.set_kinematics("block", kinematics)?;
        moving.clamp("block", "bottom")?;
        let indenter = RigidBody::<3>::new("indenter", Point::<3>::new(0.0, 0.0, 3.0))?
            .prescribe(0, Constant(0.0))?
            .prescribe(1, Constant(0.0))?
            .prescribe(2, FnHistory::new(move |t| -press * t))?
            .prescribe(3, Constant(0.0))?
            .prescribe(4, Constant(0.0))?
            .prescribe(5, Constant(0.0))?;
        moving.add_rigid_body(indenter)?;
        let shape = Arc::new(SphereObstacle::new(Point::<3>::new(0.0, 0.0, 3.0), RADIUS, false)?);
        moving.contact_rigid_body("indent", "block", "top", "indenter", shape, 0.0)?;
        let mut fixed = JointModel::<3>::new();
        fixed.add_body("block", mesh()?, law()?)?;
        fixed.set_kinematics("block", kinematics)?;
        fixed.prescribe("block", "bottom", Vector::<3>::new(0.0, 0.0, press), FnHistory::new(|t| t))?;
        let sphere = SphereObstacle::new(Point::<3>::new(0.0, 0.0, 3.0), RADIUS, false)?;
        fixed.contact_rigid("indent", "block", "top", sphere, 0.0)?;
        assert!(moving.is_nonlinear() && fixed.is_nonlinear());
        let mut runs = Vec::new();
        for joint in [&moving, &fixed] {
            let mut levels = Vec::new();
            let run = joint.run_quasistatic_with(&times, |view| {
                let (u, lambda_n, _) = fields_of(view);
                levels.push((u, lambda_n, view.result.kkt.max()));
                Ok(())
            })?;
            assert_eq!(run.records.len(), times.len());
            runs.push((run, levels));
        }
        let ((rm, lm), (rf, lf)) = (&runs[0], &runs[1]);
        for (level, &t) in times.iter().enumerate() {
            let ((um, pm, kkt_m), (uf, pf, kkt_f)) = (&lm[level], &lf[level]);
            let shift = Vector::<3>::new(0.0, 0.0, press * t);
            let shifted: Vec<Vec<Vector<3>>> =
                uf.iter().map(|b| b.iter().map(|v| v - shift).collect()).collect();
            let du = max_diff(um, &shifted) / max_abs(um);
            let (lmax, dl) = pressure_difference(pf, pm);
            let (nm, nf) = (rm.records[level].pairs[0].normal_force, rf.records[level].pairs[0].normal_force);
            let rigid = &rm.records[level].rigid[0];
            eprintln!(
                "finite {finite}, t = {t}: normal force {nm:.6} vs {nf:.6}, displacements {du:.1e}, pressures {dl:.1e}, KKT {kkt_m:.1e} / {kkt_f:.1e}, reaction {:.6}",
                rigid.reaction[2]
            );
            assert!(lmax > 0.0 && nm > 0.0, "level {level}: no contact");
            assert!(du < 1e-6 && dl < 1e-6, "level {level}: displacements {du:e}, pressures {dl:e}");
            assert!((nm - nf).abs() < 1e-6 * nf, "level {level}: normal force {nm} vs {nf}");
            assert!(*kkt_m < 1e-8 && *kkt_f < 1e-8, "level {level}: KKT {kkt_m:e} {kkt_f:e}");
            // the prescribed body's reaction (what holds it at its pose) balances the contact
            // resultant (the pair's force, on the partner)
            assert!(
                (rigid.reaction[2] + rm.records[level].pairs[0].force[2]).abs() < 1e-9 * nm,
                "level {level}: {rigid:?}"
            );
        }
    }
    Ok(())
}
