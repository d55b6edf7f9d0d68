//! Round-trip tests: write with the writers, read back with the readers, compare exactly.

use std::path::PathBuf;

use synovia_io::{
    parse_vtu, read_pvd, read_vtu, write_vtu, Encoding, Field, FieldLocation, IoError, PvdWriter,
    TimeSeriesWriter, VtuPiece, VtuWriter, BODY_FIELD, VTK_TETRA, VTK_TRIANGLE,
};
use synovia_mesh::{Mesh, Point, Tensor, Vector};

type TestResult = Result<(), Box<dyn std::error::Error>>;

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("synovia-io-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).ok();
    dir
}

/// Unit square as an `n × n` grid of squares, each split into two counter-clockwise triangles.
fn grid_2d(n: usize) -> Mesh<2> {
    let h = 1.0 / n as f64;
    let mut nodes = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            nodes.push(Point::<2>::new(i as f64 * h, j as f64 * h));
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut cells = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (v0, v1, v2, v3) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            cells.extend_from_slice(&[v0, v1, v2, v0, v2, v3]);
        }
    }
    Mesh::new(nodes, cells).expect("valid grid")
}

/// Unit cube split into 6 tetrahedra (Kuhn / Freudenthal), orientation repaired.
fn kuhn_cube() -> Mesh<3> {
    let nodes: Vec<Point<3>> = (0..8)
        .map(|k| Point::<3>::new((k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64))
        .collect();
    let mut cells = Vec::new();
    for perm in [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
        let mut v = 0usize;
        cells.push(v);
        for axis in perm {
            v |= 1 << axis;
            cells.push(v);
        }
    }
    let (mesh, _flipped) = Mesh::new_with_repair(nodes, cells).expect("valid cube");
    mesh
}

/// Awkward values that only survive an exact round trip.
fn tricky(i: usize) -> f64 {
    const SPECIAL: [f64; 9] = [
        0.1 + 0.2,
        -0.0,
        1e-300,
        5e-324,
        f64::MAX,
        f64::MIN_POSITIVE,
        1.0 / 3.0,
        -123456.789e17,
        std::f64::consts::PI,
    ];
    if i < SPECIAL.len() {
        SPECIAL[i]
    } else {
        ((i as f64) * 0.731).sin() * 10f64.powi((i % 7) as i32 - 3)
    }
}

fn assert_bits_eq(name: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{name}: length");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.to_bits(), w.to_bits(), "{name}[{k}]: got {g:e}, want {w:e}");
    }
}

fn assert_field(piece: &VtuPiece, want: &Field) {
    let got = match want.location {
        FieldLocation::Point => piece.point_field(&want.name),
        FieldLocation::Cell => piece.cell_field(&want.name),
    };
    let got = got.unwrap_or_else(|| panic!("field `{}` missing", want.name));
    assert_eq!(got.location, want.location, "{}", want.name);
    assert_eq!(got.components, want.components, "{}", want.name);
    assert_bits_eq(&want.name, &got.values, &want.values);
}

fn assert_geometry<const D: usize>(piece: &VtuPiece, mesh: &Mesh<D>, cell_type: u8) {
    assert_eq!(piece.n_points(), mesh.n_nodes());
    for (p, x) in piece.points.iter().zip(mesh.nodes()) {
        for k in 0..3 {
            let want = if k < D { x[k] } else { 0.0 };
            assert_eq!(p[k].to_bits(), want.to_bits());
        }
    }
    assert_eq!(piece.connectivity, mesh.cells_flat());
    let offsets: Vec<usize> = (1..=mesh.n_cells()).map(|c| c * (D + 1)).collect();
    assert_eq!(piece.offsets, offsets);
    assert_eq!(piece.types, vec![cell_type; mesh.n_cells()]);
    for c in 0..mesh.n_cells() {
        assert_eq!(piece.cell(c), Some(mesh.cell(c)));
    }
    assert_eq!(piece.cell(mesh.n_cells()), None);
}

