//! Rigid bodies with mixed control, rigid contact shapes and STL surfaces from Python:
//! `synovia.Surface`, `synovia.Shape`, `synovia.read_stl`, and the generic bodies of the
//! `Model` methods that add rigid bodies (the [`synovia::rigid`] API, as
//! `synovia-scenario` translates a `[[rigid_body]]`), and the pose inputs that
//! `Session.set_pose` sets ([`synovia::rigid::PoseInput`]).

use std::any::Any;
use std::path::PathBuf;
use std::sync::Arc;

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use synovia::builder::JointModel;
use synovia::contact_ops::operators::{CylinderObstacle, PlaneObstacle, SignedDistance, SphereObstacle};
use synovia::contact_ops::SurfaceObstacle;
use synovia::mesh::math::Point;
use synovia::mesh::TriangleSurface;
use synovia::rigid::{PoseInput, RigidBody};

use crate::error::{err, msg};
use crate::history::history;
use crate::model::{body_id, float_array, floats, index_array, point, vector};

/// A triangle surface in 3D (`synovia.Surface`), e.g. read from an STL file by
/// `synovia.read_stl`: the boundary of a rigid shape (`Shape.surface`).
#[pyclass(name = "Surface", module = "synovia", frozen)]
#[derive(Debug, Clone)]
pub struct PySurface {
    pub(crate) surface: Arc<TriangleSurface>,
}

#[pymethods]
impl PySurface {
    /// A surface from `vertices` `(n, 3)` and `triangles` `(m, 3)` (vertex indices, the
    /// right-hand rule gives the normal). Checks finiteness, indices and non-degenerate
    /// triangles.
    #[new]
    fn new(vertices: &Bound<'_, PyAny>, triangles: &Bound<'_, PyAny>) -> PyResult<Self> {
        let v: Vec<Point<3>> =
            float_array(vertices, 3, "vertices")?.iter().map(|r| Point::<3>::new(r[0], r[1], r[2])).collect();
        let t: Vec<[usize; 3]> =
            index_array(triangles, 3, "triangles")?.iter().map(|r| [r[0], r[1], r[2]]).collect();
        let surface = TriangleSurface::new(v, t).map_err(err)?;
        Ok(Self { surface: Arc::new(surface) })
    }
    /// The vertices, shape `(n, 3)`.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v: Vec<f64> = self.surface.vertices().iter().flat_map(|p| [p[0], p[1], p[2]]).collect();
        let n = v.len() / 3;
        PyArray1::from_vec_bound(py, v).reshape([n, 3])
    }
    /// The triangles (vertex indices), shape `(m, 3)`.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u64>>> {
        let t: Vec<u64> = self.surface.triangles().iter().flat_map(|t| t.map(|i| i as u64)).collect();
        let n = t.len() / 3;
        PyArray1::from_vec_bound(py, t).reshape([n, 3])
    }
    /// Total area.
    #[getter]
    fn area(&self) -> f64 {
        self.surface.area()
    }
    /// The signed enclosed volume (positive for a closed surface with outward normals;
    /// meaningless for an open one).
    #[getter]
    fn signed_volume(&self) -> f64 {
        self.surface.signed_volume()
    }
    /// Axis-aligned bounding box `(lo, hi)` of the vertices used by triangles.
    #[getter]
    fn bounding_box(&self) -> Option<(Vec<f64>, Vec<f64>)> {
        self.surface
            .bounding_box()
            .map(|(lo, hi)| (lo.iter().copied().collect(), hi.iter().copied().collect()))
    }
    /// The surface scaled by `factor` about the origin (units: 1000 from m to mm).
    fn scaled(&self, factor: f64) -> PyResult<Self> {
        Ok(Self { surface: Arc::new(self.surface.scaled(factor).map_err(err)?) })
    }
    /// Whether the surface bounds a solid (closed, manifold, consistently and outward
    /// oriented, not crossing itself): what `Shape.surface(..., solid=True)` needs.
    #[getter]
    fn is_closed_solid(&self) -> bool {
        self.surface.check_closed_solid().is_ok()
    }
    fn __len__(&self) -> usize {
        self.surface.len()
    }
    fn __repr__(&self) -> String {
        format!("Surface(vertices={}, triangles={})", self.surface.vertices().len(), self.surface.len())
    }
}

