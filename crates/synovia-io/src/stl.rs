//! STL surfaces: [`read_stl`] / [`parse_stl`] read binary and ASCII STL files (through the
//! [`stl_io`] crate) into a [`TriangleSurface`], merging the corners STL stores per triangle
//! into shared vertices; [`write_stl`] writes a surface as binary STL.
//!
//! STL has no units: the coordinates are taken as they are (the joint data of synovia are in
//! metres; scale with [`TriangleSurface::scaled`]). The per-triangle normals stored in the file
//! are ignored: the vertex order (right-hand rule) defines the orientation, as in every STL
//! writer we know of. STL stores single-precision coordinates.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use synovia_mesh::{Point, TriangleSurface};

use crate::error::IoError;

/// Reads the STL file at `path` (binary or ASCII) as a [`TriangleSurface`] (identical corners
/// merged into one vertex).
///
/// # Errors
/// [`IoError::Io`] if the file cannot be read, [`IoError::Parse`] if it is not an STL file,
/// [`IoError::Surface`] if its triangles are invalid (degenerate, non-finite).
pub fn read_stl(path: impl AsRef<Path>) -> Result<TriangleSurface, IoError> {
    let path = path.as_ref();
    let bytes = crate::util::read_regular_file(path)?;
    parse_stl_at(&bytes, path)
}

/// [`read_stl`] of the bytes of an STL file.
///
/// # Errors
/// As [`read_stl`] (the path in the messages is `<bytes>`).
pub fn parse_stl(bytes: &[u8]) -> Result<TriangleSurface, IoError> {
    parse_stl_at(bytes, Path::new("<bytes>"))
}

fn parse_stl_at(bytes: &[u8], path: &Path) -> Result<TriangleSurface, IoError> {
    if bytes.len() < 15 {
        return Err(IoError::parse(path, format!("{} bytes: too short for an STL file", bytes.len())));
    }
    // binary STL: 80-byte header, u32 count, 50 bytes per triangle. Check the count against
    // the length first, so a corrupt count cannot make the reader allocate gigabytes.
    let ascii = bytes.starts_with(b"solid") && bytes[5..bytes.len().min(1024)].iter().all(|b| b.is_ascii());
    if !ascii {
        if bytes.len() < 84 {
            return Err(IoError::parse(
                path,
                format!("{} bytes: too short for a binary STL file", bytes.len()),
            ));
        }
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        let expected = 84 + 50 * count;
        if expected != bytes.len() as u64 {
            return Err(IoError::parse(
                path,
                format!(
                    "binary STL header declares {count} triangles ({expected} bytes), the file has {} bytes",
                    bytes.len()
                ),
            ));
        }
    }
    let mesh = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| IoError::parse(path, e.to_string()))?;
    let vertices: Vec<Point<3>> =
        mesh.vertices.iter().map(|v| Point::<3>::new(v[0] as f64, v[1] as f64, v[2] as f64)).collect();
    let triangles: Vec<[usize; 3]> = mesh.faces.iter().map(|f| f.vertices).collect();
    TriangleSurface::new(vertices, triangles)
        .map_err(|source| IoError::Surface { path: path.to_path_buf(), source })
}

/// Writes `surface` as a binary STL file (single precision, normals from the vertex order).
///
/// # Errors
/// [`IoError::Io`] if the file cannot be written.
pub fn write_stl(path: impl AsRef<Path>, surface: &TriangleSurface) -> Result<(), IoError> {
    let path: PathBuf = path.as_ref().to_path_buf();
    let to_f32 = |p: &Point<3>| stl_io::Vector::new([p.x as f32, p.y as f32, p.z as f32]);
    let triangles: Vec<stl_io::Triangle> = (0..surface.len())
        .map(|t| {
            let [a, b, c] = surface.corners(t);
            stl_io::Triangle {
                normal: to_f32(&surface.normal(t)),
                vertices: [to_f32(&a), to_f32(&b), to_f32(&c)],
            }
        })
        .collect();
    let mut file = std::io::BufWriter::new(std::fs::File::create(&path).map_err(|e| IoError::io(&path, e))?);
    stl_io::write_stl(&mut file, triangles.iter()).map_err(|e| IoError::io(&path, e))?;
    use std::io::Write;
    file.flush().map_err(|e| IoError::io(&path, e))
}
