//! MPRGP and MPGP on small dense quadratic programmes with known solutions or checked against
//! their KKT conditions.

use approx::assert_relative_eq;
use nalgebra::{DMatrix, DVector};
use synovia_contact::ContactError;
use synovia_uzawa::{estimate_norm, mpgp, mprgp, ConvexBlock, DenseHessian, Expansion, QpOptions};

const INF: f64 = f64::INFINITY;

/// Deterministic pseudo-random numbers in `[-1, 1)`.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

fn random_spd(n: usize, rng: &mut Lcg) -> DMatrix<f64> {
    let m = DMatrix::from_fn(n, n, |_, _| rng.next());
    m.transpose() * m + DMatrix::identity(n, n) * 0.05
}

fn gradient(h: &DMatrix<f64>, x: &[f64], b: &[f64]) -> Vec<f64> {
    let hx = h * DVector::from_column_slice(x);
    hx.iter().zip(b).map(|(a, b)| a - b).collect()
}

/// KKT of `min ½xᵀHx − bᵀx, l ≤ x ≤ u`: feasibility and sign conditions on `g = Hx − b`.
fn box_kkt(h: &DMatrix<f64>, b: &[f64], l: &[f64], u: &[f64], x: &[f64]) -> f64 {
    let g = gradient(h, x, b);
    let scale = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut worst = 0.0_f64;
    for i in 0..x.len() {
        assert!(x[i] >= l[i] && x[i] <= u[i], "x_{i} = {} outside [{}, {}]", x[i], l[i], u[i]);
        let r = if x[i] <= l[i] && x[i] >= u[i] {
            0.0
        } else if x[i] <= l[i] {
            (-g[i]).max(0.0)
        } else if x[i] >= u[i] {
            g[i].max(0.0)
        } else {
            g[i].abs()
        };
        worst = worst.max(r);
    }
    worst / scale
}

#[test]
fn mprgp_known_solutions() {
    // H = diag(2, 4, 1), b = (2, −4, 3): unconstrained minimiser (1, −1, 3)
    let h = DMatrix::from_diagonal(&DVector::from_vec(vec![2.0, 4.0, 1.0]));
    let b = [2.0, -4.0, 3.0];
    // inactive bounds
    let mut x = vec![0.0; 3];
    let rep = mprgp(&mut DenseHessian(h.clone()), &b, &[-5.0; 3], &[5.0; 3], &mut x, &QpOptions::default())
        .expect("mprgp");
    assert!(rep.converged);
    for (a, e) in x.iter().zip([1.0, -1.0, 3.0]) {
        assert_relative_eq!(*a, e, epsilon = 1e-12);
    }
    // x ≥ 0, x ≤ 2: solution (1, 0, 2)
    let mut x = vec![0.5; 3];
    mprgp(&mut DenseHessian(h.clone()), &b, &[0.0; 3], &[2.0; 3], &mut x, &QpOptions::default())
        .expect("mprgp");
    for (a, e) in x.iter().zip([1.0, 0.0, 2.0]) {
        assert_relative_eq!(*a, e, epsilon = 1e-12);
    }
    // coupled 2×2 with one active lower bound: H = [[2, 1], [1, 2]], b = (−1, 3), x ≥ 0:
    // x_1 = 0 active (g_1 = x_2 + 1 > 0), x_2 = 3/2
    let h2 = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 2.0]);
    let mut x = vec![1.0, 1.0];
    let rep =
        mprgp(&mut DenseHessian(h2), &[-1.0, 3.0], &[0.0, 0.0], &[INF, INF], &mut x, &QpOptions::default())
            .expect("mprgp");
    assert_relative_eq!(x[0], 0.0, epsilon = 1e-14);
    assert_relative_eq!(x[1], 1.5, epsilon = 1e-12);
    assert!(rep.projected_gradient_norm <= 1e-10 * 10f64.sqrt());
}

