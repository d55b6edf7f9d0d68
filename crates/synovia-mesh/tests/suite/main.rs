//! The integration tests of `synovia-mesh`, one module per concern, compiled into one test binary
//! (the generic code they use is instantiated once, not once per file). Run one module with a
//! filter, e.g. `cargo test --release -p synovia-mesh --test suite generators::`.

mod common;
mod generators;
mod map_nodes;
mod refine;
