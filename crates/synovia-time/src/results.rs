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
    /// The two sides of a pair split by a plane
    /// ([`PairSplit`](synovia_contact::operators::PairSplit)): positive side first, each
    /// with the figures above over its own contact nodes and friction cells (`name` = the
    /// side's name, `sides` empty); their forces, moments, areas add up to the pair's. Empty
    /// for a pair without a split.
    pub sides: Vec<PairRecord>,
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
            sides: Vec::new(),
        }
    }
}

/// Records without contact (every figure zero) of every pair of `geometry`, with the empty
/// sides of split pairs (so that CSV columns line up with later steps).
pub fn empty_pair_records<const D: usize>(geometry: &ContactGeometry<D>) -> Vec<PairRecord> {
    geometry
        .pairs
        .iter()
        .enumerate()
        .map(|(p, (name, _))| {
            let mut rec = PairRecord::empty(name);
            if let Some(Some(split)) = geometry.report_splits.get(p) {
                rec.sides = vec![PairRecord::empty(&split.positive), PairRecord::empty(&split.negative)];
            }
            rec
        })
        .collect()
}

/// `x × f` of two vectors of dimension `D` embedded in 3D.
fn moment_of<const D: usize>(x: &Vector<D>, f: &Vector<D>) -> [Real; 3] {
    cross3(embed3(x), embed3(f))
}

/// A 2D or 3D vector as a 3D one (2D: `z = 0`), for moments and rotations of both dimensions.
pub fn embed3<const D: usize>(v: &Vector<D>) -> [Real; 3] {
    let mut out = [0.0; 3];
    for (o, x) in out.iter_mut().zip(v.iter()) {
        *o = *x;
    }
    out
}

