//! `synovia.Model`: a joint model in 2D or 3D from NumPy arrays or a scenario file, and
//! `synovia.Material`.

use std::any::Any;
use std::sync::Arc;

use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use synovia::builder::{Analysis, BodyMaterial, JointModel};
use synovia::contact_ops::obstacle::SignedDistance;
use synovia::contact_ops::operators::{ContactPair, CylinderObstacle, PlaneObstacle, SphereObstacle};
use synovia::fem::{BodyId, ComponentMask};
use synovia::material::{anisotropic, isotropic, plane_strain, plane_stress, Material, VoigtMatrix};
use synovia::mesh::math::{Point, Vector};
use synovia::mesh::{BoundaryKind, Mesh};
use synovia::prelude::LoadHistory;
use synovia_scenario::{build::build, Scenario};

use crate::error::{err, msg, set_callback_error, solved, take_callback_error};
use crate::history::history;
use crate::result::{Collector, PyRunResult, RunData};
use crate::rigid::{self, PoseInputs, PoseSlot, PyShape, RigidSpec};
use crate::session::PySession;

// The model is shared with the thread of a `Session` and runs release the GIL: it must be
// `Send + Sync`.
const _: fn() = || {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<JointModel<2>>();
    send_sync::<JointModel<3>>();
};

/// The material of a body (`synovia.Material`), made by its static constructors and turned
/// into the model's material when a body is added.
#[pyclass(name = "Material", module = "synovia", frozen)]
#[derive(Debug, Clone)]
pub struct PyMaterial {
    kind: MatKind,
}

#[derive(Debug, Clone)]
enum MatKind {
    Isotropic { e: f64, nu: f64 },
    PlaneStrain { e: f64, nu: f64 },
    PlaneStress { e: f64, nu: f64 },
    Anisotropic { c: Vec<f64>, n: usize },
    NeoHookean { e: f64, nu: f64 },
    MooneyRivlin { c1: f64, c2: f64, lambda: f64 },
}

#[pymethods]
impl PyMaterial {
    /// Isotropic linear elasticity with Young's modulus `E` and Poisson's ratio `nu`: 3D, or
    /// plane strain on a 2D body.
    #[staticmethod]
    #[allow(non_snake_case)]
    fn isotropic(E: f64, nu: f64) -> Self {
        Self { kind: MatKind::Isotropic { e: E, nu } }
    }
    /// Isotropic, plane strain (2D bodies only).
    #[staticmethod]
    #[allow(non_snake_case)]
    fn plane_strain(E: f64, nu: f64) -> Self {
        Self { kind: MatKind::PlaneStrain { e: E, nu } }
    }
    /// Isotropic, plane stress (2D bodies only).
    #[staticmethod]
    #[allow(non_snake_case)]
    fn plane_stress(E: f64, nu: f64) -> Self {
        Self { kind: MatKind::PlaneStress { e: E, nu } }
    }
    /// General anisotropic elasticity from the Voigt stiffness matrix `C` (3 × 3 in 2D,
    /// 6 × 6 in 3D; engineering shear strains; symmetric positive definite).
    #[staticmethod]
    #[allow(non_snake_case)]
    fn anisotropic(C: PyReadonlyArray2<'_, f64>) -> PyResult<Self> {
        let a = C.as_array();
        if a.nrows() != a.ncols() {
            return Err(msg(format!("the stiffness matrix must be square, got {}×{}", a.nrows(), a.ncols())));
        }
        Ok(Self { kind: MatKind::Anisotropic { c: a.iter().copied().collect(), n: a.nrows() } })
    }
    /// Compressible neo-Hookean hyperelasticity `W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²` with the
    /// small-strain constants `E`, `nu` (plane strain on a 2D body). Run it in finite strain with
    /// `Model.set_kinematics(body, "finite")` (docs/nonlinear.md).
    #[staticmethod]
    #[allow(non_snake_case)]
    fn neo_hookean(E: f64, nu: f64) -> Self {
        Self { kind: MatKind::NeoHookean { e: E, nu } }
    }
    /// Compressible Mooney–Rivlin hyperelasticity
    /// `W = c₁(I₁ − 3) + c₂(I₂ − 3) − 2(c₁ + 2c₂) ln J + λ/2 (ln J)²`.
    #[staticmethod]
    fn mooney_rivlin(c1: f64, c2: f64, lam: f64) -> Self {
        Self { kind: MatKind::MooneyRivlin { c1, c2, lambda: lam } }
    }
    fn __repr__(&self) -> String {
        format!("Material({:?})", self.kind)
    }
}

fn downcast<U: 'static>(b: Box<dyn Any>, what: &str) -> PyResult<U> {
    b.downcast::<U>().map(|b| *b).map_err(|_| msg(what.to_string()))
}

fn material_for<const D: usize>(m: &PyMaterial) -> PyResult<BodyMaterial<D>> {
    let any: Box<dyn Any> = match (&m.kind, D) {
        (MatKind::Isotropic { e, nu }, 3) => {
            Box::new(BodyMaterial::<3>::from(isotropic(*e, *nu).map_err(err)?))
        }
        (MatKind::Isotropic { e, nu } | MatKind::PlaneStrain { e, nu }, 2) => {
            Box::new(BodyMaterial::<2>::from(plane_strain(*e, *nu).map_err(err)?))
        }
        (MatKind::PlaneStress { e, nu }, 2) => {
            Box::new(BodyMaterial::<2>::from(plane_stress(*e, *nu).map_err(err)?))
        }
        (MatKind::Anisotropic { c, n }, _) => {
            let c = VoigtMatrix::from_row_slice(*n, *n, c);
            return Ok(BodyMaterial::<D>::from(anisotropic::<D>(c).map_err(err)?));
        }
        (MatKind::NeoHookean { e, nu }, _) => {
            let law: Arc<dyn Material<D>> = Arc::new(synovia::material::neo_hookean(*e, *nu).map_err(err)?);
            return Ok(BodyMaterial::<D>::from(law));
        }
        (MatKind::MooneyRivlin { c1, c2, lambda }, _) => {
            let law: Arc<dyn Material<D>> =
                Arc::new(synovia::material::mooney_rivlin(*c1, *c2, *lambda).map_err(err)?);
            return Ok(BodyMaterial::<D>::from(law));
        }
        _ => return Err(msg("plane strain and plane stress materials are for 2D bodies only")),
    };
    downcast::<BodyMaterial<D>>(any, "material of another dimension")
}

/// The joint model of either dimension, shared with open sessions.
#[derive(Debug, Clone)]
pub(crate) enum Joint {
    D2(Arc<JointModel<2>>),
    D3(Arc<JointModel<3>>),
}

macro_rules! with_joint {
    ($self:expr, $j:ident => $body:expr) => {
        match &$self.joint {
            Joint::D2($j) => $body,
            Joint::D3($j) => $body,
        }
    };
}

macro_rules! with_joint_mut {
    ($self:expr, $j:ident => $body:expr) => {
        match &mut $self.joint {
            Joint::D2(a) => {
                let $j = get_mut(a)?;
                $body
            }
            Joint::D3(a) => {
                let $j = get_mut(a)?;
                $body
            }
        }
    };
}

