//! The C API called from Rust: a model from arrays against the same model through
//! `JointModel`, scenario files, and the documented error codes for NULL pointers, invalid
//! handles and wrong sizes.
#![allow(clippy::unwrap_used, clippy::undocumented_unsafe_blocks)]

mod common;

use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};

use synovia_capi::*;

use common::{arrays, last_error, ok};

/// The punch of `common` through the C API, with its conditions and pair.
fn punch_model() -> *mut SynModel {
    let a = common::punch();
    let body = vec![0; a.elements.len() / 3];
    let desc = arrays(&a, &body, &[common::YOUNG], &[common::POISSON]);
    let mut m = null_mut();
    ok(unsafe { syn_model_from_arrays(&desc, &mut m) });
    assert!(!m.is_null());
    let v = common::STEPS[0].1;
    ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, v.as_ptr(), 2) });
    let mut pair = usize::MAX;
    let (p, n) = ([0.0, 0.0], [0.0, 1.0]);
    ok(unsafe {
        syn_model_add_contact_plane(
            m,
            common::TAG_BOTTOM,
            p.as_ptr(),
            n.as_ptr(),
            2,
            common::FRICTION,
            &mut pair,
        )
    });
    assert_eq!(pair, 0);
    m
}

fn force(m: *mut SynModel, pair: usize) -> f64 {
    let mut f = f64::NAN;
    let mut v = [f64::NAN; 3];
    ok(unsafe { syn_model_get_pair_force(m, pair, &mut f, v.as_mut_ptr()) });
    // the normals are coordinate axes in these models: one component of the resultant is ± the
    // normal force
    assert!(
        v.iter().all(|x| x.is_finite()) && v.iter().any(|x| (x.abs() - f).abs() <= 1e-9 * f.abs()),
        "{v:?} {f}"
    );
    f
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

#[test]
fn arrays_model_matches_joint_model_over_quasistatic_steps() {
    let reference = common::reference_forces().unwrap();
    let jm = common::joint_model().unwrap();
    let times: Vec<f64> = common::STEPS.iter().map(|s| s.0).collect();
    let rust = jm.run_quasistatic(&times).unwrap();
    let m = punch_model();
    // results before any solve
    let mut f = 0.0;
    assert_eq!(unsafe { syn_model_get_pair_force(m, 0, &mut f, null_mut()) }, SynStatus::NoSolution);
    for (i, (t, v)) in common::STEPS.iter().enumerate() {
        ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, v.as_ptr(), 2) });
        if i == 0 {
            ok(syn_model_solve_static(m, *t));
        } else {
            ok(syn_model_solve_step(m, *t));
        }
        let f = force(m, 0);
        assert!(f > 0.0);
        assert!(rel(f, reference[i]) <= 1e-12, "step {i}: C API {f:e}, Rust API {:e}", reference[i]);
        let mut info = SynSolveInfo::default();
        ok(unsafe { syn_model_get_solve_info(m, &mut info) });
        assert_eq!(info.step, i);
        assert_eq!(info.time, *t);
        assert!(info.iterations > 0 && info.kkt_residual < 1e-6, "{info:?}");
        assert!(info.n_dofs > 0 && info.n_contact_nodes == common::NX + 1, "{info:?}");
    }
    // the friction state makes the steps differ from fresh static solves at the same load
    let step2 = force(m, 0);
    // displacements against the Rust API's
    let mut n = 0;
    ok(unsafe { syn_model_num_nodes(m, &mut n) });
    assert_eq!(n, (common::NX + 1) * (common::NY + 1));
    let mut u = vec![f64::NAN; 2 * n];
    ok(unsafe { syn_model_get_displacements(m, u.as_mut_ptr(), u.len()) });
    let scale = u.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
    let diff = rust.displacement[0]
        .iter()
        .enumerate()
        .fold(0.0_f64, |s, (i, ui)| s.max((ui[0] - u[2 * i]).abs()).max((ui[1] - u[2 * i + 1]).abs()));
    assert!(diff <= 1e-12 * scale, "displacements differ by {diff:e} (scale {scale:e})");
    // the top moved as prescribed
    let top = common::NY * (common::NX + 1);
    assert_eq!([u[2 * top], u[2 * top + 1]], common::STEPS[2].1);
    // contact nodes: the bottom nodes, pressures >= 0, some in contact
    let mut nc = 0;
    ok(unsafe { syn_model_num_contact_nodes(m, &mut nc) });
    let mut pair = vec![-1; nc];
    let mut node = vec![-1; nc];
    let mut xy = vec![f64::NAN; 2 * nc];
    let mut p = vec![f64::NAN; nc];
    ok(unsafe {
        syn_model_get_contact_nodes(
            m,
            nc,
            pair.as_mut_ptr(),
            node.as_mut_ptr(),
            xy.as_mut_ptr(),
            p.as_mut_ptr(),
        )
    });
    let a = common::punch();
    for r in 0..nc {
        assert_eq!(pair[r], 0);
        let g = node[r] as usize;
        assert!(g <= common::NX, "bottom node expected, got {g}");
        assert_eq!([xy[2 * r], xy[2 * r + 1]], [a.coords[2 * g], a.coords[2 * g + 1]]);
        assert!(p[r] >= 0.0);
    }
    let in_contact = p.iter().filter(|&&x| x > 0.0).count();
    assert!((3..nc).contains(&in_contact), "{in_contact} of {nc} nodes in contact");
    // NULL buffers are skipped
    ok(unsafe { syn_model_get_contact_nodes(m, nc, null_mut(), null_mut(), null_mut(), p.as_mut_ptr()) });
    // a static solve restarts the sequence: frictionless at the last load
    ok(syn_model_solve_static(m, 2.0));
    let fresh = force(m, 0);
    assert!(rel(fresh, step2) > 1e-9, "friction history had no effect: {fresh} vs {step2}");
    ok(syn_model_free(m));
}

