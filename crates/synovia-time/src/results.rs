//! Per-step results: contact resultants, areas, pressures, stick/slip areas, energies; CSV output.

use std::io::Write;
use std::path::Path;

use synovia_contact::operators::ContactGeometry;
use synovia_contact::StaticContactResult;
use synovia_io::IoError;
use synovia_mesh::math::{Real, Vector};

/// Figures of one contact pair at one time level.
#[derive(Debug, Clone, PartialEq)]
pub struct PairRecord {
    /// Pair name.
    pub name: String,
    /// Resultant contact force acting on body `k` (normal and friction parts), 3 components
    /// (`z = 0` in 2D); per unit thickness in 2D.
    pub force: [Real; 3],
    /// Normal force `Σ_r κ_r Λ_n,r`.
    pub normal_force: Real,
    /// Magnitude of the friction force `‖Σ_c g_c κ_c Λ_t,c T_c‖`.
    pub tangential_force: Real,
    /// Contact area (length in 2D): `Σ κ_r` over the nodes with `Λ_n > 0`.
    pub contact_area: Real,
    /// Peak contact pressure `max Λ_n`.
    pub peak_pressure: Real,
    /// Area of the sticking cells (`‖Λ_t‖ < 1`).
    pub stick_area: Real,
    /// Area of the slipping cells (`‖Λ_t‖ = 1`).
    pub slip_area: Real,
    /// Moment of the contact forces on body `k` about the origin,
    /// `Σ_r x_r × f_r` over the contact nodes (normal and friction forces at the node's
    /// reference position `x_r`), 3 components (2D: only `z`).
    pub moment: [Real; 3],
    /// Centre of pressure: the contact nodes' reference positions weighted by their normal
    /// forces, `Σ_r κ_r Λ_n,r x_r / Σ_r κ_r Λ_n,r`; `None` without contact.
    pub centre_of_pressure: Option<[Real; 3]>,
    /// Mean contact pressure `normal_force / contact_area` (0 without contact).
    pub mean_pressure: Real,
}

impl PairRecord {
    /// A record of a pair without contact (every figure zero).
    pub fn empty(name: &str) -> Self {
        Self {
            name: name.to_string(),
            force: [0.0; 3],
            normal_force: 0.0,
            tangential_force: 0.0,
            contact_area: 0.0,
            peak_pressure: 0.0,
            stick_area: 0.0,
            slip_area: 0.0,
            moment: [0.0; 3],
            centre_of_pressure: None,
            mean_pressure: 0.0,
        }
    }
}

/// `x × f` of two vectors of dimension `D` embedded in 3D.
fn moment_of<const D: usize>(x: &Vector<D>, f: &Vector<D>) -> [Real; 3] {
    let e = |v: &Vector<D>| [v[0], v[1], if D > 2 { v[2] } else { 0.0 }];
    let (a, b) = (e(x), e(f));
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Figures of one time level.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StepRecord {
    /// Step index (0 = initial state).
    pub step: usize,
    /// Time `t_i`.
    pub time: Real,
    /// Per contact pair.
    pub pairs: Vec<PairRecord>,
    /// Friction work dissipated during this step, `Σ_c g_c κ_c ‖Δ[u_t]_c‖` (≥ 0).
    pub friction_dissipation: Real,
    /// Friction work dissipated since the start.
    pub cumulative_friction_dissipation: Real,
    /// Kinetic energy `½ Vᵀ M_ρ V` (dynamic stepping; 0 otherwise).
    pub kinetic_energy: Real,
    /// Strain energy `½ Uᵀ A⁽⁰⁾ U`.
    pub strain_energy: Real,
    /// Energy dissipated by viscosity and damping during this step (dynamic stepping).
    pub viscous_dissipation: Real,
    /// Contact solver iterations (summed over Coulomb fixed-point iterations).
    pub iterations: usize,
    /// Wall time of the step (s).
    pub step_s: Real,
    /// The contact solver that produced the accepted solution of this step
    /// ([`SolverReport::solver`](synovia_contact::SolverReport): e.g. `"pdas"`, or
    /// `"dual-mprgp"` after the `pdas-fallback` hand-over); empty without contact pairs.
    pub solver: String,
    /// Why the configured solver handed over to another one, if it did
    /// ([`SolverReport::fallback`](synovia_contact::SolverReport)).
    pub fallback: Option<String>,
    /// Per rigid body with mixed control (none without rigid bodies).
    pub rigid: Vec<RigidRecord>,
}

/// The state of a rigid body with mixed control at one level (`synovia::rigid`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RigidRecord {
    /// Rigid body name.
    pub name: String,
    /// Generalised coordinates `q` (translations in the length unit, angles in radians;
    /// 2D: `t_x, t_y, θ`, 3D: `t_x, t_y, t_z, θ_x, θ_y, θ_z`).
    pub dofs: Vec<Real>,
    /// Generalised forces `Q_k` the elastic bodies exert on the rigid body (forces, and
    /// moments about the axes of the angles through the moved reference point).
    pub reaction: Vec<Real>,
    /// The applied generalised force `F_k` of each force-controlled degree of freedom
    /// (`None`: prescribed).
    pub applied: Vec<Option<Real>>,
    /// Resultant force the elastic bodies exert on the rigid body (3 components, `z = 0` in 2D).
    pub force: [Real; 3],
    /// Its moment about the moved reference point `c + t` (3 components; 2D: only `z`).
    pub moment: [Real; 3],
    /// Largest `|Q_k + F_k| / scale_k` over the force-controlled degrees of freedom (0 if
    /// there are none).
    pub balance_error: Real,
    /// Contact solves spent on this level.
    pub solves: usize,
}

