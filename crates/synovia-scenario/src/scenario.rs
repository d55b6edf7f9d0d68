//! The TOML scenario format (see `docs/scenario.md`): its serde types, parsing, and errors that
//! name the key path and the line:column in the file.
//!
//! Parsing is done in two stages:
//!
//! 1. [`Scenario::parse`]: TOML syntax and the shape of the document (unknown keys, wrong
//!    types, missing required keys) through serde; errors carry toml's span.
//! 2. [`crate::build`]: the meaning (generator parameters, materials, part and body names,
//!    histories, analysis): every value that is checked is kept as a [`Spanned`] so the error
//!    points at it.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

/// A value with its byte range in the scenario file.
pub type Sp<T> = Spanned<T>;

/// An error in a scenario file: the file, the key path (e.g. `body[0].material.E`), the
/// position (1-based line and column) and the message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScenarioError {
    /// The scenario file as given.
    pub file: String,
    /// Dotted key path with array indices (0-based), e.g. `boundary[2].part`; empty for errors
    /// about the whole file.
    pub key: String,
    /// 1-based line (0 if unknown).
    pub line: usize,
    /// 1-based column in characters (0 if unknown).
    pub column: usize,
    /// What is wrong.
    pub message: String,
    /// The offending source line with a caret under the position, if known.
    pub snippet: Option<String>,
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if self.line > 0 {
            write!(f, ":{}:{}", self.line, self.column)?;
        }
        if self.key.is_empty() {
            write!(f, ": {}", self.message)?;
        } else {
            write!(f, ": `{}`: {}", self.key, self.message)?;
        }
        if let Some(s) = &self.snippet {
            write!(f, "\n{s}")?;
        }
        Ok(())
    }
}

impl std::error::Error for ScenarioError {}

/// The text of a scenario file and where it came from; turns byte ranges into positions.
#[derive(Debug, Clone)]
pub struct Source {
    /// The file as given (for messages).
    pub file: String,
    /// Its directory (relative paths in the scenario are resolved against it).
    pub dir: PathBuf,
    /// Its text.
    pub text: String,
}

impl Source {
    /// A source from text; `file` names it in messages and gives the base directory.
    pub fn new(file: impl AsRef<Path>, text: String) -> Self {
        let file = file.as_ref();
        let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
        Self { file: file.display().to_string(), dir, text }
    }

    /// 1-based `(line, column)` of byte `offset` (columns count characters).
    pub fn position(&self, offset: usize) -> (usize, usize) {
        let offset = floor_char_boundary(&self.text, offset.min(self.text.len()));
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = self.text[line_start..offset].chars().count() + 1;
        (line, column)
    }

    /// The error `message` about `key` at the byte range `span`.
    pub fn error(
        &self,
        key: impl Into<String>,
        span: Option<Range<usize>>,
        message: impl Into<String>,
    ) -> ScenarioError {
        let (line, column, snippet) = match span {
            Some(span) => {
                let (line, column) = self.position(span.start);
                let text = self.text.lines().nth(line - 1).unwrap_or("");
                let width =
                    self.text.get(span.clone()).map_or(1, |s| s.lines().next().unwrap_or("").chars().count());
                let caret = format!("{}{}", " ".repeat(column - 1), "^".repeat(width.clamp(1, 80)));
                let gutter = " ".repeat(line.to_string().len());
                (line, column, Some(format!("{gutter} |\n{line} | {text}\n{gutter} | {caret}")))
            }
            None => (0, 0, None),
        };
        ScenarioError {
            file: self.file.clone(),
            key: key.into(),
            line,
            column,
            message: message.into(),
            snippet,
        }
    }

    /// An error about the whole file (no position).
    pub fn file_error(&self, message: impl Into<String>) -> ScenarioError {
        self.error("", None, message)
    }

    /// The error for a toml deserialisation error, with the key path found from its span.
    fn toml_error(&self, e: &toml::de::Error) -> ScenarioError {
        let mut key = e.span().map(|s| key_path_at(&self.text, s.start)).unwrap_or_default();
        let message = e.message().trim_end().replace('\n', "; ");
        // a missing key is named by the path of its table plus its own name (a missing
        // top-level key: by its name alone; the error's span is then the whole document)
        if let Some(field) = message.strip_prefix("missing field `").and_then(|m| m.split('`').next()) {
            let top_level = e.span().is_none_or(|s| s.start == 0 && s.end >= self.text.trim_end().len());
            if top_level {
                key.clear();
            }
            if !key.is_empty() {
                key.push('.');
            }
            key.push_str(field);
        }
        self.error(key, e.span(), message)
    }

