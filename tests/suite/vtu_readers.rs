//! VTU files that every reader takes: the library's and the CLI writer's multi-body files
//! (one piece with the `body` arrays, zlib by default) read whole by meshio and by VTK's own
//! XML reader (Python packages `meshio` and `vtk` from PyPI; `tests/support/vtu_readers.py`),
//! and the stress and strain fields checked against the solution.
//!
//! The Python readers run when `python3` (or `$SYNOVIA_PYTHON`) has `meshio` and `vtk`; CI
//! installs both (`.ci/run`), and with `CI` set their absence is a failure, not a skip.

use std::path::{Path, PathBuf};
use std::process::Command;

use synovia::contact::{StaticContact, StaticContactResult};
use synovia::fem::Model;
use synovia::io::{read_vtu, Encoding};
use synovia::solvers::by_name;
use synovia_models::hertz::{hertz2d_model, hertz3d_model, Hertz2d, Hertz3d};
use synovia_time::quasistatic::{QuasiStaticOutput, QuasiStaticParams, QuasiStaticStepper};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("synovia-vtu-readers-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// Two elastic cylinders pressed together: a two-body 2D contact model and its solution.
fn two_cylinders() -> (Model<2>, StaticContact<2>, StaticContactResult<2>) {
    let p = Hertz2d { levels: 4, e2: Some(2.0e3), ..Default::default() };
    let (model, pairs) = hertz2d_model(&p).expect("model");
    assert_eq!(model.bodies().len(), 2);
    let sc = StaticContact::new(&model, &pairs, Default::default()).expect("factorise");
    let solver = by_name("pdas").expect("solver");
    let res = sc.solve(&model, 0.0, solver.as_ref(), None, None, None).expect("solve");
    assert!(res.solution.lambda_n.iter().any(|&l| l > 0.0), "the cylinders must touch");
    (model, sc, res)
}

/// What the Python readers must see in `path`: counts, cells per body, and per field its
/// components and the sum of its values as the Rust reader reads them.
fn expectation<const D: usize>(path: &Path, model: &Model<D>) -> serde_json::Value {
    let data = read_vtu(path).expect("read back");
    assert_eq!(data.pieces.len(), model.bodies().len(), "{}: one entry per body", path.display());
    let mut point = serde_json::Map::new();
    let mut cell = serde_json::Map::new();
    for (location, fields) in [
        (&mut point, data.pieces.iter().map(|p| &p.point_data).collect::<Vec<_>>()),
        (&mut cell, data.pieces.iter().map(|p| &p.cell_data).collect()),
    ] {
        for (j, f) in fields[0].iter().enumerate() {
            let sum: f64 = fields.iter().map(|fs| fs[j].values.iter().sum::<f64>()).sum();
            location.insert(f.name.clone(), serde_json::json!({"components": f.components, "sum": sum}));
        }
    }
    serde_json::json!({
        "file": path.to_string_lossy(),
        "n_points": model.bodies().iter().map(|b| b.mesh.n_nodes()).sum::<usize>(),
        "n_cells": model.bodies().iter().map(|b| b.mesh.n_cells()).sum::<usize>(),
        "cells_per_body": model.bodies().iter().map(|b| b.mesh.n_cells()).collect::<Vec<_>>(),
        "point": point,
        "cell": cell,
    })
}

#[test]
fn library_files_carry_stress_and_strain_of_every_body() {
    let (model, sc, res) = two_cylinders();
    let dir = scratch("fields");
    let path = dir.join("cylinders.vtu");
    synovia::output::contact_vtu(&model, sc.geometry(), &res, Encoding::Zlib)
        .expect("writer")
        .write(&path)
        .expect("write");
    let text = std::fs::read_to_string(&path).expect("text");
    assert_eq!(text.matches("<Piece ").count(), 1, "all bodies in one piece");
    assert!(text.contains(r#"compressor="vtkZLibDataCompressor""#));
    let data = read_vtu(&path).expect("read");
    let fields = synovia::fem::post::body_fields(&model, &res.displacement).expect("fields");
    for (b, (piece, f)) in data.pieces.iter().zip(&fields).enumerate() {
        assert_eq!(piece.n_cells(), model.bodies()[b].mesh.n_cells());
        let stress = piece.cell_field("stress").expect("stress");
        let strain = piece.cell_field("strain").expect("strain");
        assert_eq!((stress.components, strain.components), (6, 6));
        for c in 0..piece.n_cells() {
            // 2D Voigt [xx, yy, xy] with σ_zz; strain with engineering shear γ_xy = 2 ε_xy
            let (s, e) = (stress.tuple(c).expect("tuple"), strain.tuple(c).expect("tuple"));
            let (sv, ev) = (&f.cell_stress[c], &f.cell_strain[c]);
            assert_eq!(s, [sv[0], sv[1], f.cell_stress_zz[c], sv[2], 0.0, 0.0]);
            assert_eq!(e, [ev[0], ev[1], 0.0, 0.5 * ev[2], 0.0, 0.0]);
        }
        let principal = piece.cell_field("principal_stress").expect("principal");
        assert_eq!(principal.values, f.cell_principal.iter().flatten().copied().collect::<Vec<_>>());
        assert_eq!(piece.cell_field("von_mises").expect("von Mises").values, f.cell_von_mises);
        let body = piece.cell_field("body").expect("body");
        assert!(body.values.iter().all(|&v| v == b as f64));
    }
    // the compact variant: displacement and contact state only
    let compact = dir.join("compact.vtu");
    synovia::output::contact_state_vtu(&model, sc.geometry(), &res, Encoding::Zlib)
        .expect("writer")
        .write(&compact)
        .expect("write");
    let piece = &read_vtu(&compact).expect("read").pieces[0];
    assert!(piece.cell_field("stress").is_none() && piece.point_field("contact_pressure").is_some());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn meshio_and_vtk_read_every_body_of_library_and_cli_files() {
    let python = std::env::var("SYNOVIA_PYTHON").unwrap_or_else(|_| "python3".into());
    let probe = Command::new(&python).args(["-c", "import meshio, vtk, numpy"]).output();
    if !probe.as_ref().is_ok_and(|o| o.status.success()) {
        let why = match &probe {
            Ok(o) => String::from_utf8_lossy(&o.stderr).into_owned(),
            Err(e) => e.to_string(),
        };
        assert!(std::env::var_os("CI").is_none(), "CI must have meshio and vtk for {python}: {why}");
        eprintln!("skipped: {python} lacks meshio or vtk (pip install meshio vtk): {why}");
        return;
    }
    let dir = scratch("python");
    let mut expected = Vec::new();
    // library: two bodies in 2D in every encoding
    let (model, sc, res) = two_cylinders();
    for encoding in [Encoding::Zlib, Encoding::Base64, Encoding::Ascii] {
        let path = dir.join(format!("cylinders_{encoding:?}.vtu"));
        synovia::output::contact_vtu(&model, sc.geometry(), &res, encoding)
            .expect("writer")
            .write(&path)
            .expect("write");
        expected.push(expectation(&path, &model));
    }
    // the CLI's writer (QuasiStaticOutput): two quasi-static steps of the same model
    let (pairs_model, pairs) =
        hertz2d_model(&Hertz2d { levels: 4, e2: Some(2.0e3), ..Default::default() }).expect("model");
    let contact = StaticContact::new(&pairs_model, &pairs, Default::default()).expect("factorise");
    let mut stepper = QuasiStaticStepper::from_contact(&pairs_model, contact, QuasiStaticParams::default())
        .expect("stepper");
    let mut out = QuasiStaticOutput::new(dir.join("cli"), "run", stepper.geometry()).expect("output");
    let solver = by_name("pdas").expect("solver");
    let mut files = Vec::new();
    stepper
        .run(&pairs_model, &[0.0, 0.5, 1.0], solver.as_ref(), |rec, r| {
            files.push(out.write_step(&pairs_model, rec, r)?);
            Ok(())
        })
        .expect("run");
    for f in &files {
        expected.push(expectation(f, &pairs_model));
    }
    // 3D: the hemisphere
    let (model3, pairs3) = hertz3d_model(&Hertz3d { levels: 6, ..Default::default() }).expect("model");
    let sc3 = StaticContact::new(&model3, &pairs3, Default::default()).expect("factorise");
    let res3 = sc3.solve(&model3, 0.0, solver.as_ref(), None, None, None).expect("solve");
    let path = dir.join("hemisphere.vtu");
    synovia::output::contact_vtu(&model3, sc3.geometry(), &res3, Encoding::Zlib)
        .expect("writer")
        .write(&path)
        .expect("write");
    expected.push(expectation(&path, &model3));

    let spec = dir.join("expected.json");
    std::fs::write(&spec, serde_json::to_string_pretty(&expected).expect("json")).expect("write spec");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/support/vtu_readers.py");
    let run = Command::new(&python).arg(&script).arg(&spec).output().expect("run python");
    let stdout = String::from_utf8_lossy(&run.stdout);
    println!("{stdout}");
    assert!(run.status.success(), "readers disagree:\n{stdout}\n{}", String::from_utf8_lossy(&run.stderr));
    assert_eq!(stdout.lines().count(), 2 * expected.len(), "one line per file and reader");
    std::fs::remove_dir_all(&dir).ok();
}