/// Reads an STL file (ASCII or binary) as a `Surface`; `scale` multiplies the coordinates
/// (units, e.g. 1000 for a file in metres in a model in millimetres).
#[pyfunction]
#[pyo3(signature = (path, scale = None))]
pub fn read_stl(py: Python<'_>, path: PathBuf, scale: Option<f64>) -> PyResult<PySurface> {
    let surface = py.allow_threads(move || -> Result<TriangleSurface, String> {
        let s = synovia::io::read_stl(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        match scale {
            Some(f) => s.scaled(f).map_err(|e| e.to_string()),
            None => Ok(s),
        }
    });
    Ok(PySurface { surface: Arc::new(surface.map_err(msg)?) })
}

#[derive(Debug, Clone)]
enum ShapeKind {
    Plane { point: Vec<f64>, normal: Vec<f64> },
    Sphere { center: Vec<f64>, radius: f64, cavity: bool },
    Cylinder { point: Vec<f64>, axis: Vec<f64>, radius: f64, cavity: bool },
    Surface { obstacle: Arc<SurfaceObstacle>, solid: bool },
}

/// A rigid contact shape (`synovia.Shape`): a fixed rigid obstacle
/// (`Model.contact_obstacle`) or the shape of a rigid body (`Model.contact_rigid_body`,
/// given in the body's own frame and placed by its pose). The signed distance is positive on
/// the side the elastic body is on.
#[pyclass(name = "Shape", module = "synovia", frozen)]
#[derive(Debug, Clone)]
pub struct PyShape {
    kind: ShapeKind,
}

#[pymethods]
impl PyShape {
    /// The half-space bounded by the plane through `point` with outward `normal` (the side
    /// the elastic body is on).
    #[staticmethod]
    fn plane(point: &Bound<'_, PyAny>, normal: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self {
            kind: ShapeKind::Plane { point: floats(point, "point")?, normal: floats(normal, "normal")? },
        })
    }
    /// A ball (`cavity=False`: the body is outside) or a spherical cavity (`cavity=True`:
    /// the body is inside) of `radius` about `center`; a disc in 2D.
    #[staticmethod]
    #[pyo3(signature = (center, radius, cavity = false))]
    fn sphere(center: &Bound<'_, PyAny>, radius: f64, cavity: bool) -> PyResult<Self> {
        Ok(Self { kind: ShapeKind::Sphere { center: floats(center, "center")?, radius, cavity } })
    }
    /// A cylinder (3D) through `point` with `axis` and `radius` (`cavity=True`: the body is
    /// inside).
    #[staticmethod]
    #[pyo3(signature = (point, axis, radius, cavity = false))]
    fn cylinder(
        point: &Bound<'_, PyAny>,
        axis: &Bound<'_, PyAny>,
        radius: f64,
        cavity: bool,
    ) -> PyResult<Self> {
        Ok(Self {
            kind: ShapeKind::Cylinder {
                point: floats(point, "point")?,
                axis: floats(axis, "axis")?,
                radius,
                cavity,
            },
        })
    }
    /// The rigid body bounded by a triangle `surface` (3D, `SurfaceObstacle`):
    /// `solid=True` (default) needs a closed surface with outward normals (the free space is
    /// outside); `solid=False` accepts an open, consistently oriented patch whose normals
    /// point into the free space. The surface is checked here. `subdivide=n` (0–4) smooths a
    /// faceted surface by `n` levels of Loop subdivision, edges whose facets meet at more
    /// than `crease_angle_deg` (default 30) kept sharp (a solid keeps its control surface for
    /// queries beyond a pair's search distance: `SurfaceObstacle::smoothed_solid`).
    /// `fillet=r` rounds the concave edges by cylinders of radius `r` tangent to both faces,
    /// each within `fillet_max_offset` of the faceted surface (default: no bound;
    /// `SurfaceObstacle::with_concave_fillet`, docs/nonlinear.md "A node in a concave corner").
    #[staticmethod]
    #[pyo3(signature = (surface, solid = true, subdivide = 0, crease_angle_deg = 30.0, fillet = 0.0, fillet_max_offset = None))]
    fn surface(
        py: Python<'_>,
        surface: PyRef<'_, PySurface>,
        solid: bool,
        subdivide: usize,
        crease_angle_deg: f64,
        fillet: f64,
        fillet_max_offset: Option<f64>,
    ) -> PyResult<Self> {
        let smoothing = (subdivide, crease_angle_deg.to_radians());
        let fillet = (fillet, fillet_max_offset.unwrap_or(f64::INFINITY));
        surface_shape(py, TriangleSurface::clone(&surface.surface), solid, smoothing, fillet, None)
    }
    /// `Shape.surface(read_stl(path, scale), solid, subdivide, crease_angle_deg, fillet,
    /// fillet_max_offset)`: the rigid body bounded by the surface of an STL file.
    #[staticmethod]
    #[pyo3(signature = (path, scale = None, solid = true, subdivide = 0, crease_angle_deg = 30.0, fillet = 0.0, fillet_max_offset = None))]
    #[allow(clippy::too_many_arguments)]
    fn stl(
        py: Python<'_>,
        path: PathBuf,
        scale: Option<f64>,
        solid: bool,
        subdivide: usize,
        crease_angle_deg: f64,
        fillet: f64,
        fillet_max_offset: Option<f64>,
    ) -> PyResult<Self> {
        let s = read_stl(py, path.clone(), scale)?;
        let smoothing = (subdivide, crease_angle_deg.to_radians());
        let fillet = (fillet, fillet_max_offset.unwrap_or(f64::INFINITY));
        surface_shape(py, TriangleSurface::clone(&s.surface), solid, smoothing, fillet, Some(&path))
    }
    /// The signed distance `φ(x)` of points `x` (`(n, D)` or one point) to the shape
    /// (positive on the elastic body's side), in the shape's own frame.
    fn distance<'py>(&self, py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let flat = floats(x, "x")?;
        let d = match &self.kind {
            ShapeKind::Cylinder { .. } | ShapeKind::Surface { .. } => 3,
            ShapeKind::Plane { point, .. } | ShapeKind::Sphere { center: point, .. } => point.len(),
        };
        if d == 0 || flat.len() % d != 0 {
            return Err(msg(format!("x must hold points of {d} coordinates")));
        }
        let out: Vec<f64> = if d == 2 {
            let s = shape_for::<2>(self)?;
            flat.chunks(2).map(|c| s.distance(&Point::<2>::new(c[0], c[1]))).collect()
        } else {
            let s = shape_for::<3>(self)?;
            flat.chunks(3).map(|c| s.distance(&Point::<3>::new(c[0], c[1], c[2]))).collect()
        };
        Ok(PyArray1::from_vec_bound(py, out))
    }
    fn __repr__(&self) -> String {
        match &self.kind {
            ShapeKind::Surface { obstacle, solid } => {
                format!("Shape.surface(triangles={}, solid={solid})", obstacle.surface().len())
            }
            k => format!("Shape({k:?})"),
        }
    }
}