    /// `path` relative to the scenario's directory (absolute paths unchanged).
    pub fn resolve(&self, path: &str) -> PathBuf {
        let p = Path::new(path);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.dir.join(p)
        }
    }
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// The dotted key path (array indices in brackets) of the innermost key or value of `text`
/// whose span contains byte `offset`, e.g. `body[1].material.E` (empty if none does).
pub fn key_path_at(text: &str, offset: usize) -> String {
    use toml::de::{DeTable, DeValue};
    fn contains(span: &Range<usize>, offset: usize) -> bool {
        span.start <= offset && offset < span.end.max(span.start + 1)
    }
    // Tables opened by a header (`[solver]`, `[[body]]`) span only their header, not their
    // keys, so every child is searched, innermost first.
    fn in_value(v: &Spanned<DeValue<'_>>, offset: usize, path: &mut Vec<String>) -> bool {
        let found = match v.get_ref() {
            DeValue::Table(t) => in_table(t, offset, path),
            DeValue::Array(a) => {
                let mut hit = false;
                for (i, e) in a.iter().enumerate() {
                    path.push(format!("[{i}]"));
                    if in_value(e, offset, path) {
                        hit = true;
                        break;
                    }
                    path.pop();
                }
                hit
            }
            _ => false,
        };
        if found {
            return true;
        }
        contains(&v.span(), offset)
    }
    fn in_table(t: &DeTable<'_>, offset: usize, path: &mut Vec<String>) -> bool {
        for (k, v) in t.iter() {
            path.push(k.get_ref().to_string());
            if in_value(v, offset, path) || contains(&k.span(), offset) {
                return true;
            }
            path.pop();
        }
        false
    }
    let (table, _) = DeTable::parse_recoverable(text);
    let mut path = Vec::new();
    in_table(table.get_ref(), offset, &mut path);
    let mut out = String::new();
    for p in path {
        if !out.is_empty() && !p.starts_with('[') {
            out.push('.');
        }
        out.push_str(&p);
    }
    out
}

/// A parsed scenario: the source text and the document.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The file and its text.
    pub source: Source,
    /// The document.
    pub doc: ScenarioDoc,
}

