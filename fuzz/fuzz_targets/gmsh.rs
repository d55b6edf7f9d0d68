//! libFuzzer target for the Gmsh reader: any bytes go through `parse_msh`, then
//! `physical_groups`, `bodies::<2>()` and `bodies::<3>()`, and every error is formatted. Any
//! panic, abort, out-of-memory or time-out is a finding (see `docs/fuzzing.md`).
#![no_main]

mod alloc_guard;

use libfuzzer_sys::fuzz_target;
use synovia_io::parse_msh;

#[global_allocator]
static ALLOC: alloc_guard::Guard = alloc_guard::Guard;

fuzz_target!(|data: &[u8]| {
    match parse_msh(data) {
        Ok(m) => {
            let _ = m.physical_groups();
            if let Err(e) = m.bodies::<2>() {
                let _ = e.to_string();
            }
            if let Err(e) = m.bodies::<3>() {
                let _ = e.to_string();
            }
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
});