#[test]
fn mprgp_with_a_closure_hessian() {
    // 1D Laplacian (tridiagonal 2, −1), b = 1, lower bound x ≥ −∞, upper x ≤ 0.05 (obstacle)
    let n = 40;
    let mut lap = |x: &[f64], y: &mut [f64]| {
        for i in 0..x.len() {
            let l = if i > 0 { x[i - 1] } else { 0.0 };
            let r = if i + 1 < x.len() { x[i + 1] } else { 0.0 };
            y[i] = 2.0 * x[i] - l - r;
        }
    };
    let h = DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            2.0
        } else if i.abs_diff(j) == 1 {
            -1.0
        } else {
            0.0
        }
    });
    let b = vec![0.01; n];
    let l = vec![-INF; n];
    let u = vec![2.0; n];
    let mut x = vec![0.0; n];
    let rep = mprgp(&mut lap, &b, &l, &u, &mut x, &QpOptions::default()).expect("mprgp");
    // the unconstrained maximum is 0.01·(n+1)²/8 ≈ 2.1 > 2: the obstacle is active in the middle
    let active = x.iter().filter(|&&v| v >= 2.0).count();
    assert!(active > 0 && active < n, "active {active}");
    assert!(box_kkt(&h, &b, &l, &u, &x) < 1e-9);
    println!("obstacle: {rep:?}");
}

#[test]
fn mprgp_random_spd_against_kkt() {
    let mut rng = Lcg(7);
    for &precondition in &[false, true] {
        for trial in 0..5 {
            let n = 30;
            let h = random_spd(n, &mut rng);
            let b: Vec<f64> = (0..n).map(|_| 3.0 * rng.next()).collect();
            let l: Vec<f64> =
                (0..n).map(|i| if i % 5 == 0 { -INF } else { -0.5 + 0.3 * rng.next() }).collect();
            let u: Vec<f64> = (0..n).map(|i| if i % 7 == 0 { INF } else { 0.5 + 0.3 * rng.next() }).collect();
            let mut x = vec![0.0; n];
            let opts = QpOptions::default().with_tolerance(1e-11).with_precondition(precondition);
            let rep = mprgp(&mut DenseHessian(h.clone()), &b, &l, &u, &mut x, &opts).expect("mprgp");
            let kkt = box_kkt(&h, &b, &l, &u, &x);
            println!(
                "trial {trial} precondition {precondition}: {} iterations ({} cg, {} exp, {} prop), {} products, kkt {kkt:.2e}",
                rep.iterations, rep.cg_steps, rep.expansion_steps, rep.proportioning_steps, rep.hessian_products
            );
            let at_bounds = (0..n).filter(|&i| x[i] <= l[i] || x[i] >= u[i]).count();
            assert!(at_bounds > 0 && at_bounds < n, "both active and free bounds wanted ({at_bounds})");
            assert!(kkt < 1e-9, "trial {trial}: KKT residual {kkt:e}");
        }
    }
}

#[test]
fn mpgp_disc_known_solution() {
    // min ½‖x‖² − bᵀx in the unit disc: x = b/‖b‖ if ‖b‖ > 1, else b
    let mut id = DenseHessian(DMatrix::identity(2, 2));
    let mut x = vec![0.0; 2];
    let blocks = [ConvexBlock::Ball { dim: 2, radius: 1.0 }];
    mpgp(&mut id, &[3.0, 4.0], &blocks, &mut x, &QpOptions::default()).expect("mpgp");
    assert_relative_eq!(x[0], 0.6, epsilon = 1e-12);
    assert_relative_eq!(x[1], 0.8, epsilon = 1e-12);
    let mut x = vec![0.9, 0.0];
    mpgp(&mut id, &[0.3, -0.4], &blocks, &mut x, &QpOptions::default()).expect("mpgp");
    assert_relative_eq!(x[0], 0.3, epsilon = 1e-12);
    assert_relative_eq!(x[1], -0.4, epsilon = 1e-12);
}