impl Scenario {
    /// Reads and parses a scenario file.
    ///
    /// # Errors
    /// A [`ScenarioError`] if the file cannot be read or does not parse.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, ScenarioError> {
        let path = path.as_ref();
        let regular = std::fs::metadata(path).map(|m| m.is_file());
        let text = match regular {
            Ok(false) => Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file (a directory, device or pipe)",
            )),
            _ => std::fs::read_to_string(path),
        }
        .map_err(|e| ScenarioError {
            file: path.display().to_string(),
            key: String::new(),
            line: 0,
            column: 0,
            message: format!("cannot read the scenario file: {e}"),
            snippet: None,
        })?;
        Self::parse(Source::new(path, text))
    }

    /// Parses a scenario from its source.
    ///
    /// # Errors
    /// A [`ScenarioError`] with the key path and position of the first problem.
    pub fn parse(source: Source) -> Result<Self, ScenarioError> {
        let doc: ScenarioDoc = toml::from_str(&source.text).map_err(|e| source.toml_error(&e))?;
        Ok(Self { source, doc })
    }

    /// The scenario's name: `name`, or the file stem.
    pub fn name(&self) -> String {
        match &self.doc.name {
            Some(n) => n.get_ref().clone(),
            // the file stem, with characters unusable in output file names replaced by `_`
            None => Path::new(&self.source.file)
                .file_stem()
                .map(|s| {
                    s.to_string_lossy()
                        .chars()
                        .map(|c| if c.is_ascii_alphanumeric() || "_-.".contains(c) { c } else { '_' })
                        .collect::<String>()
                })
                .filter(|s| !s.is_empty() && !s.starts_with('.'))
                .unwrap_or_else(|| "scenario".to_string()),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The document
// ---------------------------------------------------------------------------------------------

/// The whole scenario file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioDoc {
    /// 2 or 3.
    pub dimension: Sp<i64>,
    /// Base name of the output files (default: the file stem).
    pub name: Option<Sp<String>>,
    /// Free text.
    pub title: Option<String>,
    /// The bodies (`[[body]]`).
    #[serde(default, rename = "body")]
    pub bodies: Vec<Sp<BodySpec>>,
    /// Boundary conditions (`[[boundary]]`).
    #[serde(default)]
    pub boundary: Vec<Sp<BoundarySpec>>,
    /// Bonded interfaces (`[[tie]]`).
    #[serde(default, rename = "tie")]
    pub ties: Vec<Sp<TieSpec>>,
    /// Contact pairs (`[[contact]]`).
    #[serde(default)]
    pub contact: Vec<Sp<ContactSpec>>,
    /// Data tables (`[[table]]`: kinematics or load histories from CSV / OpenSim `.sto` files).
    #[serde(default, rename = "table")]
    pub tables: Vec<Sp<TableSpec>>,
    /// Rigid bodies with mixed control (`[[rigid_body]]`).
    #[serde(default, rename = "rigid_body")]
    pub rigid_bodies: Vec<Sp<RigidBodySpec>>,
    /// The contact solver.
    pub solver: Option<Sp<SolverSpec>>,
    /// The Newton iteration of nonlinear models (`[newton]`: a nonlinear material or finite
    /// strain in some body).
    pub newton: Option<Sp<NewtonSpec>>,
    /// The force-control iteration of rigid bodies (`[force_control]`: a force-controlled
    /// degree of freedom in some rigid body).
    pub force_control: Option<Sp<ForceControlSpec>>,
    /// The analysis.
    pub analysis: Sp<AnalysisSpec>,
    /// Output options.
    pub output: Option<Sp<OutputSpec>>,
    /// The model's units (`[units]`): labels of the outputs and the unit-mistake check.
    pub units: Option<Sp<UnitsSpec>>,
    /// A parameter study (`[sweep]`, [`crate::sweep`]); ignored by a plain build.
    pub sweep: Option<crate::sweep::SweepSpec>,
}

/// `[units]`: the units the model's numbers are in. They only label the outputs (synovia
/// computes in any consistent units) — except `check`, the unit-mistake check.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnitsSpec {
    /// Length unit of the meshes (default `mm`).
    pub length: Option<Sp<String>>,
    /// Force unit of the loads (default `N`).
    pub force: Option<Sp<String>>,
    /// Time unit (default `s`).
    pub time: Option<Sp<String>>,
    /// Refuse a model whose loads or prescribed displacements would strain a body by more
    /// than 100 % (a unit mistake; default `true`).
    pub check: Option<Sp<bool>>,
}

/// One body: mesh, material, optional dynamic data, body force and extra boundary parts.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name.
    pub name: Sp<String>,
    /// The mesh.
    pub mesh: Sp<MeshSpec>,
    /// The material.
    pub material: Sp<MaterialSpec>,
    /// Density for dynamic runs of elastic bodies.
    pub density: Option<Sp<f64>>,
    /// Uniform initial velocity (dynamic runs).
    pub initial_velocity: Option<Sp<Vec<f64>>>,
    /// Body force `h(t) value` per unit volume.
    pub body_force: Option<Sp<LoadSpec>>,
    /// Strain kinematics: `small` (default) or `finite` (total Lagrangian; docs/model.md §2.3).
    pub kinematics: Option<Sp<String>>,
    /// Extra boundary parts selected geometrically (`[[body.part]]`).
    #[serde(default, rename = "part")]
    pub parts: Vec<Sp<PartSpec>>,
}

