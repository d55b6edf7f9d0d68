//! From a parsed [`Scenario`] to a [`JointModel`]: meshes, materials, parts, boundary
//! conditions, ties, contact pairs, solver and analysis, with every semantic error located at
//! the value it is about.

use std::any::Any;
use std::collections::{HashMap, HashSet};
use std::ops::Range;
use std::path::PathBuf;
use std::sync::Arc;

use synovia::builder::{Analysis, BodyMaterial, JointError, JointModel, TfetiSettings, TFETI};
use synovia::contact_ops::operators::{ContactPair, CylinderObstacle, PlaneObstacle, SphereObstacle};
use synovia::contact_ops::{ContactParams, ExponentialFriction};
use synovia::fem::{ComponentMask, ElasticParams, FemError, OrderingChoice};
use synovia::feti::{
    CoarseConstraint, DecompositionParams, Expansion, Partitioner, Preconditioner, TfetiParams,
};
use synovia::io::gmsh::GmshMesh;
use synovia::io::Encoding;
use synovia::material::{
    anisotropic, plane_strain, plane_stress, transversely_isotropic, transversely_isotropic_plane_strain,
    transversely_isotropic_plane_stress, voigt_len, KelvinVoigt, LinearElastic, Material, TransverseIsotropy,
    VoigtMatrix,
};
use synovia::mesh::generators::{
    ball, box_mesh, disc, half_disc, half_disc_refined_within, hemisphere, hemisphere_refined_within,
    layered_arc_2d, layered_cap_3d, rectangle, Grading,
};
use synovia::mesh::math::{Point, Vector};
use synovia::mesh::{BoundaryKind, Mesh};
use synovia::nonlinear::{ActiveSetStrategy, GeometryUpdate};
use synovia::time::dynamic::{DynamicParams, MassKind};
use synovia::time::history::{Constant, LoadHistory, Periodic, PiecewiseLinear, RigidMotion};
use synovia::time::quasistatic::QuasiStaticParams;
use synovia::time::results::Units;

use crate::scenario::*;

/// A scenario turned into a model, ready to run.
#[derive(Debug)]
pub struct Built<const D: usize> {
    /// The model with its pairs, solver and analysis.
    pub joint: JointModel<D>,
    /// The analysis (also set on `joint`).
    pub analysis: Analysis,
    /// Output options.
    pub output: OutputPlan,
    /// Base name of the output files.
    pub name: String,
    /// Warnings found while building (e.g. unused duplicate nodes of a mesh); the model is
    /// usable.
    pub warnings: Vec<String>,
    /// The unit labels of the outputs (`[units]`; default mm, N, s).
    pub units: Units,
}

/// Where and how often to write results.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputPlan {
    /// `output.dir` (relative to the current directory), if given.
    pub dir: Option<PathBuf>,
    /// Write a `.vtu` every `vtu_every` steps (and the last one); 0 = none.
    pub vtu_every: usize,
    /// VTU encoding.
    pub encoding: Encoding,
    /// `output.stress`: the `.vtu` files carry the stress and strain fields (default `true`).
    pub stress: bool,
}

type R<T> = Result<T, ScenarioError>;

/// Size guards of a scenario build: a scenario asking for more gets an error at the key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest mesh a generator may make (cells, estimated from its parameters; default 2·10⁷).
    pub max_cells: f64,
    /// Most refinement levels of `half_disc` / `hemisphere` (the cell size halves about every
    /// two levels in 2D and three in 3D; default 30).
    pub max_refine_levels: usize,
    /// Most steps of a quasi-static `times = { start, end, steps }` range (its levels are
    /// allocated when the model is built; default 10⁷).
    pub max_time_steps: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self { max_cells: 2.0e7, max_refine_levels: 30, max_time_steps: 10_000_000 }
    }
}

static LIMITS: std::sync::Mutex<Option<Limits>> = std::sync::Mutex::new(None);

/// Sets the size guards of every later build in this process (e.g. smaller ones for fuzzing,
/// where the parser and validation are under test, not the mesh generators at scale).
pub fn set_limits(limits: Limits) {
    let mut guard = LIMITS.lock().unwrap_or_else(|e| e.into_inner());
    *guard = Some(limits);
}

/// The size guards in force ([`set_limits`], else [`Limits::default`]).
pub fn limits() -> Limits {
    LIMITS.lock().unwrap_or_else(|e| e.into_inner()).unwrap_or_default()
}

fn key(prefix: &str, field: &str) -> String {
    if prefix.is_empty() {
        field.to_string()
    } else {
        format!("{prefix}.{field}")
    }
}

const AXES: [&str; 3] = ["x", "y", "z"];

struct Cx<'a> {
    src: &'a Source,
    warnings: std::cell::RefCell<Vec<String>>,
}

impl Cx<'_> {
    fn err(&self, key: impl Into<String>, span: Range<usize>, msg: impl Into<String>) -> ScenarioError {
        self.src.error(key, Some(span), msg)
    }

    /// The required field `field` of the table at `span`.
    fn req<'t, T>(
        &self,
        v: &'t Option<Sp<T>>,
        prefix: &str,
        field: &str,
        span: &Range<usize>,
        why: &str,
    ) -> R<&'t Sp<T>> {
        v.as_ref().ok_or_else(|| self.err(prefix, span.clone(), format!("missing `{field}` ({why})")))
    }

    /// Errors on the first present field that is not in `allowed`.
    fn only(
        &self,
        prefix: &str,
        present: &[(&str, Option<Range<usize>>)],
        allowed: &[&str],
        what: &str,
    ) -> R<()> {
        for (name, span) in present {
            if let Some(span) = span {
                if !allowed.contains(name) {
                    return Err(self.err(
                        key(prefix, name),
                        span.clone(),
                        format!(
                            "`{name}` does not apply to {what} (keys used there: {})",
                            allowed.join(", ")
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    fn finite(&self, v: &Sp<f64>, k: &str) -> R<f64> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(k, v.span(), format!("must be finite, got {x}")))
        }
    }

    fn positive(&self, v: &Sp<f64>, k: &str) -> R<f64> {
        let x = *v.get_ref();
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(k, v.span(), format!("must be finite and > 0, got {x}")))
        }
    }

    fn non_negative(&self, v: &Sp<f64>, k: &str) -> R<f64> {
        let x = *v.get_ref();
        if x.is_finite() && x >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(k, v.span(), format!("must be finite and ≥ 0, got {x}")))
        }
    }

    /// The value named by the keyword `v` among `options` (name, value); any other name is an
    /// error at `k`: "{what} is `a`, `b` or `c`, got `x`".
    fn keyword<T: Clone>(&self, v: &Sp<String>, k: &str, what: &str, options: &[(&str, T)]) -> R<T> {
        let name = v.get_ref().as_str();
        if let Some((_, t)) = options.iter().find(|(n, _)| *n == name) {
            return Ok(t.clone());
        }
        let names: Vec<String> = options.iter().map(|(n, _)| format!("`{n}`")).collect();
        let list = match names.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => String::new(),
        };
        Err(self.err(k, v.span(), format!("{what} is {list}, got `{name}`")))
    }

    fn at_least(&self, v: &Sp<usize>, k: &str, min: usize) -> R<usize> {
        let x = *v.get_ref();
        if x >= min {
            Ok(x)
        } else {
            Err(self.err(k, v.span(), format!("must be at least {min}, got {x}")))
        }
    }

    /// A vector with exactly `n` finite entries.
    fn array(&self, v: &Sp<Vec<f64>>, k: &str, n: usize, what: &str) -> R<Vec<f64>> {
        let a = v.get_ref();
        if a.len() != n {
            return Err(self.err(k, v.span(), format!("{what} needs {n} numbers, got {}", a.len())));
        }
        if let Some(x) = a.iter().find(|x| !x.is_finite()) {
            return Err(self.err(k, v.span(), format!("{what} must be finite, got {x}")));
        }
        Ok(a.clone())
    }

    fn vector<const D: usize>(&self, v: &Sp<Vec<f64>>, k: &str) -> R<Vector<D>> {
        let a = self.array(v, k, D, &format!("a {D}D vector"))?;
        Ok(Vector::<D>::from_fn(|i, _| a[i]))
    }

    fn point<const D: usize>(&self, v: &Sp<Vec<f64>>, k: &str) -> R<Point<D>> {
        let a = self.array(v, k, D, &format!("a {D}D point"))?;
        Ok(Point::<D>::from_fn(|i, _| a[i]))
    }

    fn nonzero<const D: usize>(&self, v: &Sp<Vec<f64>>, k: &str) -> R<Vector<D>> {
        let n = self.vector::<D>(v, k)?;
        if n.norm() > 0.0 {
            Ok(n)
        } else {
            Err(self.err(k, v.span(), "must not be the zero vector"))
        }
    }

    /// A `[lo, hi]` range with `lo ≤ hi` (infinite ends allowed).
    fn range(&self, v: &Sp<Vec<f64>>, k: &str) -> R<(f64, f64)> {
        let a = v.get_ref();
        if a.len() != 2 || a.iter().any(|x| x.is_nan()) || a[0] > a[1] {
            return Err(self.err(k, v.span(), format!("needs a range [lo, hi] with lo ≤ hi, got {a:?}")));
        }
        Ok((a[0], a[1]))
    }

    fn history(&self, h: Option<&Sp<HistorySpec>>, k: &str) -> R<Arc<dyn LoadHistory>> {
        let Some(h) = h else { return Ok(Arc::new(Constant(1.0))) };
        match h.get_ref() {
            HistorySpec::Constant(c) => {
                if c.is_finite() {
                    Ok(Arc::new(Constant(*c)))
                } else {
                    Err(self.err(k, h.span(), format!("must be finite, got {c}")))
                }
            }
            HistorySpec::Table { rows, period } => {
                let table_key = if period.is_some() { key(k, "table") } else { k.to_string() };
                if rows.is_empty() {
                    return Err(self.err(
                        &table_key,
                        h.span(),
                        "the history table is empty; give rows [t, v]",
                    ));
                }
                let mut points = Vec::with_capacity(rows.len());
                for (i, row) in rows.iter().enumerate() {
                    let rk = format!("{table_key}[{i}]");
                    let r = row.get_ref();
                    if r.len() != 2 {
                        return Err(self.err(
                            rk,
                            row.span(),
                            format!("a history row is [t, v] (two numbers), got {r:?}"),
                        ));
                    }
                    if !(r[0].is_finite() && r[1].is_finite()) {
                        return Err(self.err(rk, row.span(), format!("history row {r:?} is not finite")));
                    }
                    if let Some(&(t_prev, _)) = points.last() {
                        if r[0] <= t_prev {
                            return Err(self.err(
                                rk,
                                row.span(),
                                format!(
                                    "history times must increase strictly: t = {} after t = {t_prev}",
                                    r[0]
                                ),
                            ));
                        }
                    }
                    points.push((r[0], r[1]));
                }
                let table = PiecewiseLinear::new(&points)
                    .map_err(|e| self.err(&table_key, h.span(), e.to_string()))?;
                match period {
                    None => Ok(Arc::new(table)),
                    Some(p) => {
                        let pk = key(k, "period");
                        let t = self.positive(p, &pk)?;
                        Ok(Arc::new(
                            Periodic::new(table, t).map_err(|e| self.err(pk, p.span(), e.to_string()))?,
                        ))
                    }
                }
            }
        }
    }
}

macro_rules! present {
    ($s:expr; $($name:literal => $f:ident),* $(,)?) => {
        [$(($name, $s.$f.as_ref().map(|v| v.span()))),*]
    };
}

