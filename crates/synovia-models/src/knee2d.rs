//! A sagittal-plane (plane-strain) tibiofemoral contact model driven through the ISO 14243-1
//! gait cycle (the `knee2d` example, `docs/knee2d.md`).
//!
//! # Model
//!
//! Axes: `x` anterior, `y` proximal; lengths in mm, forces in N, stresses in MPa.
//!
//! * **Femur**: a circular condyle, bone (`radii[0] ≤ r ≤ R_b`) with a bonded cartilage layer
//!   (`R_b ≤ r ≤ R_b + t_f`), meshed by [`layered_arc_2d`] (matching nodes on the interface,
//!   tied). The inner bone arc is driven by a prescribed rigid translation.
//! * **Tibia**: a bone block (`60 × 20 mm`) with a bonded cartilage layer of thickness `t_t` on
//!   top, both meshed by [`rectangle`] refined toward `x = 0`; the base is clamped.
//! * **Contact**: the two cartilage surfaces, non-matching, node-to-segment
//!   ([`ContactPair::node_to_segment`]): slave nodes on the (flat) tibial cartilage, master
//!   segments on the femoral cartilage. Frictionless (synovial joints have μ ≈ 0.01–0.02, which
//!   changes the normal load transfer by a similar relative amount).
//!
//! # Kinematics per pose
//!
//! The flexion angle `θ(t)` is a rotation of the femur about the condyle centre
//! ([`RigidMotion`], a rotation). Linear (small-strain) elasticity cannot carry a 58° rigid
//! rotation as a displacement (the linearised strain of a rotation is `cos θ − 1`, 47 % at
//! 58°), so each pose is a separate small-deformation problem measured from the femur in its
//! posed orientation. The femur is modelled in its **body frame** ([`BodyPlacement`]): its
//! mesh and stiffness stay those of the reference pose, the contact geometry is built with
//! the femur placed at `R(θ(t))(x − c) + c` ([`StaticContact::place_bodies`]) and the rows of
//! the femoral nodes act on displacements in the femur frame (`R(θ)ᵀ n`), and the prescribed
//! motion of the driven arc is rotated into that frame. The stiffness is therefore factorised
//! **once for the whole cycle** ([`KneeCycle`]); only the contact rows change from pose to
//! pose. This is the same problem as re-meshing the femur in each pose ([`Knee2d::model`],
//! kept as the reference; `tests/suite/knee2d.rs` compares the two). For a frictionless contact the
//! solution of a pose does not depend on the path, so no state is carried between steps. With
//! flexion the contact moves over the femoral cartilage (toward the posterior condyle), i.e.
//! over different elements of the femur mesh. Femoral displacements of a [`KneePose`] are in
//! the femur frame ([`BodyPlacement::to_global`] turns them into space);
//! [`synovia::output::contact_vtu`] writes the posed configuration.
//!
//! # Load control
//!
//! The ISO axial force `F(t)` (N) is applied per unit slice thickness, `P(t) = F(t) / w` with
//! the effective condyle width `w` ([`Knee2d::width`], 30 mm). The vertical translation `δ` of
//! the femur's driven arc that makes the contact resultant equal `P(t)` is found per step by a
//! secant iteration on `δ` (one contact solve per iterate on the cycle's factorisation, warm
//! started), to the relative tolerance [`Knee2d::tolerance`].

use std::error::Error;
use std::f64::consts::PI;
use std::sync::Arc;
use std::time::Instant;

use synovia_contact::operators::{BodyPlacement, ContactGeometry, ContactPair};
use synovia_contact::{ContactSolution, ContactSolver, SolverReport, StaticContact, StaticContactResult};
use synovia_fem::{BodyId, ElasticParams, Model};
use synovia_material::plane_strain;
use synovia_mesh::generators::{layered_arc_2d, rectangle, Grading};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::BoundaryKind;
use synovia_time::history::{LoadHistory, PiecewiseLinear, RigidMotion, SharedValue};

/// Errors of the knee model (mesh, model, contact and iteration failures).
pub type KneeError = Box<dyn Error + Send + Sync>;

/// ISO 14243-1:2009 axial force (N) over the gait cycle (% of cycle), **an approximation**
/// digitised from the load curve of the standard (load-controlled knee wear simulator):
/// two peaks of 2600 N at ≈ 13 % and ≈ 50 %, a swing-phase minimum of ≈ 168 N.
pub const ISO14243_AXIAL_FORCE: &[(Real, Real)] = &[
    (0.0, 168.0),
    (3.0, 500.0),
    (6.0, 1150.0),
    (9.0, 1900.0),
    (11.0, 2400.0),
    (13.0, 2600.0),
    (15.0, 2450.0),
    (18.0, 2000.0),
    (22.0, 1550.0),
    (27.0, 1250.0),
    (32.0, 1150.0),
    (37.0, 1300.0),
    (42.0, 1750.0),
    (46.0, 2250.0),
    (50.0, 2600.0),
    (53.0, 2250.0),
    (56.0, 1500.0),
    (59.0, 750.0),
    (62.0, 300.0),
    (65.0, 168.0),
    (80.0, 168.0),
    (100.0, 168.0),
];

/// ISO 14243-1:2009 flexion angle (degrees) over the gait cycle (% of cycle), **an
/// approximation** digitised from the standard's curve: stance flexion of ≈ 20° near 15 %,
/// near extension at ≈ 40 %, the swing-phase maximum of 58° near 72 %, back to 0° at 100 %.
pub const ISO14243_FLEXION_DEG: &[(Real, Real)] = &[
    (0.0, 0.0),
    (4.0, 7.0),
    (8.0, 14.0),
    (12.0, 18.5),
    (16.0, 20.0),
    (20.0, 18.0),
    (26.0, 12.0),
    (32.0, 7.0),
    (38.0, 4.5),
    (44.0, 6.0),
    (50.0, 11.0),
    (55.0, 20.0),
    (60.0, 34.0),
    (65.0, 48.0),
    (70.0, 56.5),
    (73.0, 58.0),
    (77.0, 56.0),
    (82.0, 47.0),
    (87.0, 33.0),
    (92.0, 17.0),
    (96.0, 6.0),
    (100.0, 0.0),
];

/// The extent `max x − min x` of the loaded contact nodes (`Λ_n > 0`; the contact length of a
/// sagittal model), and the row and value of the peak pressure `max Λ_n`.
fn contact_length_and_peak(geo: &ContactGeometry<2>, lambda_n: &[Real]) -> (Real, usize, Real) {
    let xs = (0..geo.len()).filter(|&r| lambda_n[r] > 0.0).map(|r| geo.nodes[r].position[0]);
    let length = xs.clone().fold(Real::NEG_INFINITY, Real::max) - xs.fold(Real::INFINITY, Real::min);
    let (peak_r, peak) =
        lambda_n
            .iter()
            .copied()
            .enumerate()
            .fold((0, 0.0), |(ri, m), (r, l)| if l > m { (r, l) } else { (ri, m) });
    (length, peak_r, peak)
}

/// The ISO 14243-1 axial force `F(t)` in N, `t` the fraction of the cycle (`0 ≤ t ≤ 1`).
///
/// # Errors
/// Never for the built-in table (kept fallible as [`PiecewiseLinear::new`]).
pub fn iso14243_axial_force() -> Result<PiecewiseLinear, KneeError> {
    let pts: Vec<(Real, Real)> = ISO14243_AXIAL_FORCE.iter().map(|&(p, f)| (p / 100.0, f)).collect();
    Ok(PiecewiseLinear::new(&pts)?)
}

/// The ISO 14243-1 flexion angle `θ(t)` in radians, `t` the fraction of the cycle.
///
/// # Errors
/// Never for the built-in table.
pub fn iso14243_flexion() -> Result<PiecewiseLinear, KneeError> {
    let pts: Vec<(Real, Real)> =
        ISO14243_FLEXION_DEG.iter().map(|&(p, a)| (p / 100.0, a.to_radians())).collect();
    Ok(PiecewiseLinear::new(&pts)?)
}

