//! The checked-in C header `include/synovia.h` must be what cbindgen generates from the crate.
//!
//! After changing the C API, regenerate it with
//! `SYNOVIA_BLESS=1 cargo test -p synovia-capi --test header`.

use std::path::Path;

#[test]
fn header_is_up_to_date() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let header = crate_dir.join("../../include/synovia.h");
    let config = match cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")) {
        Ok(c) => c,
        Err(e) => panic!("cannot read cbindgen.toml: {e}"),
    };
    let bindings = match cbindgen::Builder::new().with_crate(crate_dir).with_config(config).generate() {
        Ok(b) => b,
        Err(e) => panic!("cbindgen failed: {e}"),
    };
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8_lossy(&generated).into_owned();
    if std::env::var_os("SYNOVIA_BLESS").is_some_and(|v| v != "0") {
        if let Err(e) = std::fs::write(&header, &generated) {
            panic!("cannot write {}: {e}", header.display());
        }
        eprintln!("wrote {}", header.display());
        return;
    }
    let current = std::fs::read_to_string(&header).unwrap_or_default();
    if current != generated {
        let line = current
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .map_or_else(|| current.lines().count().min(generated.lines().count()) + 1, |i| i + 1);
        panic!(
            "include/synovia.h is out of date with the C API (first difference at line {line}).\n\
             Regenerate it with:\n    SYNOVIA_BLESS=1 cargo test -p synovia-capi --test header"
        );
    }
}
