//! `[sweep]`: a parameter study over one scenario (docs/scenario.md, *Parameter studies*).
//!
//! ```toml
//! [sweep]
//! mode = "product"                         # or "zip" (default "product")
//! [sweep.values]
//! "boundary[0].value" = [[0.0, -0.05], [0.0, -0.1]]
//! "body[0].material.E" = [5.0, 10.0, 20.0]
//! ```
//!
//! Each key of `[sweep.values]` is the path of a scenario key — dotted names with 0-based
//! array indices, as in the error messages (`body[0].material.E`, `contact[1].friction`) —
//! and its value the list of values that key takes. With `mode = "product"` the *cases* are
//! the Cartesian product of the lists (the last key varies fastest); with `mode = "zip"` all
//! lists have the same length `n` and case `i` takes the `i`-th value of every list.
//!
//! A case is the scenario with these keys replaced ([`case_scenario`]): every table and array
//! element on the path must exist in the scenario; the last name may be new (an optional key
//! the scenario leaves out) — the case scenario is then checked like any other, so a typo is
//! reported as an unknown key. Cases are distributed over the tasks of a scheduler array by
//! [`task_cases`]: task `i` of `n` runs the cases `c` with `c mod n = i`.

use std::fmt;
use std::ops::Range;

use serde::de::{MapAccess, Visitor};
use serde::{Deserialize, Deserializer};

use crate::scenario::{Scenario, ScenarioError, Source, Sp};

/// `[sweep]` of a scenario.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// `"product"` (default) or `"zip"`.
    pub mode: Option<Sp<String>>,
    /// Key path → list of values, in the order written.
    pub values: Sp<SweepValues>,
}

/// The entries of `[sweep.values]` in the order written: key path and its list of values.
#[derive(Debug, Clone, Default)]
pub struct SweepValues(pub Vec<(String, Sp<Vec<toml::Value>>)>);

impl<'de> Deserialize<'de> for SweepValues {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Ordered;
        impl<'de> Visitor<'de> for Ordered {
            type Value = SweepValues;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a table of key paths, each with a list of values")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<SweepValues, A::Error> {
                let mut out = Vec::new();
                while let Some((k, v)) = map.next_entry::<String, Sp<Vec<toml::Value>>>()? {
                    out.push((k, v));
                }
                Ok(SweepValues(out))
            }
        }
        deserializer.deserialize_map(Ordered)
    }
}

/// How the lists combine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SweepMode {
    /// Cartesian product (the last key varies fastest).
    Product,
    /// Element-wise: case `i` takes the `i`-th value of every list.
    Zip,
}

/// One case of a sweep: its index and the value of every swept key.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// 0-based index among all cases of the sweep.
    pub index: usize,
    /// Key path and value, in the order of `[sweep.values]`.
    pub parameters: Vec<(String, toml::Value)>,
}

/// Errors of the task selection ([`task_cases`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TaskError {
    /// `tasks` is 0.
    #[error("the number of tasks must be at least 1")]
    NoTasks,
    /// `index ≥ tasks`.
    #[error("task index {index} is out of range for {tasks} tasks (0-based: 0 to {})", tasks - 1)]
    IndexOutOfRange {
        /// The index.
        index: usize,
        /// The number of tasks.
        tasks: usize,
    },
    /// More tasks than cases: some tasks would have nothing to do.
    #[error("{tasks} tasks for a sweep of {cases} cases: use at most {cases} tasks (e.g. sbatch --array=0-{})", cases.saturating_sub(1))]
    MoreTasksThanCases {
        /// The number of tasks.
        tasks: usize,
        /// The number of cases.
        cases: usize,
    },
}

/// The cases that task `index` of `tasks` runs out of `cases`: `c` with `c mod tasks = index`.
///
/// # Errors
/// [`TaskError`] for `tasks = 0`, `index ≥ tasks` or `tasks > cases`.
pub fn task_cases(cases: usize, index: usize, tasks: usize) -> Result<Vec<usize>, TaskError> {
    if tasks == 0 {
        return Err(TaskError::NoTasks);
    }
    if index >= tasks {
        return Err(TaskError::IndexOutOfRange { index, tasks });
    }
    if tasks > cases {
        return Err(TaskError::MoreTasksThanCases { tasks, cases });
    }
    Ok((index..cases).step_by(tasks).collect())
}