/// Parameters of the sagittal knee model (see the [module documentation](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct Knee2d {
    /// Inner radius of the femoral bone arc (the driven boundary), mm.
    pub femur_inner_radius: Real,
    /// Radius of the subchondral bone surface of the condyle, mm.
    pub condyle_bone_radius: Real,
    /// Femoral cartilage thickness, mm.
    pub femur_cartilage: Real,
    /// Tibial cartilage thickness, mm.
    pub tibia_cartilage: Real,
    /// Half the anteroposterior length of the tibial block, mm.
    pub tibia_half_length: Real,
    /// Depth of the tibial bone block below the cartilage, mm.
    pub tibia_depth: Real,
    /// Cartilage Young's modulus (MPa) and Poisson ratio.
    pub cartilage: (Real, Real),
    /// Bone Young's modulus (MPa) and Poisson ratio.
    pub bone: (Real, Real),
    /// Effective condyle width `w` (mm): the load per unit slice thickness is `F / w`.
    pub width: Real,
    /// Femur mesh: cells along the arc, across the bone, across the cartilage.
    pub femur_cells: (usize, usize, usize),
    /// Tibia mesh: cells along x, across the bone, across the cartilage.
    pub tibia_cells: (usize, usize, usize),
    /// Relative tolerance of the load balance `|P_contact − P| / P` of the secant iteration.
    pub tolerance: Real,
    /// Node-to-segment search distance (mm).
    pub search_distance: Real,
    /// Material (E in MPa, ν) of the femoral layer when it is not cartilage (e.g. the CoCr
    /// femoral component of a knee replacement, [`Knee2d::tkr`]); `None`: [`Knee2d::cartilage`].
    pub femur_layer_material: Option<(Real, Real)>,
    /// Material of the tibial layer when it is not cartilage (e.g. a UHMWPE insert); `None`:
    /// [`Knee2d::cartilage`].
    pub tibia_layer_material: Option<(Real, Real)>,
    /// Material of the tibial block when it is not bone (e.g. a metal tray); `None`:
    /// [`Knee2d::bone`].
    pub tibia_base_material: Option<(Real, Real)>,
    /// Width (mm) of the region around `x = 0` toward which the tibial mesh is refined (ratio 4).
    pub tibia_refinement_width: Real,
    /// Body names: femoral bone, femoral layer, tibial block, tibial layer (VTU piece names).
    pub body_names: [&'static str; 4],
}

impl Default for Knee2d {
    fn default() -> Self {
        Self {
            femur_inner_radius: 10.0,
            condyle_bone_radius: 20.0,
            femur_cartilage: 2.5,
            tibia_cartilage: 2.5,
            tibia_half_length: 30.0,
            tibia_depth: 20.0,
            cartilage: (10.0, 0.45),
            bone: (800.0, 0.3),
            width: 30.0,
            femur_cells: (200, 10, 5),
            tibia_cells: (180, 24, 5),
            tolerance: 1e-4,
            search_distance: 4.0,
            femur_layer_material: None,
            tibia_layer_material: None,
            tibia_base_material: None,
            tibia_refinement_width: 24.0,
            body_names: ["femur_bone", "femur_cartilage", "tibia_bone", "tibia_cartilage"],
        }
    }
}

/// The figures of one pose of the cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct KneeStep {
    /// Cycle fraction `t`.
    pub time: Real,
    /// Flexion angle, degrees.
    pub flexion_deg: Real,
    /// ISO axial force `F(t)`, N.
    pub load_n: Real,
    /// Applied load per unit thickness `P = F / w`, N/mm.
    pub load_per_mm: Real,
    /// Vertical resultant of the contact tractions, `|Σ_r κ_r Λ_n,r n_r · e_y|`, N/mm.
    pub contact_force_per_mm: Real,
    /// Horizontal resultant of the contact tractions, N/mm (≈ 0 for the flat plateau).
    pub contact_shear_per_mm: Real,
    /// `|contact_force − P| / P`.
    pub balance_error: Real,
    /// Largest nodal contact pressure `max Λ_n`, MPa.
    pub peak_pressure: Real,
    /// Extent of the active contact nodes along x, mm.
    pub contact_length: Real,
    /// x of the pressure peak on the tibial plateau, mm.
    pub peak_x: Real,
    /// Vertical approach `δ` of the femur's driven arc, mm.
    pub approach: Real,
    /// Contact solves of the secant iteration.
    pub solves: usize,
    /// Contact solver iterations, summed over the solves.
    pub solver_iterations: usize,
    /// Largest KKT residual of the accepted solution.
    pub kkt: Real,
    /// Wall time of the pose (model, factorisation, solves), s.
    pub seconds: Real,
}

/// One solved pose of a [`KneeCycle`]: the figures, the cycle's model and contact problem (its
/// geometry placed at this pose) and the solution.
#[derive(Debug)]
pub struct KneePose<'a> {
    /// Figures of the pose.
    pub step: KneeStep,
    /// The model: the femur in its body frame (reference pose), shared by every pose.
    pub model: &'a Model<2>,
    /// The contact problem (the cycle's one factorisation; the geometry of this pose).
    pub contact: &'a StaticContact<2>,
    /// The accepted contact solution (femoral displacements in the femur frame).
    pub result: StaticContactResult<2>,
}

/// A knee model set up for a sequence of poses: the femur in its body frame, the stiffness
/// factorised once ([`Knee2d::cycle`]); each [`KneeCycle::solve_pose`] places the femur and
/// rebuilds the contact rows only (see the [module documentation](self)).
#[derive(Debug)]
pub struct KneeCycle {
    knee: Knee2d,
    model: Model<2>,
    pairs: Vec<ContactPair<2>>,
    contact: StaticContact<2>,
    /// Flexion angle of the current pose, read by the prescribed motion of the driven arc.
    angle: SharedValue,
    femur: [BodyId; 2],
    force: PiecewiseLinear,
    flexion: PiecewiseLinear,
    /// `Λ_n` of the last accepted pose, the warm start of the next pose's first solve.
    last_pressure: Option<Vec<Real>>,
    /// `dP/dδ` of the last pose's final secant step and its load `P`: the predictor of the
    /// next pose's approach.
    last_slope: Option<Real>,
    last_target: Option<Real>,
}

impl Knee2d {
    /// A coarse mesh for tests (≈ 3 000 dofs).
    pub fn coarse() -> Self {
        Self { femur_cells: (100, 5, 3), tibia_cells: (90, 10, 3), ..Self::default() }
    }

    /// A total knee replacement (the `tkr2d` example, `docs/knee2d.md`): a 4 mm CoCr femoral
    /// component (E = 210 GPa, ν = 0.3) on the femoral bone arc (outer radius 24 mm), on a 9 mm
    /// UHMWPE insert (E = 700 MPa, ν = 0.46) on a metal (Ti-6Al-4V, E = 110 GPa, ν = 0.3) tray
    /// block; the tibial mesh is refined toward the narrower contact of the stiff materials.
    pub fn tkr() -> Self {
        Self {
            condyle_bone_radius: 20.0,
            femur_cartilage: 4.0,
            tibia_cartilage: 9.0,
            tibia_depth: 10.0,
            femur_layer_material: Some((210_000.0, 0.3)),
            tibia_layer_material: Some((700.0, 0.46)),
            tibia_base_material: Some((110_000.0, 0.3)),
            femur_cells: (320, 8, 4),
            tibia_cells: (200, 6, 18),
            tibia_refinement_width: 8.0,
            search_distance: 2.0,
            body_names: ["femur_bone", "femoral_component", "tibial_tray", "tibial_insert"],
            ..Self::default()
        }
    }

    /// A coarse [`Knee2d::tkr`] mesh for tests.
    pub fn tkr_coarse() -> Self {
        Self { femur_cells: (160, 4, 2), tibia_cells: (100, 3, 9), ..Self::tkr() }
    }

    /// The condyle centre in the reference (touching) position: the femoral cartilage touches
    /// the tibial cartilage surface `y = 0` at `x = 0`.
    pub fn condyle_centre(&self) -> Point<2> {
        Point::<2>::new(0.0, self.condyle_bone_radius + self.femur_cartilage)
    }

    /// The flexion as a rigid motion of the femur: rotation by `θ(t)` about the condyle centre.
    ///
    /// # Errors
    /// Never for the built-in table.
    pub fn flexion_motion(&self) -> Result<RigidMotion<2>, KneeError> {
        Ok(RigidMotion::<2>::rotation(self.condyle_centre(), iso14243_flexion()?))
    }

    /// The model **re-meshed** in the pose of cycle fraction `time`: bodies 0 `femur_bone`, 1
    /// `femur_cartilage`, 2 `tibia_bone`, 3 `tibia_cartilage`; the femur mesh is placed in the
    /// pose and its inner arc moves down by the model time `δ` (the "time" argument of the
    /// solves is the approach `δ`). One factorisation per pose; the cycle itself uses the body
    /// frame instead ([`Knee2d::cycle`]), and this model is the reference it is tested against.
    ///
    /// # Errors
    /// Mesh, material or model errors.
    pub fn model(&self, time: Real) -> Result<(Model<2>, Vec<ContactPair<2>>), KneeError> {
        let (model, pairs, _) = self.build_model(Some(time), None)?;
        Ok((model, pairs))
    }

    /// The model with the femur in its body frame (the reference pose, θ = 0): the driven arc
    /// moves by `δ` downward **in space**, i.e. by `R(θ)ᵀ (0, −δ)` in the femur frame, with `θ`
    /// read from `angle` at every solve. Returns the model, the contact pair and the femur's
    /// two bodies (bone, layer).
    ///
    /// # Errors
    /// Mesh, material or model errors.
    pub fn body_frame_model(
        &self,
        angle: SharedValue,
    ) -> Result<(Model<2>, Vec<ContactPair<2>>, [BodyId; 2]), KneeError> {
        self.build_model(None, Some(angle))
    }

