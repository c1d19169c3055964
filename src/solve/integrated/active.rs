//! The active set of contacts and friction at one state ([`Active`]): which contacts are
//! closed and how each friction contact moves ([`Mode`]), with its check against a model
//! ([`check_active`]) and the tolerance by which it is decided ([`DECIDE_TOLERANCE`]). The
//! decision itself is `solve::integrated::contacts`' (which re-exports these), and `solve::integrated::rest` examines
//! an active set for equilibrium; both import it from here.

use crate::model::ModelInfo;
use crate::solve::SolveError;

/// How small, relative to the largest of its kind, a force or normal acceleration may be and
/// still count as zero when a contact's state is decided.
pub const DECIDE_TOLERANCE: f64 = 1e-9;

/// A sign of a slip: the direction a friction slides in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sign {
    /// Slipping along its slip row (`T qd > 0`).
    Plus,
    /// Slipping against it.
    Minus,
}

impl Sign {
    /// `+1` or `-1`.
    pub fn value(self) -> f64 {
        match self {
            Sign::Plus => 1.0,
            Sign::Minus => -1.0,
        }
    }

    /// The sign of `x` as `f64::signum` gives it: `Plus` for `+0`, `Minus` for `-0` (a NaN by
    /// its sign bit).
    pub fn of(x: f64) -> Sign {
        if x.is_sign_negative() {
            Sign::Minus
        } else {
            Sign::Plus
        }
    }

    /// The other way.
    pub fn flip(self) -> Sign {
        match self {
            Sign::Plus => Sign::Minus,
            Sign::Minus => Sign::Plus,
        }
    }
}

/// How a friction contact moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Sliding with the slip velocity's sign; the friction force is `-sign mu N`.
    Slide(Sign),
    /// Stuck: the slip velocity stays zero, the friction force is what keeps it so.
    Stick,
}

impl Mode {
    /// `slides +`, `slides -` or `sticks`.
    pub fn describe(self) -> &'static str {
        match self {
            Mode::Slide(Sign::Plus) => "slides +",
            Mode::Slide(Sign::Minus) => "slides -",
            Mode::Stick => "sticks",
        }
    }
}

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

    /// `contact_force, floor_normal closed; floor_friction sticks` (`nothing closed` when no
    /// contact is).
    pub fn describe(&self, info: &ModelInfo) -> String {
        let closed = self.closed_names(info);
        let mut out = if closed.is_empty() {
            "nothing closed".to_string()
        } else {
            format!("{} closed", closed.join(", "))
        };
        let modes: Vec<String> = (info.frictions.iter().zip(&self.modes).enumerate())
            .filter(|(j, _)| self.friction_acts(info, *j))
            .map(|(_, (f, m))| format!("{} {}", f.name, m.describe()))
            .collect();
        if !modes.is_empty() {
            out.push_str("; ");
            out.push_str(&modes.join(", "));
        }
        out
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
