//! # synovia-time
//!
//! Time-varying loads (docs/model.md §7): load histories, prescribed rigid motions of boundary parts,
//! the quasi-static stepper (a Tresca contact problem per time level with `g_c` frozen from the
//! previous level, incremental slip, optional Coulomb fixed point) and the dynamic semi-implicit
//! Kelvin–Voigt stepper — linear, or with a nonlinear elastic part solved by Newton's method
//! (`nonlinear_dynamic`, docs/model.md (12.2)) — with per-step results written as CSV and PVD.
#![warn(missing_docs)]

pub mod dynamic;
pub mod error;
pub mod history;
pub mod nonlinear_dynamic;
pub mod quasistatic;
pub mod results;
pub mod solid_fields;
pub mod table;

pub use error::TimeError;
