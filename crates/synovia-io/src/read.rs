//! Reading back the `.vtu` files this crate writes (round-trip tests, verification).

use std::collections::HashMap;
use std::path::Path;

use base64::engine::general_purpose::STANDARD;
use base64::Engine;
use quick_xml::events::Event;
use quick_xml::Reader;
use synovia_mesh::{Mesh, Point};

use crate::error::IoError;
use crate::field::{Field, FieldLocation};
use crate::util::{attributes, element_name};
use crate::vtu::{BODY_FIELD, VTK_TETRA, VTK_TRIANGLE};

/// The contents of a `.vtu` file: its bodies in file order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VtuData {
    /// One entry per body. A `<Piece>` carrying the point and cell fields `"body"` (as
    /// [`crate::VtuWriter`] writes every file: all bodies in one piece) is split back into its
    /// bodies, each with its own points (renumbered from 0), cells and field values; the point
    /// field `"body"` is dropped, the cell field kept. Any other piece is one entry as it is.
    pub pieces: Vec<VtuPiece>,
}

/// One `<Piece>` of a `.vtu` file, with the arrays as stored (cells in VTK's flat form).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VtuPiece {
    /// Point coordinates (always 3; `z = 0` for 2D meshes).
    pub points: Vec<[f64; 3]>,
    /// Flat cell-node list.
    pub connectivity: Vec<usize>,
    /// End (exclusive) of each cell in `connectivity`.
    pub offsets: Vec<usize>,
    /// VTK cell type of each cell ([`VTK_TRIANGLE`], [`VTK_TETRA`], ...).
    pub types: Vec<u8>,
    /// `<PointData>` arrays in file order (location [`FieldLocation::Point`]).
    pub point_data: Vec<Field>,
    /// `<CellData>` arrays in file order, including the `"body"` field the writer adds.
    pub cell_data: Vec<Field>,
}

impl VtuPiece {
    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.types.len()
    }

    /// Node indices of cell `c`, or `None` when out of range.
    pub fn cell(&self, c: usize) -> Option<&[usize]> {
        let start = match c {
            0 => 0,
            _ => *self.offsets.get(c - 1)?,
        };
        let end = *self.offsets.get(c)?;
        self.connectivity.get(start..end)
    }

    /// The point field called `name`.
    pub fn point_field(&self, name: &str) -> Option<&Field> {
        self.point_data.iter().find(|f| f.name == name)
    }

    /// The cell field called `name`.
    pub fn cell_field(&self, name: &str) -> Option<&Field> {
        self.cell_data.iter().find(|f| f.name == name)
    }

    /// Rebuilds a [`Mesh`] from the piece: every cell must be a triangle (`D = 2`; the `z`
    /// coordinate is dropped) or a tetrahedron (`D = 3`); the mesh is validated like
    /// [`Mesh::new`].
    ///
    /// # Errors
    /// [`IoError::CellType`] for a cell of another type, [`IoError::Mesh`] when the mesh is
    /// invalid (e.g. an inverted cell, or `D` not 2 or 3).
    pub fn to_mesh<const D: usize>(&self) -> Result<Mesh<D>, IoError> {
        let expected = if D == 2 { VTK_TRIANGLE } else { VTK_TETRA };
        if let Some((cell, &found)) = self.types.iter().enumerate().find(|(_, &t)| t != expected) {
            return Err(IoError::CellType { cell, expected, found });
        }
        let nodes = self
            .points
            .iter()
            .map(|p| Point::<D>::from_fn(|k, _| p.get(k).copied().unwrap_or(0.0)))
            .collect();
        Ok(Mesh::new(nodes, self.connectivity.clone())?)
    }
}

