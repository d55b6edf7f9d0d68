//! Hertz and Cattaneo–Mindlin contact problems with closed-form references (docs/model.md §9), shared by
//! the examples `hertz2d`, `hertz3d`, `cattaneo_mindlin` and the test suite.
//!
//! * 2D Hertz (plane strain): a half-disc of radius `R` pressed by a prescribed displacement of
//!   its flat top onto a rigid flat (`E₂ = ∞`), or onto a second, mirrored half-disc of another
//!   material. `1/E* = Σ (1 − ν_i²)/E_i`, `1/R* = Σ 1/R_i`, `a = sqrt(4 P R*/(π E*))`,
//!   `p₀ = 2P/(π a)`, `p(x) = p₀ sqrt(1 − x²/a²)`, `P` the contact force per unit thickness.
//! * 3D Hertz: a hemisphere on a rigid flat, `a = (3 P R*/(4 E*))^{1/3}`, `p₀ = 3P/(2π a²)`.
//! * 2D Cattaneo–Mindlin: two identical half-discs (Dundurs `β = 0`), first pressed together
//!   (frictionless), then sheared by a tangential displacement of the top with Tresca friction
//!   `g_c = μ p` from the normal state and slip measured from it: stick zone
//!   `|x| ≤ c = a sqrt(1 − Q/(μP))` and traction
//!   `q(x) = μ p₀ sqrt(1 − x²/a²) − (c/a) μ p₀ sqrt(1 − x²/c²)` (second term for `|x| ≤ c` only).
//!
//! The contact half-width and peak pressure are measured by a least-squares fit of
//! `p² = p₀² (1 − x²/a²)` to the nodal pressures of the inner 80 % of the contact zone, which
//! is insensitive to the one-element uncertainty of the contact edge.

use std::sync::Arc;
use std::time::Instant;

use synovia_contact::operators::{ContactPair, PlaneObstacle};
use synovia_contact::{ContactError, ContactSolver};
use synovia_fem::{BodyId, ElasticParams, ElasticSolver, FemError, Model};
use synovia_material::{isotropic, plane_strain};
use synovia_mesh::generators::{
    box_mesh, half_disc_refined, hemisphere_refined, nodes_1d, rectangle, Grading,
};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::refine::StraightMidpoint;
use synovia_mesh::{BoundaryKind, Mesh};

use synovia::contact::{StaticContact, StaticContactResult};

/// Figures of one Hertz or Cattaneo–Mindlin run.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRun {
    /// Problem name.
    pub problem: String,
    /// Refinement level.
    pub level: usize,
    /// Mesh size at the contact point.
    pub h: Real,
    /// Reduced unknowns.
    pub dofs: usize,
    /// Contact nodes (candidates).
    pub contact_nodes: usize,
    /// Nodes in contact (`Λ_n > 0`).
    pub active_nodes: usize,
    /// Solver name.
    pub solver: String,
    /// Solver iterations (outer) of the final solve.
    pub iterations: usize,
    /// Solver iterations on the coarse levels of the nested iteration (0 without it).
    pub coarse_iterations: usize,
    /// Contact solve time (s), excluding the factorisation of `A`.
    pub solve_s: Real,
    /// One plain elastic factorisation + solve of the same `A` (s), same run.
    pub linear_solve_s: Real,
    /// Contact force `P` (per unit thickness in 2D).
    pub force: Real,
    /// Analytic half-width / radius for `P`.
    pub a_exact: Real,
    /// Measured half-width / radius.
    pub a: Real,
    /// Analytic peak pressure.
    pub p0_exact: Real,
    /// Measured peak pressure.
    pub p0: Real,
    /// Relative L² error of the pressure profile against `p₀ sqrt(1 − x²/a²)` (exact `a`, `p₀`).
    pub pressure_l2_err: Real,
    /// Cattaneo–Mindlin only: `Q / (μ P)`.
    pub q_ratio: Real,
    /// Cattaneo–Mindlin only: measured stick half-width (2D: midway between the outermost
    /// sticking node and the next slipping one; 3D: the stick radius of the moments of the stick
    /// deficit, [`stick_radius_from_moments`]).
    pub c: Real,
    /// Cattaneo–Mindlin only: analytic stick half-width.
    pub c_exact: Real,
    /// 3D Cattaneo–Mindlin only: the stick radius `sqrt(A_stick/π)` of the area of the stick
    /// cells (0 elsewhere).
    pub c_stick_area: Real,
    /// 3D only: the contact radius `sqrt(A_contact/π)` of the area of the nodes in contact
    /// (0 elsewhere).
    pub a_contact_area: Real,
    /// 3D Cattaneo–Mindlin only: the stick radius of Mindlin's traction ratio fitted to the
    /// nodal `‖Λ_t‖` ([`fit_stick_radius`]; 0 elsewhere).
    pub c_fit: Real,
    /// Cattaneo–Mindlin only: relative L² error of the tangential traction.
    pub traction_l2_err: Real,
    /// Cattaneo–Mindlin only: `max (|q| − μ p)` over the contact nodes (≤ 0 up to round-off).
    pub coulomb_excess: Real,
    /// Largest KKT residual of the solution (docs/model.md §5).
    pub kkt: Real,
    /// The computed nodal pressure profile `(radial coordinate, Λ_n)` of the contact nodes,
    /// in contact-node order (for plots against the Hertz curve).
    pub profile: Vec<(Real, Real)>,
}

impl ContactRun {
    /// `|a − a_exact| / a_exact`.
    pub fn a_rel_err(&self) -> Real {
        (self.a - self.a_exact).abs() / self.a_exact
    }
    /// `|p₀ − p₀_exact| / p₀_exact`.
    pub fn p0_rel_err(&self) -> Real {
        (self.p0 - self.p0_exact).abs() / self.p0_exact
    }
    /// `|c − c_exact| / c_exact`.
    pub fn c_rel_err(&self) -> Real {
        (self.c - self.c_exact).abs() / self.c_exact
    }
    /// One JSON line with the key figures.
    pub fn json(&self) -> String {
        let mut s = format!(
            "{{\"problem\":\"{}\",\"level\":{},\"h\":{:.4e},\"dofs\":{},\"contact_nodes\":{},\"active_nodes\":{},\"solver\":\"{}\",\"iterations\":{},\"coarse_iterations\":{},\"solve_s\":{:.4},\"linear_solve_s\":{:.4},\"force\":{:.6e},\"a\":{:.6e},\"a_exact\":{:.6e},\"a_rel_err\":{:.3e},\"p0\":{:.6e},\"p0_exact\":{:.6e},\"p0_rel_err\":{:.3e},\"pressure_l2_err\":{:.3e},\"kkt\":{:.2e}",
            self.problem, self.level, self.h, self.dofs, self.contact_nodes, self.active_nodes, self.solver,
            self.iterations, self.coarse_iterations, self.solve_s, self.linear_solve_s, self.force, self.a, self.a_exact, self.a_rel_err(),
            self.p0, self.p0_exact, self.p0_rel_err(), self.pressure_l2_err, self.kkt
        );
        if self.c_exact > 0.0 {
            s.push_str(&format!(
                ",\"q_ratio\":{:.4},\"c\":{:.6e},\"c_exact\":{:.6e},\"c_rel_err\":{:.3e},\"traction_l2_err\":{:.3e},\"coulomb_excess\":{:.2e}",
                self.q_ratio, self.c, self.c_exact, self.c_rel_err(), self.traction_l2_err, self.coulomb_excess
            ));
        }
        if self.c_stick_area > 0.0 {
            s.push_str(&format!(
                ",\"c_fit\":{:.6e},\"c_stick_area\":{:.6e},\"a_contact_area\":{:.6e}",
                self.c_fit, self.c_stick_area, self.a_contact_area
            ));
        }
        s.push('}');
        s
    }
}

