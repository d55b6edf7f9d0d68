//! The integration tests of the `synovia` package, one module per concern, compiled into one
//! test binary: the library's generic code is instantiated once for all of them instead of
//! once per file (CI's build time). Run one module with a filter, e.g.
//! `cargo test --release --test suite knee2d_nonlinear::`.

mod backend;
mod cattaneo_mindlin3d;
mod contact;
mod contact_mortar;
mod contact_nonmatching;
mod convergence;
mod coulomb;
mod discretisation;
mod dynamic_nonlinear;
mod dynamic_rigid;
mod errors;
mod fast_path;
mod foundation;
mod gmsh_solve;
mod hip3d;
mod input_audit;
mod knee2d;
mod knee2d_nonlinear;
mod nonlinear_convergence;
mod nonlinear_rigid;
mod nonlinear_rigid_condyles;
mod patch;
mod pose_input;
mod pose_resolve_whole_factor;
mod proptest_contact;
mod reliability;
mod reporting;
mod rigid_body;
mod screening;
mod semi_coercive;
mod session;
mod session_nonlinear;
mod solver_robustness;
mod stiffness_ratio;
mod surface_obstacle;
mod tkr3d_model;
mod vtu_readers;