/// Reads a `.vtu` file written by [`crate::VtuWriter`] (ASCII, inline base64 binary or
/// inline zlib-compressed binary, either byte order, `UInt32` or `UInt64` headers, no appended
/// data), split into bodies ([`VtuData::pieces`]).
///
/// # Errors
/// [`IoError::Io`] when the file cannot be read; [`IoError::Parse`] (with a message and, for
/// XML errors, the byte position) for anything malformed: bad XML, truncation, missing or
/// inconsistent arrays, undecodable numbers or base64, out-of-range connectivity.
pub fn read_vtu(path: impl AsRef<Path>) -> Result<VtuData, IoError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| IoError::io(path, e))?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| IoError::parse(path, format!("the file is not UTF-8: {e}")))?;
    parse_vtu_document(text).map_err(|m| IoError::parse(path, m))
}

/// Parses a `.vtu` document held in memory (as [`read_vtu`]; errors name the path `<string>`).
///
/// # Errors
/// [`IoError::Parse`] for malformed input.
pub fn parse_vtu(xml: &str) -> Result<VtuData, IoError> {
    parse_vtu_document(xml).map_err(|m| IoError::parse("<string>", m))
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Section {
    PointData,
    CellData,
    Points,
    Cells,
    Ignored,
}

#[derive(Debug)]
struct RawArray {
    section: Section,
    attrs: HashMap<String, String>,
    text: String,
    position: u64,
}

impl RawArray {
    fn name(&self) -> &str {
        self.attrs.get("Name").map_or("<unnamed>", String::as_str)
    }
}

#[derive(Debug, Default)]
struct PieceBuilder {
    n_points: usize,
    n_cells: usize,
    arrays: Vec<RawArray>,
}

#[derive(Debug, Clone, Copy)]
struct Header {
    big_endian: bool,
    header_bytes: usize,
    /// `compressor="vtkZLibDataCompressor"`: binary arrays are zlib blocks.
    zlib: bool,
}

struct Parser {
    stack: Vec<String>,
    header: Header,
    pieces: Vec<VtuPiece>,
    piece: Option<PieceBuilder>,
    array: Option<RawArray>,
}

fn parse_vtu_document(xml: &str) -> Result<VtuData, String> {
    let mut reader = Reader::from_str(xml);
    let mut p = Parser {
        stack: Vec::new(),
        header: Header { big_endian: false, header_bytes: 4, zlib: false },
        pieces: Vec::new(),
        piece: None,
        array: None,
    };
    loop {
        let position = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| format!("malformed XML at byte {}: {e}", reader.error_position()))?;
        match event {
            Event::Start(e) => {
                let attrs = attributes(&e).map_err(|m| format!("{m} at byte {position}"))?;
                let name = element_name(&e);
                p.open(&name, attrs, position)?;
                p.stack.push(name);
            }
            Event::Empty(e) => {
                let attrs = attributes(&e).map_err(|m| format!("{m} at byte {position}"))?;
                let name = element_name(&e);
                p.open(&name, attrs, position)?;
                p.close(&name)?;
                if p.stack.is_empty() {
                    break;
                }
            }
            Event::End(e) => {
                let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
                p.stack.pop();
                p.close(&name)?;
                if p.stack.is_empty() {
                    break;
                }
            }
            Event::Text(t) => {
                if let Some(a) = &mut p.array {
                    let text = t.decode().map_err(|e| format!("bad text at byte {position}: {e}"))?;
                    a.text.push_str(&text);
                }
            }
            Event::CData(t) => {
                if let Some(a) = &mut p.array {
                    let text = t.decode().map_err(|e| format!("bad CDATA at byte {position}: {e}"))?;
                    a.text.push_str(&text);
                }
            }
            Event::GeneralRef(_) if p.array.is_some() => {
                return Err(format!("unexpected entity reference inside a DataArray at byte {position}"));
            }
            Event::Eof => {
                return Err(match p.stack.last() {
                    Some(open) => {
                        format!("unexpected end of file inside <{open}> (truncated file?)")
                    }
                    None => "no <VTKFile> element".to_string(),
                });
            }
            _ => {}
        }
    }
    let mut pieces = Vec::with_capacity(p.pieces.len());
    for (index, piece) in p.pieces.into_iter().enumerate() {
        pieces.extend(split_bodies(piece).map_err(|m| format!("piece {index}: {m}"))?);
    }
    Ok(VtuData { pieces })
}