/// Least-squares fit of `p² = A − B r²` over the points with `r ≤ 0.8 r_max`:
/// returns `(a, p₀) = (sqrt(A/B), sqrt(A))`.
pub fn fit_elliptic(points: &[(Real, Real)]) -> (Real, Real) {
    let rmax = points.iter().filter(|p| p.1 > 0.0).map(|p| p.0.abs()).fold(0.0, Real::max);
    let sel: Vec<(Real, Real)> = points
        .iter()
        .filter(|p| p.1 > 0.0 && p.0.abs() <= 0.8 * rmax)
        .map(|p| (p.0 * p.0, p.1 * p.1))
        .collect();
    let n = sel.len() as Real;
    if sel.len() < 2 {
        return (Real::NAN, Real::NAN);
    }
    let mx = sel.iter().map(|p| p.0).sum::<Real>() / n;
    let my = sel.iter().map(|p| p.1).sum::<Real>() / n;
    let sxy: Real = sel.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: Real = sel.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let slope = sxy / sxx; // −B
    let intercept = my - slope * mx; // A
    ((intercept / -slope).sqrt(), intercept.sqrt())
}

/// Parameters of the 2D Hertz / Cattaneo–Mindlin problems.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hertz2d {
    /// Radius `R` of the half-disc(s).
    pub radius: Real,
    /// Young's modulus of the indenter (upper half-disc).
    pub e1: Real,
    /// Its Poisson ratio.
    pub nu1: Real,
    /// Young's modulus of the lower body (`None`: rigid flat).
    pub e2: Option<Real>,
    /// Its Poisson ratio.
    pub nu2: Real,
    /// Vertical push of the top.
    pub push: Real,
    /// Coarse cells along the radius.
    pub n: usize,
    /// Refinement levels toward the contact point.
    pub levels: usize,
    /// Radius of the refined zone (multiple of the expected `a`).
    pub refine_radius: Real,
    /// Warm-start cold solves by nested iteration on the contact rows (default `true`).
    pub nested: bool,
}

impl Default for Hertz2d {
    fn default() -> Self {
        Self {
            radius: 1.0,
            e1: 1.0,
            nu1: 0.3,
            e2: None,
            nu2: 0.3,
            push: 0.01,
            n: 8,
            levels: 10,
            refine_radius: 0.16,
            nested: true,
        }
    }
}

fn fem(e: impl Into<FemError>) -> ContactError {
    ContactError::Fem(e.into())
}

/// The half-disc indenter of radius `r` above `y = 0` (touching it at the origin), refined
/// `levels` times toward the origin within `refine_radius · r`, its flat top `"top"` of kind
/// `Prescribed` (the caller adds its contact part).
fn half_disc_indenter(
    r: Real,
    n: usize,
    refine_radius: Real,
    levels: usize,
) -> Result<Mesh<2>, ContactError> {
    let mut mesh = half_disc_refined(
        Point::<2>::new(0.0, r),
        r,
        n,
        Point::<2>::new(0.0, 0.0),
        refine_radius * r,
        levels,
    )?;
    mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
    Ok(mesh)
}

/// The hemisphere indenter of radius `r` above `z = 0` (touching it at the origin), refined
/// `levels` times toward the origin within `refine_radius · r`: flat top `"top"` of kind
/// `Prescribed`, contact part `"contact"` = its cap below `z < 0.15 r`.
fn hemisphere_indenter(
    r: Real,
    n: usize,
    refine_radius: Real,
    levels: usize,
) -> Result<Mesh<3>, ContactError> {
    let mut mesh = hemisphere_refined(
        Point::<3>::new(0.0, 0.0, r),
        r,
        n,
        Point::<3>::zeros(),
        refine_radius * r,
        levels,
    )?;
    mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
    mesh.add_boundary_part("contact", BoundaryKind::Contact, move |x, n| x[2] < 0.15 * r && n[2] < 0.0)?;
    Ok(mesh)
}

/// Builds the model of a 2D Hertz problem: the upper half-disc `"indenter"` (contact part
/// `"contact"`: its arc below `y < 0.3 R`), and either a rigid flat `y = 0` or the mirrored
/// lower half-disc `"base"`.
pub fn hertz2d_model(p: &Hertz2d) -> Result<(Model<2>, Vec<ContactPair<2>>), ContactError> {
    let r = p.radius;
    let mut upper = half_disc_indenter(r, p.n, p.refine_radius, p.levels)?;
    let sel = move |x: &Point<2>, n: &Vector<2>| x[1] < 0.3 * r && n[1] < 0.0;
    let mut model = Model::<2>::new();
    let mut pairs = Vec::new();
    let lower = match p.e2 {
        Some(_) => {
            let mut lower = upper.reflected(1, 0.0)?;
            lower.set_part_kind("top", BoundaryKind::Clamped)?;
            lower.add_boundary_part("contact", BoundaryKind::Contact, move |x, n| {
                x[1] > -0.3 * r && n[1] > 0.0
            })?;
            Some(lower)
        }
        None => None,
    };
    upper.add_boundary_part("contact", BoundaryKind::Contact, sel)?;
    let push = p.push;
    let up =
        model.add_body("indenter", upper, Arc::new(plane_strain(p.e1, p.nu1).map_err(fem)?)).map_err(fem)?;
    // the top moves down by `push` and sideways by t (the time is the tangential displacement)
    model.prescribe(up, "top", move |_, t| Vector::<2>::new(t, -push)).map_err(fem)?;
    match (lower, p.e2) {
        (Some(lower), Some(e2)) => {
            let lo = model
                .add_body("base", lower, Arc::new(plane_strain(e2, p.nu2).map_err(fem)?))
                .map_err(fem)?;
            pairs.push(
                ContactPair::node_to_node("indenter-base", up, "contact", lo, "contact")
                    .with_fixed_normal(Vector::<2>::new(0.0, -1.0)),
            );
        }
        _ => {
            let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0))?;
            pairs.push(ContactPair::rigid("indenter-flat", up, "contact", Arc::new(flat)));
        }
    }
    Ok((model, pairs))
}

fn linear_solve_time<const D: usize>(model: &Model<D>) -> Result<Real, ContactError> {
    let t0 = Instant::now();
    let mut s = ElasticSolver::new(model, ElasticParams::default())?;
    s.solve(model, 0.0)?;
    Ok(t0.elapsed().as_secs_f64())
}

fn contact_h<const D: usize>(model: &Model<D>) -> Real {
    let mesh = &model.bodies()[0].mesh;
    let mut h = Real::INFINITY;
    if let Ok(part) = mesh.boundary_part("contact") {
        for f in part.facets() {
            h = h.min(mesh.facet_measure(f).powf(1.0 / (D as Real - 1.0)));
        }
    }
    h
}

