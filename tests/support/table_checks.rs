//! The checks of the history-table fuzzers, shared by the proptest target (`fuzz_table` of
//! `synovia-time`) and the libFuzzer target (`fuzz/fuzz_targets/table.rs`): bytes (as lossy
//! UTF-8) go through `Table::parse_storage` and `Table::parse_csv`; a table that parses is used
//! as a scenario does — `require` of the six kinematics columns, `column`, and `history` with
//! unit factors (metres to millimetres, percent to cycles, a reversed time, extreme factors),
//! evaluated over and around the table's time range. Every history built with a factor below
//! 1e300 must give finite values. See `docs/fuzzing.md`.
//!
//! The including module brings `Table` and `LoadHistory` into scope.

use super::{LoadHistory, Table};

/// The kinematics columns a `tkr3d` scenario requires.
pub const KINEMATICS: [&str; 6] =
    ["knee_ant_r", "knee_sup_r", "knee_lat_r", "knee_flex_r", "knee_add_r", "knee_rot_r"];

/// Use a parsed table as a scenario does; `Err` on a non-finite value.
pub fn use_table(table: &Table) -> Result<(), String> {
    let _ = table.require(&KINEMATICS).map_err(|e| e.to_string());
    let (t0, t1) = match (table.time().first(), table.time().last()) {
        (Some(a), Some(b)) => (*a, *b),
        _ => return Err("a table without rows was accepted".into()),
    };
    if !(t0.is_finite() && t1.is_finite() && t0 <= t1) {
        return Err(format!("times {t0} … {t1}"));
    }
    for name in table.names().iter().skip(1).map(String::as_str).chain(KINEMATICS) {
        let _ = table.column(name).map_err(|e| e.to_string());
        for (factor, time_factor) in [(1.0, 1.0), (1000.0, 0.01), (1e300, 1e300), (-1.0, -1.0), (0.0, 1.0)] {
            match table.history(name, factor, time_factor) {
                Ok(h) => {
                    for k in 0..=8 {
                        let t = (t0 + (t1 - t0) * k as f64 / 8.0) * time_factor;
                        for at in [t, t - 1.0, t + 1e-9, -t] {
                            let v = h.value(at);
                            if !v.is_finite() && factor.abs() < 1e300 {
                                return Err(format!("history of `{name}` × {factor}: {v} at t = {at}"));
                            }
                        }
                    }
                }
                Err(e) => {
                    let _ = e.to_string();
                }
            }
        }
    }
    Ok(())
}

/// Parse as OpenSim storage and as CSV and use what parses. `Err(message)` on a non-finite
/// value (a panic propagates).
pub fn exercise_table(bytes: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(bytes);
    for parsed in [Table::parse_storage(&text, "fuzz.sto"), Table::parse_csv(&text, "fuzz.csv")] {
        match parsed {
            Ok(t) => use_table(&t)?,
            Err(e) => {
                let _ = e.to_string();
            }
        }
    }
    Ok(())
}