#[test]
fn changing_values_does_not_need_a_new_model() {
    // the same load solved twice through value changes gives the same answer (to rounding)
    let m = punch_model();
    ok(syn_model_solve_static(m, 0.0));
    let f0 = force(m, 0);
    let deeper = [0.0, -0.08];
    ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, deeper.as_ptr(), 2) });
    ok(syn_model_solve_static(m, 0.0));
    assert!(force(m, 0) > f0);
    let v = common::STEPS[0].1;
    ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, v.as_ptr(), 2) });
    ok(syn_model_solve_static(m, 0.0));
    // to rounding: A⁻¹F of the repeated load is recycled from the solved loads
    assert!(rel(force(m, 0), f0) < 1e-12, "{} vs {f0}", force(m, 0));
    // steps must move forward in time
    assert_eq!(syn_model_solve_step(m, 0.0), SynStatus::InvalidArgument);
    assert!(last_error().contains("later"), "{}", last_error());
    ok(syn_model_solve_step(m, 0.5));
    ok(syn_model_free(m));
}

#[test]
fn null_pointers_and_invalid_handles_are_reported() {
    // free(NULL) is a no-op
    ok(syn_model_free(null_mut()));
    let mut out = null_mut();
    assert_eq!(unsafe { syn_model_from_arrays(null(), &mut out) }, SynStatus::NullPointer);
    assert!(out.is_null());
    assert!(last_error().contains("arrays"), "{}", last_error());
    assert_eq!(unsafe { syn_model_from_scenario(null(), &mut out) }, SynStatus::NullPointer);
    let m = punch_model();
    let a = common::punch();
    let body = vec![0; a.elements.len() / 3];
    let desc = arrays(&a, &body, &[1.0], &[0.3]);
    assert_eq!(unsafe { syn_model_from_arrays(&desc, null_mut()) }, SynStatus::NullPointer);
    let mut n = 0;
    assert_eq!(unsafe { syn_model_num_nodes(null(), &mut n) }, SynStatus::NullPointer);
    assert_eq!(unsafe { syn_model_num_nodes(m, null_mut()) }, SynStatus::NullPointer);
    assert_eq!(unsafe { syn_model_set_displacement(m, common::TAG_TOP, null(), 2) }, SynStatus::NullPointer);
    let name = CString::new("body_0").unwrap();
    let mut tag = -1;
    assert_eq!(unsafe { syn_model_part_tag(m, name.as_ptr(), null(), &mut tag) }, SynStatus::NullPointer);
    let part = CString::new("tag_2").unwrap();
    ok(unsafe { syn_model_part_tag(m, name.as_ptr(), part.as_ptr(), &mut tag) });
    assert_eq!(tag, 2);
    ok(syn_model_solve_static(m, 0.0));
    assert_eq!(unsafe { syn_model_get_displacements(m, null_mut(), 10) }, SynStatus::NullPointer);
    // made-up and freed handles
    let fake = std::ptr::without_provenance_mut::<SynModel>(0xdead_bee0);
    assert_eq!(syn_model_solve_static(fake, 0.0), SynStatus::InvalidHandle);
    assert_eq!(syn_model_free(fake), SynStatus::InvalidHandle);
    ok(syn_model_free(m));
    assert_eq!(syn_model_solve_static(m, 0.0), SynStatus::InvalidHandle);
    assert_eq!(unsafe { syn_model_num_nodes(m, &mut n) }, SynStatus::InvalidHandle);
    assert_eq!(syn_model_free(m), SynStatus::InvalidHandle);
    assert!(last_error().contains("not a live model handle"), "{}", last_error());
    // status names
    let s = unsafe { CStr::from_ptr(syn_status_name(SynStatus::InvalidHandle as i32)) };
    assert_eq!(s.to_str().unwrap(), "SYN_STATUS_INVALID_HANDLE");
    let s = unsafe { CStr::from_ptr(syn_status_name(99)) };
    assert_eq!(s.to_str().unwrap(), "SYN_STATUS_UNKNOWN");
    let v = unsafe { CStr::from_ptr(syn_version()) };
    assert_eq!(v.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
}

#[test]
fn wrong_sizes_and_indices_are_reported() {
    let a = common::punch();
    let n_el = a.elements.len() / 3;
    let body = vec![0; n_el];
    let mut m = null_mut();
    let check = |desc: &SynMeshArrays, expected: SynStatus, m: &mut *mut SynModel| {
        let s = unsafe { syn_model_from_arrays(desc, m) };
        assert_eq!(s, expected, "{}", last_error());
        assert!(m.is_null());
        assert!(!last_error().is_empty());
    };
    // element node index out of range, negative too
    let mut bad = common::punch();
    bad.elements[7] = (bad.coords.len() / 2) as i32;
    check(&arrays(&bad, &body, &[1.0], &[0.3]), SynStatus::IndexOutOfRange, &mut m);
    bad.elements[7] = -1;
    check(&arrays(&bad, &body, &[1.0], &[0.3]), SynStatus::IndexOutOfRange, &mut m);
    // one body id per element
    check(&arrays(&a, &body[1..], &[1.0], &[0.3]), SynStatus::SizeMismatch, &mut m);
    // body id out of range
    let mut body2 = body.clone();
    body2[3] = 1;
    check(&arrays(&a, &body2, &[1.0], &[0.3]), SynStatus::IndexOutOfRange, &mut m);
    // materials: counts disagree; invalid value
    check(&arrays(&a, &body, &[1.0], &[0.3, 0.3]), SynStatus::SizeMismatch, &mut m);
    check(&arrays(&a, &body, &[1.0], &[0.7]), SynStatus::ModelRejected, &mut m);
    // coordinates not a multiple of the dimension; facets vs tags
    let mut desc = arrays(&a, &body, &[1.0], &[0.3]);
    desc.coords_len -= 1;
    check(&desc, SynStatus::SizeMismatch, &mut m);
    let mut desc = arrays(&a, &body, &[1.0], &[0.3]);
    desc.facet_tags_len -= 1;
    check(&desc, SynStatus::SizeMismatch, &mut m);
    // a NULL non-empty array; a bad dimension
    let mut desc = arrays(&a, &body, &[1.0], &[0.3]);
    desc.elements = null();
    check(&desc, SynStatus::NullPointer, &mut m);
    let mut desc = arrays(&a, &body, &[1.0], &[0.3]);
    desc.dimension = 4;
    check(&desc, SynStatus::InvalidArgument, &mut m);
    // an interior edge is not a boundary facet
    let mut bad = common::punch();
    bad.facets[0] = (common::NX + 2) as i32;
    check(&arrays(&bad, &body, &[1.0], &[0.3]), SynStatus::ModelRejected, &mut m);

    let m = punch_model();
    // condition values of the wrong size, unknown tags, conflicting conditions
    let v3 = [0.0; 3];
    assert_eq!(
        unsafe { syn_model_set_displacement(m, common::TAG_TOP, v3.as_ptr(), 3) },
        SynStatus::SizeMismatch
    );
    assert_eq!(unsafe { syn_model_set_traction(m, 42, v3.as_ptr(), 2) }, SynStatus::InvalidArgument);
    assert_eq!(syn_model_set_pressure(m, common::TAG_TOP, 1.0), SynStatus::ModelRejected);
    assert_eq!(syn_model_clamp(m, common::TAG_BOTTOM), SynStatus::ModelRejected);
    assert_eq!(syn_model_set_pressure(m, common::TAG_TOP, f64::NAN), SynStatus::InvalidArgument);
    let mut pair = 0;
    assert_eq!(
        unsafe { syn_model_add_contact(m, common::TAG_TOP, common::TAG_BOTTOM, 7, 0.0, &mut pair) },
        SynStatus::InvalidArgument
    );
    assert_eq!(
        unsafe {
            syn_model_add_contact_plane(m, common::TAG_TOP, v3.as_ptr(), v3.as_ptr(), 3, 0.0, &mut pair)
        },
        SynStatus::SizeMismatch
    );
    let solver = CString::new("newton").unwrap();
    assert_eq!(unsafe { syn_model_set_solver(m, solver.as_ptr()) }, SynStatus::InvalidArgument);
    ok(syn_model_solve_static(m, 0.0));
    // result buffers of the wrong size, pair index out of range
    let mut u = vec![0.0; 10];
    assert_eq!(unsafe { syn_model_get_displacements(m, u.as_mut_ptr(), u.len()) }, SynStatus::SizeMismatch);
    let mut p = vec![0.0; 3];
    assert_eq!(
        unsafe { syn_model_get_contact_nodes(m, 3, null_mut(), null_mut(), null_mut(), p.as_mut_ptr()) },
        SynStatus::SizeMismatch
    );
    let mut f = 0.0;
    assert_eq!(unsafe { syn_model_get_pair_force(m, 1, &mut f, null_mut()) }, SynStatus::IndexOutOfRange);
    // truncated messages: the full length is returned, the buffer is NUL-terminated
    let full = last_error();
    let mut small = [1 as c_char; 8];
    let len = unsafe { syn_last_error_message(small.as_mut_ptr(), small.len()) };
    assert_eq!(len, full.len());
    let s = unsafe { CStr::from_ptr(small.as_ptr()) }.to_str().unwrap().to_string();
    assert_eq!(s, full[..7]);
    ok(syn_model_free(m));
}

#[test]
fn elastic_model_without_contact_and_a_pressure_load() {
    let a = common::punch();
    let body = vec![0; a.elements.len() / 3];
    let desc = arrays(&a, &body, &[common::YOUNG], &[common::POISSON]);
    let mut m = null_mut();
    ok(unsafe { syn_model_from_arrays(&desc, &mut m) });
    ok(syn_model_clamp(m, common::TAG_TOP));
    ok(syn_model_clamp(m, common::TAG_TOP));
    ok(syn_model_set_pressure(m, common::TAG_BOTTOM, 5.0));
    ok(syn_model_solve_static(m, 0.0));
    let mut n = 0;
    ok(unsafe { syn_model_num_nodes(m, &mut n) });
    let mut u = vec![0.0; 2 * n];
    ok(unsafe { syn_model_get_displacements(m, u.as_mut_ptr(), u.len()) });
    // pressure on the bottom pushes it up; the middle moves most
    let mid = common::NX / 2;
    assert!(u[2 * mid + 1] > 0.0, "{}", u[2 * mid + 1]);
    let mut nc = 7;
    ok(unsafe { syn_model_num_contact_nodes(m, &mut nc) });
    assert_eq!(nc, 0);
    let mut pairs = 9;
    ok(unsafe { syn_model_num_pairs(m, &mut pairs) });
    assert_eq!(pairs, 0);
    // doubling the pressure doubles the displacement (linear)
    ok(syn_model_set_pressure(m, common::TAG_BOTTOM, 10.0));
    ok(syn_model_solve_step(m, 1.0));
    let mut u2 = vec![0.0; 2 * n];
    ok(unsafe { syn_model_get_displacements(m, u2.as_mut_ptr(), u2.len()) });
    assert!(rel(u2[2 * mid + 1], 2.0 * u[2 * mid + 1]) < 1e-10);
    let mut d = 0;
    ok(unsafe { syn_model_dimension(m, &mut d) });
    assert_eq!(d, 2);
    ok(syn_model_free(m));
}

#[test]
fn scenario_model_matches_the_cli_build() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/hertz2d.toml");
    let sc = synovia_scenario::Scenario::from_file(&path).unwrap();
    let built = synovia_scenario::build::build::<2>(&sc).unwrap();
    let rust = built.joint.run_static(0.0).unwrap();
    let expected = rust.records[0].pairs[0].normal_force;
    let c = CString::new(path.to_str().unwrap()).unwrap();
    let mut m = null_mut();
    ok(unsafe { syn_model_from_scenario(c.as_ptr(), &mut m) });
    let mut pairs = 0;
    ok(unsafe { syn_model_num_pairs(m, &mut pairs) });
    assert_eq!(pairs, 1);
    let (body, part) = (CString::new("cylinder").unwrap(), CString::new("contact").unwrap());
    let mut tag = -1;
    ok(unsafe { syn_model_part_tag(m, body.as_ptr(), part.as_ptr(), &mut tag) });
    assert!(tag >= 0);
    // the contact part is taken
    assert_eq!(syn_model_clamp(m, tag), SynStatus::ModelRejected);
    ok(syn_model_solve_static(m, 0.0));
    let f = force(m, 0);
    assert!(rel(f, expected) <= 1e-12, "C API {f:e}, Rust API {expected:e}");
    ok(syn_model_free(m));
    // a broken scenario
    let bad = CString::new("/nonexistent/scenario.toml").unwrap();
    assert_eq!(unsafe { syn_model_from_scenario(bad.as_ptr(), &mut m) }, SynStatus::Scenario);
    assert!(m.is_null());
    assert!(last_error().contains("nonexistent"), "{}", last_error());
}