/// A mesh: a generator with its parameters, or a Gmsh file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct MeshSpec {
    /// Generator name (`rectangle`, `box`, `disc`, `half_disc`, `ball`, `hemisphere`,
    /// `layered_arc`, `layered_cap`).
    pub generator: Option<Sp<String>>,
    /// A Gmsh `.msh` file, relative to the scenario file.
    pub gmsh: Option<Sp<String>>,
    /// The physical group of the Gmsh file that is this body (default: the body's name).
    pub group: Option<Sp<String>>,
    pub x: Option<Sp<Vec<f64>>>,
    pub y: Option<Sp<Vec<f64>>>,
    pub lo: Option<Sp<Vec<f64>>>,
    pub hi: Option<Sp<Vec<f64>>>,
    pub cells: Option<Sp<Vec<usize>>>,
    pub grading: Option<Sp<Vec<Sp<GradingSpec>>>>,
    pub center: Option<Sp<Vec<f64>>>,
    pub radius: Option<Sp<f64>>,
    pub n: Option<Sp<usize>>,
    pub refine: Option<Sp<RefineSpec>>,
    pub radii: Option<Sp<Vec<f64>>>,
    pub angles_deg: Option<Sp<Vec<f64>>>,
    pub half_angle_deg: Option<Sp<f64>>,
    pub n_angle: Option<Sp<usize>>,
    pub n_surface: Option<Sp<usize>>,
    pub n_radial: Option<Sp<Vec<usize>>>,
    pub layer: Option<Sp<usize>>,
    /// Mirror the mesh in the plane `axis = at`.
    pub reflect: Option<Sp<ReflectSpec>>,
    /// Translate the mesh (after reflecting).
    pub translate: Option<Sp<Vec<f64>>>,
}

/// Node distribution along one axis of `rectangle` / `box`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct GradingSpec {
    #[serde(rename = "type")]
    pub kind: Sp<String>,
    pub ratio: Option<Sp<f64>>,
    pub center: Option<Sp<f64>>,
    pub width: Option<Sp<f64>>,
}

/// Local refinement of `half_disc` / `hemisphere` toward a ball.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct RefineSpec {
    pub center: Sp<Vec<f64>>,
    pub radius: Sp<f64>,
    pub levels: Sp<usize>,
}

/// Mirror in the plane `x_axis = at`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ReflectSpec {
    pub axis: Sp<String>,
    #[serde(default)]
    pub at: f64,
}

/// A material (flat table; `type` says which keys apply).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct MaterialSpec {
    /// `isotropic`, `transversely_isotropic`, `anisotropic`, `kelvin_voigt`, `neo_hookean`,
    /// `mooney_rivlin`.
    #[serde(rename = "type")]
    pub kind: Sp<String>,
    #[serde(rename = "E")]
    pub e: Option<Sp<f64>>,
    pub nu: Option<Sp<f64>>,
    /// 2D reduction: `strain` (default) or `stress`.
    pub plane: Option<Sp<String>>,
    #[serde(rename = "E_p")]
    pub e_p: Option<Sp<f64>>,
    pub nu_p: Option<Sp<f64>>,
    #[serde(rename = "E_a")]
    pub e_a: Option<Sp<f64>>,
    pub nu_ap: Option<Sp<f64>>,
    #[serde(rename = "G_a")]
    pub g_a: Option<Sp<f64>>,
    pub axis: Option<Sp<Vec<f64>>>,
    #[serde(rename = "C")]
    pub c: Option<Sp<Vec<Vec<f64>>>>,
    pub elastic: Option<Sp<Box<MaterialSpec>>>,
    pub viscous: Option<Sp<Box<MaterialSpec>>>,
    pub density: Option<Sp<f64>>,
    pub damping: Option<Sp<f64>>,
    /// Mooney–Rivlin `c₁`, `c₂` and the volumetric `λ`.
    pub c1: Option<Sp<f64>>,
    pub c2: Option<Sp<f64>>,
    pub lambda: Option<Sp<f64>>,
}

/// A boundary part selected geometrically among the boundary facets (or among the facets of
/// the part `from`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct PartSpec {
    pub name: Sp<String>,
    pub from: Option<Sp<String>>,
    pub x: Option<Sp<Vec<f64>>>,
    pub y: Option<Sp<Vec<f64>>>,
    pub z: Option<Sp<Vec<f64>>>,
    pub normal: Option<Sp<Vec<f64>>>,
    pub max_angle_deg: Option<Sp<f64>>,
    pub within: Option<Sp<BallSpec>>,
}

/// A ball `|x − center| ≤ radius`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct BallSpec {
    pub center: Sp<Vec<f64>>,
    pub radius: Sp<f64>,
}

/// A vector load scaled by a history.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct LoadSpec {
    pub value: Sp<Vec<f64>>,
    pub history: Option<Sp<HistorySpec>>,
}

