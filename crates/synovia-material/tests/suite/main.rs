//! The integration tests of `synovia-material`, one module per concern, compiled into one test binary
//! (the generic code they use is instantiated once, not once per file). Run one module with a
//! filter, e.g. `cargo test --release -p synovia-material --test suite materials::`.

mod materials;
mod proptests;