fn fields_2d(mesh: &Mesh<2>) -> Vec<Field> {
    let u: Vec<Vector<2>> =
        (0..mesh.n_nodes()).map(|i| Vector::<2>::new(tricky(2 * i), tricky(2 * i + 1))).collect();
    let stress: Vec<Tensor<2>> = (0..mesh.n_cells())
        .map(|c| Tensor::<2>::new(tricky(c), tricky(c + 3), tricky(c + 3), tricky(c + 11)))
        .collect();
    vec![
        Field::point_vectors("displacement", &u),
        Field::point_scalars("temperature", (0..mesh.n_nodes()).map(|i| tricky(i + 5)).collect()),
        Field::cell_tensors("stress", &stress),
        Field::cell_scalars("a<b & \"c\"", (0..mesh.n_cells()).map(|c| c as f64).collect()),
    ]
}

fn fields_3d(mesh: &Mesh<3>) -> Vec<Field> {
    let u: Vec<Vector<3>> = (0..mesh.n_nodes())
        .map(|i| Vector::<3>::new(tricky(3 * i), tricky(3 * i + 1), tricky(3 * i + 2)))
        .collect();
    let stress: Vec<Tensor<3>> =
        (0..mesh.n_cells()).map(|c| Tensor::<3>::from_fn(|i, j| tricky(9 * c + 3 * i + j))).collect();
    vec![
        Field::point_vectors("displacement", &u),
        Field::point_scalars("pressure", (0..mesh.n_nodes()).map(|i| tricky(i + 2)).collect()),
        Field::cell_tensors("stress", &stress),
    ]
}