/// A boundary condition on a part of a body.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct BoundarySpec {
    pub body: Sp<String>,
    pub part: Sp<String>,
    /// `clamped`, `symmetry`, `prescribed`, `rigid_motion`, `traction`, `pressure`,
    /// `traction_free`.
    pub kind: Sp<String>,
    pub value: Option<Sp<NumOrVec>>,
    pub components: Option<Sp<Vec<Sp<String>>>>,
    pub history: Option<Sp<HistorySpec>>,
    pub translation: Option<Sp<Vec<f64>>>,
    pub rotation_deg: Option<Sp<f64>>,
    pub center: Option<Sp<Vec<f64>>>,
    pub axis: Option<Sp<Vec<f64>>>,
    pub rotation_history: Option<Sp<HistorySpec>>,
    /// `kind = "rigid_body"`: the rigid body the part is tied to.
    pub rigid_body: Option<Sp<String>>,
}

/// A bonded interface.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct TieSpec {
    pub body_a: Sp<String>,
    pub part_a: Sp<String>,
    pub body_b: Sp<String>,
    pub part_b: Sp<String>,
}

/// A contact pair: a part of a body against a part of another body or a rigid obstacle.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ContactSpec {
    pub name: Option<Sp<String>>,
    pub body: Sp<String>,
    pub part: Sp<String>,
    pub partner: Option<Sp<PartnerSpec>>,
    /// Body-body pairs: `node_to_node` (default), `node_to_segment` (2D; `node_to_facet` in
    /// 3D, either name works) or `mortar`.
    pub discretisation: Option<Sp<String>>,
    /// Body-body non-matching pairs: the largest slave-to-master distance searched.
    pub search_distance: Option<Sp<f64>>,
    pub obstacle: Option<Sp<ObstacleSpec>>,
    /// The shape of this rigid body (`[[rigid_body]]`) is the partner.
    pub rigid_body: Option<Sp<String>>,
    pub friction: Option<Sp<f64>>,
    pub friction_law: Option<Sp<FrictionLawSpec>>,
    pub normal: Option<Sp<Vec<f64>>>,
    pub tolerance: Option<Sp<f64>>,
    pub refuse_initial_penetration: Option<Sp<bool>>,
    /// Reporting only: split the pair's figures by a plane into two sides.
    pub split: Option<Sp<SplitSpec>>,
}

/// `split = { point = [..], normal = [..], positive = "lateral", negative = "medial" }`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct SplitSpec {
    pub point: Sp<Vec<f64>>,
    pub normal: Sp<Vec<f64>>,
    pub positive: Sp<String>,
    pub negative: Sp<String>,
}

/// The other body of a node-to-node pair.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct PartnerSpec {
    pub body: Sp<String>,
    pub part: Sp<String>,
}

/// A rigid obstacle.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ObstacleSpec {
    /// `plane`, `sphere` (circle in 2D), `cylinder` (3D), `stl` (3D, a triangle surface).
    #[serde(rename = "type")]
    pub kind: Sp<String>,
    /// `stl`: the file (relative to the scenario).
    pub file: Option<Sp<String>>,
    /// `stl`: factor from the file's length unit to the model's (e.g. 1000 for metres → mm).
    pub scale: Option<Sp<f64>>,
    /// `stl`: `true` (default) requires a closed, manifold surface (inside = negative
    /// distance); `false` accepts an open patch (distance signed by the facet normals).
    pub solid: Option<Sp<bool>>,
    /// `stl`: levels of Loop subdivision (0–4, default 0) that smooth a faceted surface
    /// (`TriangleSurface::loop_subdivided`, docs/scenario.md).
    pub subdivide: Option<Sp<i64>>,
    /// `stl` with `subdivide`: edges whose facets meet at more than this angle (degrees,
    /// default 30) stay sharp.
    pub crease_angle_deg: Option<Sp<f64>>,
    /// `stl`: radius (model length unit) of the cylindrical fillets that round the surface's
    /// concave edges (`SurfaceObstacle::with_concave_fillet`; default 0: none).
    pub fillet: Option<Sp<f64>>,
    /// `stl` with `fillet`: the largest offset of a fillet from the faceted surface (the
    /// radius of a sharper edge is cut to it; default: no bound).
    pub fillet_max_offset: Option<Sp<f64>>,
    pub point: Option<Sp<Vec<f64>>>,
    pub normal: Option<Sp<Vec<f64>>>,
    pub center: Option<Sp<Vec<f64>>>,
    pub radius: Option<Sp<f64>>,
    pub axis: Option<Sp<Vec<f64>>>,
    pub cavity: Option<Sp<bool>>,
}

