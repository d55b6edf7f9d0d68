//! Results of runs and session solves as NumPy arrays and Python dicts.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use synovia::builder::RunResult;
use synovia::contact_ops::operators::ContactGeometry;
use synovia::contact_ops::{KktReport, StaticContactResult};
use synovia::fem::post::body_fields_with_kinematics;
use synovia::fem::Kinematics;
use synovia::fem::Model;
use synovia::mesh::math::Vector;
use synovia::time::results::{PairRecord, RigidRecord, StepRecord};

use crate::error::msg;

/// The mesh of one body, flattened.
#[derive(Debug, Clone)]
pub struct BodyMesh {
    /// Body name.
    pub name: String,
    /// Node coordinates, `n_nodes × D`.
    pub nodes: Vec<f64>,
    /// Cells, `n_cells × (D + 1)`.
    pub cells: Vec<usize>,
    /// Boundary part names.
    pub parts: Vec<String>,
}

/// The stress fields of one body at the last step.
#[derive(Debug, Clone, Default)]
pub struct BodyStress {
    /// Voigt stress recovered to nodes, `n_nodes × nv`.
    pub nodal_stress: Vec<f64>,
    /// Von Mises stress at nodes.
    pub nodal_von_mises: Vec<f64>,
    /// Voigt stress per cell, `n_cells × nv`.
    pub cell_stress: Vec<f64>,
    /// Von Mises stress per cell.
    pub cell_von_mises: Vec<f64>,
    /// Strain energy of the body.
    pub strain_energy: f64,
}

/// A contact row of the last step.
#[derive(Debug, Clone)]
pub struct ContactRow {
    /// Pair name.
    pub pair: String,
    /// Body of the contact node.
    pub body: usize,
    /// Node (in the body's numbering).
    pub node: usize,
    /// Position of the node.
    pub position: Vec<f64>,
    /// Normal multiplier `Λ_n` (contact pressure).
    pub pressure: f64,
}

/// Everything a run or a session solve hands back (owned, so it can cross threads).
#[derive(Debug, Clone, Default)]
pub struct RunData {
    /// Dimension.
    pub dim: usize,
    /// The meshes of the bodies.
    pub bodies: Vec<BodyMesh>,
    /// One record per step.
    pub records: Vec<StepRecord>,
    /// Displacement of the last step per body, `n_nodes × D` flat.
    pub displacement: Vec<Vec<f64>>,
    /// Displacement per step per body (only with `keep_steps`).
    pub step_displacement: Vec<Vec<Vec<f64>>>,
    /// Nodal contact pressure per step per body (0 away from contact nodes).
    pub pressure: Vec<Vec<Vec<f64>>>,
    /// Stresses of the last step per body.
    pub stress: Vec<BodyStress>,
    /// The contact rows of the last step.
    pub contact: Vec<ContactRow>,
    /// KKT residuals of the last step.
    pub kkt: Option<KktReport>,
    /// Reduced unknowns.
    pub n_dofs: usize,
    /// Contact nodes of all pairs.
    pub contact_nodes: usize,
    /// Solver name.
    pub solver: String,
    /// Set-up time, s.
    pub setup_s: f64,
    /// Total time, s.
    pub total_s: f64,
    /// Session solves only: whether the solve was warm-started.
    pub warm_started: Option<bool>,
}

fn flat<const D: usize>(v: &[Vector<D>]) -> Vec<f64> {
    v.iter().flat_map(|x| x.iter().copied().collect::<Vec<_>>()).collect()
}

/// The meshes of the bodies of `model`.
pub fn meshes<const D: usize>(model: &Model<D>) -> Vec<BodyMesh> {
    model
        .bodies()
        .iter()
        .map(|b| BodyMesh {
            name: b.name.clone(),
            nodes: b.mesh.nodes().iter().flat_map(|p| p.iter().copied().collect::<Vec<_>>()).collect(),
            cells: b.mesh.cells().flat_map(|c| c.iter().copied()).collect(),
            parts: b.mesh.boundary_parts().iter().map(|p| p.name().to_string()).collect(),
        })
        .collect()
}