/// The shape bounded by `surface` (checked: closed solid, or an oriented open patch).
fn surface_shape(
    py: Python<'_>,
    surface: TriangleSurface,
    solid: bool,
    (levels, crease_angle): (usize, f64),
    (fillet, fillet_max_offset): (f64, f64),
    file: Option<&std::path::Path>,
) -> PyResult<PyShape> {
    let built = py.allow_threads(move || {
        let obstacle = if solid {
            SurfaceObstacle::smoothed_solid(surface, levels, crease_angle).map_err(|e| {
                format!("{e} (a solid surface must be closed; solid=False accepts an open patch)")
            })
        } else {
            let smooth = surface.loop_subdivided(levels, crease_angle).map_err(|e| e.to_string())?;
            SurfaceObstacle::new(smooth).map_err(|e| e.to_string())
        }?;
        obstacle.with_concave_fillet(fillet, fillet_max_offset).map_err(|e| format!("fillet: {e}"))
    });
    let obstacle = built.map_err(|e| match file {
        Some(f) => msg(format!("{}: {e}", f.display())),
        None => msg(e),
    })?;
    Ok(PyShape { kind: ShapeKind::Surface { obstacle: Arc::new(obstacle), solid } })
}

/// The signed distance of a shape in dimension `D`.
pub(crate) fn shape_for<const D: usize>(s: &PyShape) -> PyResult<Arc<dyn SignedDistance<D>>> {
    let any: Box<dyn Any> = match &s.kind {
        ShapeKind::Plane { point: p, normal } => {
            let o =
                PlaneObstacle::new(point::<D>(p, "point")?, vector::<D>(normal, "normal")?).map_err(err)?;
            return Ok(Arc::new(o));
        }
        ShapeKind::Sphere { center, radius, cavity } => {
            let o = SphereObstacle::new(point::<D>(center, "center")?, *radius, *cavity).map_err(err)?;
            return Ok(Arc::new(o));
        }
        ShapeKind::Cylinder { point: p, axis, radius, cavity } => {
            let o =
                CylinderObstacle::new(point::<3>(p, "point")?, vector::<3>(axis, "axis")?, *radius, *cavity)
                    .map_err(err)?;
            let d: Arc<dyn SignedDistance<3>> = Arc::new(o);
            Box::new(d)
        }
        ShapeKind::Surface { obstacle, .. } => {
            let d: Arc<dyn SignedDistance<3>> = obstacle.clone();
            Box::new(d)
        }
    };
    any.downcast::<Arc<dyn SignedDistance<D>>>()
        .map(|b| *b)
        .map_err(|_| msg(format!("cylinder and surface shapes are 3D only (this model is {D}D)")))
}