fn span(s: &Sp<impl Sized>) -> Option<Range<usize>> {
    Some(s.span())
}

/// The cases of the scenario's `[sweep]` (`None` without one).
///
/// # Errors
/// A [`ScenarioError`] at the offending `[sweep]` entry: an unknown mode, no keys, an empty
/// list, lists of different lengths with `mode = "zip"`, or a key path that does not parse.
pub fn cases(sc: &Scenario) -> Result<Option<Vec<Case>>, ScenarioError> {
    let Some(spec) = &sc.doc.sweep else { return Ok(None) };
    let src = &sc.source;
    let mode = match &spec.mode {
        None => SweepMode::Product,
        Some(m) => match m.get_ref().as_str() {
            "product" => SweepMode::Product,
            "zip" => SweepMode::Zip,
            other => {
                return Err(src.error(
                    "sweep.mode",
                    span(m),
                    format!("unknown sweep mode `{other}` (expected \"product\" or \"zip\")"),
                ))
            }
        },
    };
    let entries = &spec.values.get_ref().0;
    if entries.is_empty() {
        return Err(src.error("sweep.values", span(&spec.values), "the sweep has no keys"));
    }
    for (key, list) in entries {
        parse_path(key).map_err(|m| src.error(format!("sweep.values.\"{key}\""), span(list), m))?;
        if list.get_ref().is_empty() {
            return Err(src.error(format!("sweep.values.\"{key}\""), span(list), "empty list of values"));
        }
    }
    let lens: Vec<usize> = entries.iter().map(|(_, l)| l.get_ref().len()).collect();
    let n = match mode {
        SweepMode::Product => lens.iter().product(),
        SweepMode::Zip => {
            if let Some((key, list)) = entries.iter().find(|(_, l)| l.get_ref().len() != lens[0]) {
                return Err(src.error(
                    format!("sweep.values.\"{key}\""),
                    span(list),
                    format!(
                        "mode \"zip\" needs lists of one length: `{}` has {} values, this one {}",
                        entries[0].0,
                        lens[0],
                        list.get_ref().len()
                    ),
                ));
            }
            lens[0]
        }
    };
    let mut out = Vec::with_capacity(n);
    for c in 0..n {
        let mut rest = c;
        let mut picks = vec![0; entries.len()];
        match mode {
            SweepMode::Zip => picks.iter_mut().for_each(|p| *p = c),
            SweepMode::Product => {
                for (p, len) in picks.iter_mut().zip(&lens).rev() {
                    *p = rest % len;
                    rest /= len;
                }
            }
        }
        let parameters = entries
            .iter()
            .zip(&picks)
            .filter_map(|((k, l), &p)| l.get_ref().get(p).map(|v| (k.clone(), v.clone())))
            .collect();
        out.push(Case { index: c, parameters });
    }
    Ok(Some(out))
}

/// One step of a key path.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Step {
    Key(String),
    Index(usize),
}

/// `body[0].material.E` → `[Key(body), Index(0), Key(material), Key(E)]`.
fn parse_path(path: &str) -> Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        let bare = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
        if name.is_empty() || !name.chars().all(bare) {
            return Err(format!(
                "`{path}` is not a key path (names of letters, digits, `_`, `-` joined by `.`, with \
                 0-based indices like `body[0].material.E`)"
            ));
        }
        steps.push(Step::Key(name.to_string()));
        while !rest.is_empty() {
            let close = rest.find(']').ok_or_else(|| format!("`{path}`: unclosed `[`"))?;
            let idx = rest
                .get(1..close)
                .filter(|_| rest.starts_with('['))
                .and_then(|s| s.parse::<usize>().ok())
                .ok_or_else(|| format!("`{path}`: an index must be a non-negative integer in `[ ]`"))?;
            steps.push(Step::Index(idx));
            rest = &rest[close + 1..];
        }
    }
    Ok(steps)
}