/// Nodal contact pressure per body of one step.
pub fn nodal_pressure<const D: usize>(
    model: &Model<D>,
    geometry: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
) -> Vec<Vec<f64>> {
    let nb = model.bodies().len();
    let mut p: Vec<Vec<f64>> = model.bodies().iter().map(|b| vec![0.0; b.mesh.n_nodes()]).collect();
    for (r, node) in geometry.nodes.iter().enumerate() {
        let (b, i) = (node.node.0 .0, node.node.1);
        if b < nb && i < p[b].len() {
            p[b][i] = result.solution.lambda_n.get(r).copied().unwrap_or(0.0);
        }
    }
    p
}

/// The contact rows of one step.
pub fn contact_rows<const D: usize>(
    geometry: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
) -> Vec<ContactRow> {
    let mut rows = Vec::with_capacity(geometry.nodes.len());
    for (name, range) in &geometry.pairs {
        for r in range.clone() {
            if let Some(node) = geometry.nodes.get(r) {
                rows.push(ContactRow {
                    pair: name.clone(),
                    body: node.node.0 .0,
                    node: node.node.1,
                    position: node.position.iter().copied().collect(),
                    pressure: result.solution.lambda_n.get(r).copied().unwrap_or(0.0),
                });
            }
        }
    }
    rows
}

/// Fills the last-step fields (displacement, stresses) of `data` from nodal displacements.
pub fn finish<const D: usize>(
    data: &mut RunData,
    model: &Model<D>,
    displacement: &[Vec<Vector<D>>],
    kinematics: &[Kinematics],
) -> Result<(), String> {
    data.dim = D;
    data.bodies = meshes(model);
    data.displacement = displacement.iter().map(|u| flat(u)).collect();
    let fields = body_fields_with_kinematics(model, displacement, kinematics).map_err(|e| e.to_string())?;
    data.stress = fields
        .iter()
        .map(|f| BodyStress {
            nodal_stress: f.nodal_stress.iter().flatten().copied().collect(),
            nodal_von_mises: f.nodal_von_mises.clone(),
            cell_stress: f.cell_stress.iter().flatten().copied().collect(),
            cell_von_mises: f.cell_von_mises.clone(),
            strain_energy: f.strain_energy,
        })
        .collect();
    Ok(())
}

/// Collects per-step data while a run proceeds.
#[derive(Debug, Default)]
pub struct Collector {
    /// Keep the displacement of every step.
    pub keep_steps: bool,
    /// The data so far.
    pub data: RunData,
}

impl Collector {
    /// Records one step.
    pub fn step<const D: usize>(
        &mut self,
        model: &Model<D>,
        geometry: &ContactGeometry<D>,
        result: &StaticContactResult<D>,
    ) {
        self.data.pressure.push(nodal_pressure(model, geometry, result));
        if self.keep_steps {
            self.data.step_displacement.push(result.displacement.iter().map(|u| flat(u)).collect());
        }
        self.data.contact = contact_rows(geometry, result);
        self.data.kkt = Some(result.kkt);
    }

    /// The data of a finished run.
    pub fn finish<const D: usize>(
        mut self,
        model: &Model<D>,
        run: RunResult<D>,
        kinematics: &[Kinematics],
    ) -> Result<RunData, String> {
        finish(&mut self.data, model, &run.displacement, kinematics)?;
        self.data.records = run.records;
        self.data.n_dofs = run.n_dofs;
        self.data.contact_nodes = run.contact_nodes;
        self.data.solver = run.solver;
        self.data.setup_s = run.setup_s;
        self.data.total_s = run.total_s;
        if run.contact.is_none() {
            self.data.kkt = None;
        }
        Ok(self.data)
    }
}

/// The result of a run (`synovia.RunResult`): per-step records (pair forces, areas, energies,
/// rigid-body states), nodal displacements, stresses and contact pressures as NumPy arrays,
/// the contact rows and KKT residuals of the last step.
///
/// Bodies are given by index or name. `step` indices follow Python (negative from the end).
#[pyclass(name = "RunResult", module = "synovia", frozen)]
#[derive(Debug)]
pub struct PyRunResult {
    pub(crate) data: RunData,
}

