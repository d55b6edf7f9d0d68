//! Writing VTK XML `UnstructuredGrid` (`.vtu`) files.

use std::io::{self, Write};
use std::path::Path;

use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;
use synovia_mesh::{Mesh, MeshError};

use crate::error::IoError;
use crate::field::{Field, FieldLocation};
use crate::util::{escape_attr, write_file_atomic};

/// VTK cell type of a linear triangle.
pub const VTK_TRIANGLE: u8 = 5;
/// VTK cell type of a linear tetrahedron.
pub const VTK_TETRA: u8 = 10;
/// Name of the cell field holding the piece (body) index, written automatically.
pub const BODY_FIELD: &str = "body";

/// How the `<DataArray>` contents are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Encoding {
    /// `format="ascii"`: human-readable numbers; `f64` values are written with Rust's
    /// shortest round-trip formatting (`{:e}`), so they read back bit-exactly.
    Ascii,
    /// `format="binary"`: the raw little-endian bytes, base64-encoded inline, preceded (inside
    /// the same base64 stream) by a `UInt32` byte count. Exact and about 3× smaller than ASCII;
    /// arrays are limited to 4 GiB.
    Base64,
    /// `format="binary"` with `compressor="vtkZLibDataCompressor"` (the default): each array's
    /// little-endian bytes cut into blocks of [`ZLIB_BLOCK_BYTES`], each block compressed with
    /// zlib (level 1, the fastest); inline, as the base64 of the `UInt64` block header `[blocks, block size, size of
    /// the last partial block (0: full), compressed size of each block]` followed by the base64
    /// of the compressed blocks (VTK's layout, read by ParaView, VTK and meshio). Exact.
    #[default]
    Zlib,
}

/// Uncompressed size of the blocks of an [`Encoding::Zlib`] array (VTK's default, 32 KiB).
pub const ZLIB_BLOCK_BYTES: usize = 1 << 15;

impl Encoding {
    fn format_attr(self) -> &'static str {
        match self {
            Encoding::Ascii => "ascii",
            Encoding::Base64 | Encoding::Zlib => "binary",
        }
    }
}

/// One `<Piece>`: a body's mesh, its fields (already validated and padded).
#[derive(Debug, Clone)]
struct Piece {
    /// Flat `x y z` coordinates.
    points: Vec<f64>,
    connectivity: Vec<i64>,
    nodes_per_cell: usize,
    cell_type: u8,
    point_data: Vec<Field>,
    cell_data: Vec<Field>,
}

impl Piece {
    fn n_points(&self) -> usize {
        self.points.len() / 3
    }
    fn n_cells(&self) -> usize {
        self.connectivity.len().checked_div(self.nodes_per_cell).unwrap_or(0)
    }
}

/// Writer of one `.vtu` file holding every body in a single `<Piece>`.
///
/// Bodies are added one by one ([`VtuWriter::add_piece`]) and written as one unstructured grid:
/// their points one after the other, their cells with the node indices shifted accordingly.
/// The cell field and the point field [`BODY_FIELD`] (`"body"`, the index of the body in the
/// order of addition, written automatically) tell the bodies apart for colouring or
/// thresholding in ParaView, and [`crate::read_vtu`] splits the grid back into bodies by them.
///
/// One piece rather than one piece per body because not every reader takes several pieces:
/// meshio (5.3) keeps only the last piece of a file (its issue #1444), while a single piece is
/// read whole by ParaView, VTK, meshio and PyVista alike. Every body must therefore be given
/// fields with the same names, locations and component counts as the first one (in any order).
#[derive(Debug, Clone, Default)]
pub struct VtuWriter {
    encoding: Encoding,
    pieces: Vec<Piece>,
}

impl VtuWriter {
    /// An empty writer using `encoding` for every data array.
    pub fn new(encoding: Encoding) -> Self {
        Self { encoding, pieces: Vec::new() }
    }

    /// The encoding of the data arrays.
    pub fn encoding(&self) -> Encoding {
        self.encoding
    }

    /// Number of pieces added so far.
    pub fn n_pieces(&self) -> usize {
        self.pieces.len()
    }

