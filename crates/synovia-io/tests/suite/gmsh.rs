//! Tests of the Gmsh `.msh` reader: hand-written ASCII fixtures (MSH 4.1 and 2.2), binary files
//! produced by a writer in this file, files produced by the `gmsh` program when it is installed,
//! and malformed input (errors, never panics).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use synovia_io::gmsh::element_type_name;
use synovia_io::{
    default_boundary_kind, parse_msh, read_msh, read_msh_bodies, GmshMesh, IoError, MshVersion,
};
use synovia_mesh::{BoundaryKind, Mesh};
use BoundaryKind::{Clamped, Contact, Symmetry, Traction, TractionFree};

type TestResult = Result<(), Box<dyn std::error::Error>>;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("data").join(name)
}

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(data(name)).expect("fixture exists")
}

fn fixture_str(name: &str) -> String {
    String::from_utf8(fixture(name)).expect("fixture is UTF-8")
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("synovia-io-gmsh-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
}

/// Total measure of a boundary part.
fn part_measure<const D: usize>(mesh: &Mesh<D>, name: &str) -> f64 {
    let part = mesh.boundary_part(name).expect("part exists");
    part.facets().map(|f| mesh.facet_measure(f)).sum()
}

fn body<'a, const D: usize>(bodies: &'a [(String, Mesh<D>)], name: &str) -> &'a Mesh<D> {
    &bodies.iter().find(|(n, _)| n == name).unwrap_or_else(|| panic!("no body `{name}`")).1
}

/// `(name, kind, measure)` of every part of a body, in order.
fn parts<const D: usize>(mesh: &Mesh<D>) -> Vec<(String, BoundaryKind, f64)> {
    mesh.boundary_parts()
        .iter()
        .map(|p| (p.name().to_string(), p.kind(), part_measure(mesh, p.name())))
        .collect()
}

fn assert_parts<const D: usize>(mesh: &Mesh<D>, want: &[(&str, BoundaryKind, f64)]) {
    let got = parts(mesh);
    assert_eq!(got.len(), want.len(), "parts {got:?}, want {want:?}");
    for ((gn, gk, gm), (wn, wk, wm)) in got.iter().zip(want) {
        assert_eq!((gn.as_str(), *gk), (*wn, *wk), "parts {got:?}");
        assert!(close(*gm, *wm), "part `{gn}` measures {gm}, want {wm}");
    }
}

// ---------------------------------------------------------------------------------------------
// A test-side MSH writer
// ---------------------------------------------------------------------------------------------

/// A mesh in Gmsh terms, to be written in any encoding.
#[derive(Debug, Clone, Default)]
struct Spec {
    /// `(dim, tag, name)`.
    names: Vec<(usize, i32, String)>,
    /// `(dim, tag, physical tags)`.
    entities: Vec<(usize, i32, Vec<i32>)>,
    /// `(tag, coordinates, entity (dim, tag))`.
    nodes: Vec<(u64, [f64; 3], (usize, i32))>,
    /// `(tag, type, entity (dim, tag), node tags)`.
    elements: Vec<SpecElement>,
}

/// An element of a [`Spec`]: `(tag, type, entity (dim, tag), node tags)`.
type SpecElement = (u64, i32, (usize, i32), Vec<u64>);

#[derive(Debug, Clone, Copy)]
enum Enc {
    Ascii,
    Binary { big_endian: bool, size_t: usize },
}

const LE8: Enc = Enc::Binary { big_endian: false, size_t: 8 };
const BE8: Enc = Enc::Binary { big_endian: true, size_t: 8 };
const LE4: Enc = Enc::Binary { big_endian: false, size_t: 4 };

/// Low-level output: ASCII values separated by spaces, one record per line, or raw binary.
struct W {
    buf: Vec<u8>,
    enc: Enc,
    fresh: bool,
}

impl W {
    fn new(enc: Enc) -> Self {
        Self { buf: Vec::new(), enc, fresh: true }
    }
    fn text(&mut self, s: &str) {
        self.buf.extend_from_slice(s.as_bytes());
    }
    fn ascii_value(&mut self, s: String) {
        if !self.fresh {
            self.buf.push(b' ');
        }
        self.fresh = false;
        self.text(&s);
    }
    fn int(&mut self, v: i32) {
        match self.enc {
            Enc::Ascii => self.ascii_value(v.to_string()),
            Enc::Binary { big_endian: true, .. } => self.buf.extend_from_slice(&v.to_be_bytes()),
            Enc::Binary { big_endian: false, .. } => self.buf.extend_from_slice(&v.to_le_bytes()),
        }
    }
    fn size(&mut self, v: u64) {
        match self.enc {
            Enc::Ascii => self.ascii_value(v.to_string()),
            Enc::Binary { big_endian, size_t: 4 } => {
                let v = u32::try_from(v).expect("fits in 4 bytes");
                self.buf.extend_from_slice(&if big_endian { v.to_be_bytes() } else { v.to_le_bytes() });
            }
            Enc::Binary { big_endian, .. } => {
                self.buf.extend_from_slice(&if big_endian { v.to_be_bytes() } else { v.to_le_bytes() })
            }
        }
    }
    fn dbl(&mut self, v: f64) {
        match self.enc {
            Enc::Ascii => self.ascii_value(format!("{v:?}")),
            Enc::Binary { big_endian: true, .. } => self.buf.extend_from_slice(&v.to_be_bytes()),
            Enc::Binary { big_endian: false, .. } => self.buf.extend_from_slice(&v.to_le_bytes()),
        }
    }
    /// Ends an ASCII record (a line); nothing in binary.
    fn end(&mut self) {
        if matches!(self.enc, Enc::Ascii) {
            self.buf.push(b'\n');
        }
        self.fresh = true;
    }
    fn header(&mut self, version: &str) {
        let (ty, size) = match self.enc {
            Enc::Ascii => (0, 8),
            Enc::Binary { size_t, .. } => (1, size_t),
        };
        self.text(&format!("$MeshFormat\n{version} {ty} {size}\n"));
        if let Enc::Binary { .. } = self.enc {
            self.int(1);
            self.text("\n");
        }
        self.text("$EndMeshFormat\n");
    }
    /// The closing line of a section (after a newline in binary files, as Gmsh writes them).
    fn close(&mut self, section: &str) {
        if let Enc::Binary { .. } = self.enc {
            self.text("\n");
        }
        self.text(&format!("$End{section}\n"));
    }
    fn physical_names(&mut self, spec: &Spec) {
        if spec.names.is_empty() {
            return;
        }
        self.text(&format!("$PhysicalNames\n{}\n", spec.names.len()));
        for (d, t, n) in &spec.names {
            self.text(&format!("{d} {t} \"{n}\"\n"));
        }
        self.text("$EndPhysicalNames\n");
    }
}

