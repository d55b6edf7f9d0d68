//! A 3D ball-in-socket hip contact model (femoral head in the acetabulum, P1 tetrahedra) under
//! a hip-joint force over the gait cycle (the `hip3d` example, `docs/knee2d.md`).
//!
//! # Model
//!
//! Lengths in mm, forces in N, stresses in MPa; the caps are around the `−z` axis of the joint
//! centre (the origin), meshed by [`layered_cap_3d`] (layers share the nodes of their common
//! sphere and are tied there).
//!
//! * **Femoral head**: bone (`15 ≤ r ≤ 23` mm) with a 2 mm cartilage layer (`23 ≤ r ≤ 25`),
//!   half-angle 70°. The inner bone sphere is driven by the rigid translation `(0, 0, −δ)`.
//! * **Acetabulum**: cartilage (`25.2 ≤ r ≤ 27.2`, a 0.2 mm radial clearance) on bone
//!   (`27.2 ≤ r ≤ 32`), half-angle 60°; the outer bone sphere is clamped.
//! * Cartilage E = 10 MPa, ν = 0.45; bone E = 800 MPa, ν = 0.3 (isotropic, small strain).
//! * **Contact**: frictionless node-to-facet ([`ContactPair::node_to_segment`]); slave nodes on
//!   the acetabular cartilage surface (the smaller cap, so every slave node projects onto the
//!   head), master facets on the head cartilage.
//!
//! # Load control
//!
//! The geometry does not change between load levels (the hip force is taken along the cap
//! axis), so the stiffness is factorised once. Per level, the approach `δ` is found by a secant
//! iteration (warm-started contact solves) until the axial contact resultant equals the hip
//! force `F(t)` ([`HIP_FORCE`], an approximate Paul/Bergmann-type curve) within
//! [`Hip3d::tolerance`].

use std::sync::Arc;
use std::time::Instant;

use synovia_contact::operators::{ContactGeometry, ContactPair};
use synovia_contact::{ContactSolver, StaticContact, StaticContactResult};
use synovia_fem::{ElasticParams, Model};
use synovia_material::isotropic;
use synovia_mesh::generators::layered_cap_3d;
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::BoundaryKind;
use synovia_time::history::{LoadHistory, PiecewiseLinear};

use crate::knee2d::KneeError;

/// Body weight (N) used to scale the hip force table.
pub const BODY_WEIGHT_N: Real = 750.0;

/// Resultant hip joint force (N) over the gait cycle (% of cycle) for a 750 N subject, **an
/// approximation** of the double-peaked walking curves of Paul (1967) and Bergmann et al.
/// (2001, instrumented prostheses): ≈ 2.8 BW at ≈ 15 % (after heel strike), a mid-stance dip of
/// ≈ 2 BW, ≈ 3 BW at ≈ 48 % (push-off), ≈ 0.3 BW in swing. ISO 14242-1 (hip wear simulators)
/// uses a similar double-peaked curve with 3 kN peaks.
pub const HIP_FORCE: &[(Real, Real)] = &[
    (0.0, 300.0),
    (5.0, 1200.0),
    (15.0, 2100.0),
    (25.0, 1650.0),
    (35.0, 1500.0),
    (48.0, 2250.0),
    (55.0, 1500.0),
    (62.0, 400.0),
    (80.0, 250.0),
    (100.0, 300.0),
];

/// The hip force `F(t)` (N), `t` the fraction of the cycle.
///
/// # Errors
/// Never for the built-in table.
pub fn hip_force() -> Result<PiecewiseLinear, KneeError> {
    let pts: Vec<(Real, Real)> = HIP_FORCE.iter().map(|&(p, f)| (p / 100.0, f)).collect();
    Ok(PiecewiseLinear::new(&pts)?)
}

/// Parameters of the hip model (see the [module documentation](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct Hip3d {
    /// Head radii: driven bone sphere, subchondral bone, cartilage surface (mm).
    pub head_radii: [Real; 3],
    /// Acetabulum radii: cartilage surface, subchondral bone, clamped outer bone (mm).
    pub socket_radii: [Real; 3],
    /// Half-angles of the head and socket caps (radians).
    pub half_angles: (Real, Real),
    /// Surface resolution `n_surface` of [`layered_cap_3d`] (head, socket).
    pub n_surface: (usize, usize),
    /// Radial cells (bone, cartilage) of each body.
    pub n_radial: (usize, usize),
    /// Cartilage Young's modulus (MPa) and Poisson ratio.
    pub cartilage: (Real, Real),
    /// Bone Young's modulus (MPa) and Poisson ratio.
    pub bone: (Real, Real),
    /// Relative tolerance of the load balance of the secant iteration.
    pub tolerance: Real,
    /// Node-to-facet search distance (mm).
    pub search_distance: Real,
}