    /// Adds `mesh` with its `fields` as the next piece (body index = number of earlier pieces).
    ///
    /// Points are written with 3 coordinates (`z = 0` in 2D), cells as [`VTK_TRIANGLE`] (2D) or
    /// [`VTK_TETRA`] (3D). Each field is checked: non-empty name without control characters,
    /// unique per location, not the reserved name `"body"`, at least one component,
    /// `components × n_nodes` (point) or `components × n_cells` (cell) values, all finite.
    /// 2-component fields are padded to 3 components with zeros.
    ///
    /// # Errors
    /// [`IoError::InvalidField`], [`IoError::FieldLength`], [`IoError::NonFinite`],
    /// [`IoError::InconsistentPieces`] (fields differ from the first piece's), and
    /// [`IoError::ArrayTooLarge`] for [`Encoding::Base64`] arrays (over all bodies) above
    /// 4 GiB. The writer is unchanged on error.
    pub fn add_piece<const D: usize>(
        &mut self,
        mesh: &Mesh<D>,
        fields: Vec<Field>,
    ) -> Result<&mut Self, IoError> {
        let cell_type = match D {
            2 => VTK_TRIANGLE,
            3 => VTK_TETRA,
            _ => return Err(MeshError::UnsupportedDimension(D).into()),
        };
        let (n_nodes, n_cells) = (mesh.n_nodes(), mesh.n_cells());
        let mut point_data = Vec::new();
        let mut cell_data = Vec::new();
        for field in fields {
            let (n, list) = match field.location {
                FieldLocation::Point => (n_nodes, &mut point_data),
                FieldLocation::Cell => (n_cells, &mut cell_data),
            };
            validate_field(&field, n, list)?;
            list.push(field.padded());
        }
        if let Some(first) = self.pieces.first() {
            let piece = self.pieces.len();
            point_data = match_fields(piece, &first.point_data, point_data)?;
            cell_data = match_fields(piece, &first.cell_data, cell_data)?;
        }
        let mut points = Vec::with_capacity(3 * n_nodes);
        for p in mesh.nodes() {
            for k in 0..3 {
                points.push(if k < D { p[k] } else { 0.0 });
            }
        }
        let mut connectivity = Vec::with_capacity((D + 1) * n_cells);
        for &i in mesh.cells_flat() {
            connectivity.push(i64::try_from(i).map_err(|_| IoError::InvalidField {
                name: "connectivity".into(),
                reason: format!("node index {i} does not fit in Int64"),
            })?);
        }
        let piece = Piece { points, connectivity, nodes_per_cell: D + 1, cell_type, point_data, cell_data };
        if self.encoding == Encoding::Base64 {
            check_sizes(self.pieces.iter().chain(std::iter::once(&piece)))?;
        }
        self.pieces.push(piece);
        Ok(self)
    }