/// Groups items by key, keeping the order of first appearance.
fn group_by<T: Clone, K: PartialEq + Clone>(items: &[T], key: impl Fn(&T) -> K) -> Vec<(K, Vec<T>)> {
    let mut out: Vec<(K, Vec<T>)> = Vec::new();
    for it in items {
        let k = key(it);
        match out.iter_mut().find(|(kk, _)| *kk == k) {
            Some((_, v)) => v.push(it.clone()),
            None => out.push((k, vec![it.clone()])),
        }
    }
    out
}

fn write41(spec: &Spec, enc: Enc) -> Vec<u8> {
    let mut w = W::new(enc);
    w.header("4.1");
    w.physical_names(spec);
    w.text("$Entities\n");
    for d in 0..4 {
        w.size(spec.entities.iter().filter(|e| e.0 == d).count() as u64);
    }
    w.end();
    for d in 0..4 {
        for (_, tag, phys) in spec.entities.iter().filter(|e| e.0 == d) {
            w.int(*tag);
            for _ in 0..(if d == 0 { 3 } else { 6 }) {
                w.dbl(0.0);
            }
            w.size(phys.len() as u64);
            for &p in phys {
                w.int(p);
            }
            if d > 0 {
                w.size(0);
            }
            w.end();
        }
    }
    w.close("Entities");

    w.text("$Nodes\n");
    let blocks = group_by(&spec.nodes, |n| n.2);
    let tags = spec.nodes.iter().map(|n| n.0);
    w.size(blocks.len() as u64);
    w.size(spec.nodes.len() as u64);
    w.size(tags.clone().min().unwrap_or(0));
    w.size(tags.max().unwrap_or(0));
    w.end();
    for ((dim, tag), nodes) in &blocks {
        w.int(*dim as i32);
        w.int(*tag);
        w.int(0);
        w.size(nodes.len() as u64);
        w.end();
        for n in nodes {
            w.size(n.0);
            w.end();
        }
        for n in nodes {
            for &x in &n.1 {
                w.dbl(x);
            }
            w.end();
        }
    }
    w.close("Nodes");

    w.text("$Elements\n");
    let blocks = group_by(&spec.elements, |e| (e.2, e.1));
    let tags = spec.elements.iter().map(|e| e.0);
    w.size(blocks.len() as u64);
    w.size(spec.elements.len() as u64);
    w.size(tags.clone().min().unwrap_or(0));
    w.size(tags.max().unwrap_or(0));
    w.end();
    for (((dim, tag), ty), elements) in &blocks {
        w.int(*dim as i32);
        w.int(*tag);
        w.int(*ty);
        w.size(elements.len() as u64);
        w.end();
        for e in elements {
            w.size(e.0);
            for &n in &e.3 {
                w.size(n);
            }
            w.end();
        }
    }
    w.close("Elements");
    w.buf
}

fn write22(spec: &Spec, enc: Enc) -> Vec<u8> {
    let mut w = W::new(enc);
    w.header("2.2");
    w.physical_names(spec);
    w.text(&format!("$Nodes\n{}\n", spec.nodes.len()));
    for n in &spec.nodes {
        match enc {
            Enc::Ascii => w.size(n.0),
            Enc::Binary { .. } => w.int(i32::try_from(n.0).expect("small tag")),
        }
        for &x in &n.1 {
            w.dbl(x);
        }
        w.end();
    }
    w.close("Nodes");
    // One record per (element, physical tag), as Gmsh writes MSH 2.2.
    let phys: HashMap<(usize, i32), Vec<i32>> =
        spec.entities.iter().map(|(d, t, p)| ((*d, *t), p.clone())).collect();
    let mut records: Vec<(u64, i32, i32, i32, Vec<u64>)> = Vec::new();
    for (tag, ty, entity, nodes) in &spec.elements {
        let ps = phys.get(entity).cloned().unwrap_or_default();
        let ps = if ps.is_empty() { vec![0] } else { ps };
        for p in ps {
            records.push((*tag, *ty, p, entity.1, nodes.clone()));
        }
    }
    w.text(&format!("$Elements\n{}\n", records.len()));
    match enc {
        Enc::Ascii => {
            for (tag, ty, p, e, nodes) in &records {
                w.size(*tag);
                w.int(*ty);
                w.int(2);
                w.int(*p);
                w.int(*e);
                for &n in nodes {
                    w.size(n);
                }
                w.end();
            }
        }
        Enc::Binary { .. } => {
            // Runs of consecutive elements of one type share a header.
            let mut i = 0;
            while i < records.len() {
                let ty = records[i].1;
                let run = records[i..].iter().take_while(|r| r.1 == ty).count();
                w.int(ty);
                w.int(run as i32);
                w.int(2);
                for (tag, _, p, e, nodes) in &records[i..i + run] {
                    w.int(*tag as i32);
                    w.int(*p);
                    w.int(*e);
                    for &n in nodes {
                        w.int(n as i32);
                    }
                }
                i += run;
            }
        }
    }
    w.close("Elements");
    w.buf
}

/// Rebuilds a [`Spec`] from a parsed file (all nodes in one block), to re-encode it.
fn spec_from(msh: &GmshMesh) -> Spec {
    let mut spec = Spec {
        names: msh.physical_names.iter().map(|p| (p.dim, p.tag, p.name.clone())).collect(),
        ..Spec::default()
    };
    for b in &msh.element_blocks {
        if !spec.entities.iter().any(|e| e.0 == b.dim && e.1 == b.entity_tag) {
            spec.entities.push((b.dim, b.entity_tag, b.physical_tags.clone()));
        }
        for (e, &tag) in b.element_tags.iter().enumerate() {
            let nodes = b.element(e).iter().map(|&i| msh.node_tags[i]).collect();
            spec.elements.push((tag, b.element_type, (b.dim, b.entity_tag), nodes));
        }
    }
    let entity = (spec.entities[0].0, spec.entities[0].1);
    spec.nodes = msh.node_tags.iter().zip(&msh.nodes).map(|(&t, &x)| (t, x, entity)).collect();
    spec
}

