//! The search for a rigid partner's position in a Newton iteration under gap control
//! ([`NonlinearContact::step_gap_controlled`], docs/nonlinear.md "Rigid bodies with mixed
//! control"), started where the contact force is far above its target with a slope that sends
//! the next trial far below the first contact.
//!
//! That is how `tkr3d --neo-hookean --free-ml --free-adduction` stopped at its first pose
//! (issue 20): the quasi-Newton step of the femur's other coordinates pressed a condyle deep at
//! the last evaluation's travel (17 038 N against a target of 168 N), the slope carried from
//! that evaluation sent the next trial 0.97 mm lower (0.26 N), and regula falsi kept the deep
//! end of the bracket while the other crept toward the root by a hundredth of the bracket per
//! trial: "gap control: no w balanced the resultant … in 60 contact solves". Here a neo-Hookean
//! ball (finite strain) is pressed by a rigid plane moving up by `w` with the normal force `T`
//! as the target, the level started at `w = 20 w*` (≈ 90 T) with the Hertz slope at the
//! solution, `1.5 T / w*`: the next trial lands ≈ 39 w* below the first contact. Checked
//! against the applied target: the normal force summed here from the multipliers equals `T`,
//! the equilibrium residual and KKT are at their tolerances.
//!
//! A solver that takes the travel as an unknown of the contact solve (`Pdas`,
//! `ContactSolver::solves_border`) starts each iteration's search with that solve, which lands on
//! the target at once: the same level in fewer trials.
#![allow(clippy::unwrap_used)]

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use synovia_contact::obstacle::FnObstacle;
use synovia_contact::operators::{ContactGeometry, ContactPair};
use synovia_contact::{ContactError, ContactProblem, ContactSolution, ContactSolver, SolveContext};
use synovia_fem::{ElasticParams, Kinematics, Model};
use synovia_material::neo_hookean;
use synovia_mesh::generators::hemisphere_refined;
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::BoundaryKind;
use synovia_nonlinear::{GapControl, NewtonParams, NonlinearContact};
use synovia_pdas::Pdas;

/// PDAS without the border: the search over trial solves alone.
struct SearchOnly(Pdas);

impl ContactSolver for SearchOnly {
    fn name(&self) -> &str {
        "pdas (search only)"
    }
    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
    ) -> Result<ContactSolution, ContactError> {
        self.0.solve(problem, context)
    }
}

const E: f64 = 10.0;
const NU: f64 = 0.3;

#[test]
fn gap_control_from_a_deep_first_trial_balances_the_target() {
    let (w_search, trials_search) = level(&SearchOnly(Pdas::default()));
    let (w_bordered, trials_bordered) = level(&Pdas::default());
    eprintln!("search: {trials_search} trials; bordered: {trials_bordered}; w {w_search:e} / {w_bordered:e}");
    assert!((w_search - w_bordered).abs() <= 1e-9 * w_search.abs(), "w {w_search:e} against {w_bordered:e}");
    assert!(trials_bordered < trials_search, "{trials_bordered} trials against {trials_search}");
}

/// The level solved with `solver`: the partner's travel and the trials.
fn level(solver: &dyn ContactSolver) -> (Real, usize) {
    // the ball of radius 1 centred at (0, 0, 1), its top held, touching z = 0 at its bottom
    let mut mesh =
        hemisphere_refined(Point::<3>::new(0.0, 0.0, 1.0), 1.0, 4, Point::<3>::zeros(), 0.15, 12).unwrap();
    mesh.set_part_kind("top", BoundaryKind::Prescribed).unwrap();
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[2] < 0.15 && n[2] < 0.0).unwrap();
    let mut model = Model::new();
    let b = model.add_body("ball", mesh, Arc::new(neo_hookean(E, NU).unwrap())).unwrap();
    model.prescribe(b, "top", |_, _| Vector::<3>::zeros()).unwrap();
    // the rigid plane z = w below the ball (the partner's position `w`, set by `pose`)
    let height = Arc::new(AtomicU64::new(0.0_f64.to_bits()));
    let read = Arc::clone(&height);
    let plane = FnObstacle::new(move |x: &Point<3>| {
        (x[2] - f64::from_bits(read.load(Ordering::Relaxed)), Vector::<3>::new(0.0, 0.0, 1.0))
    });
    let pairs = vec![ContactPair::rigid("ball-plane", b, "contact", Arc::new(plane))];
    let mut nl = NonlinearContact::new(
        &model,
        &pairs,
        &[Kinematics::FiniteStrain],
        ElasticParams::default(),
        NewtonParams::default(),
    )
    .unwrap();
    // the target: the Hertz force of an approach w* = 0.005 (small strain, E* = E / (1 − ν²))
    let w_star: Real = 0.005;
    let target = 4.0 / 3.0 * E / (1.0 - NU * NU) * w_star.powf(1.5);
    let pose = |w: Real| height.store(w.to_bits(), Ordering::Relaxed);
    // d_r(w) = z_r − w: ∂d/∂w = −1; the resultant on the plane, Σ κ_r Λ_n,r (non-decreasing in w)
    let sensitivity = |geometry: &ContactGeometry<3>| vec![-1.0; geometry.len()];
    let resultant = |geometry: &ContactGeometry<3>, lambda: &[Real]| -> Real {
        geometry.nodes.iter().zip(lambda).map(|(n, l)| n.weight * l).sum()
    };
    let tolerance = 1e-10 * target;
    let mut control = GapControl {
        pose: &pose,
        sensitivity: &sensitivity,
        resultant: &resultant,
        target,
        tolerance,
        // Hertz's slope at the solution: too small for the chord from the deep start
        slope: 1.5 * target / w_star,
        w: 20.0 * w_star,
        overlap: 1e-4,
        max_step: 1.0,
        base: 0.0,
        trials: 0,
        friction: None,
    };
    let level = nl.step_gap_controlled(&model, 1.0, solver, &mut control).unwrap();
    // the applied target, from the multipliers of the committed level
    let geometry = nl.geometry();
    let force: Real =
        geometry.nodes.iter().zip(&level.contact.solution.lambda_n).map(|(n, l)| n.weight * l).sum();
    let iterations = &level.report.iterations;
    let residual = iterations.last().map_or(Real::NAN, |i| i.residual);
    eprintln!(
        "w = {:.6e} (w* = {w_star}), force {force:.12e} against {target:.12e}, {} trials, {} Newton iterations, residual {residual:.1e}, KKT {:.1e}",
        control.w,
        control.trials,
        iterations.len(),
        level.contact.kkt.max()
    );
    assert!((force - target).abs() <= tolerance, "force {force:e} against {target:e}");
    assert!(residual <= NewtonParams::default().tolerance, "{iterations:?}");
    assert!(level.contact.kkt.max() <= 1e-10, "{:?}", level.contact.kkt);
    // the plane's travel is the Hertz approach to a few per cent (finite strain, mesh)
    assert!((control.w / w_star - 1.0).abs() < 0.1, "w = {:e}", control.w);
    (control.w, control.trials)
}
