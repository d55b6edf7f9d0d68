//! Choosing a contact solver by name (examples, scenario files).

use synovia_contact::{ContactError, ContactParams, ContactSolver};

/// Names accepted by [`by_name`].
pub const SOLVER_NAMES: &[&str] = &["pdas", "au-pdas", "uzawa-mprgp", "dual-mprgp"];

/// The solver called `name` (see [`SOLVER_NAMES`]) with its default parameters.
pub fn by_name(name: &str) -> Result<Box<dyn ContactSolver>, ContactError> {
    Ok(match name {
        "pdas" => Box::new(synovia_pdas::Pdas::default()),
        "au-pdas" => Box::new(synovia_pdas::AuPdas::default()),
        "uzawa-mprgp" => Box::new(synovia_uzawa::UzawaMprgp::default()),
        "dual-mprgp" => Box::new(synovia_uzawa::DualMprgp::default()),
        _ => return by_name_with(name, ContactParams::default()),
    })
}

/// The solver called `name` with the given parameters.
pub fn by_name_with(name: &str, params: ContactParams) -> Result<Box<dyn ContactSolver>, ContactError> {
    Ok(match name {
        "pdas" => Box::new(synovia_pdas::Pdas::new(params)),
        "au-pdas" => Box::new(synovia_pdas::AuPdas::new(params)),
        "uzawa-mprgp" => Box::new(synovia_uzawa::UzawaMprgp::new(params)),
        "dual-mprgp" => Box::new(synovia_uzawa::DualMprgp::new(params)),
        _ => {
            return Err(ContactError::InvalidParameter(format!(
                "unknown contact solver `{name}`; choose one of {SOLVER_NAMES:?}"
            )))
        }
    })
}