/// Two unit cubes `[0,1]² × [0,1]` (`tibia`) and `[0,1]² × [1,2]` (`femur`), 6 Kuhn tetrahedra
/// each, sharing the nodes of the face `z = 1`; node tags are scrambled. Boundary groups:
/// `clamped_base` (z = 0), `contact_cartilage` (z = 1, on both bodies), `prescribed_top`
/// (z = 2), unnamed group 12 (all lateral faces), plus a point and a line group (ignored in 3D).
fn two_cubes() -> Spec {
    let mut spec = Spec::default();
    for (d, t, n) in [
        (3, 1, "tibia"),
        (3, 2, "femur"),
        (2, 1, "clamped_base"),
        (2, 10, "contact_cartilage"),
        (2, 11, "prescribed_top"),
        (0, 7, "origin"),
        (1, 8, "edge"),
    ] {
        spec.names.push((d, t, n.to_string()));
    }
    spec.entities = vec![
        (0, 1, vec![7]),
        (1, 1, vec![8]),
        (2, 1, vec![1]),
        (2, 2, vec![10]),
        (2, 3, vec![11]),
        (2, 4, vec![12]),
        (2, 5, vec![12]),
        (3, 1, vec![1]),
        (3, 2, vec![2]),
    ];
    let tag = |idx: usize| ((idx * 5) % 12 + 1) as u64; // a permutation of 1..=12
    for idx in 0..12 {
        let (i, j, k) = (idx & 1, (idx >> 1) & 1, idx >> 2);
        let entity = (3, if k < 2 { 1 } else { 2 });
        spec.nodes.push((tag(idx), [i as f64, j as f64, k as f64], entity));
    }
    let z = |idx: usize| (idx >> 2) as f64;
    let mut next = 100u64;
    let mut triangles = Vec::new();
    for cube in 0..2 {
        let global = |v: usize| (v & 1) + 2 * ((v >> 1) & 1) + 4 * (((v >> 2) & 1) + cube);
        let mut tets = Vec::new();
        for perm in [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
            let mut v = 0usize;
            let mut tet = vec![global(v)];
            for axis in perm {
                v |= 1 << axis;
                tet.push(global(v));
            }
            tets.push(tet);
        }
        let mut faces: HashMap<Vec<usize>, (usize, Vec<usize>)> = HashMap::new();
        for tet in &tets {
            for opp in 0..4 {
                let face: Vec<usize> = (0..4).filter(|&k| k != opp).map(|k| tet[k]).collect();
                let mut key = face.clone();
                key.sort_unstable();
                faces.entry(key).or_insert((0, face)).0 += 1;
            }
        }
        let mut boundary: Vec<Vec<usize>> = faces.into_values().filter(|f| f.0 == 1).map(|f| f.1).collect();
        boundary.sort();
        for face in boundary {
            let zs: Vec<f64> = face.iter().map(|&i| z(i)).collect();
            let flat = |v: f64| zs.iter().all(|&zz| zz == v);
            let entity = if flat(cube as f64) {
                if cube == 0 {
                    1
                } else {
                    continue; // the interface, already added from the lower cube
                }
            } else if flat(cube as f64 + 1.0) {
                if cube == 0 {
                    2
                } else {
                    3
                }
            } else {
                4 + cube as i32
            };
            triangles.push((entity, face));
        }
        for tet in tets {
            next += 1;
            spec.elements.push((next, 4, (3, cube as i32 + 1), tet.iter().map(|&i| tag(i)).collect()));
        }
    }
    for (entity, face) in triangles {
        next += 1;
        spec.elements.push((next, 2, (2, entity), face.iter().map(|&i| tag(i)).collect()));
    }
    spec.elements.push((1, 15, (0, 1), vec![tag(0)]));
    spec.elements.push((2, 1, (1, 1), vec![tag(0), tag(1)]));
    spec
}

// ---------------------------------------------------------------------------------------------
// Hand-written ASCII fixtures
// ---------------------------------------------------------------------------------------------

fn check_two_squares(bodies: &[(String, Mesh<2>)]) {
    let names: Vec<&str> = bodies.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["lower", "upper"]);
    let lower = body(bodies, "lower");
    let upper = body(bodies, "upper");
    assert_eq!((lower.n_nodes(), lower.n_cells()), (4, 2));
    assert_eq!((upper.n_nodes(), upper.n_cells()), (5, 3));
    assert!(close(lower.measure(), 1.0) && close(upper.measure(), 1.0));
    for c in 0..upper.n_cells() {
        assert!(upper.cell_measure(c) > 0.0, "cell {c} repaired to positive orientation");
    }
    // Nodes are numbered by Gmsh tag: upper holds tags 3, 4, 5, 6, 7.
    let coords: Vec<[f64; 2]> = upper.nodes().iter().map(|p| [p[0], p[1]]).collect();
    assert_eq!(coords, [[1.0, 1.0], [0.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.5, 2.0]]);
    use BoundaryKind::*;
    assert_parts(
        lower,
        &[
            ("free_right", TractionFree, 1.0),
            ("clamped_bottom", Clamped, 1.0),
            ("Contact_Interface", Contact, 1.0),
            ("symmetry_left", Symmetry, 1.0),
        ],
    );
    assert_parts(
        upper,
        &[
            ("Contact_Interface", Contact, 1.0),
            ("symmetry_left", Symmetry, 1.0),
            ("traction_top", Traction, 1.0),
            ("physical_15", TractionFree, 1.0),
        ],
    );
    // Outward normals: the interface points down (−y) on `upper`, up (+y) on `lower`.
    let n_up = upper.nodal_normals("Contact_Interface").expect("part");
    assert!(n_up.iter().all(|(_, n)| close(n[1], -1.0)));
    let n_low = lower.nodal_normals("Contact_Interface").expect("part");
    assert!(n_low.iter().all(|(_, n)| close(n[1], 1.0)));
}

#[test]
fn ascii_41_fixture() -> TestResult {
    let msh = read_msh(data("two_squares_41.msh"))?;
    assert_eq!((msh.version, msh.binary), (MshVersion::Msh41, false));
    assert_eq!(msh.nodes.len(), 7);
    assert_eq!(msh.element_blocks.len(), 10);
    assert_eq!(msh.element_blocks.iter().map(|b| b.len()).sum::<usize>(), 14);
    let groups: Vec<(usize, i32, String, usize)> =
        msh.physical_groups().into_iter().map(|g| (g.dim, g.tag, g.name, g.n_elements)).collect();
    let want: Vec<(usize, i32, String, usize)> = [
        (0, 100, "corner", 1),
        (1, 1, "free_right", 1),
        (1, 11, "clamped_bottom", 1),
        (1, 12, "Contact_Interface", 1),
        (1, 13, "symmetry_left", 2),
        (1, 14, "traction_top", 2),
        (1, 15, "physical_15", 1),
        (2, 1, "lower", 2),
        (2, 2, "upper", 3),
    ]
    .into_iter()
    .map(|(d, t, n, c)| (d, t, n.to_string(), c))
    .collect();
    assert_eq!(groups, want);
    check_two_squares(&msh.bodies::<2>()?);
    check_two_squares(&read_msh_bodies::<2>(data("two_squares_41.msh"))?);
    Ok(())
}

