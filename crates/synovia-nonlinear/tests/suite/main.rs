//! The integration tests of `synovia-nonlinear`, one module per concern, compiled into one test binary
//! (the generic code they use is instantiated once, not once per file). Run one module with a
//! filter, e.g. `cargo test --release -p synovia-nonlinear --test suite active_set_strategies::`.

mod active_set_strategies;
mod concave_crease;
mod deformed_geometry_solves;
mod gap_control_search;
mod hertz_small_load;
mod homogeneous;
mod linear_bodies;
mod multipliers_only;
mod placed_friction;

/// Helpers shared by the modules.
mod common {
    use synovia_contact::operators::ContactPair;
    use synovia_fem::{ElasticParams, Kinematics, Model};
    use synovia_nonlinear::{NewtonParams, NonlinearContact};

    /// The times `k / levels`, `k = 1, …, levels`: a loading in `levels` equal steps.
    pub fn level_times(levels: usize) -> Vec<f64> {
        (1..=levels).map(|k| k as f64 / levels as f64).collect()
    }

    /// `max |a − b| / max |b|` (`b` the reference).
    pub fn max_rel(a: &[f64], b: &[f64]) -> f64 {
        assert_eq!(a.len(), b.len());
        let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
        a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
    }

    /// The Newton solver of `model` with every body in finite strain.
    pub fn finite_strain<const D: usize>(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        params: NewtonParams,
    ) -> NonlinearContact<D> {
        NonlinearContact::new(model, pairs, &[Kinematics::FiniteStrain], ElasticParams::default(), params)
            .expect("set-up")
    }
}
