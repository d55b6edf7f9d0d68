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