fn get_mut<const D: usize>(a: &mut Arc<JointModel<D>>) -> PyResult<&mut JointModel<D>> {
    Arc::get_mut(a).ok_or_else(|| {
        msg("the model is in use by an open Session: close it (Session.close()) before changing the model")
    })
}

pub(crate) fn vector<const D: usize>(v: &[f64], what: &str) -> PyResult<Vector<D>> {
    if v.len() != D {
        return Err(msg(format!("{what} must have {D} components, got {}", v.len())));
    }
    Ok(Vector::<D>::from_fn(|i, _| v[i]))
}

pub(crate) fn point<const D: usize>(v: &[f64], what: &str) -> PyResult<Point<D>> {
    Ok(Point::from(vector::<D>(v, what)?))
}

fn mask(components: Option<Vec<usize>>, d: usize) -> PyResult<ComponentMask> {
    match components {
        None => Ok(ComponentMask::ALL),
        Some(c) => {
            let mut m = [false; 3];
            for k in c {
                if k >= d {
                    return Err(msg(format!("component {k} out of range for dimension {d}")));
                }
                m[k] = true;
            }
            Ok(ComponentMask(m))
        }
    }
}

pub(crate) fn body_id<const D: usize>(j: &JointModel<D>, body: &Bound<'_, PyAny>) -> PyResult<BodyId> {
    if let Ok(i) = body.extract::<usize>() {
        j.model().body(BodyId(i)).map_err(err)?;
        return Ok(BodyId(i));
    }
    let name: String = body.extract().map_err(|_| msg("a body is given by its index (int) or name (str)"))?;
    j.model().body_id(&name).map_err(err)
}

pub(crate) fn index_array(obj: &Bound<'_, PyAny>, cols: usize, what: &str) -> PyResult<Vec<Vec<usize>>> {
    let np = obj.py().import_bound("numpy")?;
    let arr = np.call_method1("asarray", (obj,))?;
    let arr = arr.call_method1("astype", ("int64",))?;
    let a: PyReadonlyArray2<i64> =
        arr.extract().map_err(|_| msg(format!("{what} must be a 2-D integer array with {cols} columns")))?;
    if a.shape()[1] != cols {
        return Err(msg(format!("{what} must have {cols} columns, got {}", a.shape()[1])));
    }
    let a = a.as_array();
    let mut out = Vec::with_capacity(a.nrows());
    for (r, row) in a.rows().into_iter().enumerate() {
        let mut v = Vec::with_capacity(cols);
        for &x in row {
            if x < 0 {
                return Err(msg(format!("{what}: negative node index {x} in row {r}")));
            }
            v.push(x as usize);
        }
        out.push(v);
    }
    Ok(out)
}

pub(crate) fn float_array(obj: &Bound<'_, PyAny>, cols: usize, what: &str) -> PyResult<Vec<Vec<f64>>> {
    let np = obj.py().import_bound("numpy")?;
    let arr = np.call_method1("asarray", (obj, "float64"))?;
    let a: PyReadonlyArray2<f64> =
        arr.extract().map_err(|_| msg(format!("{what} must be a 2-D float array with {cols} columns")))?;
    if a.shape()[1] != cols {
        return Err(msg(format!("{what} must have {cols} columns, got {}", a.shape()[1])));
    }
    Ok(a.as_array().rows().into_iter().map(|r| r.to_vec()).collect())
}

/// The values of a Python vector-like (`D` floats).
pub(crate) fn floats(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(vec![v]);
    }
    let np = obj.py().import_bound("numpy")?;
    let arr = np.call_method1("asarray", (obj, "float64"))?.call_method0("ravel")?;
    arr.call_method0("tolist")?
        .extract::<Vec<f64>>()
        .map_err(|_| msg(format!("{what} must be a sequence of floats")))
}

/// A Python callable `f(x, t) -> D floats` as a displacement field.
fn py_field<const D: usize>(f: Py<PyAny>) -> impl Fn(&Point<D>, f64) -> Vector<D> + Send + Sync + 'static {
    move |x: &Point<D>, t: f64| {
        Python::with_gil(|py| {
            let call = || -> PyResult<Vector<D>> {
                let xs = numpy::PyArray1::from_vec_bound(py, x.iter().copied().collect());
                let v = f.call1(py, (xs, t))?;
                let v = floats(v.bind(py), "the value of a displacement field")?;
                vector::<D>(&v, "the value of a displacement field")
            };
            call().unwrap_or_else(|e| {
                set_callback_error(e);
                Vector::<D>::from_element(f64::NAN)
            })
        })
    }
}

fn scaled<const D: usize>(
    h: impl LoadHistory + 'static,
    v: Vector<D>,
) -> impl Fn(&Point<D>, f64) -> Vector<D> + Send + Sync {
    move |_x: &Point<D>, t: f64| v * h.value(t)
}

// ----- the generic bodies of the methods -----

fn add_body<const D: usize>(
    j: &mut JointModel<D>,
    name: &str,
    nodes: &Bound<'_, PyAny>,
    cells: &Bound<'_, PyAny>,
    material: &PyMaterial,
    parts: Option<&Bound<'_, PyDict>>,
) -> PyResult<usize> {
    let pts: Vec<Point<D>> =
        float_array(nodes, D, "nodes")?.iter().map(|r| Point::<D>::from_fn(|i, _| r[i])).collect();
    let cells: Vec<usize> = index_array(cells, D + 1, "cells")?.into_iter().flatten().collect();
    // cells of either orientation (meshio meshes need not orient them): inverted ones are flipped
    let (mut mesh, _flipped) =
        Mesh::<D>::new_with_repair(pts, cells).map_err(|e| msg(format!("body `{name}`: {e}")))?;
    if let Some(parts) = parts {
        for (k, v) in parts.iter() {
            let pname: String = k.extract()?;
            let facets = index_array(&v, D, &format!("part `{pname}`"))?;
            mesh.add_boundary_part_from_facets(&pname, BoundaryKind::TractionFree, &facets)
                .map_err(|e| msg(format!("body `{name}`, part `{pname}`: {e}")))?;
        }
    }
    let mat = material_for::<D>(material)?;
    Ok(j.add_body(name, mesh, mat).map_err(err)?.0)
}

fn add_part<const D: usize>(
    j: &mut JointModel<D>,
    body: &Bound<'_, PyAny>,
    name: &str,
    facets: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let id = body_id(j, body)?;
    let facets = index_array(facets, D, &format!("part `{name}`"))?;
    let b = j.model_mut().body_mut(id).map_err(err)?;
    let bname = b.name.clone();
    b.mesh
        .add_boundary_part_from_facets(name, BoundaryKind::TractionFree, &facets)
        .map_err(|e| msg(format!("body `{bname}`, part `{name}`: {e}")))?;
    Ok(())
}

