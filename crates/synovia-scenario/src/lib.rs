//! # synovia-scenario
//!
//! Inputs turned into models, for the `synovia` command (`synovia-cli`) and the C API
//! (`synovia-capi`):
//!
//! - [`scenario`]: the TOML scenario format (serde types; [`ScenarioError`]s that name the key
//!   path, e.g. `body[0].material.E`, and the line and column in the file);
//! - [`build`]: a parsed [`Scenario`] turned into a [`JointModel`](synovia::builder::JointModel)
//!   (bodies `Ωᵏ` of `docs/model.md §1`, materials `§2`, conditions on `Γᵏ_D`, `Γᵏ_N`, contact
//!   pairs `§3`, solver `§6` and analysis `§7`), with every semantic error located at the value
//!   it is about;
//! - [`arrays`]: a model from flat arrays (node coordinates, P1 cells with a body id each,
//!   tagged boundary facets, one isotropic material per body), with boundary conditions set by
//!   part tag and contact pairs between tagged parts — the input of the C API.
//!
//! The format is documented with a complete example in `docs/scenario.md`, the array input in
//! `docs/c-api.md`.
//!
//! ```
//! use synovia_scenario::{build::build, Scenario, Source};
//!
//! let text = r#"
//! dimension = 2
//! [[body]]
//! name = "block"
//! mesh = { generator = "rectangle", x = [0.0, 2.0], y = [0.0, 1.0], cells = [4, 2] }
//! material = { type = "isotropic", E = 1000.0, nu = 0.3 }
//! [[boundary]]
//! body = "block"
//! part = "bottom"
//! kind = "clamped"
//! [analysis]
//! type = "static"
//! "#;
//! let sc = Scenario::parse(Source::new("block.toml", text.to_string()))?;
//! let built = build::<2>(&sc)?;
//! assert_eq!(built.joint.model().bodies().len(), 1);
//! # Ok::<(), synovia_scenario::ScenarioError>(())
//! ```
#![warn(missing_docs)]

pub mod arrays;
pub mod build;
pub mod scenario;
pub mod sweep;

pub use arrays::{ArrayError, ArrayModel, ConditionChange, ConditionKind, ModelArrays};
pub use scenario::{Scenario, ScenarioError, Source};