    /// Writes the file to `path` (atomically: to `path.tmp`, then renamed, so readers never
    /// see a half-written file).
    ///
    /// # Errors
    /// [`IoError::Io`] when the file cannot be created, written or renamed.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), IoError> {
        write_file_atomic(path.as_ref(), |w| self.write_to(w))
    }

    /// Writes the XML document to any byte sink (wrap files in a `BufWriter`).
    ///
    /// # Errors
    /// Whatever the sink returns.
    pub fn write_to<W: Write>(&self, mut w: W) -> io::Result<()> {
        let (header_type, compressor) = match self.encoding {
            Encoding::Zlib => ("UInt64", r#" compressor="vtkZLibDataCompressor""#),
            Encoding::Ascii | Encoding::Base64 => ("UInt32", ""),
        };
        writeln!(w, r#"<?xml version="1.0"?>"#)?;
        writeln!(
            w,
            r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="{header_type}"{compressor}>"#
        )?;
        writeln!(w, "  <UnstructuredGrid>")?;
        self.write_grid(&mut w)?;
        writeln!(w, "  </UnstructuredGrid>")?;
        writeln!(w, "</VTKFile>")?;
        w.flush()
    }

    /// The XML document as a string.
    pub fn to_xml_string(&self) -> String {
        let mut buf = Vec::new();
        // Writing into a Vec cannot fail; the output is UTF-8 by construction.
        let _ = self.write_to(&mut buf);
        String::from_utf8_lossy(&buf).into_owned()
    }

    /// The single `<Piece>`: every body's points, cells and fields one after the other.
    fn write_grid<W: Write>(&self, w: &mut W) -> io::Result<()> {
        let n_points: usize = self.pieces.iter().map(Piece::n_points).sum();
        let n_cells: usize = self.pieces.iter().map(Piece::n_cells).sum();
        let body_of = |n: fn(&Piece) -> usize| -> Vec<i32> {
            let mut v = Vec::with_capacity(self.pieces.iter().map(n).sum());
            for (body, piece) in self.pieces.iter().enumerate() {
                v.extend(std::iter::repeat_n(i32::try_from(body).unwrap_or(i32::MAX), n(piece)));
            }
            v
        };
        writeln!(w, r#"    <Piece NumberOfPoints="{n_points}" NumberOfCells="{n_cells}">"#)?;
        self.write_data(w, "PointData", |p| &p.point_data, &body_of(Piece::n_points))?;
        self.write_data(w, "CellData", |p| &p.cell_data, &body_of(Piece::n_cells))?;
        writeln!(w, "      <Points>")?;
        let points: Vec<&[f64]> = self.pieces.iter().map(|p| p.points.as_slice()).collect();
        self.write_array(w, "Points", 3, &points)?;
        writeln!(w, "      </Points>")?;
        writeln!(w, "      <Cells>")?;
        let (mut connectivity, mut offsets, mut types) =
            (Vec::new(), Vec::with_capacity(n_cells), Vec::with_capacity(n_cells));
        let (mut first_point, mut end) = (0_i64, 0_i64);
        for piece in &self.pieces {
            connectivity.extend(piece.connectivity.iter().map(|&i| i + first_point));
            for _ in 0..piece.n_cells() {
                end += i64::try_from(piece.nodes_per_cell).unwrap_or(i64::MAX);
                offsets.push(end);
            }
            types.extend(std::iter::repeat_n(piece.cell_type, piece.n_cells()));
            first_point += i64::try_from(piece.n_points()).unwrap_or(i64::MAX);
        }
        self.write_array(w, "connectivity", 1, &[&connectivity])?;
        self.write_array(w, "offsets", 1, &[&offsets])?;
        self.write_array(w, "types", 1, &[&types])?;
        writeln!(w, "      </Cells>")?;
        writeln!(w, "    </Piece>")
    }

    /// A `<PointData>` / `<CellData>` section: each field of the bodies (`fields_of`) over all
    /// of them, then the `body` array.
    fn write_data<W: Write>(
        &self,
        w: &mut W,
        section: &str,
        fields_of: fn(&Piece) -> &Vec<Field>,
        body: &[i32],
    ) -> io::Result<()> {
        writeln!(w, "      <{section}>")?;
        if let Some(first) = self.pieces.first() {
            for (j, f) in fields_of(first).iter().enumerate() {
                let parts: Vec<&[f64]> =
                    self.pieces.iter().map(|p| fields_of(p)[j].values.as_slice()).collect();
                self.write_array(w, &f.name, f.components, &parts)?;
            }
        }
        self.write_array(w, BODY_FIELD, 1, &[body])?;
        writeln!(w, "      </{section}>")
    }

    /// One `<DataArray>` holding the values of `parts` one after the other.
    fn write_array<W: Write, T: Scalar>(
        &self,
        w: &mut W,
        name: &str,
        components: usize,
        parts: &[&[T]],
    ) -> io::Result<()> {
        write!(w, r#"        <DataArray type="{}" Name="{}""#, T::TYPE, escape_attr(name))?;
        if components != 1 {
            write!(w, r#" NumberOfComponents="{components}""#)?;
        }
        writeln!(w, r#" format="{}">"#, self.encoding.format_attr())?;
        let values = || parts.iter().flat_map(|p| p.iter().copied());
        match self.encoding {
            Encoding::Ascii => {
                let per_line = if components > 1 { components } else { 12 };
                for (i, v) in values().enumerate() {
                    if i % per_line == 0 {
                        if i > 0 {
                            writeln!(w)?;
                        }
                        write!(w, "         ")?;
                    }
                    write!(w, " ")?;
                    v.write_ascii(w)?;
                }
                if parts.iter().any(|p| !p.is_empty()) {
                    writeln!(w)?;
                }
            }
            Encoding::Base64 => {
                write!(w, "          ")?;
                let bytes = parts.iter().map(|p| p.len()).sum::<usize>() * T::SIZE;
                let header = u32::try_from(bytes)
                    .map_err(|_| io::Error::other("array larger than a UInt32 header allows"))?;
                {
                    let mut enc = EncoderWriter::new(&mut *w, &STANDARD);
                    enc.write_all(&header.to_le_bytes())?;
                    let mut buf = Vec::with_capacity(4096 * T::SIZE);
                    for part in parts {
                        for chunk in part.chunks(4096) {
                            buf.clear();
                            for v in chunk {
                                v.push_le(&mut buf);
                            }
                            enc.write_all(&buf)?;
                        }
                    }
                    enc.finish()?;
                }
                writeln!(w)?;
            }
            Encoding::Zlib => {
                write!(w, "          ")?;
                let mut raw = Vec::with_capacity(parts.iter().map(|p| p.len()).sum::<usize>() * T::SIZE);
                for v in values() {
                    v.push_le(&mut raw);
                }
                let (header, data) = zlib_blocks(&raw)?;
                // header and blocks are two base64 streams, as VTK writes and reads them
                for bytes in [header, data] {
                    let mut enc = EncoderWriter::new(&mut *w, &STANDARD);
                    enc.write_all(&bytes)?;
                    enc.finish()?;
                }
                writeln!(w)?;
            }
        }
        writeln!(w, "        </DataArray>")
    }
}

/// VTK's compressed layout of `raw` ([`Encoding::Zlib`]): the little-endian `UInt64` header
/// `[blocks, block size, last partial block size (0: full), compressed sizes…]` and the
/// compressed blocks one after the other.
fn zlib_blocks(raw: &[u8]) -> io::Result<(Vec<u8>, Vec<u8>)> {
    use flate2::write::ZlibEncoder;
    use flate2::Compression;
    let to_u64 = |n: usize| u64::try_from(n).map_err(|_| io::Error::other("size beyond UInt64"));
    let blocks = raw.chunks(ZLIB_BLOCK_BYTES);
    let mut header = Vec::with_capacity(8 * (3 + blocks.len()));
    header.extend_from_slice(&to_u64(blocks.len())?.to_le_bytes());
    header.extend_from_slice(&to_u64(ZLIB_BLOCK_BYTES)?.to_le_bytes());
    header.extend_from_slice(&to_u64(raw.len() % ZLIB_BLOCK_BYTES)?.to_le_bytes());
    let mut data = Vec::new();
    for block in blocks {
        let start = data.len();
        // level 1: on knee2d's fields 1 % larger than the default level 6 and 2.7× faster
        // (docs/output.md)
        let mut enc = ZlibEncoder::new(std::mem::take(&mut data), Compression::fast());
        enc.write_all(block)?;
        data = enc.finish()?;
        header.extend_from_slice(&to_u64(data.len() - start)?.to_le_bytes());
    }
    Ok((header, data))
}

/// Writes one body's mesh and fields to a `.vtu` file (zlib-compressed, the default
/// [`Encoding`]; see [`VtuWriter`]).
///
/// # Errors
/// As [`VtuWriter::add_piece`] and [`VtuWriter::write`].
pub fn write_vtu<const D: usize>(
    path: impl AsRef<Path>,
    mesh: &Mesh<D>,
    fields: &[Field],
) -> Result<(), IoError> {
    let mut writer = VtuWriter::new(Encoding::default());
    writer.add_piece(mesh, fields.to_vec())?;
    writer.write(path)
}

fn validate_field(field: &Field, n_entities: usize, earlier: &[Field]) -> Result<(), IoError> {
    let invalid =
        |reason: &str| IoError::InvalidField { name: field.name.clone(), reason: reason.to_string() };
    if field.name.is_empty() {
        return Err(invalid("the name is empty"));
    }
    if field.name.chars().any(char::is_control) {
        return Err(invalid("the name contains control characters"));
    }
    if field.name == BODY_FIELD {
        return Err(invalid(
            "`body` is reserved: the writer adds the body index as point and cell field `body`",
        ));
    }
    if earlier.iter().any(|f| f.name == field.name) {
        return Err(invalid("another field at the same location has this name"));
    }
    if field.components == 0 {
        return Err(invalid("a field needs at least one component"));
    }
    let expected = field.components.saturating_mul(n_entities);
    if field.values.len() != expected {
        return Err(IoError::FieldLength { name: field.name.clone(), expected, got: field.values.len() });
    }
    if let Some(index) = field.values.iter().position(|v| !v.is_finite()) {
        return Err(IoError::NonFinite { name: field.name.clone(), index });
    }
    Ok(())
}

/// Orders `fields` like `reference` (the first piece's), failing when the sets differ.
fn match_fields(piece: usize, reference: &[Field], mut fields: Vec<Field>) -> Result<Vec<Field>, IoError> {
    let mismatch = |reason: String| IoError::InconsistentPieces { piece, reason };
    let mut ordered = Vec::with_capacity(reference.len());
    for r in reference {
        let i = fields
            .iter()
            .position(|f| f.name == r.name)
            .ok_or_else(|| mismatch(format!("missing {:?} field `{}`", r.location, r.name)))?;
        let f = fields.swap_remove(i);
        if f.components != r.components {
            return Err(mismatch(format!(
                "field `{}` has {} components instead of {}",
                f.name, f.components, r.components
            )));
        }
        ordered.push(f);
    }
    if let Some(extra) = fields.first() {
        return Err(mismatch(format!("{:?} field `{}` is not in piece 0", extra.location, extra.name)));
    }
    Ok(ordered)
}

/// The [`Encoding::Base64`] limit (a `UInt32` byte count) on the arrays of the grid made of
/// `pieces`.
fn check_sizes<'a>(pieces: impl Iterator<Item = &'a Piece> + Clone) -> Result<(), IoError> {
    let check = |name: &str, count: usize, size: usize| {
        let bytes = count.saturating_mul(size);
        if u32::try_from(bytes).is_err() {
            Err(IoError::ArrayTooLarge { name: name.to_string(), bytes })
        } else {
            Ok(())
        }
    };
    let total = |f: fn(&Piece) -> usize| pieces.clone().map(f).fold(0_usize, usize::saturating_add);
    check("Points", total(|p| p.points.len()), 8)?;
    check("connectivity", total(|p| p.connectivity.len()), 8)?;
    check("offsets", total(Piece::n_cells), 8)?;
    check(BODY_FIELD, total(Piece::n_cells).max(total(Piece::n_points)), 4)?;
    if let Some(first) = pieces.clone().next() {
        for (j, f) in first.point_data.iter().enumerate() {
            check(&f.name, pieces.clone().map(|p| p.point_data[j].values.len()).sum(), 8)?;
        }
        for (j, f) in first.cell_data.iter().enumerate() {
            check(&f.name, pieces.clone().map(|p| p.cell_data[j].values.len()).sum(), 8)?;
        }
    }
    Ok(())
}

/// A number type written into a `<DataArray>`.
trait Scalar: Copy {
    /// VTK type name.
    const TYPE: &'static str;
    /// Size in bytes.
    const SIZE: usize;
    fn push_le(self, buf: &mut Vec<u8>);
    fn write_ascii<W: Write>(self, w: &mut W) -> io::Result<()>;
}

impl Scalar for f64 {
    const TYPE: &'static str = "Float64";
    const SIZE: usize = 8;
    fn push_le(self, buf: &mut Vec<u8>) {
        buf.extend_from_slice(&self.to_le_bytes());
    }
    fn write_ascii<W: Write>(self, w: &mut W) -> io::Result<()> {
        write!(w, "{self:e}")
    }
}

macro_rules! int_scalar {
    ($t:ty, $name:literal) => {
        impl Scalar for $t {
            const TYPE: &'static str = $name;
            const SIZE: usize = std::mem::size_of::<$t>();
            fn push_le(self, buf: &mut Vec<u8>) {
                buf.extend_from_slice(&self.to_le_bytes());
            }
            fn write_ascii<W: Write>(self, w: &mut W) -> io::Result<()> {
                write!(w, "{self}")
            }
        }
    };
}
int_scalar!(i64, "Int64");
int_scalar!(i32, "Int32");
int_scalar!(u8, "UInt8");