/// Builds the model of a parsed scenario in dimension `D` (which must be the scenario's
/// `dimension`).
///
/// # Errors
/// The first problem found, located at its key.
pub fn build<const D: usize>(sc: &Scenario) -> R<Built<D>> {
    let cx = Cx { src: &sc.source, warnings: std::cell::RefCell::new(Vec::new()) };
    let doc = &sc.doc;
    let dim = doc.dimension.get_ref();
    if *dim != D as i64 {
        return Err(cx.err("dimension", doc.dimension.span(), format!("must be 2 or 3, got {dim}")));
    }
    if let Some(n) = &doc.name {
        let v = n.get_ref();
        if v.is_empty()
            || !v.chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c))
            || v.starts_with('.')
        {
            return Err(cx.err(
                "name",
                n.span(),
                format!("`{v}` is not a usable file name: use letters, digits, `_`, `-` and `.`"),
            ));
        }
    }
    let analysis = analysis(&cx, &doc.analysis)?;
    let mut joint = JointModel::<D>::new();
    let mut gmsh: HashMap<PathBuf, GmshMesh> = HashMap::new();
    if doc.bodies.is_empty() {
        return Err(cx.src.file_error("the scenario has no [[body]]"));
    }
    for (i, b) in doc.bodies.iter().enumerate() {
        add_body(&cx, &mut joint, b.get_ref(), &format!("body[{i}]"), &mut gmsh, doc.bodies[..i].iter())?;
    }
    let names: Vec<String> = doc.bodies.iter().map(|b| b.get_ref().name.get_ref().clone()).collect();
    let tables = tables(&cx, &doc.tables)?;
    let mut shapes: HashMap<String, Shape<D>> = HashMap::new();
    for (i, r) in doc.rigid_bodies.iter().enumerate() {
        rigid_body(&cx, &mut joint, r, &format!("rigid_body[{i}]"), &tables, &mut shapes)?;
    }
    let mut used = HashSet::new();
    for (i, bc) in doc.boundary.iter().enumerate() {
        boundary(&cx, &mut joint, bc, &format!("boundary[{i}]"), &names, &mut used)?;
    }
    for (i, t) in doc.ties.iter().enumerate() {
        let k = format!("tie[{i}]");
        let t = t.get_ref();
        let (a, pa) =
            body_part(&cx, &joint, &t.body_a, &t.part_a, &key(&k, "body_a"), &key(&k, "part_a"), &names)?;
        let (b, pb) =
            body_part(&cx, &joint, &t.body_b, &t.part_b, &key(&k, "body_b"), &key(&k, "part_b"), &names)?;
        joint
            .tie(a.as_str(), &pa, b.as_str(), &pb)
            .map_err(|e| cx.err(&k, t.body_a.span(), e.to_string()))?;
    }
    // friction laws F_c(v) need slip speeds, i.e. levels in time
    let in_time = !matches!(analysis, Analysis::Static { .. });
    for (i, c) in doc.contact.iter().enumerate() {
        contact(&cx, &mut joint, c, &format!("contact[{i}]"), &names, in_time, &shapes)?;
    }
    if let Some(s) = &doc.solver {
        solver(&cx, &mut joint, s)?;
    }
    if let Some(n) = &doc.newton {
        newton(&cx, &mut joint, n)?;
    }
    if let Some(f) = &doc.force_control {
        force_control(&cx, &mut joint, f)?;
    }
    quasi_and_dynamic_params(&cx, &mut joint, &doc.analysis)?;
    // missing data for Prescribed / Traction parts (e.g. Gmsh parts named `prescribed_*`)
    if let Err(e) = joint.model().validate() {
        let (k, span) = match &e {
            FemError::MissingBoundaryData { body, .. } => names
                .iter()
                .position(|n| n == body)
                .map(|i| (format!("body[{i}].mesh"), doc.bodies[i].get_ref().mesh.span()))
                .unwrap_or_else(|| ("boundary".into(), doc.analysis.span())),
            _ => ("body".into(), doc.bodies[0].span()),
        };
        return Err(cx.err(k, span, e.to_string()));
    }
    if matches!(analysis, Analysis::Dynamic { .. }) {
        for (i, b) in doc.bodies.iter().enumerate() {
            let b = b.get_ref();
            if b.density.is_none() && b.material.get_ref().kind.get_ref() != "kelvin_voigt" {
                return Err(cx.err(
                    format!("body[{i}]"),
                    b.name.span(),
                    format!(
                        "body `{}` needs `density` (or a kelvin_voigt material) for a dynamic analysis",
                        b.name.get_ref()
                    ),
                ));
            }
        }
        // rigid bodies in a dynamic analysis are massless and prescribed in every coordinate
        // (`JointModel::run_dynamic` refuses force control and tied parts): said by `check`
        // at the key, not first by `run`
        for (i, r) in doc.rigid_bodies.iter().enumerate() {
            let s = r.get_ref();
            let dofs =
                [("tx", &s.tx), ("ty", &s.ty), ("tz", &s.tz), ("rx", &s.rx), ("ry", &s.ry), ("rz", &s.rz)];
            for (name, dof) in dofs {
                if let Some(f) = dof.as_ref().and_then(|d| d.get_ref().force.as_ref()) {
                    return Err(cx.err(
                        format!("rigid_body[{i}].{name}.force"),
                        f.span(),
                        "force-controlled coordinates of rigid bodies are not supported in dynamic analyses (rigid bodies have no mass there: prescribe every coordinate, or use a static or quasi-static analysis)",
                    ));
                }
            }
        }
        for (j, bc) in doc.boundary.iter().enumerate() {
            if bc.get_ref().kind.get_ref() == "rigid_body" {
                return Err(cx.err(
                    format!("boundary[{j}].kind"),
                    bc.get_ref().kind.span(),
                    "parts tied to a rigid body are not supported in dynamic analyses yet (static and quasi-static analyses take them); prescribe the part's motion instead",
                ));
            }
        }
    }
    joint.set_analysis(analysis.clone());
    if joint.uses_tfeti() {
        // what TFETI does not treat (dynamic analyses, rigid bodies with mixed control, …),
        // at the solver's name
        if let Err(e @ JointError::Unsupported { .. }) = joint.tfeti_support() {
            let (k, span) = match doc.solver.as_ref().and_then(|s| s.get_ref().name.as_ref()) {
                Some(n) => ("solver.name".to_string(), n.span()),
                None => ("solver".to_string(), doc.analysis.span()),
            };
            return Err(cx.err(k, span, e.to_string()));
        }
    }
    let output = output(&cx, doc.output.as_ref())?;
    let units = units(&cx, doc, &joint, &analysis)?;
    Ok(Built { joint, analysis, output, name: sc.name(), warnings: cx.warnings.into_inner(), units })
}

/// Resolves a body name and one of its part names (errors list what exists).
fn body_part<const D: usize>(
    cx: &Cx<'_>,
    joint: &JointModel<D>,
    body: &Sp<String>,
    part: &Sp<String>,
    body_key: &str,
    part_key: &str,
    names: &[String],
) -> R<(String, String)> {
    let b = check_body(cx, joint, body, body_key, names)?;
    let mesh = &joint.model().bodies()[b].mesh;
    let p = part.get_ref();
    if mesh.boundary_part(p).is_err() {
        let parts: Vec<&str> = mesh.boundary_parts().iter().map(|p| p.name()).collect();
        return Err(cx.err(
            part_key,
            part.span(),
            format!("body `{}` has no part `{p}` (its parts: {})", body.get_ref(), parts.join(", ")),
        ));
    }
    Ok((body.get_ref().clone(), p.clone()))
}

fn check_body<const D: usize>(
    cx: &Cx<'_>,
    joint: &JointModel<D>,
    body: &Sp<String>,
    body_key: &str,
    names: &[String],
) -> R<usize> {
    joint.model().body_id(body.get_ref()).map(|id| id.0).map_err(|_| {
        cx.err(body_key, body.span(), format!("no body `{}` (bodies: {})", body.get_ref(), names.join(", ")))
    })
}

// ----- bodies -----

fn add_body<'a, const D: usize>(
    cx: &Cx<'_>,
    joint: &mut JointModel<D>,
    b: &BodySpec,
    k: &str,
    gmsh: &mut HashMap<PathBuf, GmshMesh>,
    mut earlier: impl Iterator<Item = &'a Sp<BodySpec>>,
) -> R<()> {
    let name = b.name.get_ref();
    if name.is_empty() {
        return Err(cx.err(key(k, "name"), b.name.span(), "a body needs a non-empty name"));
    }
    if earlier.any(|e| e.get_ref().name.get_ref() == name) {
        return Err(cx.err(key(k, "name"), b.name.span(), format!("two bodies are called `{name}`")));
    }
    let mut mesh = mesh::<D>(cx, &b.mesh, &key(k, "mesh"), name, gmsh)?;
    for (j, p) in b.parts.iter().enumerate() {
        define_part(cx, &mut mesh, p, &format!("{k}.part[{j}]"))?;
    }
    let material = material::<D>(cx, &b.material, &key(k, "material"), true)?;
    let is_kv = matches!(material, BodyMaterial::KelvinVoigt(_));
    let id = joint.add_body(name, mesh, material).map_err(|e| cx.err(k, b.name.span(), e.to_string()))?;
    if let Some(d) = &b.density {
        let dk = key(k, "density");
        if is_kv {
            return Err(cx.err(
                dk,
                d.span(),
                "a kelvin_voigt material has its own `density`; remove this one",
            ));
        }
        let rho = cx.positive(d, &dk)?;
        joint.set_density(id, rho).map_err(|e| cx.err(dk, d.span(), e.to_string()))?;
    }
    if let Some(kin) = &b.kinematics {
        let kk = key(k, "kinematics");
        let value = cx.keyword(
            kin,
            &kk,
            "`kinematics`",
            &[
                ("small", synovia::fem::Kinematics::SmallStrain),
                ("finite", synovia::fem::Kinematics::FiniteStrain),
            ],
        )?;
        joint.set_kinematics(id, value).map_err(|e| cx.err(kk, kin.span(), e.to_string()))?;
    }
    if let Some(v) = &b.initial_velocity {
        let vk = key(k, "initial_velocity");
        let v0 = cx.vector::<D>(v, &vk)?;
        joint.initial_velocity(id, v0).map_err(|e| cx.err(vk, v.span(), e.to_string()))?;
    }
    if let Some(f) = &b.body_force {
        let fk = key(k, "body_force");
        let l = f.get_ref();
        let value = cx.vector::<D>(&l.value, &key(&fk, "value"))?;
        let h = cx.history(l.history.as_ref(), &key(&fk, "history"))?;
        joint.body_force(id, value, h).map_err(|e| cx.err(fk, f.span(), e.to_string()))?;
    }
    Ok(())
}

fn grading(cx: &Cx<'_>, g: &Sp<GradingSpec>, k: &str) -> R<Grading> {
    let s = g.get_ref();
    let kind = s.kind.get_ref().as_str();
    let present = present!(s; "ratio" => ratio, "center" => center, "width" => width);
    let span = g.span();
    let ratio = |cx: &Cx<'_>| -> R<f64> {
        cx.positive(cx.req(&s.ratio, k, "ratio", &span, &format!("grading `{kind}`"))?, &key(k, "ratio"))
    };
    Ok(match kind {
        "uniform" => {
            cx.only(k, &present, &[], "grading `uniform`")?;
            Grading::Uniform
        }
        "geometric" | "toward_low" | "toward_high" => {
            cx.only(k, &present, &["ratio"], &format!("grading `{kind}`"))?;
            let r = ratio(cx)?;
            match kind {
                "geometric" => Grading::Geometric { ratio: r },
                "toward_low" => Grading::TowardLow { ratio: r },
                _ => Grading::TowardHigh { ratio: r },
            }
        }
        "refined" => {
            let why = "grading `refined`";
            let center = cx.finite(cx.req(&s.center, k, "center", &span, why)?, &key(k, "center"))?;
            let width = cx.positive(cx.req(&s.width, k, "width", &span, why)?, &key(k, "width"))?;
            Grading::Refined { center, width, ratio: ratio(cx)? }
        }
        other => {
            return Err(cx.err(
                key(k, "type"),
                s.kind.span(),
                format!("unknown grading `{other}` (uniform, geometric, toward_low, toward_high, refined)"),
            ))
        }
    })
}