/// Sets `path` in `doc` to `value` (intermediate tables and array elements must exist).
fn set_path(doc: &mut toml::Table, path: &str, value: toml::Value) -> Result<(), String> {
    let steps = parse_path(path)?;
    let (last, init) = steps.split_last().ok_or_else(|| format!("`{path}`: empty key path"))?;
    let mut here: &mut toml::Value = match init.first() {
        None => {
            return match last {
                Step::Key(k) => {
                    doc.insert(k.clone(), value);
                    Ok(())
                }
                Step::Index(_) => Err(format!("`{path}`: starts with an index")),
            }
        }
        Some(Step::Key(k)) => doc.get_mut(k).ok_or_else(|| format!("the scenario has no key `{k}`"))?,
        Some(Step::Index(_)) => return Err(format!("`{path}`: starts with an index")),
    };
    let mut walked = match init.first() {
        Some(Step::Key(k)) => k.clone(),
        _ => String::new(),
    };
    for step in init.iter().skip(1).chain(std::iter::once(last)) {
        let is_last = std::ptr::eq(step, last);
        match step {
            Step::Key(k) => {
                let t = here.as_table_mut().ok_or_else(|| format!("`{walked}` is not a table"))?;
                if is_last {
                    t.insert(k.clone(), value);
                    return Ok(());
                }
                here = t.get_mut(k).ok_or_else(|| format!("the scenario has no key `{walked}.{k}`"))?;
                walked = format!("{walked}.{k}");
            }
            Step::Index(i) => {
                let a = here.as_array_mut().ok_or_else(|| format!("`{walked}` is not an array"))?;
                let len = a.len();
                let slot = a
                    .get_mut(*i)
                    .ok_or_else(|| format!("`{walked}` has {len} element(s); index {i} is out of range"))?;
                if is_last {
                    *slot = value;
                    return Ok(());
                }
                here = slot;
                walked = format!("{walked}[{i}]");
            }
        }
    }
    Ok(())
}

/// The scenario of one case: the file's document without `[sweep]`, with the case's keys
/// replaced, parsed again (same file name and base directory, so relative paths still
/// resolve). The case's text is [`Scenario::source`]`.text` of the result.
///
/// # Errors
/// A [`ScenarioError`] at the `[sweep.values]` entry whose path does not exist in the
/// scenario, or — for a case scenario that does not parse (a value of the wrong type, an
/// unknown key) — the parse error, its message prefixed with the case and located at the
/// sweep entry of its key when there is one (else at `[sweep]`).
pub fn case_scenario(sc: &Scenario, case: &Case) -> Result<Scenario, ScenarioError> {
    let src = &sc.source;
    let spec_span = sc.doc.sweep.as_ref().map(|s| s.values.span());
    let entry_span = |key: &str| -> Option<Range<usize>> {
        sc.doc
            .sweep
            .as_ref()
            .and_then(|s| s.values.get_ref().0.iter().find(|(k, _)| k == key).map(|(_, l)| l.span()))
            .or_else(|| spec_span.clone())
    };
    let mut doc: toml::Table = toml::from_str(&src.text)
        .map_err(|e| src.file_error(format!("cannot read the scenario as TOML: {e}")))?;
    doc.remove("sweep");
    for (key, value) in &case.parameters {
        set_path(&mut doc, key, value.clone())
            .map_err(|m| src.error(format!("sweep.values.\"{key}\""), entry_span(key), m))?;
    }
    let text = toml::to_string(&doc).map_err(|e| {
        src.error("sweep", spec_span.clone(), format!("cannot write case {}: {e}", case.index))
    })?;
    let generated = Source { file: src.file.clone(), dir: src.dir.clone(), text };
    Scenario::parse(generated).map_err(|e| {
        let swept = case.parameters.iter().find(|(k, _)| e.key == *k || e.key.starts_with(&format!("{k}.")));
        let at = swept.map_or_else(|| spec_span.clone(), |(k, _)| entry_span(k));
        let mut err = src.error(
            e.key.clone(),
            at,
            format!("sweep case {} ({}): {}", case.index, describe(case), e.message),
        );
        err.key = e.key;
        err
    })
}

