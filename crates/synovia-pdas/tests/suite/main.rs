//! The integration tests of `synovia-pdas`, one module per concern, compiled into one test binary
//! (the generic code they use is instantiated once, not once per file). Run one module with a
//! filter, e.g. `cargo test --release -p synovia-pdas --test suite border::`.

mod border;
mod common;
mod errors;
mod frictionless;
mod step;
mod tresca;
