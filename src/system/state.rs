//! The values a model's functions take and give: a full [`State`] (coordinates and velocities
//! of one length, finite) and the [`Points`], with the checks of finiteness the other files
//! share.

use super::SystemError;

/// A full (unreduced) state: coordinates and velocities in the order of
/// [`ModelInfo::coordinates`](crate::model::ModelInfo::coordinates).
///
/// Its coordinates and velocities always have the same length, and one built by
/// [`State::new`] (or [`Bound::state`](super::Bound::state), which also checks the length
/// against a model) holds finite values only. Which model a state belongs to is not part of
/// it: every [`Bound`](super::Bound) method that takes one checks its length against the
/// model and returns
/// [`SystemError::Length`] otherwise.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    pub(crate) q: Vec<f64>,
    pub(crate) qd: Vec<f64>,
}

impl State {
    /// A state from its coordinates and velocities: as many of each, every value finite
    /// ([`SystemError::StateShape`], [`SystemError::NotFiniteInput`] otherwise).
    pub fn new(q: Vec<f64>, qd: Vec<f64>) -> Result<State, SystemError> {
        if q.len() != qd.len() {
            return Err(SystemError::StateShape {
                q: q.len(),
                qd: qd.len(),
            });
        }
        finite("q", &q)?;
        finite("qd", &qd)?;
        Ok(State { q, qd })
    }

    /// A state of `n` coordinates, all zero and at rest (filled by the model's functions).
    pub(crate) fn zeros(n: usize) -> State {
        State {
            q: vec![0.0; n],
            qd: vec![0.0; n],
        }
    }

    /// The coordinates.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// The velocities.
    pub fn qd(&self) -> &[f64] {
        &self.qd
    }

    /// The number of coordinates.
    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// Whether the state has no coordinates.
    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }

    /// The coordinates and velocities.
    pub fn into_parts(self) -> (Vec<f64>, Vec<f64>) {
        (self.q, self.qd)
    }
}

/// `Ok` when every value of `values` is finite, else the first that is not, named `what`.
pub(super) fn finite(what: &'static str, values: &[f64]) -> Result<(), SystemError> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(SystemError::NotFiniteInput {
            what,
            index,
            value: values[index],
        }),
    }
}

/// Sets `buffer` to `len` zeros, keeping its allocation.
pub(super) fn zeroed(buffer: &mut Vec<f64>, len: usize) {
    buffer.clear();
    buffer.resize(len, 0.0);
}

/// `Ok` when `value` is finite, else [`SystemError::NotFiniteInput`] naming it.
pub(super) fn finite_scalar(what: &'static str, value: f64) -> Result<(), SystemError> {
    finite(what, &[value])
}

/// Positions and velocities of every named point of a model, in the order of
/// [`ModelInfo::points`](crate::model::ModelInfo::points).
#[derive(Debug, Clone, PartialEq)]
pub struct Points {
    /// Positions `[x, y]` (m).
    pub pos: Vec<[f64; 2]>,
    /// Velocities `[vx, vy]` (m/s).
    pub vel: Vec<[f64; 2]>,
}
