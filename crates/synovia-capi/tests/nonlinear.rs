//! Material laws selected by name through the C API (`syn_model_set_material`,
//! `syn_model_set_kinematics`, issue 20): the hyperelastic laws reduce to linear elasticity at
//! first order in the strain, the C API solves the same discrete problem as the Rust API, a
//! failed nonlinear solve keeps the last solution, and bad names and constants get their
//! status codes.
#![allow(clippy::unwrap_used, clippy::undocumented_unsafe_blocks)]

mod common;

use std::ffi::CString;
use std::ptr::{null, null_mut};
use std::sync::Arc;

use synovia::fem::BodyId;
use synovia::material::{neo_hookean, Material};
use synovia_capi::*;

use common::{arrays, last_error, ok};

/// The punch mesh of `common` as a C API model without conditions (linear, E = 1000, ν = 0.3,
/// plane strain).
fn linear_punch() -> *mut SynModel {
    let a = common::punch();
    let body = vec![0; a.elements.len() / 3];
    let (young, poisson) = ([common::YOUNG], [common::POISSON]);
    let desc = arrays(&a, &body, &young, &poisson);
    let mut m = null_mut();
    ok(unsafe { syn_model_from_arrays(&desc, &mut m) });
    m
}

/// The punch of `common` (linear, E = 1000, ν = 0.3, plane strain) with its top moved by
/// `top` and pressed frictionless onto the plane `y = 0`.
fn punch(top: [f64; 2], friction: f64) -> *mut SynModel {
    let m = linear_punch();
    ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, top.as_ptr(), 2) });
    let (p, n) = ([0.0, 0.0], [0.0, 1.0]);
    ok(unsafe {
        syn_model_add_contact_plane(m, common::TAG_BOTTOM, p.as_ptr(), n.as_ptr(), 2, friction, null_mut())
    });
    m
}

fn set_law(m: *mut SynModel, law: &str, constants: &[f64]) -> SynStatus {
    let law = CString::new(law).unwrap();
    unsafe { syn_model_set_material(m, 0, law.as_ptr(), constants.as_ptr(), constants.len()) }
}

fn set_kinematics(m: *mut SynModel, k: &str) -> SynStatus {
    let k = CString::new(k).unwrap();
    unsafe { syn_model_set_kinematics(m, 0, k.as_ptr()) }
}

fn normal_force(m: *mut SynModel) -> f64 {
    let mut f = f64::NAN;
    let mut v = [f64::NAN; 3];
    ok(unsafe { syn_model_get_pair_force(m, 0, &mut f, v.as_mut_ptr()) });
    f
}

fn info(m: *mut SynModel) -> SynSolveInfo {
    let mut i =
        SynSolveInfo { time: 0.0, step: 0, iterations: 0, kkt_residual: 0.0, n_dofs: 0, n_contact_nodes: 0 };
    ok(unsafe { syn_model_get_solve_info(m, &mut i) });
    i
}

fn displacements(m: *mut SynModel) -> Vec<f64> {
    let mut n = 0;
    ok(unsafe { syn_model_num_nodes(m, &mut n) });
    let mut u = vec![f64::NAN; 2 * n];
    ok(unsafe { syn_model_get_displacements(m, u.as_mut_ptr(), u.len()) });
    u
}

/// The static normal force of the punch pushed by `s × 0.05` onto the floor with the law `law`
/// (`None`: the linear law of the arrays).
fn static_force(s: f64, law: Option<(&str, &[f64])>) -> f64 {
    let m = punch([0.0, -0.05 * s], 0.0);
    if let Some((name, c)) = law {
        ok(set_law(m, name, c));
    }
    ok(syn_model_solve_static(m, 0.0));
    let i = info(m);
    assert!(i.kkt_residual <= 1e-8, "KKT {:e}", i.kkt_residual);
    let f = normal_force(m);
    ok(syn_model_free(m));
    f
}