impl PyRunResult {
    fn body(&self, body: &Bound<'_, PyAny>) -> PyResult<usize> {
        if let Ok(i) = body.extract::<isize>() {
            let n = self.data.bodies.len() as isize;
            let j = if i < 0 { i + n } else { i };
            if (0..n).contains(&j) {
                return Ok(j as usize);
            }
            return Err(msg(format!("body index {i} out of range (the result has {n} bodies)")));
        }
        let name: String = body.extract()?;
        self.data.bodies.iter().position(|b| b.name == name).ok_or_else(|| {
            msg(format!(
                "no body `{name}` (bodies: {:?})",
                self.data.bodies.iter().map(|b| b.name.as_str()).collect::<Vec<_>>()
            ))
        })
    }
    fn step_index(&self, step: isize, n: usize) -> PyResult<usize> {
        let j = if step < 0 { step + n as isize } else { step };
        if (0..n as isize).contains(&j) {
            Ok(j as usize)
        } else {
            Err(msg(format!("step {step} out of range (the result has {n} steps)")))
        }
    }
    fn nv(&self) -> usize {
        self.data.dim * (self.data.dim + 1) / 2
    }
}

fn array2<'py>(py: Python<'py>, v: Vec<f64>, cols: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows = v.len().checked_div(cols).unwrap_or(0);
    PyArray1::from_vec_bound(py, v).reshape([rows, cols])
}

/// A pair record as a dict.
pub fn pair_dict<'py>(py: Python<'py>, p: &PairRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new_bound(py);
    d.set_item("name", &p.name)?;
    d.set_item("force", p.force.to_vec())?;
    d.set_item("normal_force", p.normal_force)?;
    d.set_item("tangential_force", p.tangential_force)?;
    d.set_item("contact_area", p.contact_area)?;
    d.set_item("peak_pressure", p.peak_pressure)?;
    d.set_item("mean_pressure", p.mean_pressure)?;
    d.set_item("stick_area", p.stick_area)?;
    d.set_item("slip_area", p.slip_area)?;
    d.set_item("moment", p.moment.to_vec())?;
    d.set_item("centre_of_pressure", p.centre_of_pressure.map(|c| c.to_vec()))?;
    let sides = PyList::empty_bound(py);
    for s in &p.sides {
        sides.append(pair_dict(py, s)?)?;
    }
    d.set_item("sides", sides)?;
    Ok(d)
}

fn rigid_dict<'py>(py: Python<'py>, r: &RigidRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new_bound(py);
    d.set_item("name", &r.name)?;
    d.set_item("dofs", r.dofs.clone())?;
    d.set_item("reaction", r.reaction.clone())?;
    d.set_item("applied", r.applied.clone())?;
    d.set_item("force", r.force.to_vec())?;
    d.set_item("moment", r.moment.to_vec())?;
    d.set_item("balance_error", r.balance_error)?;
    d.set_item("solves", r.solves)?;
    Ok(d)
}

/// A step record as a dict.
pub fn record_dict<'py>(py: Python<'py>, r: &StepRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new_bound(py);
    d.set_item("step", r.step)?;
    d.set_item("time", r.time)?;
    let pairs = PyList::empty_bound(py);
    for p in &r.pairs {
        pairs.append(pair_dict(py, p)?)?;
    }
    d.set_item("pairs", pairs)?;
    d.set_item("friction_dissipation", r.friction_dissipation)?;
    d.set_item("cumulative_friction_dissipation", r.cumulative_friction_dissipation)?;
    d.set_item("kinetic_energy", r.kinetic_energy)?;
    d.set_item("strain_energy", r.strain_energy)?;
    d.set_item("viscous_dissipation", r.viscous_dissipation)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("step_s", r.step_s)?;
    d.set_item("solver", &r.solver)?;
    d.set_item("fallback", r.fallback.clone())?;
    let rigid = PyList::empty_bound(py);
    for x in &r.rigid {
        rigid.append(rigid_dict(py, x)?)?;
    }
    d.set_item("rigid", rigid)?;
    Ok(d)
}

