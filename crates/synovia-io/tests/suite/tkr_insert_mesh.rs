//! The committed volume meshes of the tibial insert (`data/tka-grand-challenge-dm/mesh/`, made by
//! `scripts/stl_to_msh.sh`, see docs/meshing.md), checked against numbers computed here from the
//! STL they come from: enclosed volume, area of the flat back face, area of the upward-facing top.
//! Also runs the script itself when `gmsh` and `python3` are on PATH.

use std::path::{Path, PathBuf};

use synovia_io::gmsh::{read_msh, GmshMesh};
use synovia_io::read_stl;
use synovia_mesh::{Mesh, TriangleSurface};

/// Millimetres per metre: the STL is in metres, the meshes in millimetres.
const MM: f64 = 1000.0;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/tka-grand-challenge-dm").join(name)
}

/// Reference numbers of the STL, in mm units: enclosed volume (divergence theorem), area of the
/// back face: `tray_flat` the exactly flat part (all corners at |y| < 1 nm), `tray_area` with the
/// nearly flat band around it (downward triangles with all corners within 0.05 mm of y = 0; the
/// decimated STL's rim there has corners between y = −18 µm and +50 µm). The mesh's `tray` part
/// must lie between the two: which facets of the band it keeps depends on the coarsening., area of the facets that the script
/// calls articular (outward normal y > 0.5, centroid above y = 6 mm), total area.
struct Reference {
    volume: f64,
    tray_flat: f64,
    tray_area: f64,
    articular_area: f64,
    area: f64,
}

fn reference() -> Reference {
    let stl: TriangleSurface = read_stl(data("tibial_insert.stl")).expect("read the STL");
    stl.check_closed().expect("the STL is closed");
    let (mut tray_flat, mut tray_area, mut articular_area) = (0.0, 0.0, 0.0);
    for t in 0..stl.len() {
        let c = stl.corners(t);
        let area = stl.area_vector(t).norm() * MM * MM;
        if c.iter().all(|p| p.y.abs() < 5e-5) && stl.normal(t).y < -0.99 {
            tray_area += area;
            if c.iter().all(|p| p.y.abs() < 1e-9) {
                tray_flat += area;
            }
        } else if stl.normal(t).y > 0.5 && stl.centroid(t).y * MM > 6.0 {
            articular_area += area;
        }
    }
    Reference {
        volume: stl.signed_volume() * MM.powi(3),
        tray_flat,
        tray_area,
        articular_area,
        area: stl.area() * MM * MM,
    }
}

/// Signed volume of each tetrahedron as written in the file (before any repair by the reader).
fn file_tet_volumes(msh: &GmshMesh) -> Vec<f64> {
    let mut out = Vec::new();
    for b in msh.element_blocks.iter().filter(|b| b.element_type == 4) {
        for e in 0..b.len() {
            let p: Vec<[f64; 3]> = b.element(e).iter().map(|&i| msh.nodes[i]).collect();
            let d = |k: usize| [p[k][0] - p[0][0], p[k][1] - p[0][1], p[k][2] - p[0][2]];
            let (a, b, c) = (d(1), d(2), d(3));
            let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
            out.push(det / 6.0);
        }
    }
    out
}

fn part_area(mesh: &Mesh<3>, name: &str) -> f64 {
    mesh.boundary_part(name).expect(name).facets().map(|f| mesh.facet_measure(f)).sum()
}