#[test]
fn distinct_handles_work_from_several_threads() {
    let reference = common::reference_forces().unwrap()[0];
    let handles: Vec<_> = (0..2)
        .map(|_| {
            std::thread::spawn(move || {
                let m = punch_model();
                ok(syn_model_solve_static(m, 0.0));
                let f = force(m, 0);
                ok(syn_model_free(m));
                f
            })
        })
        .collect();
    for h in handles {
        let f = h.join().unwrap();
        assert!(rel(f, reference) <= 1e-12);
    }
}

/// Coordinates, cells, bottom and top edges of a mesh.
type RectMesh = (Vec<f64>, Vec<usize>, Vec<[usize; 2]>, Vec<[usize; 2]>);

/// A structured triangle mesh of a rectangle: coordinates, cells, bottom and top edges.
fn rect(x: (f64, f64), y: (f64, f64), nx: usize, ny: usize) -> RectMesh {
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut coords = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            coords.push(x.0 + (x.1 - x.0) * i as f64 / nx as f64);
            coords.push(y.0 + (y.1 - y.0) * j as f64 / ny as f64);
        }
    }
    let mut cells = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            cells.extend_from_slice(&[a, b, c, a, c, d]);
        }
    }
    let bottom = (0..nx).map(|i| [id(i, 0), id(i + 1, 0)]).collect();
    let top = (0..nx).map(|i| [id(i, ny), id(i + 1, ny)]).collect();
    (coords, cells, bottom, top)
}

