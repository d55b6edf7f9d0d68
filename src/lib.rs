//! # synovia
//!
//! Finite-element simulation of human joints (knee, hip, their total replacements) as
//! multi-body contact problems under time-varying loads. This facade re-exports the workspace
//! crates:
//!
//! | crate | concern |
//! |---|---|
//! | [`mesh`] (`synovia-mesh`) | simplicial meshes, boundary parts, generators, local refinement |
//! | [`material`] (`synovia-material`) | constitutive laws `C⁽⁰⁾`, `C⁽¹⁾` (isotropic, transversely isotropic, anisotropic, Kelvin–Voigt) |
//! | [`fem`] (`synovia-fem`) | P1 elements, constraints, assembly, sparse Cholesky, post-processing |
//! | [`io`] (`synovia-io`) | VTU/PVD output for ParaView |
//! | [`contact_ops`] (`synovia-contact`) | contact pairs, `B_hn`/`B_Ht`, the contact problem, `ContactSolver`, KKT checker |
//! | [`pdas`] (`synovia-pdas`) | semismooth Newton / PDAS and AU-PDAS |
//! | [`uzawa`] (`synovia-uzawa`) | Uzawa with MPRGP, and the dual QP on the interface |
//! | [`time`] (`synovia-time`) | load histories, rigid motions, quasi-static and dynamic time stepping |
//!
//! See `docs/architecture.md` for the crate graph and the path of data from mesh to solution,
//! and the specification `spec/model.md` for the equations.
//!
//! ```
//! use std::sync::Arc;
//! use synovia::prelude::*;
//!
//! // A 2 × 1 block, clamped at the bottom, pulled up at the top by a traction of 0.01 E.
//! let mut mesh = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4, Grading::Uniform, Grading::Uniform)?;
//! mesh.set_part_kind("bottom", BoundaryKind::Clamped)?;
//! mesh.set_part_kind("top", BoundaryKind::Traction)?;
//! let material = plane_strain(1.0e3, 0.3)?;
//! let mut model = Model::<2>::new();
//! let block = model.add_body("block", mesh, Arc::new(material))?;
//! model.traction(block, "top", |_x, _n, _t| Vector::<2>::new(0.0, 10.0))?;
//! let solution = solve_elastic(&model, 0.0)?;
//! let top = solution.displacement[0].iter().map(|u| u[1]).fold(0.0, f64::max);
//! assert!(top > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub use synovia_contact as contact_ops;
pub use synovia_fem as fem;
pub use synovia_io as io;
pub use synovia_material as material;
pub use synovia_mesh as mesh;
pub use synovia_pdas as pdas;
pub use synovia_time as time;
pub use synovia_uzawa as uzawa;

/// Static contact problems of a model (re-exported from `synovia-contact`).
pub mod contact {
    pub use synovia_contact::static_contact::*;
}
pub mod hertz;
pub mod output;
pub mod solvers;
pub mod verification;

/// The types most programs need.
pub mod prelude {
    pub use synovia_fem::{
        solve_elastic, BodyFields, BodyId, ComponentMask, ElasticParams, ElasticSolution, ElasticSolver,
        FemError, Model,
    };
    pub use synovia_material::{
        anisotropic, isotropic, plane_strain, plane_stress, transversely_isotropic, KelvinVoigt,
        LinearElastic, Material, MaterialError, TransverseIsotropy,
    };
    pub use synovia_mesh::generators::{box_mesh, rectangle, Grading};
    pub use synovia_mesh::math::{Point, Real, Vector};
    pub use synovia_mesh::{BoundaryKind, Mesh, MeshError};
}