#[test]
fn ascii_22_fixture_matches_41() -> TestResult {
    let msh = read_msh(data("two_squares_22.msh"))?;
    assert_eq!((msh.version, msh.binary), (MshVersion::Msh22, false));
    assert_eq!(msh.nodes.len(), 7);
    let b22 = msh.bodies::<2>()?;
    check_two_squares(&b22);
    let b41 = read_msh(data("two_squares_41.msh"))?.bodies::<2>()?;
    assert_eq!(b22, b41, "MSH 2.2 and 4.1 of the same mesh give identical bodies");
    Ok(())
}

#[test]
fn fixtures_reencoded_in_every_format_agree() -> TestResult {
    let want = read_msh(data("two_squares_41.msh"))?.bodies::<2>()?;
    let spec = spec_from(&read_msh(data("two_squares_22.msh"))?);
    for enc in [Enc::Ascii, LE8, BE8, LE4] {
        let got = parse_msh(&write41(&spec, enc))?;
        assert_eq!(got.version, MshVersion::Msh41);
        assert_eq!(got.bodies::<2>()?, want, "4.1 {enc:?}");
    }
    for enc in [Enc::Ascii, LE8, BE8] {
        let got = parse_msh(&write22(&spec, enc))?;
        assert_eq!(got.version, MshVersion::Msh22);
        assert_eq!(got.bodies::<2>()?, want, "2.2 {enc:?}");
    }
    Ok(())
}

#[test]
fn custom_part_kinds() -> TestResult {
    let msh = read_msh(data("two_squares_41.msh"))?;
    let kind = |name: &str| match name {
        "traction_top" => BoundaryKind::Prescribed,
        "physical_15" => BoundaryKind::Clamped,
        other => default_boundary_kind(other),
    };
    let bodies = msh.bodies_with_kinds::<2>(&kind)?;
    let upper = body(&bodies, "upper");
    assert_eq!(upper.boundary_part("traction_top")?.kind(), BoundaryKind::Prescribed);
    assert_eq!(upper.boundary_part("physical_15")?.kind(), BoundaryKind::Clamped);
    assert_eq!(upper.boundary_part("symmetry_left")?.kind(), BoundaryKind::Symmetry);
    Ok(())
}

#[test]
fn default_kind_convention() {
    use BoundaryKind::*;
    for (name, kind) in [
        ("clamped", Clamped),
        ("Clamped_Base", Clamped),
        ("PRESCRIBED_displacement", Prescribed),
        ("traction", Traction),
        ("traction_load", Traction),
        ("Traction_Free_side", TractionFree),
        ("traction-free", TractionFree),
        ("tractionfree", TractionFree),
        ("free_surface", TractionFree),
        ("symmetry_x", Symmetry),
        ("Contact_cartilage", Contact),
        ("femur_surface", TractionFree),
        ("", TractionFree),
    ] {
        assert_eq!(default_boundary_kind(name), kind, "{name}");
    }
}

#[test]
fn element_type_names() {
    assert_eq!(element_type_name(1), "2-node line");
    assert_eq!(element_type_name(2), "3-node triangle");
    assert_eq!(element_type_name(3), "4-node quadrangle");
    assert_eq!(element_type_name(4), "4-node tetrahedron");
    assert_eq!(element_type_name(9), "6-node triangle");
    assert_eq!(element_type_name(11), "10-node tetrahedron");
    assert_eq!(element_type_name(15), "1-node point");
    assert_eq!(element_type_name(93), "125-node hexahedron");
    assert_eq!(element_type_name(34), "polygon");
    assert_eq!(element_type_name(0), "unknown element type");
}

// ---------------------------------------------------------------------------------------------
// 3D, binary
// ---------------------------------------------------------------------------------------------

fn check_two_cubes(bodies: &[(String, Mesh<3>)]) {
    let names: Vec<&str> = bodies.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["tibia", "femur"]);
    use BoundaryKind::*;
    for (name, parts) in [
        (
            "tibia",
            [
                ("clamped_base", Clamped, 1.0),
                ("contact_cartilage", Contact, 1.0),
                ("physical_12", TractionFree, 4.0),
            ],
        ),
        (
            "femur",
            [
                ("contact_cartilage", Contact, 1.0),
                ("prescribed_top", Prescribed, 1.0),
                ("physical_12", TractionFree, 4.0),
            ],
        ),
    ] {
        let mesh = body(bodies, name);
        assert_eq!((mesh.n_nodes(), mesh.n_cells()), (8, 6), "{name}");
        assert!(close(mesh.measure(), 1.0), "{name} volume {}", mesh.measure());
        assert_parts(mesh, &parts);
    }
    // Nodes by increasing tag: tibia holds grid nodes 0..8 with tags (5 idx mod 12) + 1, the
    // smallest being tag 1 at grid node 0, then tag 2 at grid node 5 = (1, 0, 1).
    let tibia = body(bodies, "tibia");
    assert_eq!([tibia.node(0)[0], tibia.node(0)[1], tibia.node(0)[2]], [0.0, 0.0, 0.0]);
    assert_eq!([tibia.node(1)[0], tibia.node(1)[1], tibia.node(1)[2]], [1.0, 0.0, 1.0]);
}

#[test]
fn binary_41_two_cubes_every_encoding_agrees() -> TestResult {
    let spec = two_cubes();
    let reference = parse_msh(&write41(&spec, Enc::Ascii))?.bodies::<3>()?;
    check_two_cubes(&reference);
    for enc in [LE8, BE8, LE4] {
        let msh = parse_msh(&write41(&spec, enc))?;
        assert_eq!((msh.version, msh.binary), (MshVersion::Msh41, true));
        assert_eq!(msh.nodes.len(), 12);
        assert_eq!(msh.bodies::<3>()?, reference, "4.1 {enc:?}");
    }
    for enc in [Enc::Ascii, LE8, BE8] {
        let msh = parse_msh(&write22(&spec, enc))?;
        assert_eq!(msh.version, MshVersion::Msh22);
        assert_eq!(msh.bodies::<3>()?, reference, "2.2 {enc:?}");
    }
    // Through a file.
    let dir = scratch("binary41");
    let path = dir.join("two_cubes.msh");
    std::fs::write(&path, write41(&spec, LE8))?;
    assert_eq!(read_msh_bodies::<3>(&path)?, reference);
    // The same file read as 2D has no surface body that lies in z = 0.
    assert!(matches!(read_msh(&path)?.bodies::<2>(), Err(IoError::GmshMapping(_))));
    Ok(())
}

