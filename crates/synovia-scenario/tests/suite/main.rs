//! The integration tests of `synovia-scenario`, one module per concern, compiled into one test binary
//! (the generic code they use is instantiated once, not once per file). Run one module with a
//! filter, e.g. `cargo test --release -p synovia-scenario --test suite arrays::`.

mod arrays;
mod dynamic_nonlinear;
mod force_control;
mod friction_law_quasistatic;
mod fuzz_stl;
mod newton_and_fillet;
