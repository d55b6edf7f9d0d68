//! The child-process harness shared by the `bench_elastic` and `bench_report` examples: every
//! case runs in a child process of the example (the same executable with `--child CASE SCALE`),
//! so that the peak resident set size it reports (`VmHWM`) is the case's own.

use std::error::Error;
use std::process::Command;

use serde_json::Value;

/// Result type of the benchmark examples.
pub type Res<T> = Result<T, Box<dyn Error + Send + Sync>>;

/// How the example was invoked.
pub enum Invocation {
    /// As a child: run `case` at `scale` and print its JSON record as the last line.
    Child {
        /// Case name.
        case: String,
        /// Size scale.
        scale: f64,
    },
    /// As the parent: run `cases` at `scale`, each in a child process.
    Parent {
        /// Size scale (default 1).
        scale: f64,
        /// Cases (default: `default_cases`).
        cases: Vec<String>,
    },
}

/// Parses `[--child CASE SCALE]` or `[SCALE [CASE…]]`.
pub fn parse_args(default_cases: &[&str]) -> Res<Invocation> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--child") {
        let case = args.get(1).ok_or("--child needs a case")?.clone();
        let scale: f64 = args.get(2).ok_or("--child needs a scale")?.parse()?;
        return Ok(Invocation::Child { case, scale });
    }
    let scale: f64 = match args.first() {
        Some(s) => s.parse().map_err(|e| format!("scale `{s}`: {e}"))?,
        None => 1.0,
    };
    if !(scale.is_finite() && scale > 0.0) {
        return Err(format!("scale must be positive, got {scale}").into());
    }
    let cases = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        default_cases.iter().map(|s| s.to_string()).collect()
    };
    Ok(Invocation::Parent { scale, cases })
}

/// Peak resident set size of this process, in bytes (`VmHWM` of `/proc/self/status`).
pub fn peak_rss_bytes() -> Res<u64> {
    let status = std::fs::read_to_string("/proc/self/status")?;
    let line =
        status.lines().find(|l| l.starts_with("VmHWM:")).ok_or("no VmHWM line in /proc/self/status")?;
    let kb: u64 = line.trim_start_matches("VmHWM:").trim().trim_end_matches("kB").trim().parse()?;
    Ok(kb * 1024)
}

/// Runs a case in a child process and parses the last line of its output.
pub fn spawn_case(case: &str, scale: f64) -> Res<Value> {
    let out = Command::new(std::env::current_exe()?)
        .args(["--child", case, &scale.to_string()])
        .stderr(std::process::Stdio::inherit())
        .output()?;
    if !out.status.success() {
        return Err(format!("case `{case}` failed with {}", out.status).into());
    }
    let stdout = String::from_utf8(out.stdout)?;
    let line = stdout.lines().last().ok_or_else(|| format!("case `{case}` printed nothing"))?;
    Ok(serde_json::from_str(line)?)
}