/// The bodies of a piece with point and cell fields [`BODY_FIELD`] (else the piece itself).
fn split_bodies(mut piece: VtuPiece) -> Result<Vec<VtuPiece>, String> {
    let (Some(pi), Some(ci)) = (
        piece.point_data.iter().position(|f| f.name == BODY_FIELD && f.components == 1),
        piece.cell_data.iter().position(|f| f.name == BODY_FIELD && f.components == 1),
    ) else {
        return Ok(vec![piece]);
    };
    let ids = |f: &Field, what: &str| -> Result<Vec<usize>, String> {
        f.values
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                // body indices are small non-negative integers stored exactly
                if v >= 0.0 && v.fract() == 0.0 && v < 1e9 {
                    Ok(v as usize)
                } else {
                    Err(format!("{what} {i} has body index {v}, not a non-negative integer"))
                }
            })
            .collect()
    };
    let point_body = ids(&piece.point_data.remove(pi), "point")?;
    let cell_body = ids(&piece.cell_data[ci], "cell")?;
    let n_bodies = point_body.iter().chain(&cell_body).map(|&b| b + 1).max().unwrap_or(0);
    // every body has a point, so the count is bounded by the file's size
    if n_bodies > point_body.len() {
        return Err(format!("body index {} with only {} points", n_bodies - 1, point_body.len()));
    }
    let mut local = vec![0_usize; point_body.len()];
    let mut counts = vec![0_usize; n_bodies];
    for (p, &b) in point_body.iter().enumerate() {
        local[p] = counts[b];
        counts[b] += 1;
    }
    let mut bodies: Vec<VtuPiece> = (0..n_bodies)
        .map(|_| VtuPiece {
            point_data: piece
                .point_data
                .iter()
                .map(|f| Field::new(f.name.clone(), f.location, f.components, Vec::new()))
                .collect(),
            cell_data: piece
                .cell_data
                .iter()
                .map(|f| Field::new(f.name.clone(), f.location, f.components, Vec::new()))
                .collect(),
            ..VtuPiece::default()
        })
        .collect();
    for (p, &b) in point_body.iter().enumerate() {
        let body = &mut bodies[b];
        body.points.push(piece.points[p]);
        for (out, f) in body.point_data.iter_mut().zip(&piece.point_data) {
            out.values.extend_from_slice(&f.values[p * f.components..(p + 1) * f.components]);
        }
    }
    for (c, &b) in cell_body.iter().enumerate() {
        let nodes = piece.cell(c).ok_or_else(|| format!("cell {c} is out of range"))?;
        let body = &mut bodies[b];
        for &n in nodes {
            if point_body[n] != b {
                return Err(format!("cell {c} of body {b} uses point {n} of body {}", point_body[n]));
            }
            body.connectivity.push(local[n]);
        }
        body.offsets.push(body.connectivity.len());
        body.types.push(piece.types[c]);
        for (out, f) in body.cell_data.iter_mut().zip(&piece.cell_data) {
            out.values.extend_from_slice(&f.values[c * f.components..(c + 1) * f.components]);
        }
    }
    Ok(bodies)
}