fn pressure_l2<const D: usize>(
    nodes: &[synovia_contact::operators::ContactNode<D>],
    res: &StaticContactResult<D>,
    a: Real,
    p0: Real,
    radial: impl Fn(&Point<D>) -> Real,
) -> Real {
    let (mut num, mut den) = (0.0, 0.0);
    for (node, &l) in nodes.iter().zip(&res.solution.lambda_n) {
        let r = radial(&node.position);
        let s = 1.0 - (r / a).powi(2);
        let ex = if s > 0.0 { p0 * s.sqrt() } else { 0.0 };
        num += node.weight * (l - ex).powi(2);
        den += node.weight * ex * ex;
    }
    (num / den).sqrt()
}

/// Solves a 2D Hertz problem with `solver` and measures `a`, `p₀` and the pressure profile.
pub fn hertz2d(p: &Hertz2d, solver: &dyn ContactSolver) -> Result<ContactRun, ContactError> {
    hertz2d_write(p, solver, None)
}

/// [`hertz2d`], also writing the contact state to `vtu` (displacement, pressure, active set)
/// when given.
pub fn hertz2d_write(
    p: &Hertz2d,
    solver: &dyn ContactSolver,
    vtu: Option<&std::path::Path>,
) -> Result<ContactRun, ContactError> {
    let (model, pairs) = hertz2d_model(p)?;
    let linear_solve_s = linear_solve_time(&model)?;
    let mut sc = StaticContact::new(&model, &pairs, ElasticParams::default())?;
    sc.set_nested_iteration(p.nested.then_some(32));
    let t0 = Instant::now();
    let res = sc.solve(&model, 0.0, solver, None, None, None)?;
    let solve_s = t0.elapsed().as_secs_f64();
    let geo = sc.geometry();
    if let Some(path) = vtu {
        synovia::output::contact_vtu(&model, geo, &res, synovia_io::Encoding::Zlib)
            .and_then(|w| w.write(path))
            .map_err(|e| ContactError::InvalidParameter(format!("writing {}: {e}", path.display())))?;
    }
    let force = res.normal_force(geo, 0..geo.len());
    let inv_e = (1.0 - p.nu1 * p.nu1) / p.e1 + p.e2.map_or(0.0, |e2| (1.0 - p.nu2 * p.nu2) / e2);
    let e_star = 1.0 / inv_e;
    let r_star = if p.e2.is_some() { p.radius / 2.0 } else { p.radius };
    let a_exact = (4.0 * force * r_star / (std::f64::consts::PI * e_star)).sqrt();
    let p0_exact = 2.0 * force / (std::f64::consts::PI * a_exact);
    let name = if p.e2.is_some() { "hertz2d_cylinders" } else { "hertz2d_rigid" };
    Ok(hertz_run(
        name,
        p.levels,
        &model,
        &sc,
        &res,
        solver,
        (solve_s, linear_solve_s),
        (force, a_exact, p0_exact),
        |x| x[0],
    ))
}

/// The figures of a Hertz-type run from a contact result: fits `a`, `p₀` along `radial` and
/// measures the pressure profile against the analytic values for the computed force.
#[allow(clippy::too_many_arguments)]
fn hertz_run<const D: usize>(
    problem: &str,
    level: usize,
    model: &Model<D>,
    sc: &StaticContact<D>,
    res: &StaticContactResult<D>,
    solver: &dyn ContactSolver,
    (solve_s, linear_solve_s): (Real, Real),
    (force, a_exact, p0_exact): (Real, Real, Real),
    radial: impl Fn(&Point<D>) -> Real,
) -> ContactRun {
    let geo = sc.geometry();
    let pts: Vec<(Real, Real)> =
        geo.nodes.iter().zip(&res.solution.lambda_n).map(|(n, l)| (radial(&n.position), *l)).collect();
    let (a, p0) = fit_elliptic(&pts);
    let l2 = pressure_l2(&geo.nodes, res, a_exact, p0_exact, &radial);
    ContactRun {
        problem: problem.to_string(),
        level,
        h: contact_h(model),
        dofs: sc.elastic().info().n_dofs,
        contact_nodes: geo.len(),
        active_nodes: res.solution.lambda_n.iter().filter(|&&l| l > 0.0).count(),
        solver: solver.name().to_string(),
        iterations: res.solution.report.iterations,
        coarse_iterations: res.coarse_iterations,
        solve_s,
        linear_solve_s,
        force,
        a_exact,
        a,
        p0_exact,
        p0,
        pressure_l2_err: l2,
        q_ratio: 0.0,
        c: 0.0,
        c_exact: 0.0,
        c_stick_area: 0.0,
        a_contact_area: 0.0,
        c_fit: 0.0,
        traction_l2_err: 0.0,
        coulomb_excess: 0.0,
        kkt: res.kkt.max(),
        profile: pts,
    }
}

/// Parameters of the 3D Hertz problem (hemisphere on a rigid flat).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hertz3d {
    /// Radius.
    pub radius: Real,
    /// Young's modulus.
    pub e: Real,
    /// Poisson ratio.
    pub nu: Real,
    /// Vertical push of the top.
    pub push: Real,
    /// Coarse cells along the radius.
    pub n: usize,
    /// Refinement levels toward the pole.
    pub levels: usize,
    /// Radius of the refined zone.
    pub refine_radius: Real,
    /// Warm-start by nested iteration on the contact rows (default `true`).
    pub nested: bool,
}

impl Default for Hertz3d {
    fn default() -> Self {
        Self { radius: 1.0, e: 1.0, nu: 0.3, push: 0.01, n: 4, levels: 12, refine_radius: 0.15, nested: true }
    }
}

/// Builds the model of the 3D Hertz problem: the hemisphere `"hemisphere"` (contact part
/// `"contact"`: its cap below `z < 0.15 R`) on the rigid flat `z = 0`; its top moves down by
/// `push` and sideways (x) by the time `t`.
pub fn hertz3d_model(p: &Hertz3d) -> Result<(Model<3>, Vec<ContactPair<3>>), ContactError> {
    let mesh = hemisphere_indenter(p.radius, p.n, p.refine_radius, p.levels)?;
    let mut model = Model::<3>::new();
    let b = model.add_body("hemisphere", mesh, Arc::new(isotropic(p.e, p.nu).map_err(fem)?)).map_err(fem)?;
    let push = p.push;
    model.prescribe(b, "top", move |_, t| Vector::<3>::new(t, 0.0, -push)).map_err(fem)?;
    let flat = PlaneObstacle::new(Point::<3>::zeros(), Vector::<3>::new(0.0, 0.0, 1.0))?;
    Ok((model, vec![ContactPair::rigid("hemisphere-flat", b, "contact", Arc::new(flat))]))
}

