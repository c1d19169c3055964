//! The active set of contacts and friction at one state ([`Active`]): which contacts are
//! closed and how each friction contact moves ([`Mode`]), with its check against a model
//! ([`check_active`]) and the tolerance by which it is decided ([`DECIDE_TOLERANCE`]). The
//! decision itself is `solve::integrated::contacts`' (which re-exports these), and
//! `solve::integrated::rest` examines an active set for equilibrium; both import it from here.

pub use crate::results::{Mode, Sign};

use crate::model::ModelInfo;
use crate::results::ContactSet;
use crate::solve::SolveError;

/// How small, relative to the largest of its kind, a force or normal acceleration may be and
/// still count as zero when a contact's state is decided.
pub const DECIDE_TOLERANCE: f64 = 1e-9;

/// Which contacts are closed, and how each friction moves.
#[derive(Debug, Clone, PartialEq)]
pub struct Active {
    /// Per contact of the system: closed (a contact the model eliminates always is).
    pub closed: Vec<bool>,
    /// Per friction: its mode (meaningful only while its contact is closed).
    pub modes: Vec<Mode>,
}

impl Active {
    /// The contacts a model holds closed by elimination, every friction sliding `+` (a
    /// placeholder for models without friction).
    pub fn of_model(info: &ModelInfo) -> Active {
        Active {
            closed: info.contacts.iter().map(|c| c.closed).collect(),
            modes: vec![Mode::Slide(Sign::Plus); info.frictions.len()],
        }
    }

    /// Whether friction `j` acts (its contact is closed).
    pub fn friction_acts(&self, info: &ModelInfo, j: usize) -> bool {
        (info.frictions.get(j)).is_some_and(|f| self.closed.get(f.contact_index) == Some(&true))
    }

    /// The names of the closed contacts.
    pub fn closed_names(&self, info: &ModelInfo) -> Vec<&'static str> {
        (info.contacts.iter().zip(&self.closed))
            .filter(|(_, c)| **c)
            .map(|(c, _)| c.name)
            .collect()
    }

    /// The set by name: its closed contacts and each acting friction's mode.
    pub fn set(&self, info: &ModelInfo) -> ContactSet {
        ContactSet {
            closed: self.closed_names(info),
            frictions: (info.frictions.iter().zip(&self.modes).enumerate())
                .filter(|(j, _)| self.friction_acts(info, *j))
                .map(|(_, (f, m))| (f.name, *m))
                .collect(),
        }
    }
}

/// `Ok` when `active` has one state per contact and one mode per friction of the model, else
/// [`SolveError::ActiveSize`].
pub fn check_active(info: &ModelInfo, active: &Active) -> Result<(), SolveError> {
    let (m, nf) = (info.contacts.len(), info.frictions.len());
    if active.closed.len() != m || active.modes.len() != nf {
        return Err(SolveError::ActiveSize {
            model: info.name,
            contacts: m,
            frictions: nf,
            closed: active.closed.len(),
            modes: active.modes.len(),
        });
    }
    Ok(())
}