fn mesh<const D: usize>(
    cx: &Cx<'_>,
    spec: &Sp<MeshSpec>,
    k: &str,
    body: &str,
    gmsh: &mut HashMap<PathBuf, GmshMesh>,
) -> R<Mesh<D>> {
    let m = spec.get_ref();
    let span = spec.span();
    let present = present!(m;
        "generator" => generator, "gmsh" => gmsh, "group" => group, "x" => x, "y" => y, "lo" => lo,
        "hi" => hi, "cells" => cells, "grading" => grading, "center" => center, "radius" => radius,
        "n" => n, "refine" => refine, "radii" => radii, "angles_deg" => angles_deg,
        "half_angle_deg" => half_angle_deg, "n_angle" => n_angle, "n_surface" => n_surface,
        "n_radial" => n_radial, "layer" => layer, "reflect" => reflect, "translate" => translate,
    );
    let common = ["reflect", "translate"];
    let mut mesh: Mesh<D> = match (&m.generator, &m.gmsh) {
        (Some(g), None) => {
            let name = g.get_ref().as_str();
            let (dim, allowed): (usize, &[&str]) = match name {
                "rectangle" => (2, &["x", "y", "cells", "grading"]),
                "box" => (3, &["lo", "hi", "cells", "grading"]),
                "disc" | "ball" => (if name == "disc" { 2 } else { 3 }, &["center", "radius", "n"]),
                "half_disc" | "hemisphere" => {
                    (if name == "half_disc" { 2 } else { 3 }, &["center", "radius", "n", "refine"])
                }
                "layered_arc" => (2, &["center", "radii", "angles_deg", "n_angle", "n_radial", "layer"]),
                "layered_cap" => (3, &["center", "radii", "half_angle_deg", "n_surface", "n_radial", "layer"]),
                other => {
                    return Err(cx.err(
                        key(k, "generator"),
                        g.span(),
                        format!(
                            "unknown generator `{other}` (rectangle, box, disc, half_disc, ball, hemisphere, layered_arc, layered_cap)"
                        ),
                    ))
                }
            };
            if dim != D {
                return Err(cx.err(
                    key(k, "generator"),
                    g.span(),
                    format!("generator `{name}` makes {dim}D meshes but the scenario has dimension = {D}"),
                ));
            }
            let mut ok: Vec<&str> = vec!["generator"];
            ok.extend_from_slice(allowed);
            ok.extend_from_slice(&common);
            cx.only(k, &present, &ok, &format!("generator `{name}`"))?;
            generate::<D>(cx, m, name, k, &span)?
        }
        (None, Some(file)) => {
            let mut ok = vec!["gmsh", "group"];
            ok.extend_from_slice(&common);
            cx.only(k, &present, &ok, "a Gmsh mesh")?;
            let path = cx.src.resolve(file.get_ref());
            let gk = key(k, "gmsh");
            if !gmsh.contains_key(&path) {
                let read = synovia::io::gmsh::read_msh(&path)
                    .map_err(|e| cx.err(&gk, file.span(), e.to_string()))?;
                gmsh.insert(path.clone(), read);
            }
            let bodies = gmsh[&path].bodies::<D>().map_err(|e| cx.err(&gk, file.span(), e.to_string()))?;
            let (group, group_span, group_key) = match &m.group {
                Some(g) => (g.get_ref().clone(), g.span(), key(k, "group")),
                None => (body.to_string(), file.span(), gk.clone()),
            };
            let available: Vec<String> = bodies.iter().map(|(n, _)| n.clone()).collect();
            bodies.into_iter().find(|(n, _)| *n == group).map(|(_, mesh)| mesh).ok_or_else(|| {
                cx.err(
                    group_key,
                    group_span,
                    format!(
                        "`{}` has no {D}D physical group `{group}` (its bodies: {}); set `group`",
                        file.get_ref(),
                        available.join(", ")
                    ),
                )
            })?
        }
        (Some(_), Some(g)) => {
            return Err(cx.err(key(k, "gmsh"), g.span(), "give either `generator` or `gmsh`, not both"))
        }
        (None, None) => return Err(cx.err(k, span, "missing `generator` or `gmsh`")),
    };
    if let Some(r) = &m.reflect {
        let rk = key(k, "reflect");
        let axis = r.get_ref().axis.get_ref();
        let a = AXES.iter().take(D).position(|x| x == axis).ok_or_else(|| {
            cx.err(
                key(&rk, "axis"),
                r.get_ref().axis.span(),
                format!("axis must be one of {}", AXES[..D].join(", ")),
            )
        })?;
        mesh = mesh.reflected(a, r.get_ref().at).map_err(|e| cx.err(&rk, r.span(), e.to_string()))?;
    }
    if let Some(t) = &m.translate {
        let tk = key(k, "translate");
        let v = cx.vector::<D>(t, &tk)?;
        mesh.map_nodes(|x| x + v).map_err(|e| cx.err(tk, t.span(), e.to_string()))?;
    }
    let file = m.gmsh.as_ref().map(|f| (f.get_ref().as_str(), gmsh.get(&cx.src.resolve(f.get_ref()))));
    check_coincident(cx, &mesh, body, k, &span, file)?;
    Ok(mesh)
}

/// Coincident nodes of a body's mesh: an error when both belong to cells (an unmerged seam,
/// or a node written twice), a warning when one of them belongs to no cell.
fn check_coincident<const D: usize>(
    cx: &Cx<'_>,
    mesh: &Mesh<D>,
    body: &str,
    k: &str,
    span: &Range<usize>,
    file: Option<(&str, Option<&GmshMesh>)>,
) -> R<()> {
    let found = synovia::io::coincident_nodes(mesh);
    if found.is_empty() {
        return Ok(());
    }
    // how to name the nodes: Gmsh node tags (found by position) or mesh indices
    let describe = |(i, j): (usize, usize)| -> String {
        let x = mesh.node(i);
        let at = synovia::fem::error::fmt_point(x.as_slice());
        let tags: Vec<u64> = match file {
            Some((_, Some(g))) => g
                .nodes
                .iter()
                .zip(&g.node_tags)
                .filter(|(p, _)| (0..D).all(|a| (p[a] - x[a]).abs() <= found.tolerance.max(0.0)))
                .map(|(_, &t)| t)
                .collect(),
            _ => Vec::new(),
        };
        if tags.len() >= 2 {
            let list: Vec<String> = tags.iter().map(u64::to_string).collect();
            format!("Gmsh nodes {} at {at}", list.join(" and "))
        } else {
            format!("nodes {i} and {j} (0-based, of the body's mesh) at {at}")
        }
    };
    let fix = match file {
        Some((f, _)) => format!(
            "merge them in Gmsh (`Coherence;` before meshing or `Coherence Mesh;` after it in the .geo file, Geometry › Coherence in the GUI) and export `{f}` again"
        ),
        None => "merge them".to_string(),
    };
    if let Some(&first) = found.in_cells.first() {
        return Err(cx.err(
            k,
            span.clone(),
            format!(
                "body `{body}`: the mesh has {} pair(s) of coincident nodes not shared by elements (an unmerged seam or a duplicated node: the mesh is cut there), e.g. {}: {fix}",
                found.in_cells.len(),
                describe(first)
            ),
        ));
    }
    if let Some(&first) = found.unused.first() {
        cx.warnings.borrow_mut().push(format!(
            "body `{body}` (`{k}`): {} pair(s) of coincident nodes of which one belongs to no element, e.g. {}; they are ignored",
            found.unused.len(),
            describe(first)
        ));
    }
    Ok(())
}

fn generate<const D: usize>(
    cx: &Cx<'_>,
    m: &MeshSpec,
    name: &str,
    k: &str,
    span: &Range<usize>,
) -> R<Mesh<D>> {
    let why = format!("generator `{name}`");
    let why = why.as_str();
    let gen_err = |e: synovia::mesh::MeshError| cx.err(k, span.clone(), e.to_string());
    let counts = |n: usize| -> R<Vec<usize>> {
        let c = cx.req(&m.cells, k, "cells", span, why)?;
        let v = c.get_ref();
        if v.len() != n || v.contains(&0) {
            return Err(cx.err(
                key(k, "cells"),
                c.span(),
                format!("needs {n} positive cell counts, got {v:?}"),
            ));
        }
        Ok(v.clone())
    };
    let gradings = |n: usize| -> R<Vec<Grading>> {
        match &m.grading {
            None => Ok(vec![Grading::Uniform; n]),
            Some(g) => {
                let gk = key(k, "grading");
                if g.get_ref().len() != n {
                    return Err(cx.err(gk, g.span(), format!("needs {n} gradings (one per axis)")));
                }
                g.get_ref().iter().enumerate().map(|(i, gi)| grading(cx, gi, &format!("{gk}[{i}]"))).collect()
            }
        }
    };
    let center = |n: usize| -> R<Vec<f64>> {
        let c = cx.req(&m.center, k, "center", span, why)?;
        cx.array(c, &key(k, "center"), n, "the center")
    };
    let radius = || -> R<f64> { cx.positive(cx.req(&m.radius, k, "radius", span, why)?, &key(k, "radius")) };
    let n_cells = || -> R<usize> { cx.at_least(cx.req(&m.n, k, "n", span, why)?, &key(k, "n"), 1) };
    let layers = || -> R<(Vec<f64>, Vec<usize>, usize)> {
        let r = cx.req(&m.radii, k, "radii", span, why)?;
        let radii = r.get_ref().clone();
        let nr = cx.req(&m.n_radial, k, "n_radial", span, why)?;
        if radii.len() < 2 || nr.get_ref().len() + 1 != radii.len() {
            return Err(cx.err(
                key(k, "n_radial"),
                nr.span(),
                format!(
                    "needs one count per layer: {} radii give {} layers",
                    radii.len(),
                    radii.len().saturating_sub(1)
                ),
            ));
        }
        let layer = m.layer.as_ref().map_or(0, |l| *l.get_ref());
        if layer >= nr.get_ref().len() {
            let lk = key(k, "layer");
            let ls = m.layer.as_ref().map_or(span.clone(), |l| l.span());
            return Err(cx.err(
                lk,
                ls,
                format!("layer {layer} does not exist ({} layers)", nr.get_ref().len()),
            ));
        }
        Ok((radii, nr.get_ref().clone(), layer))
    };
    // guard against meshes that cannot fit in memory (or take hours) before generating them
    let get = |v: &Option<Sp<usize>>| v.as_ref().map_or(0.0, |x| *x.get_ref() as f64);
    let prod = m.cells.as_ref().map_or(0.0, |c| c.get_ref().iter().map(|&x| x as f64).product::<f64>());
    let n_layers = m.n_radial.as_ref().map_or(0.0, |c| c.get_ref().iter().map(|&x| x as f64).sum::<f64>());
    let n = get(&m.n);
    let estimate = match name {
        "rectangle" => 2.0 * prod,
        "box" => 6.0 * prod,
        "disc" => 8.0 * n * n,
        "half_disc" => 4.0 * n * n,
        "ball" => 48.0 * n * n * n,
        "hemisphere" => 24.0 * n * n * n,
        "layered_arc" => 2.0 * get(&m.n_angle) * n_layers,
        _ => 24.0 * get(&m.n_surface).powi(2) * n_layers,
    };
    let max_cells = limits().max_cells;
    if estimate > max_cells {
        return Err(cx.err(
            k,
            span.clone(),
            format!("the mesh would have about {estimate:.3e} cells, more than the limit {max_cells:e}"),
        ));
    }
    // a refinement's cell count depends on how much of the mesh its region covers (up to
    // `2^levels` times the cells): checked level by level while refining
    let max_cells_usize = if max_cells >= usize::MAX as f64 { usize::MAX } else { max_cells as usize };
    if let Some(r) = &m.refine {
        let levels = *r.get_ref().levels.get_ref();
        let max_levels = limits().max_refine_levels;
        if levels > max_levels {
            return Err(cx.err(
                key(k, "refine.levels"),
                r.get_ref().levels.span(),
                format!("at most {max_levels} refinement levels, got {levels}"),
            ));
        }
    }
    let mesh: Box<dyn Any> = match name {
        "rectangle" => {
            let x = cx.range(cx.req(&m.x, k, "x", span, why)?, &key(k, "x"))?;
            let y = cx.range(cx.req(&m.y, k, "y", span, why)?, &key(k, "y"))?;
            let c = counts(2)?;
            let g = gradings(2)?;
            Box::new(rectangle(x.0, x.1, y.0, y.1, c[0], c[1], g[0], g[1]).map_err(gen_err)?)
        }
        "box" => {
            let lo = cx.array(cx.req(&m.lo, k, "lo", span, why)?, &key(k, "lo"), 3, "`lo`")?;
            let hi = cx.array(cx.req(&m.hi, k, "hi", span, why)?, &key(k, "hi"), 3, "`hi`")?;
            let c = counts(3)?;
            let g = gradings(3)?;
            Box::new(
                box_mesh(
                    [lo[0], lo[1], lo[2]],
                    [hi[0], hi[1], hi[2]],
                    [c[0], c[1], c[2]],
                    [g[0], g[1], g[2]],
                )
                .map_err(gen_err)?,
            )
        }
        "disc" => {
            let c = center(2)?;
            Box::new(disc(Point::<2>::new(c[0], c[1]), radius()?, n_cells()?).map_err(gen_err)?)
        }
        "ball" => {
            let c = center(3)?;
            Box::new(ball(Point::<3>::new(c[0], c[1], c[2]), radius()?, n_cells()?).map_err(gen_err)?)
        }
        "half_disc" | "hemisphere" => {
            let c = center(D)?;
            let (r, n) = (radius()?, n_cells()?);
            let refine = match &m.refine {
                None => None,
                Some(rf) => {
                    let rk = key(k, "refine");
                    let s = rf.get_ref();
                    let rc = cx.array(&s.center, &key(&rk, "center"), D, "the center")?;
                    Some((rc, cx.positive(&s.radius, &key(&rk, "radius"))?, *s.levels.get_ref()))
                }
            };
            if name == "half_disc" {
                let cp = Point::<2>::new(c[0], c[1]);
                Box::new(match refine {
                    None => half_disc(cp, r, n).map_err(gen_err)?,
                    Some((rc, rr, l)) => half_disc_refined_within(
                        cp,
                        r,
                        n,
                        Point::<2>::new(rc[0], rc[1]),
                        rr,
                        l,
                        max_cells_usize,
                    )
                    .map_err(gen_err)?,
                })
            } else {
                let cp = Point::<3>::new(c[0], c[1], c[2]);
                Box::new(match refine {
                    None => hemisphere(cp, r, n).map_err(gen_err)?,
                    Some((rc, rr, l)) => hemisphere_refined_within(
                        cp,
                        r,
                        n,
                        Point::<3>::new(rc[0], rc[1], rc[2]),
                        rr,
                        l,
                        max_cells_usize,
                    )
                    .map_err(gen_err)?,
                })
            }
        }
        "layered_arc" => {
            let c = center(2)?;
            let a = cx.req(&m.angles_deg, k, "angles_deg", span, why)?;
            let a = cx.array(a, &key(k, "angles_deg"), 2, "the angle range [start, end] in degrees")?;
            let n_angle = cx.at_least(cx.req(&m.n_angle, k, "n_angle", span, why)?, &key(k, "n_angle"), 1)?;
            let (radii, nr, layer) = layers()?;
            let mut all = layered_arc_2d(
                Point::<2>::new(c[0], c[1]),
                &radii,
                (a[0].to_radians(), a[1].to_radians()),
                n_angle,
                &nr,
            )
            .map_err(gen_err)?;
            Box::new(all.swap_remove(layer))
        }
        "layered_cap" => {
            let c = center(3)?;
            let h = cx.req(&m.half_angle_deg, k, "half_angle_deg", span, why)?;
            let h = cx.positive(h, &key(k, "half_angle_deg"))?;
            let ns =
                cx.at_least(cx.req(&m.n_surface, k, "n_surface", span, why)?, &key(k, "n_surface"), 1)?;
            let (radii, nr, layer) = layers()?;
            let mut all = layered_cap_3d(Point::<3>::new(c[0], c[1], c[2]), &radii, h.to_radians(), ns, &nr)
                .map_err(gen_err)?;
            Box::new(all.swap_remove(layer))
        }
        _ => return Err(cx.err(key(k, "generator"), span.clone(), format!("unknown generator `{name}`"))),
    };
    mesh.downcast::<Mesh<D>>().map(|b| *b).map_err(|_| {
        cx.err(key(k, "generator"), span.clone(), format!("generator `{name}` does not make {D}D meshes"))
    })
}