#[test]
fn roundtrip_2d_both_encodings() -> TestResult {
    let dir = scratch("rt2d");
    let mesh = grid_2d(4);
    let fields = fields_2d(&mesh);
    for encoding in [Encoding::Ascii, Encoding::Base64, Encoding::Zlib] {
        let path = dir.join(format!("grid_{encoding:?}.vtu"));
        VtuWriter::new(encoding).add_piece(&mesh, fields.clone())?.write(&path)?;
        let data = read_vtu(&path)?;
        assert_eq!(data.pieces.len(), 1);
        let piece = &data.pieces[0];
        assert_geometry(piece, &mesh, VTK_TRIANGLE);
        for f in &fields {
            assert_field(piece, f);
        }
        // 2D tensors are padded into 3 × 3 row-major tensors.
        let stress = piece.cell_field("stress").ok_or("stress")?;
        assert_eq!(stress.tuple(0).ok_or("tuple")?[2], 0.0);
        assert_eq!(stress.tuple(0).ok_or("tuple")?[8], 0.0);
        assert_eq!(stress.tuple(0).ok_or("tuple")?[1].to_bits(), tricky(3).to_bits());
        let body = piece.cell_field(BODY_FIELD).ok_or("body")?;
        assert_eq!(body.values, vec![0.0; mesh.n_cells()]);
        assert_eq!(piece.point_data.len(), 2);
        assert_eq!(piece.cell_data.len(), 3);
        assert_eq!(piece.to_mesh::<2>()?, mesh);
        assert!(matches!(piece.to_mesh::<3>(), Err(IoError::CellType { cell: 0, .. })));
        let text = std::fs::read_to_string(&path)?;
        assert!(text.contains(match encoding {
            Encoding::Ascii => r#"format="ascii""#,
            Encoding::Base64 => r#"format="binary""#,
            Encoding::Zlib => r#"compressor="vtkZLibDataCompressor""#,
        }));
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

#[test]
fn roundtrip_3d_both_encodings() -> TestResult {
    let dir = scratch("rt3d");
    let mesh = kuhn_cube();
    assert_eq!(mesh.n_cells(), 6);
    let fields = fields_3d(&mesh);
    for encoding in [Encoding::Ascii, Encoding::Base64, Encoding::Zlib] {
        let path = dir.join(format!("cube_{encoding:?}.vtu"));
        VtuWriter::new(encoding).add_piece(&mesh, fields.clone())?.write(&path)?;
        let piece = &read_vtu(&path)?.pieces[0];
        assert_geometry(piece, &mesh, VTK_TETRA);
        for f in &fields {
            assert_field(piece, f);
        }
        assert_eq!(piece.to_mesh::<3>()?, mesh);
    }
    // The convenience writer produces the same document as an explicit zlib writer.
    let path = dir.join("convenience.vtu");
    write_vtu(&path, &mesh, &fields)?;
    let explicit = VtuWriter::new(Encoding::Zlib).add_piece(&mesh, fields.clone())?.to_xml_string();
    assert_eq!(std::fs::read_to_string(&path)?, explicit);
    assert_eq!(parse_vtu(&explicit)?, read_vtu(&path)?);
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

#[test]
fn ascii_uses_shortest_round_trip_numbers() -> TestResult {
    let mesh = grid_2d(1);
    let xml = VtuWriter::new(Encoding::Ascii)
        .add_piece(&mesh, vec![Field::point_scalars("s", vec![0.1, 1.0, -2.5e-7, 3.0])])?
        .to_xml_string();
    assert!(xml.contains(" 1e-1 1e0 -2.5e-7 3e0"), "{xml}");
    Ok(())
}

#[test]
fn two_component_fields_are_padded() -> TestResult {
    let mesh = grid_2d(1);
    let v = vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
    let xml = VtuWriter::new(Encoding::Base64)
        .add_piece(&mesh, vec![Field::new("v", FieldLocation::Point, 2, v)])?
        .to_xml_string();
    let f = parse_vtu(&xml)?.pieces[0].point_field("v").cloned().ok_or("v")?;
    assert_eq!(f.components, 3);
    assert_eq!(f.values, vec![1.0, 2.0, 0.0, 3.0, 4.0, 0.0, 5.0, 6.0, 0.0, 7.0, 8.0, 0.0]);
    Ok(())
}

#[test]
fn two_pieces_in_one_file() -> TestResult {
    let dir = scratch("pieces");
    let square = grid_2d(2);
    let cube = kuhn_cube();
    let square_fields = vec![
        Field::point_vectors("u", &square.nodes().iter().map(|x| x * 0.5).collect::<Vec<Vector<2>>>()),
        Field::cell_scalars("p", (0..square.n_cells()).map(|c| c as f64 + 0.25).collect()),
    ];
    // Same fields, other order: the writer reorders them like the first piece.
    let cube_fields = vec![
        Field::cell_scalars("p", (0..cube.n_cells()).map(|c| -(c as f64)).collect()),
        Field::point_vectors("u", &cube.nodes().iter().map(|x| x * 2.0).collect::<Vec<_>>()),
    ];
    for encoding in [Encoding::Ascii, Encoding::Base64, Encoding::Zlib] {
        let path = dir.join("two.vtu");
        let mut w = VtuWriter::new(encoding);
        w.add_piece(&square, square_fields.clone())?.add_piece(&cube, cube_fields.clone())?;
        assert_eq!(w.n_pieces(), 2);
        w.write(&path)?;
        // one <Piece> holding both bodies, so that readers taking one piece get every cell
        let text = std::fs::read_to_string(&path)?;
        assert_eq!(text.matches("<Piece ").count(), 1);
        let (np, nc) = (square.n_nodes() + cube.n_nodes(), square.n_cells() + cube.n_cells());
        assert!(text.contains(&format!(r#"NumberOfPoints="{np}" NumberOfCells="{nc}""#)), "{np} {nc}");
        let data = read_vtu(&path)?;
        assert_eq!(data.pieces.len(), 2);
        assert_geometry(&data.pieces[0], &square, VTK_TRIANGLE);
        assert_geometry(&data.pieces[1], &cube, VTK_TETRA);
        for f in &square_fields {
            assert_field(&data.pieces[0], f);
        }
        for f in &cube_fields {
            assert_field(&data.pieces[1], f);
        }
        for (i, piece) in data.pieces.iter().enumerate() {
            let body = piece.cell_field(BODY_FIELD).ok_or("body")?;
            assert_eq!(body.values, vec![i as f64; piece.n_cells()]);
            let names: Vec<&str> = piece.cell_data.iter().map(|f| f.name.as_str()).collect();
            assert_eq!(names, ["p", BODY_FIELD]);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

#[test]
fn pieces_must_carry_the_same_fields() -> TestResult {
    let square = grid_2d(1);
    let scalars = |name: &str| Field::point_scalars(name, vec![0.0; square.n_nodes()]);
    let mut w = VtuWriter::new(Encoding::Ascii);
    w.add_piece(&square, vec![scalars("a")])?;
    for fields in [vec![], vec![scalars("b")], vec![scalars("a"), scalars("b")]] {
        let err = w.add_piece(&square, fields).err().ok_or("accepted")?;
        assert!(matches!(err, IoError::InconsistentPieces { piece: 1, .. }), "{err}");
    }
    let err = w
        .add_piece(&square, vec![Field::new("a", FieldLocation::Point, 3, vec![0.0; 12])])
        .err()
        .ok_or("accepted")?;
    assert!(matches!(err, IoError::InconsistentPieces { .. }), "{err}");
    assert_eq!(w.n_pieces(), 1);
    Ok(())
}

#[test]
fn time_series_with_pvd() -> TestResult {
    let dir = scratch("series");
    let mesh = grid_2d(2);
    let times = [0.0, 0.125, 1.0 / 3.0];
    let mut series = TimeSeriesWriter::new(dir.join("out"), "knee", Encoding::Base64)?;
    let mut written = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let s: Vec<f64> = (0..mesh.n_nodes()).map(|i| t * i as f64 + k as f64).collect();
        written.push(series.write_mesh(t, &mesh, vec![Field::point_scalars("s", s)])?);
        // After every step the collection lists exactly the steps so far.
        assert_eq!(read_pvd(series.pvd_path())?.len(), k + 1);
    }
    assert_eq!(series.n_steps(), 3);
    assert_eq!(series.pvd_path(), dir.join("out").join("knee.pvd"));
    assert_eq!(written[2], dir.join("out").join("knee_0002.vtu"));
    // Times must increase; a rejected step leaves the series untouched.
    let err = series.write_mesh(0.2, &mesh, vec![Field::point_scalars("s", vec![0.0; 9])]);
    assert!(matches!(err, Err(IoError::TimeNotIncreasing { .. })));
    let err = series.write_mesh(f64::NAN, &mesh, vec![]);
    assert!(matches!(err, Err(IoError::NonFinite { index: 3, .. })));

    let entries = read_pvd(series.pvd_path())?;
    assert_eq!(entries.len(), 3);
    for (k, e) in entries.iter().enumerate() {
        assert_eq!(e.time.to_bits(), times[k].to_bits());
        assert_eq!(e.part, 0);
        assert_eq!(e.file, written[k]);
        let piece = &read_vtu(&e.file)?.pieces[0];
        let s = piece.point_field("s").ok_or("s")?;
        assert_eq!(s.values[1], times[k] + k as f64);
    }
    // File names in the collection are relative to its directory.
    let text = std::fs::read_to_string(series.pvd_path())?;
    assert!(text.contains(r#"file="knee_0001.vtu""#), "{text}");
    assert!(!dir.join("out").join("knee.pvd.tmp").exists());
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

#[test]
fn pvd_writer_parts_and_paths() -> TestResult {
    let dir = scratch("pvd");
    let mut pvd = PvdWriter::new(dir.join("run.pvd"));
    pvd.add(0.0, dir.join("a_0.vtu"))?
        .add_part(0.0, 1, dir.join("b_0.vtu"))?
        .add(0.5, "sub/a_1.vtu")?
        .add(1.0, "/abs/a_2.vtu")?;
    assert!(matches!(pvd.add(f64::INFINITY, "x.vtu"), Err(IoError::NonFinite { index: 4, .. })));
    pvd.write()?;
    let entries = read_pvd(pvd.path())?;
    let files: Vec<PathBuf> = entries.iter().map(|e| e.file.clone()).collect();
    assert_eq!(
        files,
        [dir.join("a_0.vtu"), dir.join("b_0.vtu"), dir.join("sub/a_1.vtu"), PathBuf::from("/abs/a_2.vtu")]
    );
    let parts: Vec<usize> = entries.iter().map(|e| e.part).collect();
    assert_eq!(parts, [0, 1, 0, 0]);
    let times: Vec<f64> = entries.iter().map(|e| e.time).collect();
    assert_eq!(times, [0.0, 0.0, 0.5, 1.0]);
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

#[test]
fn field_validation_errors() {
    let mesh = grid_2d(2);
    let (nn, nc) = (mesh.n_nodes(), mesh.n_cells());
    let add = |f: Field| VtuWriter::new(Encoding::Ascii).add_piece(&mesh, vec![f]).map(|_| ());

    match add(Field::point_scalars("s", vec![0.0; nn - 1])) {
        Err(IoError::FieldLength { name, expected, got }) => {
            assert_eq!((name.as_str(), expected, got), ("s", nn, nn - 1));
        }
        other => panic!("expected FieldLength, got {other:?}"),
    }
    match add(Field::new("t", FieldLocation::Cell, 9, vec![0.0; 9 * nc + 1])) {
        Err(IoError::FieldLength { expected, .. }) => assert_eq!(expected, 9 * nc),
        other => panic!("expected FieldLength, got {other:?}"),
    }
    let mut values = vec![1.0; 3 * nn];
    values[7] = f64::NAN;
    match add(Field::new("u", FieldLocation::Point, 3, values)) {
        Err(IoError::NonFinite { name, index }) => assert_eq!((name.as_str(), index), ("u", 7)),
        other => panic!("expected NonFinite, got {other:?}"),
    }
    let mut values = vec![1.0; nc];
    values[nc - 1] = f64::NEG_INFINITY;
    assert!(matches!(
        add(Field::cell_scalars("c", values)),
        Err(IoError::NonFinite { index, .. }) if index == nc - 1
    ));
    for bad in [
        Field::cell_scalars(BODY_FIELD, vec![0.0; nc]),
        Field::cell_scalars("", vec![0.0; nc]),
        Field::cell_scalars("a\nb", vec![0.0; nc]),
        Field::new("z", FieldLocation::Point, 0, vec![]),
    ] {
        assert!(matches!(add(bad), Err(IoError::InvalidField { .. })));
    }
    let add_all = |fs: Vec<Field>| VtuWriter::new(Encoding::Ascii).add_piece(&mesh, fs).map(|_| ());
    let dup =
        add_all(vec![Field::point_scalars("d", vec![0.0; nn]), Field::point_scalars("d", vec![1.0; nn])]);
    assert!(matches!(dup, Err(IoError::InvalidField { .. })));
    // Same name at different locations is fine.
    let ok = add_all(vec![Field::point_scalars("d", vec![0.0; nn]), Field::cell_scalars("d", vec![1.0; nc])]);
    assert!(ok.is_ok());
    assert!(matches!(
        TimeSeriesWriter::new(std::env::temp_dir(), "a/b", Encoding::Ascii),
        Err(IoError::InvalidName { .. })
    ));
}

fn assert_parse_error(result: Result<impl std::fmt::Debug, IoError>, what: &str) {
    match result {
        Err(IoError::Parse { message, .. }) => assert!(!message.is_empty(), "{what}"),
        other => panic!("{what}: expected a Parse error, got {other:?}"),
    }
}

#[test]
fn truncated_files_are_parse_errors() -> TestResult {
    let dir = scratch("truncated");
    let mesh = grid_2d(1);
    let fields = vec![Field::point_scalars("s", vec![0.5; mesh.n_nodes()])];
    for encoding in [Encoding::Ascii, Encoding::Base64] {
        let xml = VtuWriter::new(encoding).add_piece(&mesh, fields.clone())?.to_xml_string();
        let end = xml.rfind("</VTKFile>").ok_or("no end tag")?;
        let path = dir.join("cut.vtu");
        for cut in (0..end).step_by(23).chain([end - 1]) {
            std::fs::write(&path, &xml.as_bytes()[..cut])?;
            assert_parse_error(read_vtu(&path), &format!("{encoding:?} cut at {cut}"));
        }
    }
    let pvd = dir.join("run.pvd");
    let mut w = PvdWriter::new(&pvd);
    w.add(0.0, "a.vtu")?.add(1.0, "b.vtu")?;
    w.write()?;
    let text = std::fs::read_to_string(&pvd)?;
    for cut in (0..text.len() - 12).step_by(17) {
        std::fs::write(&pvd, &text.as_bytes()[..cut])?;
        assert_parse_error(read_pvd(&pvd), &format!("pvd cut at {cut}"));
    }
    assert!(matches!(read_vtu(dir.join("missing.vtu")), Err(IoError::Io { .. })));
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

#[test]
fn garbled_files_are_parse_errors() -> TestResult {
    let mesh = grid_2d(1);
    let fields = vec![Field::point_scalars("s", vec![0.5, 1.5, 2.5, 3.5])];
    let ascii = VtuWriter::new(Encoding::Ascii).add_piece(&mesh, fields.clone())?.to_xml_string();
    let binary = VtuWriter::new(Encoding::Base64).add_piece(&mesh, fields)?.to_xml_string();
    let cases: Vec<(&str, String)> = vec![
        ("not xml", "hello world".to_string()),
        ("empty", String::new()),
        ("wrong root", "<Foo/>".to_string()),
        ("wrong type", ascii.replace("UnstructuredGrid\" version", "PolyData\" version")),
        ("bad number", ascii.replace("1.5e0", "1.5x0")),
        ("too few values", ascii.replace(" 1.5e0", "")),
        ("connectivity out of range", ascii.replace("0 1 3 0 3 2", "0 1 3 0 3 9")),
        ("negative index", ascii.replace("0 1 3 0 3 2", "0 1 3 0 3 -2")),
        ("offsets past end", ascii.replace(">\n          3 6\n", ">\n          3 7\n")),
        ("triangle with 4 nodes", ascii.replace(">\n          3 6\n", ">\n          4 6\n")),
        ("missing NumberOfCells", ascii.replace(" NumberOfCells=\"2\"", "")),
        ("mismatched tags", ascii.replace("</Points>", "</Pointz>")),
        ("unknown type", ascii.replace("type=\"Float64\" Name=\"s\"", "type=\"Float99\" Name=\"s\"")),
        ("bad base64", binary.replacen("AAAA", "A!AA", 1)),
        ("short base64", binary.replacen("AAAA", "", 1)),
        ("appended", binary.replacen("format=\"binary\"", "format=\"appended\"", 1)),
        ("no points", ascii.replace("<Points>", "<Pointless>").replace("</Points>", "</Pointless>")),
    ];
    for (what, xml) in &cases {
        assert_parse_error(parse_vtu(xml), what);
    }
    // Sanity: the unmodified documents parse, and each modification changed something.
    assert!(parse_vtu(&ascii).is_ok() && parse_vtu(&binary).is_ok());
    for (what, xml) in &cases {
        assert!(xml != &ascii && xml != &binary, "case `{what}` did not modify the document");
    }
    let dir = scratch("garbled");
    let path = dir.join("binary.vtu");
    std::fs::write(&path, [0xff, 0xfe, 0x00, 0x3c, 0x80])?;
    assert_parse_error(read_vtu(&path), "non-UTF-8 file");
    let pvd = dir.join("x.pvd");
    std::fs::write(
        &pvd,
        r#"<VTKFile type="Collection"><Collection><DataSet timestep="1"/></Collection></VTKFile>"#,
    )?;
    assert_parse_error(read_pvd(&pvd), "DataSet without file");
    std::fs::write(
        &pvd,
        r#"<VTKFile type="Collection"><Collection><DataSet timestep="x" file="a.vtu"/></Collection></VTKFile>"#,
    )?;
    assert_parse_error(read_pvd(&pvd), "bad timestep");
    std::fs::write(&pvd, &ascii)?;
    assert_parse_error(read_pvd(&pvd), "a vtu is not a pvd");
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

/// The reader also accepts the variants other VTK writers produce for the same layout:
/// `Float32`/`Int32` arrays, and base64 headers encoded separately from the data.
#[test]
fn reads_foreign_variants() -> TestResult {
    use base64::engine::general_purpose::STANDARD;
    use base64::Engine;
    let points: Vec<u8> =
        [0f32, 0., 0., 1., 0., 0., 0., 1., 0.].iter().flat_map(|v| v.to_le_bytes()).collect();
    let header = STANDARD.encode((points.len() as u32).to_le_bytes());
    let xml = format!(
        r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
 <UnstructuredGrid><Piece NumberOfPoints="3" NumberOfCells="1">
  <Points><DataArray type="Float32" NumberOfComponents="3" format="binary">{header}{data}</DataArray></Points>
  <Cells>
   <DataArray type="Int32" Name="connectivity" format="ascii">0 1 2</DataArray>
   <DataArray type="Int32" Name="offsets" format="ascii">3</DataArray>
   <DataArray type="UInt8" Name="types" format="ascii">5</DataArray>
  </Cells>
  <CellData><DataArray type="Int32" Name="id" format="ascii">42</DataArray></CellData>
 </Piece></UnstructuredGrid>
</VTKFile>"#,
        data = STANDARD.encode(&points)
    );
    let data = parse_vtu(&xml)?;
    let piece = &data.pieces[0];
    assert_eq!(piece.points, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(piece.cell_field("id").map(|f| f.values.clone()), Some(vec![42.0]));
    let mesh = piece.to_mesh::<2>()?;
    assert_eq!(mesh.measure(), 0.5);
    Ok(())
}

#[test]
fn zlib_arrays_of_many_blocks_read_back_exactly_and_smaller() -> TestResult {
    // 10 201 nodes: the displacement is 245 KB, eight 32 KiB blocks with a partial last one
    let mesh = grid_2d(100);
    let fields = fields_2d(&mesh);
    let smooth: Vec<f64> = mesh.nodes().iter().map(|x| (x[0] * 3.0).sin() * x[1]).collect();
    let mut all = fields.clone();
    all.push(Field::point_scalars("smooth", smooth));
    let zlib = VtuWriter::new(Encoding::Zlib).add_piece(&mesh, all.clone())?.to_xml_string();
    let base64 = VtuWriter::new(Encoding::Base64).add_piece(&mesh, all.clone())?.to_xml_string();
    let piece = &parse_vtu(&zlib)?.pieces[0];
    assert_geometry(piece, &mesh, VTK_TRIANGLE);
    for f in &all {
        assert_field(piece, f);
    }
    assert_eq!(parse_vtu(&zlib)?, parse_vtu(&base64)?);
    assert!(zlib.len() < base64.len(), "{} vs {}", zlib.len(), base64.len());
    Ok(())
}

#[test]
fn corrupt_zlib_arrays_are_parse_errors() -> TestResult {
    let mesh = grid_2d(30);
    let xml = VtuWriter::new(Encoding::Zlib).add_piece(&mesh, fields_2d(&mesh))?.to_xml_string();
    // the first data array's base64 text
    let start = xml.find(r#"format="binary">"#).ok_or("no binary array")? + r#"format="binary">"#.len();
    let end = start + xml[start..].find("</DataArray>").ok_or("unterminated")?;
    let text = xml[start..end].trim();
    let cases = [
        ("truncated", text[..text.len() / 2].to_string()),
        ("empty", String::new()),
        ("bad base64", format!("{}!!!!", &text[..text.len() - 4])),
        // a header announcing 2^32 blocks
        ("huge header", format!("AAAAAAEAAAA={}", &text[12..])),
        // a block flipped in the middle of the compressed data
        ("garbled", {
            let mut t = text.as_bytes().to_vec();
            let k = t.len() - 40;
            t[k] = if t[k] == b'A' { b'B' } else { b'A' };
            String::from_utf8(t)?
        }),
    ];
    for (what, bad) in cases {
        let doc = format!("{}{}{}", &xml[..start], bad, &xml[end..]);
        let err = parse_vtu(&doc).err().ok_or(format!("{what}: accepted"))?;
        assert!(matches!(err, IoError::Parse { .. }), "{what}: {err}");
    }
    let unknown = xml.replace("vtkZLibDataCompressor", "vtkLZ4DataCompressor");
    let err = parse_vtu(&unknown).err().ok_or("lz4 accepted")?;
    assert!(err.to_string().contains("vtkLZ4DataCompressor"), "{err}");
    Ok(())
}

#[test]
fn body_is_a_reserved_point_and_cell_field() -> TestResult {
    let mesh = grid_2d(1);
    for field in [
        Field::point_scalars(BODY_FIELD, vec![0.0; mesh.n_nodes()]),
        Field::cell_scalars(BODY_FIELD, vec![0.0; mesh.n_cells()]),
    ] {
        let err = VtuWriter::new(Encoding::Zlib).add_piece(&mesh, vec![field]).err().ok_or("accepted")?;
        assert!(matches!(err, IoError::InvalidField { .. }), "{err}");
    }
    Ok(())
}

#[test]
fn inconsistent_body_arrays_are_parse_errors() -> TestResult {
    let mesh = grid_2d(1);
    let xml = VtuWriter::new(Encoding::Ascii)
        .add_piece(&mesh, vec![Field::point_scalars("s", vec![1.0; mesh.n_nodes()])])?
        .to_xml_string();
    // the point array comes first (PointData before CellData)
    let point_body = "<DataArray type=\"Int32\" Name=\"body\" format=\"ascii\">\n          0 0 0 0";
    assert!(xml.contains(point_body), "{xml}");
    for (what, values) in [
        ("a huge body index", "0 0 0 999999999"),
        ("a negative body index", "0 0 0 -1"),
        ("a cell across bodies", "0 0 0 1"),
    ] {
        let doc = xml.replace(point_body, &point_body.replace("0 0 0 0", values));
        let err = parse_vtu(&doc).err().ok_or(format!("{what}: accepted"))?;
        assert!(matches!(err, IoError::Parse { .. }), "{what}: {err}");
    }
    Ok(())
}