/// The displacements of the punch without contact, its bottom clamped and its top moved by
/// `s × (0.01, −0.05)`, with the law `law` in small strain (`None`: the arrays' linear law).
fn compressed(s: f64, law: Option<(&str, &[f64])>) -> Vec<f64> {
    let m = linear_punch();
    ok(syn_model_clamp(m, common::TAG_BOTTOM));
    let top = [0.01 * s, -0.05 * s];
    ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, top.as_ptr(), 2) });
    if let Some((name, c)) = law {
        ok(set_law(m, name, c));
    }
    ok(syn_model_solve_static(m, 0.0));
    let u = displacements(m);
    ok(syn_model_free(m));
    u
}

fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |m, x| m.max(x.abs()))
}

/// Neo-Hookean and Mooney–Rivlin laws by name: their linearisations are the isotropic law
/// (neo-Hookean with the same `E`, `ν`; Mooney–Rivlin with `μ = 2(c₁ + c₂)`,
/// `λ₀ = λ + 4c₂`), so the relative difference of the displacements from the linear solution
/// is first order in the load: it halves with the top's motion (5 %, 2.5 %, 1.25 %, 0.625 %
/// nominal strain). With contact the difference of the force also falls with the push.
#[test]
fn hyperelastic_laws_by_name_agree_with_linear_elasticity_at_first_order() {
    let (e, nu) = (common::YOUNG, common::POISSON);
    let mu = e / (2.0 * (1.0 + nu));
    let lambda0 = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let (c1, c2) = (0.3 * mu, 0.2 * mu);
    let mr = [c1, c2, lambda0 - 4.0 * c2];
    for (name, constants) in [("neo_hookean", &[e, nu][..]), ("mooney_rivlin", &mr[..])] {
        let d: Vec<f64> = [1.0, 0.5, 0.25, 0.125]
            .iter()
            .map(|&s| {
                let (lin, nl) = (compressed(s, None), compressed(s, Some((name, constants))));
                max_abs(lin.iter().zip(&nl).map(|(a, b)| a - b)) / max_abs(lin.iter().copied())
            })
            .collect();
        eprintln!("{name}: relative displacement difference from linear {d:?}");
        assert!(d[0] > 1e-4 && d[0] < 0.2, "{name}: {d:?}");
        for w in d.windows(2) {
            let rate = w[0] / w[1];
            assert!((1.8..2.2).contains(&rate), "{name}: not first order: {d:?}");
        }
        let f: Vec<f64> = [1.0, 0.25]
            .iter()
            .map(|&s| {
                let (lin, nl) = (static_force(s, None), static_force(s, Some((name, constants))));
                assert!(lin > 0.0 && nl > 0.0, "{name}: {lin} {nl}");
                (nl - lin).abs() / lin
            })
            .collect();
        eprintln!("{name}: relative force difference from linear with contact {f:?}");
        assert!(f[1] < 0.5 * f[0] && f[0] < 0.2, "{name}: {f:?}");
    }
}

/// The C API's neo-Hookean punch is the Rust API's (`JointModel` with the law set on its
/// body) to round-off, statically and over two frictional quasi-static steps, in small and
/// finite strain.
#[test]
fn c_api_neo_hookean_equals_the_rust_api() {
    let (e, nu) = (common::YOUNG, common::POISSON);
    for finite in [false, true] {
        let mut jm = common::joint_model().unwrap();
        let law: Arc<dyn Material<2>> = Arc::new(neo_hookean(e, nu).unwrap());
        jm.model_mut().body_mut(BodyId(0)).unwrap().material = law;
        if finite {
            jm.set_kinematics(BodyId(0), synovia::fem::Kinematics::FiniteStrain).unwrap();
        }
        let times: Vec<f64> = common::STEPS.iter().map(|s| s.0).collect();
        let rust = jm.run_quasistatic(&times).unwrap();
        let m = punch(common::STEPS[0].1, common::FRICTION);
        ok(set_law(m, "neo_hookean", &[e, nu]));
        if finite {
            ok(set_kinematics(m, "finite"));
        }
        for (k, (t, top)) in common::STEPS.iter().enumerate() {
            ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, top.as_ptr(), 2) });
            ok(if k == 0 { syn_model_solve_static(m, *t) } else { syn_model_solve_step(m, *t) });
            let (c, r) = (normal_force(m), rust.records[k].pairs[0].normal_force);
            assert!((c - r).abs() <= 1e-10 * r.abs(), "finite {finite}, step {k}: C {c:e}, Rust {r:e}");
            let i = info(m);
            assert_eq!(i.step, k);
            assert!(i.kkt_residual <= 1e-8, "KKT {:e}", i.kkt_residual);
        }
        ok(syn_model_free(m));
    }
}

