//! The small model shared by the C example's reference (`examples/reference.rs`) and the
//! tests: a 2D rounded punch (a block whose bottom is an arc of radius `R`) pressed onto the
//! rigid plane `y = 0` with Coulomb friction, its top moved in three quasi-static steps.
//!
//! `examples/c/main.c` builds the same mesh with the same formulas (keep them in sync).
#![allow(dead_code)]

use synovia::builder::JointModel;
use synovia::contact_ops::operators::PlaneObstacle;
use synovia::fem::ComponentMask;
use synovia::material::plane_strain;
use synovia::mesh::math::{Point, Vector};
use synovia::mesh::{BoundaryKind, Mesh};
use synovia_capi::{syn_last_error_message, SynMeshArrays, SynStatus};

/// Elements across.
pub const NX: usize = 24;
/// Elements up.
pub const NY: usize = 10;
/// Radius of the bottom arc.
pub const RADIUS: f64 = 2.0;
/// Young's modulus and Poisson's ratio (plane strain).
pub const YOUNG: f64 = 1000.0;
/// Poisson's ratio.
pub const POISSON: f64 = 0.3;
/// Coulomb coefficient against the plane.
pub const FRICTION: f64 = 0.3;
/// Facet tags.
pub const TAG_BOTTOM: i32 = 1;
/// Facet tag of the top.
pub const TAG_TOP: i32 = 2;
/// The times of the three steps and the displacement of the top at each.
pub const STEPS: [(f64, [f64; 2]); 3] = [(0.0, [0.0, -0.05]), (1.0, [0.004, -0.06]), (2.0, [0.01, -0.06])];

/// The mesh as flat arrays: coordinates (x, y per node), triangles (3 per element, counter-
/// clockwise), boundary edges (2 nodes each) and their tags.
pub struct Arrays {
    /// Node coordinates.
    pub coords: Vec<f64>,
    /// Triangles.
    pub elements: Vec<i32>,
    /// Boundary edges.
    pub facets: Vec<i32>,
    /// Tags of the edges.
    pub tags: Vec<i32>,
}

/// The punch mesh: `(NX + 1) (NY + 1)` nodes, node `(i, j)` = `j (NX + 1) + i` at
/// `x = −1 + 2 i / NX`, `y = b(x) + (1 − b(x)) j / NY` with `b(x) = R − sqrt(R² − x²)`.
pub fn punch() -> Arrays {
    let mut coords = Vec::new();
    for j in 0..=NY {
        for i in 0..=NX {
            let x = -1.0 + 2.0 * (i as f64) / (NX as f64);
            let b = RADIUS - (RADIUS * RADIUS - x * x).sqrt();
            let y = b + (1.0 - b) * (j as f64) / (NY as f64);
            coords.push(x);
            coords.push(y);
        }
    }
    let id = |i: usize, j: usize| (j * (NX + 1) + i) as i32;
    let mut elements = Vec::new();
    for j in 0..NY {
        for i in 0..NX {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            elements.extend_from_slice(&[a, b, c, a, c, d]);
        }
    }
    let mut facets = Vec::new();
    let mut tags = Vec::new();
    for i in 0..NX {
        facets.extend_from_slice(&[id(i, 0), id(i + 1, 0)]);
        tags.push(TAG_BOTTOM);
    }
    for i in 0..NX {
        facets.extend_from_slice(&[id(i, NY), id(i + 1, NY)]);
        tags.push(TAG_TOP);
    }
    Arrays { coords, elements, facets, tags }
}

/// The displacement of the top at time `t` (the value of the step at or before `t`).
pub fn top_displacement(t: f64) -> Vector<2> {
    let mut v = STEPS[0].1;
    for (time, value) in STEPS {
        if t >= time {
            v = value;
        }
    }
    Vector::<2>::new(v[0], v[1])
}

/// The punch model through the Rust API.
pub fn joint_model() -> Result<JointModel<2>, Box<dyn std::error::Error>> {
    let a = punch();
    let nodes: Vec<Point<2>> = a.coords.chunks(2).map(|c| Point::<2>::new(c[0], c[1])).collect();
    let cells: Vec<usize> = a.elements.iter().map(|&i| i as usize).collect();
    let mut mesh = Mesh::<2>::new(nodes, cells)?;
    for (tag, name) in [(TAG_BOTTOM, "bottom"), (TAG_TOP, "top")] {
        let facets: Vec<Vec<usize>> = a
            .facets
            .chunks(2)
            .zip(&a.tags)
            .filter(|(_, &t)| t == tag)
            .map(|(f, _)| f.iter().map(|&i| i as usize).collect())
            .collect();
        mesh.add_boundary_part_from_facets(name, BoundaryKind::TractionFree, &facets)?;
    }
    let mut jm = JointModel::<2>::new();
    let b = jm.add_body("punch", mesh, plane_strain(YOUNG, POISSON)?)?;
    jm.prescribe_field(b, "top", ComponentMask::ALL, |_x, t| top_displacement(t))?;
    let plane = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::y())?;
    jm.contact_rigid("floor", b, "bottom", plane, FRICTION)?;
    Ok(jm)
}

/// The normal contact force after each of the three steps, through the Rust API
/// (`JointModel::run_quasistatic`).
pub fn reference_forces() -> Result<Vec<f64>, Box<dyn std::error::Error>> {
    let jm = joint_model()?;
    let times: Vec<f64> = STEPS.iter().map(|s| s.0).collect();
    let res = jm.run_quasistatic(&times)?;
    Ok(res.records.iter().map(|r| r.pairs[0].normal_force).collect())
}

/// The message of the last failed C API call on this thread.
pub fn last_error() -> String {
    let mut buf = vec![0 as std::ffi::c_char; 1024];
    // SAFETY: `buf` is writable for its length.
    unsafe { syn_last_error_message(buf.as_mut_ptr(), buf.len()) };
    // SAFETY: syn_last_error_message NUL-terminates within `buf`.
    unsafe { std::ffi::CStr::from_ptr(buf.as_ptr()) }.to_string_lossy().into_owned()
}

/// Asserts that a C API call succeeded (with its error message otherwise).
#[track_caller]
pub fn ok(status: SynStatus) {
    assert_eq!(status, SynStatus::Ok, "{}", last_error());
}

/// The 2D arrays of `a` for `syn_model_from_arrays`, with the body of each element and one
/// `E`, `ν` per body (the slices must outlive the returned view).
pub fn arrays(a: &Arrays, body: &[i32], young: &[f64], poisson: &[f64]) -> SynMeshArrays {
    SynMeshArrays {
        dimension: 2,
        coords: a.coords.as_ptr(),
        coords_len: a.coords.len(),
        elements: a.elements.as_ptr(),
        elements_len: a.elements.len(),
        element_body: body.as_ptr(),
        element_body_len: body.len(),
        facets: a.facets.as_ptr(),
        facets_len: a.facets.len(),
        facet_tags: a.tags.as_ptr(),
        facet_tags_len: a.tags.len(),
        young: young.as_ptr(),
        young_len: young.len(),
        poisson: poisson.as_ptr(),
        poisson_len: poisson.len(),
    }
}