    fn build_model(
        &self,
        posed_at: Option<Real>,
        frame_angle: Option<SharedValue>,
    ) -> Result<(Model<2>, Vec<ContactPair<2>>, [BodyId; 2]), KneeError> {
        let c = self.condyle_centre();
        let (na, nb, nc) = self.femur_cells;
        // body-frame arc: the contact point of flexion θ is at the body angle −90° − θ
        let range = ((-170.0_f64).to_radians(), (-60.0_f64).to_radians());
        let radii = [
            self.femur_inner_radius,
            self.condyle_bone_radius,
            self.condyle_bone_radius + self.femur_cartilage,
        ];
        let mut layers = layered_arc_2d(c, &radii, range, na, &[nb, nc])?;
        if let Some(time) = posed_at {
            let motion = self.flexion_motion()?;
            for m in &mut layers {
                m.map_nodes(|x| motion.position(x, time))?;
            }
        }
        let mut f_cart = layers.pop().ok_or("layered_arc_2d returned no layers")?;
        let mut f_bone = layers.pop().ok_or("layered_arc_2d returned one layer")?;
        f_bone.set_part_kind("inner", BoundaryKind::Prescribed)?;
        f_cart.set_part_kind("outer", BoundaryKind::Contact)?;

        let (nx, nyb, nyc) = self.tibia_cells;
        let l = self.tibia_half_length;
        let gx = Grading::Refined { center: 0.0, width: self.tibia_refinement_width, ratio: 4.0 };
        let tc = self.tibia_cartilage;
        let mut t_bone =
            rectangle(-l, l, -tc - self.tibia_depth, -tc, nx, nyb, gx, Grading::TowardHigh { ratio: 1.08 })?;
        let mut t_cart = rectangle(-l, l, -tc, 0.0, nx, nyc, gx, Grading::Uniform)?;
        t_bone.set_part_kind("bottom", BoundaryKind::Clamped)?;
        t_cart.set_part_kind("top", BoundaryKind::Contact)?;

        let mat = |m: Option<(Real, Real)>, d: (Real, Real)| {
            let (e, nu) = m.unwrap_or(d);
            plane_strain(e, nu).map(Arc::new)
        };
        let [n_fb, n_fc, n_tb, n_tc] = self.body_names;
        let mut model = Model::<2>::new();
        let fb = model.add_body(n_fb, f_bone, mat(None, self.bone)?)?;
        let fc = model.add_body(n_fc, f_cart, mat(self.femur_layer_material, self.cartilage)?)?;
        let tb = model.add_body(n_tb, t_bone, mat(self.tibia_base_material, self.bone)?)?;
        let tcb = model.add_body(n_tc, t_cart, mat(self.tibia_layer_material, self.cartilage)?)?;
        model.tie(fb, "outer", fc, "inner")?;
        model.tie(tb, "top", tcb, "bottom")?;
        match frame_angle {
            // R(θ)ᵀ (0, −δ) = (−δ sin θ, −δ cos θ)
            Some(angle) => model.prescribe(fb, "inner", move |_, d| {
                let (s, c) = angle.get().sin_cos();
                Vector::<2>::new(-d * s, -d * c)
            })?,
            None => model.prescribe(fb, "inner", |_, d| Vector::<2>::new(0.0, -d))?,
        };
        let pair = ContactPair::node_to_segment("tibia-femur", tcb, "top", fc, "outer")
            .with_search_distance(self.search_distance);
        Ok((model, vec![pair], [fb, fc]))
    }

    /// Sets the model up for a sequence of poses: the femur in its body frame
    /// ([`Knee2d::body_frame_model`]) and one factorisation of the stiffness with the contact
    /// parts' dofs ordered last ([`StaticContact::new`]).
    ///
    /// # Errors
    /// Model or factorisation errors.
    pub fn cycle(&self) -> Result<KneeCycle, KneeError> {
        let angle = SharedValue::new(0.0);
        let (model, pairs, femur) = self.body_frame_model(angle.clone())?;
        let contact = StaticContact::new(&model, &pairs, ElasticParams::default())?;
        Ok(KneeCycle {
            knee: self.clone(),
            model,
            pairs,
            contact,
            angle,
            femur,
            force: iso14243_axial_force()?,
            flexion: iso14243_flexion()?,
            last_pressure: None,
            last_slope: None,
            last_target: None,
        })
    }

    /// Solves the poses `times` in order on one [`KneeCycle`] (one factorisation; each pose
    /// started from the previous approach), calling `each` after every pose.
    ///
    /// # Errors
    /// From [`KneeCycle::solve_pose`] or `each`.
    pub fn run(
        &self,
        times: &[Real],
        solver: &dyn ContactSolver,
        mut each: impl FnMut(&KneePose<'_>) -> Result<(), KneeError>,
    ) -> Result<Vec<KneeStep>, KneeError> {
        let mut cycle = self.cycle()?;
        let mut guess = None;
        let mut steps = Vec::with_capacity(times.len());
        for &t in times {
            let pose = cycle.solve_pose(t, solver, guess)?;
            guess = Some(pose.step.approach);
            each(&pose)?;
            steps.push(pose.step);
        }
        Ok(steps)
    }
}

impl KneeCycle {
    /// The model (femur in its body frame).
    pub fn model(&self) -> &Model<2> {
        &self.model
    }
    /// The contact problem (factorisation and the geometry of the last pose).
    pub fn contact(&self) -> &StaticContact<2> {
        &self.contact
    }
    /// The knee parameters.
    pub fn knee(&self) -> &Knee2d {
        &self.knee
    }

    /// The placement of every body at the flexion angle `theta` (radians): the femur's two
    /// bodies rotated about the condyle centre, the tibia where its mesh is.
    ///
    /// # Errors
    /// If `theta` is not finite.
    pub fn placements(&self, theta: Real) -> Result<Vec<BodyPlacement<2>>, KneeError> {
        femur_placements(self.knee.condyle_centre(), theta, &self.femur, self.model.bodies().len())
    }

    /// Solves the pose of cycle fraction `time` under the ISO load: secant iteration on the
    /// approach `δ` (starting from `guess`, e.g. the previous pose's) until the contact
    /// resultant equals `F(t) / w` within [`Knee2d::tolerance`].
    ///
    /// # Errors
    /// Model or contact failures, or no convergence of the secant iteration in 40 solves.
    pub fn solve_pose(
        &mut self,
        time: Real,
        solver: &dyn ContactSolver,
        guess: Option<Real>,
    ) -> Result<KneePose<'_>, KneeError> {
        let start = Instant::now();
        let load_n = self.force.value(time);
        let theta = self.flexion.value(time);
        let target = load_n / self.knee.width;
        self.angle.set(theta);
        let placements = self.placements(theta)?;
        let previous = self.contact.place_bodies(&self.model, &self.pairs, &placements)?;
        // warm start: the last pose's pressures carried to this pose's contact nodes
        let carried = self.last_pressure.take().map(|l| ContactSolution {
            u: Vec::new(),
            lambda_n: self.contact.geometry().transfer(&previous, &l),
            lambda_t: Vec::new(),
            report: SolverReport::default(),
        });
        let (model, contact) = (&self.model, &self.contact);
        let mut solves = 0;
        let mut its = 0;
        // the secant iterates need only the multipliers; U and the KKT check are completed
        // for the accepted one
        let mut solve =
            |d: Real, warm: Option<&ContactSolution>| -> Result<(Real, ContactSolution), KneeError> {
                let (sol, coarse) = contact.solve_multipliers(model, d, solver, None, None, warm)?;
                solves += 1;
                its += sol.report.iterations + coarse;
                let f = traction_resultant(contact.geometry(), &sol.lambda_n)[1].abs();
                Ok((f, sol))
            };
        let tolerance = self.knee.tolerance * target;
        // predictor: the last pose's approach moved along its force slope to this pose's load
        let slope_prev = self.last_slope.filter(|s| *s > 0.0 && s.is_finite());
        let mut d0 = guess.filter(|g| *g > 0.0).unwrap_or(0.05);
        if let (Some(slope), Some(last_target)) = (slope_prev, self.last_target) {
            d0 = (d0 + (target - last_target) / slope).clamp(0.5 * d0, 2.0 * d0);
        }
        // bracket from below: a positive force
        let (mut f0, mut r0) = solve(d0, carried.as_ref())?;
        while f0 <= 0.0 {
            d0 *= 2.0;
            (f0, r0) = solve(d0, Some(&r0))?;
            if d0 > 10.0 {
                return Err(format!("t = {time}: no contact up to an approach of {d0} mm").into());
            }
        }
        let (d1, r1, slope) = if (f0 - target).abs() <= tolerance {
            (d0, r0, slope_prev)
        } else {
            // first step: the last pose's slope, or (first pose) the power law of a thin layer,
            // contact force ~ δ^(3/2) roughly
            let mut d1 = match slope_prev {
                Some(slope) => (d0 + (target - f0) / slope).clamp(0.3 * d0, 3.0 * d0),
                None => d0 * (target / f0).powf(2.0 / 3.0).clamp(0.3, 3.0),
            };
            let (mut f1, mut r1) = solve(d1, Some(&r0))?;
            let mut slope = (f1 - f0) / (d1 - d0);
            let mut iter = 0;
            while (f1 - target).abs() > tolerance {
                iter += 1;
                if iter > 40 {
                    return Err(format!("t = {time}: load balance not reached: {f1} vs {target} N/mm").into());
                }
                let mut d2 =
                    if slope > 0.0 && slope.is_finite() { d1 + (target - f1) / slope } else { 1.5 * d1 };
                if d2 <= 0.0 {
                    d2 = 0.5 * d1;
                }
                let (f2, r2) = solve(d2, Some(&r1))?;
                slope = (f2 - f1) / (d2 - d1);
                (d0, f0) = (d1, f1);
                (d1, f1, r1) = (d2, f2, r2);
            }
            let _ = (d0, f0);
            (d1, r1, Some(slope).filter(|s| *s > 0.0 && s.is_finite()).or(slope_prev))
        };
        let r1 = contact.complete(model, d1, None, None, r1)?;
        let geo = contact.geometry();
        let force = resultant(geo, &r1);
        let (contact_length, peak_r, peak) = contact_length_and_peak(geo, &r1.solution.lambda_n);
        let step = KneeStep {
            time,
            flexion_deg: theta.to_degrees(),
            load_n,
            load_per_mm: target,
            contact_force_per_mm: force[1].abs(),
            contact_shear_per_mm: force[0],
            balance_error: (force[1].abs() - target).abs() / target,
            peak_pressure: peak,
            contact_length,
            peak_x: geo.nodes.get(peak_r).map_or(0.0, |n| n.position[0]),
            approach: d1,
            solves,
            solver_iterations: its,
            kkt: r1.kkt.max(),
            seconds: start.elapsed().as_secs_f64(),
        };
        self.last_pressure = Some(r1.solution.lambda_n.clone());
        self.last_slope = slope;
        self.last_target = Some(target);
        Ok(KneePose { step, model, contact, result: r1 })
    }
}