/// The pose input of a rigid body whose pose is set between solves (`pose_input=True`).
#[derive(Debug, Clone)]
pub(crate) enum PoseSlot {
    D2(PoseInput<2>),
    D3(PoseInput<3>),
}

/// The pose inputs of a model's rigid bodies, by rigid body name.
pub(crate) type PoseInputs = Vec<(String, PoseSlot)>;

/// The controls of a `Model.add_rigid_body` call.
pub(crate) struct RigidSpec<'a, 'py> {
    pub name: &'a str,
    pub center: Option<&'a Bound<'py, PyAny>>,
    pub rotation_order: Option<&'a str>,
    pub prescribe: Option<&'a Bound<'py, PyDict>>,
    pub force: Option<&'a Bound<'py, PyDict>>,
    pub guess: Option<&'a Bound<'py, PyDict>>,
    pub pose_input: bool,
}

/// The entries `{dof name: history}` of a dict with their degree-of-freedom indices.
fn dof_entries<'py, const D: usize>(
    rigid: &str,
    d: Option<&Bound<'py, PyDict>>,
) -> PyResult<Vec<(String, usize, Bound<'py, PyAny>)>> {
    let mut out = Vec::new();
    if let Some(d) = d {
        for (k, v) in d.iter() {
            let name: String =
                k.extract().map_err(|_| msg("rigid degrees of freedom are given by name (str)"))?;
            let index =
                RigidBody::<D>::dof_index(&name).map_err(|e| msg(format!("rigid body `{rigid}`: {e}")))?;
            out.push((name, index, v));
        }
    }
    Ok(out)
}

/// Adds a rigid body (as `synovia-scenario` does for a `[[rigid_body]]`): its reference point,
/// rotation order, then per degree of freedom (by name) a prescribed coordinate history or a
/// generalised force history (with an optional predictor); with `pose_input`, every degree of
/// freedom not otherwise controlled follows a pose set between solves.
pub(crate) fn add_rigid_body<const D: usize>(
    j: &mut JointModel<D>,
    spec: &RigidSpec<'_, '_>,
) -> PyResult<(usize, Option<PoseInput<D>>)> {
    let centre = match spec.center {
        Some(c) => point::<D>(&floats(c, "center")?, "center")?,
        None => Point::<D>::zeros(),
    };
    let mut body = RigidBody::<D>::new(spec.name, centre).map_err(err)?;
    if let Some(order) = spec.rotation_order {
        if D != 3 {
            return Err(msg(format!("rigid body `{}`: a rotation order is 3D only", spec.name)));
        }
        body = body.with_rotation_order(order).map_err(err)?;
    }
    let input = spec.pose_input.then(PoseInput::<D>::new);
    if let Some(input) = &input {
        body = body.prescribe_pose(input);
    }
    let prescribed = dof_entries::<D>(spec.name, spec.prescribe)?;
    let forced = dof_entries::<D>(spec.name, spec.force)?;
    let guesses = dof_entries::<D>(spec.name, spec.guess)?;
    for (name, index, _) in &prescribed {
        if forced.iter().any(|(_, i, _)| i == index) {
            return Err(msg(format!(
                "rigid body `{}`: degree of freedom `{name}` is both prescribed and force-controlled",
                spec.name
            )));
        }
    }
    for (name, index, _) in &guesses {
        if !forced.iter().any(|(_, i, _)| i == index) {
            return Err(msg(format!(
                "rigid body `{}`: a guess applies to a force-controlled degree of freedom, `{name}` is not one",
                spec.name
            )));
        }
    }
    for (_, index, h) in &prescribed {
        body = body.prescribe(*index, history(Some(h))?).map_err(err)?;
    }
    for (_, index, h) in &forced {
        let load = history(Some(h))?;
        body = match guesses.iter().find(|(_, i, _)| i == index) {
            Some((_, _, g)) => body.force_with_guess(*index, load, history(Some(g))?),
            None => body.force(*index, load),
        }
        .map_err(err)?;
    }
    let id = j.add_rigid_body(body).map_err(err)?;
    Ok((id, input))
}

