//! The integration tests of `synovia-cli`, one module per concern, compiled into one test binary
//! (the generic code they use is instantiated once, not once per file). Run one module with a
//! filter, e.g. `cargo test --release -p synovia-cli --test suite cli::`.

mod cli;
mod concurrent;
mod format;
mod fuzz_scenario;
mod outputs;
mod setup_checks;
mod stl_subdivide;
mod sweep;
mod tfeti;
mod units;