impl Parser {
    fn open(&mut self, name: &str, attrs: HashMap<String, String>, position: u64) -> Result<(), String> {
        let parent = self.stack.last().map(String::as_str);
        let expect_parent = |want: &str| {
            if parent == Some(want) {
                Ok(())
            } else {
                Err(format!("<{name}> at byte {position} is not inside <{want}>"))
            }
        };
        match (parent, name) {
            (None, "VTKFile") => {
                let ty = attrs.get("type").map(String::as_str);
                if ty != Some("UnstructuredGrid") {
                    return Err(format!(
                        "VTKFile type is {ty:?}, expected \"UnstructuredGrid\" (a .vtu file)"
                    ));
                }
                self.header.zlib = match attrs.get("compressor").map(String::as_str) {
                    None => false,
                    Some("vtkZLibDataCompressor") => true,
                    Some(other) => {
                        return Err(format!(
                            "compressor {other:?} is not supported (only vtkZLibDataCompressor)"
                        ))
                    }
                };
                self.header.big_endian = match attrs.get("byte_order").map(String::as_str) {
                    None | Some("LittleEndian") => false,
                    Some("BigEndian") => true,
                    Some(other) => return Err(format!("unknown byte_order {other:?}")),
                };
                self.header.header_bytes = match attrs.get("header_type").map(String::as_str) {
                    None | Some("UInt32") => 4,
                    Some("UInt64") => 8,
                    Some(other) => return Err(format!("unknown header_type {other:?}")),
                };
            }
            (None, other) => {
                return Err(format!("root element is <{other}>, expected <VTKFile>"));
            }
            (_, "UnstructuredGrid") => expect_parent("VTKFile")?,
            (_, "Piece") => {
                expect_parent("UnstructuredGrid")?;
                let count = |key: &str| -> Result<usize, String> {
                    let v =
                        attrs.get(key).ok_or_else(|| format!("<Piece> at byte {position} lacks {key}"))?;
                    v.trim().parse().map_err(|_| format!("<Piece> at byte {position}: bad {key}=\"{v}\""))
                };
                self.piece = Some(PieceBuilder {
                    n_points: count("NumberOfPoints")?,
                    n_cells: count("NumberOfCells")?,
                    arrays: Vec::new(),
                });
            }
            (_, "PointData" | "CellData" | "Points" | "Cells") => expect_parent("Piece")?,
            (_, "AppendedData") => {
                return Err("appended data is not supported (only inline ascii/binary)".into())
            }
            (_, "DataArray") => {
                if self.array.is_some() {
                    return Err(format!("nested <DataArray> at byte {position}"));
                }
                let section = match parent {
                    Some("PointData") => Section::PointData,
                    Some("CellData") => Section::CellData,
                    Some("Points") => Section::Points,
                    Some("Cells") => Section::Cells,
                    _ => Section::Ignored,
                };
                self.array = Some(RawArray { section, attrs, text: String::new(), position });
            }
            _ => {}
        }
        Ok(())
    }

    fn close(&mut self, name: &str) -> Result<(), String> {
        match name {
            "DataArray" => {
                if let Some(array) = self.array.take() {
                    if array.section != Section::Ignored {
                        if let Some(piece) = &mut self.piece {
                            piece.arrays.push(array);
                        }
                    }
                }
            }
            "Piece" => {
                if let Some(builder) = self.piece.take() {
                    let index = self.pieces.len();
                    let piece =
                        finish_piece(builder, self.header).map_err(|m| format!("piece {index}: {m}"))?;
                    self.pieces.push(piece);
                }
            }
            _ => {}
        }
        Ok(())
    }
}

