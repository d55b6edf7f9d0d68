//! The integration tests of `synovia-io`, one module per concern, compiled into one test binary
//! (the generic code they use is instantiated once, not once per file). Run one module with a
//! filter, e.g. `cargo test --release -p synovia-io --test suite fuzz_gmsh::`.

mod fuzz_gmsh;
mod gmsh;
mod roundtrip;
mod stl;
mod tkr_insert_mesh;