fn add_part_where<const D: usize>(
    j: &mut JointModel<D>,
    body: &Bound<'_, PyAny>,
    name: &str,
    select: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let id = body_id(j, body)?;
    let py = select.py();
    let f = select.clone().unbind();
    let r = j.define_part(id, name, |x: &Point<D>, n: &Vector<D>| {
        let xs = numpy::PyArray1::from_vec_bound(py, x.iter().copied().collect());
        let ns = numpy::PyArray1::from_vec_bound(py, n.iter().copied().collect());
        match f.call1(py, (xs, ns)).and_then(|v| v.is_truthy(py)) {
            Ok(b) => b,
            Err(e) => {
                set_callback_error(e);
                false
            }
        }
    });
    if let Some(e) = take_callback_error() {
        return Err(e);
    }
    r.map_err(err)?;
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn contact_pair<const D: usize>(
    j: &mut JointModel<D>,
    name: &str,
    body_k: &Bound<'_, PyAny>,
    part_k: &str,
    body_l: &Bound<'_, PyAny>,
    part_l: &str,
    friction: f64,
    discretisation: &str,
    search_distance: Option<f64>,
) -> PyResult<()> {
    let k = body_id(j, body_k)?;
    let l = body_id(j, body_l)?;
    let pair = match discretisation {
        "node-to-node" | "node_to_node" => ContactPair::node_to_node(name, k, part_k, l, part_l),
        "node-to-segment" | "node_to_segment" | "node-to-facet" | "node_to_facet" => {
            ContactPair::node_to_segment(name, k, part_k, l, part_l)
        }
        "mortar" => ContactPair::mortar(name, k, part_k, l, part_l),
        _ => {
            return Err(msg(format!(
                "unknown discretisation `{discretisation}`: use \"node-to-node\", \"node-to-segment\" or \"mortar\""
            )))
        }
    };
    let mut pair = pair.with_friction(friction);
    if let Some(d) = search_distance {
        pair = pair.with_search_distance(d);
    }
    j.add_contact(pair).map_err(err)?;
    Ok(())
}

fn contact_obstacle<const D: usize>(
    j: &mut JointModel<D>,
    name: &str,
    body: &Bound<'_, PyAny>,
    part: &str,
    obstacle: Arc<dyn SignedDistance<D>>,
    friction: f64,
) -> PyResult<()> {
    let id = body_id(j, body)?;
    j.add_contact(ContactPair::rigid(name, id, part, obstacle).with_friction(friction)).map_err(err)?;
    Ok(())
}

fn run_joint<const D: usize>(
    joint: &JointModel<D>,
    how: &RunKind,
    keep_steps: bool,
) -> Result<RunData, synovia::builder::JointError> {
    let mut col = Collector { keep_steps, ..Default::default() };
    let observer = |v: &synovia::builder::StepView<'_, D>| {
        col.step(v.model, v.geometry, v.result);
        Ok(())
    };
    let run = match how {
        RunKind::Static(t) => joint.run_quasistatic_with(&[*t], observer)?,
        RunKind::QuasiStatic(times) => joint.run_quasistatic_with(times, observer)?,
        RunKind::Dynamic(dt, steps) => joint.run_dynamic_with(*dt, *steps, observer)?,
        RunKind::Analysis => joint.run_with(observer)?,
    };
    col.finish(joint.model(), run, joint.kinematics()).map_err(synovia::builder::JointError::Invalid)
}

#[derive(Debug, Clone)]
enum RunKind {
    Static(f64),
    QuasiStatic(Vec<f64>),
    Dynamic(f64, usize),
    Analysis,
}

/// A joint model (`synovia.Model`): bodies (P1 triangles in 2D, tetrahedra in 3D) from NumPy
/// arrays, materials, boundary conditions on named boundary parts with load histories, contact
/// pairs, the contact solver, and static, quasi-static and dynamic runs.
///
/// Bodies are referred to by index (`int`) or name (`str`). A load history is `None` (1 at
/// every time), a number, a `synovia.Parameter`, an `(n, 2)` table of `(t, h)` rows (piecewise
/// linear) or a callable `h(t)`.
#[pyclass(name = "Model", module = "synovia")]
#[derive(Debug)]
pub struct PyModel {
    pub(crate) joint: Joint,
    name: Option<String>,
    warnings: Vec<String>,
    /// The pose inputs of rigid bodies added with `pose_input=True`.
    poses: PoseInputs,
}

impl PyModel {
    fn run_kind(&self, py: Python<'_>, how: RunKind, keep_steps: bool) -> PyResult<PyRunResult> {
        let joint = self.joint.clone();
        take_callback_error();
        let r = py.allow_threads(move || match &joint {
            Joint::D2(j) => run_joint(j, &how, keep_steps),
            Joint::D3(j) => run_joint(j, &how, keep_steps),
        });
        let data = solved(r)?;
        Ok(PyRunResult { data })
    }
}

#[pymethods]
impl PyModel {
    /// An empty model of dimension 2 (plane problems) or 3.
    #[new]
    fn new(dimension: usize) -> PyResult<Self> {
        let joint = match dimension {
            2 => Joint::D2(Arc::new(JointModel::new())),
            3 => Joint::D3(Arc::new(JointModel::new())),
            _ => return Err(msg(format!("dimension must be 2 or 3, got {dimension}"))),
        };
        Ok(Self { joint, name: None, warnings: Vec::new(), poses: Vec::new() })
    }

    /// A model from a TOML scenario file (`docs/scenario.md`): bodies, materials, conditions,
    /// contact pairs, rigid bodies, solver and analysis; `Model.run()` runs its analysis.
    /// Output settings of the file (`[output]`) are not used: results come back as a
    /// `RunResult`.
    #[staticmethod]
    fn from_scenario(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let built = py.allow_threads(move || -> Result<(Joint, String, Vec<String>), String> {
            let sc = Scenario::from_file(&path).map_err(|e| e.to_string())?;
            let dim = *sc.doc.dimension.get_ref();
            let name = sc.name();
            match dim {
                2 => build::<2>(&sc)
                    .map(|b| (Joint::D2(Arc::new(b.joint)), name, b.warnings))
                    .map_err(|e| e.to_string()),
                3 => build::<3>(&sc)
                    .map(|b| (Joint::D3(Arc::new(b.joint)), name, b.warnings))
                    .map_err(|e| e.to_string()),
                _ => Err(format!("{}: dimension must be 2 or 3, got {dim}", path.display())),
            }
        });
        let (joint, name, warnings) = built.map_err(msg)?;
        Ok(Self { joint, name: Some(name), warnings, poses: Vec::new() })
    }