/// Computes the pair records of a contact solution.
pub fn pair_records<const D: usize>(
    geometry: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
) -> Vec<PairRecord> {
    let sol = &result.solution;
    let comps = D - 1;
    let mut out: Vec<PairRecord> = geometry
        .pairs
        .iter()
        .map(|(name, range)| {
            let mut force = Vector::<D>::zeros();
            let mut centre = Vector::<D>::zeros();
            let mut moment = [0.0; 3];
            let (mut nf, mut area, mut peak) = (0.0, 0.0, 0.0_f64);
            for r in range.clone() {
                let node = &geometry.nodes[r];
                let l = sol.lambda_n.get(r).copied().unwrap_or(0.0);
                nf += node.weight * l;
                let f = -node.normal * (node.weight * l);
                force += f;
                centre += node.position * (node.weight * l);
                for (m, v) in moment.iter_mut().zip(moment_of(&node.position, &f)) {
                    *m += v;
                }
                if l > 0.0 {
                    area += node.weight;
                    peak = peak.max(l);
                }
            }
            let centre_of_pressure = (nf > 0.0).then(|| {
                let c = centre / nf;
                [c[0], c[1], if D > 2 { c[2] } else { 0.0 }]
            });
            PairRecord {
                normal_force: nf,
                contact_area: area,
                peak_pressure: peak,
                moment,
                centre_of_pressure,
                mean_pressure: if area > 0.0 { nf / area } else { 0.0 },
                ..PairRecord::empty(name)
            }
            .with_force(&force)
        })
        .collect();
    // friction cells
    let mut friction = vec![Vector::<D>::zeros(); geometry.pairs.len()];
    for (c, (&r, &g)) in result.cell_node.iter().zip(&result.slip_bound).enumerate() {
        let node = &geometry.nodes[r];
        let pair = node.pair;
        let l = &sol.lambda_t[c * comps..(c + 1) * comps];
        let mut f = Vector::<D>::zeros();
        for (k, lk) in l.iter().enumerate() {
            f -= node.tangents[k] * (g * node.weight * lk);
        }
        friction[pair] += f;
        for (m, v) in out[pair].moment.iter_mut().zip(moment_of(&node.position, &f)) {
            *m += v;
        }
        let ln = l.iter().map(|v| v * v).sum::<Real>().sqrt();
        if ln < 1.0 - 1e-6 {
            out[pair].stick_area += node.weight;
        } else {
            out[pair].slip_area += node.weight;
        }
    }
    for (rec, f) in out.iter_mut().zip(&friction) {
        rec.tangential_force = f.norm();
        for i in 0..D {
            rec.force[i] += f[i];
        }
    }
    out
}

impl PairRecord {
    #[must_use]
    fn with_force<const D: usize>(mut self, f: &Vector<D>) -> Self {
        for i in 0..D {
            self.force[i] = f[i];
        }
        self
    }
}

/// Writes the records as CSV: one row per step; pair columns are prefixed by the pair name.
pub fn write_csv(path: &Path, records: &[StepRecord]) -> Result<(), IoError> {
    let io = |source| IoError::Io { path: path.to_path_buf(), source };
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    let mut header = String::from(
        "step,time,iterations,step_s,kinetic_energy,strain_energy,viscous_dissipation,friction_dissipation,cumulative_friction_dissipation",
    );
    if let Some(first) = records.first() {
        for p in &first.pairs {
            for col in [
                "force_x",
                "force_y",
                "force_z",
                "normal_force",
                "tangential_force",
                "contact_area",
                "peak_pressure",
                "stick_area",
                "slip_area",
                "moment_x",
                "moment_y",
                "moment_z",
                "centre_of_pressure_x",
                "centre_of_pressure_y",
                "centre_of_pressure_z",
                "mean_pressure",
            ] {
                header.push_str(&format!(",{}_{col}", p.name));
            }
        }
    }
    writeln!(f, "{header}").map_err(io)?;
    for r in records {
        let mut line = format!(
            "{},{},{},{},{},{},{},{},{}",
            r.step,
            r.time,
            r.iterations,
            r.step_s,
            r.kinetic_energy,
            r.strain_energy,
            r.viscous_dissipation,
            r.friction_dissipation,
            r.cumulative_friction_dissipation
        );
        for p in &r.pairs {
            line.push_str(&format!(
                ",{},{},{},{},{},{},{},{},{}",
                p.force[0],
                p.force[1],
                p.force[2],
                p.normal_force,
                p.tangential_force,
                p.contact_area,
                p.peak_pressure,
                p.stick_area,
                p.slip_area
            ));
            line.push_str(&format!(",{},{},{}", p.moment[0], p.moment[1], p.moment[2]));
            match p.centre_of_pressure {
                // no contact: empty cells (no made-up position)
                None => line.push_str(",,,"),
                Some(c) => line.push_str(&format!(",{},{},{}", c[0], c[1], c[2])),
            }
            line.push_str(&format!(",{}", p.mean_pressure));
        }
        writeln!(f, "{line}").map_err(io)?;
    }
    f.flush().map_err(io)
}