/// The resultant `Σ_r κ_r Λ_n,r n_r` of the contact tractions on the slave side (N/mm).
pub fn resultant(geometry: &ContactGeometry<2>, result: &StaticContactResult<2>) -> Vector<2> {
    traction_resultant(geometry, &result.solution.lambda_n)
}

/// `Σ_r κ_r Λ_n,r n_r` for nodal pressures `lambda_n` (one per contact node of `geometry`).
pub fn traction_resultant(geometry: &ContactGeometry<2>, lambda_n: &[Real]) -> Vector<2> {
    geometry
        .nodes
        .iter()
        .zip(lambda_n)
        .fold(Vector::<2>::zeros(), |acc, (n, &l)| acc + n.normal * (n.weight * l))
}

/// The cycle fractions of `n` uniform steps over one cycle, `i / n` for `i = 0, …, n − 1`, with
/// the first load peak (13 %) added.
pub fn cycle_times(n: usize) -> Vec<Real> {
    let mut t: Vec<Real> = (0..n).map(|i| i as Real / n as Real).collect();
    if !t.iter().any(|&x| (x - 0.13).abs() < 1e-9) {
        t.push(0.13);
        t.sort_by(Real::total_cmp);
    }
    t
}

/// Half-space Hertz estimate `(a, p₀)` of a cylinder of radius `r` pressed with `p` (N/mm) on a
/// flat, both sides of modulus `e`, ratio `nu`: `E* = E / (2 (1 − ν²))`, `a = √(4 P R / (π E*))`,
/// `p₀ = 2 P / (π a)`.
pub fn hertz_estimate(p: Real, r: Real, e: Real, nu: Real) -> (Real, Real) {
    let e_star = e / (2.0 * (1.0 - nu * nu));
    let a = (4.0 * p * r / (PI * e_star)).sqrt();
    (a, 2.0 * p / (PI * a))
}

/// One pose of the cycle with hyperelastic cartilage ([`nonlinear_cycle`]).
#[derive(Debug, Clone, PartialEq)]
pub struct NonlinearKneeStep {
    /// The figures of the pose as for the linear cycle; `solver_iterations` counts the Newton
    /// iterations of the pose (each a warm-started linearised contact solve).
    pub step: KneeStep,
    /// Numeric factorisations of the tangent over the pose.
    pub factorisations: usize,
    /// The contact gap of the accepted solution evaluated on its own deformed configuration:
    /// `max |d(x + u)|` over the active slave nodes, with `d` the signed distance along the
    /// normal field of the deformed master surface ([`SmoothNodeToSegment`] rebuilt at
    /// `x + u`), mm. Zero for an exact geometry fixed point.
    pub gap_error: Real,
    /// The largest penetration `max(0, −d(x + u))` over every slave node there, mm.
    pub penetration: Real,
    /// The shortest facet of the tibial cartilage surface (reference mesh), mm: the scale of
    /// [`NonlinearKneeStep::gap_error`].
    pub mesh_size: Real,
    /// The pose was solved under load control inside the Newton iteration
    /// ([`nonlinear_cycle_with`]); `false`: by the secant iteration on `δ`.
    pub load_controlled: bool,
    /// Contact solves of the load control's secant iterations on `δ` over the pose (the
    /// trials of [`synovia::nonlinear::LoadControl::trials`], at least one per Newton
    /// iteration; 0 for a pose solved by the secant iteration around whole Newton solves).
    pub load_control_trials: usize,
}

impl Knee2d {
    /// The Newton parameters of [`nonlinear_cycle`]: the contact geometry rebuilt on the
    /// deformed configuration until it settles (`GeometryUpdate::Converged`, relative change
    /// of the solution per rebuild ≤ 1e-4), Aitken-relaxed from ω = 0.9, passes with a moving
    /// geometry ended at a relative residual of 1e-3 (the last one at 1e-7: over the 41 poses of
    /// `knee2d_nonlinear` the peak pressures, contact lengths and approaches are the same to
    /// the printed 4–5 digits as with 1e-8, and those of 1e-8 to 5 digits as with 1e-10; the
    /// geometry tolerance sets their accuracy), the last pass also ended by a full step of at
    /// most the geometry tolerance once the geometry has settled
    /// (`NewtonParams::settled_increment`: 207 → 149 Newton iterations over the cycle, the
    /// figures the same to the printed digits but two fifth digits of a peak pressure),
    /// modified Newton (the tangent kept while full steps contract the residual by 0.5; with
    /// the femur placed in its own frame, `FemurFrame::Placed`, the tangent is also kept across
    /// poses: 176 Newton iterations and 28 factorisations over the 41 poses, against 194 and
    /// 20 with 0.7 and 160 and 43 with 0.3, the cycle 4 % faster than with 0.7; with the femur's
    /// meshes moved, 0.7 gave 45 factorisations against 51 with 0.5). docs/nonlinear.md
    /// ("Fifth round", "The femur in its own frame") gives the measurements behind these
    /// choices.
    pub fn nonlinear_newton_params() -> synovia::nonlinear::NewtonParams {
        synovia::nonlinear::NewtonParams::default()
            .with_tolerance(1e-7)
            .with_geometry_update(synovia::nonlinear::GeometryUpdate::Converged)
            .with_geometry_tolerance(1e-4)
            .with_geometry_relaxation(0.9)
            .with_geometry_aitken(true)
            .with_geometry_pass_tolerance(Some(1e-3))
            .with_settled_increment(Some(1e-4))
            .with_max_geometry_passes(60)
            .with_tangent_reuse(Some(0.5))
    }

    /// The model of [`Knee2d::model`] at the pose `time` with both cartilage layers (the layers
    /// whose material is [`Knee2d::cartilage`]) compressible neo-Hookean with the small-strain
    /// constants `(E, ν)` of the linear model, in total Lagrangian finite strain, the bones
    /// linear, and the contact pair [`SmoothNodeToSegment`] (tibial cartilage slave, femoral
    /// cartilage master, [`Knee2d::search_distance`]). Returns the model, the pair and one
    /// kinematics per body.
    ///
    /// # Errors
    /// Mesh, material or model errors.
    #[allow(clippy::type_complexity)]
    pub fn neo_hookean_model(
        &self,
        time: Real,
    ) -> Result<(Model<2>, Vec<ContactPair<2>>, Vec<synovia_fem::Kinematics>), KneeError> {
        let (model, _) = self.model(time)?;
        self.with_neo_hookean_layers(model)
    }

    /// [`Knee2d::neo_hookean_model`] with the femur in its body frame
    /// ([`Knee2d::body_frame_model`]: the reference pose θ = 0, the driven arc moved by
    /// `R(θ)ᵀ (0, −δ)` with `θ` read from `angle`), to be placed at each pose
    /// ([`synovia::nonlinear::NonlinearContact::place_bodies`]). Returns the model, the pair,
    /// one kinematics per body and the femur's two bodies (bone, layer).
    ///
    /// # Errors
    /// Mesh, material or model errors.
    #[allow(clippy::type_complexity)]
    pub fn neo_hookean_body_frame_model(
        &self,
        angle: SharedValue,
    ) -> Result<(Model<2>, Vec<ContactPair<2>>, Vec<synovia_fem::Kinematics>, [BodyId; 2]), KneeError> {
        let (model, _, femur) = self.build_model(None, Some(angle))?;
        let (model, pairs, kinematics) = self.with_neo_hookean_layers(model)?;
        Ok((model, pairs, kinematics, femur))
    }

