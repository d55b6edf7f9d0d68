//! # synovia-io
//!
//! Output of synovia results for [ParaView](https://www.paraview.org) (and any VTK-based
//! tool) in the VTK XML formats, a reader of the same files for round-trip tests and
//! verification, and a reader of Gmsh meshes.
//!
//! * [`VtuWriter`] / [`write_vtu`]: one `.vtu` file (VTK XML `UnstructuredGrid`) holding all
//!   bodies in one `<Piece>` (told apart by the point and cell field `body`), with point and
//!   cell [`Field`]s, zlib-compressed by default.
//! * [`PvdWriter`]: a `.pvd` collection listing `.vtu` files with their times (a time series).
//! * [`TimeSeriesWriter`]: writes `DIR/NAME_0000.vtu`, `DIR/NAME_0001.vtu`, … and rewrites
//!   `DIR/NAME.pvd` after every step, so an interrupted run still leaves a readable series.
//! * [`read_vtu`], [`parse_vtu`], [`read_pvd`]: read back exactly what the writers write
//!   (split into bodies again).
//! * [`gmsh`]: input of [Gmsh](https://gmsh.info) `.msh` meshes (MSH 4.1 and 2.2, ASCII or
//!   binary): [`read_msh`] parses a file, [`GmshMesh::bodies`] turns its physical groups into
//!   one synovia [`Mesh`](synovia_mesh::Mesh) per body with named boundary parts (see the
//!   [`gmsh`] module for the mapping and the part-kind naming convention).
//! * [`stl`]: STL surfaces (binary and ASCII) as [`TriangleSurface`](synovia_mesh::TriangleSurface)s:
//!   [`read_stl`], [`parse_stl`], [`write_stl`].
//!
//! Every problem is an [`IoError`]; nothing here panics on user input. Fields with NaN or
//! infinite values are rejected ([`IoError::NonFinite`], naming the field and the index)
//! rather than written, since ParaView renders them badly or not at all.
//!
//! ## File layout
//!
//! A `.vtu` file written by [`VtuWriter`] looks like this (shown with [`Encoding::Ascii`]; all
//! bodies in one `<Piece>`, their points and cells in the order the bodies were added):
//!
//! ```xml
//! <?xml version="1.0"?>
//! <VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt32">
//!   <UnstructuredGrid>
//!     <Piece NumberOfPoints="4" NumberOfCells="2">
//!       <PointData>
//!         <DataArray type="Float64" Name="displacement" NumberOfComponents="3" format="ascii">
//!           …one tuple per point…
//!         </DataArray>
//!         <DataArray type="Int32" Name="body" format="ascii">0 0 0 0</DataArray>
//!       </PointData>
//!       <CellData>
//!         <DataArray type="Float64" Name="stress" NumberOfComponents="9" format="ascii">…</DataArray>
//!         <DataArray type="Int32" Name="body" format="ascii">0 0</DataArray>
//!       </CellData>
//!       <Points>
//!         <DataArray type="Float64" Name="Points" NumberOfComponents="3" format="ascii">…</DataArray>
//!       </Points>
//!       <Cells>
//!         <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 0 2 3</DataArray>
//!         <DataArray type="Int64" Name="offsets" format="ascii">3 6</DataArray>
//!         <DataArray type="UInt8" Name="types" format="ascii">5 5</DataArray>
//!       </Cells>
//!     </Piece>
//!   </UnstructuredGrid>
//! </VTKFile>
//! ```
//!
//! * **Points** always have 3 coordinates (`z = 0` for 2D meshes).
//! * **Cells** are stored VTK-style: the flat `connectivity` list, `offsets` (end of each cell
//!   in it) and `types`: `5` ([`VTK_TRIANGLE`]) in 2D, `10` ([`VTK_TETRA`]) in 3D, with the
//!   mesh's (positively oriented) node order.
//! * **Fields**: each [`Field`] becomes a `Float64` `<DataArray>` under `<PointData>` or
//!   `<CellData>` with `NumberOfComponents` = its component count; 2-component fields are
//!   padded to 3 (`z = 0`) so ParaView treats them as vectors; 9 components are a row-major
//!   `3 × 3` tensor ([`Field::cell_tensors`] pads 2D tensors).
//! * **`body`**: the writer always adds an `Int32` point field and an `Int32` cell field named
//!   `"body"` holding the body index (0 for the first body added). Callers must not pass a
//!   field of that name. One piece rather than one per body so that every reader gets every
//!   body: meshio 5.3 keeps only the last piece of a file (its issue #1444).
//! * **Encodings** ([`Encoding`]): [`Encoding::Zlib`] (the default) writes `format="binary"`
//!   with `compressor="vtkZLibDataCompressor"` and `header_type="UInt64"`: per array the base64
//!   of the block header and the base64 of the zlib-compressed 32 KiB blocks, VTK's own layout;
//!   `format="ascii"` writes `f64` values in Rust's shortest round-trip form (`{:e}`, e.g.
//!   `1.25e-3`); [`Encoding::Base64`] writes, per array, the base64 encoding of a little-endian
//!   `UInt32` byte count followed by the raw little-endian values. All three are exact. No
//!   appended data.
//!
//! A `.pvd` collection lists the files of a time series:
//!
//! ```xml
//! <?xml version="1.0"?>
//! <VTKFile type="Collection" version="0.1" byte_order="LittleEndian">
//!   <Collection>
//!     <DataSet timestep="0.0" group="" part="0" file="run_0000.vtu"/>
//!     <DataSet timestep="0.5" group="" part="0" file="run_0001.vtu"/>
//!   </Collection>
//! </VTKFile>
//! ```
//!
//! File names are relative to the `.pvd` file's directory.
//!
//! ## Viewing results in ParaView
//!
//! 1. *File → Open* the `.pvd` (a time series) or a single `.vtu`, then press *Apply*.
//! 2. Colour by a point or cell array in the toolbar; choose `body` to tell the bodies apart
//!    (all pieces of a file are loaded as one unstructured grid). To show one body only, apply
//!    the *Threshold* filter on `body`.
//! 3. To see the deformed configuration, apply *Warp By Vector* with the displacement field
//!    (scale factor 1 for the true deformation).
//! 4. For a time series, use the time controls (▶, or the *Time* field) to step through the
//!    `timestep` values; *File → Save Animation* exports a movie.
//! 5. 2D results lie in the plane `z = 0`: switch the view to *2D* interaction mode.
//!
//! ## Example
//!
//! ```no_run
//! use synovia_io::{Encoding, Field, TimeSeriesWriter};
//! use synovia_mesh::{Mesh, Point, Vector};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let nodes = vec![Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.0), Point::<2>::new(0.0, 1.0)];
//! let mesh = Mesh::<2>::new(nodes, vec![0, 1, 2])?;
//! let mut series = TimeSeriesWriter::new("results", "knee", Encoding::Base64)?;
//! for step in 0..3 {
//!     let t = 0.1 * step as f64;
//!     let u: Vec<Vector<2>> = mesh.nodes().iter().map(|x| x * t).collect();
//!     let fields = vec![
//!         Field::point_vectors("displacement", &u),
//!         Field::cell_scalars("pressure", vec![t]),
//!     ];
//!     series.write_mesh(t, &mesh, fields)?; // results/knee_000N.vtu + results/knee.pvd
//! }
//! # Ok(())
//! # }
//! ```
#![warn(missing_docs)]

pub mod duplicates;
pub mod error;
pub mod field;
pub mod gmsh;
pub mod pvd;
pub mod read;
pub mod stl;
mod util;
pub mod vtu;

pub use duplicates::{coincident_nodes, CoincidentNodes, COINCIDENT_TOLERANCE};
pub use error::IoError;
pub use field::{Field, FieldLocation};
pub use gmsh::{
    default_boundary_kind, parse_msh, read_msh, read_msh_bodies, ElementBlock, GmshMesh, MshVersion,
    PhysicalGroup, PhysicalName,
};
pub use pvd::{read_pvd, PvdEntry, PvdWriter, TimeSeriesWriter};
pub use read::{parse_vtu, read_vtu, VtuData, VtuPiece};
pub use stl::{parse_stl, read_stl, write_stl};
pub use vtu::{write_vtu, Encoding, VtuWriter, BODY_FIELD, VTK_TETRA, VTK_TRIANGLE};
