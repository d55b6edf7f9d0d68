//! # synovia-models
//!
//! Demonstration and verification models built on the `synovia` library, shared by its
//! examples, integration tests and benches (they are not part of the library's API):
//!
//! | module | model | reference |
//! |---|---|---|
//! | [`hertz`] | 2D/3D Hertz contact of a half-disc / hemisphere on a flat or a second body, 2D Cattaneo–Mindlin shear, on matching and non-matching meshes | closed-form Hertz and Cattaneo–Mindlin solutions (`docs/model.md §8`, `§9`) |
//! | [`knee2d`] | a 2D tibiofemoral joint (femoral condyle with cartilage on a tibial plateau) through a gait cycle | equilibrium, KKT conditions (`docs/model.md §3`, `§7`) |
//! | [`hip3d`] | a 3D hip: femoral head with cartilage in an acetabular cup | equilibrium, KKT conditions (`docs/model.md §3`) |
//! | [`tkr3d`] | the total knee replacement of Grand Challenge subject DM over a measured gait cycle (insert elastic, femoral component rigid, ISO 14243-1 force) | equilibrium, KKT conditions (`docs/tkr3d.md`) |
//! | [`verification`] | manufactured solution of bonded multi-body anisotropic elasticity | exact displacement, `O(h)` energy and `O(h²)` `L²` errors (`docs/model.md §8`) |
//!
//! ```
//! use synovia_models::hertz::Hertz2d;
//!
//! let h = Hertz2d::default();
//! assert!(h.radius > 0.0);
//! ```
#![warn(missing_docs)]

pub mod hertz;
pub mod hip3d;
pub mod knee2d;
pub mod smooth_gap;
pub mod tkr3d;
pub mod verification;
