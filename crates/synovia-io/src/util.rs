//! Small shared helpers: XML escaping, atomic file writes, attribute parsing.

use std::borrow::Cow;
use std::collections::HashMap;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use quick_xml::events::BytesStart;

use crate::error::IoError;

/// Reads the whole file at `path`, which must be a regular file: a device or pipe (`/dev/zero`,
/// a FIFO) given as a mesh path would otherwise be read until memory runs out.
pub(crate) fn read_regular_file(path: &Path) -> Result<Vec<u8>, IoError> {
    let meta = std::fs::metadata(path).map_err(|e| IoError::io(path, e))?;
    if !meta.is_file() {
        return Err(IoError::io(
            path,
            io::Error::new(io::ErrorKind::InvalidInput, "not a regular file (a directory, device or pipe)"),
        ));
    }
    std::fs::read(path).map_err(|e| IoError::io(path, e))
}

/// Escapes `& < > " '` for use inside a double-quoted attribute.
pub(crate) fn escape_attr(s: &str) -> Cow<'_, str> {
    quick_xml::escape::escape(s)
}

/// Writes a file through `body` into `path.tmp`, then renames it onto `path`, so that a reader
/// (or a crashed run) never leaves a half-written file under the final name.
pub(crate) fn write_file_atomic(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), IoError> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let result = (|| {
        let file = File::create(&tmp)?;
        let mut w = BufWriter::new(file);
        body(&mut w)?;
        w.flush()?;
        Ok(())
    })();
    match result {
        Ok(()) => std::fs::rename(&tmp, path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            IoError::io(path, e)
        }),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(IoError::io(path, e))
        }
    }
}

/// The attributes of an element, unescaped.
pub(crate) fn attributes(e: &BytesStart<'_>) -> Result<HashMap<String, String>, String> {
    let mut out = HashMap::new();
    for a in e.attributes() {
        let a = a.map_err(|err| format!("bad attribute: {err}"))?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let value =
            a.unescape_value().map_err(|err| format!("bad value of attribute `{key}`: {err}"))?.into_owned();
        out.insert(key, value);
    }
    Ok(out)
}

/// Name of an element as a string.
pub(crate) fn element_name(e: &BytesStart<'_>) -> String {
    String::from_utf8_lossy(e.name().as_ref()).into_owned()
}

/// The path as UTF-8, or [`IoError::NonUtf8Path`].
pub(crate) fn utf8_path(path: &Path) -> Result<&str, IoError> {
    path.to_str().ok_or_else(|| IoError::NonUtf8Path { path: path.to_path_buf() })
}
