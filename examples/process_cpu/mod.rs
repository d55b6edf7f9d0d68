//! CPU time of the example's process, shared by the examples that compare costs by CPU time
//! (`knee2d_nonlinear`, `tkr3d --neo-hookean`): on a shared machine the wall time of a run
//! depends on what else runs, its CPU time much less.

/// CPU time of this process, all threads, user + system (s): from `/proc/self/stat` (fields 14
/// and 15, in clock ticks of 1/100 s on Linux), NaN where that file cannot be read (other
/// systems), so the ratio shows as NaN rather than a wrong number.
pub fn process_cpu_s() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return f64::NAN };
    // the command name (field 2) is in parentheses and may hold spaces: fields after the last ')'
    let Some(rest) = stat.rfind(')').map(|i| &stat[i + 1..]) else { return f64::NAN };
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // after ')': field 3 (state) is index 0, so utime (14) is index 11 and stime (15) index 12
    match (
        fields.get(11).and_then(|v| v.parse::<f64>().ok()),
        fields.get(12).and_then(|v| v.parse::<f64>().ok()),
    ) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
}
