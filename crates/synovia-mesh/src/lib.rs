//! # synovia-mesh
//!
//! Simplicial meshes for synovia: one conforming P1 mesh per body, in 2D (triangles) or 3D
//! (tetrahedra), generic over the dimension `const D: usize`.
//!
//! A [`Mesh`] holds node coordinates, cells and named [`BoundaryPart`]s of the kinds of
//! docs/model.md §1 ([`BoundaryKind`]: prescribed `u₂(t)`, clamped, traction `P(t)`, traction free,
//! symmetry `Γ₀`, contact). Every cell is positively oriented, which the constructors check
//! (and [`Mesh::new_with_repair`] enforces). Boundary facets carry the outward orientation, so
//! [`Mesh::facet_normal`] is the outward unit normal `n` and [`Mesh::nodal_normals`] the
//! measure-weighted nodal normals used by symmetry and contact conditions.
//!
//! The [`generators`] module builds the meshes synovia's verification and joint models need, and
//! [`refine`] refines any mesh locally toward a region by conforming longest-edge bisection.
#![warn(missing_docs)]

pub mod error;
pub mod generators;
pub mod intersect;
pub mod matching;
pub mod math;
pub mod mesh;
pub mod refine;
pub mod subdivision;
pub mod surface;

pub use error::MeshError;
pub use math::{Point, Real, Tensor, Vector};
pub use mesh::{BoundaryFacet, BoundaryKind, BoundaryPart, CellOrientation, Mesh};
pub use surface::{SurfaceError, TriangleSurface};