/// `key = value, …` of a case (values in TOML syntax).
pub fn describe(case: &Case) -> String {
    case.parameters.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = r#"
dimension = 2
[[body]]
name = "block"
mesh = { generator = "rectangle", x = [0.0, 2.0], y = [0.0, 1.0], cells = [4, 2] }
material = { type = "isotropic", E = 1000.0, nu = 0.3 }
[[boundary]]
body = "block"
part = "bottom"
kind = "clamped"
[analysis]
type = "static"
"#;

    fn scenario(sweep: &str) -> Scenario {
        Scenario::parse(Source::new("s.toml", format!("{BASE}{sweep}"))).expect("parse")
    }

    #[test]
    fn product_and_zip_cases_in_order() {
        let sc = scenario(
            "[sweep]\n[sweep.values]\n\"body[0].material.E\" = [1.0, 2.0]\n\"body[0].material.nu\" = [0.1, 0.2, 0.3]\n",
        );
        let cs = cases(&sc).expect("cases").expect("a sweep");
        assert_eq!(cs.len(), 6);
        assert_eq!(
            cs[4].parameters,
            vec![
                ("body[0].material.E".to_string(), toml::Value::Float(2.0)),
                ("body[0].material.nu".to_string(), toml::Value::Float(0.2))
            ]
        );
        let one = case_scenario(&sc, &cs[4]).expect("case");
        assert!(one.doc.sweep.is_none());
        let v: toml::Table = toml::from_str(&one.source.text).expect("toml");
        assert_eq!(v["body"][0]["material"]["E"].as_float(), Some(2.0));
        assert_eq!(v["body"][0]["material"]["nu"].as_float(), Some(0.2));
        assert_eq!(v["body"][0]["name"].as_str(), Some("block"));

        let zip = scenario(
            "[sweep]\nmode = \"zip\"\n[sweep.values]\n\"body[0].material.E\" = [1.0, 2.0]\n\"body[0].material.nu\" = [0.1, 0.2]\n",
        );
        let cs = cases(&zip).expect("cases").expect("a sweep");
        assert_eq!(cs.len(), 2);
        assert_eq!(cs[1].parameters[1].1, toml::Value::Float(0.2));
    }

    #[test]
    fn bad_sweeps_are_located_errors() {
        let e = cases(&scenario(
            "[sweep]\nmode = \"zip\"\n[sweep.values]\n\"body[0].material.E\" = [1.0, 2.0]\n\"body[0].material.nu\" = [0.1]\n",
        ))
        .expect_err("zip lengths");
        assert!(e.message.contains("one length"), "{e}");
        assert_eq!(e.line, 17, "{e}");
        let sc = scenario("[sweep.values]\n\"body[3].material.E\" = [1.0]\n");
        let cs = cases(&sc).expect("cases").expect("a sweep");
        let e = case_scenario(&sc, &cs[0]).expect_err("no body[3]");
        assert!(e.message.contains("index 3 is out of range"), "{e}");
        let sc = scenario("[sweep.values]\n\"body[0].material.EE\" = [1.0]\n");
        let cs = cases(&sc).expect("cases").expect("a sweep");
        let e = case_scenario(&sc, &cs[0]).expect_err("unknown key");
        assert!(e.message.contains("sweep case 0"), "{e}");
        let e = cases(&scenario("[sweep]\nmode = \"grid\"\n[sweep.values]\nx = [1]\n")).expect_err("mode");
        assert!(e.message.contains("unknown sweep mode"), "{e}");
        let e = cases(&scenario("[sweep.values]\n\"body[x]\" = [1]\n")).expect_err("path");
        assert!(e.message.contains("index"), "{e}");
    }

    #[test]
    fn tasks_take_every_nth_case() {
        assert_eq!(task_cases(7, 1, 3), Ok(vec![1, 4]));
        assert_eq!(task_cases(3, 2, 3), Ok(vec![2]));
        assert_eq!(task_cases(3, 3, 3), Err(TaskError::IndexOutOfRange { index: 3, tasks: 3 }));
        assert_eq!(task_cases(3, 0, 4), Err(TaskError::MoreTasksThanCases { tasks: 4, cases: 3 }));
        assert_eq!(task_cases(3, 0, 0), Err(TaskError::NoTasks));
    }
}
