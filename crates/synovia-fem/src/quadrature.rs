//! Quadrature rules on the reference simplex.
//!
//! Points are given in barycentric coordinates `(λ_0, …, λ_D)` and the weights sum to 1, so
//! `∫_T f dx ≈ |T| Σ_q w_q f(x(λ_q))` on any simplex `T`. Low degrees use the classical
//! symmetric rules with positive weights; higher degrees use the collapsed (Duffy) tensor Gauss
//! rule, also with positive weights.

use crate::error::FemError;

/// A quadrature rule on the reference `D`-simplex.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadratureRule {
    /// Barycentric coordinates, `D + 1` per point.
    pub barycentric: Vec<Vec<f64>>,
    /// Weights, summing to 1.
    pub weights: Vec<f64>,
    /// Polynomial degree integrated exactly.
    pub degree: usize,
}

impl QuadratureRule {
    /// A rule exact for polynomials of degree `degree` on the `dim`-simplex (`dim` = 1, 2, 3).
    ///
    /// Degree ≤ 1: centroid; degree 2: the symmetric 2-point (segment), 3-point (triangle) and
    /// 4-point (tetrahedron) rules; higher: collapsed Gauss–Legendre with `⌈(degree + dim)/2⌉`
    /// points per direction (degree ≤ 9).
    pub fn simplex(dim: usize, degree: usize) -> Result<Self, FemError> {
        if !(1..=3).contains(&dim) || degree > 9 {
            return Err(FemError::InvalidParameter(format!(
                "no quadrature rule of degree {degree} on the {dim}-simplex"
            )));
        }
        if degree <= 1 {
            return Ok(Self {
                barycentric: vec![vec![1.0 / (dim + 1) as f64; dim + 1]],
                weights: vec![1.0],
                degree: 1,
            });
        }
        if degree == 2 {
            let (a, b) = match dim {
                1 => (0.5 + 0.5 / 3f64.sqrt(), 0.5 - 0.5 / 3f64.sqrt()),
                2 => (2.0 / 3.0, 1.0 / 6.0),
                _ => (0.585_410_196_624_968_5, 0.138_196_601_125_010_5),
            };
            let n = dim + 1;
            let barycentric = (0..n).map(|k| (0..n).map(|i| if i == k { a } else { b }).collect()).collect();
            return Ok(Self { barycentric, weights: vec![1.0 / n as f64; n], degree: 2 });
        }
        let npts = (degree + dim).div_ceil(2);
        let (x, w) = gauss_legendre_01(npts)?;
        let mut barycentric = Vec::new();
        let mut weights = Vec::new();
        let fact: f64 = (1..=dim).map(|k| k as f64).product();
        match dim {
            1 => {
                for (xi, wi) in x.iter().zip(&w) {
                    barycentric.push(vec![1.0 - xi, *xi]);
                    weights.push(*wi);
                }
            }
            2 => {
                for (u, wu) in x.iter().zip(&w) {
                    for (v, wv) in x.iter().zip(&w) {
                        let (p, q) = (*u, (1.0 - u) * v);
                        barycentric.push(vec![1.0 - p - q, p, q]);
                        weights.push(wu * wv * (1.0 - u) * fact);
                    }
                }
            }
            _ => {
                for (u, wu) in x.iter().zip(&w) {
                    for (v, wv) in x.iter().zip(&w) {
                        for (s, ws) in x.iter().zip(&w) {
                            let p = *u;
                            let q = (1.0 - u) * v;
                            let r = (1.0 - u) * (1.0 - v) * s;
                            barycentric.push(vec![1.0 - p - q - r, p, q, r]);
                            weights.push(wu * wv * ws * (1.0 - u) * (1.0 - u) * (1.0 - v) * fact);
                        }
                    }
                }
            }
        }
        Ok(Self { barycentric, weights, degree })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// `true` if the rule has no points (never for rules built by [`QuadratureRule::simplex`]).
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }
}

