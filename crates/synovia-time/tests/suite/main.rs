//! The integration tests of `synovia-time`, one module per concern, compiled into one test binary
//! (the generic code they use is instantiated once, not once per file). Run one module with a
//! filter, e.g. `cargo test --release -p synovia-time --test suite dynamic::`.

mod dynamic;
mod friction_laws;
mod fuzz_table;
mod history;
mod nonlinear_dynamic;
mod one_pipeline;
mod quasistatic;
mod table;
