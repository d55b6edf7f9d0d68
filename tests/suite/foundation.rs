//! Foundation behaviour: time-dependent Dirichlet data, factorisation reuse, fixed-pattern
//! re-assembly, mass matrices, strain energy, sprs conversion, VTU output read back.

use std::sync::Arc;

use synovia::fem::assembly::{assemble_matrix, pattern};
use synovia::fem::element::{mass_into, stiffness_into};
use synovia::fem::{DofMap, ElasticParams, ElasticSolver, SymmetricMatrix};
use synovia::prelude::*;

fn cantilever() -> Model<2> {
    let mut mesh = rectangle(0.0, 4.0, 0.0, 1.0, 16, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
    mesh.set_part_kind("left", BoundaryKind::Clamped).expect("part");
    mesh.set_part_kind("right", BoundaryKind::Prescribed).expect("part");
    let mut model = Model::<2>::new();
    let b = model.add_body("beam", mesh, Arc::new(plane_strain(100.0, 0.3).expect("ok"))).expect("body");
    // the tip is pushed down linearly in time
    model.prescribe(b, "right", |_, t| Vector::<2>::new(0.0, -0.01 * t)).expect("prescribe");
    model
}

#[test]
fn time_dependent_dirichlet_data_scales_the_solution_with_one_factorisation() {
    let model = cantilever();
    let mut solver = ElasticSolver::new(&model, ElasticParams::default()).expect("factorise");
    let u1 = solver.solve(&model, 1.0).expect("t = 1");
    let u3 = solver.solve(&model, 3.0).expect("t = 3");
    let u0 = solver.solve(&model, 0.0).expect("t = 0");
    let mut max1: f64 = 0.0;
    for (a, b) in u1.displacement[0].iter().zip(&u3.displacement[0]) {
        assert!((b - 3.0 * a).norm() < 1e-13, "linearity in t");
        max1 = max1.max(a.norm());
    }
    assert!(max1 > 0.009, "the prescribed tip displacement is reached");
    assert!(u0.displacement[0].iter().all(|u| u.norm() == 0.0));
    // tip nodes have exactly the prescribed value
    let mesh = &model.bodies()[0].mesh;
    for n in mesh.boundary_part("right").expect("part").nodes() {
        assert!((u3.displacement[0][n] - Vector::<2>::new(0.0, -0.03)).norm() < 1e-15);
    }
}

#[test]
fn strain_energy_equals_half_the_work_of_the_loads() {
    let mut mesh = box_mesh([0.0; 3], [2.0, 1.0, 1.0], [6, 3, 3], [Grading::Uniform; 3]).expect("mesh");
    mesh.set_part_kind("left", BoundaryKind::Clamped).expect("part");
    mesh.set_part_kind("right", BoundaryKind::Traction).expect("part");
    let mut model = Model::<3>::new();
    let b = model.add_body("block", mesh, Arc::new(isotropic(50.0, 0.25).expect("ok"))).expect("body");
    model.traction(b, "right", |x, _, _| Vector::<3>::new(0.1 * x[1], 0.0, -0.2)).expect("traction");
    model.body_force(b, |_, _| Vector::<3>::new(0.0, 0.05, 0.0)).expect("force");
    let mut solver = ElasticSolver::new(&model, ElasticParams::default()).expect("factorise");
    let sol = solver.solve(&model, 0.0).expect("solve");
    let fields = solver.fields(&model, &sol).expect("fields");
    let (rhs, _) = solver.rhs(&model, 0.0).expect("rhs");
    let work: f64 = rhs.iter().zip(&sol.reduced).map(|(f, u)| f * u).sum();
    let energy = fields[0].strain_energy;
    assert!(energy > 0.0);
    assert!((energy - 0.5 * work).abs() < 1e-10 * energy, "energy {energy} vs work/2 {}", 0.5 * work);
    // and ½ uᵀ K u
    let quad = 0.5 * solver.stiffness().quadratic_form(&sol.reduced);
    assert!((quad - energy).abs() < 1e-10 * energy);
    // the energy alone (what the step records compute) is the same
    let total = synovia::fem::post::total_strain_energy(&model, &sol.displacement).expect("energy");
    assert!((total - energy).abs() < 1e-12 * energy, "{total} vs {energy}");
    assert!(synovia::fem::post::total_strain_energy(&model, &[]).is_err());
    // von Mises and principal stresses are consistent: σ_vm² = ½ Σ (σ_i − σ_j)²
    for (vm, p) in fields[0].cell_von_mises.iter().zip(&fields[0].cell_principal) {
        let v2 = 0.5 * ((p[0] - p[1]).powi(2) + (p[1] - p[2]).powi(2) + (p[2] - p[0]).powi(2));
        assert!((vm * vm - v2).abs() < 1e-9 * (1.0 + v2));
        assert!(p[0] >= p[1] && p[1] >= p[2]);
    }
}

#[test]
fn reassembly_reuses_the_pattern_without_reallocation() {
    let model = cantilever();
    let dofs = DofMap::new(&model).expect("dofs");
    let (mut k, _) = pattern(&model, &dofs).expect("pattern");
    let c = plane_strain(100.0, 0.3).expect("ok").stiffness().clone();
    assemble_matrix(&model, &dofs, &mut k, |_, _, geo, out| stiffness_into(geo, &c, out)).expect("assemble");
    let ptr = k.values().as_ptr();
    let first: Vec<f64> = k.values().to_vec();
    let c2 = &c * 2.0;
    assemble_matrix(&model, &dofs, &mut k, |_, _, geo, out| stiffness_into(geo, &c2, out)).expect("assemble");
    assert_eq!(ptr, k.values().as_ptr(), "values were reallocated");
    for (a, b) in first.iter().zip(k.values()) {
        assert!((2.0 * a - b).abs() <= 1e-12 * a.abs().max(1.0));
    }
}

#[test]
fn mass_matrices_integrate_the_density() {
    // free body (no constraints): 1ᵀ M 1 per component = ρ |Ω|
    let mesh = rectangle(0.0, 3.0, 0.0, 2.0, 6, 5, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut model = Model::<2>::new();
    model.add_body("b", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    let dofs = DofMap::new(&model).expect("dofs");
    let (mut m, _) = pattern(&model, &dofs).expect("pattern");
    let rho = 1.7;
    for lumped in [false, true] {
        assemble_matrix(&model, &dofs, &mut m, |_, _, geo, out| mass_into(geo, rho, lumped, out))
            .expect("mass");
        let ones_x: Vec<f64> = (0..dofs.n_dofs()).map(|i| if i % 2 == 0 { 1.0 } else { 0.0 }).collect();
        let total = m.quadratic_form(&ones_x);
        assert!((total - rho * 6.0).abs() < 1e-12, "lumped = {lumped}: {total}");
        // the second moment ∫ ρ x² is exact for the consistent mass only
        let xs: Vec<f64> = (0..dofs.n_dofs())
            .map(|i| if i % 2 == 0 { model.bodies()[0].mesh.node(i / 2)[0] } else { 0.0 })
            .collect();
        let second = m.quadratic_form(&xs);
        let exact = rho * 2.0 * 27.0 / 3.0;
        if lumped {
            assert!(second > exact);
        } else {
            assert!((second - exact).abs() < 1e-10 * exact);
        }
    }
}

#[test]
fn sprs_round_trip_preserves_the_matrix() {
    let model = cantilever();
    let solver = ElasticSolver::new(&model, ElasticParams::default()).expect("factorise");
    let k = solver.stiffness();
    let s = k.to_sprs();
    assert_eq!(s.rows(), k.n());
    assert_eq!(s.nnz(), 2 * k.nnz() - k.n());
    let back = SymmetricMatrix::from_sprs(&s).expect("square");
    assert_eq!(back.values(), k.values());
    let x: Vec<f64> = (0..k.n()).map(|i| (i as f64).sin()).collect();
    let mut y1 = vec![0.0; k.n()];
    k.mul_vec(&x, &mut y1);
    let y2 = &s * &sprs::CsVec::new(k.n(), (0..k.n()).collect(), x.clone());
    for (i, v) in y2.iter() {
        assert!((y1[i] - v).abs() < 1e-10 * (1.0 + v.abs()));
    }
}

#[test]
fn metis_and_amd_orderings_give_the_same_solution() {
    let mut mesh = box_mesh([0.0; 3], [1.0; 3], [4, 4, 4], [Grading::Uniform; 3]).expect("mesh");
    mesh.set_part_kind("bottom", BoundaryKind::Clamped).expect("part");
    mesh.set_part_kind("top", BoundaryKind::Traction).expect("part");
    let mut model = Model::<3>::new();
    let b = model.add_body("cube", mesh, Arc::new(isotropic(10.0, 0.3).expect("ok"))).expect("body");
    model.traction(b, "top", |x, _, _| Vector::<3>::new(x[1], 0.0, -1.0)).expect("traction");
    let mut sols = Vec::new();
    for ordering in [synovia::fem::OrderingChoice::Amd, synovia::fem::OrderingChoice::Metis] {
        let mut s =
            ElasticSolver::new(&model, ElasticParams::default().with_ordering(ordering)).expect("factorise");
        sols.push(s.solve(&model, 0.0).expect("solve").reduced);
    }
    let scale = sols[0].iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    for (a, b) in sols[0].iter().zip(&sols[1]) {
        assert!((a - b).abs() < 1e-10 * scale);
    }
}

#[test]
fn vtu_output_of_a_solution_reads_back() {
    let model = cantilever();
    let mut solver = ElasticSolver::new(&model, ElasticParams::default()).expect("factorise");
    let sol = solver.solve(&model, 1.0).expect("solve");
    let fields = solver.fields(&model, &sol).expect("fields");
    let dir = std::env::temp_dir().join(format!("synovia-foundation-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("beam.vtu");
    synovia::output::elastic_vtu(&model, &sol, &fields, synovia::io::Encoding::Zlib)
        .expect("writer")
        .write(&path)
        .expect("write");
    let data = synovia::io::read_vtu(&path).expect("read");
    let piece = &data.pieces[0];
    assert_eq!(piece.n_points(), model.bodies()[0].mesh.n_nodes());
    let disp = piece.point_field("displacement").expect("displacement field");
    for (i, u) in sol.displacement[0].iter().enumerate() {
        let t = disp.tuple(i).expect("tuple");
        assert_eq!([t[0], t[1], t[2]], [u[0], u[1], 0.0]);
    }
    let vm = piece.cell_field("von_mises").expect("von Mises field");
    assert_eq!(vm.values, fields[0].cell_von_mises);
    std::fs::remove_dir_all(&dir).ok();
}

/// The trailing block of a factorisation with the interface dofs ordered last
/// (`ElasticSolver::new_with_ordering` with `interface_ordering`) reproduces `(A⁻¹)_cc` computed with the whole factor, for
/// the simplicial (small) and the supernodal (larger) factor layouts of faer.
#[test]
fn trailing_block_of_the_factor_gives_the_interface_inverse() {
    use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
    let mut layouts = Vec::new();
    for n in [6, 60] {
        let mut mesh =
            rectangle(0.0, 2.0, 0.0, 1.0, 2 * n, n, Grading::Uniform, Grading::Uniform).expect("mesh");
        mesh.set_part_kind("bottom", BoundaryKind::Clamped).expect("part");
        let top: Vec<usize> = mesh.boundary_part("top").expect("top").facets().flatten().copied().collect();
        let mut model = Model::<2>::new();
        let b = model.add_body("block", mesh, Arc::new(plane_strain(3.0, 0.3).expect("m"))).expect("body");
        let mut nodes: Vec<(BodyId, usize)> = top.iter().map(|&i| (b, i)).collect();
        nodes.sort_unstable();
        nodes.dedup();
        let ordering = synovia::contact::interface_ordering(&nodes, Default::default());
        let solver = ElasticSolver::new_with_ordering(&model, ElasticParams::default(), false, &ordering)
            .expect("factor");
        let chol = solver.cholesky();
        let block = chol.trailing().expect("trailing block");
        layouts.push(matches!(chol.symbolic().raw(), SymbolicCholeskyRaw::Supernodal(_)));
        let k = block.dofs.len();
        assert_eq!(k, 2 * nodes.len());
        let nd = solver.dofs().n_dofs();
        let mut worst: f64 = 0.0;
        for p in [0, k / 3, k - 1] {
            let mut e = vec![0.0; nd];
            e[block.dofs[p]] = 1.0;
            chol.solve_in_place(&mut e).expect("solve");
            let mut x = faer::Mat::<f64>::zeros(k, 1);
            x[(p, 0)] = 1.0;
            block.solve_in_place(x.as_mut()).expect("block solve");
            let scale = e.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            for (q, &d) in block.dofs.iter().enumerate() {
                worst = worst.max((x[(q, 0)] - e[d]).abs() / scale);
            }
        }
        assert!(worst < 1e-12, "n = {n}: (A⁻¹)_cc differs by {worst:e}");
        // a right-hand side on the trailing dofs: forward substitution with L₂₂ only, backward
        // with the whole factor — the same solution as the full solve
        let mut b = vec![0.0; nd];
        for (q, &d) in block.dofs.iter().enumerate() {
            b[d] = (q as f64 * 0.37).sin() + 0.1;
        }
        let mut full = b.clone();
        chol.solve_in_place(&mut full).expect("solve");
        let mut half = b.clone();
        chol.solve_trailing_supported_in_place(&mut half).expect("trailing solve");
        let scale = full.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let diff = full.iter().zip(&half).fold(0.0_f64, |a, (x, y)| a.max((x - y).abs())) / scale;
        assert!(diff < 1e-12, "n = {n}: trailing-supported solve differs by {diff:e}");
        // an entry off the trailing dofs: falls back to the full solve
        let off = (0..nd).find(|i| block.position[*i] == usize::MAX).expect("an interior dof");
        b[off] = 1.0;
        let (mut full, mut half) = (b.clone(), b.clone());
        chol.solve_in_place(&mut full).expect("solve");
        chol.solve_trailing_supported_in_place(&mut half).expect("fallback");
        assert_eq!(full, half);
    }
    assert_eq!(layouts, vec![false, true], "both faer layouts must be exercised");
}

/// A trailing ordering over a base that is not a permutation is an error, not a panic.
#[test]
fn trailing_ordering_over_a_bad_base_permutation_is_an_error() {
    use synovia::fem::{CholeskySolver, Ordering};
    let solver = ElasticSolver::new(&cantilever(), ElasticParams::default()).expect("factor");
    let a = solver.stiffness();
    let n = a.n();
    let mut too_big: Vec<usize> = (0..n).collect();
    too_big[1] = n + 7;
    for base in [vec![0; n], too_big, (0..n - 1).collect()] {
        let ordering = Ordering::Trailing { base: Box::new(Ordering::Custom(base)), last: vec![0, 1] };
        assert!(CholeskySolver::analyse(a, &ordering).is_err());
    }
    let ok = Ordering::Trailing { base: Box::new(Ordering::Custom((0..n).collect())), last: vec![0, 1] };
    assert!(CholeskySolver::analyse(a, &ok).is_ok());
}

/// Recycled solves (`LoadSubspace`): a load in the span of loads solved before is answered
/// without a solve and agrees with a direct solve to rounding; a new load is solved and its
/// direction kept; the oldest direction is dropped when the subspace is full.
#[test]
fn load_subspace_recycles_combinations_of_solved_loads() {
    use synovia::linalg::{CholeskyOperator, LoadSubspace};
    let solver = ElasticSolver::new(&cantilever(), ElasticParams::default()).expect("factor");
    let (a, chol) = (solver.stiffness(), solver.cholesky());
    let op = CholeskyOperator::new(a, chol).expect("operator");
    let n = chol.n();
    let load = |k: f64| -> Vec<f64> { (0..n).map(|i| ((i as f64 + 1.0) * k).sin()).collect() };
    let direct = |f: &[f64]| {
        let mut x = f.to_vec();
        chol.solve_in_place(&mut x).expect("solve");
        x
    };
    let rel = |a: &[f64], b: &[f64]| {
        let s = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / s
    };
    let mut sub = LoadSubspace::new(2);
    let (f1, f2, f3) = (load(0.3), load(1.7), load(2.9));
    for f in [&f1, &f2] {
        assert!(rel(&sub.solve(&op, f).expect("solve"), &direct(f)) < 1e-13);
    }
    assert_eq!((sub.len(), sub.counts()), (2, (0, 2)));
    let combo: Vec<f64> = f1.iter().zip(&f2).map(|(a, b)| 3.0 * a - 2.0 * b).collect();
    let x = sub.solve(&op, &combo).expect("recycled");
    assert_eq!(sub.counts(), (1, 2), "a combination needs no solve");
    let err = rel(&x, &direct(&combo));
    assert!(err < 1e-12, "recycled solution differs by {err:e}");
    // a new direction: solved, kept, and the oldest (f1's) dropped
    assert!(rel(&sub.solve(&op, &f3).expect("solve"), &direct(&f3)) < 1e-13);
    assert_eq!((sub.len(), sub.counts()), (2, (1, 3)));
    let x3 = sub.solve(&op, &f3.iter().map(|v| -0.5 * v).collect::<Vec<_>>()).expect("recycled");
    assert_eq!(sub.counts(), (2, 3), "f3 is in the subspace");
    assert!(rel(&x3, &direct(&f3).iter().map(|v| -0.5 * v).collect::<Vec<_>>()) < 1e-12);
    sub.solve(&op, &f1).expect("solve");
    assert_eq!(sub.counts(), (2, 4), "f1 left the subspace");
    // zero load, wrong length, NaN
    assert!(sub.solve(&op, &vec![0.0; n]).expect("zero").iter().all(|v| *v == 0.0));
    assert!(sub.solve(&op, &vec![1.0; n + 1]).is_err());
    let mut bad = f1.clone();
    bad[3] = f64::NAN;
    assert!(sub.solve(&op, &bad).is_err());
}