/// Solves the 3D Hertz problem with `solver`.
pub fn hertz3d(p: &Hertz3d, solver: &dyn ContactSolver) -> Result<ContactRun, ContactError> {
    let r = p.radius;
    let (model, pairs) = hertz3d_model(p)?;
    let linear_solve_s = linear_solve_time(&model)?;
    let mut sc = StaticContact::new(&model, &pairs, ElasticParams::default())?;
    sc.set_nested_iteration(p.nested.then_some(32));
    let t0 = Instant::now();
    let res = sc.solve(&model, 0.0, solver, None, None, None)?;
    let solve_s = t0.elapsed().as_secs_f64();
    let geo = sc.geometry();
    let force = res.normal_force(geo, 0..geo.len());
    let e_star = p.e / (1.0 - p.nu * p.nu);
    let a_exact = (3.0 * force * r / (4.0 * e_star)).cbrt();
    let p0_exact = 3.0 * force / (2.0 * std::f64::consts::PI * a_exact * a_exact);
    let radial = |x: &Point<3>| (x[0] * x[0] + x[1] * x[1]).sqrt();
    Ok(hertz_run(
        "hertz3d_rigid",
        p.levels,
        &model,
        &sc,
        &res,
        solver,
        (solve_s, linear_solve_s),
        (force, a_exact, p0_exact),
        radial,
    ))
}

/// Solves the 2D Cattaneo–Mindlin problem: two identical half-discs (parameters `p` with
/// `e2 = Some(e1)` enforced), friction coefficient `mu`, tangential load tuned (secant on the
/// top's tangential displacement) to `Q / (μ P) = q_ratio` within 0.5 %.
pub fn cattaneo_mindlin_2d(
    p: &Hertz2d,
    mu: Real,
    q_ratio: Real,
    solver: &dyn ContactSolver,
) -> Result<ContactRun, ContactError> {
    if !(mu > 0.0 && q_ratio > 0.0 && q_ratio < 1.0) {
        return Err(ContactError::InvalidParameter(format!(
            "need μ > 0 and 0 < Q/(μP) < 1, got {mu}, {q_ratio}"
        )));
    }
    let p = Hertz2d { e2: Some(p.e1), nu2: p.nu1, ..*p };
    let (model, mut pairs) = hertz2d_model(&p)?;
    pairs[0].friction = mu;
    let linear_solve_s = linear_solve_time(&model)?;
    let sc = StaticContact::new(&model, &pairs, ElasticParams::default())?;
    let geo = sc.geometry();
    let t0 = Instant::now();
    // ## normal step (frictionless), then Tresca with g_c = μ p
    let normal = sc.solve(&model, 0.0, solver, None, None, None)?;
    let force = normal.normal_force(geo, 0..geo.len());
    let gc = geo.slip_bounds_from_pressure(&normal.solution.lambda_n);
    let tangential_force = |res: &StaticContactResult<2>| -> Real {
        res.cell_node
            .iter()
            .zip(&res.slip_bound)
            .zip(&res.solution.lambda_t)
            .map(|((&r, g), l)| g * geo.nodes[r].weight * l)
            .sum::<Real>()
            .abs()
    };
    let mut iterations = normal.solution.report.iterations;
    let coarse_iterations = normal.coarse_iterations;
    let mut solve = |shift: Real| -> Result<(StaticContactResult<2>, Real), ContactError> {
        let res = sc.solve(&model, shift, solver, Some(&gc), Some(&normal.displacement), None)?;
        iterations += res.solution.report.iterations;
        let q = tangential_force(&res) / (mu * force);
        Ok((res, q))
    };
    // secant on the shift
    let mut s0 = 1e-4 * p.radius;
    let (mut r0, mut q0) = solve(s0)?;
    let mut s1 = s0 * q_ratio / q0.max(1e-12);
    let (mut r1, mut q1) = solve(s1)?;
    for _ in 0..20 {
        if (q1 - q_ratio).abs() < 5e-3 * q_ratio {
            break;
        }
        let s2 = s1 + (q_ratio - q1) * (s1 - s0) / (q1 - q0);
        s0 = s1;
        q0 = q1;
        r0 = r1;
        s1 = s2;
        let (r2, q2) = solve(s1)?;
        r1 = r2;
        q1 = q2;
    }
    drop(r0);
    let res = r1;
    let solve_s = t0.elapsed().as_secs_f64();
    let e_star = 1.0 / (2.0 * (1.0 - p.nu1 * p.nu1) / p.e1);
    let r_star = p.radius / 2.0;
    let a_exact = (4.0 * force * r_star / (std::f64::consts::PI * e_star)).sqrt();
    let p0_exact = 2.0 * force / (std::f64::consts::PI * a_exact);
    let c_exact = a_exact * (1.0 - q1).sqrt();
    // stick zone and traction
    let (mut stick_max, mut slip_min): (Real, Real) = (0.0, Real::INFINITY);
    let (mut num, mut den, mut excess): (Real, Real, Real) = (0.0, 0.0, Real::NEG_INFINITY);
    for ((&r, g), l) in res.cell_node.iter().zip(&res.slip_bound).zip(&res.solution.lambda_t) {
        let x = geo.nodes[r].position[0].abs();
        if l.abs() < 1.0 - 1e-6 {
            stick_max = stick_max.max(x);
        }
        let q = g * l.abs();
        let s1 = 1.0 - (x / a_exact).powi(2);
        let s2 = 1.0 - (x / c_exact).powi(2);
        let mut qe = if s1 > 0.0 { mu * p0_exact * s1.sqrt() } else { 0.0 };
        if s2 > 0.0 {
            qe -= c_exact / a_exact * mu * p0_exact * s2.sqrt();
        }
        let w = geo.nodes[r].weight;
        num += w * (q - qe).powi(2);
        den += w * qe * qe;
        excess = excess.max(q - mu * res.solution.lambda_n[r].abs());
    }
    for ((&r, _), l) in res.cell_node.iter().zip(&res.slip_bound).zip(&res.solution.lambda_t) {
        let x = geo.nodes[r].position[0].abs();
        if l.abs() >= 1.0 - 1e-6 && x > stick_max {
            slip_min = slip_min.min(x);
        }
    }
    let c = if slip_min.is_finite() { 0.5 * (stick_max + slip_min) } else { stick_max };
    let mut run = hertz_run(
        "cattaneo_mindlin_2d",
        p.levels,
        &model,
        &sc,
        &res,
        solver,
        (solve_s, linear_solve_s),
        (force, a_exact, p0_exact),
        |x| x[0],
    );
    run.iterations = iterations;
    run.coarse_iterations = coarse_iterations;
    run.q_ratio = q1;
    run.c = c;
    run.c_exact = c_exact;
    run.traction_l2_err = (num / den).sqrt();
    run.coulomb_excess = excess;
    run.kkt = res.kkt.max().max(normal.kkt.max());
    Ok(run)
}