impl Default for Hip3d {
    fn default() -> Self {
        Self {
            head_radii: [15.0, 23.0, 25.0],
            socket_radii: [25.5, 27.5, 32.0],
            half_angles: (80.0_f64.to_radians(), 70.0_f64.to_radians()),
            n_surface: (16, 14),
            n_radial: (3, 2),
            cartilage: (10.0, 0.45),
            bone: (800.0, 0.3),
            tolerance: 1e-3,
            search_distance: 1.0,
        }
    }
}

/// The figures of one load level.
#[derive(Debug, Clone, PartialEq)]
pub struct HipStep {
    /// Cycle fraction `t`.
    pub time: Real,
    /// Hip force `F(t)`, N.
    pub load_n: Real,
    /// Axial contact resultant `|Σ_r κ_r Λ_n,r n_r · e_z|`, N.
    pub contact_force_n: Real,
    /// Transverse contact resultant (x, y), N (≈ 0 by symmetry).
    pub contact_shear_n: Real,
    /// `|contact_force − F| / F`.
    pub balance_error: Real,
    /// Largest nodal contact pressure, MPa.
    pub peak_pressure: Real,
    /// Mean pressure `F / area`, MPa.
    pub mean_pressure: Real,
    /// Contact area (sum of the weights of the active nodes), mm².
    pub contact_area: Real,
    /// Active contact nodes.
    pub active_nodes: usize,
    /// Approach `δ` of the head, mm.
    pub approach: Real,
    /// Contact solves of the secant iteration.
    pub solves: usize,
    /// Largest KKT residual of the accepted solution.
    pub kkt: Real,
    /// Wall time of the level, s.
    pub seconds: Real,
}

/// The factorised hip model.
#[derive(Debug)]
pub struct HipModel {
    /// The model (bodies 0 head bone, 1 head cartilage, 2 socket cartilage, 3 socket bone).
    pub model: Model<3>,
    /// The contact problem.
    pub contact: StaticContact<3>,
}

impl Hip3d {
    /// A coarse mesh for tests.
    pub fn coarse() -> Self {
        Self { n_surface: (8, 7), n_radial: (1, 1), ..Self::default() }
    }

    /// Builds the model and factorises it; the model time is the approach `δ`.
    ///
    /// # Errors
    /// Mesh, material, model or contact-geometry errors.
    pub fn build(&self) -> Result<HipModel, KneeError> {
        let c = Point::<3>::zeros();
        let (nb, nc) = self.n_radial;
        let mut head = layered_cap_3d(c, &self.head_radii, self.half_angles.0, self.n_surface.0, &[nb, nc])?;
        let mut socket =
            layered_cap_3d(c, &self.socket_radii, self.half_angles.1, self.n_surface.1, &[nc, nb])?;
        let s_bone = socket.pop().ok_or("no socket bone layer")?;
        let s_cart = socket.pop().ok_or("no socket cartilage layer")?;
        let h_cart = head.pop().ok_or("no head cartilage layer")?;
        let h_bone = head.pop().ok_or("no head bone layer")?;
        let (mut h_bone, mut h_cart, mut s_cart, mut s_bone) = (h_bone, h_cart, s_cart, s_bone);
        h_bone.set_part_kind("inner", BoundaryKind::Prescribed)?;
        h_cart.set_part_kind("outer", BoundaryKind::Contact)?;
        s_cart.set_part_kind("inner", BoundaryKind::Contact)?;
        s_bone.set_part_kind("outer", BoundaryKind::Clamped)?;
        let mat = |(e, nu): (Real, Real)| isotropic(e, nu).map(Arc::new);
        let mut model = Model::<3>::new();
        let hb = model.add_body("head_bone", h_bone, mat(self.bone)?)?;
        let hc = model.add_body("head_cartilage", h_cart, mat(self.cartilage)?)?;
        let sc = model.add_body("socket_cartilage", s_cart, mat(self.cartilage)?)?;
        let sb = model.add_body("socket_bone", s_bone, mat(self.bone)?)?;
        model.tie(hb, "outer", hc, "inner")?;
        model.tie(sc, "outer", sb, "inner")?;
        model.prescribe(hb, "inner", |_, d| Vector::<3>::new(0.0, 0.0, -d))?;
        let pair = ContactPair::node_to_segment("socket-head", sc, "inner", hc, "outer")
            .with_search_distance(self.search_distance);
        let contact = StaticContact::new(&model, &[pair], ElasticParams::default())?;
        Ok(HipModel { model, contact })
    }