/// KKT residuals as a dict (with `max`).
pub fn kkt_dict<'py>(py: Python<'py>, k: &KktReport) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new_bound(py);
    d.set_item("equilibrium", k.equilibrium)?;
    d.set_item("penetration", k.penetration)?;
    d.set_item("negative_pressure", k.negative_pressure)?;
    d.set_item("complementarity", k.complementarity)?;
    d.set_item("friction_bound", k.friction_bound)?;
    d.set_item("stick_slip", k.stick_slip)?;
    d.set_item("slip_direction", k.slip_direction)?;
    d.set_item("displacement_scale", k.displacement_scale)?;
    d.set_item("max", k.max())?;
    Ok(d)
}

#[pymethods]
impl PyRunResult {
    /// Dimension (2 or 3).
    #[getter]
    fn dimension(&self) -> usize {
        self.data.dim
    }
    /// Body names, in model order.
    #[getter]
    fn bodies(&self) -> Vec<String> {
        self.data.bodies.iter().map(|b| b.name.clone()).collect()
    }
    /// Number of steps (records).
    #[getter]
    fn n_steps(&self) -> usize {
        self.data.records.len()
    }
    fn __len__(&self) -> usize {
        self.data.records.len()
    }
    /// The time of each step, shape `(n_steps,)`.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec_bound(py, self.data.records.iter().map(|r| r.time).collect())
    }
    /// The step records as dicts: `step`, `time`, `pairs` (per contact pair: `force`,
    /// `normal_force`, `tangential_force`, `contact_area`, `peak_pressure`, `mean_pressure`,
    /// `stick_area`, `slip_area`, `moment`, `centre_of_pressure`, `sides`), energies,
    /// `iterations`, `step_s`, `solver`, `fallback`, `rigid` (rigid-body states).
    #[getter]
    fn records<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let l = PyList::empty_bound(py);
        for r in &self.data.records {
            l.append(record_dict(py, r)?)?;
        }
        Ok(l)
    }
    /// The per-pair figures of one step (default: the last) as a dict `{pair name: dict}`.
    #[pyo3(signature = (step = -1))]
    fn pairs<'py>(&self, py: Python<'py>, step: isize) -> PyResult<Bound<'py, PyDict>> {
        let i = self.step_index(step, self.data.records.len())?;
        let d = PyDict::new_bound(py);
        for p in &self.data.records[i].pairs {
            d.set_item(&p.name, pair_dict(py, p)?)?;
        }
        Ok(d)
    }
    /// The rigid-body states of one step (default: the last) as a dict `{rigid body name:
    /// dict}`: `dofs` (coordinates `q`, lengths and radians, `dof_names` order), `reaction`
    /// (the generalised forces `Q` the elastic bodies exert), `applied` (the applied
    /// generalised force `F` of each force-controlled coordinate, `None` if prescribed), `force` and
    /// `moment` (resultant on the rigid body and its moment about the moved reference point),
    /// `balance_error`, `solves`.
    #[pyo3(signature = (step = -1))]
    fn rigid_bodies<'py>(&self, py: Python<'py>, step: isize) -> PyResult<Bound<'py, PyDict>> {
        let i = self.step_index(step, self.data.records.len())?;
        let d = PyDict::new_bound(py);
        for r in &self.data.records[i].rigid {
            d.set_item(&r.name, rigid_dict(py, r)?)?;
        }
        Ok(d)
    }
    /// One figure of one pair over the steps, shape `(n_steps,)`: `quantity` is a scalar key
    /// of the pair dicts (`normal_force`, `contact_area`, `peak_pressure`, …).
    fn pair_history<'py>(
        &self,
        py: Python<'py>,
        pair: &str,
        quantity: &str,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let mut out = Vec::with_capacity(self.data.records.len());
        for r in &self.data.records {
            let p = r
                .pairs
                .iter()
                .find(|p| p.name == pair)
                .ok_or_else(|| msg(format!("no contact pair `{pair}` in step {}", r.step)))?;
            out.push(match quantity {
                "normal_force" => p.normal_force,
                "tangential_force" => p.tangential_force,
                "contact_area" => p.contact_area,
                "peak_pressure" => p.peak_pressure,
                "mean_pressure" => p.mean_pressure,
                "stick_area" => p.stick_area,
                "slip_area" => p.slip_area,
                _ => return Err(msg(format!("unknown pair quantity `{quantity}`"))),
            });
        }
        Ok(PyArray1::from_vec_bound(py, out))
    }
    /// Node coordinates of a body, shape `(n_nodes, D)`.
    fn nodes<'py>(&self, py: Python<'py>, body: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let b = self.body(body)?;
        array2(py, self.data.bodies[b].nodes.clone(), self.data.dim)
    }
    /// Cells (node indices) of a body, shape `(n_cells, D + 1)`.
    fn cells<'py>(&self, py: Python<'py>, body: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<u64>>> {
        let b = self.body(body)?;
        let v: Vec<u64> = self.data.bodies[b].cells.iter().map(|&c| c as u64).collect();
        let rows = v.len() / (self.data.dim + 1);
        PyArray1::from_vec_bound(py, v).reshape([rows, self.data.dim + 1])
    }
    /// Nodal displacements of a body, shape `(n_nodes, D)`; the last step, or `step` if the
    /// run kept every step (`keep_steps=True`).
    #[pyo3(signature = (body = None, step = None))]
    fn displacement<'py>(
        &self,
        py: Python<'py>,
        body: Option<&Bound<'py, PyAny>>,
        step: Option<isize>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let b = match body {
            Some(b) => self.body(b)?,
            None => 0,
        };
        let u = match step {
            None => self.data.displacement.get(b).cloned().unwrap_or_default(),
            Some(s) => {
                if self.data.step_displacement.is_empty() {
                    return Err(msg(
                        "this run kept only the last step's displacement: run with keep_steps=True",
                    ));
                }
                let i = self.step_index(s, self.data.step_displacement.len())?;
                self.data.step_displacement[i][b].clone()
            }
        };
        array2(py, u, self.data.dim)
    }
    /// Nodal contact pressure `Λ_n` of a body (0 away from its contact nodes), shape
    /// `(n_nodes,)`, at `step` (default the last).
    #[pyo3(signature = (body = None, step = -1))]
    fn contact_pressure<'py>(
        &self,
        py: Python<'py>,
        body: Option<&Bound<'py, PyAny>>,
        step: isize,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let b = match body {
            Some(b) => self.body(b)?,
            None => 0,
        };
        if self.data.pressure.is_empty() {
            let n = self.data.bodies[b].nodes.len() / self.data.dim.max(1);
            return Ok(PyArray1::from_vec_bound(py, vec![0.0; n]));
        }
        let i = self.step_index(step, self.data.pressure.len())?;
        Ok(PyArray1::from_vec_bound(py, self.data.pressure[i][b].clone()))
    }
    /// Voigt stress of a body at the last step: recovered to nodes (`location="node"`,
    /// shape `(n_nodes, nv)`) or per cell (`location="cell"`, `(n_cells, nv)`); `nv` = 3 in 2D
    /// (`σ_xx, σ_yy, σ_xy`), 6 in 3D (`σ_xx, σ_yy, σ_zz, σ_yz, σ_xz, σ_xy`).
    #[pyo3(signature = (body = None, location = "node"))]
    fn stress<'py>(
        &self,
        py: Python<'py>,
        body: Option<&Bound<'py, PyAny>>,
        location: &str,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let b = match body {
            Some(b) => self.body(b)?,
            None => 0,
        };
        let s = &self.data.stress[b];
        match location {
            "node" => array2(py, s.nodal_stress.clone(), self.nv()),
            "cell" => array2(py, s.cell_stress.clone(), self.nv()),
            _ => Err(msg(format!("location must be \"node\" or \"cell\", got {location:?}"))),
        }
    }
    /// Von Mises stress of a body at the last step, at nodes or per cell.
    #[pyo3(signature = (body = None, location = "node"))]
    fn von_mises<'py>(
        &self,
        py: Python<'py>,
        body: Option<&Bound<'py, PyAny>>,
        location: &str,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let b = match body {
            Some(b) => self.body(b)?,
            None => 0,
        };
        let s = &self.data.stress[b];
        match location {
            "node" => Ok(PyArray1::from_vec_bound(py, s.nodal_von_mises.clone())),
            "cell" => Ok(PyArray1::from_vec_bound(py, s.cell_von_mises.clone())),
            _ => Err(msg(format!("location must be \"node\" or \"cell\", got {location:?}"))),
        }
    }
    /// Strain energy of each body at the last step.
    #[getter]
    fn strain_energy(&self) -> Vec<f64> {
        self.data.stress.iter().map(|s| s.strain_energy).collect()
    }
    /// The contact rows of the last step as a dict of arrays: `pair` (list of names), `body`,
    /// `node` (int arrays), `position` (`(n, D)`), `pressure` (`Λ_n`).
    #[getter]
    fn contact<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new_bound(py);
        let rows = &self.data.contact;
        d.set_item("pair", rows.iter().map(|r| r.pair.clone()).collect::<Vec<_>>())?;
        d.set_item("body", PyArray1::from_vec_bound(py, rows.iter().map(|r| r.body as u64).collect()))?;
        d.set_item("node", PyArray1::from_vec_bound(py, rows.iter().map(|r| r.node as u64).collect()))?;
        d.set_item(
            "position",
            array2(py, rows.iter().flat_map(|r| r.position.clone()).collect(), self.data.dim)?,
        )?;
        d.set_item("pressure", PyArray1::from_vec_bound(py, rows.iter().map(|r| r.pressure).collect()))?;
        Ok(d)
    }
    /// KKT residuals of the last step (`equilibrium`, `penetration`, `negative_pressure`,
    /// `complementarity`, `friction_bound`, `stick_slip`, `slip_direction`, `max`), `None`
    /// without contact pairs.
    #[getter]
    fn kkt<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.data.kkt.as_ref().map(|k| kkt_dict(py, k)).transpose()
    }
    /// Reduced unknowns of the system.
    #[getter]
    fn n_dofs(&self) -> usize {
        self.data.n_dofs
    }
    /// Contact nodes of all pairs.
    #[getter]
    fn contact_nodes(&self) -> usize {
        self.data.contact_nodes
    }
    /// The contact solver's name.
    #[getter]
    fn solver(&self) -> String {
        self.data.solver.clone()
    }
    /// Set-up time (assembly, factorisation, contact geometry), s.
    #[getter]
    fn setup_s(&self) -> f64 {
        self.data.setup_s
    }
    /// Wall time of the run, s.
    #[getter]
    fn total_s(&self) -> f64 {
        self.data.total_s
    }
    /// Session solves: whether the solve was warm-started (`None` for runs).
    #[getter]
    fn warm_started(&self) -> Option<bool> {
        self.data.warm_started
    }
    /// The body as a `meshio.Mesh` with point data `displacement`, `contact_pressure`,
    /// `von_mises`, `stress` and cell data `von_mises`, `stress` (needs `meshio`).
    #[pyo3(signature = (body = None, step = -1))]
    fn to_meshio<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
        body: Option<&Bound<'py, PyAny>>,
        step: isize,
    ) -> PyResult<Bound<'py, PyAny>> {
        let helper = py.import_bound("synovia._meshio")?;
        let body = match body {
            Some(b) => b.clone(),
            None => 0i64.into_py(py).into_bound(py),
        };
        helper.call_method1("result_to_meshio", (slf, body, step))
    }
    fn __repr__(&self) -> String {
        format!(
            "RunResult(dimension={}, bodies={:?}, steps={}, solver={:?})",
            self.data.dim,
            self.data.bodies.iter().map(|b| b.name.as_str()).collect::<Vec<_>>(),
            self.data.records.len(),
            self.data.solver
        )
    }
}