#[test]
fn wrong_dimension_is_an_error() -> TestResult {
    let msh = read_msh(data("two_squares_41.msh"))?;
    match msh.bodies::<3>() {
        Err(IoError::GmshMapping(m)) => assert!(m.contains("no physical group of dimension 3"), "{m}"),
        other => panic!("expected a mapping error, got {other:?}"),
    }
    assert!(matches!(msh.bodies::<1>(), Err(IoError::Mesh(_))));
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// The gmsh program (installed in CI)
// ---------------------------------------------------------------------------------------------

/// A list of simplices by vertex coordinates (padded to 3), each sorted, the list sorted.
type Simplices = Vec<Vec<[f64; 3]>>;
/// Cells and parts of each body by coordinates, independent of node and element numbering.
type Canonical = Vec<(String, Simplices, Vec<(String, Simplices)>)>;

fn canonical<const D: usize>(bodies: &[(String, Mesh<D>)]) -> Canonical {
    let simplices = |mesh: &Mesh<D>, list: &mut dyn Iterator<Item = &[usize]>| {
        let key = |v: &[f64; 3]| v.map(f64::to_bits);
        let mut out: Simplices = list
            .map(|c| {
                let mut v: Vec<[f64; 3]> = c
                    .iter()
                    .map(|&i| std::array::from_fn(|k| if k < D { mesh.node(i)[k] } else { 0.0 }))
                    .collect();
                v.sort_unstable_by_key(key);
                v
            })
            .collect();
        out.sort_unstable_by(|a, b| a.iter().map(key).cmp(b.iter().map(key)));
        out
    };
    bodies
        .iter()
        .map(|(name, mesh)| {
            let mut parts: Vec<(String, Simplices)> = mesh
                .boundary_parts()
                .iter()
                .map(|p| (p.name().to_string(), simplices(mesh, &mut p.facets())))
                .collect();
            parts.sort_by(|a, b| a.0.cmp(&b.0));
            (name.clone(), simplices(mesh, &mut mesh.cells()), parts)
        })
        .collect()
}

/// Whether two canonical forms agree, coordinates within `tol`.
fn same(a: &Canonical, b: &Canonical, tol: f64) -> bool {
    let simplices = |x: &Simplices, y: &Simplices| {
        x.len() == y.len()
            && x.iter().zip(y).all(|(s, t)| {
                s.len() == t.len()
                    && s.iter().zip(t).all(|(p, q)| p.iter().zip(q).all(|(u, v)| (u - v).abs() <= tol))
            })
    };
    a.len() == b.len()
        && a.iter().zip(b).all(|((an, ac, ap), (bn, bc, bp))| {
            an == bn
                && simplices(ac, bc)
                && ap.len() == bp.len()
                && ap.iter().zip(bp).all(|((pn, ps), (qn, qs))| pn == qn && simplices(ps, qs))
        })
}

/// Checks body names, cell counts, measures (1 each) and the parts
/// `(body, part, kind, measure)` of a mesh written by Gmsh.
fn check_bodies<const D: usize>(
    file: &str,
    bodies: &[(String, Mesh<D>)],
    bodies_want: &[&str],
    parts_want: &[(&str, &str, BoundaryKind, f64)],
) -> TestResult {
    let names: Vec<&str> = bodies.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, bodies_want, "{file}");
    for (name, mesh) in bodies {
        assert!(mesh.n_cells() > 10, "{file}: {name} has {} cells", mesh.n_cells());
        assert!(close(mesh.measure(), 1.0), "{file}: {name} measures {}", mesh.measure());
        let n_parts = parts_want.iter().filter(|p| p.0 == name).count();
        assert_eq!(mesh.boundary_parts().len(), n_parts, "{file}: {name}: {:?}", parts(mesh));
    }
    for &(name, part, kind, measure) in parts_want {
        let mesh = body(bodies, name);
        assert_eq!(mesh.boundary_part(part)?.kind(), kind, "{file}: {name}.{part}");
        let got = part_measure(mesh, part);
        assert!(close(got, measure), "{file}: {name}.{part} measures {got}, want {measure}");
    }
    Ok(())
}

/// Parts of the bodies meshed from `two_squares.geo`.
const SQUARES_PARTS: [(&str, &str, BoundaryKind, f64); 8] = [
    ("lower", "clamped_bottom", Clamped, 1.0),
    ("lower", "contact_interface", Contact, 1.0),
    ("lower", "symmetry_left", Symmetry, 1.0),
    ("lower", "free_right", TractionFree, 1.0),
    ("upper", "contact_interface", Contact, 1.0),
    ("upper", "traction_top", Traction, 1.0),
    ("upper", "symmetry_left", Symmetry, 1.0),
    ("upper", "free_right", TractionFree, 1.0),
];

/// Parts of the bodies meshed from `two_boxes.geo`.
const BOXES_PARTS: [(&str, &str, BoundaryKind, f64); 8] = [
    ("lower", "clamped_bottom", Clamped, 1.0),
    ("lower", "contact_interface", Contact, 1.0),
    ("lower", "symmetry_back", Symmetry, 1.0),
    ("lower", "symmetry_front", Symmetry, 1.0),
    ("upper", "contact_interface", Contact, 1.0),
    ("upper", "traction_top", Traction, 1.0),
    ("upper", "symmetry_back", Symmetry, 1.0),
    ("upper", "symmetry_front", Symmetry, 1.0),
];

#[test]
fn binary_files_written_by_gmsh() -> TestResult {
    let msh = read_msh(data("two_squares_gmsh41_bin.msh"))?;
    assert_eq!((msh.version, msh.binary), (MshVersion::Msh41, true));
    check_bodies("two_squares_gmsh41_bin.msh", &msh.bodies::<2>()?, &["lower", "upper"], &SQUARES_PARTS)?;
    let msh = read_msh(data("two_boxes_gmsh22_bin.msh"))?;
    assert_eq!((msh.version, msh.binary), (MshVersion::Msh22, true));
    check_bodies("two_boxes_gmsh22_bin.msh", &msh.bodies::<3>()?, &["lower", "upper"], &BOXES_PARTS)?;
    Ok(())
}