/// `Model.tie_to_rigid_body`.
pub(crate) fn tie<const D: usize>(
    j: &mut JointModel<D>,
    body: &Bound<'_, PyAny>,
    part: &str,
    rigid: &str,
) -> PyResult<()> {
    let id = body_id(j, body)?;
    j.tie_to_rigid_body(id, part, rigid).map_err(err)?;
    Ok(())
}

/// `Model.contact_rigid_body`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn contact<const D: usize>(
    j: &mut JointModel<D>,
    name: &str,
    body: &Bound<'_, PyAny>,
    part: &str,
    rigid: &str,
    shape: &PyShape,
    friction: f64,
    search_distance: Option<f64>,
) -> PyResult<()> {
    let id = body_id(j, body)?;
    let s = shape_for::<D>(shape)?;
    j.contact_rigid_body(name, id, part, rigid, s, friction).map_err(err)?;
    if let Some(d) = search_distance {
        j.search_distance(name, d).map_err(err)?;
    }
    Ok(())
}

/// Sets the pose of the rigid body `rigid` (`Session.set_pose`, `Model.set_pose`):
/// `translation` of its reference point and, in 3D, one of `quaternion` `[w, x, y, z]`,
/// `axis` with `angle`, or a 3 × 3 `rotation` matrix; in 2D, `angle`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn set_pose(
    inputs: &PoseInputs,
    rigid: &str,
    translation: &Bound<'_, PyAny>,
    quaternion: Option<&Bound<'_, PyAny>>,
    axis: Option<&Bound<'_, PyAny>>,
    angle: Option<f64>,
    rotation: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let slot = inputs.iter().find(|(n, _)| n == rigid).map(|(_, s)| s).ok_or_else(|| {
        let known: Vec<&str> = inputs.iter().map(|(n, _)| n.as_str()).collect();
        msg(format!(
            "rigid body `{rigid}` has no pose input (add it with pose_input=True; rigid bodies with one: {known:?})"
        ))
    })?;
    let t = floats(translation, "translation")?;
    let fixed = |v: Vec<f64>, n: usize, what: &str| -> PyResult<Vec<f64>> {
        if v.len() != n {
            return Err(msg(format!("{what} must have {n} components, got {}", v.len())));
        }
        Ok(v)
    };
    match slot {
        PoseSlot::D2(input) => {
            if quaternion.is_some() || axis.is_some() || rotation.is_some() {
                return Err(msg(
                    "a 2D pose is a translation and an angle (quaternion, axis and rotation are 3D)",
                ));
            }
            let t = fixed(t, 2, "translation")?;
            input.set([t[0], t[1]], angle.unwrap_or(0.0)).map_err(err)
        }
        PoseSlot::D3(input) => {
            let t = fixed(t, 3, "translation")?;
            let t = [t[0], t[1], t[2]];
            match (quaternion, axis, angle, rotation) {
                (Some(q), None, None, None) => {
                    let q = fixed(floats(q, "quaternion")?, 4, "quaternion [w, x, y, z]")?;
                    input.set_quaternion(t, [q[0], q[1], q[2], q[3]]).map_err(err)
                }
                (None, Some(a), Some(angle), None) => {
                    let a = fixed(floats(a, "axis")?, 3, "axis")?;
                    input.set_axis_angle(t, [a[0], a[1], a[2]], angle).map_err(err)
                }
                (None, None, None, Some(r)) => {
                    let rows = float_array(r, 3, "rotation")?;
                    if rows.len() != 3 {
                        return Err(msg(format!("rotation must be a 3 × 3 matrix, got {} rows", rows.len())));
                    }
                    let m = [[rows[0][0], rows[0][1], rows[0][2]], [rows[1][0], rows[1][1], rows[1][2]], [
                        rows[2][0], rows[2][1], rows[2][2],
                    ]];
                    input.set_rotation_matrix(t, m).map_err(err)
                }
                (None, None, None, None) => input.set_quaternion(t, [1.0, 0.0, 0.0, 0.0]).map_err(err),
                _ => Err(msg(
                    "give one rotation: quaternion=[w, x, y, z], axis=[x, y, z] with angle=θ, or rotation=3 × 3 matrix",
                )),
            }
        }
    }
}