/// Parameters of the 2D Hertz problem on non-matching meshes: the half-disc indenter of
/// [`Hertz2d`] (radius `R`, refined toward its lowest point) pressed by a prescribed
/// displacement of its flat top onto an elastic block `[−W, W] × [−H, 0]` clamped at its base,
/// whose mesh is refined toward the contact point with [`Grading::Refined`] to another mesh
/// size. The pair is node-to-segment ([`ContactPair::node_to_segment`]).
///
/// Reference: the Hertz line contact of a cylinder on a half-space, `1/E* = Σ (1 − ν_i²)/E_i`,
/// `R* = R`; the block stands for the half-space when `H, W ≫ a`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzBlock2d {
    /// Radius `R` of the indenter.
    pub radius: Real,
    /// Young's modulus of the indenter.
    pub e1: Real,
    /// Its Poisson ratio.
    pub nu1: Real,
    /// Young's modulus of the block.
    pub e2: Real,
    /// Its Poisson ratio.
    pub nu2: Real,
    /// Vertical push of the indenter's top.
    pub push: Real,
    /// Coarse cells of the indenter along its radius.
    pub n: usize,
    /// Refinement levels of the indenter toward its lowest point.
    pub levels: usize,
    /// Radius of the indenter's refined zone (multiple of `R`).
    pub refine_radius: Real,
    /// Half-width `W` of the block.
    pub half_width: Real,
    /// Depth `H` of the block.
    pub depth: Real,
    /// Block cell size in its fine window at the contact point.
    pub block_h: Real,
    /// Block cell size far from the contact.
    pub block_h_far: Real,
    /// Half-width of the block's fine window along x (its depth along y is half of it).
    pub window: Real,
    /// `true`: the indenter's nodes are the slave nodes (block = master); `false`: the block's.
    pub slave_indenter: bool,
    /// `true`: dual mortar ([`ContactPair::mortar`]); `false` (default): node-to-segment.
    pub mortar: bool,
    /// Warm-start by nested iteration on the contact rows (default `true`).
    pub nested: bool,
}

impl Default for HertzBlock2d {
    fn default() -> Self {
        Self {
            radius: 1.0,
            e1: 1.0,
            nu1: 0.3,
            e2: 1.0,
            nu2: 0.3,
            push: 0.01,
            n: 8,
            levels: 10,
            refine_radius: 0.16,
            half_width: 1.0,
            depth: 1.0,
            block_h: 1.5e-3,
            block_h_far: 0.1,
            window: 0.12,
            slave_indenter: true,
            mortar: false,
            nested: true,
        }
    }
}

/// `[a, b]` graded by [`Grading::Refined`] with cells of about `h` in the window
/// `|x − center| ≤ width/2` and `h_far` far from it: the grading and the number of cells
/// (the smallest `n` whose finest cell is at most `1.02 h`).
pub fn refined_axis(
    a: Real,
    b: Real,
    center: Real,
    width: Real,
    h: Real,
    h_far: Real,
) -> Result<(Grading, usize), ContactError> {
    let ratio = (h_far / h).max(1.0);
    let g = Grading::Refined { center, width, ratio };
    let mut n = ((b - a) / h_far).ceil().max(1.0) as usize;
    loop {
        let x = nodes_1d(a, b, n, g)?;
        let hmin = x.windows(2).map(|w| w[1] - w[0]).fold(Real::INFINITY, Real::min);
        if hmin <= 1.02 * h || n > 100_000 {
            return Ok((g, n));
        }
        n = (n as Real * (hmin / h).clamp(1.01, 1.5)).ceil() as usize;
    }
}

/// The model of [`HertzBlock2d`]: body 0 `"indenter"` (contact part `"contact"`, its arc below
/// `y < 0.3 R`), body 1 `"block"` (contact part `"top"`), and the node-to-segment pair.
pub fn hertz2d_block_model(p: &HertzBlock2d) -> Result<(Model<2>, Vec<ContactPair<2>>), ContactError> {
    let r = p.radius;
    let mut upper = half_disc_indenter(r, p.n, p.refine_radius, p.levels)?;
    upper.add_boundary_part("contact", BoundaryKind::Contact, move |x, n| x[1] < 0.3 * r && n[1] < 0.0)?;
    let (gx, nx) = refined_axis(-p.half_width, p.half_width, 0.0, 2.0 * p.window, p.block_h, p.block_h_far)?;
    let (gy, ny) = refined_axis(-p.depth, 0.0, 0.0, p.window, p.block_h, p.block_h_far)?;
    let mut block = rectangle(-p.half_width, p.half_width, -p.depth, 0.0, nx, ny, gx, gy)?;
    block.set_part_kind("bottom", BoundaryKind::Clamped)?;
    block.set_part_kind("top", BoundaryKind::Contact)?;
    let mut model = Model::<2>::new();
    let up =
        model.add_body("indenter", upper, Arc::new(plane_strain(p.e1, p.nu1).map_err(fem)?)).map_err(fem)?;
    let push = p.push;
    model.prescribe(up, "top", move |_, t| Vector::<2>::new(t, -push)).map_err(fem)?;
    let lo =
        model.add_body("block", block, Arc::new(plane_strain(p.e2, p.nu2).map_err(fem)?)).map_err(fem)?;
    let pair = non_matching_pair(p.mortar, p.slave_indenter, (up, "contact"), (lo, "top"));
    Ok((model, vec![pair]))
}

/// The pair of an indenter–block problem: node-to-segment or mortar, either side slave.
fn non_matching_pair<const D: usize>(
    mortar: bool,
    slave_indenter: bool,
    indenter: (BodyId, &str),
    block: (BodyId, &str),
) -> ContactPair<D> {
    let ((bk, pk), (bl, pl), name) = if slave_indenter {
        (indenter, block, "indenter-block")
    } else {
        (block, indenter, "block-indenter")
    };
    if mortar {
        ContactPair::mortar(name, bk, pk, bl, pl)
    } else {
        ContactPair::node_to_segment(name, bk, pk, bl, pl)
    }
}

/// Solves [`HertzBlock2d`] with `solver` and measures `a`, `p₀` (fit of the slave nodal
/// pressures) and the pressure profile against the Hertz line contact for the computed force.
pub fn hertz2d_block(p: &HertzBlock2d, solver: &dyn ContactSolver) -> Result<ContactRun, ContactError> {
    let (model, pairs) = hertz2d_block_model(p)?;
    let linear_solve_s = linear_solve_time(&model)?;
    let mut sc = StaticContact::new(&model, &pairs, ElasticParams::default())?;
    sc.set_nested_iteration(p.nested.then_some(32));
    let t0 = Instant::now();
    let res = sc.solve(&model, 0.0, solver, None, None, None)?;
    let solve_s = t0.elapsed().as_secs_f64();
    let geo = sc.geometry();
    let force = res.normal_force(geo, 0..geo.len());
    let inv_e = (1.0 - p.nu1 * p.nu1) / p.e1 + (1.0 - p.nu2 * p.nu2) / p.e2;
    let e_star = 1.0 / inv_e;
    let a_exact = (4.0 * force * p.radius / (std::f64::consts::PI * e_star)).sqrt();
    let p0_exact = 2.0 * force / (std::f64::consts::PI * a_exact);
    let name = match (p.mortar, p.slave_indenter) {
        (false, true) => "hertz2d_block_slave_indenter",
        (false, false) => "hertz2d_block_slave_block",
        (true, true) => "hertz2d_block_mortar_slave_indenter",
        (true, false) => "hertz2d_block_mortar_slave_block",
    };
    let mut run = hertz_run(
        name,
        p.levels,
        &model,
        &sc,
        &res,
        solver,
        (solve_s, linear_solve_s),
        (force, a_exact, p0_exact),
        |x| x[0],
    );
    // mesh size at the contact point of the slave side
    run.h = if p.slave_indenter { contact_h(&model) } else { p.block_h };
    Ok(run)
}