/// `[newton]`: the Newton iteration of nonlinear models (`synovia::nonlinear::NewtonParams`;
/// every key optional, the defaults those of `NewtonParams::default()`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonSpec {
    /// Relative equilibrium residual to reach (default 1e-10).
    pub tolerance: Option<Sp<f64>>,
    /// Newton iterations per level (default 30).
    pub max_iterations: Option<Sp<usize>>,
    /// Backtracking line search (default true).
    pub line_search: Option<Sp<bool>>,
    /// Halvings of a level after a failure (default 8).
    pub max_cutbacks: Option<Sp<usize>>,
    /// Modified Newton: keep the factorised tangent while full steps reduce the residual by
    /// this factor, in (0, 1) (default: a fresh tangent at every iteration).
    pub tangent_reuse: Option<Sp<f64>>,
    /// Finite strain: when the contact geometry is rebuilt on the deformed configuration:
    /// `converged` (default), `per_level`, `reference`.
    pub geometry: Option<Sp<String>>,
    /// Finite strain: change of the solution below which a rebuild counts as settled
    /// (default 1e-8).
    pub geometry_tolerance: Option<Sp<f64>>,
    /// Finite strain: rebuilds per level (default 20).
    pub max_geometry_passes: Option<Sp<usize>>,
    /// Finite strain: relaxation ω in (0, 1] of the rebuilds (default 0.5).
    pub geometry_relaxation: Option<Sp<f64>>,
    /// Finite strain: Aitken's dynamic relaxation of the rebuilds (default false).
    pub geometry_aitken: Option<Sp<bool>>,
    /// Finite strain: the relative residual at which a pass ends while its geometry still
    /// moves (default: each pass converges to `tolerance`).
    pub geometry_pass_tolerance: Option<Sp<f64>>,
    /// Finite strain: once the geometry has settled, a full step of at most this relative
    /// size ends the iteration (default: only `tolerance` ends it).
    pub settled_increment: Option<Sp<f64>>,
    /// The contact's active sets against the Newton iteration: `nested` (default),
    /// `combined`, `outer`.
    pub active_sets: Option<Sp<String>>,
}

/// `[force_control]`: the iteration that finds the force-controlled coordinates of rigid
/// bodies (`synovia::rigid::ForceControlParams`; every key optional, the defaults those of
/// `ForceControlParams::default()`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceControlSpec {
    /// Relative balance `|Q_k + F_k| ≤ tolerance × scale` (default 1e-10).
    pub tolerance: Option<Sp<f64>>,
    /// Contact solves per level (default 60).
    pub max_solves: Option<Sp<usize>>,
    /// Motion from the pose the geometry was built at, relative to the model size, before it
    /// is rebuilt (default 1e-6).
    pub geometry_tolerance: Option<Sp<f64>>,
    /// The coordinates solved inside the contact solve (default true; false: the search over
    /// trial solves).
    pub bordered: Option<Sp<bool>>,
    /// Several coordinates, search over trial solves: a fresh finite-difference Jacobian at
    /// every accepted iterate (default false: Broyden updates).
    pub fresh_jacobian: Option<Sp<bool>>,
}

/// The exponential static-to-kinetic friction law (dynamic runs).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct FrictionLawSpec {
    #[serde(rename = "static")]
    pub static_coefficient: Sp<f64>,
    #[serde(rename = "kinetic")]
    pub kinetic_coefficient: Sp<f64>,
    #[serde(rename = "speed")]
    pub characteristic_speed: Sp<f64>,
}