#[test]
fn mpgp_random_spd_with_discs_and_half_lines() {
    let mut rng = Lcg(11);
    for trial in 0..5 {
        // 10 half-lines x ≥ 0 followed by 10 discs of radius 0.8
        let (nh, nd) = (10, 10);
        let n = nh + 2 * nd;
        let h = random_spd(n, &mut rng);
        let b: Vec<f64> = (0..n).map(|_| 3.0 * rng.next()).collect();
        let mut blocks = vec![ConvexBlock::Interval { lower: 0.0, upper: INF }; nh];
        blocks.extend(std::iter::repeat_n(ConvexBlock::Ball { dim: 2, radius: 0.8 }, nd));
        let mut x = vec![0.0; n];
        let opts = QpOptions::default().with_tolerance(1e-11);
        let rep = mpgp(&mut DenseHessian(h.clone()), &b, &blocks, &mut x, &opts).expect("mpgp");
        let g = gradient(&h, &x, &b);
        let scale = b.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut worst = 0.0_f64;
        let mut on_sphere = 0;
        for i in 0..nh {
            assert!(x[i] >= 0.0);
            worst = worst.max(if x[i] == 0.0 { (-g[i]).max(0.0) } else { g[i].abs() });
        }
        for c in 0..nd {
            let (xc, gc) = (&x[nh + 2 * c..nh + 2 * c + 2], &g[nh + 2 * c..nh + 2 * c + 2]);
            let r = (xc[0] * xc[0] + xc[1] * xc[1]).sqrt();
            assert!(r <= 0.8 * (1.0 + 1e-14));
            if r >= 0.8 * (1.0 - 1e-9) {
                on_sphere += 1;
                // g = −λ n with λ ≥ 0: tangential part zero, normal part non-positive
                let (nx, ny) = (xc[0] / r, xc[1] / r);
                let gn = gc[0] * nx + gc[1] * ny;
                let gt = -gc[0] * ny + gc[1] * nx;
                worst = worst.max(gt.abs()).max(gn.max(0.0));
            } else {
                worst = worst.max(gc[0].abs()).max(gc[1].abs());
            }
        }
        println!(
            "trial {trial}: {} iterations ({} cg, {} exp, {} prop), {} products, {on_sphere} discs active, kkt {:.2e}",
            rep.iterations,
            rep.cg_steps,
            rep.expansion_steps,
            rep.proportioning_steps,
            rep.hessian_products,
            worst / scale
        );
        assert!(on_sphere > 0 && on_sphere < nd, "both active and free discs wanted ({on_sphere})");
        assert!(worst / scale < 1e-9, "trial {trial}: KKT residual {:e}", worst / scale);
    }
}

#[test]
fn mpgp_with_intervals_matches_mprgp() {
    let mut rng = Lcg(3);
    let n = 20;
    let h = random_spd(n, &mut rng);
    let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    let l = vec![-0.2; n];
    let u = vec![0.2; n];
    let blocks: Vec<ConvexBlock> =
        l.iter().zip(&u).map(|(&lower, &upper)| ConvexBlock::Interval { lower, upper }).collect();
    let opts = QpOptions::default().with_tolerance(1e-12);
    let mut x1 = vec![0.0; n];
    let mut x2 = vec![0.0; n];
    mprgp(&mut DenseHessian(h.clone()), &b, &l, &u, &mut x1, &opts).expect("mprgp");
    mpgp(&mut DenseHessian(h.clone()), &b, &blocks, &mut x2, &opts).expect("mpgp");
    for (a, c) in x1.iter().zip(&x2) {
        assert!((a - c).abs() < 1e-9, "{a} vs {c}");
    }
}

#[test]
fn power_method_estimates_the_norm() {
    let h = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 2.0, 10.0, 3.0]));
    let (l, k) = estimate_norm(&mut DenseHessian(h), 4, 50).expect("power method");
    assert!(k >= 1 && (l - 10.0).abs() < 1e-2 && l <= 10.0 + 1e-12, "{l}");
}