/// Parameters of the 3D Hertz problem on non-matching meshes: the hemisphere of [`Hertz3d`]
/// (radius `R`, refined toward its pole) pressed by a prescribed displacement of its flat top
/// onto an elastic block `[−W, W]² × [−H, 0]` clamped at its base, meshed as a coarse Kuhn box
/// ([`box_mesh`], `block_n` hexes along `W` and `H`) refined `block_levels` times toward the
/// ball of radius `block_refine_radius` around the contact point (bisection,
/// [`synovia_mesh::refine::refine_toward`]): another mesh, with nodes that do not match the
/// indenter's. The pair is node-to-facet or dual mortar.
///
/// Reference: the Hertz point contact of a sphere on a half-space, `1/E* = Σ (1 − ν_i²)/E_i`,
/// `R* = R`, `a = (3 P R*/(4 E*))^{1/3}`, `p₀ = 3P/(2π a²)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzBlock3d {
    /// Radius `R` of the indenter.
    pub radius: Real,
    /// Young's modulus of the indenter.
    pub e1: Real,
    /// Its Poisson ratio.
    pub nu1: Real,
    /// Young's modulus of the block.
    pub e2: Real,
    /// Its Poisson ratio.
    pub nu2: Real,
    /// Vertical push of the indenter's top.
    pub push: Real,
    /// Coarse cells of the indenter along its radius.
    pub n: usize,
    /// Refinement levels of the indenter toward its pole.
    pub levels: usize,
    /// Radius of the indenter's refined zone (multiple of `R`).
    pub refine_radius: Real,
    /// Half-width `W` of the block.
    pub half_width: Real,
    /// Depth `H` of the block.
    pub depth: Real,
    /// Coarse hexes of the block along `W` (and along `H`).
    pub block_n: usize,
    /// Refinement levels of the block toward the contact point (`h` halves about every three).
    pub block_levels: usize,
    /// Radius of the block's refined zone around the contact point.
    pub block_refine_radius: Real,
    /// `true`: the indenter's nodes are the slave nodes (block = master); `false`: the block's.
    pub slave_indenter: bool,
    /// `true` (default): dual mortar ([`ContactPair::mortar`]); `false`: node-to-facet.
    pub mortar: bool,
    /// Warm-start by nested iteration on the contact rows (default `true`).
    pub nested: bool,
}

impl Default for HertzBlock3d {
    fn default() -> Self {
        Self {
            radius: 1.0,
            e1: 1.0,
            nu1: 0.3,
            e2: 1.0,
            nu2: 0.3,
            push: 0.01,
            n: 4,
            levels: 12,
            refine_radius: 0.15,
            half_width: 1.0,
            depth: 1.0,
            block_n: 3,
            block_levels: 12,
            block_refine_radius: 0.15,
            slave_indenter: true,
            mortar: true,
            nested: true,
        }
    }
}

/// The model of [`HertzBlock3d`]: body 0 `"indenter"` (contact part `"contact"`: its cap below
/// `z < 0.15 R`; its top moved by `(t, 0, −push)` at time `t`), body 1 `"block"` (contact part
/// `"top"`), and the pair.
pub fn hertz3d_block_model(p: &HertzBlock3d) -> Result<(Model<3>, Vec<ContactPair<3>>), ContactError> {
    let upper = hemisphere_indenter(p.radius, p.n, p.refine_radius, p.levels)?;
    let (w, d, nb) = (p.half_width, p.depth, p.block_n.max(1));
    let coarse = box_mesh([-w, -w, -d], [w, w, 0.0], [2 * nb, 2 * nb, nb], [Grading::Uniform; 3])?;
    let rr = p.block_refine_radius;
    let mut block = coarse.refined_toward(|x| x.norm() <= rr, p.block_levels, &StraightMidpoint)?;
    block.set_part_kind("bottom", BoundaryKind::Clamped)?;
    block.set_part_kind("top", BoundaryKind::Contact)?;
    let mut model = Model::<3>::new();
    let up =
        model.add_body("indenter", upper, Arc::new(isotropic(p.e1, p.nu1).map_err(fem)?)).map_err(fem)?;
    let push = p.push;
    model.prescribe(up, "top", move |_, t| Vector::<3>::new(t, 0.0, -push)).map_err(fem)?;
    let lo = model.add_body("block", block, Arc::new(isotropic(p.e2, p.nu2).map_err(fem)?)).map_err(fem)?;
    let pair = non_matching_pair(p.mortar, p.slave_indenter, (up, "contact"), (lo, "top"));
    Ok((model, vec![pair]))
}

/// Smallest `sqrt(area)` of the facets of part `part` of body `body`.
fn part_h(model: &Model<3>, body: usize, part: &str) -> Real {
    let mesh = &model.bodies()[body].mesh;
    mesh.boundary_part(part)
        .map(|p| p.facets().map(|f| mesh.facet_measure(f).sqrt()).fold(Real::INFINITY, Real::min))
        .unwrap_or(Real::NAN)
}

/// Solves [`HertzBlock3d`] with `solver` and measures `a`, `p₀` (fit of the slave nodal
/// pressures against the radius) and the pressure profile against the Hertz point contact for
/// the computed force. Returns the run and the contact mesh sizes `(indenter h, block h)`
/// (smallest `sqrt(facet area)`).
pub fn hertz3d_block(
    p: &HertzBlock3d,
    solver: &dyn ContactSolver,
) -> Result<(ContactRun, (Real, Real)), ContactError> {
    let (model, pairs) = hertz3d_block_model(p)?;
    let linear_solve_s = linear_solve_time(&model)?;
    let mut sc = StaticContact::new(&model, &pairs, ElasticParams::default())?;
    sc.set_nested_iteration(p.nested.then_some(32));
    let t0 = Instant::now();
    let res = sc.solve(&model, 0.0, solver, None, None, None)?;
    let solve_s = t0.elapsed().as_secs_f64();
    let geo = sc.geometry();
    let force = res.normal_force(geo, 0..geo.len());
    let inv_e = (1.0 - p.nu1 * p.nu1) / p.e1 + (1.0 - p.nu2 * p.nu2) / p.e2;
    let e_star = 1.0 / inv_e;
    let a_exact = (3.0 * force * p.radius / (4.0 * e_star)).cbrt();
    let p0_exact = 3.0 * force / (2.0 * std::f64::consts::PI * a_exact * a_exact);
    let name = match (p.mortar, p.slave_indenter) {
        (false, true) => "hertz3d_block_slave_indenter",
        (false, false) => "hertz3d_block_slave_block",
        (true, true) => "hertz3d_block_mortar_slave_indenter",
        (true, false) => "hertz3d_block_mortar_slave_block",
    };
    let mut run = hertz_run(
        name,
        p.levels,
        &model,
        &sc,
        &res,
        solver,
        (solve_s, linear_solve_s),
        (force, a_exact, p0_exact),
        |x| (x[0] * x[0] + x[1] * x[1]).sqrt(),
    );
    let h = (part_h(&model, 0, "contact"), part_h(&model, 1, "top"));
    run.h = if p.slave_indenter { h.0 } else { h.1 };
    Ok((run, h))
}