fn finish_piece(b: PieceBuilder, header: Header) -> Result<VtuPiece, String> {
    let (np, nc) = (b.n_points, b.n_cells);
    let mut piece = VtuPiece::default();
    let mut points = None;
    let (mut connectivity, mut offsets, mut types) = (None, None, None);
    for a in &b.arrays {
        let components = components_of(a)?;
        let values =
            decode(a, header).map_err(|m| format!("DataArray `{}` at byte {}: {m}", a.name(), a.position))?;
        let count_err = |want: usize| {
            format!(
                "DataArray `{}` at byte {} has {} values, expected {want}",
                a.name(),
                a.position,
                values.len()
            )
        };
        match a.section {
            Section::Points => {
                if components != 3 || values.len() != 3 * np {
                    return Err(count_err(3 * np));
                }
                let v = values.to_f64();
                points = Some(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
            }
            Section::Cells => {
                let idx = values.to_indices().map_err(|m| format!("DataArray `{}`: {m}", a.name()))?;
                match a.name() {
                    "connectivity" => connectivity = Some(idx),
                    "offsets" if idx.len() == nc => offsets = Some(idx),
                    "types" if idx.len() == nc => {
                        let t: Result<Vec<u8>, _> = idx.iter().map(|&t| u8::try_from(t)).collect();
                        types = Some(t.map_err(|_| "cell type out of range 0..=255".to_string())?);
                    }
                    "offsets" | "types" => return Err(count_err(nc)),
                    _ => {}
                }
            }
            Section::PointData | Section::CellData => {
                let (n, location) = if a.section == Section::PointData {
                    (np, FieldLocation::Point)
                } else {
                    (nc, FieldLocation::Cell)
                };
                let Some(name) = a.attrs.get("Name") else {
                    return Err(format!("DataArray at byte {} has no Name", a.position));
                };
                if values.len() != components.saturating_mul(n) {
                    return Err(count_err(components.saturating_mul(n)));
                }
                let field = Field::new(name.clone(), location, components, values.to_f64());
                match location {
                    FieldLocation::Point => piece.point_data.push(field),
                    FieldLocation::Cell => piece.cell_data.push(field),
                }
            }
            Section::Ignored => {}
        }
    }
    piece.points = points.ok_or("missing <Points> DataArray")?;
    piece.connectivity = connectivity.ok_or("missing `connectivity` DataArray")?;
    piece.offsets = offsets.ok_or("missing `offsets` DataArray")?;
    piece.types = types.ok_or("missing `types` DataArray")?;
    let mut start = 0;
    for (c, (&end, &ty)) in piece.offsets.iter().zip(&piece.types).enumerate() {
        if end < start || end > piece.connectivity.len() {
            return Err(format!("cell {c}: offset {end} out of order or past the connectivity"));
        }
        let want = match ty {
            VTK_TRIANGLE => Some(3),
            VTK_TETRA => Some(4),
            _ => None,
        };
        if want.is_some_and(|w| w != end - start) {
            return Err(format!("cell {c} of type {ty} has {} nodes", end - start));
        }
        start = end;
    }
    if start != piece.connectivity.len() {
        return Err(format!(
            "the connectivity has {} entries but the offsets end at {start}",
            piece.connectivity.len()
        ));
    }
    if let Some(&bad) = piece.connectivity.iter().find(|&&i| i >= np) {
        return Err(format!("connectivity refers to point {bad}, but there are {np} points"));
    }
    Ok(piece)
}

fn components_of(a: &RawArray) -> Result<usize, String> {
    match a.attrs.get("NumberOfComponents") {
        None => Ok(1),
        Some(v) => match v.trim().parse::<usize>() {
            Ok(n) if n >= 1 => Ok(n),
            _ => Err(format!(
                "DataArray `{}` at byte {}: bad NumberOfComponents=\"{v}\"",
                a.name(),
                a.position
            )),
        },
    }
}

/// Decoded array contents.
#[derive(Debug)]
enum Values {
    Float(Vec<f64>),
    Int(Vec<i64>),
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::Float(v) => v.len(),
            Values::Int(v) => v.len(),
        }
    }
    fn to_f64(&self) -> Vec<f64> {
        match self {
            Values::Float(v) => v.clone(),
            Values::Int(v) => v.iter().map(|&i| i as f64).collect(),
        }
    }
    fn to_indices(&self) -> Result<Vec<usize>, String> {
        match self {
            Values::Float(_) => Err("expected an integer type".into()),
            Values::Int(v) => {
                v.iter().map(|&i| usize::try_from(i).map_err(|_| format!("negative index {i}"))).collect()
            }
        }
    }
}