    /// The cartilage layers of `model` neo-Hookean in finite strain and the
    /// [`SmoothNodeToSegment`] pair (see [`Knee2d::neo_hookean_model`]).
    #[allow(clippy::type_complexity)]
    fn with_neo_hookean_layers(
        &self,
        mut model: Model<2>,
    ) -> Result<(Model<2>, Vec<ContactPair<2>>, Vec<synovia_fem::Kinematics>), KneeError> {
        use synovia_fem::Kinematics;
        let (e, nu) = self.cartilage;
        let law: Arc<dyn synovia_material::Material<2>> = Arc::new(synovia_material::neo_hookean(e, nu)?);
        let [_, n_fc, _, n_tc] = self.body_names;
        let mut kinematics = vec![Kinematics::SmallStrain; model.bodies().len()];
        for (name, layer) in [(n_fc, self.femur_layer_material), (n_tc, self.tibia_layer_material)] {
            if layer.is_none() {
                let id = model.body_id(name)?;
                model.body_mut(id)?.material = law.clone();
                kinematics[id.0] = Kinematics::FiniteStrain;
            }
        }
        let pair = ContactPair::custom(
            "tibia-femur",
            model.body_id(n_tc)?,
            "top",
            Arc::new(SmoothNodeToSegment {
                body: model.body_id(n_fc)?,
                part: "outer".into(),
                search_distance: self.search_distance,
            }),
        );
        Ok((model, vec![pair], kinematics))
    }
}

/// The cycle with hyperelastic cartilage (docs/nonlinear.md): the model of
/// [`Knee2d::neo_hookean_body_frame_model`] built **once**, at the first pose, and one
/// [`synovia::nonlinear::NonlinearContact`] (one symbolic analysis) for the cycle. At each
/// pose the femur's two bodies are placed in space, turned about the condyle centre `c` by
/// the flexion `θ` ([`synovia::nonlinear::NonlinearContact::place_bodies`], the poses of
/// [`Knee2d::model`]; the meshes and the tangent's factorisation stay in the femur's frame),
/// and the converged state is carried to the new placement — the femur's displacement field
/// kept in space ([`nonlinear_cycle_with`] with [`Carry::InSpace`] and [`FemurFrame::Placed`]),
/// so every pose continues from the previous pose's solution instead of ramping from the
/// reference configuration. Each pose is solved by the Newton
/// iteration with `params` (e.g. [`Knee2d::nonlinear_newton_params`]) under the same load
/// control as the linear cycle: a secant iteration on the approach `δ` until the vertical
/// contact resultant `Σ κ_r Λ_n,r n_r · e_y` equals `F(t) / w` within [`Knee2d::tolerance`],
/// started at `guesses[i]` (e.g. the linear cycle's approach) scaled by the last pose's
/// ratio of approach to guess, and stepped with the last pose's slope `dF/dδ`. With
/// finite-strain kinematics the contact geometry (pairing, normals, gaps) is that of the
/// deformed configuration, rebuilt until it settles; [`NonlinearKneeStep::gap_error`] measures
/// what is left of it.
///
/// # Errors
/// Model, Newton or contact failures; no load balance within 40 solves.
pub fn nonlinear_cycle(
    knee: &Knee2d,
    times: &[Real],
    guesses: &[Real],
    solver: &dyn ContactSolver,
    params: synovia::nonlinear::NewtonParams,
) -> Result<Vec<NonlinearKneeStep>, KneeError> {
    nonlinear_cycle_with(knee, times, guesses, solver, params, Carry::InSpace, true, FemurFrame::Placed)
}

/// One placement per body of a model of `n_bodies`: the femur's bodies turned by `theta`
/// about the condyle centre `centre`, the others where their meshes are.
fn femur_placements(
    centre: Point<2>,
    theta: Real,
    femur: &[BodyId; 2],
    n_bodies: usize,
) -> Result<Vec<BodyPlacement<2>>, KneeError> {
    let turned = BodyPlacement::planar_rotation(centre, theta)?;
    Ok((0..n_bodies)
        .map(|b| if femur.iter().any(|f| f.0 == b) { turned } else { BodyPlacement::identity() })
        .collect())
}

/// The femur's displacement field in space at the converged state of `nl`: one
/// [`SpatialField`] per femur body, on its meshes placed by `placement` (the identity for
/// meshes moved in place), with the values `R u` (about `centre`).
fn femur_fields_in_space(
    nl: &synovia::nonlinear::NonlinearContact<2>,
    model: &Model<2>,
    femur: &[BodyId; 2],
    placement: &BodyPlacement<2>,
    centre: Point<2>,
) -> Result<Vec<SpatialField>, KneeError> {
    let lifts = nl.dofs().lifts(model, nl.time())?;
    let disp = nl.dofs().expand(nl.reduced(), &lifts)?;
    let mut fields = Vec::with_capacity(femur.len());
    for &b in femur {
        let mut mesh = model.body(b)?.mesh.clone();
        mesh.map_nodes(|x| placement.position(x))?;
        let values: Vec<Vector<2>> = disp[b.0].iter().map(|u| placement.to_global(u)).collect();
        fields.push(SpatialField::new(&mesh, &values, centre));
    }
    Ok(fields)
}

/// How [`nonlinear_cycle_with`] carries the converged state of one pose to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Carry {
    /// The femur's deformed shape rotated with its mesh: `u ↦ R(Δθ)(u − t) + t`,
    /// `t = (0, −δ)`, contact forces `c ↦ R(Δθ) c`.
    Rotate,
    /// The femur's displacement field kept in space: the new displacement of a node at
    /// `x' = c + R(Δθ)(x − c)` is the old field interpolated (P1) at `x'`
    /// (`u'(x') = u(x')`, [`SpatialField`]); the deformed contact zone stays under the load.
    InSpace,
}

/// How [`nonlinear_cycle_with`] moves the femur between poses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FemurFrame {
    /// The femur in its body frame, placed at each pose
    /// ([`synovia::nonlinear::NonlinearContact::place_bodies`],
    /// [`Knee2d::neo_hookean_body_frame_model`]): its meshes, and so the tangent's
    /// factorisation, stay as they are; the contact geometry is that of the placed deformed
    /// femur, `c + R(θ)(x + u − c)`.
    Placed,
    /// The femur's two meshes rotated about the condyle centre by the change of flexion
    /// (the tangent refactorised at every pose).
    MovedMesh,
}