fn define_part<const D: usize>(cx: &Cx<'_>, mesh: &mut Mesh<D>, p: &Sp<PartSpec>, k: &str) -> R<()> {
    let s = p.get_ref();
    let name = s.name.get_ref().clone();
    if mesh.boundary_part(&name).is_ok() {
        return Err(cx.err(key(k, "name"), s.name.span(), format!("the mesh already has a part `{name}`")));
    }
    let mut ranges: Vec<(usize, f64, f64)> = Vec::new();
    for (a, r) in [&s.x, &s.y, &s.z].into_iter().enumerate() {
        if let Some(r) = r {
            let rk = key(k, AXES[a]);
            if a >= D {
                return Err(cx.err(rk, r.span(), format!("`{}` does not apply in {D}D", AXES[a])));
            }
            let (lo, hi) = cx.range(r, &rk)?;
            ranges.push((a, lo, hi));
        }
    }
    let direction = match &s.normal {
        Some(n) => {
            let d = cx.nonzero::<D>(n, &key(k, "normal"))?;
            Some(d / d.norm())
        }
        None => None,
    };
    let max_angle = match &s.max_angle_deg {
        Some(a) => {
            let ak = key(k, "max_angle_deg");
            if s.normal.is_none() {
                return Err(cx.err(ak, a.span(), "`max_angle_deg` needs `normal`"));
            }
            let v = cx.positive(a, &ak)?;
            if v > 180.0 {
                return Err(cx.err(ak, a.span(), format!("must be at most 180, got {v}")));
            }
            v
        }
        None => 90.0,
    };
    let cos_max = max_angle.to_radians().cos();
    let ball = match &s.within {
        Some(w) => {
            let wk = key(k, "within");
            let c = cx.point::<D>(&w.get_ref().center, &key(&wk, "center"))?;
            Some((c, cx.positive(&w.get_ref().radius, &key(&wk, "radius"))?))
        }
        None => None,
    };
    let select = |x: &Point<D>, n: &Vector<D>| -> bool {
        ranges.iter().all(|&(a, lo, hi)| x[a] >= lo && x[a] <= hi)
            && direction.is_none_or(|d| n.dot(&d) > cos_max + 1e-12)
            && ball.is_none_or(|(c, r)| (x - c).norm() <= r)
    };
    let result = match &s.from {
        None => mesh.add_boundary_part(&name, BoundaryKind::TractionFree, select).map(|_| ()),
        Some(from) => {
            let part = mesh.boundary_part(from.get_ref()).map_err(|_| {
                let parts: Vec<&str> = mesh.boundary_parts().iter().map(|p| p.name()).collect();
                cx.err(
                    key(k, "from"),
                    from.span(),
                    format!("the mesh has no part `{}` (its parts: {})", from.get_ref(), parts.join(", ")),
                )
            })?;
            let facets: Vec<Vec<usize>> = part
                .facets()
                .filter(|f| select(&mesh.facet_centroid(f), &mesh.facet_normal(f)))
                .map(<[usize]>::to_vec)
                .collect();
            mesh.add_boundary_part_from_facets(&name, BoundaryKind::TractionFree, &facets).map(|_| ())
        }
    };
    result.map_err(|e| cx.err(k, p.span(), format!("part `{name}`: {e}")))
}

/// The material of a `material` table (`kelvin_voigt` only where `allow_kv`).
fn material<const D: usize>(
    cx: &Cx<'_>,
    spec: &Sp<MaterialSpec>,
    k: &str,
    allow_kv: bool,
) -> R<BodyMaterial<D>> {
    let m = spec.get_ref();
    let span = spec.span();
    let kind = m.kind.get_ref().as_str();
    let why = format!("material `{kind}`");
    let why = why.as_str();
    let present = present!(m;
        "E" => e, "nu" => nu, "plane" => plane, "E_p" => e_p, "nu_p" => nu_p, "E_a" => e_a,
        "nu_ap" => nu_ap, "G_a" => g_a, "axis" => axis, "C" => c, "elastic" => elastic,
        "viscous" => viscous, "density" => density, "damping" => damping, "c1" => c1, "c2" => c2,
        "lambda" => lambda,
    );
    let plane_stress_wanted = || -> R<bool> {
        match &m.plane {
            None => Ok(false),
            Some(p) => {
                let pk = key(k, "plane");
                if D != 2 {
                    return Err(cx.err(pk, p.span(), "`plane` applies to 2D scenarios only"));
                }
                cx.keyword(p, &pk, "`plane`", &[("strain", false), ("stress", true)])
            }
        }
    };
    let mat_err = |e: synovia::material::MaterialError| cx.err(k, span.clone(), e.to_string());
    let linear: Box<dyn Any> = match kind {
        "isotropic" => {
            cx.only(k, &present, &["E", "nu", "plane"], why)?;
            let e = cx.positive(cx.req(&m.e, k, "E", &span, why)?, &key(k, "E"))?;
            let nu = cx.finite(cx.req(&m.nu, k, "nu", &span, why)?, &key(k, "nu"))?;
            if D == 2 {
                let mat = if plane_stress_wanted()? { plane_stress(e, nu) } else { plane_strain(e, nu) };
                Box::new(mat.map_err(mat_err)?)
            } else {
                Box::new(synovia::material::isotropic(e, nu).map_err(mat_err)?)
            }
        }
        "transversely_isotropic" => {
            cx.only(k, &present, &["E_p", "nu_p", "E_a", "nu_ap", "G_a", "axis", "plane"], why)?;
            let p = TransverseIsotropy {
                e_p: cx.finite(cx.req(&m.e_p, k, "E_p", &span, why)?, &key(k, "E_p"))?,
                nu_p: cx.finite(cx.req(&m.nu_p, k, "nu_p", &span, why)?, &key(k, "nu_p"))?,
                e_a: cx.finite(cx.req(&m.e_a, k, "E_a", &span, why)?, &key(k, "E_a"))?,
                nu_ap: cx.finite(cx.req(&m.nu_ap, k, "nu_ap", &span, why)?, &key(k, "nu_ap"))?,
                g_a: cx.finite(cx.req(&m.g_a, k, "G_a", &span, why)?, &key(k, "G_a"))?,
            };
            let axis = cx.nonzero::<D>(cx.req(&m.axis, k, "axis", &span, why)?, &key(k, "axis"))?;
            if D == 2 {
                let a = Vector::<2>::new(axis[0], axis[1]);
                let mat = if plane_stress_wanted()? {
                    transversely_isotropic_plane_stress(p, a)
                } else {
                    transversely_isotropic_plane_strain(p, a)
                };
                Box::new(mat.map_err(mat_err)?)
            } else {
                let a = Vector::<3>::new(axis[0], axis[1], axis.get(2).copied().unwrap_or(0.0));
                Box::new(transversely_isotropic(p, a).map_err(mat_err)?)
            }
        }
        "anisotropic" => {
            cx.only(k, &present, &["C", "plane"], why)?;
            let c = cx.req(&m.c, k, "C", &span, why)?;
            let ck = key(k, "C");
            let rows = c.get_ref();
            let n = rows.len();
            if rows.iter().any(|r| r.len() != n) || rows.iter().flatten().any(|x| !x.is_finite()) {
                return Err(cx.err(ck, c.span(), "`C` must be a square matrix of finite numbers (rows of equal length)"));
            }
            let data: Vec<f64> = rows.iter().flatten().copied().collect();
            let matrix = VoigtMatrix::from_row_slice(n, n, &data);
            let cerr = |e: synovia::material::MaterialError| cx.err(&ck, c.span(), e.to_string());
            if n == voigt_len(D) && m.plane.is_none() {
                Box::new(anisotropic::<D>(matrix).map_err(cerr)?)
            } else if D == 2 && n == 6 {
                let full = anisotropic::<3>(matrix).map_err(cerr)?;
                Box::new(if plane_stress_wanted()? { full.plane_stress().map_err(cerr)? } else { full.plane_strain() })
            } else {
                return Err(cx.err(
                    ck,
                    c.span(),
                    format!(
                        "`C` is {n}×{n}; in {D}D give the {v}×{v} Voigt matrix{extra}",
                        v = voigt_len(D),
                        extra = if D == 2 { " (without `plane`), or a 6×6 3D matrix with `plane`" } else { "" }
                    ),
                ));
            }
        }
        "neo_hookean" | "mooney_rivlin" => {
            if m.plane.as_ref().is_some_and(|p| p.get_ref() != "strain") {
                let p = m.plane.as_ref().map(|p| p.span()).unwrap_or(span.clone());
                return Err(cx.err(key(k, "plane"), p, "hyperelastic laws are in plane strain in 2D (`plane = \"strain\"`)"));
            }
            if D == 2 {
                plane_stress_wanted()?;
            }
            let law: Arc<dyn Material<D>> = if kind == "neo_hookean" {
                cx.only(k, &present, &["E", "nu", "plane"], why)?;
                let e = cx.positive(cx.req(&m.e, k, "E", &span, why)?, &key(k, "E"))?;
                let nu = cx.finite(cx.req(&m.nu, k, "nu", &span, why)?, &key(k, "nu"))?;
                Arc::new(synovia::material::neo_hookean(e, nu).map_err(mat_err)?)
            } else {
                cx.only(k, &present, &["c1", "c2", "lambda", "plane"], why)?;
                let c1 = cx.non_negative(cx.req(&m.c1, k, "c1", &span, why)?, &key(k, "c1"))?;
                let c2 = cx.non_negative(cx.req(&m.c2, k, "c2", &span, why)?, &key(k, "c2"))?;
                let lambda = cx.non_negative(cx.req(&m.lambda, k, "lambda", &span, why)?, &key(k, "lambda"))?;
                Arc::new(synovia::material::mooney_rivlin(c1, c2, lambda).map_err(mat_err)?)
            };
            return Ok(BodyMaterial::Elastic(law));
        }
        "kelvin_voigt" => {
            if !allow_kv {
                return Err(cx.err(key(k, "type"), m.kind.span(), "a kelvin_voigt material cannot be nested"));
            }
            cx.only(k, &present, &["elastic", "viscous", "density", "damping"], why)?;
            let el = cx.req(&m.elastic, k, "elastic", &span, why)?;
            let c0 = linear_of::<D>(cx, el, &key(k, "elastic"))?;
            let c1: Option<Arc<dyn Material<D>>> = match &m.viscous {
                None => None,
                Some(v) => Some(linear_of::<D>(cx, v, &key(k, "viscous"))?),
            };
            let rho = cx.positive(cx.req(&m.density, k, "density", &span, why)?, &key(k, "density"))?;
            let alpha = match &m.damping {
                Some(d) => cx.non_negative(d, &key(k, "damping"))?,
                None => 0.0,
            };
            let kv = KelvinVoigt::new(c0, c1, rho, alpha).map_err(mat_err)?;
            return Ok(BodyMaterial::KelvinVoigt(kv));
        }
        other => {
            return Err(cx.err(
                key(k, "type"),
                m.kind.span(),
                format!("unknown material type `{other}` (isotropic, transversely_isotropic, anisotropic, kelvin_voigt, neo_hookean, mooney_rivlin)"),
            ))
        }
    };
    let linear = linear
        .downcast::<LinearElastic<D>>()
        .map_err(|_| cx.err(k, span.clone(), format!("material `{kind}` is not available in {D}D")))?;
    Ok(BodyMaterial::Elastic(Arc::new(*linear)))
}

/// A nested (`elastic` / `viscous`) material of a Kelvin–Voigt body (linear, kept as built so
/// that 2D plane-strain data survive).
fn linear_of<const D: usize>(cx: &Cx<'_>, spec: &Sp<Box<MaterialSpec>>, k: &str) -> R<Arc<dyn Material<D>>> {
    let inner = Sp::new(spec.span(), (**spec.get_ref()).clone());
    match material::<D>(cx, &inner, k, false)? {
        BodyMaterial::Elastic(m) => Ok(m),
        BodyMaterial::KelvinVoigt(_) => {
            Err(cx.err(k, spec.span(), "a kelvin_voigt material cannot be nested"))
        }
    }
}