fn decode(a: &RawArray, header: Header) -> Result<Values, String> {
    let ty = a.attrs.get("type").map(String::as_str).ok_or("no type attribute")?;
    let is_float = match ty {
        "Float32" | "Float64" => true,
        "Int8" | "UInt8" | "Int16" | "UInt16" | "Int32" | "UInt32" | "Int64" | "UInt64" => false,
        other => return Err(format!("unsupported type {other:?}")),
    };
    match a.attrs.get("format").map(String::as_str) {
        Some("ascii") => {
            let tokens = a.text.split_ascii_whitespace();
            if is_float {
                let v: Result<Vec<f64>, _> =
                    tokens.map(|t| t.parse::<f64>().map_err(|_| format!("bad number {t:?}"))).collect();
                Ok(Values::Float(v?))
            } else {
                let v: Result<Vec<i64>, _> =
                    tokens.map(|t| t.parse::<i64>().map_err(|_| format!("bad integer {t:?}"))).collect();
                Ok(Values::Int(v?))
            }
        }
        Some("binary") => {
            let bytes =
                if header.zlib { decode_zlib(&a.text, header)? } else { decode_base64(&a.text, header)? };
            binary_values(&bytes, ty, header.big_endian)
        }
        Some("appended") => Err("appended data is not supported".into()),
        other => Err(format!("unsupported format {other:?}")),
    }
}

/// An unsigned integer of the file's header type from `bytes` (4 or 8 of them).
fn header_uint(bytes: &[u8], header: Header) -> Result<u64, String> {
    match header.header_bytes {
        8 => {
            let a: [u8; 8] = bytes.try_into().map_err(|_| "bad binary header")?;
            Ok(if header.big_endian { u64::from_be_bytes(a) } else { u64::from_le_bytes(a) })
        }
        _ => {
            let a: [u8; 4] = bytes.try_into().map_err(|_| "bad binary header")?;
            Ok(u64::from(if header.big_endian { u32::from_be_bytes(a) } else { u32::from_le_bytes(a) }))
        }
    }
}

/// Payload of a zlib-compressed inline array (VTK's layout): the base64 of the header
/// `[blocks, block size, last partial block size (0: full), compressed sizes…]`, then the
/// base64 of the compressed blocks; each block is inflated and checked against its size.
fn decode_zlib(text: &str, header: Header) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let compact: String = text.split_ascii_whitespace().collect();
    let hb = header.header_bytes;
    let chars = |bytes: usize| bytes.div_ceil(3).saturating_mul(4);
    let invalid = |e: base64::DecodeError| format!("invalid base64 in the compression header: {e}");
    let first = compact.get(..chars(hb)).ok_or("compressed data shorter than its header")?;
    let first = STANDARD.decode(first).map_err(invalid)?;
    let blocks = usize::try_from(header_uint(first.get(..hb).ok_or("bad compression header")?, header)?)
        .map_err(|_| "too many blocks")?;
    let header_len = blocks.checked_add(3).and_then(|n| n.checked_mul(hb)).ok_or("too many blocks")?;
    if chars(header_len) > compact.len() {
        return Err(format!("the compression header announces {blocks} blocks, more than the data holds"));
    }
    let (head, body) = compact.split_at(chars(header_len));
    let head = STANDARD.decode(head).map_err(invalid)?;
    let body = STANDARD.decode(body).map_err(|e| format!("invalid base64 in the compressed data: {e}"))?;
    let item = |i: usize| -> Result<usize, String> {
        let v = header_uint(head.get(i * hb..(i + 1) * hb).ok_or("bad compression header")?, header)?;
        usize::try_from(v).map_err(|_| "size in the compression header too large".to_string())
    };
    let (block_size, last) = (item(1)?, item(2)?);
    if last > block_size {
        return Err(format!("last block of {last} bytes is larger than the block size {block_size}"));
    }
    let mut out = Vec::new();
    let mut start = 0_usize;
    for b in 0..blocks {
        let size = item(3 + b)?;
        let end = start.checked_add(size).filter(|&e| e <= body.len()).ok_or_else(|| {
            format!("compressed block {b} ends past the data ({} bytes; truncated?)", body.len())
        })?;
        let want = if b + 1 == blocks && last > 0 { last } else { block_size };
        let before = out.len();
        let mut inflate = flate2::read::ZlibDecoder::new(&body[start..end])
            .take(u64::try_from(want).unwrap_or(u64::MAX).saturating_add(1));
        inflate.read_to_end(&mut out).map_err(|e| format!("compressed block {b}: {e}"))?;
        if out.len() - before != want {
            return Err(format!(
                "compressed block {b} inflates to {} bytes, its header announces {want}",
                out.len() - before
            ));
        }
        start = end;
    }
    Ok(out)
}