/// Solves the 3D Cattaneo–Mindlin problem: two identical hemispheres (parameters `p`: radius
/// `R`, `E`, `ν`, refinement; the upper one `"upper"` touches the mirrored lower one `"lower"`
/// at the origin, contact parts their caps `|z| < 0.15 R`, node to node with the fixed normal
/// `−e_z`) are pressed together by the prescribed displacement `−push e_z` of the upper top
/// (lower top clamped), frictionless; then sheared by a tangential displacement `s e_x` of the
/// upper top with Tresca friction `g_c = μ p` from the normal state and slip measured from it.
/// Identical materials give Dundurs `β = 0`, so the pressure does not change under the shear
/// and this Tresca problem is the Coulomb problem. For each `Q/(μP)` of `q_ratios` (each
/// in `(0, 1)`), `s` is tuned by a secant to within 0.5 %; the run records
///
/// ```text
/// a_Hertz = (3 P R*/(4 E*))^{1/3},  R* = R/2,  1/E* = 2 (1 − ν²)/E,     p₀ = 3P/(2π a²),
/// c_exact = a_Hertz (1 − Q/(μP))^{1/3}                                    (Mindlin),
/// c       = sqrt(5/2 · Σ_r D_r ρ_r² / Σ_r D_r),  D_r = κ_r g_r (1 − ‖Λ_t,r‖)
///                                                 ([`stick_radius_from_moments`], run.c),
/// c_fit   = Mindlin's traction ratio fitted to ‖Λ_t,r‖ = |q_r|/(μ p_r)   ([`fit_stick_radius`]),
/// c_area  = sqrt(A_stick / π),   A_stick = Σ_{stick cells} κ_r   (cells with ‖Λ_t‖ < 1 − 10⁻⁶),
/// q(r)    = μ p₀ sqrt(1 − r²/a²) − (c/a) μ p₀ sqrt(1 − r²/c²)   (second term for r ≤ c),
/// ```
///
/// `a` (fit of the pressure, [`fit_elliptic`]), the relative L² error of `|q|` and the
/// Coulomb check `max(|q| − μ p)`. `D_r` is the stick deficit `μ p − |q|` of cell `r` as a
/// force (`ρ_r` its distance from the axis): a sum of nodal forces, it needs neither `a` nor the
/// nodal pressures `Λ_n = F_n/κ`, which alternate by a few per cent between the contact nodes
/// with large and small dual cells of these bisection meshes; `c_fit` and `c_area` are built
/// on those nodal values and are reported beside `c` (docs/contact.md).
/// Mindlin's solution (uniform tangential displacement of the stick zone, traction parallel to
/// the load) is exact for `ν = 0`; for `ν > 0` it neglects a small transverse traction.
///
/// # Errors
/// [`ContactError::InvalidParameter`] for `μ ≤ 0` or a ratio outside `(0, 1)`; the errors of the
/// model set-up and of the solves.
pub fn cattaneo_mindlin_3d(
    p: &Hertz3d,
    mu: Real,
    q_ratios: &[Real],
    solver: &dyn ContactSolver,
) -> Result<Vec<ContactRun>, ContactError> {
    if !(mu > 0.0 && mu.is_finite()) || q_ratios.iter().any(|q| !(*q > 0.0 && *q < 1.0)) {
        return Err(ContactError::InvalidParameter(format!(
            "need μ > 0 and 0 < Q/(μP) < 1, got {mu}, {q_ratios:?}"
        )));
    }
    let r = p.radius;
    let mut upper = hemisphere_refined(
        Point::<3>::new(0.0, 0.0, r),
        r,
        p.n,
        Point::<3>::zeros(),
        p.refine_radius * r,
        p.levels,
    )?;
    upper.set_part_kind("top", BoundaryKind::Prescribed)?;
    let mut lower = upper.reflected(2, 0.0)?;
    lower.set_part_kind("top", BoundaryKind::Clamped)?;
    upper.add_boundary_part("contact", BoundaryKind::Contact, move |x, n| x[2] < 0.15 * r && n[2] < 0.0)?;
    lower.add_boundary_part("contact", BoundaryKind::Contact, move |x, n| x[2] > -0.15 * r && n[2] > 0.0)?;
    let material = Arc::new(isotropic(p.e, p.nu).map_err(fem)?);
    let mut model = Model::<3>::new();
    let up = model.add_body("upper", upper, material.clone()).map_err(fem)?;
    let lo = model.add_body("lower", lower, material).map_err(fem)?;
    let push = p.push;
    model.prescribe(up, "top", move |_, t| Vector::<3>::new(t, 0.0, -push)).map_err(fem)?;
    let mut pair = ContactPair::node_to_node("upper-lower", up, "contact", lo, "contact")
        .with_fixed_normal(Vector::<3>::new(0.0, 0.0, -1.0));
    pair.friction = mu;
    let pairs = vec![pair];
    let linear_solve_s = linear_solve_time(&model)?;
    let mut sc = StaticContact::new(&model, &pairs, ElasticParams::default())?;
    sc.set_nested_iteration(p.nested.then_some(32));
    let geo = sc.geometry().clone();
    let t0 = Instant::now();
    let normal = sc.solve(&model, 0.0, solver, None, None, None)?;
    let normal_s = t0.elapsed().as_secs_f64();
    let force = normal.normal_force(&geo, 0..geo.len());
    let gc = geo.slip_bounds_from_pressure(&normal.solution.lambda_n);
    let e_star = p.e / (2.0 * (1.0 - p.nu * p.nu));
    let r_star = r / 2.0;
    let a_exact = (3.0 * force * r_star / (4.0 * e_star)).cbrt();
    let p0_exact = 3.0 * force / (2.0 * std::f64::consts::PI * a_exact * a_exact);
    let radial = |x: &Point<3>| (x[0] * x[0] + x[1] * x[1]).sqrt();
    // the friction force of a cell c: g_c κ_c Σ_j Λ_t,c,j T_c,j
    let traction = |res: &StaticContactResult<3>, c: usize| -> (usize, Real, Vector<3>) {
        let node = res.cell_node[c];
        let n = &geo.nodes[node];
        let (l1, l2) = (res.solution.lambda_t[2 * c], res.solution.lambda_t[2 * c + 1]);
        (node, (l1 * l1 + l2 * l2).sqrt(), (n.tangents[0] * l1 + n.tangents[1] * l2) * res.slip_bound[c])
    };
    let tangential_force = |res: &StaticContactResult<3>| -> Real {
        (0..res.cell_node.len())
            .map(|c| {
                let (node, _, q) = traction(res, c);
                q * geo.nodes[node].weight
            })
            .sum::<Vector<3>>()
            .norm()
    };
    let mut warm: Option<synovia_contact::ContactSolution> = None;
    let iterations = std::cell::Cell::new(0);
    let solve = |shift: Real,
                 warm: &mut Option<synovia_contact::ContactSolution>|
     -> Result<(StaticContactResult<3>, Real), ContactError> {
        let res = sc.solve(&model, shift, solver, Some(&gc), Some(&normal.displacement), warm.as_ref())?;
        iterations.set(iterations.get() + res.solution.report.iterations);
        *warm = Some(res.solution.clone());
        let q = tangential_force(&res) / (mu * force);
        Ok((res, q))
    };
    let mut runs = Vec::new();
    let (mut s_prev, mut q_prev) = (0.0, 0.0);
    for &target in q_ratios {
        let t_tangential = Instant::now();
        // secant on the shift from the last converged point (the origin for the first ratio)
        let mut s0 = if s_prev > 0.0 { s_prev } else { 1e-4 * r };
        let (_, mut q0) = solve(s0, &mut warm)?;
        let mut s1 =
            if s_prev > 0.0 && q_prev > 0.0 { s_prev * target / q_prev } else { s0 * target / q0.max(1e-12) };
        let (mut res, mut q1) = solve(s1, &mut warm)?;
        for _ in 0..20 {
            if (q1 - target).abs() < 5e-3 * target || q1 == q0 {
                break;
            }
            let s2 = s1 + (target - q1) * (s1 - s0) / (q1 - q0);
            s0 = s1;
            q0 = q1;
            s1 = s2;
            (res, q1) = solve(s1, &mut warm)?;
        }
        s_prev = s1;
        q_prev = q1;
        let c_exact = a_exact * (1.0 - q1).cbrt();
        let (mut stick_area, mut num, mut den, mut excess) = (0.0, 0.0, 0.0, Real::NEG_INFINITY);
        let mut ratio_points = Vec::with_capacity(res.cell_node.len());
        let mut deficit_points = Vec::with_capacity(res.cell_node.len());
        for c in 0..res.cell_node.len() {
            let (node, norm, q) = traction(&res, c);
            let w = geo.nodes[node].weight;
            if norm < 1.0 - 1e-6 {
                stick_area += w;
            }
            let x = radial(&geo.nodes[node].position);
            if res.solution.lambda_n[node] > 0.0 {
                ratio_points.push((x, norm, w));
            }
            // the stick deficit μ p − |q| of the cell as a force, κ g_c (1 − ‖Λ_t‖) (0 if it slips)
            deficit_points.push((x, w * res.slip_bound[c] * (1.0 - norm)));
            let s1 = 1.0 - (x / a_exact).powi(2);
            let s2 = 1.0 - (x / c_exact).powi(2);
            let mut qe = if s1 > 0.0 { mu * p0_exact * s1.sqrt() } else { 0.0 };
            if s2 > 0.0 {
                qe -= c_exact / a_exact * mu * p0_exact * s2.sqrt();
            }
            num += w * (q.norm() - qe).powi(2);
            den += w * qe * qe;
            excess = excess.max(q.norm() - mu * res.solution.lambda_n[node].abs());
        }
        let mut run = hertz_run(
            "cattaneo_mindlin_3d",
            p.levels,
            &model,
            &sc,
            &res,
            solver,
            (normal_s + t_tangential.elapsed().as_secs_f64(), linear_solve_s),
            (force, a_exact, p0_exact),
            radial,
        );
        run.iterations = iterations.get();
        run.coarse_iterations = normal.coarse_iterations;
        run.q_ratio = q1;
        run.c = stick_radius_from_moments(&deficit_points);
        run.c_fit = fit_stick_radius(&ratio_points, a_exact);
        run.c_stick_area = (stick_area / std::f64::consts::PI).sqrt();
        let contact_area: Real = geo
            .nodes
            .iter()
            .zip(&normal.solution.lambda_n)
            .filter(|(_, &l)| l > 0.0)
            .map(|(n, _)| n.weight)
            .sum();
        run.a_contact_area = (contact_area / std::f64::consts::PI).sqrt();
        run.c_exact = c_exact;
        run.traction_l2_err = (num / den).sqrt();
        run.coulomb_excess = excess;
        run.kkt = res.kkt.max().max(normal.kkt.max());
        runs.push(run);
    }
    Ok(runs)
}