/// The contact solver and its parameters.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct SolverSpec {
    pub name: Option<Sp<String>>,
    pub tolerance: Option<Sp<f64>>,
    pub max_iterations: Option<Sp<usize>>,
    pub rho_scale: Option<Sp<f64>>,
    pub nested_iteration: Option<Sp<usize>>,
    pub ordering: Option<Sp<String>>,
    pub load_degree: Option<Sp<usize>>,
    pub memory_limit_mb: Option<Sp<f64>>,
    /// Largest number of contact dofs ordered last as a dense interface block (default 8000;
    /// 0: none, whole-factor solves of the active rows).
    pub interface_block_dofs: Option<Sp<usize>>,
    /// Gap screening of whole-factor solves (length): each solve runs on the contact rows with
    /// gap at most this and adds the others that come into contact (exact).
    pub screening_band: Option<Sp<f64>>,
    /// `tfeti`: number of parts the model is cut into (default 8).
    pub subdomains: Option<Sp<usize>>,
    /// `tfeti`: `metis` (default) or `bisection`.
    pub partitioner: Option<Sp<String>>,
    /// `tfeti`: `dirichlet` (default), `lumped` or `none`.
    pub preconditioner: Option<Sp<String>>,
    /// `tfeti`: the penalty `ρ` of SMALBE as a multiple of `‖PFP‖` (default 1).
    pub rho: Option<Sp<f64>>,
    /// `tfeti`: how the coarse condition `Gλ = e` is met: `penalty` (SMALBE, default) or
    /// `projector` (the oblique projector along the equality rows, one bound-constrained run).
    pub coarse: Option<Sp<String>>,
    /// `tfeti`: the expansion step of MPRGP/MPGP: `fixed` (default), `projected_cg` or
    /// `preconditioned`.
    pub expansion: Option<Sp<String>>,
}

/// The analysis (flat table; `type` says which keys apply).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct AnalysisSpec {
    /// `static`, `quasistatic`, `dynamic`.
    #[serde(rename = "type")]
    pub kind: Sp<String>,
    pub time: Option<Sp<f64>>,
    pub times: Option<Sp<TimesSpec>>,
    pub coulomb_fixed_point: Option<Sp<bool>>,
    pub max_fixed_point: Option<Sp<usize>>,
    pub fixed_point_tolerance: Option<Sp<f64>>,
    pub incremental_slip: Option<Sp<bool>>,
    pub initial_friction: Option<Sp<bool>>,
    pub dt: Option<Sp<f64>>,
    pub steps: Option<Sp<usize>>,
    pub t0: Option<Sp<f64>>,
    pub mass: Option<Sp<String>>,
    pub coulomb_iterations: Option<Sp<usize>>,
    pub coulomb_tolerance: Option<Sp<f64>>,
}

/// Output options.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct OutputSpec {
    pub dir: Option<Sp<String>>,
    pub vtu_every: Option<Sp<usize>>,
    pub encoding: Option<Sp<String>>,
    pub stress: Option<Sp<bool>>,
}

// ---------------------------------------------------------------------------------------------
// Values with several forms
// ---------------------------------------------------------------------------------------------

/// A number or an array of numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum NumOrVec {
    /// A number.
    Num(f64),
    /// An array of numbers.
    Vec(Vec<f64>),
}

