//! libFuzzer target for STL surfaces as a scenario's `stl` shape uses them: the checks of
//! `tests/support/stl_checks.rs` (shared with the proptest target `fuzz_stl`) — `parse_stl`,
//! `TriangleSurface::scaled`, the three `SurfaceObstacle` constructors and a concave fillet,
//! closest-point and signed-distance queries around the surface. Any panic, abort,
//! out-of-memory or time-out is a finding, and so is a non-finite distance, gradient or closest
//! point (see `docs/fuzzing.md`).
#![no_main]

mod alloc_guard;

use libfuzzer_sys::fuzz_target;
use synovia_contact::operators::SignedDistance;
use synovia_contact::SurfaceObstacle;
use synovia_io::parse_stl;
use synovia_mesh::{Point, TriangleSurface};

#[path = "../../tests/support/stl_checks.rs"]
mod stl_checks;

#[global_allocator]
static ALLOC: alloc_guard::Guard = alloc_guard::Guard;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = stl_checks::exercise_stl(data) {
        panic!("{e}");
    }
});