#[test]
fn qp_errors() {
    let h = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 1.0]));
    let mut x = vec![0.0; 2];
    // lower > upper
    let e = mprgp(
        &mut DenseHessian(h.clone()),
        &[1.0, 1.0],
        &[1.0, 0.0],
        &[0.0, 1.0],
        &mut x,
        &QpOptions::default(),
    );
    assert!(matches!(e, Err(ContactError::Infeasible(_))), "{e:?}");
    // size mismatch
    let e =
        mprgp(&mut DenseHessian(h.clone()), &[1.0, 1.0], &[0.0], &[1.0, 1.0], &mut x, &QpOptions::default());
    assert!(matches!(e, Err(ContactError::InvalidParameter(_))), "{e:?}");
    // step factor outside (0, 2]
    let opts = QpOptions::default().with_step_factor(2.5);
    let e = mprgp(&mut DenseHessian(h.clone()), &[1.0, 1.0], &[0.0; 2], &[1.0; 2], &mut x, &opts);
    assert!(matches!(e, Err(ContactError::InvalidParameter(_))), "{e:?}");
    // unbounded below: a zero-curvature descent ray inside the feasible set
    let singular = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 0.0]));
    let mut x = vec![0.0; 2];
    let e = mprgp(
        &mut DenseHessian(singular.clone()),
        &[1.0, 1.0],
        &[0.0; 2],
        &[INF; 2],
        &mut x,
        &QpOptions::default(),
    );
    assert!(matches!(e, Err(ContactError::Infeasible(_))), "{e:?}");
    let blocks = [ConvexBlock::Interval { lower: 0.0, upper: INF }; 2];
    let mut x = vec![0.0; 2];
    let e = mpgp(&mut DenseHessian(singular), &[1.0, 1.0], &blocks, &mut x, &QpOptions::default());
    assert!(matches!(e, Err(ContactError::Infeasible(_))), "{e:?}");
    // blocks not covering the vector
    let e = mpgp(&mut DenseHessian(h.clone()), &[1.0, 1.0], &blocks[..1], &mut x, &QpOptions::default());
    assert!(matches!(e, Err(ContactError::InvalidParameter(_))), "{e:?}");
    // too few iterations: NoConvergence with one history entry per iteration
    let mut rng = Lcg(5);
    let h = random_spd(20, &mut rng);
    let b: Vec<f64> = (0..20).map(|_| rng.next()).collect();
    let mut x = vec![0.0; 20];
    let opts = QpOptions::default().with_max_iterations(3);
    match mprgp(&mut DenseHessian(h), &b, &[-INF; 20], &[INF; 20], &mut x, &opts) {
        Err(ContactError::NoConvergence { solver, iterations, history }) => {
            assert_eq!(solver, "mprgp");
            assert_eq!(iterations, 3);
            assert_eq!(history.len(), 3);
            assert!(history.iter().all(|r| r.normal > 0.0));
        }
        other => panic!("expected NoConvergence, got {other:?}"),
    }
}

