//! libFuzzer target for the history tables of a scenario's `[[table]]` (kinematics and load
//! files): any bytes (as lossy UTF-8) go through `Table::parse_storage` and `Table::parse_csv`;
//! a table that parses is used as a scenario does — `require` of the six kinematics columns,
//! `column`, and `history` with unit factors, evaluated over the table's time range. Any
//! panic, abort, out-of-memory or time-out is a finding, and so is a non-finite value of a
//! history built with a moderate factor (see `docs/fuzzing.md`).
#![no_main]

mod alloc_guard;

use libfuzzer_sys::fuzz_target;
use synovia_time::history::LoadHistory;
use synovia_time::table::Table;

#[global_allocator]
static ALLOC: alloc_guard::Guard = alloc_guard::Guard;

const KINEMATICS: [&str; 6] =
    ["knee_ant_r", "knee_sup_r", "knee_lat_r", "knee_flex_r", "knee_add_r", "knee_rot_r"];

fn use_table(table: &Table) {
    if let Err(e) = table.require(&KINEMATICS) {
        let _ = e.to_string();
    }
    let (t0, t1) = match (table.time().first(), table.time().last()) {
        (Some(a), Some(b)) => (*a, *b),
        _ => panic!("a table without rows was accepted"),
    };
    assert!(t0.is_finite() && t1.is_finite() && t0 <= t1, "times {t0} … {t1}");
    for name in table.names().iter().skip(1).map(String::as_str).chain(KINEMATICS) {
        for (factor, time_factor) in [(1.0, 1.0), (1000.0, 0.01), (-1.0, -1.0)] {
            match table.history(name, factor, time_factor) {
                Ok(h) => {
                    for k in 0..=4 {
                        let t = (t0 + (t1 - t0) * k as f64 / 4.0) * time_factor;
                        let v = h.value(t);
                        assert!(v.is_finite(), "history of `{name}` × {factor}: {v} at t = {t}");
                    }
                }
                Err(e) => {
                    let _ = e.to_string();
                }
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    for parsed in [Table::parse_storage(&text, "fuzz.sto"), Table::parse_csv(&text, "fuzz.csv")] {
        match parsed {
            Ok(t) => use_table(&t),
            Err(e) => {
                let _ = e.to_string();
            }
        }
    }
});