/// Meshes `geo` with the `gmsh` program in MSH 4.1 and 2.2, ASCII and binary, reads the four
/// files as `D`-dimensional bodies, checks body names, cell counts, measures and the parts
/// `(body, part, kind, measure)`, and that the four files give the same meshes. `None` when
/// `gmsh` is not installed.
fn check_gmsh_program<const D: usize>(
    geo: &str,
    bodies_want: &[&str],
    parts_want: &[(&str, &str, BoundaryKind, f64)],
) -> Result<Option<()>, Box<dyn std::error::Error>> {
    if std::process::Command::new("gmsh").arg("-version").output().is_err() {
        eprintln!("note: `gmsh` is not on PATH; skipping the test on files written by gmsh from {geo}");
        return Ok(None);
    }
    let dir = scratch(&format!("gmsh-program-{D}d"));
    let mut all = Vec::new();
    for (file, args, version, binary) in [
        ("msh41.msh", &["-format", "msh41"][..], MshVersion::Msh41, false),
        ("msh41_bin.msh", &["-format", "msh41", "-bin"][..], MshVersion::Msh41, true),
        ("msh22.msh", &["-format", "msh22"][..], MshVersion::Msh22, false),
        ("msh22_bin.msh", &["-format", "msh22", "-bin"][..], MshVersion::Msh22, true),
    ] {
        let out = dir.join(file);
        let run = std::process::Command::new("gmsh")
            .arg(format!("-{D}"))
            .arg(data(geo))
            .arg("-o")
            .arg(&out)
            .args(args)
            .output()?;
        assert!(run.status.success(), "gmsh failed on {geo}: {}", String::from_utf8_lossy(&run.stderr));
        let msh = read_msh(&out)?;
        assert_eq!((msh.version, msh.binary), (version, binary), "{file}");
        let bodies = msh.bodies::<D>()?;
        check_bodies(file, &bodies, bodies_want, parts_want)?;
        all.push((file, canonical(&bodies)));
    }
    // ASCII files hold 17 significant digits, binary files the exact doubles: the same mesh up
    // to round-off, and bit for bit within one encoding.
    let (ascii41, bin41, ascii22, bin22) = (&all[0], &all[1], &all[2], &all[3]);
    assert!(same(&ascii41.1, &ascii22.1, 0.0), "{} and {} differ", ascii41.0, ascii22.0);
    assert!(same(&bin41.1, &bin22.1, 0.0), "{} and {} differ", bin41.0, bin22.0);
    assert!(same(&ascii41.1, &bin41.1, 1e-15), "{} and {} differ", ascii41.0, bin41.0);
    Ok(Some(()))
}

#[test]
fn gmsh_program_2d() -> TestResult {
    check_gmsh_program::<2>("two_squares.geo", &["lower", "upper"], &SQUARES_PARTS)?;
    Ok(())
}