    /// Solves the load levels `times` (cycle fractions) in order on one factorisation, calling
    /// `each` with the figures and the accepted solution of every level.
    ///
    /// # Errors
    /// Model or contact failures, no convergence of the secant iteration, or from `each`.
    pub fn run(
        &self,
        hip: &HipModel,
        times: &[Real],
        solver: &dyn ContactSolver,
        mut each: impl FnMut(&HipStep, &StaticContactResult<3>) -> Result<(), KneeError>,
    ) -> Result<Vec<HipStep>, KneeError> {
        let clearance = self.socket_radii[0] - self.head_radii[2];
        let force = hip_force()?;
        let geo = hip.contact.geometry();
        let mut steps = Vec::with_capacity(times.len());
        let mut prev: Option<(Real, StaticContactResult<3>)> = None;
        for &time in times {
            let start = Instant::now();
            let target = force.value(time);
            let mut solves = 0;
            let mut solve = |d: Real,
                             warm: Option<&StaticContactResult<3>>|
             -> Result<(Real, StaticContactResult<3>), KneeError> {
                let res = hip.contact.solve(&hip.model, d, solver, None, None, warm.map(|w| &w.solution))?;
                solves += 1;
                Ok((resultant(geo, &res)[2].abs(), res))
            };
            // start from the previous level: penetration beyond the clearance ~ F^(0.8)
            let mut d0 = match &prev {
                Some((d, _)) => *d,
                None => clearance + 0.1,
            };
            let (mut f0, mut r0) = solve(d0, prev.as_ref().map(|p| &p.1))?;
            while f0 <= 0.0 {
                d0 = clearance + 2.0 * (d0 - clearance);
                (f0, r0) = solve(d0, Some(&r0))?;
                if d0 > 5.0 {
                    return Err(format!("t = {time}: no contact up to an approach of {d0} mm").into());
                }
            }
            let (mut d1, mut f1, mut r1) = (d0, f0, r0);
            if (f1 - target).abs() > self.tolerance * target {
                let s0 = d0 - clearance;
                d1 = clearance + s0 * (target / f0).powf(0.8).clamp(0.2, 5.0);
                let (fa, ra) = solve(d1, Some(&r1))?;
                (f1, r1) = (fa, ra);
            }
            let mut iter = 0;
            while (f1 - target).abs() > self.tolerance * target {
                iter += 1;
                if iter > 30 {
                    return Err(format!("t = {time}: load balance not reached: {f1} vs {target} N").into());
                }
                let slope = (f1 - f0) / (d1 - d0);
                let mut d2 =
                    if slope > 0.0 && slope.is_finite() { d1 + (target - f1) / slope } else { 1.2 * d1 };
                if d2 <= clearance {
                    d2 = 0.5 * (d1 + clearance);
                }
                let (f2, r2) = solve(d2, Some(&r1))?;
                (d0, f0) = (d1, f1);
                (d1, f1, r1) = (d2, f2, r2);
            }
            let res = resultant(geo, &r1);
            let lambda = &r1.solution.lambda_n;
            let active: Vec<usize> = (0..geo.len()).filter(|&r| lambda[r] > 0.0).collect();
            let area: Real = active.iter().map(|&r| geo.nodes[r].weight).sum();
            let peak = lambda.iter().copied().fold(0.0, Real::max);
            let step = HipStep {
                time,
                load_n: target,
                contact_force_n: res[2].abs(),
                contact_shear_n: res[0].hypot(res[1]),
                balance_error: (res[2].abs() - target).abs() / target,
                peak_pressure: peak,
                mean_pressure: if area > 0.0 { target / area } else { 0.0 },
                contact_area: area,
                active_nodes: active.len(),
                approach: d1,
                solves,
                kkt: r1.kkt.max(),
                seconds: start.elapsed().as_secs_f64(),
            };
            each(&step, &r1)?;
            steps.push(step);
            prev = Some((d1, r1));
        }
        Ok(steps)
    }
}

/// The resultant `Σ_r κ_r Λ_n,r n_r` of the contact tractions on the slave side (N).
pub fn resultant(geometry: &ContactGeometry<3>, result: &StaticContactResult<3>) -> Vector<3> {
    geometry
        .nodes
        .iter()
        .zip(&result.solution.lambda_n)
        .fold(Vector::<3>::zeros(), |acc, (n, &l)| acc + n.normal * (n.weight * l))
}