impl<'de> Deserialize<'de> for NumOrVec {
    fn deserialize<De: Deserializer<'de>>(d: De) -> Result<Self, De::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = NumOrVec;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number or an array of numbers")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<NumOrVec, E> {
                Ok(NumOrVec::Num(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<NumOrVec, E> {
                Ok(NumOrVec::Num(v as f64))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<NumOrVec, E> {
                Ok(NumOrVec::Num(v))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<NumOrVec, A::Error> {
                let mut out = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    out.push(x);
                }
                Ok(NumOrVec::Vec(out))
            }
        }
        d.deserialize_any(V)
    }
}

/// A load history `h(t)`: a constant, a table `[[t, v], …]` (linear interpolation, constant
/// extrapolation), or `{ table = [[t, v], …], period = T }` (the table repeated with period
/// `T`).
#[derive(Debug, Clone, PartialEq)]
pub enum HistorySpec {
    /// `h(t) = c`.
    Constant(f64),
    /// A table, each row spanned.
    Table {
        /// The rows `[t, v]`.
        rows: Vec<Sp<Vec<f64>>>,
        /// Period, if periodic.
        period: Option<Sp<f64>>,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HistoryTable {
    table: Vec<Sp<Vec<f64>>>,
    period: Option<Sp<f64>>,
}

impl<'de> Deserialize<'de> for HistorySpec {
    fn deserialize<De: Deserializer<'de>>(d: De) -> Result<Self, De::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = HistorySpec;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number, a table [[t, v], ...] or { table = [[t, v], ...], period = T }")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<HistorySpec, E> {
                Ok(HistorySpec::Constant(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<HistorySpec, E> {
                Ok(HistorySpec::Constant(v as f64))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<HistorySpec, E> {
                Ok(HistorySpec::Constant(v))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<HistorySpec, A::Error> {
                let mut rows = Vec::new();
                while let Some(row) = seq.next_element::<Sp<Vec<f64>>>()? {
                    rows.push(row);
                }
                Ok(HistorySpec::Table { rows, period: None })
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<HistorySpec, A::Error> {
                let t = HistoryTable::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(HistorySpec::Table { rows: t.table, period: t.period })
            }
        }
        d.deserialize_any(V)
    }
}

/// The time levels of a quasi-static analysis: a list, or `{ start, end, steps }` (`steps + 1`
/// equally spaced levels).
#[derive(Debug, Clone, PartialEq)]
pub enum TimesSpec {
    /// Explicit levels.
    List(Vec<f64>),
    /// `steps + 1` levels from `start` to `end`.
    Range {
        /// First level.
        start: f64,
        /// Last level.
        end: f64,
        /// Number of intervals.
        steps: usize,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TimesRange {
    start: f64,
    end: f64,
    steps: usize,
}

impl<'de> Deserialize<'de> for TimesSpec {
    fn deserialize<De: Deserializer<'de>>(d: De) -> Result<Self, De::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = TimesSpec;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("an array of times or { start = t0, end = t1, steps = n }")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<TimesSpec, A::Error> {
                let mut out = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    out.push(x);
                }
                Ok(TimesSpec::List(out))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<TimesSpec, A::Error> {
                let r = TimesRange::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(TimesSpec::Range { start: r.start, end: r.end, steps: r.steps })
            }
        }
        d.deserialize_any(V)
    }
}

/// A data table (`[[table]]`): columns of a CSV or OpenSim `.sto`/`.mot` file, used by rigid
/// body degrees of freedom.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableSpec {
    /// The name the degrees of freedom refer to.
    pub name: Sp<String>,
    /// The file (relative to the scenario).
    pub file: Sp<String>,
    /// Factor from the table's time to the scenario's (e.g. 0.01: percent of a cycle → cycles).
    pub time_scale: Option<Sp<f64>>,
}

/// A rigid body with mixed control (`[[rigid_body]]`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidBodySpec {
    /// Name.
    pub name: Sp<String>,
    /// Reference point `c` (default the origin).
    pub center: Option<Sp<Vec<f64>>>,
    /// 3D rotation order, a permutation of `xyz` (default `"zxy"`: `R = R_z R_x R_y`).
    pub rotation_order: Option<Sp<String>>,
    /// Its contact shape in its own frame (same keys as a contact `obstacle`, plus `stl`).
    pub shape: Option<Sp<ObstacleSpec>>,
    /// Degrees of freedom (absent: prescribed zero).
    pub tx: Option<Sp<DofSpec>>,
    #[allow(missing_docs)]
    pub ty: Option<Sp<DofSpec>>,
    #[allow(missing_docs)]
    pub tz: Option<Sp<DofSpec>>,
    #[allow(missing_docs)]
    pub rx: Option<Sp<DofSpec>>,
    #[allow(missing_docs)]
    pub ry: Option<Sp<DofSpec>>,
    #[allow(missing_docs)]
    pub rz: Option<Sp<DofSpec>>,
}

/// The control of one rigid degree of freedom: prescribed (`value`, or a table column) or
/// force-controlled (`force`), each times `history` or a table column.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DofSpec {
    /// Prescribed coordinate (length unit; angles in degrees for `rx`, `ry`, `rz`).
    pub value: Option<Sp<f64>>,
    /// Applied generalised force (force unit; moment for rotations).
    pub force: Option<Sp<f64>>,
    /// History multiplying `value` / `force` (default 1).
    pub history: Option<Sp<HistorySpec>>,
    /// A `[[table]]` name: the coordinate (or the force) is a column of it.
    pub table: Option<Sp<String>>,
    /// The column of `table`.
    pub column: Option<Sp<String>>,
    /// Factor applied to the column (unit conversion; e.g. 1000 for metres → mm).
    pub scale: Option<Sp<f64>>,
    /// Unit of an angle column: `"rad"` (default) or `"deg"`.
    pub unit: Option<Sp<String>>,
    /// Force control: a column of `table` that predicts the coordinate (e.g. the measured
    /// translation), times `guess_scale`.
    pub guess_column: Option<Sp<String>>,
    /// Factor of `guess_column` (default 1).
    pub guess_scale: Option<Sp<f64>>,
}
