//! libFuzzer target for the scenario parser: any bytes (as lossy UTF-8) go through
//! `Scenario::parse` and, for a document that parses, the model build of its dimension
//! (meshes, materials, conditions, pairs, solver, analysis; not the solve), as `synovia check`
//! does; every error is formatted with `Display` and `Debug`. Any panic, abort,
//! out-of-memory or time-out is a finding (see `docs/fuzzing.md`).
//!
//! The scenario's path is `examples/scenarios/fuzz.toml`, so `mesh = { gmsh = "block2d.msh" }`
//! resolves to the example mesh. The build's size guards are much smaller than the CLI's
//! (2·10⁷ cells, 30 refinement levels, 10⁷ time steps): the parser and validation are under
//! test, not the mesh generators at scale. Profiles of first runs (guards of 2·10⁴ / 5·10³
//! cells and 12 / 8 levels) showed the refined mesh generators taking ≈ 80 % of the time,
//! at 200–450 exec/s. The coarse seeds of the corpus (`refine.levels = 2`, a few dozen cells)
//! build under these guards; the examples' `levels = 8` stop at the guard with its error.
#![no_main]

mod alloc_guard;

use libfuzzer_sys::fuzz_target;
use synovia_scenario::build::{build, set_limits, Limits};
use synovia_scenario::{Scenario, ScenarioError, Source};

const PATH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenarios/fuzz.toml");

fn check(sc: &Scenario) -> Result<(), ScenarioError> {
    match *sc.doc.dimension.get_ref() {
        2 => build::<2>(sc).map(|_| ()),
        3 => build::<3>(sc).map(|_| ()),
        _ => Ok(()),
    }
}

#[global_allocator]
static ALLOC: alloc_guard::Guard = alloc_guard::Guard;

fuzz_target!(
    init: {
        set_limits(Limits { max_cells: 2.0e3, max_refine_levels: 4, max_time_steps: 10_000 });
    },
    |data: &[u8]| {
        let text = String::from_utf8_lossy(data).into_owned();
        if let Err(e) = Scenario::parse(Source::new(PATH, text)).and_then(|sc| check(&sc)) {
            let _ = e.to_string();
            let _ = format!("{e:?}");
        }
    }
);
