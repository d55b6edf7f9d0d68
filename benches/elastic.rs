//! Criterion benchmark of the stages of the elastic foundation (see `docs/performance.md`):
//! pattern + assembly, symbolic analysis (ordering included), numeric Cholesky factorisation and
//! the triangular solves, for
//!
//! - `2d`: unit square, plane strain, `316 × 316` cells of two triangles, clamped bottom, traction
//!   on top (≈ 200k reduced DOFs, AMD);
//! - `3d`: unit cube, isotropic, `40 × 40 × 40` cells of six tetrahedra, clamped bottom, traction
//!   on top (≈ 202k reduced DOFs, METIS);
//! - `3d-small`: the cube with `24³` cells (≈ 45k DOFs), to compare AMD with METIS in the
//!   symbolic and numeric stages (AMD at full 3D size takes much longer and more memory).
//!
//! `SYNOVIA_BENCH_SCALE=0.25 cargo bench --bench elastic` scales every DOF count by 0.25 for a
//! quick run. Every benchmark takes 10 samples (criterion's minimum, flat sampling); the 3D
//! factorisation takes 12–16 s per iteration, so a full run took about 5 minutes on the idle
//! 2-core machine (9 with other builds running). Fixtures are built only for the
//! benchmarks selected by a filter, e.g. `cargo bench --bench elastic -- 2d`.
// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::cell::OnceCell;
use std::sync::Arc;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use synovia::fem::assembly::{add_loads, assemble_matrix, assemble_matrix_with, body_stiffnesses, pattern};
use synovia::fem::element::{stiffness_into, SimplexGeometry};
use synovia::fem::{CholeskySolver, DofMap, Ordering, SymmetricMatrix};
use synovia::prelude::*;

/// DOF scale factor from `SYNOVIA_BENCH_SCALE` (default 1).
fn scale() -> f64 {
    std::env::var("SYNOVIA_BENCH_SCALE")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or(1.0)
}

/// Cells per side for `base` cells per side at scale 1, DOFs scaled by `scale()`.
fn cells(base: usize, dim: i32) -> usize {
    ((base as f64) * scale().powf(1.0 / f64::from(dim))).round().max(2.0) as usize
}

fn model_2d(n: usize) -> Model<2> {
    let mut mesh =
        rectangle(0.0, 1.0, 0.0, 1.0, n, n, Grading::Uniform, Grading::Uniform).expect("rectangle");
    mesh.set_part_kind("bottom", BoundaryKind::Clamped).expect("bottom");
    mesh.set_part_kind("top", BoundaryKind::Traction).expect("top");
    let mut model = Model::<2>::new();
    let material = plane_strain(1.0, 0.3).expect("material");
    let b = model.add_body("block", mesh, Arc::new(material)).expect("body");
    model.traction(b, "top", |x, _n, _t| Vector::<2>::new(0.01 * x[0], -0.02)).expect("traction");
    model
}

fn model_3d(n: usize) -> Model<3> {
    let mut mesh = box_mesh([0.0; 3], [1.0; 3], [n; 3], [Grading::Uniform; 3]).expect("box mesh");
    mesh.set_part_kind("bottom", BoundaryKind::Clamped).expect("bottom");
    mesh.set_part_kind("top", BoundaryKind::Traction).expect("top");
    let mut model = Model::<3>::new();
    let material = isotropic(1.0, 0.3).expect("material");
    let b = model.add_body("block", mesh, Arc::new(material)).expect("body");
    model
        .traction(b, "top", |x, _n, _t| Vector::<3>::new(0.01 * x[0], 0.005 * x[1], -0.02))
        .expect("traction");
    model
}

/// Dof map, pattern (with its METIS input) and assembled stiffness.
fn setup<const D: usize>(model: &Model<D>) -> (DofMap<D>, SymmetricMatrix, Ordering) {
    let dofs = DofMap::new(model).expect("dof map");
    dofs.check_coercive(model).expect("coercive");
    let (k, metis) = pattern(model, &dofs).expect("pattern");
    (dofs, k, metis)
}

fn assemble<const D: usize>(model: &Model<D>, dofs: &DofMap<D>, k: &mut SymmetricMatrix) {
    let c = body_stiffnesses(model).expect("stiffnesses");
    assemble_matrix(model, dofs, k, |b, _, geo, out| stiffness_into(geo, &c[b], out)).expect("assembly");
}

