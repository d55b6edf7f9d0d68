//! A mesh made by the `gmsh` command-line tool is read and solved: `tests/data/disc_on_block.geo`
//! (a half-disc on a block, two bodies with named physical groups) is meshed with
//! `gmsh -2 … -format msh41` into a temporary directory, read with `synovia_io::gmsh`, and the
//! frictionless node-to-segment contact of the disc pushed down on the block is solved with
//! PDAS. Checked: the KKT conditions, and that the contact resultant equals the vertical
//! reactions at the driven top of the disc and at the clamped base of the block, both computed
//! independently from the displacements (P1 element forces `A σ·∇N_a` summed over the part's
//! nodes). Without `gmsh` on PATH the test prints a note and passes.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

use synovia::contact::StaticContact;
use synovia::contact_ops::operators::ContactPair;
use synovia::fem::{ElasticParams, Model};
use synovia::material::plane_strain;
use synovia::mesh::math::{Real, Vector};
use synovia::mesh::Mesh;

const E: Real = 1000.0;
const NU: Real = 0.3;
const DELTA: Real = 0.03;

fn gmsh_available() -> bool {
    Command::new("gmsh").arg("--version").output().map(|o| o.status.success()).unwrap_or(false)
}

fn mesh_with_gmsh(geo: &Path) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("synovia_gmsh_solve_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let msh = dir.join("disc_on_block.msh");
    let out = Command::new("gmsh")
        .arg("-2")
        .arg(geo)
        .arg("-o")
        .arg(&msh)
        .args(["-format", "msh41", "-v", "2"])
        .output()
        .expect("run gmsh");
    assert!(out.status.success(), "gmsh failed: {}", String::from_utf8_lossy(&out.stderr));
    msh
}

/// Vertical resultant of the P1 element forces `f_a = A_e σ_e ∇N_a` (i.e. `K u`) over the nodes
/// of `part` (plane strain, isotropic): the force of the support on the body there.
fn part_reaction_y(mesh: &Mesh<2>, u: &[Vector<2>], part: &str) -> Real {
    let lambda = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
    let mu = E / (2.0 * (1.0 + NU));
    let on_part: std::collections::HashSet<usize> =
        mesh.boundary_part(part).expect("part").nodes().into_iter().collect();
    let mut fy = 0.0;
    for cell in mesh.cells() {
        if !cell.iter().any(|n| on_part.contains(n)) {
            continue;
        }
        let x: Vec<_> = cell.iter().map(|&n| *mesh.node(n)).collect();
        let a2 = (x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]);
        let grads = [
            [(x[1][1] - x[2][1]) / a2, (x[2][0] - x[1][0]) / a2],
            [(x[2][1] - x[0][1]) / a2, (x[0][0] - x[2][0]) / a2],
            [(x[0][1] - x[1][1]) / a2, (x[1][0] - x[0][0]) / a2],
        ];
        let mut du = [[0.0; 2]; 2]; // du[i][j] = ∂u_i/∂x_j
        for (k, &n) in cell.iter().enumerate() {
            for i in 0..2 {
                for j in 0..2 {
                    du[i][j] += u[n][i] * grads[k][j];
                }
            }
        }
        let (exx, eyy, exy) = (du[0][0], du[1][1], 0.5 * (du[0][1] + du[1][0]));
        let tr = exx + eyy;
        let (sxy, syy) = (2.0 * mu * exy, lambda * tr + 2.0 * mu * eyy);
        let area = 0.5 * a2.abs();
        for (k, &n) in cell.iter().enumerate() {
            if on_part.contains(&n) {
                fy += area * (sxy * grads[k][0] + syy * grads[k][1]);
            }
        }
    }
    fy
}

#[test]
fn gmsh_cli_mesh_is_read_and_solved_with_balanced_contact_force() {
    if !gmsh_available() {
        println!("note: `gmsh` is not on PATH; skipping the gmsh CLI mesh-and-solve test");
        return;
    }
    let geo = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/disc_on_block.geo");
    let msh = mesh_with_gmsh(&geo);
    let gm = synovia::io::gmsh::read_msh(&msh).expect("read the gmsh output");
    let bodies = gm.bodies::<2>().expect("bodies");
    let _ = std::fs::remove_dir_all(msh.parent().expect("dir"));
    let mesh_of = |name: &str| bodies.iter().find(|(n, _)| n == name).map(|(_, m)| m.clone()).expect(name);
    let (lower, upper) = (mesh_of("lower"), mesh_of("upper"));
    assert!(
        lower.n_cells() > 100 && upper.n_cells() > 100,
        "{} / {} cells",
        lower.n_cells(),
        upper.n_cells()
    );

    let mat = Arc::new(plane_strain(E, NU).expect("material"));
    let mut model = Model::<2>::new();
    let lo = model.add_body("lower", lower.clone(), mat.clone()).expect("lower");
    let up = model.add_body("upper", upper.clone(), mat).expect("upper");
    model.prescribe(up, "prescribed_top", |_, t| Vector::<2>::new(0.0, -DELTA * t)).expect("prescribe");
    let pair = ContactPair::node_to_segment("disc-block", lo, "contact_lower", up, "contact_upper")
        .with_search_distance(0.2);
    let contact = StaticContact::new(&model, &[pair], ElasticParams::default()).expect("contact problem");
    let solver = synovia::solvers::by_name("pdas").expect("pdas");
    let res = contact.solve(&model, 1.0, solver.as_ref(), None, None, None).expect("solve");
    assert!(res.kkt.satisfied(1e-8), "KKT {:?}", res.kkt);

    let geo_c = contact.geometry();
    let active = res.solution.lambda_n.iter().filter(|&&l| l > 0.0).count();
    assert!(active >= 3, "only {active} active contact nodes");
    let resultant = geo_c
        .nodes
        .iter()
        .zip(&res.solution.lambda_n)
        .fold(Vector::<2>::zeros(), |acc, (n, &l)| acc + n.normal * (n.weight * l));
    let top = part_reaction_y(&upper, &res.displacement[up.0], "prescribed_top");
    let base = part_reaction_y(&lower, &res.displacement[lo.0], "clamped_base");
    println!("contact resultant {resultant:?}, top element force {top}, base element force {base}, {active} active");
    let f = resultant[1].abs();
    assert!(f > 1.0, "contact force {f}");
    // `K u` on a supported part is the force of the support on the body: the driven top pushes
    // the disc down (< 0), the clamped base pushes the block up (> 0)
    assert!(top < 0.0 && base > 0.0, "reaction signs: top {top}, base {base}");
    assert!((top.abs() - f).abs() <= 1e-6 * f, "top reaction {top} vs contact {f}");
    assert!((base - f).abs() <= 1e-6 * f, "base reaction {base} vs contact {f}");
    // the unstructured mesh is not exactly symmetric: a small horizontal resultant remains
    assert!(resultant[0].abs() <= 2e-2 * f, "horizontal resultant {}", resultant[0]);
}