// ----- boundary conditions -----

fn boundary<const D: usize>(
    cx: &Cx<'_>,
    joint: &mut JointModel<D>,
    bc: &Sp<BoundarySpec>,
    k: &str,
    names: &[String],
    used: &mut HashSet<(String, String)>,
) -> R<()> {
    let s = bc.get_ref();
    let span = bc.span();
    let (body, part) = body_part(cx, joint, &s.body, &s.part, &key(k, "body"), &key(k, "part"), names)?;
    if s.kind.get_ref() != "traction_free" {
        used.insert((body.clone(), part.clone()));
    }
    let kind = s.kind.get_ref().as_str();
    let why = format!("kind `{kind}`");
    let why = why.as_str();
    let present = present!(s;
        "value" => value, "components" => components, "history" => history,
        "translation" => translation, "rotation_deg" => rotation_deg, "center" => center, "axis" => axis,
        "rotation_history" => rotation_history, "rigid_body" => rigid_body,
    );
    let vector_value = || -> R<Vector<D>> {
        let v = cx.req(&s.value, k, "value", &span, &format!("a `{kind}` part needs its vector"))?;
        match v.get_ref() {
            NumOrVec::Vec(a) => cx.vector::<D>(&Sp::new(v.span(), a.clone()), &key(k, "value")),
            NumOrVec::Num(x) => Err(cx.err(
                key(k, "value"),
                v.span(),
                format!("a `{kind}` value is a {D}D vector, got the number {x}"),
            )),
        }
    };
    let history = || cx.history(s.history.as_ref(), &key(k, "history"));
    let built_err = |e: synovia::builder::JointError| cx.err(key(k, "kind"), s.kind.span(), e.to_string());
    match kind {
        "clamped" | "symmetry" | "traction_free" => {
            cx.only(k, &present, &[], why)?;
            match kind {
                "clamped" => joint.clamp(body.as_str(), &part).map(|_| ()),
                "symmetry" => joint.symmetry(body.as_str(), &part).map(|_| ()),
                _ => {
                    if used.contains(&(body.clone(), part.clone())) {
                        return Err(cx.err(
                            key(k, "kind"),
                            s.kind.span(),
                            format!("part `{part}` of body `{body}` already has a condition above"),
                        ));
                    }
                    let id = joint.model().body_id(&body).map_err(|e| cx.err(k, span.clone(), e.to_string()))?;
                    let b = joint.model_mut().body_mut(id).map_err(|e| cx.err(k, span.clone(), e.to_string()))?;
                    b.mesh.set_part_kind(&part, BoundaryKind::TractionFree).map_err(|e| cx.err(k, span.clone(), e.to_string()))?;
                    Ok(())
                }
            }
            .map_err(built_err)?;
        }
        "rigid_body" => {
            cx.only(k, &present, &["rigid_body"], why)?;
            let r = cx.req(&s.rigid_body, k, "rigid_body", &span, why)?;
            joint
                .tie_to_rigid_body(body.as_str(), &part, r.get_ref())
                .map_err(|e| cx.err(key(k, "rigid_body"), r.span(), e.to_string()))?;
        }
        "prescribed" => {
            cx.only(k, &present, &["value", "components", "history"], why)?;
            let value = vector_value()?;
            let mut mask = ComponentMask::ALL;
            if let Some(c) = &s.components {
                let ck = key(k, "components");
                let mut m = [false; 3];
                if c.get_ref().is_empty() {
                    return Err(cx.err(ck, c.span(), "give at least one component"));
                }
                for (j, comp) in c.get_ref().iter().enumerate() {
                    let a = AXES.iter().take(D).position(|x| x == comp.get_ref()).ok_or_else(|| {
                        cx.err(format!("{ck}[{j}]"), comp.span(), format!("a component is one of {}", AXES[..D].join(", ")))
                    })?;
                    m[a] = true;
                }
                mask = ComponentMask(m);
            }
            joint.prescribe_components(body.as_str(), &part, mask, value, history()?).map_err(built_err)?;
        }
        "rigid_motion" => {
            cx.only(
                k,
                &present,
                &["translation", "history", "rotation_deg", "center", "axis", "rotation_history"],
                why,
            )?;
            if s.translation.is_none() && s.rotation_deg.is_none() {
                return Err(cx.err(k, span, "missing `translation` or `rotation_deg` (kind `rigid_motion`)"));
            }
            let mut motion = match &s.rotation_deg {
                None => {
                    for (name, v) in [("center", &s.center), ("axis", &s.axis)] {
                        if let Some(v) = v {
                            return Err(cx.err(key(k, name), v.span(), format!("`{name}` needs `rotation_deg`")));
                        }
                    }
                    if let Some(h) = &s.rotation_history {
                        return Err(cx.err(key(k, "rotation_history"), h.span(), "`rotation_history` needs `rotation_deg`"));
                    }
                    RigidMotion::<D>::identity()
                }
                Some(rot) => {
                    let angle = cx.finite(rot, &key(k, "rotation_deg"))?.to_radians();
                    let h = cx.history(s.rotation_history.as_ref(), &key(k, "rotation_history"))?;
                    let theta = synovia::time::history::FnHistory::new(move |t| angle * h.value(t));
                    let c = cx.req(&s.center, k, "center", &span, "a rotation")?;
                    let cv = cx.array(c, &key(k, "center"), D, "the rotation center")?;
                    let m: Box<dyn Any> = if D == 2 {
                        if let Some(a) = &s.axis {
                            return Err(cx.err(key(k, "axis"), a.span(), "`axis` applies to 3D rotations only"));
                        }
                        Box::new(RigidMotion::<2>::rotation(Point::<2>::new(cv[0], cv[1]), theta))
                    } else {
                        let a = cx.req(&s.axis, k, "axis", &span, "a 3D rotation")?;
                        let av = cx.nonzero::<3>(&Sp::new(a.span(), a.get_ref().clone()), &key(k, "axis"))?;
                        Box::new(
                            RigidMotion::<3>::rotation(Point::<3>::new(cv[0], cv[1], cv[2]), av, theta)
                                .map_err(|e| cx.err(key(k, "axis"), a.span(), e.to_string()))?,
                        )
                    };
                    *m.downcast::<RigidMotion<D>>().map_err(|_| cx.err(k, span.clone(), "rotation not available"))?
                }
            };
            if let Some(t) = &s.translation {
                let tv = cx.vector::<D>(t, &key(k, "translation"))?;
                let h = history()?;
                for (a, &v) in tv.iter().enumerate() {
                    let h = h.clone();
                    motion = motion
                        .with_translation_component(a, synovia::time::history::FnHistory::new(move |t| v * h.value(t)))
                        .map_err(|e| cx.err(key(k, "translation"), t.span(), e.to_string()))?;
                }
            } else if let Some(h) = &s.history {
                return Err(cx.err(key(k, "history"), h.span(), "`history` scales `translation`; use `rotation_history` for the angle"));
            }
            joint.rigid_motion(body.as_str(), &part, motion).map_err(built_err)?;
        }
        "traction" => {
            cx.only(k, &present, &["value", "history"], why)?;
            let value = vector_value()?;
            joint.traction(body.as_str(), &part, value, history()?).map_err(built_err)?;
        }
        "pressure" => {
            cx.only(k, &present, &["value", "history"], why)?;
            let v = cx.req(&s.value, k, "value", &span, "a `pressure` part needs its pressure")?;
            let p = match v.get_ref() {
                NumOrVec::Num(x) if x.is_finite() => *x,
                other => {
                    let got = match other {
                        NumOrVec::Num(x) => x.to_string(),
                        NumOrVec::Vec(v) => format!("a list of {} numbers", v.len()),
                    };
                    return Err(cx.err(key(k, "value"), v.span(), format!("a pressure is one finite number, got {got}")));
                }
            };
            joint.pressure(body.as_str(), &part, p, history()?).map_err(built_err)?;
        }
        other => {
            return Err(cx.err(
                key(k, "kind"),
                s.kind.span(),
                format!(
                    "unknown boundary kind `{other}` (clamped, symmetry, prescribed, rigid_motion, traction, pressure, traction_free)"
                ),
            ))
        }
    }
    Ok(())
}

// ----- contact -----

fn contact<const D: usize>(
    cx: &Cx<'_>,
    joint: &mut JointModel<D>,
    c: &Sp<ContactSpec>,
    k: &str,
    names: &[String],
    in_time: bool,
    shapes: &HashMap<String, Shape<D>>,
) -> R<()> {
    let s = c.get_ref();
    let span = c.span();
    let (body, part) = body_part(cx, joint, &s.body, &s.part, &key(k, "body"), &key(k, "part"), names)?;
    let name = match &s.name {
        Some(n) => n.get_ref().clone(),
        None => format!("{body}:{part}"),
    };
    if joint.pairs().iter().any(|p| p.name == name) {
        let ns = s.name.as_ref().map_or(span.clone(), |n| n.span());
        return Err(cx.err(key(k, "name"), ns, format!("two contact pairs are called `{name}`")));
    }
    let friction = match &s.friction {
        Some(f) => cx.non_negative(f, &key(k, "friction"))?,
        None => 0.0,
    };
    let id = joint.model().body_id(&body).map_err(|e| cx.err(k, span.clone(), e.to_string()))?;
    if let Some(r) = &s.rigid_body {
        let rk = key(k, "rigid_body");
        if s.partner.is_some() || s.obstacle.is_some() {
            return Err(cx.err(rk, r.span(), "give one of `partner`, `obstacle` and `rigid_body`"));
        }
        let shape = shapes.get(r.get_ref()).ok_or_else(|| {
            let known: Vec<&String> = shapes.keys().collect();
            cx.err(
                &rk,
                r.span(),
                format!(
                    "no rigid body `{}` with a `shape` (rigid bodies with shapes: {known:?})",
                    r.get_ref()
                ),
            )
        })?;
        joint
            .contact_rigid_body(&name, id, &part, r.get_ref(), shape.clone(), friction)
            .map_err(|e| cx.err(key(k, "part"), s.part.span(), e.to_string()))?;
        if let Some(d) = &s.search_distance {
            let dk = key(k, "search_distance");
            joint
                .search_distance(&name, cx.positive(d, &dk)?)
                .map_err(|e| cx.err(dk, d.span(), e.to_string()))?;
        }
        return contact_options(cx, joint, s, k, &name, in_time);
    }
    let mut pair = match (&s.partner, &s.obstacle) {
        (Some(p), None) => {
            let pk = key(k, "partner");
            let (lb, lp) = body_part(
                cx,
                joint,
                &p.get_ref().body,
                &p.get_ref().part,
                &key(&pk, "body"),
                &key(&pk, "part"),
                names,
            )?;
            if lb == body {
                return Err(cx.err(
                    key(&pk, "body"),
                    p.get_ref().body.span(),
                    "a body cannot be in contact with itself",
                ));
            }
            let l = joint.model().body_id(&lb).map_err(|e| cx.err(&pk, p.span(), e.to_string()))?;
            let kind = s.discretisation.as_ref().map_or("node_to_node", |d| d.get_ref().as_str());
            let matching_only = |f: &str, v: Option<std::ops::Range<usize>>| match v {
                Some(sp) if kind != "node_to_node" => Err(cx.err(
                    key(k, f),
                    sp,
                    format!("`{f}` applies to node-to-node pairs only (this pair is `{kind}`)"),
                )),
                _ => Ok(()),
            };
            matching_only("normal", s.normal.as_ref().map(|v| v.span()))?;
            matching_only("tolerance", s.tolerance.as_ref().map(|v| v.span()))?;
            let mut pair = match kind {
                "node_to_node" => {
                    if let Some(d) = &s.search_distance {
                        return Err(cx.err(
                            key(k, "search_distance"),
                            d.span(),
                            "`search_distance` applies to `node_to_segment` and `mortar` pairs only",
                        ));
                    }
                    ContactPair::<D>::node_to_node(&name, id, &part, l, &lp)
                }
                "node_to_segment" | "node_to_facet" => {
                    ContactPair::<D>::node_to_segment(&name, id, &part, l, &lp)
                }
                "mortar" => ContactPair::<D>::mortar(&name, id, &part, l, &lp),
                other => {
                    let span = s.discretisation.as_ref().map_or(span.clone(), |d| d.span());
                    return Err(cx.err(
                        key(k, "discretisation"),
                        span,
                        format!(
                            "unknown contact discretisation `{other}`: use `node_to_node`, `node_to_segment` \
                             (`node_to_facet` in 3D) or `mortar`"
                        ),
                    ));
                }
            };
            if let Some(d) = &s.search_distance {
                pair = pair.with_search_distance(cx.positive(d, &key(k, "search_distance"))?);
            }
            if let Some(n) = &s.normal {
                pair = pair.with_fixed_normal(cx.nonzero::<D>(n, &key(k, "normal"))?);
            }
            if let Some(t) = &s.tolerance {
                pair = pair.with_pairing_tolerance(cx.positive(t, &key(k, "tolerance"))?);
            }
            pair
        }
        (None, Some(o)) => {
            for (f, v) in [
                ("normal", s.normal.as_ref().map(|v| v.span())),
                ("tolerance", s.tolerance.as_ref().map(|v| v.span())),
                ("discretisation", s.discretisation.as_ref().map(|v| v.span())),
                ("search_distance", s.search_distance.as_ref().map(|v| v.span())),
            ] {
                if let Some(sp) = v {
                    return Err(cx.err(
                        key(k, f),
                        sp,
                        format!("`{f}` applies to body-body pairs (`partner`) only"),
                    ));
                }
            }
            ContactPair::rigid(&name, id, &part, obstacle::<D>(cx, o, &key(k, "obstacle"))?)
        }
        (Some(_), Some(o)) => {
            return Err(cx.err(key(k, "obstacle"), o.span(), "give either `partner` or `obstacle`, not both"))
        }
        (None, None) => {
            return Err(cx.err(k, span, "missing `partner` (another body) or `obstacle` (a rigid one)"))
        }
    };
    pair.friction = friction;
    joint.add_contact(pair).map_err(|e| cx.err(key(k, "part"), s.part.span(), e.to_string()))?;
    contact_options(cx, joint, s, k, &name, in_time)
}