    /// Dimension (2 or 3).
    #[getter]
    fn dimension(&self) -> usize {
        match self.joint {
            Joint::D2(_) => 2,
            Joint::D3(_) => 3,
        }
    }
    /// The scenario's name (models from scenario files), else `None`.
    #[getter]
    fn name(&self) -> Option<String> {
        self.name.clone()
    }
    /// Warnings found while building a scenario (the model is usable).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }
    /// Body names, in order.
    #[getter]
    fn bodies(&self) -> Vec<String> {
        with_joint!(self, j => j.model().bodies().iter().map(|b| b.name.clone()).collect())
    }
    /// Contact pair names.
    #[getter]
    fn pairs(&self) -> Vec<String> {
        with_joint!(self, j => j.pairs().iter().map(|p| p.name.clone()).collect())
    }
    /// The analysis set by the scenario (`{"type": "static", "time": t}`,
    /// `{"type": "quasistatic", "times": [...]}`, `{"type": "dynamic", "dt": dt, "steps": n}`)
    /// or `None`.
    #[getter]
    fn analysis<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let a = with_joint!(self, j => j.analysis().cloned());
        let Some(a) = a else { return Ok(None) };
        let d = PyDict::new_bound(py);
        d.set_item("type", a.kind())?;
        match a {
            Analysis::Static { time } => d.set_item("time", time)?,
            Analysis::QuasiStatic { times } => d.set_item("times", times)?,
            Analysis::Dynamic { dt, steps } => {
                d.set_item("dt", dt)?;
                d.set_item("steps", steps)?;
            }
        }
        Ok(Some(d))
    }
    /// The contact solver's name.
    #[getter]
    fn solver_name(&self) -> String {
        with_joint!(self, j => j.solver_name().to_string())
    }
    /// Boundary part names of a body.
    fn parts(&self, body: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
        with_joint!(self, j => {
            let id = body_id(j, body)?;
            let b = j.model().body(id).map_err(err)?;
            Ok(b.mesh.boundary_parts().iter().map(|p| p.name().to_string()).collect())
        })
    }
    /// The facets of a boundary part (node indices), shape `(k, D)`.
    fn facets<'py>(
        &self,
        py: Python<'py>,
        body: &Bound<'py, PyAny>,
        part: &str,
    ) -> PyResult<Bound<'py, numpy::PyArray2<u64>>> {
        use numpy::PyArrayMethods;
        let d = self.dimension();
        let v = with_joint!(self, j => {
            let id = body_id(j, body)?;
            let b = j.model().body(id).map_err(err)?;
            let p = b.mesh.boundary_part(part).map_err(err)?;
            p.facets().flat_map(|f| f.iter().map(|&i| i as u64).collect::<Vec<_>>()).collect::<Vec<u64>>()
        });
        let n = v.len() / d;
        numpy::PyArray1::from_vec_bound(py, v).reshape([n, d])
    }
    /// Node coordinates of a body, shape `(n_nodes, D)`.
    fn nodes<'py>(
        &self,
        py: Python<'py>,
        body: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        use numpy::PyArrayMethods;
        let (v, d) = with_joint!(self, j => {
            let id = body_id(j, body)?;
            let b = j.model().body(id).map_err(err)?;
            (b.mesh.nodes().iter().flat_map(|p| p.iter().copied().collect::<Vec<_>>()).collect::<Vec<f64>>(), self.dimension())
        });
        let n = v.len() / d;
        numpy::PyArray1::from_vec_bound(py, v).reshape([n, d])
    }
    /// Cells of a body, shape `(n_cells, D + 1)`.
    fn cells<'py>(
        &self,
        py: Python<'py>,
        body: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<u64>>> {
        use numpy::PyArrayMethods;
        let (v, d) = with_joint!(self, j => {
            let id = body_id(j, body)?;
            let b = j.model().body(id).map_err(err)?;
            (b.mesh.cells().flat_map(|c| c.iter().map(|&i| i as u64).collect::<Vec<_>>()).collect::<Vec<u64>>(), self.dimension())
        });
        let n = v.len() / (d + 1);
        numpy::PyArray1::from_vec_bound(py, v).reshape([n, d + 1])
    }

    /// Adds a body: `nodes` `(n, D)` coordinates, `cells` `(m, D + 1)` node indices (P1
    /// triangles / tetrahedra, any orientation), its `material`, and boundary `parts`
    /// `{name: (k, D) facet node indices}` (edges in 2D, triangles in 3D; each must be a
    /// boundary facet). Returns the body's index.
    #[pyo3(signature = (name, nodes, cells, material, parts = None))]
    fn add_body(
        &mut self,
        name: &str,
        nodes: &Bound<'_, PyAny>,
        cells: &Bound<'_, PyAny>,
        material: PyRef<'_, PyMaterial>,
        parts: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<usize> {
        with_joint_mut!(self, j => add_body(j, name, nodes, cells, &material, parts))
    }
    /// Adds a body from a `meshio.Mesh`: its triangles (2D) or tetrahedra (3D) with the
    /// points they use; boundary parts from its line (2D) / triangle (3D) cells, named by
    /// `cell_sets` or by the `gmsh:physical` tags with the names of `field_data` (else
    /// `tag_<n>`). Returns the body's index.
    fn add_meshio(
        &mut self,
        py: Python<'_>,
        name: &str,
        mesh: &Bound<'_, PyAny>,
        material: PyRef<'_, PyMaterial>,
    ) -> PyResult<usize> {
        let helper = py.import_bound("synovia._meshio")?;
        let arrays = helper.call_method1("arrays_from_meshio", (mesh, self.dimension()))?;
        let (nodes, cells, parts): (Bound<'_, PyAny>, Bound<'_, PyAny>, Bound<'_, PyDict>) =
            arrays.extract()?;
        with_joint_mut!(self, j => add_body(j, name, &nodes, &cells, &material, Some(&parts)))
    }
    /// Adds a boundary part from facets (`(k, D)` node indices of boundary facets).
    fn add_part(&mut self, body: &Bound<'_, PyAny>, name: &str, facets: &Bound<'_, PyAny>) -> PyResult<()> {
        with_joint_mut!(self, j => add_part(j, body, name, facets))
    }
    /// Adds a boundary part: the boundary facets whose centroid `x` and outward unit normal
    /// `n` (NumPy arrays) satisfy `select(x, n)`.
    fn add_part_where(
        &mut self,
        body: &Bound<'_, PyAny>,
        name: &str,
        select: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        with_joint_mut!(self, j => add_part_where(j, body, name, select))
    }

    /// Clamps a part (`u = 0`).
    fn clamp(&mut self, body: &Bound<'_, PyAny>, part: &str) -> PyResult<()> {
        with_joint_mut!(self, j => { let id = body_id(j, body)?; j.clamp(id, part).map_err(err)?; Ok(()) })
    }
    /// Makes a part a symmetry plane / sliding support (`u · n = 0`).
    fn symmetry(&mut self, body: &Bound<'_, PyAny>, part: &str) -> PyResult<()> {
        with_joint_mut!(self, j => { let id = body_id(j, body)?; j.symmetry(id, part).map_err(err)?; Ok(()) })
    }
    /// Prescribes the displacement `u(x, t) = h(t) value` on a part; `components` (indices)
    /// restricts it to some components, the others stay free.
    #[pyo3(signature = (body, part, value, history = None, components = None))]
    fn prescribe(
        &mut self,
        body: &Bound<'_, PyAny>,
        part: &str,
        value: &Bound<'_, PyAny>,
        history: Option<&Bound<'_, PyAny>>,
        components: Option<Vec<usize>>,
    ) -> PyResult<()> {
        let value = floats(value, "value")?;
        let h = self::history(history)?;
        let d = self.dimension();
        let m = mask(components, d)?;
        with_joint_mut!(self, j => {
            let id = body_id(j, body)?;
            j.prescribe_field(id, part, m, scaled(h, vector(&value, "value")?)).map_err(err)?;
            Ok(())
        })
    }
    /// Prescribes any displacement field `u = field(x, t)` (a callable returning `D` floats)
    /// on a part.
    #[pyo3(signature = (body, part, field, components = None))]
    fn prescribe_field(
        &mut self,
        body: &Bound<'_, PyAny>,
        part: &str,
        field: &Bound<'_, PyAny>,
        components: Option<Vec<usize>>,
    ) -> PyResult<()> {
        if !field.is_callable() {
            return Err(msg("field must be a callable f(x, t) returning the displacement"));
        }
        let m = mask(components, self.dimension())?;
        let f = field.clone().unbind();
        with_joint_mut!(self, j => {
            let id = body_id(j, body)?;
            j.prescribe_field(id, part, m, py_field(f)).map_err(err)?;
            Ok(())
        })
    }
    /// Prescribes the traction `τ n = h(t) value` on a part.
    #[pyo3(signature = (body, part, value, history = None))]
    fn traction(
        &mut self,
        body: &Bound<'_, PyAny>,
        part: &str,
        value: &Bound<'_, PyAny>,
        history: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let value = floats(value, "value")?;
        let h = self::history(history)?;
        with_joint_mut!(self, j => {
            let id = body_id(j, body)?;
            j.traction(id, part, vector(&value, "value")?, h).map_err(err)?;
            Ok(())
        })
    }
    /// Prescribes a normal pressure `p(t) = h(t) value` on a part (`p > 0` pushes into the
    /// body).
    #[pyo3(signature = (body, part, value, history = None))]
    fn pressure(
        &mut self,
        body: &Bound<'_, PyAny>,
        part: &str,
        value: f64,
        history: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let h = self::history(history)?;
        with_joint_mut!(self, j => {
            let id = body_id(j, body)?;
            j.pressure(id, part, value, h).map_err(err)?;
            Ok(())
        })
    }
    /// Sets the body force `F(x, t) = h(t) value` per unit volume of a body.
    #[pyo3(signature = (body, value, history = None))]
    fn body_force(
        &mut self,
        body: &Bound<'_, PyAny>,
        value: &Bound<'_, PyAny>,
        history: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let value = floats(value, "value")?;
        let h = self::history(history)?;
        with_joint_mut!(self, j => {
            let id = body_id(j, body)?;
            j.body_force(id, vector(&value, "value")?, h).map_err(err)?;
            Ok(())
        })
    }
    /// Bonds `part_a` of `body_a` to `part_b` of `body_b` (nodes at equal positions share
    /// their displacement).
    fn tie(
        &mut self,
        body_a: &Bound<'_, PyAny>,
        part_a: &str,
        body_b: &Bound<'_, PyAny>,
        part_b: &str,
    ) -> PyResult<()> {
        with_joint_mut!(self, j => {
            let a = body_id(j, body_a)?;
            let b = body_id(j, body_b)?;
            j.tie(a, part_a, b, part_b).map_err(err)?;
            Ok(())
        })
    }
    /// Sets the strain kinematics of a body: `"small"` (default) or `"finite"` (total
    /// Lagrangian; the model is then solved by the Newton iteration, docs/nonlinear.md).
    fn set_kinematics(&mut self, body: &Bound<'_, PyAny>, kinematics: &str) -> PyResult<()> {
        let k = match kinematics {
            "small" => synovia::fem::Kinematics::SmallStrain,
            "finite" => synovia::fem::Kinematics::FiniteStrain,
            other => return Err(msg(format!("kinematics is \"small\" or \"finite\", got \"{other}\""))),
        };
        with_joint_mut!(self, j => { let id = body_id(j, body)?; j.set_kinematics(id, k).map_err(err)?; Ok(()) })
    }
    /// Parameters of the Newton iteration of nonlinear models (a `neo_hookean` or
    /// `mooney_rivlin` material, or finite strain; docs/nonlinear.md): only the given ones
    /// change. `tangent_reuse=ρ` in (0, 1): modified Newton, the factorised tangent kept while
    /// each full step reduces the residual by `ρ`; `fresh_tangent=True`: Newton's method, a
    /// fresh tangent at every iteration (the default); `geometry`: `"converged"`, `"per_level"` or
    /// `"reference"`; `geometry_aitken`: Aitken's relaxation of the geometry passes;
    /// `geometry_pass_tolerance`: the relative residual at which a pass ends while its geometry
    /// still moves; `settled_increment`: once the geometry has settled, a full step of at most
    /// this relative size ends the iteration. Checked as a whole (SynoviaError naming the
    /// parameter out of range).
    #[pyo3(signature = (*, tolerance = None, max_iterations = None, line_search = None, max_cutbacks = None, tangent_reuse = None, fresh_tangent = false, geometry = None, geometry_tolerance = None, max_geometry_passes = None, geometry_relaxation = None, geometry_aitken = None, geometry_pass_tolerance = None, settled_increment = None))]
    #[allow(clippy::too_many_arguments)]
    fn newton_params(
        &mut self,
        tolerance: Option<f64>,
        max_iterations: Option<usize>,
        line_search: Option<bool>,
        max_cutbacks: Option<usize>,
        tangent_reuse: Option<f64>,
        fresh_tangent: bool,
        geometry: Option<&str>,
        geometry_tolerance: Option<f64>,
        max_geometry_passes: Option<usize>,
        geometry_relaxation: Option<f64>,
        geometry_aitken: Option<bool>,
        geometry_pass_tolerance: Option<f64>,
        settled_increment: Option<f64>,
    ) -> PyResult<()> {
        use synovia::nonlinear::GeometryUpdate;
        let update = match geometry {
            None => None,
            Some(name) => match GeometryUpdate::NAMES.iter().find(|(n, _)| *n == name) {
                Some(&(_, g)) => Some(g),
                None => {
                    let names: Vec<String> =
                        GeometryUpdate::NAMES.iter().map(|(n, _)| format!("\"{n}\"")).collect();
                    return Err(msg(format!("geometry is one of {}, got \"{name}\"", names.join(", "))));
                }
            },
        };
        with_joint_mut!(self, j => {
            let mut p = j.newton_parameters();
            if let Some(v) = tolerance { p = p.with_tolerance(v); }
            if let Some(v) = max_iterations { p = p.with_max_iterations(v); }
            if let Some(v) = line_search { p = p.with_line_search(v); }
            if let Some(v) = max_cutbacks { p = p.with_max_cutbacks(v); }
            if let Some(v) = tangent_reuse { p = p.with_tangent_reuse(Some(v)); }
            if fresh_tangent { p = p.with_tangent_reuse(None); }
            if let Some(v) = update { p = p.with_geometry_update(v); }
            if let Some(v) = geometry_tolerance { p = p.with_geometry_tolerance(v); }
            if let Some(v) = max_geometry_passes { p = p.with_max_geometry_passes(v); }
            if let Some(v) = geometry_relaxation { p = p.with_geometry_relaxation(v); }
            if let Some(v) = geometry_aitken { p = p.with_geometry_aitken(v); }
            if let Some(v) = geometry_pass_tolerance { p = p.with_geometry_pass_tolerance(Some(v)); }
            if let Some(v) = settled_increment { p = p.with_settled_increment(Some(v)); }
            p.check().map_err(err)?;
            j.newton_params(p);
            Ok(())
        })
    }
    /// Parameters of the iteration that finds the force-controlled coordinates of rigid bodies
    /// (docs/model.md §10): only the given ones change. `tolerance` in (0, 1): the relative
    /// balance; `max_solves`: contact solves per level; `geometry_tolerance`: motion (relative to
    /// the model size) before the contact geometry is rebuilt; `bordered=False`: the search over
    /// trial solves instead of the coordinates solved inside the contact solve (the default);
    /// `fresh_jacobian`: a fresh finite-difference Jacobian at every iterate of that search.
    /// SynoviaError for a parameter out of range.
    #[pyo3(signature = (*, tolerance = None, max_solves = None, geometry_tolerance = None, bordered = None, fresh_jacobian = None))]
    fn force_control(
        &mut self,
        tolerance: Option<f64>,
        max_solves: Option<usize>,
        geometry_tolerance: Option<f64>,
        bordered: Option<bool>,
        fresh_jacobian: Option<bool>,
    ) -> PyResult<()> {
        if let Some(v) = tolerance.filter(|v| !(v.is_finite() && *v > 0.0 && *v < 1.0)) {
            return Err(msg(format!("tolerance must lie in (0, 1), got {v}")));
        }
        if max_solves == Some(0) {
            return Err(msg("max_solves must be at least 1".to_string()));
        }
        if let Some(v) = geometry_tolerance.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(msg(format!("geometry_tolerance must be positive and finite, got {v}")));
        }
        with_joint_mut!(self, j => {
            let mut p = j.force_control_params();
            if let Some(v) = tolerance { p.tolerance = v; }
            if let Some(v) = max_solves { p.max_solves = v; }
            if let Some(v) = geometry_tolerance { p.geometry_tolerance = v; }
            if let Some(v) = bordered { p.bordered = v; }
            if let Some(v) = fresh_jacobian { p.fresh_jacobian = v; }
            j.force_control(p);
            Ok(())
        })
    }
    /// Sets the density of a body (dynamic runs).
    fn set_density(&mut self, body: &Bound<'_, PyAny>, density: f64) -> PyResult<()> {
        with_joint_mut!(self, j => { let id = body_id(j, body)?; j.set_density(id, density).map_err(err)?; Ok(()) })
    }
    /// Sets a uniform initial velocity of a body (dynamic runs).
    fn initial_velocity(&mut self, body: &Bound<'_, PyAny>, velocity: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = floats(velocity, "velocity")?;
        with_joint_mut!(self, j => { let id = body_id(j, body)?; j.initial_velocity(id, vector(&v, "velocity")?).map_err(err)?; Ok(()) })
    }

    /// Adds a body–body contact pair between `part_k` of `body_k` and `part_l` of `body_l`
    /// with Coulomb coefficient `friction`. `discretisation`: `"node-to-node"` (matching
    /// nodes), `"node-to-segment"` (node-to-facet in 3D; non-matching meshes) or `"mortar"`
    /// (dual mortar). `search_distance` bounds the contact search (non-matching pairs).
    #[pyo3(signature = (name, body_k, part_k, body_l, part_l, friction = 0.0, discretisation = "node-to-node", search_distance = None))]
    #[allow(clippy::too_many_arguments)]
    fn contact(
        &mut self,
        name: &str,
        body_k: &Bound<'_, PyAny>,
        part_k: &str,
        body_l: &Bound<'_, PyAny>,
        part_l: &str,
        friction: f64,
        discretisation: &str,
        search_distance: Option<f64>,
    ) -> PyResult<()> {
        with_joint_mut!(self, j => contact_pair(j, name, body_k, part_k, body_l, part_l, friction, discretisation, search_distance))
    }
    /// Adds a contact pair between a part and the rigid half-space bounded by the plane
    /// through `point` with outward `normal` (the side the body is on).
    #[pyo3(signature = (name, body, part, point, normal, friction = 0.0))]
    #[allow(clippy::too_many_arguments)]
    fn contact_plane(
        &mut self,
        name: &str,
        body: &Bound<'_, PyAny>,
        part: &str,
        point: &Bound<'_, PyAny>,
        normal: &Bound<'_, PyAny>,
        friction: f64,
    ) -> PyResult<()> {
        let (p, n) = (floats(point, "point")?, floats(normal, "normal")?);
        with_joint_mut!(self, j => {
            let o = PlaneObstacle::new(self::point(&p, "point")?, vector(&n, "normal")?).map_err(err)?;
            contact_obstacle(j, name, body, part, Arc::new(o), friction)
        })
    }
    /// Adds a contact pair between a part and a rigid ball (`cavity=False`, the body is
    /// outside) or spherical cavity (`cavity=True`, the body is inside) of `radius` about
    /// `center` (a disc / circular hole in 2D).
    #[pyo3(signature = (name, body, part, center, radius, cavity = false, friction = 0.0))]
    #[allow(clippy::too_many_arguments)]
    fn contact_sphere(
        &mut self,
        name: &str,
        body: &Bound<'_, PyAny>,
        part: &str,
        center: &Bound<'_, PyAny>,
        radius: f64,
        cavity: bool,
        friction: f64,
    ) -> PyResult<()> {
        let c = floats(center, "center")?;
        with_joint_mut!(self, j => {
            let o = SphereObstacle::new(self::point(&c, "center")?, radius, cavity).map_err(err)?;
            contact_obstacle(j, name, body, part, Arc::new(o), friction)
        })
    }
    /// Adds a contact pair between a part and a rigid cylinder (3D only) through `point` with
    /// `axis` and `radius` (`cavity=True`: the body is inside).
    #[pyo3(signature = (name, body, part, point, axis, radius, cavity = false, friction = 0.0))]
    #[allow(clippy::too_many_arguments)]
    fn contact_cylinder(
        &mut self,
        name: &str,
        body: &Bound<'_, PyAny>,
        part: &str,
        point: &Bound<'_, PyAny>,
        axis: &Bound<'_, PyAny>,
        radius: f64,
        cavity: bool,
        friction: f64,
    ) -> PyResult<()> {
        let (p, a) = (floats(point, "point")?, floats(axis, "axis")?);
        let Joint::D3(arc) = &mut self.joint else {
            return Err(msg("cylinder obstacles are 3D only (use contact_sphere for a disc in 2D)"));
        };
        let j = get_mut(arc)?;
        let o =
            CylinderObstacle::new(self::point::<3>(&p, "point")?, vector::<3>(&a, "axis")?, radius, cavity)
                .map_err(err)?;
        contact_obstacle(j, name, body, part, Arc::new(o), friction)
    }
    /// Adds a contact pair between a part and a fixed rigid obstacle of any `Shape` (plane,
    /// sphere, cylinder, or a surface such as an STL file); `search_distance` bounds the
    /// contact search.
    #[pyo3(signature = (name, body, part, shape, friction = 0.0, search_distance = None))]
    #[allow(clippy::too_many_arguments)]
    fn contact_obstacle(
        &mut self,
        name: &str,
        body: &Bound<'_, PyAny>,
        part: &str,
        shape: PyRef<'_, PyShape>,
        friction: f64,
        search_distance: Option<f64>,
    ) -> PyResult<()> {
        with_joint_mut!(self, j => {
            let o = rigid::shape_for(&shape)?;
            let id = body_id(j, body)?;
            let mut pair = ContactPair::rigid(name, id, part, o).with_friction(friction);
            if let Some(d) = search_distance {
                pair = pair.with_search_distance(d);
            }
            j.add_contact(pair).map_err(err)?;
            Ok(())
        })
    }

    /// Adds a rigid body with mixed control (`synovia::rigid`, a scenario's `[[rigid_body]]`):
    /// reference point `center` (default the origin) and, in 3D, `rotation_order` (default
    /// `"zxy"`: `R = R_z R_x R_y`). Its degrees of freedom, by name (`"tx"`, `"ty"`, `"tz"`,
    /// `"rx"`, `"ry"`, `"rz"`; 2D `"tx"`, `"ty"`, `"rz"`), are held at 0 unless given:
    /// `prescribe={dof: history}` (the coordinate `q(t)`, length or radians), or
    /// `force={dof: history}` (the generalised force `F(t)`: a force along the axis, or a
    /// moment about the angle's axis; the coordinate is found from the body's equilibrium),
    /// with `guess={dof: history}` an optional predictor of a force-controlled coordinate.
    /// A history is a number, a `Parameter`, an `(n, 2)` table or a callable, as elsewhere.
    /// `pose_input=True`: every degree of freedom not in `prescribe`/`force` follows the pose
    /// set by `Session.set_pose` / `Model.set_pose` (identity until set). Returns the rigid
    /// body's index.
    #[pyo3(signature = (name, center = None, rotation_order = None, prescribe = None, force = None, guess = None, pose_input = false))]
    #[allow(clippy::too_many_arguments)]
    fn add_rigid_body(
        &mut self,
        name: &str,
        center: Option<&Bound<'_, PyAny>>,
        rotation_order: Option<&str>,
        prescribe: Option<&Bound<'_, PyDict>>,
        force: Option<&Bound<'_, PyDict>>,
        guess: Option<&Bound<'_, PyDict>>,
        pose_input: bool,
    ) -> PyResult<usize> {
        let spec = RigidSpec { name, center, rotation_order, prescribe, force, guess, pose_input };
        match &mut self.joint {
            Joint::D2(a) => {
                let (id, input) = rigid::add_rigid_body(get_mut(a)?, &spec)?;
                if let Some(i) = input {
                    self.poses.push((name.to_string(), PoseSlot::D2(i)));
                }
                Ok(id)
            }
            Joint::D3(a) => {
                let (id, input) = rigid::add_rigid_body(get_mut(a)?, &spec)?;
                if let Some(i) = input {
                    self.poses.push((name.to_string(), PoseSlot::D3(i)));
                }
                Ok(id)
            }
        }
    }
    /// Rigid body names, in order.
    #[getter]
    fn rigid_bodies(&self) -> Vec<String> {
        with_joint!(self, j => j.rigid_bodies().iter().map(|b| b.name().to_string()).collect())
    }
    /// Ties a part of an elastic body to rigid body `rigid` (a rigid plate): the part moves
    /// with the rigid body's pose and its reactions load the rigid body.
    fn tie_to_rigid_body(&mut self, body: &Bound<'_, PyAny>, part: &str, rigid: &str) -> PyResult<()> {
        with_joint_mut!(self, j => rigid::tie(j, body, part, rigid))
    }
    /// Adds a contact pair between a part and the `shape` of rigid body `rigid` (given in
    /// the rigid body's frame, placed by its pose at every level); the contact forces load
    /// the rigid body.
    #[pyo3(signature = (name, body, part, rigid, shape, friction = 0.0, search_distance = None))]
    #[allow(clippy::too_many_arguments)]
    fn contact_rigid_body(
        &mut self,
        name: &str,
        body: &Bound<'_, PyAny>,
        part: &str,
        rigid: &str,
        shape: PyRef<'_, PyShape>,
        friction: f64,
        search_distance: Option<f64>,
    ) -> PyResult<()> {
        with_joint_mut!(self, j => rigid::contact(j, name, body, part, rigid, &shape, friction, search_distance))
    }
    /// Sets the pose of a rigid body added with `pose_input=True` for the next runs (see
    /// `Session.set_pose`).
    #[pyo3(signature = (rigid, translation, quaternion = None, axis = None, angle = None, rotation = None))]
    #[allow(clippy::too_many_arguments)]
    fn set_pose(
        &self,
        rigid: &str,
        translation: &Bound<'_, PyAny>,
        quaternion: Option<&Bound<'_, PyAny>>,
        axis: Option<&Bound<'_, PyAny>>,
        angle: Option<f64>,
        rotation: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        rigid::set_pose(&self.poses, rigid, translation, quaternion, axis, angle, rotation)
    }
    /// Sets the friction law of a contact pair (quasi-static and dynamic runs), by name:
    /// `"coulomb"` with `mu` (a constant coefficient, `ConstantFriction`), or
    /// `"exponential"` with `static`, `kinetic` and `speed`
    /// (`F_c(v) = μ_k + (μ_s − μ_k) exp(−v / v_c)`, `ExponentialFriction`; the scenario key
    /// `friction_law`).
    #[pyo3(signature = (pair, law, mu = None, r#static = None, kinetic = None, speed = None))]
    #[allow(clippy::too_many_arguments)]
    fn friction_law(
        &mut self,
        pair: &str,
        law: &str,
        mu: Option<f64>,
        r#static: Option<f64>,
        kinetic: Option<f64>,
        speed: Option<f64>,
    ) -> PyResult<()> {
        let need = |v: Option<f64>, what: &str, positive: bool| -> PyResult<f64> {
            let v = v.ok_or_else(|| msg(format!("friction law `{law}` needs `{what}`")))?;
            if !v.is_finite() || v < 0.0 || (positive && v == 0.0) {
                let kind = if positive { "positive" } else { "non-negative" };
                return Err(msg(format!(
                    "friction law `{law}`: `{what}` must be finite and {kind}, got {v}"
                )));
            }
            Ok(v)
        };
        let unused = |given: &[(&str, Option<f64>)]| -> PyResult<()> {
            match given.iter().find(|(_, v)| v.is_some()) {
                Some((k, _)) => Err(msg(format!("friction law `{law}` takes no `{k}`"))),
                None => Ok(()),
            }
        };
        let l: Arc<dyn synovia::contact_ops::FrictionLaw> = match law {
            "coulomb" | "constant" => {
                unused(&[("static", r#static), ("kinetic", kinetic), ("speed", speed)])?;
                Arc::new(synovia::contact_ops::ConstantFriction(need(mu, "mu", false)?))
            }
            "exponential" => {
                unused(&[("mu", mu)])?;
                Arc::new(synovia::contact_ops::ExponentialFriction {
                    static_coefficient: need(r#static, "static", false)?,
                    kinetic_coefficient: need(kinetic, "kinetic", false)?,
                    characteristic_speed: need(speed, "speed", true)?,
                })
            }
            other => {
                return Err(msg(format!(
                    "unknown friction law `{other}`: use \"coulomb\" (mu) or \"exponential\" (static, kinetic, speed)"
                )))
            }
        };
        with_joint_mut!(self, j => { j.friction_law(pair, l.clone()).map_err(err)?; Ok(()) })
    }
    /// The friction scheme of quasi-static runs and session steps (the scenario's
    /// `[analysis]` keys): `coulomb_fixed_point=False` (default) is Tresca friction with the
    /// slip bound frozen from the previous level, `True` re-solves each level until the bound
    /// `F_c |Λ_n|` stops changing (Coulomb; at most `max_fixed_point` solves, relative
    /// tolerance `fixed_point_tolerance`); `incremental_slip` measures slip from the previous
    /// level (default) or from the reference state; `initial_friction` adds a Tresca solve at
    /// step 0. Unset arguments take the defaults.
    #[pyo3(signature = (coulomb_fixed_point = None, max_fixed_point = None, fixed_point_tolerance = None, incremental_slip = None, initial_friction = None))]
    fn quasistatic_options(
        &mut self,
        coulomb_fixed_point: Option<bool>,
        max_fixed_point: Option<usize>,
        fixed_point_tolerance: Option<f64>,
        incremental_slip: Option<bool>,
        initial_friction: Option<bool>,
    ) -> PyResult<()> {
        let mut q = synovia::time::quasistatic::QuasiStaticParams::default();
        if let Some(v) = coulomb_fixed_point {
            q.coulomb_fixed_point = v;
        }
        if let Some(v) = max_fixed_point {
            if v < 1 {
                return Err(msg("max_fixed_point must be at least 1"));
            }
            q.max_fixed_point = v;
        }
        if let Some(v) = fixed_point_tolerance {
            if !(v.is_finite() && v > 0.0) {
                return Err(msg(format!("fixed_point_tolerance must be finite and positive, got {v}")));
            }
            q.fixed_point_tolerance = v;
        }
        if let Some(v) = incremental_slip {
            q.incremental_slip = v;
        }
        if let Some(v) = initial_friction {
            q.initial_friction = v;
        }
        with_joint_mut!(self, j => { j.quasistatic_params(q); Ok(()) })
    }
    /// Chooses the contact solver by name: `"pdas-fallback"` (default), `"pdas"`,
    /// `"au-pdas"`, `"uzawa-mprgp"` or `"dual-mprgp"`.
    fn solver(&mut self, name: &str) -> PyResult<()> {
        with_joint_mut!(self, j => { j.solver(name).map_err(err)?; Ok(()) })
    }
    /// Options of the contact solve (the scenario's `[solver]` keys): `interface_block_dofs`,
    /// the largest contact interface factorised as a dense trailing block (0: none; large
    /// candidate surfaces with moving patches), and `screening_band`, each solve on the
    /// contact rows within that distance of the partner (exact, docs/performance.md).
    #[pyo3(signature = (interface_block_dofs = None, screening_band = None))]
    fn solver_options(
        &mut self,
        interface_block_dofs: Option<usize>,
        screening_band: Option<f64>,
    ) -> PyResult<()> {
        with_joint_mut!(self, j => {
            if let Some(v) = interface_block_dofs {
                let base = synovia::linalg::InterfaceBlockParams::default();
                j.interface_block(base.with_max_dofs(v).with_screened_dofs(base.screened_dofs.min(v)));
            }
            if let Some(b) = screening_band {
                j.screening_band(Some(b)).map_err(err)?;
            }
            Ok(())
        })
    }
    /// Reports the figures of contact pair `pair` also split by the plane through `point`
    /// with `normal` into the sides `positive` (where the normal points) and `negative` (e.g.
    /// lateral and medial): each pair dict then has them in `sides`. Reporting only.
    #[pyo3(signature = (pair, point, normal, positive = "positive", negative = "negative"))]
    fn split_pair(
        &mut self,
        pair: &str,
        point: &Bound<'_, PyAny>,
        normal: &Bound<'_, PyAny>,
        positive: &str,
        negative: &str,
    ) -> PyResult<()> {
        let d = self.dimension();
        let three = |v: Vec<f64>, what: &str| -> PyResult<[f64; 3]> {
            if v.len() != d {
                return Err(msg(format!("{what} must have {d} components, got {}", v.len())));
            }
            Ok([v[0], v[1], v.get(2).copied().unwrap_or(0.0)])
        };
        let split = synovia::contact_ops::operators::PairSplit::new(
            positive,
            negative,
            three(floats(point, "point")?, "point")?,
            three(floats(normal, "normal")?, "normal")?,
        )
        .map_err(err)?;
        with_joint_mut!(self, j => { j.split_pair_report(pair, split.clone()).map_err(err)?; Ok(()) })
    }
    /// Nested iteration for cold-started contact solves (`None` turns it off; default 32).
    #[pyo3(signature = (min_rows))]
    fn nested_iteration(&mut self, min_rows: Option<usize>) -> PyResult<()> {
        with_joint_mut!(self, j => { j.nested_iteration(min_rows); Ok(()) })
    }

    /// Solves the static problem at time `t` (GIL released).
    #[pyo3(signature = (t = 0.0))]
    fn run_static(&self, py: Python<'_>, t: f64) -> PyResult<PyRunResult> {
        self.run_kind(py, RunKind::Static(t), false)
    }
    /// Runs the quasi-static scheme over `times` (strictly increasing; GIL released).
    /// `keep_steps=True` keeps the displacement of every step.
    #[pyo3(signature = (times, keep_steps = false))]
    fn run_quasistatic(&self, py: Python<'_>, times: Vec<f64>, keep_steps: bool) -> PyResult<PyRunResult> {
        self.run_kind(py, RunKind::QuasiStatic(times), keep_steps)
    }
    /// Runs the dynamic scheme: `steps` steps of `dt` (record 0 is the initial state; needs
    /// densities). GIL released.
    #[pyo3(signature = (dt, steps, keep_steps = false))]
    fn run_dynamic(&self, py: Python<'_>, dt: f64, steps: usize, keep_steps: bool) -> PyResult<PyRunResult> {
        self.run_kind(py, RunKind::Dynamic(dt, steps), keep_steps)
    }
    /// Runs the analysis of the scenario file the model came from (GIL released).
    #[pyo3(signature = (keep_steps = false))]
    fn run(&self, py: Python<'_>, keep_steps: bool) -> PyResult<PyRunResult> {
        self.run_kind(py, RunKind::Analysis, keep_steps)
    }
    /// Validates, assembles and factorises the model once and returns a `Session` that
    /// solves it again and again with new loads (`Parameter` values, callables reading Python
    /// state, or the time) without refactorising. The model cannot be changed while the
    /// session is open.
    fn prepare(&self, py: Python<'_>) -> PyResult<PySession> {
        PySession::open(py, self.joint.clone(), self.poses.clone())
    }
    fn __repr__(&self) -> String {
        format!("Model(dimension={}, bodies={:?}, pairs={:?})", self.dimension(), self.bodies(), self.pairs())
    }
}

/// Runs a TOML scenario file (its analysis) and returns the `RunResult`; same as
/// `Model.from_scenario(path).run()`.
#[pyfunction]
#[pyo3(signature = (path, keep_steps = false))]
pub fn run_scenario(py: Python<'_>, path: std::path::PathBuf, keep_steps: bool) -> PyResult<PyRunResult> {
    let m = PyModel::from_scenario(py, path)?;
    m.run(py, keep_steps)
}