/// A block (body 1) pressed and then pulled sideways on a wider clamped block (body 0) with
/// a body–body pair of `kind`, through the C API and through `JointModel`: forces and
/// displacements agree to 1e-12.
fn two_blocks(kind: SynContactKind, upper_nx: usize) {
    use synovia::builder::JointModel;
    use synovia::contact_ops::operators::ContactPair;
    use synovia::fem::ComponentMask;
    use synovia::material::plane_strain;
    use synovia::mesh::math::{Point, Vector};
    use synovia::mesh::{BoundaryKind, Mesh};

    let lower = rect((0.0, 2.0), (-1.0, 0.0), 8, 4);
    let upper = rect((0.5, 1.5), (0.0, 1.0), upper_nx, 4);
    let steps = [(0.0, [0.0, -0.01]), (1.0, [0.002, -0.01])];
    let friction = 0.2;
    let (young, poisson) = ([200.0, 100.0], [0.3, 0.25]);

    // the Rust API
    let mut jm = JointModel::<2>::new();
    let mut ids = Vec::new();
    for (b, (coords, cells, bottom, top)) in [&lower, &upper].into_iter().enumerate() {
        let nodes: Vec<Point<2>> = coords.chunks(2).map(|c| Point::<2>::new(c[0], c[1])).collect();
        let mut mesh = Mesh::<2>::new(nodes, cells.clone()).unwrap();
        for (name, f) in [("bottom", bottom), ("top", top)] {
            let facets: Vec<Vec<usize>> = f.iter().map(|e| e.to_vec()).collect();
            mesh.add_boundary_part_from_facets(name, BoundaryKind::TractionFree, &facets).unwrap();
        }
        ids.push(jm.add_body(&format!("b{b}"), mesh, plane_strain(young[b], poisson[b]).unwrap()).unwrap());
    }
    jm.clamp(ids[0], "bottom").unwrap();
    jm.prescribe_field(ids[1], "top", ComponentMask::ALL, move |_x, t| {
        let v = if t < 0.5 { steps[0].1 } else { steps[1].1 };
        Vector::<2>::new(v[0], v[1])
    })
    .unwrap();
    let pair = match kind {
        SynContactKind::NodeToNode => ContactPair::node_to_node("c", ids[1], "bottom", ids[0], "top"),
        SynContactKind::NodeToSegment => ContactPair::node_to_segment("c", ids[1], "bottom", ids[0], "top"),
    };
    jm.add_contact(pair.with_friction(friction)).unwrap();
    let rust = jm.run_quasistatic(&[steps[0].0, steps[1].0]).unwrap();

    // the C API: one global numbering, lower block first; tags 1..4
    let offset = lower.0.len() / 2;
    let mut coords = lower.0.clone();
    coords.extend_from_slice(&upper.0);
    let mut elements: Vec<i32> = lower.1.iter().map(|&i| i as i32).collect();
    elements.extend(upper.1.iter().map(|&i| (i + offset) as i32));
    let mut body = vec![0; lower.1.len() / 3];
    body.extend(vec![1; upper.1.len() / 3]);
    let mut facets = Vec::new();
    let mut tags = Vec::new();
    for (tag, edges, off) in
        [(1, &lower.2, 0), (2, &lower.3, 0), (3, &upper.2, offset), (4, &upper.3, offset)]
    {
        for e in edges {
            facets.extend_from_slice(&[(e[0] + off) as i32, (e[1] + off) as i32]);
            tags.push(tag);
        }
    }
    let a = common::Arrays { coords, elements, facets, tags };
    let desc = arrays(&a, &body, &young, &poisson);
    let mut m = null_mut();
    ok(unsafe { syn_model_from_arrays(&desc, &mut m) });
    ok(syn_model_clamp(m, 1));
    ok(unsafe { syn_model_set_displacement(m, 4, steps[0].1.as_ptr(), 2) });
    let mut index = 9;
    ok(unsafe { syn_model_add_contact(m, 3, 2, kind as i32, friction, &mut index) });
    assert_eq!(index, 0);
    for (i, (t, v)) in steps.iter().enumerate() {
        ok(unsafe { syn_model_set_displacement(m, 4, v.as_ptr(), 2) });
        ok(if i == 0 { syn_model_solve_static(m, *t) } else { syn_model_solve_step(m, *t) });
        let f = force(m, 0);
        let expected = rust.records[i].pairs[0].normal_force;
        assert!(
            f > 0.0 && rel(f, expected) <= 1e-12,
            "{kind:?} step {i}: C API {f:e}, Rust API {expected:e}"
        );
    }
    let mut u = vec![0.0; a.coords.len()];
    ok(unsafe { syn_model_get_displacements(m, u.as_mut_ptr(), u.len()) });
    let mut scale = 0.0_f64;
    let mut diff = 0.0_f64;
    for (b, off) in [(0, 0), (1, offset)] {
        for (i, ui) in rust.displacement[b].iter().enumerate() {
            for k in 0..2 {
                scale = scale.max(ui[k].abs());
                diff = diff.max((ui[k] - u[2 * (i + off) + k]).abs());
            }
        }
    }
    assert!(diff <= 1e-12 * scale, "{kind:?}: displacements differ by {diff:e} (scale {scale:e})");
    // the contact nodes are the upper block's bottom nodes
    let mut nc = 0;
    ok(unsafe { syn_model_num_contact_nodes(m, &mut nc) });
    assert_eq!(nc, upper_nx + 1);
    let mut node = vec![-1; nc];
    ok(unsafe { syn_model_get_contact_nodes(m, nc, null_mut(), node.as_mut_ptr(), null_mut(), null_mut()) });
    assert!(node.iter().all(|&g| (offset..=offset + upper_nx).contains(&(g as usize))), "{node:?}");
    ok(syn_model_free(m));
}