/// The options of a contact pair once it is added: initial penetration policy, friction law.
fn contact_options<const D: usize>(
    cx: &Cx<'_>,
    joint: &mut JointModel<D>,
    s: &ContactSpec,
    k: &str,
    name: &str,
    in_time: bool,
) -> R<()> {
    let name = name.to_string();
    if let Some(r) = &s.refuse_initial_penetration {
        joint
            .refuse_initial_penetration_in(&name, *r.get_ref())
            .map_err(|e| cx.err(key(k, "refuse_initial_penetration"), r.span(), e.to_string()))?;
    }
    if let Some(sp) = &s.split {
        let sk = key(k, "split");
        let v = sp.get_ref();
        let three = |a: &Sp<Vec<f64>>, what: &str| -> R<[f64; 3]> {
            let x = cx.array(a, &key(&sk, what), D, &format!("a {D}D {what}"))?;
            Ok([x[0], x[1], if D > 2 { x[2] } else { 0.0 }])
        };
        let split = synovia::contact_ops::operators::PairSplit::new(
            v.positive.get_ref(),
            v.negative.get_ref(),
            three(&v.point, "point")?,
            three(&v.normal, "normal")?,
        )
        .map_err(|e| cx.err(sk.clone(), sp.span(), e.to_string()))?;
        joint.split_pair_report(&name, split).map_err(|e| cx.err(sk, sp.span(), e.to_string()))?;
    }
    if let Some(l) = &s.friction_law {
        let lk = key(k, "friction_law");
        if !in_time {
            return Err(cx.err(
                lk,
                l.span(),
                "`friction_law` needs slip speeds: quasi-static and dynamic analyses only (a static analysis: use `friction`)",
            ));
        }
        let ls = l.get_ref();
        let law = ExponentialFriction {
            static_coefficient: cx.non_negative(&ls.static_coefficient, &key(&lk, "static"))?,
            kinetic_coefficient: cx.non_negative(&ls.kinetic_coefficient, &key(&lk, "kinetic"))?,
            characteristic_speed: cx.positive(&ls.characteristic_speed, &key(&lk, "speed"))?,
        };
        joint.friction_law(&name, Arc::new(law)).map_err(|e| cx.err(lk, l.span(), e.to_string()))?;
    }
    Ok(())
}

fn obstacle<const D: usize>(
    cx: &Cx<'_>,
    o: &Sp<ObstacleSpec>,
    k: &str,
) -> R<Arc<dyn synovia::contact_ops::operators::SignedDistance<D>>> {
    let s = o.get_ref();
    let span = o.span();
    let kind = s.kind.get_ref().as_str();
    let why = format!("obstacle `{kind}`");
    let why = why.as_str();
    let present = present!(s; "point" => point, "normal" => normal, "center" => center, "radius" => radius,
        "axis" => axis, "cavity" => cavity, "file" => file, "scale" => scale, "solid" => solid,
        "subdivide" => subdivide, "crease_angle_deg" => crease_angle_deg, "fillet" => fillet,
        "fillet_max_offset" => fillet_max_offset);
    let cavity = s.cavity.as_ref().is_some_and(|c| *c.get_ref());
    let any: Box<dyn Any> = match kind {
        "plane" => {
            cx.only(k, &present, &["point", "normal"], why)?;
            let p = cx.point::<D>(cx.req(&s.point, k, "point", &span, why)?, &key(k, "point"))?;
            let n = cx.nonzero::<D>(cx.req(&s.normal, k, "normal", &span, why)?, &key(k, "normal"))?;
            let plane = PlaneObstacle::new(p, n).map_err(|e| cx.err(k, span.clone(), e.to_string()))?;
            let d: Arc<dyn synovia::contact_ops::operators::SignedDistance<D>> = Arc::new(plane);
            return Ok(d);
        }
        "sphere" => {
            cx.only(k, &present, &["center", "radius", "cavity"], why)?;
            let c = cx.point::<D>(cx.req(&s.center, k, "center", &span, why)?, &key(k, "center"))?;
            let r = cx.positive(cx.req(&s.radius, k, "radius", &span, why)?, &key(k, "radius"))?;
            let d: Arc<dyn synovia::contact_ops::operators::SignedDistance<D>> = Arc::new(
                SphereObstacle::new(c, r, cavity).map_err(|e| cx.err(k, span.clone(), e.to_string()))?,
            );
            return Ok(d);
        }
        "cylinder" => {
            if D != 3 {
                return Err(cx.err(
                    key(k, "type"),
                    s.kind.span(),
                    "a `cylinder` obstacle is 3D; in 2D use `sphere`",
                ));
            }
            cx.only(k, &present, &["point", "axis", "radius", "cavity"], why)?;
            let p = cx.point::<3>(cx.req(&s.point, k, "point", &span, why)?, &key(k, "point"))?;
            let a = cx.nonzero::<3>(cx.req(&s.axis, k, "axis", &span, why)?, &key(k, "axis"))?;
            let r = cx.positive(cx.req(&s.radius, k, "radius", &span, why)?, &key(k, "radius"))?;
            let d: Arc<dyn synovia::contact_ops::operators::SignedDistance<3>> = Arc::new(
                CylinderObstacle::new(p, a, r, cavity).map_err(|e| cx.err(k, span.clone(), e.to_string()))?,
            );
            Box::new(d)
        }
        "stl" => {
            if D != 3 {
                return Err(cx.err(key(k, "type"), s.kind.span(), "an `stl` surface is 3D"));
            }
            cx.only(
                k,
                &present,
                &["file", "scale", "solid", "subdivide", "crease_angle_deg", "fillet", "fillet_max_offset"],
                why,
            )?;
            let f = cx.req(&s.file, k, "file", &span, why)?;
            let fk = key(k, "file");
            let path = cx.src.resolve(f.get_ref());
            let mut surface =
                synovia::io::read_stl(&path).map_err(|e| cx.err(&fk, f.span(), e.to_string()))?;
            if let Some(sc) = &s.scale {
                let factor = cx.positive(sc, &key(k, "scale"))?;
                surface =
                    surface.scaled(factor).map_err(|e| cx.err(key(k, "scale"), sc.span(), e.to_string()))?;
            }
            let solid = s.solid.as_ref().is_none_or(|v| *v.get_ref());
            // `subdivide`: Loop subdivision (a solid keeps its control surface for far queries)
            let mut smoothing = None;
            if let Some(levels) = &s.subdivide {
                let n = usize::try_from(*levels.get_ref()).map_err(|_| {
                    cx.err(key(k, "subdivide"), levels.span(), "levels of subdivision must be 0 to 4")
                })?;
                let angle = match &s.crease_angle_deg {
                    Some(a) => cx.finite(a, &key(k, "crease_angle_deg"))?,
                    None => 30.0,
                }
                .to_radians();
                if solid {
                    smoothing = Some((n, angle));
                } else {
                    surface = surface
                        .loop_subdivided(n, angle)
                        .map_err(|e| cx.err(key(k, "subdivide"), levels.span(), e.to_string()))?;
                }
            } else if let Some(a) = &s.crease_angle_deg {
                return Err(cx.err(
                    key(k, "crease_angle_deg"),
                    a.span(),
                    "`crease_angle_deg` needs `subdivide`",
                ));
            }
            let obstacle = if let Some((n, angle)) = smoothing {
                synovia::contact_ops::SurfaceObstacle::smoothed_solid(surface, n, angle)
            } else if solid {
                synovia::contact_ops::SurfaceObstacle::solid(surface)
            } else {
                synovia::contact_ops::SurfaceObstacle::new(surface)
            }
            .map_err(|e| {
                cx.err(
                    &fk,
                    f.span(),
                    format!(
                        "{}: {e}{}",
                        f.get_ref(),
                        if solid {
                            " (a `solid` surface must be closed; `solid = false` accepts an open patch)"
                        } else {
                            ""
                        }
                    ),
                )
            })?;
            // `fillet`: the concave edges rounded (continuous normals where a node is pressed
            // into a groove of the surface; docs/nonlinear.md "A node in a concave corner")
            let obstacle = match (&s.fillet, &s.fillet_max_offset) {
                (Some(r), offset) => {
                    let radius = cx.non_negative(r, &key(k, "fillet"))?;
                    let max_offset = match offset {
                        Some(o) => cx.positive(o, &key(k, "fillet_max_offset"))?,
                        None => f64::INFINITY,
                    };
                    obstacle
                        .with_concave_fillet(radius, max_offset)
                        .map_err(|e| cx.err(key(k, "fillet"), r.span(), e.to_string()))?
                }
                (None, Some(o)) => {
                    return Err(cx.err(
                        key(k, "fillet_max_offset"),
                        o.span(),
                        "`fillet_max_offset` needs `fillet`",
                    ))
                }
                (None, None) => obstacle,
            };
            let d: Arc<dyn synovia::contact_ops::operators::SignedDistance<3>> = Arc::new(obstacle);
            Box::new(d)
        }
        other => {
            return Err(cx.err(
                key(k, "type"),
                s.kind.span(),
                format!("unknown obstacle `{other}` (plane, sphere, cylinder, stl)"),
            ))
        }
    };
    any.downcast::<Arc<dyn synovia::contact_ops::operators::SignedDistance<D>>>()
        .map(|b| *b)
        .map_err(|_| cx.err(k, span, format!("obstacle `{kind}` is not available in {D}D")))
}

// ----- solver, analysis, output -----

fn solver<const D: usize>(cx: &Cx<'_>, joint: &mut JointModel<D>, s: &Sp<SolverSpec>) -> R<()> {
    let k = "solver";
    let s = s.get_ref();
    let present = present!(s;
        "tolerance" => tolerance, "max_iterations" => max_iterations, "rho_scale" => rho_scale,
        "nested_iteration" => nested_iteration, "ordering" => ordering, "load_degree" => load_degree,
        "memory_limit_mb" => memory_limit_mb, "interface_block_dofs" => interface_block_dofs,
        "screening_band" => screening_band, "subdomains" => subdomains, "partitioner" => partitioner,
        "preconditioner" => preconditioner, "rho" => rho, "coarse" => coarse, "expansion" => expansion,
    );
    if s.name.as_ref().is_some_and(|n| n.get_ref() == TFETI) {
        return tfeti_solver(cx, joint, s, &present);
    }
    let tfeti_keys = ["subdomains", "partitioner", "preconditioner", "rho", "coarse", "expansion"];
    let direct: Vec<&str> = present.iter().map(|(n, _)| *n).filter(|n| !tfeti_keys.contains(n)).collect();
    let name = s.name.as_ref().map_or(synovia::solvers::DEFAULT_SOLVER, |n| n.get_ref().as_str());
    cx.only(k, &present, &direct, &format!("solver `{name}`; they are keys of `{TFETI}`"))?;
    let mut params = ContactParams::default();
    if let Some(t) = &s.tolerance {
        params.tolerance = cx.positive(t, "solver.tolerance")?;
    }
    if let Some(m) = &s.max_iterations {
        params.max_iterations = cx.at_least(m, "solver.max_iterations", 1)?;
    }
    if let Some(r) = &s.rho_scale {
        params.rho_scale = cx.positive(r, "solver.rho_scale")?;
    }
    joint.contact_params(params);
    if let Some(n) = &s.name {
        joint.solver(n.get_ref()).map_err(|e| cx.err(key(k, "name"), n.span(), e.to_string()))?;
    }
    if let Some(n) = &s.nested_iteration {
        let v = *n.get_ref();
        joint.nested_iteration((v > 0).then_some(v));
    }
    if let Some(n) = &s.interface_block_dofs {
        let v = *n.get_ref();
        let base = synovia::linalg::InterfaceBlockParams::default();
        joint.interface_block(base.with_max_dofs(v).with_screened_dofs(base.screened_dofs.min(v)));
    }
    if let Some(b) = &s.screening_band {
        joint
            .screening_band(Some(*b.get_ref()))
            .map_err(|e| cx.err(key(k, "screening_band"), b.span(), e.to_string()))?;
    }
    let mut elastic = ElasticParams::default();
    if let Some(o) = &s.ordering {
        elastic.ordering = cx.keyword(
            o,
            "solver.ordering",
            "ordering",
            &[("auto", OrderingChoice::Auto), ("amd", OrderingChoice::Amd), ("metis", OrderingChoice::Metis)],
        )?;
    }
    if let Some(d) = &s.load_degree {
        elastic.load_degree = cx.at_least(d, "solver.load_degree", 1)?;
    }
    if let Some(m) = &s.memory_limit_mb {
        let mb = cx.positive(m, "solver.memory_limit_mb")?;
        elastic.memory_limit = Some((mb * 1024.0 * 1024.0).min(u64::MAX as f64) as u64);
    }
    joint.elastic_params(elastic);
    Ok(())
}