/// The sequential assembly as it was before the parallel column blocks (entry by entry
/// through `SymmetricMatrix::add`, one binary search per entry), kept as the baseline of
/// `assembly/*/assemble-before`.
fn assemble_before<const D: usize>(model: &Model<D>, dofs: &DofMap<D>, matrix: &mut SymmetricMatrix) {
    let body_c = body_stiffnesses(model).expect("stiffnesses");
    matrix.zero();
    let n = D * (D + 1);
    let mut ke = vec![0.0; n * n];
    let groups = dofs.groups();
    for (bi, body) in model.bodies().iter().enumerate() {
        for c in 0..body.mesh.n_cells() {
            let pts = body.mesh.cell_points(c);
            let geo = SimplexGeometry::new(&pts).expect("geometry");
            stiffness_into(&geo, &body_c[bi], &mut ke);
            let cell = body.mesh.cell(c);
            for (a, &na) in cell.iter().enumerate() {
                let ga = &groups[dofs.group_of(BodyId(bi), na)];
                for (b, &nb) in cell.iter().enumerate() {
                    let gb = &groups[dofs.group_of(BodyId(bi), nb)];
                    for k in 0..ga.n_dofs {
                        let r = ga.first_dof + k;
                        for l in 0..gb.n_dofs {
                            let col = gb.first_dof + l;
                            if r < col {
                                continue;
                            }
                            let v = if ga.free && gb.free {
                                ke[(D * a + k) * n + D * b + l]
                            } else {
                                let mut v = 0.0;
                                for i in 0..D {
                                    for j in 0..D {
                                        v +=
                                            ga.basis[k][i] * ke[(D * a + i) * n + D * b + j] * gb.basis[l][j];
                                    }
                                }
                                v
                            };
                            matrix.add(r, col, v).expect("in pattern");
                        }
                    }
                }
            }
        }
    }
}

/// A problem with its dof map and (empty) stiffness pattern, for the assembly benchmarks.
struct AssemblyFixture<const D: usize> {
    model: Model<D>,
    dofs: DofMap<D>,
    k: SymmetricMatrix,
}

impl<const D: usize> AssemblyFixture<D> {
    fn new(model: Model<D>) -> Self {
        let (dofs, k, _) = setup(&model);
        Self { model, dofs, k }
    }
}

/// A problem with everything up to the factorisation done, and its right-hand side.
struct Fixture<const D: usize> {
    k: SymmetricMatrix,
    ordering: Ordering,
    solver: CholeskySolver,
    rhs: Vec<f64>,
}

impl<const D: usize> Fixture<D> {
    fn new(model: Model<D>, ordering: fn(Ordering) -> Ordering) -> Self {
        let (dofs, mut k, metis) = setup(&model);
        assemble(&model, &dofs, &mut k);
        let ordering = ordering(metis);
        let mut solver = CholeskySolver::analyse(&k, &ordering).expect("analyse");
        solver.factorize(&k).expect("factorize");
        let mut rhs = vec![0.0; dofs.n_dofs()];
        add_loads(&model, &dofs, 0.0, 2, &mut rhs).expect("loads");
        eprintln!(
            "fixture {D}D: {} dofs, {} matrix nnz, {} factor nnz",
            dofs.n_dofs(),
            k.nnz(),
            solver.info().factor_nnz
        );
        Self { k, ordering, solver, rhs }
    }
}

fn amd(_: Ordering) -> Ordering {
    Ordering::Amd
}

fn metis(o: Ordering) -> Ordering {
    o
}

