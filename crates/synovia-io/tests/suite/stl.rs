//! STL input: round trips, ASCII and binary, corrupt files as typed errors, and the real
//! implant surfaces of `data/tka-grand-challenge-dm` (counts and closedness of its README).

use std::path::PathBuf;

use synovia_io::{parse_stl, read_stl, write_stl, IoError};
use synovia_mesh::{Point, SurfaceError, TriangleSurface};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/tka-grand-challenge-dm").join(name)
}

#[test]
fn binary_round_trip_keeps_the_surface() {
    let sphere = TriangleSurface::icosphere(Point::<3>::new(0.1, 0.2, -0.3), 0.02, 3).expect("icosphere");
    let dir = std::env::temp_dir().join(format!("synovia-stl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("sphere.stl");
    write_stl(&path, &sphere).expect("write");
    let back = read_stl(&path).expect("read");
    assert_eq!(back.len(), sphere.len());
    assert_eq!(back.vertices().len(), sphere.vertices().len(), "corners merged into shared vertices");
    back.check_closed().expect("closed, outward");
    for t in 0..sphere.len() {
        for (a, b) in back.corners(t).iter().zip(sphere.corners(t)) {
            assert!((a - b).norm() <= 1e-7 * b.norm(), "single precision: {a:?} vs {b:?}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn ascii_stl_is_read() {
    let text = "solid tetra\n\
        facet normal 0 0 -1\n outer loop\n  vertex 0 0 0\n  vertex 0 1 0\n  vertex 1 0 0\n endloop\nendfacet\n\
        facet normal 0 -1 0\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 0 1\n endloop\nendfacet\n\
        facet normal -1 0 0\n outer loop\n  vertex 0 0 0\n  vertex 0 0 1\n  vertex 0 1 0\n endloop\nendfacet\n\
        facet normal 1 1 1\n outer loop\n  vertex 1 0 0\n  vertex 0 1 0\n  vertex 0 0 1\n endloop\nendfacet\n\
        endsolid tetra\n";
    let s = parse_stl(text.as_bytes()).expect("ascii");
    assert_eq!((s.len(), s.vertices().len()), (4, 4));
    s.check_closed().expect("the unit tetrahedron, outward");
    assert!((s.signed_volume() - 1.0 / 6.0).abs() < 1e-15);
}

#[test]
fn corrupt_files_are_typed_errors() {
    // too short
    assert!(matches!(parse_stl(b"solid"), Err(IoError::Parse { .. })));
    // binary with a triangle count that does not match the length (no huge allocation)
    let mut bytes = vec![0u8; 84 + 50];
    bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let err = parse_stl(&bytes).expect_err("count");
    assert!(err.to_string().contains("declares 4294967295 triangles"), "{err}");
    // a binary file whose single triangle is degenerate (all zeros)
    let mut one = vec![0u8; 84 + 50];
    one[80..84].copy_from_slice(&1u32.to_le_bytes());
    let err = parse_stl(&one).expect_err("degenerate");
    assert!(matches!(err, IoError::Surface { source: SurfaceError::DegenerateTriangle { .. }, .. }), "{err}");
    // an ASCII file cut in the middle
    let err = parse_stl(b"solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0")
        .expect_err("cut");
    assert!(matches!(err, IoError::Parse { .. }), "{err}");
    // missing file
    assert!(matches!(read_stl("/nonexistent/knee.stl"), Err(IoError::Io { .. })));
}

/// The counts, closedness and boxes stated in data/tka-grand-challenge-dm/README.md.
#[test]
fn implant_surfaces_of_the_grand_challenge_data() {
    let cases = [
        ("femoral_component.stl", 24_442, true),
        ("femoral_component_contact.stl", 24_960, false),
        ("tibial_insert.stl", 52_918, true),
        ("tibial_insert_contact.stl", 15_042, false),
    ];
    for (name, triangles, closed) in cases {
        let s = read_stl(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(s.len(), triangles, "{name}");
        s.check_manifold().unwrap_or_else(|e| panic!("{name}: {e}"));
        match s.check_closed() {
            Ok(()) => assert!(closed, "{name} should be open"),
            Err(SurfaceError::Open { boundary_edges, .. }) => {
                assert!(!closed, "{name}: {boundary_edges} boundary edges");
            }
            Err(e) => panic!("{name}: {e}"),
        }
        let (lo, hi) = s.bounding_box().expect("box");
        assert!(
            hi.iter().chain(lo.iter()).all(|x| x.abs() < 0.05),
            "{name}: metres, within 5 cm: {lo:?} {hi:?}"
        );
    }
    let insert = read_stl(data("tibial_insert.stl")).expect("insert");
    let (lo, _) = insert.bounding_box().expect("box");
    assert!(lo.y.abs() < 1e-4, "the insert's tray side lies at y = 0 within 0.1 mm (got {})", lo.y);
}

/// A device given as a surface or mesh path is refused, not read until memory runs out.
#[test]
fn devices_are_not_read_as_files() {
    for path in ["/dev/zero", "/"] {
        if std::path::Path::new(path).exists() {
            let err = read_stl(path).expect_err("device");
            assert!(err.to_string().contains("not a regular file"), "{err}");
            let err = synovia_io::read_msh(path).expect_err("device");
            assert!(err.to_string().contains("not a regular file"), "{err}");
        }
    }
}

/// Self-intersection of the implant surfaces, timed (printed with
/// `cargo test --release -p synovia-io --test suite stl:: -- --nocapture`; about 0.1 s each): the
/// femoral component and both contact patches do not cross themselves; the tibial insert
/// crosses itself at 45 pairs of triangles in about eight small folds (e.g. triangles 293 and
/// 47 589 share the vertex (20.218, 9.624, 30.054) mm and overlap along 62 µm from it). Each of
/// the 45 was confirmed in exact rational arithmetic on the file's `f32` coordinates (pairs
/// without a common vertex: two edges cross the other triangle; pairs with one: both
/// triangles leave the common vertex on the same side along the planes' common line).
#[test]
fn grand_challenge_surfaces_and_self_intersection() {
    for (name, folds) in [
        ("femoral_component.stl", 0),
        ("tibial_insert.stl", 45),
        ("femoral_component_contact.stl", 0),
        ("tibial_insert_contact.stl", 0),
    ] {
        let s = read_stl(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let start = std::time::Instant::now();
        let found = s.self_intersections();
        let took = start.elapsed().as_secs_f64();
        println!("{name}: {} triangles, self-intersection check {took:.3} s: {found:?}", s.len());
        assert!(took < 1.0, "{name}: {took} s");
        assert_eq!(found.len(), folds, "{name}: {found:?}");
        match s.check_self_intersection() {
            Ok(()) => assert_eq!(folds, 0),
            Err(SurfaceError::SelfIntersection { triangles, .. }) => {
                assert_eq!(triangles, found[0].0);
                assert!(matches!(s.check_closed_solid(), Err(SurfaceError::SelfIntersection { .. })));
            }
            Err(e) => panic!("{name}: {e}"),
        }
        if name == "femoral_component.stl" {
            s.check_closed_solid().unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
}