/// The longer expansion steps (`Expansion::ProjectedCg`, `Expansion::Preconditioned`) reach the
/// same solutions as Dostál's fixed step: on strictly convex random box problems (with and
/// without Jacobi preconditioning in face) the KKT residual is below 1e-9 and `x` equals the
/// fixed-step solution to 1e-8 (the minimiser is unique).
#[test]
fn longer_expansion_steps_reach_the_same_box_solutions() {
    let mut rng = Lcg(7);
    for &precondition in &[false, true] {
        for trial in 0..5 {
            let n = 30;
            let h = random_spd(n, &mut rng);
            let b: Vec<f64> = (0..n).map(|_| 3.0 * rng.next()).collect();
            let l: Vec<f64> =
                (0..n).map(|i| if i % 5 == 0 { -INF } else { -0.5 + 0.3 * rng.next() }).collect();
            let u: Vec<f64> = (0..n).map(|i| if i % 7 == 0 { INF } else { 0.5 + 0.3 * rng.next() }).collect();
            let base = QpOptions::default().with_tolerance(1e-12).with_precondition(precondition);
            let mut x0 = vec![0.0; n];
            let fixed = mprgp(&mut DenseHessian(h.clone()), &b, &l, &u, &mut x0, &base).expect("fixed");
            for expansion in [Expansion::ProjectedCg, Expansion::Preconditioned] {
                let mut x = vec![0.0; n];
                let opts = base.with_expansion(expansion);
                let rep = mprgp(&mut DenseHessian(h.clone()), &b, &l, &u, &mut x, &opts).expect("mprgp");
                let kkt = box_kkt(&h, &b, &l, &u, &x);
                let diff = x.iter().zip(&x0).fold(0.0_f64, |m, (a, c)| m.max((a - c).abs()));
                println!(
                    "trial {trial} precondition {precondition} {expansion:?}: {} iterations ({} exp, {} fallbacks) vs fixed {} ({} exp), kkt {kkt:.2e}, |x − x_fixed| {diff:.2e}",
                    rep.iterations, rep.expansion_steps, rep.expansion_fallbacks, fixed.iterations, fixed.expansion_steps
                );
                assert!(kkt < 1e-9, "trial {trial} {expansion:?}: KKT residual {kkt:e}");
                assert!(diff < 1e-8, "trial {trial} {expansion:?}: differs from the fixed step by {diff:e}");
            }
        }
    }
}

/// As above for MPGP with discs and half-lines (3D friction-like blocks): KKT of the disc
/// constraints and equality with the fixed-step solution.
#[test]
fn longer_expansion_steps_reach_the_same_disc_solutions() {
    let mut rng = Lcg(11);
    for trial in 0..5 {
        let (nh, nd) = (10, 10);
        let n = nh + 2 * nd;
        let h = random_spd(n, &mut rng);
        let b: Vec<f64> = (0..n).map(|_| 3.0 * rng.next()).collect();
        let mut blocks = vec![ConvexBlock::Interval { lower: 0.0, upper: INF }; nh];
        blocks.extend(std::iter::repeat_n(ConvexBlock::Ball { dim: 2, radius: 0.8 }, nd));
        let base = QpOptions::default().with_tolerance(1e-12);
        let mut x0 = vec![0.0; n];
        mpgp(&mut DenseHessian(h.clone()), &b, &blocks, &mut x0, &base).expect("fixed");
        for expansion in [Expansion::ProjectedCg, Expansion::Preconditioned] {
            let mut x = vec![0.0; n];
            let rep =
                mpgp(&mut DenseHessian(h.clone()), &b, &blocks, &mut x, &base.with_expansion(expansion))
                    .expect("mpgp");
            let g = gradient(&h, &x, &b);
            let scale = b.iter().map(|v| v * v).sum::<f64>().sqrt();
            let mut worst = 0.0_f64;
            for i in 0..nh {
                assert!(x[i] >= 0.0);
                worst = worst.max(if x[i] == 0.0 { (-g[i]).max(0.0) } else { g[i].abs() });
            }
            for c in 0..nd {
                let (xc, gc) = (&x[nh + 2 * c..nh + 2 * c + 2], &g[nh + 2 * c..nh + 2 * c + 2]);
                let r = (xc[0] * xc[0] + xc[1] * xc[1]).sqrt();
                assert!(r <= 0.8 * (1.0 + 1e-14));
                if r >= 0.8 * (1.0 - 1e-9) {
                    let (nx, ny) = (xc[0] / r, xc[1] / r);
                    let gn = gc[0] * nx + gc[1] * ny;
                    let gt = -gc[0] * ny + gc[1] * nx;
                    worst = worst.max(gt.abs()).max(gn.max(0.0));
                } else {
                    worst = worst.max(gc[0].abs()).max(gc[1].abs());
                }
            }
            let diff = x.iter().zip(&x0).fold(0.0_f64, |m, (a, c)| m.max((a - c).abs()));
            println!(
                "trial {trial} {expansion:?}: {} iterations ({} exp, {} fallbacks), kkt {:.2e}, |x − x_fixed| {diff:.2e}",
                rep.iterations,
                rep.expansion_steps,
                rep.expansion_fallbacks,
                worst / scale
            );
            assert!(worst / scale < 1e-9, "trial {trial} {expansion:?}: KKT residual {:e}", worst / scale);
            assert!(diff < 1e-8, "trial {trial} {expansion:?}: differs from the fixed step by {diff:e}");
        }
    }
}