fn elastic(c: &mut Criterion) {
    let n2 = cells(316, 2);
    let n3 = cells(40, 3);
    let n3s = cells(24, 3);
    let f2: OnceCell<Fixture<2>> = OnceCell::new();
    let f3: OnceCell<Fixture<3>> = OnceCell::new();
    let f3s_amd: OnceCell<Fixture<3>> = OnceCell::new();
    let f3s_metis: OnceCell<Fixture<3>> = OnceCell::new();
    let fx2 = || f2.get_or_init(|| Fixture::new(model_2d(n2), amd));
    let fx3 = || f3.get_or_init(|| Fixture::new(model_3d(n3), metis));
    let fx3s_amd = || f3s_amd.get_or_init(|| Fixture::new(model_3d(n3s), amd));
    let fx3s_metis = || f3s_metis.get_or_init(|| Fixture::new(model_3d(n3s), metis));

    // ## Pattern (dof map + coercivity check + pattern) and stiffness assembly (fixtures
    // without factorisation, so that `-- assembly` runs quickly)
    let a2: OnceCell<AssemblyFixture<2>> = OnceCell::new();
    let a3: OnceCell<AssemblyFixture<3>> = OnceCell::new();
    let ax2 = || a2.get_or_init(|| AssemblyFixture::new(model_2d(n2)));
    let ax3 = || a3.get_or_init(|| AssemblyFixture::new(model_3d(n3)));
    let mut g = c.benchmark_group("assembly");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    g.bench_function("2d/pattern", |b| {
        let f = ax2();
        b.iter(|| setup(&f.model))
    });
    g.bench_function("2d/assemble", |b| {
        let f = ax2();
        let mut k = f.k.clone();
        b.iter(|| assemble(&f.model, &f.dofs, &mut k))
    });
    for blocks in [2, 4, 8] {
        g.bench_function(format!("2d/assemble-blocks{blocks}"), |b| {
            let f = ax2();
            let mut k = f.k.clone();
            let c = body_stiffnesses(&f.model).expect("stiffnesses");
            b.iter(|| {
                assemble_matrix_with(&f.model, &f.dofs, &mut k, blocks, |b, _, geo, out| {
                    stiffness_into(geo, &c[b], out)
                })
                .expect("assembly")
            })
        });
    }
    g.bench_function("2d/assemble-before", |b| {
        let f = ax2();
        let mut k = f.k.clone();
        b.iter(|| assemble_before(&f.model, &f.dofs, &mut k))
    });
    g.bench_function("2d/loads", |b| {
        let f = ax2();
        let mut rhs = vec![0.0; f.dofs.n_dofs()];
        b.iter(|| add_loads(&f.model, &f.dofs, 0.0, 2, &mut rhs).expect("loads"))
    });
    g.bench_function("3d/pattern", |b| {
        let f = ax3();
        b.iter(|| setup(&f.model))
    });
    g.bench_function("3d/assemble", |b| {
        let f = ax3();
        let mut k = f.k.clone();
        b.iter(|| assemble(&f.model, &f.dofs, &mut k))
    });
    for blocks in [2, 4, 8] {
        g.bench_function(format!("3d/assemble-blocks{blocks}"), |b| {
            let f = ax3();
            let mut k = f.k.clone();
            let c = body_stiffnesses(&f.model).expect("stiffnesses");
            b.iter(|| {
                assemble_matrix_with(&f.model, &f.dofs, &mut k, blocks, |b, _, geo, out| {
                    stiffness_into(geo, &c[b], out)
                })
                .expect("assembly")
            })
        });
    }
    g.bench_function("3d/assemble-before", |b| {
        let f = ax3();
        let mut k = f.k.clone();
        b.iter(|| assemble_before(&f.model, &f.dofs, &mut k))
    });
    g.bench_function("3d/loads", |b| {
        let f = ax3();
        let mut rhs = vec![0.0; f.dofs.n_dofs()];
        b.iter(|| add_loads(&f.model, &f.dofs, 0.0, 2, &mut rhs).expect("loads"))
    });
    g.finish();

    // ## Ordering + symbolic analysis
    let mut g = c.benchmark_group("symbolic");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    g.bench_function("2d/amd", |b| {
        let f = fx2();
        b.iter(|| CholeskySolver::analyse(&f.k, &f.ordering).expect("analyse"))
    });
    g.bench_function("3d/metis", |b| {
        let f = fx3();
        b.iter(|| CholeskySolver::analyse(&f.k, &f.ordering).expect("analyse"))
    });
    g.bench_function("3d-small/amd", |b| {
        let f = fx3s_amd();
        b.iter(|| CholeskySolver::analyse(&f.k, &f.ordering).expect("analyse"))
    });
    g.bench_function("3d-small/metis", |b| {
        let f = fx3s_metis();
        b.iter(|| CholeskySolver::analyse(&f.k, &f.ordering).expect("analyse"))
    });
    g.finish();

    // ## Numeric factorisation (symbolic analysis reused; a fresh solver, so that the fixture's
    // factor stays valid for the solve group)
    let mut g = c.benchmark_group("numeric");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(5));
    g.bench_function("2d/amd", |b| {
        let f = fx2();
        let mut s = CholeskySolver::analyse(&f.k, &f.ordering).expect("analyse");
        b.iter(|| s.factorize(&f.k).expect("factorize"))
    });
    g.bench_function("3d/metis", |b| {
        let f = fx3();
        let mut s = CholeskySolver::analyse(&f.k, &f.ordering).expect("analyse");
        b.iter(|| s.factorize(&f.k).expect("factorize"))
    });
    g.bench_function("3d-small/amd", |b| {
        let f = fx3s_amd();
        let mut s = CholeskySolver::analyse(&f.k, &f.ordering).expect("analyse");
        b.iter(|| s.factorize(&f.k).expect("factorize"))
    });
    g.bench_function("3d-small/metis", |b| {
        let f = fx3s_metis();
        let mut s = CholeskySolver::analyse(&f.k, &f.ordering).expect("analyse");
        b.iter(|| s.factorize(&f.k).expect("factorize"))
    });
    g.finish();

    // ## Triangular solves, one right-hand side
    let mut g = c.benchmark_group("solve");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    g.bench_function("2d/amd", |b| {
        let f = fx2();
        let mut x = f.rhs.clone();
        b.iter(|| {
            x.copy_from_slice(&f.rhs);
            f.solver.solve_in_place(&mut x).expect("solve")
        })
    });
    g.bench_function("3d/metis", |b| {
        let f = fx3();
        let mut x = f.rhs.clone();
        b.iter(|| {
            x.copy_from_slice(&f.rhs);
            f.solver.solve_in_place(&mut x).expect("solve")
        })
    });
    g.finish();
}

criterion_group!(benches, elastic);
criterion_main!(benches);