/// Base64 payload of a binary inline array, without its byte-count header.
fn decode_base64(text: &str, header: Header) -> Result<Vec<u8>, String> {
    let compact: String = text.split_ascii_whitespace().collect();
    let hb = header.header_bytes;
    let (head, mut body) = match STANDARD.decode(&compact) {
        Ok(mut all) if all.len() >= hb => {
            let body = all.split_off(hb);
            (all, body)
        }
        Ok(_) => return Err("binary data shorter than its header".into()),
        Err(first_error) => {
            // Some VTK writers encode the header and the data as two base64 blocks.
            let split = 4 * hb.div_ceil(3);
            let (h, d) =
                compact.split_at_checked(split).ok_or_else(|| format!("invalid base64: {first_error}"))?;
            match (STANDARD.decode(h), STANDARD.decode(d)) {
                (Ok(h), Ok(d)) if h.len() == hb => (h, d),
                _ => return Err(format!("invalid base64: {first_error}")),
            }
        }
    };
    let announced = header_uint(head.get(..hb).ok_or("bad binary header")?, header)?;
    let announced = usize::try_from(announced).map_err(|_| "header too large")?;
    if body.len() < announced {
        return Err(format!(
            "binary data holds {} bytes, its header announces {announced} (truncated?)",
            body.len()
        ));
    }
    body.truncate(announced);
    Ok(body)
}

fn binary_values(bytes: &[u8], ty: &str, big: bool) -> Result<Values, String> {
    macro_rules! elems {
        ($t:ty, $conv:expr) => {{
            const N: usize = std::mem::size_of::<$t>();
            if !bytes.chunks_exact(N).remainder().is_empty() {
                return Err(format!("{} bytes is not a whole number of {ty}", bytes.len()));
            }
            bytes
                .chunks_exact(N)
                .map(|c| {
                    let mut a = [0u8; N];
                    a.copy_from_slice(c);
                    let v = if big { <$t>::from_be_bytes(a) } else { <$t>::from_le_bytes(a) };
                    $conv(v)
                })
                .collect::<Result<Vec<_>, String>>()?
        }};
    }
    let int = |v: i128| i64::try_from(v).map_err(|_| format!("integer {v} out of range"));
    Ok(match ty {
        "Float32" => Values::Float(elems!(f32, |v: f32| Ok(f64::from(v)))),
        "Float64" => Values::Float(elems!(f64, |v: f64| Ok(v))),
        "Int8" => Values::Int(elems!(i8, |v: i8| int(v.into()))),
        "UInt8" => Values::Int(elems!(u8, |v: u8| int(v.into()))),
        "Int16" => Values::Int(elems!(i16, |v: i16| int(v.into()))),
        "UInt16" => Values::Int(elems!(u16, |v: u16| int(v.into()))),
        "Int32" => Values::Int(elems!(i32, |v: i32| int(v.into()))),
        "UInt32" => Values::Int(elems!(u32, |v: u32| int(v.into()))),
        "Int64" => Values::Int(elems!(i64, |v: i64| int(v.into()))),
        "UInt64" => Values::Int(elems!(u64, |v: u64| int(v.into()))),
        other => return Err(format!("unsupported type {other:?}")),
    })
}