/// [`nonlinear_cycle`] with the state carried between poses by `carry`, and with
/// `load_control` the poses after the first solved under load control inside the Newton
/// iteration ([`synovia::nonlinear::NonlinearContact::step_controlled`]: every iteration
/// chooses the approach `δ` at which its linearised problem balances `F(t) / w`), falling back
/// to the secant iteration on `δ` around whole Newton solves if that fails; without it, the
/// secant iteration for every pose; `frame` chooses how the femur moves between poses.
///
/// # Errors
/// As [`nonlinear_cycle`].
#[allow(clippy::too_many_arguments)]
pub fn nonlinear_cycle_with(
    knee: &Knee2d,
    times: &[Real],
    guesses: &[Real],
    solver: &dyn ContactSolver,
    params: synovia::nonlinear::NewtonParams,
    carry: Carry,
    control: bool,
    frame: FemurFrame,
) -> Result<Vec<NonlinearKneeStep>, KneeError> {
    use synovia::nonlinear::NonlinearContact;
    let force = iso14243_axial_force()?;
    let flexion = iso14243_flexion()?;
    let mut steps = Vec::with_capacity(times.len());
    let Some(&first) = times.first() else { return Ok(steps) };
    let setup = Instant::now();
    let placed = frame == FemurFrame::Placed;
    // the flexion read by the body-frame model's driven arc (`FemurFrame::Placed`)
    let angle = SharedValue::new(flexion.value(first));
    let (mut model, pairs, kinematics) = if placed {
        let (model, pairs, kinematics, _) = knee.neo_hookean_body_frame_model(angle.clone())?;
        (model, pairs, kinematics)
    } else {
        knee.neo_hookean_model(first)?
    };
    let femur = [model.body_id(knee.body_names[0])?, model.body_id(knee.body_names[1])?];
    let centre = knee.condyle_centre();
    let n_bodies = model.bodies().len();
    // the tangent is refactorised at most Newton iterations (56 times over the 41 poses of the
    // cycle): METIS nested dissection gives it a factor of 1.21M entries against AMD's 1.77M
    // (the 2D default), −10 % of the cycle's CPU time (docs/nonlinear.md, "Fourth round")
    let elastic = ElasticParams::default().with_ordering(synovia::fem::OrderingChoice::Metis);
    let mut nl = NonlinearContact::new(&model, &pairs, &kinematics, elastic, params)?;
    let mut theta_model = flexion.value(first);
    if placed {
        nl.place_bodies(&model, &femur_placements(centre, theta_model, &femur, n_bodies)?)?;
    }
    let mut setup_s = setup.elapsed().as_secs_f64();
    // the last pose's approach and its guess, and the slope dF/dδ of its last secant step
    let mut last_approach: Option<(Real, Option<Real>)> = None;
    let mut last_slope: Option<(Real, Real)> = None;
    for (i, &time) in times.iter().enumerate() {
        let start = Instant::now();
        let theta = flexion.value(time);
        let load_n = force.value(time);
        let target = load_n / knee.width;
        let tolerance = knee.tolerance * target;
        // the femur placed in this pose, its deformed state carried along
        if theta != theta_model {
            // where the femur's meshes are in space: placed in its frame, or moved in place
            let p_old = if placed {
                BodyPlacement::planar_rotation(centre, theta_model)?
            } else {
                BodyPlacement::identity()
            };
            let fields = match carry {
                Carry::Rotate => None,
                Carry::InSpace => Some(femur_fields_in_space(&nl, &model, &femur, &p_old, centre)?),
            };
            let slot = |b: BodyId| femur.iter().position(|f| *f == b);
            // the arc's translation t = (0, −δ) stays vertical in space
            let t = Vector::<2>::new(0.0, -nl.time());
            // the femur's frame after the move (placed: its body frame turned by θ; moved
            // meshes: space) and the turn of its shape within that frame (moved meshes only)
            let (p_new, shape) = if placed {
                (BodyPlacement::planar_rotation(centre, theta)?, BodyPlacement::identity())
            } else {
                (BodyPlacement::identity(), BodyPlacement::planar_rotation(centre, theta - theta_model)?)
            };
            for &b in femur.iter().filter(|_| !placed) {
                model.body_mut(b)?.mesh.map_nodes(|x| shape.position(x))?;
            }
            let model_ref = &model;
            let displacement = |b: BodyId, i: usize, u: &Vector<2>| match (slot(b), &fields) {
                // the field in space at the node's new position, in the new frame
                (Some(k), Some(fields)) => model_ref
                    .body(b)
                    .ok()
                    .and_then(|body| body.mesh.nodes().get(i))
                    .map_or(*u, |x| p_new.to_body(&fields[k].value(&p_new.position(x)))),
                // the shape turned with the femur, the arc's translation kept vertical
                (Some(_), None) => shape.to_global(&(u - p_old.to_body(&t))) + p_new.to_body(&t),
                (None, _) => *u,
            };
            // contact forces kept in space (InSpace) or turned with the femur (Rotate)
            let force = |b: BodyId, _: usize, c: &Vector<2>| match (slot(b), &fields) {
                (Some(_), Some(_)) => p_new.to_body(&p_old.to_global(c)),
                (Some(_), None) => shape.to_global(c),
                (None, _) => *c,
            };
            if placed {
                nl.map_state_in_frames(displacement, force);
                angle.set(theta);
                nl.place_bodies(&model, &femur_placements(centre, theta, &femur, n_bodies)?)?;
            } else {
                nl.map_state(displacement, force);
            }
            theta_model = theta;
        }
        let (mut solves, mut newton, mut factorisations) = (0usize, 0usize, 0usize);
        let mut extra = (0usize, 0usize, 0usize);
        let model_ref = &model;
        let mut solve = |d: Real,
                         nl: &mut NonlinearContact<2>|
         -> Result<(Real, synovia::nonlinear::NonlinearResult<2>), KneeError> {
            let r = nl.step_to(model_ref, d, solver)?;
            solves += 1;
            newton += r.report.total_iterations;
            factorisations += r.report.factorisations;
            let f = traction_resultant(nl.geometry(), &r.contact.solution.lambda_n)[1].abs();
            Ok((f, r))
        };
        // the guess scaled by the last pose's ratio of approach to guess (the nonlinear layer
        // is stiffer than the linear one by a factor that changes slowly along the cycle)
        let mut d0 = match (guesses.get(i).copied().filter(|g| *g > 0.0), last_approach) {
            (Some(g), Some((d, Some(g_last)))) => g * d / g_last,
            (Some(g), _) => g,
            (None, Some((d, _))) => d,
            (None, None) => 0.05,
        };
        // load control inside the Newton iteration from the previous pose's state (the approach
        // chosen per iteration on the linearised problem); the secant iteration on δ around
        // whole Newton solves when it fails, and for the first pose
        let mut controlled = None;
        let mut trials = 0;
        if let (true, Some((slope, f_last))) = (control, last_slope) {
            let resultant = |g: &ContactGeometry<2>, l: &[Real]| traction_resultant(g, l)[1].abs();
            let mut ctl = synovia::nonlinear::LoadControl {
                resultant: &resultant,
                target,
                tolerance,
                slope: slope * (target / f_last).cbrt(),
                trials: 0,
            };
            // on failure the state is unchanged: the secant iteration below
            if let Ok(r) = nl.step_controlled(&model, d0, solver, &mut ctl) {
                extra.0 += 1;
                extra.1 += r.report.total_iterations;
                extra.2 += r.report.factorisations;
                last_slope = Some((ctl.slope, target));
                trials = ctl.trials;
                controlled = Some((r.time, r));
            }
        }
        let was_controlled = controlled.is_some();
        let (d1, r1) = if let Some(done) = controlled {
            done
        } else {
            let (mut f0, mut r0) = solve(d0, &mut nl)?;
            while f0 <= 0.0 {
                d0 *= 2.0;
                if d0 > 10.0 {
                    return Err(format!("t = {time}: no contact up to an approach of {d0} mm").into());
                }
                (f0, r0) = solve(d0, &mut nl)?;
            }
            let (d1, r1) = if (f0 - target).abs() <= tolerance {
                (d0, r0)
            } else {
                // first step: the last pose's slope carried to this load (a thin layer's force
                // grows roughly as δ^(3/2), so dF/dδ ∝ F^(1/3)), or (first pose) that power law
                let mut d1 = match last_slope {
                    Some((slope, f_last)) if slope > 0.0 && f_last > 0.0 => {
                        let slope = slope * (f0 / f_last).cbrt();
                        (d0 + (target - f0) / slope).clamp(0.5 * d0, 2.0 * d0)
                    }
                    _ => d0 * (target / f0).powf(2.0 / 3.0).clamp(0.5, 2.0),
                };
                let (mut f1, mut r1) = solve(d1, &mut nl)?;
                let mut iter = 0;
                while (f1 - target).abs() > tolerance {
                    iter += 1;
                    if iter > 40 {
                        return Err(
                            format!("t = {time}: load balance not reached: {f1} vs {target} N/mm").into()
                        );
                    }
                    let slope = (f1 - f0) / (d1 - d0);
                    let mut d2 =
                        if slope > 0.0 && slope.is_finite() { d1 + (target - f1) / slope } else { 1.5 * d1 };
                    if d2 <= 0.0 {
                        d2 = 0.5 * d1;
                    }
                    let (f2, r2) = solve(d2, &mut nl)?;
                    (d0, f0) = (d1, f1);
                    (d1, f1, r1) = (d2, f2, r2);
                }
                let slope = (f1 - f0) / (d1 - d0);
                if slope > 0.0 && slope.is_finite() {
                    last_slope = Some((slope, f1));
                }
                (d1, r1)
            };
            (d1, r1)
        };
        solves += extra.0;
        newton += extra.1;
        factorisations += extra.2;
        last_approach = Some((d1, guesses.get(i).copied().filter(|g| *g > 0.0)));
        let contact = &r1.contact;
        let geo = nl.geometry();
        let force_v = traction_resultant(geo, &contact.solution.lambda_n);
        let (contact_length, peak_r, peak) = contact_length_and_peak(geo, &contact.solution.lambda_n);
        // the gaps of the solution on its own deformed configuration: d(x + u) = d_total − [u] · n
        let disp = &contact.displacement;
        let deformed = if placed {
            ContactGeometry::new_placed(
                &model,
                &pairs,
                &femur_placements(centre, theta_model, &femur, n_bodies)?,
            )?
            .updated(&model, &pairs, disp)?
        } else {
            ContactGeometry::new_deformed(&model, &pairs, disp)?
        };
        let active_nodes: std::collections::HashSet<usize> = (0..geo.len())
            .filter(|&r| contact.solution.lambda_n[r] > 0.0)
            .map(|r| geo.nodes[r].node.1)
            .collect();
        let (mut gap_error, mut penetration) = (0.0_f64, 0.0_f64);
        for (r, node) in deformed.nodes.iter().enumerate() {
            let jump = deformed.jump(r, disp).ok_or("contact node outside the displacement field")?;
            let d = node.gap - jump.dot(&node.normal);
            penetration = penetration.max(-d);
            if active_nodes.contains(&node.node.1) {
                gap_error = gap_error.max(d.abs());
            }
        }
        let tibia = model.body(model.body_id(knee.body_names[3])?)?;
        let mesh_size = tibia
            .mesh
            .boundary_part("top")?
            .facets()
            .filter_map(|f| match f {
                [a, b] => Some((tibia.mesh.node(*a) - tibia.mesh.node(*b)).norm()),
                _ => None,
            })
            .fold(Real::INFINITY, Real::min);
        steps.push(NonlinearKneeStep {
            step: KneeStep {
                time,
                flexion_deg: flexion.value(time).to_degrees(),
                load_n,
                load_per_mm: target,
                contact_force_per_mm: force_v[1].abs(),
                contact_shear_per_mm: force_v[0],
                balance_error: (force_v[1].abs() - target).abs() / target,
                peak_pressure: peak,
                contact_length,
                peak_x: geo.nodes.get(peak_r).map_or(0.0, |n| n.position[0]),
                approach: d1,
                solves,
                solver_iterations: newton,
                kkt: contact.kkt.max(),
                seconds: start.elapsed().as_secs_f64() + std::mem::take(&mut setup_s),
            },
            factorisations,
            gap_error,
            penetration: penetration.max(0.0),
            mesh_size,
            load_controlled: was_controlled,
            load_control_trials: trials,
        });
    }
    Ok(steps)
}