/// A step that fails (the top pushed through the floor: inverted elements at every cut-back)
/// keeps the last solution, and the next step continues from it exactly as if the failed one
/// had not been asked.
#[test]
fn a_failed_nonlinear_step_keeps_the_last_solution() {
    let run = |fail_first: bool| {
        let m = punch([0.0, -0.05], 0.0);
        ok(set_law(m, "neo_hookean", &[common::YOUNG, common::POISSON]));
        ok(set_kinematics(m, "finite"));
        ok(syn_model_solve_static(m, 0.0));
        let before = displacements(m);
        if fail_first {
            let through = [0.0, -3.0];
            ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, through.as_ptr(), 2) });
            assert_eq!(syn_model_solve_step(m, 1.0), SynStatus::SolveFailed);
            assert!(!last_error().is_empty());
            assert_eq!(displacements(m), before, "the failed step changed the solution");
            assert_eq!(info(m).step, 0);
        }
        let next = [0.0, -0.06];
        ok(unsafe { syn_model_set_displacement(m, common::TAG_TOP, next.as_ptr(), 2) });
        ok(syn_model_solve_step(m, 1.0));
        let (u, f) = (displacements(m), normal_force(m));
        ok(syn_model_free(m));
        (u, f)
    };
    let (u_clean, f_clean) = run(false);
    let (u_after, f_after) = run(true);
    assert!((f_after - f_clean).abs() <= 1e-10 * f_clean, "{f_after:e} vs {f_clean:e}");
    let du = u_clean.iter().zip(&u_after).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(du <= 1e-10, "{du:e}");
}

#[test]
fn bad_laws_and_kinematics_get_their_status() {
    let m = punch([0.0, -0.05], 0.0);
    assert_eq!(set_law(m, "ogden", &[1.0, 0.3]), SynStatus::InvalidArgument);
    assert!(last_error().contains("ogden"), "{}", last_error());
    assert_eq!(set_law(m, "neo_hookean", &[1.0]), SynStatus::InvalidArgument);
    assert!(last_error().contains("2 constants"), "{}", last_error());
    assert_eq!(set_law(m, "neo_hookean", &[f64::NAN, 0.3]), SynStatus::InvalidArgument);
    assert_eq!(set_law(m, "neo_hookean", &[-1.0, 0.3]), SynStatus::ModelRejected);
    assert_eq!(set_law(m, "neo_hookean", &[1.0, 0.5]), SynStatus::ModelRejected);
    assert_eq!(set_law(m, "mooney_rivlin", &[-1.0, 0.0, 1.0]), SynStatus::ModelRejected);
    let law = CString::new("isotropic").unwrap();
    assert_eq!(
        unsafe { syn_model_set_material(m, 1, law.as_ptr(), [1.0, 0.3].as_ptr(), 2) },
        SynStatus::IndexOutOfRange
    );
    assert_eq!(
        unsafe { syn_model_set_material(m, 0, null(), [1.0, 0.3].as_ptr(), 2) },
        SynStatus::NullPointer
    );
    assert_eq!(unsafe { syn_model_set_material(m, 0, law.as_ptr(), null(), 2) }, SynStatus::NullPointer);
    assert_eq!(set_kinematics(m, "large"), SynStatus::InvalidArgument);
    assert_eq!(
        unsafe { syn_model_set_kinematics(m, 3, CString::new("finite").unwrap().as_ptr()) },
        SynStatus::IndexOutOfRange
    );
    // nothing was changed by the refused calls: the linear model solves as before
    ok(syn_model_solve_static(m, 0.0));
    let f = normal_force(m);
    ok(syn_model_free(m));
    let reference = static_force(1.0, None);
    assert!((f - reference).abs() <= 1e-12 * reference, "{f} vs {reference}");
    // "isotropic" by name is the arrays' law
    let by_name = static_force(1.0, Some(("isotropic", &[common::YOUNG, common::POISSON])));
    assert!((by_name - reference).abs() <= 1e-12 * reference, "{by_name} vs {reference}");
}