/// What the longer steps are for: a badly scaled obstacle problem, `H = D (L + I) D` (`L` the
/// 1D Laplacian, `D = diag(1, 0.05, 1, 0.05, …)`, 200 unknowns) with upper bounds that most
/// entries reach, solved with Jacobi preconditioning in face. The CG steps see the scaling; the
/// fixed step `ᾱ = 1.9/‖H‖` moves the entries with `D_i = 0.05` by a factor 400 too little, so
/// the fixed-step expansion adds few bounds per step. The longer steps must need fewer than
/// half the expansion steps, and reach the same solution (KKT).
#[test]
fn longer_expansion_steps_need_fewer_expansion_steps_on_a_scaled_obstacle() {
    let n = 200;
    let d: Vec<f64> = (0..n).map(|i| if i % 2 == 0 { 1.0 } else { 0.05 }).collect();
    let h = DMatrix::from_fn(n, n, |i, j| {
        let a = if i == j {
            3.0
        } else if i.abs_diff(j) == 1 {
            -1.0
        } else {
            0.0
        };
        d[i] * a * d[j]
    });
    // (L + I) y = c, c_i = 2 sin(π i/n), has y ≈ c inside; x = D⁻¹ y, bounded by 0.8 / D_i
    let b: Vec<f64> = d
        .iter()
        .enumerate()
        .map(|(i, di)| di * 2.0 * (std::f64::consts::PI * i as f64 / n as f64).sin())
        .collect();
    let l = vec![-INF; n];
    let u: Vec<f64> = d.iter().map(|di| 0.8 / di).collect();
    let mut counts = Vec::new();
    let mut solutions = Vec::new();
    for expansion in [Expansion::Fixed, Expansion::ProjectedCg, Expansion::Preconditioned] {
        let mut x = vec![0.0; n];
        let opts = QpOptions::default().with_tolerance(1e-13).with_expansion(expansion);
        let rep = mprgp(&mut DenseHessian(h.clone()), &b, &l, &u, &mut x, &opts).expect("mprgp");
        let active = (0..n).filter(|&i| x[i] >= u[i]).count();
        let kkt = box_kkt(&h, &b, &l, &u, &x);
        println!(
            "{expansion:?}: {} iterations ({} cg, {} exp, {} prop, {} fallbacks), {} products, {active} active, kkt {kkt:.2e}",
            rep.iterations,
            rep.cg_steps,
            rep.expansion_steps,
            rep.proportioning_steps,
            rep.expansion_fallbacks,
            rep.hessian_products
        );
        assert!(active > n / 4 && active < n, "active {active}");
        assert!(kkt < 1e-9, "{expansion:?}: KKT residual {kkt:e}");
        counts.push(rep.expansion_steps);
        solutions.push(x);
    }
    for x in &solutions[1..] {
        let diff = x.iter().zip(&solutions[0]).fold(0.0_f64, |m, (a, c)| m.max((a - c).abs()));
        println!("|x − x_fixed| = {diff:.2e} (max |x| = 16)");
        assert!(diff < 1e-8, "differs from the fixed step by {diff:e}");
    }
    assert!(2 * counts[1] < counts[0] && 2 * counts[2] < counts[0], "expansion steps {counts:?}");
}