/// A nodal field of a P1 triangle mesh of an annular sector about `centre`, evaluated at any
/// point by linear interpolation on the cell that contains it,
/// `v(x) = Σ_a φ_a(x) v_a` (barycentric `φ_a`); a point just outside the mesh (e.g. on the
/// circle beyond a chord of the boundary, every barycentric coordinate ≥ −1/4 on the nearest
/// cell of its angle) by linear extrapolation on that cell, and a point farther out (beyond
/// the sector's angles) by the value of the nearest node. Cells are found through bins of the
/// polar angle about `centre`.
#[derive(Debug, Clone)]
pub struct SpatialField {
    nodes: Vec<Point<2>>,
    cells: Vec<[usize; 3]>,
    values: Vec<Vector<2>>,
    centre: Point<2>,
    start: Real,
    width: Real,
    bins: Vec<Vec<usize>>,
    /// The node indices sorted by `x₀` (ties by index), for the nearest-node search.
    by_x: Vec<usize>,
}

impl SpatialField {
    /// The field `values` (one per node) on `mesh`, binned about `centre`.
    pub fn new(mesh: &synovia_mesh::Mesh<2>, values: &[Vector<2>], centre: Point<2>) -> Self {
        let nodes: Vec<Point<2>> = mesh.nodes().to_vec();
        let cells: Vec<[usize; 3]> = mesh.cells().filter_map(|c| <[usize; 3]>::try_from(c).ok()).collect();
        let angle = |x: &Point<2>| (x[1] - centre[1]).atan2(x[0] - centre[0]);
        let (lo, hi) = nodes
            .iter()
            .map(angle)
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(l, h), a| (l.min(a), h.max(a)));
        let n_bins = cells.len().clamp(1, 1024);
        let width = ((hi - lo) / n_bins as Real).max(Real::EPSILON);
        let mut bins = vec![Vec::new(); n_bins];
        for (k, c) in cells.iter().enumerate() {
            let a = c.map(|i| angle(&nodes[i]));
            let (amin, amax) = (
                a.iter().copied().fold(Real::INFINITY, Real::min),
                a.iter().copied().fold(Real::NEG_INFINITY, Real::max),
            );
            if amax - amin > PI {
                continue;
            }
            let first = (((amin - lo) / width).floor().max(0.0) as usize).min(n_bins - 1);
            let last = (((amax - lo) / width).floor().max(0.0) as usize).min(n_bins - 1);
            for bin in &mut bins[first..=last] {
                bin.push(k);
            }
        }
        let mut by_x: Vec<usize> = (0..nodes.len()).collect();
        by_x.sort_by(|&a, &b| nodes[a][0].total_cmp(&nodes[b][0]).then(a.cmp(&b)));
        Self { nodes, cells, values: values.to_vec(), centre, start: lo, width, bins, by_x }
    }

    /// The node nearest to `x` (the smallest index among equally near ones), `None` for an
    /// empty mesh: a scan of the nodes sorted by `x₀` outward from `x₀`, ended on each side when
    /// `(x₀ − y₀)²` alone exceeds the best squared distance.
    fn nearest_node(&self, x: &Point<2>) -> Option<usize> {
        let start = self.by_x.partition_point(|&i| self.nodes[i][0] < x[0]);
        let mut best: Option<(Real, usize)> = None;
        let mut consider = |i: usize| -> bool {
            let d = self.nodes[i] - x;
            if best.is_some_and(|(b, _)| d[0] * d[0] > b) {
                return false;
            }
            let d2 = d.norm_squared();
            if best.is_none_or(|(b, j)| d2 < b || (d2 == b && i < j)) {
                best = Some((d2, i));
            }
            true
        };
        let (mut up, mut down) = (start, start);
        let (mut go_up, mut go_down) = (true, true);
        while go_up || go_down {
            if go_up {
                go_up = up < self.by_x.len() && consider(self.by_x[up]);
                up += 1;
            }
            if go_down {
                go_down = down > 0 && consider(self.by_x[down - 1]);
                down = down.saturating_sub(1);
            }
        }
        best.map(|(_, i)| i)
    }

    /// `v(x)` (see the type docs).
    pub fn value(&self, x: &Point<2>) -> Vector<2> {
        let a = (x[1] - self.centre[1]).atan2(x[0] - self.centre[0]);
        let bin = (a - self.start) / self.width;
        // the cell of the angle's bin whose smallest barycentric coordinate is largest: the
        // cell containing x, or (x in the sliver between a chord of the boundary and its arc)
        // the nearest one, extrapolated linearly
        let mut best: Option<(Real, [usize; 3], [Real; 3])> = None;
        if bin >= 0.0 && (bin as usize) < self.bins.len() {
            for &k in &self.bins[bin as usize] {
                let [i, j, l] = self.cells[k];
                let (p, q, r) = (self.nodes[i], self.nodes[j], self.nodes[l]);
                let det = (q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]);
                if det == 0.0 {
                    continue;
                }
                let s = ((x[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (x[1] - p[1])) / det;
                let t = ((q[0] - p[0]) * (x[1] - p[1]) - (x[0] - p[0]) * (q[1] - p[1])) / det;
                let phi = [1.0 - s - t, s, t];
                let worst = phi.iter().copied().fold(Real::INFINITY, Real::min);
                if best.as_ref().is_none_or(|b| worst > b.0) {
                    best = Some((worst, [i, j, l], phi));
                }
                if worst >= 0.0 {
                    break;
                }
            }
        }
        match best {
            Some((worst, idx, phi)) if worst >= -0.25 => {
                idx.iter().zip(phi).fold(Vector::<2>::zeros(), |acc, (&n, w)| acc + self.values[n] * w)
            }
            _ => self.nearest_node(x).map_or_else(Vector::<2>::zeros, |i| self.values[i]),
        }
    }
}

/// Node-to-segment contact (2D) with a **continuous master normal** for finite-strain runs,
/// where the contact geometry is rebuilt on the deformed configuration (docs/nonlinear.md).
///
/// The built-in [`synovia_contact::discretisation::NodeToSegment`] uses the normal of the
/// master segment a slave node projects onto. That normal jumps at every master vertex, so the
/// geometry as a function of the deformation is discontinuous: on the loaded `knee2d` poses a
/// slave node near a vertex is pushed by one segment's normal onto the next segment and back,
/// and the geometry fixed point does not exist (docs/nonlinear.md, measured). Here the master
/// normal is interpolated along the segment from the unit nodal normals `n_a`, `n_b` of the
/// master surface at the positions of the context,
///
/// ```text
/// ñ(ξ) = (1 − ξ) n_a + ξ n_b,   n(ξ) = ñ(ξ) / |ñ(ξ)|,   x(ξ) = (1 − ξ) x_a + ξ x_b,
/// ```
///
/// and the master point of a slave node `x_s` is where the normal field passes through it,
/// `(x_s − x(ξ)) × ñ(ξ) = 0` with `ξ ∈ [0, 1]` (a quadratic in `ξ`), on the facing segment
/// (`n(ξ) · n_s < 0`) closest to `x_s`. The row then has the normal `−n(ξ)`, master weights
/// `(1 − ξ, ξ)` and the gap `d = (x_s − x(ξ)) · n(ξ)`. At a vertex both segments give the same
/// point and normal, so the rows depend continuously on the positions. On the undeformed flat
/// or circular surfaces of `knee2d` it gives the same rows as the built-in discretisation up
/// to the discretisation of the circle (the nodal normal of an arc is its radial direction).
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothNodeToSegment {
    /// The master body.
    pub body: BodyId,
    /// Its contact part.
    pub part: String,
    /// Largest `|x_s − x(ξ)|` of a paired slave node (mm).
    pub search_distance: Real,
}