/// `a × b`.
pub fn cross3(a: [Real; 3], b: [Real; 3]) -> [Real; 3] {
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

/// Computes the pair records of a contact solution, with the sides of the pairs that have a
/// reporting split ([`ContactGeometry::report_splits`]).
#[tracing::instrument(level = "debug", skip_all)]
pub fn pair_records<const D: usize>(
    geometry: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
) -> Vec<PairRecord> {
    let mut out = records_where(geometry, result, |_| true);
    for (p, split) in geometry.report_splits.iter().enumerate() {
        let (Some(split), Some(rec)) = (split, out.get_mut(p)) else { continue };
        for (name, positive) in [(&split.positive, true), (&split.negative, false)] {
            let side = records_where(geometry, result, |r| {
                let node = &geometry.nodes[r];
                node.pair == p && split.is_positive(node.position.as_slice()) == positive
            });
            let mut side = side.into_iter().nth(p).unwrap_or_else(|| PairRecord::empty(name));
            side.name.clone_from(name);
            rec.sides.push(side);
        }
    }
    out
}

/// The pair records over the contact nodes `r` with `keep(r)` (and their friction cells).
fn records_where<const D: usize>(
    geometry: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
    keep: impl Fn(usize) -> bool,
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
            for r in range.clone().filter(|&r| keep(r)) {
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
        if !keep(r) {
            continue;
        }
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

/// The contact area above a pressure threshold, per pair and per side of a split pair (as
/// [`pair_records`]: `[pair, positive side, negative side]` for a split pair, `[pair]`
/// otherwise): `Σ κ_r` over the contact nodes with `Λ_n,r > p_min`. With `p_min = 0` it is
/// [`PairRecord::contact_area`]. Pressure-sensitive film measures this (Fuji Prescale LW: from
/// 2.5 MPa); a computed area without a threshold also counts the fringe of a conforming
/// contact where the pressure falls to zero, which the element size decides
/// (docs/tkr3d.md, "Mesh convergence").
pub fn contact_area_above<const D: usize>(
    geometry: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
    p_min: Real,
) -> Vec<Vec<Real>> {
    geometry
        .pairs
        .iter()
        .enumerate()
        .map(|(p, (_, range))| {
            let split = geometry.report_splits.get(p).and_then(Option::as_ref);
            let mut areas = vec![0.0; if split.is_some() { 3 } else { 1 }];
            for r in range.clone() {
                let node = &geometry.nodes[r];
                if result.solution.lambda_n.get(r).copied().unwrap_or(0.0) > p_min {
                    areas[0] += node.weight;
                    if let Some(split) = split {
                        let side = if split.is_positive(node.position.as_slice()) { 1 } else { 2 };
                        areas[side] += node.weight;
                    }
                }
            }
            areas
        })
        .collect()
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

/// Labels of the model's units for the outputs. synovia computes in any consistent units (the
/// user's length unit `L` and force unit `F`; pressures and moduli in `F/L²`, energies in
/// `F·L`); these labels only name them in CSV headers and `summary.json`. Default: `mm`, `N`,
/// `s` (pressures in `MPa`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Units {
    /// Length unit of the meshes.
    pub length: String,
    /// Force unit of the loads.
    pub force: String,
    /// Time unit of the histories and time levels.
    pub time: String,
}

impl Default for Units {
    fn default() -> Self {
        Self { length: "mm".into(), force: "N".into(), time: "s".into() }
    }
}

/// The physical quantity of an output figure ([`Units::label`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// A count or ratio: `-`.
    Count,
    /// Model time.
    Time,
    /// Wall-clock time: always `s`.
    WallTime,
    /// A position or length.
    Length,
    /// An area (in 2D: a length per unit thickness).
    Area,
    /// A force (in 2D: per unit thickness).
    Force,
    /// A moment (in 2D: per unit thickness).
    Moment,
    /// A pressure or stress (also in 2D).
    Pressure,
    /// An energy or work (in 2D: per unit thickness).
    Energy,
}

impl Units {
    /// The pressure unit: `MPa` for `N` and `mm`, `Pa` for `N` and `m`, `kPa` for `kN` and `m`,
    /// `GPa` for `kN` and `mm`, else `F/L^2`.
    pub fn pressure(&self) -> String {
        match (self.force.as_str(), self.length.as_str()) {
            ("N", "mm") | ("MN", "m") => "MPa".into(),
            ("N", "m") => "Pa".into(),
            ("kN", "m") => "kPa".into(),
            ("kN", "mm") => "GPa".into(),
            (f, l) => format!("{f}/{l}^2"),
        }
    }
    /// The unit label of a quantity in dimension `dimension` (2D: per unit thickness, written
    /// `…/L`).
    pub fn label(&self, q: Quantity, dimension: usize) -> String {
        let (l, f) = (&self.length, &self.force);
        let per = if dimension == 2 { format!("/{l}") } else { String::new() };
        match q {
            Quantity::Count => "-".into(),
            Quantity::Time => self.time.clone(),
            Quantity::WallTime => "s".into(),
            Quantity::Length => l.clone(),
            Quantity::Area => format!("{l}^2{per}"),
            Quantity::Force => format!("{f}{per}"),
            Quantity::Moment | Quantity::Energy => format!("{f}*{l}{per}"),
            Quantity::Pressure => self.pressure(),
        }
    }
}

/// The step columns of the CSV and their quantities.
const STEP_COLUMNS: [(&str, Quantity); 9] = [
    ("step", Quantity::Count),
    ("time", Quantity::Time),
    ("iterations", Quantity::Count),
    ("step_s", Quantity::WallTime),
    ("kinetic_energy", Quantity::Energy),
    ("strain_energy", Quantity::Energy),
    ("viscous_dissipation", Quantity::Energy),
    ("friction_dissipation", Quantity::Energy),
    ("cumulative_friction_dissipation", Quantity::Energy),
];

/// The pair columns of the CSV (prefixed by the pair name, and for the sides of a split pair
/// by `PAIR_SIDE`) and their quantities.
pub const PAIR_COLUMNS: [(&str, Quantity); 16] = [
    ("force_x", Quantity::Force),
    ("force_y", Quantity::Force),
    ("force_z", Quantity::Force),
    ("normal_force", Quantity::Force),
    ("tangential_force", Quantity::Force),
    ("contact_area", Quantity::Area),
    ("peak_pressure", Quantity::Pressure),
    ("stick_area", Quantity::Area),
    ("slip_area", Quantity::Area),
    ("moment_x", Quantity::Moment),
    ("moment_y", Quantity::Moment),
    ("moment_z", Quantity::Moment),
    ("centre_of_pressure_x", Quantity::Length),
    ("centre_of_pressure_y", Quantity::Length),
    ("centre_of_pressure_z", Quantity::Length),
    ("mean_pressure", Quantity::Pressure),
];

/// The cells of one pair (or side) record in the order of [`PAIR_COLUMNS`]; no contact:
/// empty centre-of-pressure cells (no made-up position).
fn pair_cells(p: &PairRecord) -> String {
    let cop = match p.centre_of_pressure {
        None => ",,".to_string(),
        Some(c) => format!("{},{},{}", c[0], c[1], c[2]),
    };
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{},{cop},{}",
        p.force[0],
        p.force[1],
        p.force[2],
        p.normal_force,
        p.tangential_force,
        p.contact_area,
        p.peak_pressure,
        p.stick_area,
        p.slip_area,
        p.moment[0],
        p.moment[1],
        p.moment[2],
        p.mean_pressure
    )
}

/// Writes the records as CSV with the default unit labels ([`Units::default`]: mm, N, s) of
/// a 3D model; see [`write_csv_with_units`].
pub fn write_csv(path: &Path, records: &[StepRecord]) -> Result<(), IoError> {
    write_csv_with_units(path, records, &Units::default(), 3)
}

/// Writes the records as CSV: one row per step; pair columns are prefixed by the pair name
/// (`PAIR_force_x`), the columns of the sides of a split pair by the pair and side names
/// (`PAIR_SIDE_force_x`, after the pair's own). Every header cell carries its unit as
/// `name [unit]` ([`Units::label`] for `dimension`; `[-]` for counts). The columns are those
/// of the first record; a later record without a side of it gets empty cells there.
pub fn write_csv_with_units(
    path: &Path,
    records: &[StepRecord],
    units: &Units,
    dimension: usize,
) -> Result<(), IoError> {
    let io = |source| IoError::Io { path: path.to_path_buf(), source };
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    let mut header: Vec<String> =
        STEP_COLUMNS.iter().map(|(c, q)| format!("{c} [{}]", units.label(*q, dimension))).collect();
    // the layout: pairs and their sides' names
    let layout: Vec<(String, Vec<String>)> = records.first().map_or_else(Vec::new, |r| {
        r.pairs.iter().map(|p| (p.name.clone(), p.sides.iter().map(|s| s.name.clone()).collect())).collect()
    });
    for (pair, sides) in &layout {
        let prefixes = std::iter::once(pair.clone()).chain(sides.iter().map(|s| format!("{pair}_{s}")));
        for prefix in prefixes {
            for (col, q) in PAIR_COLUMNS {
                header.push(format!("{prefix}_{col} [{}]", units.label(q, dimension)));
            }
        }
    }
    writeln!(f, "{}", header.join(",")).map_err(io)?;
    let empty = vec![""; PAIR_COLUMNS.len()].join(",");
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
        for (k, (pair, sides)) in layout.iter().enumerate() {
            let rec = r.pairs.get(k).filter(|p| &p.name == pair);
            line.push(',');
            line.push_str(&rec.map_or_else(|| empty.clone(), pair_cells));
            for side in sides {
                line.push(',');
                match rec.and_then(|p| p.sides.iter().find(|s| &s.name == side)) {
                    Some(s) => line.push_str(&pair_cells(s)),
                    None => line.push_str(&empty),
                }
            }
        }
        writeln!(f, "{line}").map_err(io)?;
    }
    f.flush().map_err(io)
}