/// `[force_control]`: the parameters of the force-control iteration of rigid bodies.
fn force_control<const D: usize>(cx: &Cx<'_>, joint: &mut JointModel<D>, f: &Sp<ForceControlSpec>) -> R<()> {
    let k = "force_control";
    if joint.rigid_bodies().iter().all(|b| b.force_dofs().is_empty()) {
        return Err(cx.err(
            k,
            f.span(),
            "`[force_control]` sets the iteration of force-controlled degrees of freedom, but no rigid body has one (`tx = { force = … }` and the like)",
        ));
    }
    let s = f.get_ref();
    let mut p = joint.force_control_params();
    if let Some(v) = &s.tolerance {
        let x = cx.positive(v, "force_control.tolerance")?;
        if x >= 1.0 {
            return Err(cx.err("force_control.tolerance", v.span(), format!("must be below 1, got {x}")));
        }
        p.tolerance = x;
    }
    if let Some(v) = &s.max_solves {
        p.max_solves = cx.at_least(v, "force_control.max_solves", 1)?;
    }
    if let Some(v) = &s.geometry_tolerance {
        p.geometry_tolerance = cx.positive(v, "force_control.geometry_tolerance")?;
    }
    if let Some(v) = &s.bordered {
        p.bordered = *v.get_ref();
    }
    if let Some(v) = &s.fresh_jacobian {
        p.fresh_jacobian = *v.get_ref();
    }
    joint.force_control(p);
    Ok(())
}

/// `[newton]`: the parameters of the Newton iteration of a nonlinear model.
fn newton<const D: usize>(cx: &Cx<'_>, joint: &mut JointModel<D>, n: &Sp<NewtonSpec>) -> R<()> {
    let k = "newton";
    if !joint.is_nonlinear() {
        return Err(cx.err(
            k,
            n.span(),
            "`[newton]` sets the Newton iteration of nonlinear models, but every body is linear with small strain (a `neo_hookean` or `mooney_rivlin` material or `kinematics = \"finite\"` makes a body nonlinear)",
        ));
    }
    let s = n.get_ref();
    let fraction = |v: &Sp<f64>, name: &str, closed: bool| -> R<f64> {
        let x = *v.get_ref();
        if x.is_finite() && x > 0.0 && (x < 1.0 || (closed && x == 1.0)) {
            Ok(x)
        } else {
            let range = if closed { "(0, 1]" } else { "(0, 1)" };
            Err(cx.err(key(k, name), v.span(), format!("must lie in {range}, got {x}")))
        }
    };
    let mut p = joint.newton_parameters();
    if let Some(v) = &s.tolerance {
        p = p.with_tolerance(cx.positive(v, "newton.tolerance")?);
    }
    if let Some(v) = &s.max_iterations {
        p = p.with_max_iterations(cx.at_least(v, "newton.max_iterations", 1)?);
    }
    if let Some(v) = &s.line_search {
        p = p.with_line_search(*v.get_ref());
    }
    if let Some(v) = &s.max_cutbacks {
        p = p.with_max_cutbacks(*v.get_ref());
    }
    if let Some(v) = &s.tangent_reuse {
        p = p.with_tangent_reuse(Some(fraction(v, "tangent_reuse", false)?));
    }
    if let Some(v) = &s.geometry {
        p = p.with_geometry_update(cx.keyword(
            v,
            "newton.geometry",
            "the geometry update",
            &GeometryUpdate::NAMES,
        )?);
    }
    if let Some(v) = &s.geometry_tolerance {
        p = p.with_geometry_tolerance(cx.positive(v, "newton.geometry_tolerance")?);
    }
    if let Some(v) = &s.max_geometry_passes {
        p = p.with_max_geometry_passes(cx.at_least(v, "newton.max_geometry_passes", 1)?);
    }
    if let Some(v) = &s.geometry_relaxation {
        p = p.with_geometry_relaxation(fraction(v, "geometry_relaxation", true)?);
    }
    if let Some(v) = &s.geometry_aitken {
        p = p.with_geometry_aitken(*v.get_ref());
    }
    if let Some(v) = &s.geometry_pass_tolerance {
        p = p.with_geometry_pass_tolerance(Some(cx.positive(v, "newton.geometry_pass_tolerance")?));
    }
    if let Some(v) = &s.settled_increment {
        p = p.with_settled_increment(Some(cx.positive(v, "newton.settled_increment")?));
    }
    if let Some(v) = &s.active_sets {
        p = p.with_active_sets(cx.keyword(
            v,
            "newton.active_sets",
            "the active-set strategy",
            &[
                ("nested", ActiveSetStrategy::Nested),
                ("combined", ActiveSetStrategy::Combined),
                ("outer", ActiveSetStrategy::Outer),
            ],
        )?);
    }
    p.check().map_err(|e| cx.err(k, n.span(), e.to_string()))?;
    joint.newton_params(p);
    Ok(())
}

/// `[solver]` with `name = "tfeti"`: the decomposition and SMALBE parameters; the keys of the
/// direct solvers' factorisation and active-set iteration do not apply.
fn tfeti_solver<const D: usize>(
    cx: &Cx<'_>,
    joint: &mut JointModel<D>,
    s: &SolverSpec,
    present: &[(&str, Option<std::ops::Range<usize>>)],
) -> R<()> {
    let k = "solver";
    let ok = [
        "tolerance",
        "max_iterations",
        "load_degree",
        "subdomains",
        "partitioner",
        "preconditioner",
        "rho",
        "coarse",
        "expansion",
    ];
    cx.only(k, present, &ok, &format!("solver `{TFETI}`"))?;
    let mut decomposition = DecompositionParams::default();
    let mut params = TfetiParams::default();
    if let Some(n) = &s.subdomains {
        decomposition = decomposition.with_subdomains(cx.at_least(n, "solver.subdomains", 1)?);
    }
    if let Some(p) = &s.partitioner {
        decomposition = decomposition.with_partitioner(cx.keyword(
            p,
            "solver.partitioner",
            "partitioner",
            &[("metis", Partitioner::Metis), ("bisection", Partitioner::Bisection)],
        )?);
    }
    if let Some(p) = &s.preconditioner {
        params = params.with_preconditioner(cx.keyword(
            p,
            "solver.preconditioner",
            "preconditioner",
            &[
                ("dirichlet", Preconditioner::Dirichlet),
                ("lumped", Preconditioner::Lumped),
                ("none", Preconditioner::None),
            ],
        )?);
    }
    if let Some(c) = &s.coarse {
        params = params.with_coarse(cx.keyword(
            c,
            "solver.coarse",
            "coarse",
            &[("penalty", CoarseConstraint::Penalty), ("projector", CoarseConstraint::Projector)],
        )?);
    }
    if let Some(e) = &s.expansion {
        params = params.with_expansion(cx.keyword(
            e,
            "solver.expansion",
            "expansion",
            &[
                ("fixed", Expansion::Fixed),
                ("projected_cg", Expansion::ProjectedCg),
                ("preconditioned", Expansion::Preconditioned),
            ],
        )?);
    }
    if let Some(t) = &s.tolerance {
        params = params.with_tolerance(cx.positive(t, "solver.tolerance")?);
    }
    if let Some(r) = &s.rho {
        params = params.with_rho_factor(cx.positive(r, "solver.rho")?);
    }
    if let Some(m) = &s.max_iterations {
        params = params.with_max_outer(cx.at_least(m, "solver.max_iterations", 1)?);
    }
    if let Some(n) = &s.name {
        joint.solver(n.get_ref()).map_err(|e| cx.err(key(k, "name"), n.span(), e.to_string()))?;
    }
    joint.tfeti(TfetiSettings::new(decomposition, params));
    let mut elastic = ElasticParams::default();
    if let Some(d) = &s.load_degree {
        elastic.load_degree = cx.at_least(d, "solver.load_degree", 1)?;
    }
    joint.elastic_params(elastic);
    Ok(())
}

fn analysis(cx: &Cx<'_>, a: &Sp<AnalysisSpec>) -> R<Analysis> {
    let k = "analysis";
    let s = a.get_ref();
    let span = a.span();
    let kind = s.kind.get_ref().as_str();
    let why = format!("analysis `{kind}`");
    let why = why.as_str();
    let present = present!(s;
        "time" => time, "times" => times, "coulomb_fixed_point" => coulomb_fixed_point,
        "max_fixed_point" => max_fixed_point, "fixed_point_tolerance" => fixed_point_tolerance,
        "incremental_slip" => incremental_slip, "initial_friction" => initial_friction, "dt" => dt,
        "steps" => steps, "t0" => t0, "mass" => mass, "coulomb_iterations" => coulomb_iterations,
        "coulomb_tolerance" => coulomb_tolerance,
    );
    let friction_keys = ["coulomb_fixed_point", "max_fixed_point", "fixed_point_tolerance"];
    match kind {
        "static" => {
            let mut ok = vec!["time", "initial_friction"];
            ok.extend_from_slice(&friction_keys);
            cx.only(k, &present, &ok, why)?;
            let time = match &s.time {
                Some(t) => cx.finite(t, "analysis.time")?,
                None => 0.0,
            };
            Ok(Analysis::Static { time })
        }
        "quasistatic" => {
            let mut ok = vec!["times", "incremental_slip", "initial_friction"];
            ok.extend_from_slice(&friction_keys);
            cx.only(k, &present, &ok, why)?;
            let t = cx.req(&s.times, k, "times", &span, why)?;
            let tk = "analysis.times";
            let times = match t.get_ref() {
                TimesSpec::List(v) => v.clone(),
                TimesSpec::Range { start, end, steps } => {
                    if !(start.is_finite() && end.is_finite() && end > start && *steps >= 1) {
                        return Err(cx.err(tk, t.span(), "needs finite start < end and steps ≥ 1"));
                    }
                    let max_steps = limits().max_time_steps;
                    if *steps > max_steps {
                        return Err(cx.err(tk, t.span(), format!("at most {max_steps} steps, got {steps}")));
                    }
                    (0..=*steps).map(|i| start + (end - start) * i as f64 / *steps as f64).collect()
                }
            };
            if times.is_empty() {
                return Err(cx.err(tk, t.span(), "needs at least one time level"));
            }
            if let Some(x) = times.iter().find(|x| !x.is_finite()) {
                return Err(cx.err(tk, t.span(), format!("times must be finite, got {x}")));
            }
            for (i, w) in times.windows(2).enumerate() {
                if w[1] <= w[0] {
                    return Err(cx.err(
                        tk,
                        t.span(),
                        format!(
                            "times must increase strictly: t[{}] = {} after t[{i}] = {}",
                            i + 1,
                            w[1],
                            w[0]
                        ),
                    ));
                }
            }
            Ok(Analysis::QuasiStatic { times })
        }
        "dynamic" => {
            cx.only(
                k,
                &present,
                &["dt", "steps", "t0", "mass", "coulomb_iterations", "coulomb_tolerance"],
                why,
            )?;
            let dt = cx.positive(cx.req(&s.dt, k, "dt", &span, why)?, "analysis.dt")?;
            let sp = cx.req(&s.steps, k, "steps", &span, why)?;
            let steps = cx.at_least(sp, "analysis.steps", 1)?;
            // a time level per step is kept (records, histories): bounded like `times`
            let max_steps = limits().max_time_steps;
            if steps > max_steps {
                return Err(cx.err(
                    "analysis.steps",
                    sp.span(),
                    format!("at most {max_steps} steps, got {steps}"),
                ));
            }
            Ok(Analysis::Dynamic { dt, steps })
        }
        other => Err(cx.err(
            "analysis.type",
            s.kind.span(),
            format!("unknown analysis `{other}` (static, quasistatic, dynamic)"),
        )),
    }
}