impl SmoothNodeToSegment {
    /// The master point `(ξ, x(ξ), n(ξ))` of `x` on the segment `a → b` with unit nodal normals
    /// `na`, `nb` (see the type docs), if the normal field passes through `x` over the segment.
    pub(crate) fn project(
        x: &Point<2>,
        (xa, xb): (&Point<2>, &Point<2>),
        (na, nb): (&Vector<2>, &Vector<2>),
    ) -> Option<(Real, Point<2>, Vector<2>)> {
        let cross = |u: &Vector<2>, v: &Vector<2>| u[0] * v[1] - u[1] * v[0];
        let a = x - xa;
        let e = xb - xa;
        let dn = nb - na;
        // f(ξ) = (a − ξ e) × (n_a + ξ dn) = c0 + c1 ξ + c2 ξ²
        let c0 = cross(&a, na);
        let c1 = cross(&a, &dn) - cross(&e, na);
        let c2 = -cross(&e, &dn);
        let scale = e.norm() * (1.0 + dn.norm());
        let mut roots = Vec::with_capacity(2);
        if c2.abs() <= 1e-14 * scale {
            if c1.abs() > 0.0 {
                roots.push(-c0 / c1);
            }
        } else {
            let disc = c1 * c1 - 4.0 * c2 * c0;
            if disc >= 0.0 {
                let s = disc.sqrt();
                // the numerically stable pair of roots
                let q = -0.5 * (c1 + c1.signum() * s);
                if q != 0.0 {
                    roots.push(q / c2);
                    roots.push(c0 / q);
                } else {
                    roots.push(0.0);
                }
            }
        }
        let tol = 1e-12;
        roots
            .into_iter()
            .filter(|xi| xi.is_finite() && *xi >= -tol && *xi <= 1.0 + tol)
            .filter_map(|xi| {
                let xi = xi.clamp(0.0, 1.0);
                let n = na * (1.0 - xi) + nb * xi;
                let len = n.norm();
                (len > 0.0).then(|| (xi, xa + e * xi, n / len))
            })
            .min_by(|p, q| (x - p.1).norm().total_cmp(&(x - q.1).norm()))
    }
}

impl synovia_contact::ContactDiscretisation<2> for SmoothNodeToSegment {
    fn kind(&self) -> &str {
        "node-to-segment (smooth normal)"
    }

    fn partner_part(&self) -> Option<(BodyId, &str)> {
        Some((self.body, &self.part))
    }

    fn rows(
        &self,
        cx: &synovia_contact::PairContext<'_, 2>,
    ) -> Result<Vec<synovia_contact::ContactRow<2>>, synovia_contact::ContactError> {
        if self.body == cx.body() {
            return Err(cx.invalid("self-contact is not supported"));
        }
        if !(self.search_distance.is_finite() && self.search_distance > 0.0) {
            return Err(cx.invalid(format!("search distance {} must be positive", self.search_distance)));
        }
        let other = cx.model().body(self.body)?;
        let facets: Vec<Vec<usize>> =
            other.mesh.boundary_part(&self.part)?.facets().map(<[usize]>::to_vec).collect();
        let (Some(pos_k), Some(pos_l)) = (cx.positions(cx.body()), cx.positions(self.body)) else {
            return Err(cx.invalid("unknown body"));
        };
        let normals: std::collections::HashMap<usize, Vector<2>> =
            synovia_mesh::mesh::nodal_normals_at(pos_l, facets.iter().map(Vec::as_slice))
                .into_iter()
                .collect();
        // the segments with their nodal normals and bounding boxes widened by the search
        // distance: a master point x(ξ) lies on its segment, so a slave node outside the
        // widened box of a segment has no master point within the search distance there
        let sd = self.search_distance;
        let segments: Vec<(usize, usize, Vector<2>, Vector<2>, Point<2>, Point<2>)> = facets
            .iter()
            .filter_map(|f| {
                let [a, b] = f[..] else { return None };
                let (na, nb) = (normals.get(&a)?, normals.get(&b)?);
                let (xa, xb) = (pos_l[a], pos_l[b]);
                let lo = Point::<2>::new(xa[0].min(xb[0]) - sd, xa[1].min(xb[1]) - sd);
                let hi = Point::<2>::new(xa[0].max(xb[0]) + sd, xa[1].max(xb[1]) + sd);
                Some((a, b, *na, *nb, lo, hi))
            })
            .collect();
        let mut rows = Vec::new();
        for &(i, ns) in cx.normals() {
            let x = &pos_k[i];
            let mut best: Option<(Real, usize, usize, Real, Vector<2>, Point<2>)> = None;
            for (a, b, na, nb, lo, hi) in &segments {
                let (a, b) = (*a, *b);
                if x[0] < lo[0] || x[0] > hi[0] || x[1] < lo[1] || x[1] > hi[1] {
                    continue;
                }
                let Some((xi, xm, n)) = Self::project(x, (&pos_l[a], &pos_l[b]), (na, nb)) else {
                    continue;
                };
                let dist = (x - xm).norm();
                if n.dot(&ns) >= 0.0 || dist > self.search_distance {
                    continue;
                }
                if best.as_ref().is_none_or(|bst| dist < bst.0) {
                    best = Some((dist, a, b, xi, n, xm));
                }
            }
            let Some((_, a, b, xi, n_l, xm)) = best else { continue };
            let n = -n_l;
            let master: Vec<(BodyId, usize, Real)> = [(a, 1.0 - xi), (b, xi)]
                .into_iter()
                .filter(|(_, w)| *w > 0.0)
                .map(|(j, w)| (self.body, j, w))
                .collect();
            rows.push(synovia_contact::ContactRow {
                node: i,
                partner: None,
                master,
                normal: n,
                weight: cx.weight(i),
                gap: (xm - x).dot(&n),
            });
        }
        if rows.is_empty() {
            return Err(cx.invalid(format!("no slave node has a master point on part `{}`", self.part)));
        }
        Ok(rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The master point of [`SmoothNodeToSegment`] on two segments of a unit arc (vertices at
    /// 80°, 90°, 100°, radial nodal normals): a point on the shared vertex's normal gets the
    /// same point and normal from both segments, and inside a segment the interpolated normal
    /// passes through the point.
    /// The nearest-node search of [`SpatialField`] (sorted by `x₀`) finds the node that a
    /// scan of all nodes finds, for points inside, around and far outside an annular mesh.
    #[test]
    fn nearest_node_equals_the_scan_of_all_nodes() {
        let knee = Knee2d::coarse();
        let (model, _) = knee.model(0.0).expect("model");
        let mesh = &model.bodies()[0].mesh;
        let values: Vec<Vector<2>> = mesh.nodes().iter().map(|x| Vector::<2>::new(x[0], -x[1])).collect();
        let field = SpatialField::new(mesh, &values, knee.condyle_centre());
        let scan = |x: &Point<2>| {
            mesh.nodes()
                .iter()
                .enumerate()
                .min_by(|u, v| (u.1 - x).norm().total_cmp(&(v.1 - x).norm()))
                .map(|(i, _)| i)
        };
        for k in 0..400 {
            let a = 0.37 * k as Real;
            let r = 5.0 + 0.11 * (k % 97) as Real;
            let x =
                knee.condyle_centre() + Vector::<2>::new(r * a.cos(), r * a.sin()) * (1.0 + (k % 5) as Real);
            assert_eq!(field.nearest_node(&x), scan(&x), "point {x:?}");
        }
        for &x in mesh.nodes().iter().step_by(7) {
            assert_eq!(field.nearest_node(&x), scan(&x));
        }
    }

    #[test]
    fn smooth_projection_is_continuous_at_a_vertex() {
        let at = |deg: Real| Vector::<2>::new(deg.to_radians().cos(), deg.to_radians().sin());
        let p = at;
        let x = Point::<2>::new(0.0, 1.2);
        let a = SmoothNodeToSegment::project(&x, (&p(80.0), &p(90.0)), (&at(80.0), &at(90.0)))
            .expect("segment 1");
        let b = SmoothNodeToSegment::project(&x, (&p(90.0), &p(100.0)), (&at(90.0), &at(100.0)))
            .expect("segment 2");
        assert!((a.0 - 1.0).abs() < 1e-12 && b.0.abs() < 1e-12, "ξ {} and {}", a.0, b.0);
        assert!((a.1 - b.1).norm() < 1e-12 && (a.2 - b.2).norm() < 1e-12);
        let y = Point::<2>::new(0.1, 1.1);
        let (xi, xm, n) =
            SmoothNodeToSegment::project(&y, (&p(80.0), &p(90.0)), (&at(80.0), &at(90.0))).expect("inside");
        let d = y - xm;
        assert!(xi > 0.0 && xi < 1.0, "ξ = {xi}");
        assert!((d[0] * n[1] - d[1] * n[0]).abs() < 1e-12, "the normal field misses the point");
        assert!(d.dot(&n) > 0.09 && d.dot(&n) < 0.11, "gap {}", d.dot(&n));
        // a point beyond the segment's normal fan has no master point on it
        assert!(SmoothNodeToSegment::project(
            &Point::<2>::new(-0.3, 1.1),
            (&p(80.0), &p(90.0)),
            (&at(80.0), &at(90.0))
        )
        .is_none());
    }
}