#[test]
fn gmsh_program_3d() -> TestResult {
    check_gmsh_program::<3>("two_boxes.geo", &["lower", "upper"], &BOXES_PARTS)?;
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------------

fn parse_err(bytes: &[u8]) -> String {
    match parse_msh(bytes) {
        Err(e @ IoError::Parse { .. }) => e.to_string(),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

/// The 1-based line of the first occurrence of `needle` in `text` (after the needle's leading
/// newlines).
fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).expect("needle in text");
    let skip = needle.len() - needle.trim_start_matches('\n').len();
    text[..at + skip].matches('\n').count() + 1
}

fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` not in the text");
    text.replacen(from, to, 1)
}

#[test]
fn unsupported_element_types() -> TestResult {
    let quadratic = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
        $PhysicalNames\n1\n2 1 \"femur\"\n$EndPhysicalNames\n\
        $Entities\n0 0 1 0\n1 0 0 0 1 1 0 1 1 0\n$EndEntities\n\
        $Nodes\n1 6 1 6\n2 1 0 6\n1\n2\n3\n4\n5\n6\n\
        0 0 0\n1 0 0\n0 1 0\n0.5 0 0\n0.5 0.5 0\n0 0.5 0\n$EndNodes\n\
        $Elements\n1 1 1 1\n2 1 9 1\n1 1 2 3 4 5 6\n$EndElements\n";
    let msh = parse_msh(quadratic.as_bytes())?;
    let err = msh.bodies::<2>().expect_err("6-node triangles are rejected");
    assert_eq!(
        err.to_string(),
        "unsupported element type 9 (6-node triangle) in physical group `femur`; synovia uses P1 simplices"
    );
    // Quadrangles in a MSH 2.2 body.
    let text = fixture_str("two_squares_22.msh");
    let text = replace_once(&text, "\n2 2 2 1 1 1 3 4\n", "\n2 3 2 1 1 1 3 4 2\n");
    match parse_msh(text.as_bytes())?.bodies::<2>() {
        Err(IoError::UnsupportedElement { element_type: 3, description, group }) => {
            assert_eq!((description.as_str(), group.as_str()), ("4-node quadrangle", "lower"));
        }
        other => panic!("expected an unsupported element, got {other:?}"),
    }
    // Second-order lines in a boundary group.
    let text = fixture_str("two_squares_22.msh");
    let text = replace_once(&text, "\n6 1 2 11 1 1 2\n", "\n6 8 2 11 1 1 2 3\n");
    match parse_msh(text.as_bytes())?.bodies::<2>() {
        Err(IoError::UnsupportedElement { element_type: 8, group, .. }) => {
            assert_eq!(group, "clamped_bottom")
        }
        other => panic!("expected an unsupported element, got {other:?}"),
    }
    Ok(())
}

#[test]
fn unsupported_versions() {
    for (text, version) in [
        ("$MeshFormat\n4 0 8\n$EndMeshFormat\n", "4"),
        ("$MeshFormat\n4.0 0 8\n$EndMeshFormat\n", "4.0"),
        ("$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", "3.0"),
        ("$NOD\n1\n1 0 0 0\n$ENDNOD\n", "1.0"),
    ] {
        match parse_msh(text.as_bytes()) {
            Err(e @ IoError::MshVersion { .. }) => {
                let m = e.to_string();
                assert!(m.contains(&format!("version {version};")) && m.contains("msh41"), "{m}");
            }
            other => panic!("expected a version error for {text:?}, got {other:?}"),
        }
    }
}

#[test]
fn malformed_ascii_files_report_the_line() {
    let t41 = fixture_str("two_squares_41.msh");
    let t22 = fixture_str("two_squares_22.msh");
    let cases: Vec<(String, String, &str)> = vec![
        // (file, the line the error is on, what the message says)
        (replace_once(&t41, "\n1 1 2 3\n", "\n1 1 2 99\n"), "\n1 1 2 99\n".into(), "node 99"),
        (replace_once(&t41, "0.5 2 0 0.5", "0.5 2 zero 0.5"), "0.5 2 zero".into(), "`zero`"),
        (replace_once(&t41, "0.5 2 0 0.5", "0.5 2 0"), "0.5 2 0\n".into(), "parametric"),
        (replace_once(&t41, "0.5 2 0 0.5", "0.5 2 0 0.5 7"), "0.5 2 0 0.5 7".into(), "extra value `7`"),
        (replace_once(&t41, "\n1 1 2 3\n", "\n1 1 2 3 4\n"), "\n1 1 2 3 4\n".into(), "needs 3"),
        (replace_once(&t41, "$Nodes\n7 7 1 7", "$Nodes\n7 8 1 7"), "7 8 1 7".into(), "announces 8 nodes"),
        (replace_once(&t41, "2 2 2 3\n", "2 2 2 4\n"), "$EndElements".into(), "found `$EndElements`"),
        (
            replace_once(&t41, "2 2 2 3\n", "2 2 2 2\n"),
            "10 14 1 14".into(),
            "announces 14 elements, but its blocks hold 13",
        ),
        (
            replace_once(&t41, "10 14 1 14", "9 11 1 14"),
            "2 2 2 3".into(),
            "expected `$EndElements`, found `2 2 2 3`",
        ),
        (replace_once(&t41, "2 2 2 3\n", "2 7 2 3\n"), "2 7 2 3".into(), "entity (dimension 2, tag 7)"),
        (replace_once(&t41, "0 1 15 1", "0 1 77 1"), "0 1 77 1".into(), "unknown element type 77"),
        (replace_once(&t41, "0 1 15 1", "1 1 15 1"), "1 1 15 1".into(), "dimension"),
        (replace_once(&t41, "\n7\n0.5", "\n6\n0.5"), "\n6\n0.5".into(), "node tag 6 is defined twice"),
        (replace_once(&t41, "2 2 \"upper\"", "2 2 upper\""), "2 2 upper".into(), "double quotes"),
        (replace_once(&t41, "$EndComments\n", ""), "$Comments".into(), "not closed"),
        (
            replace_once(
                &t41,
                "$EndEntities\n",
                "$EndEntities\n$PartitionedEntities\n$EndPartitionedEntities\n",
            ),
            "$PartitionedEntities".into(),
            "partitioned",
        ),
        (replace_once(&t22, "\n7\n1 0 0 0", "\n8\n1 0 0 0"), "$EndNodes".into(), "ends too early"),
        (replace_once(&t22, "\n7\n1 0 0 0", "\n6\n1 0 0 0"), "7 0.5 2 0".into(), "expected `$EndNodes`"),
        (
            replace_once(&t22, "\n14\n1 2 2", "\n18446744073709551615\n1 2 2"),
            "$EndElements".into(),
            "ends too early",
        ),
        (replace_once(&t22, "3 1 1 0", "3 1 nan 0"), "3 1 nan".into(), "not finite"),
        (replace_once(&t22, "2.2 0 8", "2.2 2 8"), "2.2 2 8".into(), "file type"),
        (replace_once(&t22, "$EndNodes", "$EndNode"), "$EndNode".into(), "expected `$EndNodes`"),
        (replace_once(&t22, "$MeshFormat", "$Mesh"), "$Mesh".into(), "start of the file"),
    ];
    for (text, line, what) in cases {
        let msg = parse_err(text.as_bytes());
        let at = format!("line {}:", line_of(&text, &line));
        assert!(
            msg.contains(&at) && msg.contains(what),
            "message `{msg}` should contain `{at}` and `{what}`"
        );
    }
    // A missing section is reported at the end of the file.
    let text = t22.replacen("$Elements", "$Elementz", 1).replacen("$EndElements", "$EndElementz", 1);
    let msg = parse_err(text.as_bytes());
    let last = format!("line {}:", text.matches('\n').count() + 1);
    assert!(msg.contains(&last) && msg.contains("missing `$Elements` section"), "{msg}");
    // Errors without a meaningful line.
    assert!(parse_err(b"").contains("empty"));
    assert!(parse_err(b"   \n\n").contains("empty"));
    assert!(parse_err(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n").contains("missing `$Nodes`"));
}

#[test]
fn mapping_errors() -> TestResult {
    let t22 = fixture_str("two_squares_22.msh");
    // A boundary group on the diagonal of `lower`: on no body's boundary.
    let text = replace_once(&t22, "\n14\n1 2 2", "\n15\n1 2 2");
    let text = replace_once(&text, "14 15 2 100 1 1\n", "14 15 2 100 1 1\n15 1 2 16 8 1 3\n");
    let text = replace_once(&text, "8\n0 100", "9\n1 16 \"diagonal\"\n0 100");
    match parse_msh(text.as_bytes())?.bodies::<2>() {
        Err(e @ IoError::GmshMapping(_)) => assert!(e.to_string().contains("`diagonal`"), "{e}"),
        other => panic!("expected a mapping error, got {other:?}"),
    }
    // A node off the plane z = 0.
    let text = replace_once(&t22, "7 0.5 2 0\n", "7 0.5 2 1e-3\n");
    match parse_msh(text.as_bytes())?.bodies::<2>() {
        Err(e @ IoError::GmshMapping(_)) => assert!(e.to_string().contains("node 7 has z = 1e-3"), "{e}"),
        other => panic!("expected a mapping error, got {other:?}"),
    }
    // Round-off in z is accepted.
    let text = replace_once(&t22, "7 0.5 2 0\n", "7 0.5 2 1e-15\n");
    parse_msh(text.as_bytes())?.bodies::<2>()?;
    // A degenerate cell: node 7 moved onto node 6.
    let text = replace_once(&t22, "7 0.5 2 0\n", "7 0 2 0\n");
    match parse_msh(text.as_bytes())?.bodies::<2>() {
        Err(e @ IoError::GmshBody { .. }) => assert!(e.to_string().contains("`upper`"), "{e}"),
        other => panic!("expected a body error, got {other:?}"),
    }
    // Two bodies with one name.
    let text = replace_once(&t22, "2 2 \"upper\"", "2 2 \"lower\"");
    assert!(matches!(parse_msh(text.as_bytes())?.bodies::<2>(), Err(IoError::GmshMapping(_))));
    // A named body group without elements.
    let text = replace_once(&t22, "8\n0 100", "9\n2 3 \"ghost\"\n0 100");
    match parse_msh(text.as_bytes())?.bodies::<2>() {
        Err(e @ IoError::GmshMapping(_)) => assert!(e.to_string().contains("`ghost`"), "{e}"),
        other => panic!("expected a mapping error, got {other:?}"),
    }
    Ok(())
}

#[test]
fn malformed_binary_files_report_the_byte_offset() {
    let good = write41(&two_cubes(), LE8);
    assert!(parse_msh(&good).is_ok());
    // Truncated inside the last node's coordinates (which end with the newline before
    // `$EndNodes`): the error points at the start of the coordinate that cannot be read.
    let end = find(&good, b"$EndNodes") - 1;
    let msg = parse_err(&good[..end - 20]);
    let x = end - 24;
    assert!(
        msg.contains(&format!("byte offset {x}:")) && msg.contains("end of file while reading x"),
        "{msg}"
    );
    // A node tag the elements do not know.
    let mut bad = good.clone();
    let at = find(&bad, b"$Elements\n") + 10 + 4 * 8 + 3 * 4 + 8 + 8; // first node of the first element
    bad[at..at + 8].copy_from_slice(&999u64.to_le_bytes());
    let msg = parse_err(&bad);
    assert!(msg.contains(&format!("byte offset {at}:")) && msg.contains("node 999"), "{msg}");
    // A bad endianness check.
    let mut bad = good.clone();
    let at = find(&bad, b"4.1 1 8\n") + 8;
    bad[at] = 2;
    assert!(parse_err(&bad).contains("endianness"));
    // Unsupported data size.
    let bad = String::from_utf8_lossy(&good).replacen("4.1 1 8", "4.1 1 2", 1);
    assert!(parse_err(bad.as_bytes()).contains("data size"));
    // Huge counts: node blocks, nodes in a block, elements in a block; 2.2 element headers.
    for (section, offset, value) in [
        (&b"$Nodes\n"[..], 0, u64::MAX),
        (b"$Nodes\n", 4 * 8 + 12, u64::MAX / 2),
        (b"$Elements\n", 0, u64::MAX),
        (b"$Elements\n", 4 * 8 + 12, 1 << 60),
        (b"$Entities\n", 0, u64::MAX),
    ] {
        let mut bad = good.clone();
        let at = find(&bad, section) + section.len() + offset;
        bad[at..at + 8].copy_from_slice(&value.to_le_bytes());
        let msg = parse_err(&bad);
        assert!(msg.contains("byte offset"), "{msg}");
    }
    let good22 = write22(&two_cubes(), LE8);
    let at = find(&good22, b"$Elements\n") + 10;
    let at = at + good22[at..].iter().position(|&b| b == b'\n').expect("count line") + 1 + 4;
    for count in [i32::MAX, -1, 0] {
        let mut bad = good22.clone();
        bad[at..at + 4].copy_from_slice(&count.to_le_bytes());
        assert!(parse_err(&bad).contains("byte offset"));
    }
}

fn find(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len()).position(|w| w == needle).expect("needle present")
}

fn rfind(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len()).rposition(|w| w == needle).expect("needle present")
}

// ---------------------------------------------------------------------------------------------
// Robustness: truncations, byte flips, garbage — errors, never panics
// ---------------------------------------------------------------------------------------------

/// xorshift64*, a fixed-seed generator for reproducible fuzzing without extra crates.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Parses `bytes` and, when that succeeds, maps it in 2D and 3D; the results do not matter,
/// only that nothing panics.
fn exercise(bytes: &[u8]) -> bool {
    match parse_msh(bytes) {
        Ok(msh) => {
            let _ = msh.bodies::<2>();
            let _ = msh.bodies::<3>();
            let _ = msh.physical_groups();
            true
        }
        Err(_) => false,
    }
}

fn corpus() -> Vec<(&'static str, Vec<u8>)> {
    let cubes = two_cubes();
    vec![
        ("ascii 4.1 fixture", fixture("two_squares_41.msh")),
        ("ascii 2.2 fixture", fixture("two_squares_22.msh")),
        ("binary 4.1 written by gmsh", fixture("two_squares_gmsh41_bin.msh")),
        ("binary 2.2 written by gmsh", fixture("two_boxes_gmsh22_bin.msh")),
        ("binary 4.1", write41(&cubes, LE8)),
        (
            "binary 4.1 big-endian, 4-byte size_t",
            write41(&cubes, Enc::Binary { big_endian: true, size_t: 4 }),
        ),
        ("binary 2.2", write22(&cubes, LE8)),
    ]
}

#[test]
fn every_truncation_is_an_error() {
    for (name, bytes) in corpus() {
        assert!(exercise(&bytes), "{name} parses");
        let end = rfind(&bytes, b"$EndElements") + b"$EndElements".len();
        for cut in 0..bytes.len() {
            let ok = exercise(&bytes[..cut]);
            assert!(cut >= end || !ok, "{name} truncated to {cut} bytes parses");
        }
    }
}

/// Iterations of the random tests: `SYNOVIA_FUZZ_ITERATIONS`, or `default`.
fn iterations(default: usize) -> usize {
    std::env::var("SYNOVIA_FUZZ_ITERATIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

#[test]
fn random_byte_flips_never_panic() {
    let mut rng = Rng(0x5eed_0f5a_0b1a_4242);
    let n = iterations(3000);
    for (_, bytes) in corpus() {
        for _ in 0..n {
            let mut b = bytes.clone();
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(b.len());
                b[i] = match rng.below(4) {
                    0 => b[i] ^ (1 << rng.below(8)),
                    1 => rng.next() as u8,
                    2 => b"0123456789 \n-.e$"[rng.below(16)],
                    _ => 0xff,
                };
            }
            exercise(&b);
            // Also a random cut of the corrupted file.
            let cut = rng.below(b.len());
            exercise(&b[..cut]);
        }
    }
}

#[test]
fn garbage_never_panics() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let headers: [&[u8]; 5] = [
        b"",
        b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n",
        b"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n",
        b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n",
        b"$MeshFormat\n2.2 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n",
    ];
    let sections: [&[u8]; 5] = [b"$Nodes\n", b"$Elements\n", b"$Entities\n", b"$PhysicalNames\n", b"$Foo\n"];
    for _ in 0..iterations(4000) {
        let mut b = headers[rng.below(headers.len())].to_vec();
        for _ in 0..rng.below(3) {
            b.extend_from_slice(sections[rng.below(sections.len())]);
            let n = rng.below(200);
            for _ in 0..n {
                b.push(if rng.below(2) == 0 { rng.next() as u8 } else { b"0123456789 \n-.e"[rng.below(15)] });
            }
        }
        // No `$End…` line can come out of the garbage, so nothing parses.
        assert!(!exercise(&b), "garbage parsed: {:?}", String::from_utf8_lossy(&b));
    }
}