/// Gauss–Legendre nodes and weights on `[0, 1]` (weights sum to 1), `n = 1..=6`.
fn gauss_legendre_01(n: usize) -> Result<(Vec<f64>, Vec<f64>), FemError> {
    let (x, w): (&[f64], &[f64]) = match n {
        1 => (&[0.0], &[2.0]),
        2 => (&[-0.577_350_269_189_625_8, 0.577_350_269_189_625_8], &[1.0, 1.0]),
        3 => (
            &[-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4],
            &[0.555_555_555_555_555_6, 0.888_888_888_888_889, 0.555_555_555_555_555_6],
        ),
        4 => (
            &[
                -0.861_136_311_594_052_6,
                -0.339_981_043_584_856_3,
                0.339_981_043_584_856_3,
                0.861_136_311_594_052_6,
            ],
            &[
                0.347_854_845_137_453_9,
                0.652_145_154_862_546_1,
                0.652_145_154_862_546_1,
                0.347_854_845_137_453_9,
            ],
        ),
        5 => (
            &[
                -0.906_179_845_938_664,
                -0.538_469_310_105_683,
                0.0,
                0.538_469_310_105_683,
                0.906_179_845_938_664,
            ],
            &[
                0.236_926_885_056_189_1,
                0.478_628_670_499_366_5,
                0.568_888_888_888_888_9,
                0.478_628_670_499_366_5,
                0.236_926_885_056_189_1,
            ],
        ),
        6 => (
            &[
                -0.932_469_514_203_152,
                -0.661_209_386_466_264_5,
                -0.238_619_186_083_196_9,
                0.238_619_186_083_196_9,
                0.661_209_386_466_264_5,
                0.932_469_514_203_152,
            ],
            &[
                0.171_324_492_379_170_3,
                0.360_761_573_048_138_6,
                0.467_913_934_572_691,
                0.467_913_934_572_691,
                0.360_761_573_048_138_6,
                0.171_324_492_379_170_3,
            ],
        ),
        _ => {
            return Err(FemError::InvalidParameter(format!(
                "Gauss–Legendre rule with {n} points not tabulated"
            )))
        }
    };
    Ok((x.iter().map(|t| 0.5 * (t + 1.0)).collect(), w.iter().map(|t| 0.5 * t).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn monomial_integral(exps: &[u32]) -> f64 {
        // ∫ over the unit simplex of x^a y^b z^c = a! b! c! / (a+b+c+dim)!, divided by 1/dim!
        let dim = exps.len();
        let f = |n: u32| (1..=n).map(|k| k as f64).product::<f64>();
        let s: u32 = exps.iter().sum();
        let num: f64 = exps.iter().map(|&e| f(e)).product();
        num / f(s + dim as u32) * f(dim as u32)
    }

    #[test]
    fn rules_integrate_monomials_exactly() {
        for dim in 1..=3usize {
            for degree in 1..=6usize {
                let rule = QuadratureRule::simplex(dim, degree).expect("rule");
                let wsum: f64 = rule.weights.iter().sum();
                assert!((wsum - 1.0).abs() < 1e-14);
                assert!(rule.weights.iter().all(|&w| w > 0.0));
                // all monomials of total degree ≤ degree
                let mut exps = vec![0u32; dim];
                loop {
                    let tot: u32 = exps.iter().sum();
                    if tot as usize <= degree {
                        let q: f64 = rule
                            .barycentric
                            .iter()
                            .zip(&rule.weights)
                            .map(|(l, w)| {
                                w * exps
                                    .iter()
                                    .enumerate()
                                    .map(|(k, &e)| l[k + 1].powi(e as i32))
                                    .product::<f64>()
                            })
                            .sum();
                        let exact = monomial_integral(&exps);
                        assert!(
                            (q - exact).abs() < 1e-13,
                            "dim {dim} degree {degree} exps {exps:?}: {q} vs {exact}"
                        );
                    }
                    // next multi-index
                    let mut k = 0;
                    loop {
                        if k == dim {
                            break;
                        }
                        exps[k] += 1;
                        if exps[k] as usize > degree {
                            exps[k] = 0;
                            k += 1;
                        } else {
                            break;
                        }
                    }
                    if k == dim {
                        break;
                    }
                }
            }
        }
    }
}