/// The stick radius `c` from the moments of the stick deficit `D = μ p − |q|`: for Mindlin's
/// traction `D(ρ) = μ p₀ (c/a) sqrt(1 − ρ²/c²)` for `ρ ≤ c` and `0` in the slip annulus, so
///
/// ```text
/// ∫ D dA = (2π/3) μ p₀ c³/a,   ∫ D ρ² dA = (4π/15) μ p₀ c⁵/a,   c² = (5/2) ∫ D ρ² dA / ∫ D dA,
/// ```
///
/// independent of `a`, `p₀` and `μ`. `points` are `(ρ_r, D_r)`, `D_r` the deficit of cell `r` as a
/// force (`κ_r (μ p_r − |q_r|)`, zero on slipping cells); the integrals become sums of nodal
/// forces. Returns NaN unless `Σ D_r > 0`.
pub fn stick_radius_from_moments(points: &[(Real, Real)]) -> Real {
    let (m0, m2) = points.iter().fold((0.0, 0.0), |(m0, m2), &(rho, d)| (m0 + d, m2 + d * rho * rho));
    if m0 > 0.0 {
        (2.5 * m2 / m0).sqrt()
    } else {
        Real::NAN
    }
}

/// The stick radius `c` of Mindlin's traction ratio fitted to the nodal ratios `φ_r = |q_r|/(μ p_r)`
/// (`= ‖Λ_t,r‖` when `g_c = μ p`): with the Hertz radius `a`,
///
/// ```text
/// φ(r; c) = 1 − sqrt((c² − r²)⁺ / (a² − r²))      (r < a),
/// c = argmin_{0 ≤ c ≤ a} Σ_r κ_r (φ_r − φ(r_r; c))²   over the points (r_r, φ_r, κ_r) with r_r < a,
/// ```
///
/// by a scan of 400 values and a golden-section refinement around the best one.
pub fn fit_stick_radius(points: &[(Real, Real, Real)], a: Real) -> Real {
    let cost = |c: Real| -> Real {
        points
            .iter()
            .filter(|(r, _, _)| *r < a)
            .map(|&(r, phi, w)| {
                let model = 1.0 - ((c * c - r * r).max(0.0) / (a * a - r * r)).sqrt();
                w * (phi - model).powi(2)
            })
            .sum()
    };
    let n = 400;
    let best = (0..=n)
        .map(|k| a * k as Real / n as Real)
        .min_by(|x, y| cost(*x).total_cmp(&cost(*y)))
        .unwrap_or(0.0);
    let (mut lo, mut hi) = ((best - a / n as Real).max(0.0), (best + a / n as Real).min(a));
    let golden = 0.5 * (5.0_f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (x1, x2) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
        if cost(x1) < cost(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mindlin's deficit on a fine polar grid (cell forces = deficit × cell area), with slipping
    /// cells (zero deficit) out to `a`: the moments give `c` to the quadrature error.
    #[test]
    fn moments_recover_mindlin_stick_radius() {
        let (a, p0, mu) = (0.1, 0.06, 0.3);
        for c in [0.02, 0.05, 0.09] {
            let (nr, nt) = (2000, 64);
            let mut points = Vec::new();
            for i in 0..nr {
                let (r0, r1) = (a * i as Real / nr as Real, a * (i + 1) as Real / nr as Real);
                let rho = 0.5 * (r0 + r1);
                let area = std::f64::consts::PI * (r1 * r1 - r0 * r0) / nt as Real;
                let d = mu * p0 * (c / a) * (1.0 - (rho / c).powi(2)).max(0.0).sqrt();
                points.extend((0..nt).map(|_| (rho, d * area)));
            }
            let got = stick_radius_from_moments(&points);
            assert!((got / c - 1.0).abs() < 1e-4, "c = {c}: got {got}");
        }
        assert!(stick_radius_from_moments(&[(0.01, 0.0)]).is_nan());
    }
}