#[test]
fn body_body_node_to_node_matches_joint_model() {
    two_blocks(SynContactKind::NodeToNode, 4);
}

#[test]
fn body_body_node_to_segment_matches_joint_model() {
    two_blocks(SynContactKind::NodeToSegment, 5);
}

#[test]
fn tetrahedra_in_3d_match_joint_model() {
    use synovia::builder::JointModel;
    use synovia::contact_ops::operators::PlaneObstacle;
    use synovia::material::isotropic;
    use synovia::mesh::generators::{box_mesh, Grading};
    use synovia::mesh::math::{Point, Vector};
    use synovia::time::history::Constant;

    // a cube on a rigid plane z = 0, its top pushed down and sideways, a pressure on its
    // right face and a traction on its front face
    let u = Grading::Uniform;
    let mesh = box_mesh([0.0; 3], [1.0; 3], [3, 3, 3], [u, u, u]).unwrap();
    let mut jm = JointModel::<3>::new();
    let b = jm.add_body("cube", mesh.clone(), isotropic(50.0, 0.3).unwrap()).unwrap();
    jm.prescribe(b, "top", Vector::<3>::new(0.005, 0.0, -0.02), Constant(1.0)).unwrap();
    jm.pressure(b, "right", 2.0, Constant(1.0)).unwrap();
    jm.traction(b, "front", Vector::<3>::new(0.0, 0.5, 0.0), Constant(1.0)).unwrap();
    let plane = PlaneObstacle::new(Point::<3>::zeros(), Vector::<3>::z()).unwrap();
    jm.contact_rigid("floor", b, "bottom", plane, 0.1).unwrap();
    let rust = jm.run_static(0.0).unwrap();
    let expected = rust.records[0].pairs[0].normal_force;

    let coords: Vec<f64> = mesh.nodes().iter().flat_map(|p| [p[0], p[1], p[2]]).collect();
    let elements: Vec<i32> = mesh.cells_flat().iter().map(|&i| i as i32).collect();
    let body = vec![0; mesh.n_cells()];
    let mut facets = Vec::new();
    let mut tags = Vec::new();
    for (tag, name) in ["top", "right", "front", "bottom"].iter().enumerate() {
        for f in mesh.boundary_part(name).unwrap().facets() {
            facets.extend(f.iter().map(|&i| i as i32));
            tags.push(tag as i32);
        }
    }
    let a = common::Arrays { coords, elements, facets, tags };
    let mut desc = arrays(&a, &body, &[50.0], &[0.3]);
    desc.dimension = 3;
    let mut m = null_mut();
    ok(unsafe { syn_model_from_arrays(&desc, &mut m) });
    let mut d = 0;
    ok(unsafe { syn_model_dimension(m, &mut d) });
    assert_eq!(d, 3);
    ok(unsafe { syn_model_set_displacement(m, 0, [0.005, 0.0, -0.02].as_ptr(), 3) });
    ok(syn_model_set_pressure(m, 1, 2.0));
    ok(unsafe { syn_model_set_traction(m, 2, [0.0, 0.5, 0.0].as_ptr(), 3) });
    let (p, n) = ([0.0; 3], [0.0, 0.0, 1.0]);
    ok(unsafe { syn_model_add_contact_plane(m, 3, p.as_ptr(), n.as_ptr(), 3, 0.1, null_mut()) });
    ok(syn_model_solve_static(m, 0.0));
    let f = force(m, 0);
    assert!(f > 0.0 && rel(f, expected) <= 1e-12, "C API {f:e}, Rust API {expected:e}");
    ok(syn_model_free(m));
}
