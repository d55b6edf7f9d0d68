//! libFuzzer target for the history tables of a scenario's `[[table]]` (kinematics and load
//! files): the checks of `tests/support/table_checks.rs` (shared with the proptest target
//! `fuzz_table`) — any bytes (as lossy UTF-8) through `Table::parse_storage` and
//! `Table::parse_csv`, a table that parses used as a scenario does (`require`, `column`,
//! `history` with unit factors, evaluated over and around its time range). Any panic, abort,
//! out-of-memory or time-out is a finding, and so is a non-finite value of a history built with
//! a factor below 1e300 (see `docs/fuzzing.md`).
#![no_main]

mod alloc_guard;

use libfuzzer_sys::fuzz_target;
use synovia_time::history::LoadHistory;
use synovia_time::table::Table;

#[path = "../../tests/support/table_checks.rs"]
mod table_checks;

#[global_allocator]
static ALLOC: alloc_guard::Guard = alloc_guard::Guard;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = table_checks::exercise_table(data) {
        panic!("{e}");
    }
});