/// The stepper options of `[analysis]` (its keys were checked by [`analysis`]).
fn quasi_and_dynamic_params<const D: usize>(
    cx: &Cx<'_>,
    joint: &mut JointModel<D>,
    a: &Sp<AnalysisSpec>,
) -> R<()> {
    let s = a.get_ref();
    let mut q = QuasiStaticParams::default();
    if let Some(v) = &s.coulomb_fixed_point {
        q.coulomb_fixed_point = *v.get_ref();
    }
    if let Some(v) = &s.max_fixed_point {
        q.max_fixed_point = cx.at_least(v, "analysis.max_fixed_point", 1)?;
    }
    if let Some(v) = &s.fixed_point_tolerance {
        q.fixed_point_tolerance = cx.positive(v, "analysis.fixed_point_tolerance")?;
    }
    if let Some(v) = &s.incremental_slip {
        q.incremental_slip = *v.get_ref();
    }
    if let Some(v) = &s.initial_friction {
        q.initial_friction = *v.get_ref();
    }
    joint.quasistatic_params(q);
    let mut d = DynamicParams::new(1.0);
    if let Some(v) = &s.t0 {
        d.t0 = cx.finite(v, "analysis.t0")?;
    }
    if let Some(v) = &s.mass {
        d.mass = cx.keyword(
            v,
            "analysis.mass",
            "mass",
            &[("consistent", MassKind::Consistent), ("lumped", MassKind::Lumped)],
        )?;
    }
    if let Some(v) = &s.coulomb_iterations {
        d.coulomb_iterations = *v.get_ref();
    }
    if let Some(v) = &s.coulomb_tolerance {
        d.coulomb_tolerance = cx.positive(v, "analysis.coulomb_tolerance")?;
    }
    joint.dynamic_params(d);
    Ok(())
}

fn output(cx: &Cx<'_>, o: Option<&Sp<OutputSpec>>) -> R<OutputPlan> {
    let mut plan = OutputPlan { dir: None, vtu_every: 1, encoding: Encoding::Zlib, stress: true };
    let Some(o) = o else { return Ok(plan) };
    let s = o.get_ref();
    if let Some(d) = &s.dir {
        if d.get_ref().is_empty() {
            return Err(cx.err("output.dir", d.span(), "must not be empty"));
        }
        plan.dir = Some(PathBuf::from(d.get_ref()));
    }
    if let Some(v) = &s.vtu_every {
        plan.vtu_every = *v.get_ref();
    }
    if let Some(v) = &s.stress {
        plan.stress = *v.get_ref();
    }
    if let Some(e) = &s.encoding {
        plan.encoding = cx.keyword(
            e,
            "output.encoding",
            "encoding",
            &[
                ("zlib", Encoding::Zlib),
                ("binary", Encoding::Base64),
                ("base64", Encoding::Base64),
                ("ascii", Encoding::Ascii),
            ],
        )?;
    }
    Ok(plan)
}

/// A rigid body's contact shape.
type Shape<const D: usize> = Arc<dyn synovia::contact_ops::operators::SignedDistance<D>>;

/// The `[[table]]` files, read, by name.
fn tables(cx: &Cx<'_>, specs: &[Sp<TableSpec>]) -> R<HashMap<String, (synovia::time::table::Table, f64)>> {
    let mut out = HashMap::new();
    for (i, t) in specs.iter().enumerate() {
        let k = format!("table[{i}]");
        let s = t.get_ref();
        let name = s.name.get_ref().clone();
        if out.contains_key(&name) {
            return Err(cx.err(key(&k, "name"), s.name.span(), format!("two tables are called `{name}`")));
        }
        let path = cx.src.resolve(s.file.get_ref());
        let table = synovia::time::table::Table::read(&path)
            .map_err(|e| cx.err(key(&k, "file"), s.file.span(), e.to_string()))?;
        let time_scale = match &s.time_scale {
            Some(v) => {
                let f = cx.finite(v, &key(&k, "time_scale"))?;
                if f == 0.0 {
                    return Err(cx.err(key(&k, "time_scale"), v.span(), "must not be 0"));
                }
                f
            }
            None => 1.0,
        };
        out.insert(name, (table, time_scale));
    }
    Ok(out)
}

/// A `[[rigid_body]]`: its controls, rotation order and shape.
fn rigid_body<const D: usize>(
    cx: &Cx<'_>,
    joint: &mut JointModel<D>,
    spec: &Sp<RigidBodySpec>,
    k: &str,
    tables: &HashMap<String, (synovia::time::table::Table, f64)>,
    shapes: &mut HashMap<String, Shape<D>>,
) -> R<()> {
    use synovia::rigid::RigidBody;
    let s = spec.get_ref();
    let name = s.name.get_ref().clone();
    let centre = match &s.center {
        Some(c) => cx.point::<D>(c, &key(k, "center"))?,
        None => Point::<D>::zeros(),
    };
    let mut body = RigidBody::<D>::new(&name, centre)
        .map_err(|e| cx.err(key(k, "name"), s.name.span(), e.to_string()))?;
    if let Some(o) = &s.rotation_order {
        if D != 3 {
            return Err(cx.err(key(k, "rotation_order"), o.span(), "a rotation order is 3D only"));
        }
        body = body
            .with_rotation_order(o.get_ref())
            .map_err(|e| cx.err(key(k, "rotation_order"), o.span(), e.to_string()))?;
    }
    let dofs = [("tx", &s.tx), ("ty", &s.ty), ("tz", &s.tz), ("rx", &s.rx), ("ry", &s.ry), ("rz", &s.rz)];
    for (dof_name, dof) in dofs {
        let Some(d) = dof else { continue };
        let dk = key(k, dof_name);
        let index = RigidBody::<D>::dof_index(dof_name).map_err(|e| cx.err(&dk, d.span(), e.to_string()))?;
        let rotation = index >= D;
        let ds = d.get_ref();
        let present = present!(ds; "value" => value, "force" => force, "history" => history,
            "table" => table, "column" => column, "scale" => scale, "unit" => unit,
            "guess_column" => guess_column, "guess_scale" => guess_scale);
        let find_table = |t: &Sp<String>| {
            tables.get(t.get_ref()).ok_or_else(|| {
                let known: Vec<&String> = tables.keys().collect();
                cx.err(
                    key(&dk, "table"),
                    t.span(),
                    format!("no [[table]] called `{}` (tables: {known:?})", t.get_ref()),
                )
            })
        };
        let guess: Option<Arc<dyn LoadHistory>> = match &ds.guess_column {
            None => {
                if let Some(g) = &ds.guess_scale {
                    return Err(cx.err(
                        key(&dk, "guess_scale"),
                        g.span(),
                        "`guess_scale` needs `guess_column`",
                    ));
                }
                None
            }
            Some(gc) => {
                let t = ds.table.as_ref().ok_or_else(|| {
                    cx.err(key(&dk, "guess_column"), gc.span(), "`guess_column` needs the `table` it is in")
                })?;
                if ds.force.is_none() {
                    return Err(cx.err(
                        key(&dk, "guess_column"),
                        gc.span(),
                        "`guess_column` applies to a force-controlled coordinate (`force`)",
                    ));
                }
                let (table, time_scale) = find_table(t)?;
                let factor = match &ds.guess_scale {
                    Some(sc) => cx.finite(sc, &key(&dk, "guess_scale"))?,
                    None => 1.0,
                };
                let h = table
                    .history(gc.get_ref(), factor, *time_scale)
                    .map_err(|e| cx.err(key(&dk, "guess_column"), gc.span(), e.to_string()))?;
                Some(Arc::new(h))
            }
        };
        let (amount, is_force) = match (&ds.value, &ds.force) {
            (Some(v), None) => (Some(cx.finite(v, &key(&dk, "value"))?), false),
            (None, Some(f)) => (Some(cx.finite(f, &key(&dk, "force"))?), true),
            (None, None) => (None, false),
            (Some(_), Some(f)) => {
                return Err(cx.err(
                    key(&dk, "force"),
                    f.span(),
                    "give either `value` (prescribed) or `force`, not both",
                ))
            }
        };
        let history: Arc<dyn LoadHistory> = match (&ds.table, &ds.column) {
            (Some(t), Some(c)) => {
                if ds.history.is_some() {
                    return Err(cx.err(
                        &dk,
                        d.span(),
                        "give either `history` or `table` with `column`, not both",
                    ));
                }
                let (table, time_scale) = find_table(t)?;
                let mut factor = match &ds.scale {
                    Some(sc) => cx.finite(sc, &key(&dk, "scale"))?,
                    None => 1.0,
                };
                match ds.unit.as_ref().map(|u| (u.get_ref().as_str(), u.span())) {
                    None | Some(("rad", _)) => {}
                    Some(("deg", _)) if rotation => factor *= std::f64::consts::PI / 180.0,
                    Some((other, span)) => {
                        return Err(cx.err(
                            key(&dk, "unit"),
                            span,
                            format!(
                            "unit `{other}`: only angles take a unit, `rad` or `deg` (lengths: use `scale`)"
                        ),
                        ))
                    }
                }
                factor *= amount.unwrap_or(1.0);
                let h = table
                    .history(c.get_ref(), factor, *time_scale)
                    .map_err(|e| cx.err(key(&dk, "column"), c.span(), e.to_string()))?;
                Arc::new(h)
            }
            (Some(t), None) if guess.is_none() => {
                return Err(cx.err(key(&dk, "table"), t.span(), "a `table` needs its `column`"))
            }
            (None, Some(c)) => {
                return Err(cx.err(key(&dk, "column"), c.span(), "a `column` needs its `table`"))
            }
            (_, None) => {
                for (n, sp) in present.iter() {
                    if let (true, Some(sp)) = (matches!(*n, "scale" | "unit"), sp) {
                        return Err(cx.err(
                            key(&dk, n),
                            sp.clone(),
                            format!("`{n}` applies to a table column"),
                        ));
                    }
                }
                let Some(a) = amount else {
                    return Err(cx.err(
                        &dk,
                        d.span(),
                        "give `value` (prescribed), `force`, or `table` with `column`",
                    ));
                };
                // prescribed angles are given in degrees
                let a = if rotation && !is_force { a.to_radians() } else { a };
                let h = cx.history(ds.history.as_ref(), &key(&dk, "history"))?;
                Arc::new(synovia::time::history::FnHistory::new(move |t| a * h.value(t)))
            }
        };
        body = if is_force {
            match guess {
                Some(g) => body.force_with_guess(index, history, g),
                None => body.force(index, history),
            }
        } else {
            body.prescribe(index, history)
        }
        .map_err(|e| cx.err(&dk, d.span(), e.to_string()))?;
    }
    if let Some(shape) = &s.shape {
        shapes.insert(name.clone(), obstacle::<D>(cx, shape, &key(k, "shape"))?);
    }
    joint.add_rigid_body(body).map_err(|e| cx.err(key(k, "name"), s.name.span(), e.to_string()))?;
    Ok(())
}

/// Strain above which the unit check refuses a model (100 %).
pub const UNIT_CHECK_REFUSE: f64 = 1.0;
/// Strain above which the unit check warns (10 %: beyond linear elasticity).
pub const UNIT_CHECK_WARN: f64 = 0.1;

/// The unit labels of `[units]`, and the unit-mistake check
/// ([`synovia::units::characteristic_strain`]): a strain above 100 % is refused (at the key
/// `units`, or the file) unless `units.check = false`, one above 10 % is a warning.
fn units<const D: usize>(
    cx: &Cx<'_>,
    doc: &ScenarioDoc,
    joint: &JointModel<D>,
    analysis: &Analysis,
) -> R<Units> {
    let mut units = Units::default();
    let mut check = true;
    if let Some(u) = &doc.units {
        let s = u.get_ref();
        for (field, value, k) in [
            (&mut units.length, &s.length, "length"),
            (&mut units.force, &s.force, "force"),
            (&mut units.time, &s.time, "time"),
        ] {
            if let Some(v) = value {
                let t = v.get_ref().trim();
                if t.is_empty() || t.contains(',') || t.contains('[') || t.contains(']') {
                    return Err(cx.err(
                        format!("units.{k}"),
                        v.span(),
                        format!("a unit label must be non-empty without `,`, `[` or `]`, got `{t}`"),
                    ));
                }
                *field = t.to_string();
            }
        }
        if let Some(c) = &s.check {
            check = *c.get_ref();
        }
    }
    let times: Vec<f64> = match analysis {
        Analysis::Static { time } => vec![*time],
        Analysis::QuasiStatic { times } => times.clone(),
        Analysis::Dynamic { dt, steps } => (0..=*steps).map(|k| k as f64 * dt).collect(),
    };
    if let Some(e) = synovia::units::characteristic_strain(joint.model(), &times) {
        let what = e.describe(&units.length, &units.force, &units.pressure());
        let labels =
            format!("the outputs are labelled in {}, {} and {}", units.length, units.force, units.pressure());
        if e.strain > UNIT_CHECK_REFUSE && check {
            let (k, span) = match &doc.units {
                Some(u) => ("units".to_string(), u.span()),
                None => ("analysis".to_string(), doc.analysis.span()),
            };
            return Err(cx.err(
                k,
                span,
                format!(
                    "{what}, more than 100 %: are the meshes in metres and the loads and moduli in N and MPa (or the reverse)? Use one consistent set of units (mm, N, MPa or m, N, Pa; {labels}); to run anyway, set `check = false` in `[units]`"
                ),
            ));
        }
        if e.strain > UNIT_CHECK_WARN {
            cx.warnings.borrow_mut().push(format!(
                "{what}: beyond the small strains of linear elasticity; check the units ({labels})"
            ));
        }
    }
    Ok(units)
}