/// Checks one mesh of the insert with articular element size `h` (mm).
fn check_insert(path: &Path, h: f64, r: &Reference) {
    let what = path.display();
    let msh = read_msh(path).unwrap_or_else(|e| panic!("{what}: {e}"));
    let vols = file_tet_volumes(&msh);
    assert!(!vols.is_empty(), "{what}: no tetrahedra");
    let smallest = vols.iter().copied().fold(f64::INFINITY, f64::min);
    let mean = vols.iter().sum::<f64>() / vols.len() as f64;
    assert!(smallest > 0.0, "{what}: a tetrahedron is inverted or flat: volume {smallest:e} mm³");
    assert!(mean > 0.0);

    let bodies = msh.bodies::<3>().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(bodies.len(), 1, "{what}: one body");
    let (name, mesh) = &bodies[0];
    assert_eq!(name, "insert");
    assert!(mesh.inverted_cells().is_empty(), "{what}: inverted cells");
    let names: Vec<&str> = mesh.boundary_parts().iter().map(|p| p.name()).collect();
    assert_eq!(names.len(), 3, "{what}: parts {names:?}");
    for n in ["tray", "articular", "side"] {
        assert!(names.contains(&n), "{what}: no part `{n}` in {names:?}");
    }
    let named: usize = mesh.boundary_parts().iter().map(|p| p.n_facets()).sum();
    assert_eq!(named, mesh.boundary_facets().len(), "{what}: every boundary facet is in one part");

    // The file's volume equals the sum of the tetrahedra, and both the STL's.
    let volume = mesh.measure();
    assert!((vols.iter().sum::<f64>() - volume).abs() < 1e-9 * volume);
    let dv = (volume - r.volume) / r.volume;
    assert!(
        dv.abs() < 0.01,
        "{what}: volume {volume:.1} mm³ vs STL {:.1} mm³ ({:+.2} %)",
        r.volume,
        100.0 * dv
    );

    // Whole boundary, back face and articular surface against the STL.
    let area: f64 = mesh.boundary_facets().iter().map(|f| mesh.facet_measure(&f.nodes)).sum();
    let da = (area - r.area) / r.area;
    assert!(da.abs() < 0.03, "{what}: boundary area {area:.1} vs STL {:.1} mm²", r.area);
    let tray = mesh.boundary_part("tray").expect("tray");
    for f in tray.facets() {
        for &n in f {
            assert!(mesh.node(n).y.abs() <= 0.05, "{what}: tray node at y = {}", mesh.node(n).y);
        }
        assert!(mesh.facet_normal(f).y < -0.99, "{what}: tray facet does not face down");
    }
    let tray_area = part_area(mesh, "tray");
    let dt = (tray_area - r.tray_area) / r.tray_area;
    assert!(
        tray_area > 0.99 * r.tray_flat && tray_area < 1.01 * r.tray_area,
        "{what}: tray area {tray_area:.1} mm², STL back face {:.1} (flat) … {:.1} (with its rim)",
        r.tray_flat,
        r.tray_area
    );
    let art = mesh.boundary_part("articular").expect("articular");
    let mut longest: f64 = 0.0;
    for f in art.facets() {
        let n = mesh.facet_normal(f);
        // 1e-5: coordinates are written with 8 digits; the STL has 60° facets (n_y = 0.5) exactly
        assert!(n.y > 0.5 - 1e-5, "{what}: articular facet with normal {n:?}");
        assert!(mesh.facet_centroid(f).y > 6.0);
        for k in 0..3 {
            longest = longest.max((mesh.node(f[k]) - mesh.node(f[(k + 1) % 3])).norm());
        }
    }
    assert!(longest <= 1.3 * h, "{what}: longest articular edge {longest:.3} mm for h = {h} mm");
    let art_area = part_area(mesh, "articular");
    let dart = (art_area - r.articular_area) / r.articular_area;
    assert!(
        dart.abs() < 0.05,
        "{what}: articular area {art_area:.1} vs STL {:.1} mm² (same criterion)",
        r.articular_area
    );
    println!(
        "{what}: {} nodes, {} tetrahedra, volume {volume:.1} mm³ ({:+.2} % vs STL), tray {tray_area:.1} mm² \
         ({:+.2} % vs the STL's face with rim), articular {art_area:.1} mm² ({:+.2} %), longest articular edge {longest:.3} mm, \
         min radius ratio {:.4}",
        mesh.n_nodes(),
        mesh.n_cells(),
        100.0 * dv,
        100.0 * dt,
        100.0 * dart,
        (0..mesh.n_cells()).map(|c| mesh.radius_ratio(c)).fold(f64::INFINITY, f64::min)
    );
}

#[test]
fn reference_numbers_of_the_stl() {
    // Independent of the meshes: the numbers the mesh checks compare with are plausible.
    let r = reference();
    assert!((r.volume - 24_796.2).abs() < 1.0, "volume {}", r.volume);
    assert!((r.tray_flat - 1_935.2).abs() < 1.0, "back face {}", r.tray_flat);
    assert!((r.tray_area - 2_477.1).abs() < 1.0, "back face and rim {}", r.tray_area);
    assert!(r.articular_area > 2_000.0 && r.articular_area < 5_000.0, "articular {}", r.articular_area);
}

#[test]
fn committed_mesh_h1() {
    check_insert(&data("mesh/tibial_insert_h1.msh"), 1.0, &reference());
}

#[test]
fn committed_mesh_h05() {
    // committed gzip-compressed (7.1 MB as MSH, 2.9 MB compressed); read by content
    let path = data("mesh/tibial_insert_h05.msh.gz");
    check_insert(&path, 0.5, &reference());
    // a truncated compressed file is a parse error naming gzip, not a panic
    let bytes = std::fs::read(&path).expect("committed mesh");
    let err = synovia_io::parse_msh(&bytes[..bytes.len() / 2]).expect_err("truncated gzip accepted");
    assert!(err.to_string().contains("gzip"), "{err}");
}

#[test]
fn the_script_meshes_the_stl() {
    for tool in ["gmsh", "python3"] {
        if std::process::Command::new(tool).arg("--version").output().is_err() {
            eprintln!("note: `{tool}` is not on PATH; skipping the test of scripts/stl_to_msh.sh");
            return;
        }
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = std::env::temp_dir().join(format!("synovia-stl-to-msh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let out = dir.join("insert_h3.msh");
    let run = std::process::Command::new("bash")
        .arg(root.join("scripts/stl_to_msh.sh"))
        .arg(data("tibial_insert.stl"))
        .arg(&out)
        .args(["-h", "3", "-H", "4"])
        .output()
        .expect("run bash");
    assert!(
        run.status.success(),
        "stl_to_msh.sh failed:\n{}\n{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    println!("{}", String::from_utf8_lossy(&run.stdout));
    check_insert(&out, 3.0, &reference());
    std::fs::remove_dir_all(&dir).ok();
}
