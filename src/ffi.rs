//! The C ABI (cargo feature `capi`): the per-point solver of any registered model, by handle,
//! with parameters in the model's order or by name, a whole scene run once to a handle on its
//! JSON results, and the registry itself, which `rodcube_models_load` extends with the models
//! of a directory of tapes (derived models that need no compiler). `include/rodcube.h` is
//! generated from this file by cbindgen (`cbindgen.toml`; `cargo run --example c_header`
//! writes it, `tests/capi_header.rs` fails when it is stale), so the doc comments here are the
//! header's documentation: they are written for a C reader and name C functions and constants
//! plainly.
//!
//! Conventions, for every function:
//! - a function that can fail returns a status code (`RODCUBE_OK` = 0, else one of the
//!   `RODCUBE_ERR_*` codes: each kind of failure has its own, `rodcube_error_name` names it and
//!   `rodcube_error_group` gives its group), and hands back what it made through an out
//!   pointer;
//! - the message of a failure is copied into the caller's buffer `err` of `err_len` bytes
//!   (NUL-terminated, cut at a character boundary; `err` may be NULL);
//! - nothing the caller must free with its own allocator is returned: a solver handle is
//!   released by `rodcube_solver_free`, a scene's results by `rodcube_results_free`; other
//!   strings are static or copied into the caller's buffers;
//! - no panic crosses the boundary: one would be caught and reported as `RODCUBE_ERR_PANIC`.
//!
//! Architecture invariant: every error of the layers below (`SystemError`, `SolveError`,
//! `PlanError`, the scene's `Kind`, `TapeError`) maps to its code by an exhaustive `match`, so
//! a new variant does not compile until it has a code here (and thereby in the header).

use crate::model::{Model, ModelInfo};
use crate::plan::PlanError;
use crate::results::{Note, SensitivityGap};
use crate::scene::{Kind, RunError, SceneError, Source};
use crate::solve::SolveError;
use crate::solve::fast::lean::{LeanPoint, LeanSolver};
use crate::solve::fast::sensitivity::SensitivityWork;
use crate::system::{SystemError, ordered_values};
use crate::tape::TapeError;
use std::ffi::{CStr, CString, c_char, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::Mutex;

// Status codes: their numbering is described in the header's opening comment (`cbindgen.toml`).

/// Success.
pub const RODCUBE_OK: c_int = 0;
/// A NULL pointer where the call needs one: a handle, an output, a text, an out pointer, or
/// an array whose count is not zero.
pub const RODCUBE_ERR_ARGUMENT: c_int = 1;
/// No model of that name in the registry (`rodcube_solver_new`).
pub const RODCUBE_ERR_MODEL: c_int = 2;
/// The output buffer is too small; `*needed` says how large it must be.
pub const RODCUBE_ERR_BUFFER: c_int = 6;
/// An internal error: a panic, caught at the boundary (please report it).
pub const RODCUBE_ERR_PANIC: c_int = 7;
/// A text argument (a model, parameter name, scene or directory) is not UTF-8.
pub const RODCUBE_ERR_UTF8: c_int = 8;
/// The results could not be written as JSON.
pub const RODCUBE_ERR_JSON: c_int = 9;

/// Group: the parameters were refused (codes 101 to 199).
pub const RODCUBE_ERR_PARAMETERS: c_int = 100;
/// A parameter the model declares was not given (by name).
pub const RODCUBE_ERR_PARAM_MISSING: c_int = 101;
/// A name that is not one of the model's parameters.
pub const RODCUBE_ERR_PARAM_UNKNOWN: c_int = 102;
/// The same parameter given twice (by name).
pub const RODCUBE_ERR_PARAM_DUPLICATE: c_int = 103;
/// A count of values that is not the model's number of parameters.
pub const RODCUBE_ERR_PARAM_COUNT: c_int = 104;
/// A parameter that is NaN or infinite.
pub const RODCUBE_ERR_PARAM_NOT_FINITE: c_int = 105;
/// A parameter the model declares positive is zero or negative.
pub const RODCUBE_ERR_PARAM_NOT_POSITIVE: c_int = 106;
/// A friction coefficient below zero.
pub const RODCUBE_ERR_PARAM_NEGATIVE_FRICTION: c_int = 107;
/// A requirement of the model on its parameters fails (e.g. `a < ell` for `rod_cube`).
pub const RODCUBE_ERR_PARAM_REQUIREMENT: c_int = 108;
/// The model has no reduced fast path to bind the parameters to.
pub const RODCUBE_ERR_PARAM_NO_REDUCTION: c_int = 109;
/// The parameters give the model a non-finite constant (an extreme input).
pub const RODCUBE_ERR_PARAM_BAD_CONSTANT: c_int = 110;
/// A state's positions and velocities differ in length (a library caller's state).
pub const RODCUBE_ERR_PARAM_STATE_SHAPE: c_int = 111;
/// A state or vector has the wrong length for the model.
pub const RODCUBE_ERR_PARAM_LENGTH: c_int = 112;
/// A state or vector holds a NaN or an infinity.
pub const RODCUBE_ERR_PARAM_NOT_FINITE_INPUT: c_int = 113;
/// A contact's coefficient of restitution (from the parameters) outside [0, 1].
pub const RODCUBE_ERR_PARAM_RESTITUTION: c_int = 114;
/// The model's reduced coordinate is none of its coordinates (a malformed model).
pub const RODCUBE_ERR_PARAM_REDUCED_INDEX: c_int = 115;
/// The model has no partial derivatives of its dynamics (forward sensitivities need them).
pub const RODCUBE_ERR_PARAM_NO_TANGENTS: c_int = 116;

/// Group: the request was refused (codes 201 to 299).
pub const RODCUBE_ERR_REQUEST: c_int = 200;
/// A fast phase was named where a system is run: run its system.
pub const RODCUBE_ERR_NOT_A_SYSTEM: c_int = 201;
/// The model cannot provide a wanted quantity.
pub const RODCUBE_ERR_UNAVAILABLE: c_int = 202;
/// The tolerance is outside the accepted range.
pub const RODCUBE_ERR_TOLERANCE: c_int = 203;
/// Fewer than 2 samples where a series or a check is wanted.
pub const RODCUBE_ERR_TOO_FEW_SAMPLES: c_int = 204;
/// More samples per series than accepted.
pub const RODCUBE_ERR_TOO_MANY_SAMPLES: c_int = 205;
/// The run's end time (`until`) is not a positive finite time.
pub const RODCUBE_ERR_UNTIL: c_int = 206;

/// Group: a solver failed (codes 301 to 399).
pub const RODCUBE_ERR_SOLVE: c_int = 300;
/// The model does not hold a unilateral first contact closed, so it cannot separate.
pub const RODCUBE_ERR_NO_CONTACT: c_int = 301;
/// The separation polynomial is identically zero or has a non-finite coefficient.
pub const RODCUBE_ERR_BAD_POLYNOMIAL: c_int = 302;
/// No separation in the phase: the contact holds to the floor, or the polynomial's
/// coefficients under- or overflowed.
pub const RODCUBE_ERR_NO_SEPARATION: c_int = 303;
/// Released from rest where the acceleration does not make it fall.
pub const RODCUBE_ERR_NO_MOTION: c_int = 304;
/// The phase starts at or beyond the vertical.
pub const RODCUBE_ERR_BEYOND_VERTICAL: c_int = 305;
/// The initial rate makes the angle grow; phases must fall.
pub const RODCUBE_ERR_RISING: c_int = 306;
/// The angular rate reaches zero (a turning point) before the end of the phase.
pub const RODCUBE_ERR_TURNING_POINT: c_int = 307;
/// A model function returned NaN or an infinity.
pub const RODCUBE_ERR_NON_FINITE: c_int = 308;
/// The phase would end at an angle fallen that is not positive and finite.
pub const RODCUBE_ERR_BAD_PHASE_END: c_int = 309;
/// An angle outside the phase was asked of its time integral.
pub const RODCUBE_ERR_OUTSIDE_PHASE: c_int = 310;
/// The adaptive quadrature did not reach its tolerance.
pub const RODCUBE_ERR_QUADRATURE: c_int = 311;
/// The time integral could not be inverted at a time.
pub const RODCUBE_ERR_INVERSION: c_int = 312;
/// An active set whose size does not match the model's contacts or frictions.
pub const RODCUBE_ERR_ACTIVE_SIZE: c_int = 313;
/// No single consistent set of closed contacts and friction modes (a contact that would
/// have to pull, Painleve's paradox, or several sets with different motions).
pub const RODCUBE_ERR_INDETERMINATE: c_int = 314;
/// The angle reaches its end with the body above the floor (a support lifted it).
pub const RODCUBE_ERR_ABOVE_FLOOR: c_int = 315;
/// The motion from rest turns back before any contact ends: it swings for ever.
pub const RODCUBE_ERR_SWINGS: c_int = 316;
/// The supports hold the system at rest: nothing moves, so no contact ends.
pub const RODCUBE_ERR_AT_REST: c_int = 317;
/// Bodies overlap where a phase starts (a gap below zero).
pub const RODCUBE_ERR_OVERLAP: c_int = 318;
/// A contact closes with a velocity at release: an impact, not modelled.
pub const RODCUBE_ERR_IMPACT_AT_RELEASE: c_int = 319;
/// The motion does not start in the phase the per-point solver solves (another contact lets
/// go first, or would have to pull): solve the system with `rodcube_run_scene`.
pub const RODCUBE_ERR_NOT_THIS_PHASE: c_int = 320;
/// The closed contacts' constraints and the mass matrix form a singular system.
pub const RODCUBE_ERR_SINGULAR_CONTACTS: c_int = 321;
/// The friction contacts switched between sticking and sliding too often (chatter).
pub const RODCUBE_ERR_TOO_MANY_SWITCHES: c_int = 322;
/// The mass matrix could not be solved.
pub const RODCUBE_ERR_SINGULAR_MASS_MATRIX: c_int = 323;
/// The ODE's right-hand side or an event function was not finite.
pub const RODCUBE_ERR_ODE_NON_FINITE: c_int = 324;
/// The ODE's step size fell below what a double can resolve.
pub const RODCUBE_ERR_STEP_SIZE_TOO_SMALL: c_int = 325;
/// The mass matrix is too ill-conditioned for the unreduced equations to mean anything.
pub const RODCUBE_ERR_ILL_CONDITIONED: c_int = 326;
/// The ODE took too many steps.
pub const RODCUBE_ERR_TOO_MANY_STEPS: c_int = 327;
/// The ODE reached its time limit without the separation or the floor.
pub const RODCUBE_ERR_NO_EVENT: c_int = 328;
/// A quantity of the energy integral was asked where the motion does not start on a fast
/// phase.
pub const RODCUBE_ERR_NOT_ON_FAST_PATH: c_int = 329;
/// A system continues with a phase model that is not in the registry.
pub const RODCUBE_ERR_UNKNOWN_PHASE_MODEL: c_int = 330;
/// A phase model whose parameters or coordinates do not fit its system's.
pub const RODCUBE_ERR_PHASE_MISMATCH: c_int = 331;
/// The model is not for the per-point solver (its separation is not a polynomial root, or
/// its motion does not start on a fast phase): run it as a scene.
pub const RODCUBE_ERR_NOT_PER_POINT: c_int = 332;
/// Phases kept separating without reaching the floor.
pub const RODCUBE_ERR_TOO_MANY_PHASES: c_int = 333;
/// The parameters a phase hands to the next were refused.
pub const RODCUBE_ERR_NEXT_PHASE: c_int = 334;
/// A result came out NaN or infinite (a model function misbehaving).
pub const RODCUBE_ERR_RESULT_NOT_FINITE: c_int = 335;
/// A phase index past the phases of the run (a planner inconsistency).
pub const RODCUBE_ERR_NO_SUCH_PHASE: c_int = 336;
/// An impact whose impulses (Newton's law of restitution with Coulomb friction) would create
/// kinetic energy.
pub const RODCUBE_ERR_IMPACT_GAINS_ENERGY: c_int = 337;
/// Solver: the point solved, but its sensitivities do not exist there (the message says why:
/// the contact opens at release, the separation is a double root of its condition, the model
/// has no partial derivatives, ...); `rodcube_sensitivities` writes no number.
pub const RODCUBE_ERR_NO_SENSITIVITY: c_int = 338;

/// Group: the scene was refused (codes 401 to 499). A scene's message lists every problem
/// found; the code is the kind of the first, in file order. Returned alone only for a scene
/// error without a problem, which scene parsing never makes.
pub const RODCUBE_ERR_SCENE: c_int = 400;
/// Scene: the scene could not be read.
pub const RODCUBE_ERR_SCENE_READ: c_int = 401;
/// Scene: not valid YAML, a duplicate key, or an empty text.
pub const RODCUBE_ERR_SCENE_SYNTAX: c_int = 402;
/// Scene: a key that scenes do not have.
pub const RODCUBE_ERR_SCENE_UNKNOWN_KEY: c_int = 403;
/// Scene: a value of the wrong type, or a required key missing.
pub const RODCUBE_ERR_SCENE_STRUCTURE: c_int = 404;
/// Scene: a model that is not in the registry.
pub const RODCUBE_ERR_SCENE_UNKNOWN_MODEL: c_int = 405;
/// Scene: a `want` entry that no quantity of the model matches.
pub const RODCUBE_ERR_SCENE_UNKNOWN_QUANTITY: c_int = 406;
/// Scene: a quantity this model cannot provide.
pub const RODCUBE_ERR_SCENE_UNAVAILABLE_QUANTITY: c_int = 407;
/// Scene: a `want` entry listed twice.
pub const RODCUBE_ERR_SCENE_DUPLICATE_QUANTITY: c_int = 408;
/// Scene: a parameter of the model that the scene does not give.
pub const RODCUBE_ERR_SCENE_MISSING_PARAMETER: c_int = 409;
/// Scene: a parameter the model does not have.
pub const RODCUBE_ERR_SCENE_UNKNOWN_PARAMETER: c_int = 410;
/// Scene: a parameter that must be strictly positive is not.
pub const RODCUBE_ERR_SCENE_NOT_POSITIVE: c_int = 411;
/// Scene: a friction coefficient below zero.
pub const RODCUBE_ERR_SCENE_NEGATIVE_FRICTION: c_int = 412;
/// Scene: NaN or an infinity (`.nan`, `.inf`).
pub const RODCUBE_ERR_SCENE_NOT_FINITE: c_int = 413;
/// Scene: `tolerance` or `samples` outside its range, or an empty `want`.
pub const RODCUBE_ERR_SCENE_OUT_OF_RANGE: c_int = 414;
/// Scene: a requirement of the model on its parameters (e.g. `a < ell`) fails.
pub const RODCUBE_ERR_SCENE_REQUIREMENT: c_int = 415;

/// Group: a tape was refused by `rodcube_models_load` (codes 501 to 599). The message names
/// the file (and, for text that is not a tape, its line and column); nothing of the directory
/// is loaded then.
pub const RODCUBE_ERR_TAPE: c_int = 500;
/// Tape: the directory or a tape in it could not be read.
pub const RODCUBE_ERR_TAPE_READ: c_int = 501;
/// Tape: not JSON of a tape's shape (a truncated file, an unknown operation, a wrong number of
/// operands, ...).
pub const RODCUBE_ERR_TAPE_SYNTAX: c_int = 502;
/// Tape: its `format` is not `rodcube-tape`.
pub const RODCUBE_ERR_TAPE_FORMAT: c_int = 503;
/// Tape: written in another version of the format; derive it again from its spec.
pub const RODCUBE_ERR_TAPE_VERSION: c_int = 504;
/// Tape: its body does not match the digest it records (edited by hand).
pub const RODCUBE_ERR_TAPE_DIGEST: c_int = 505;
/// Tape: the model's description (`body.info`) is inconsistent (a name that is not an
/// identifier, a parameter named twice, an index past its list).
pub const RODCUBE_ERR_TAPE_INFO: c_int = 506;
/// Tape: a method's program is refused (unknown, missing, given twice, or one that could read
/// out of bounds or a register not yet written).
pub const RODCUBE_ERR_TAPE_METHOD: c_int = 507;

/// Every status code with its name, for `rodcube_error_name` and `rodcube_error_group`.
macro_rules! named {
    ($($code:ident),* $(,)?) => {
        &[$(($code, match CStr::from_bytes_with_nul(concat!(stringify!($code), "\0").as_bytes()) {
            Ok(name) => name,
            Err(_) => c"",
        })),*]
    };
}

/// The status codes and their names, in the order of the header.
static CODES: &[(c_int, &CStr)] = named![
    RODCUBE_OK,
    RODCUBE_ERR_ARGUMENT,
    RODCUBE_ERR_MODEL,
    RODCUBE_ERR_BUFFER,
    RODCUBE_ERR_PANIC,
    RODCUBE_ERR_UTF8,
    RODCUBE_ERR_JSON,
    RODCUBE_ERR_PARAMETERS,
    RODCUBE_ERR_PARAM_MISSING,
    RODCUBE_ERR_PARAM_UNKNOWN,
    RODCUBE_ERR_PARAM_DUPLICATE,
    RODCUBE_ERR_PARAM_COUNT,
    RODCUBE_ERR_PARAM_NOT_FINITE,
    RODCUBE_ERR_PARAM_NOT_POSITIVE,
    RODCUBE_ERR_PARAM_NEGATIVE_FRICTION,
    RODCUBE_ERR_PARAM_REQUIREMENT,
    RODCUBE_ERR_PARAM_NO_REDUCTION,
    RODCUBE_ERR_PARAM_BAD_CONSTANT,
    RODCUBE_ERR_PARAM_STATE_SHAPE,
    RODCUBE_ERR_PARAM_LENGTH,
    RODCUBE_ERR_PARAM_NOT_FINITE_INPUT,
    RODCUBE_ERR_PARAM_RESTITUTION,
    RODCUBE_ERR_PARAM_REDUCED_INDEX,
    RODCUBE_ERR_PARAM_NO_TANGENTS,
    RODCUBE_ERR_REQUEST,
    RODCUBE_ERR_NOT_A_SYSTEM,
    RODCUBE_ERR_UNAVAILABLE,
    RODCUBE_ERR_TOLERANCE,
    RODCUBE_ERR_TOO_FEW_SAMPLES,
    RODCUBE_ERR_TOO_MANY_SAMPLES,
    RODCUBE_ERR_UNTIL,
    RODCUBE_ERR_SOLVE,
    RODCUBE_ERR_NO_CONTACT,
    RODCUBE_ERR_BAD_POLYNOMIAL,
    RODCUBE_ERR_NO_SEPARATION,
    RODCUBE_ERR_NO_MOTION,
    RODCUBE_ERR_BEYOND_VERTICAL,
    RODCUBE_ERR_RISING,
    RODCUBE_ERR_TURNING_POINT,
    RODCUBE_ERR_NON_FINITE,
    RODCUBE_ERR_BAD_PHASE_END,
    RODCUBE_ERR_OUTSIDE_PHASE,
    RODCUBE_ERR_QUADRATURE,
    RODCUBE_ERR_INVERSION,
    RODCUBE_ERR_ACTIVE_SIZE,
    RODCUBE_ERR_INDETERMINATE,
    RODCUBE_ERR_ABOVE_FLOOR,
    RODCUBE_ERR_SWINGS,
    RODCUBE_ERR_AT_REST,
    RODCUBE_ERR_OVERLAP,
    RODCUBE_ERR_IMPACT_AT_RELEASE,
    RODCUBE_ERR_NOT_THIS_PHASE,
    RODCUBE_ERR_SINGULAR_CONTACTS,
    RODCUBE_ERR_TOO_MANY_SWITCHES,
    RODCUBE_ERR_SINGULAR_MASS_MATRIX,
    RODCUBE_ERR_ODE_NON_FINITE,
    RODCUBE_ERR_STEP_SIZE_TOO_SMALL,
    RODCUBE_ERR_ILL_CONDITIONED,
    RODCUBE_ERR_TOO_MANY_STEPS,
    RODCUBE_ERR_NO_EVENT,
    RODCUBE_ERR_NOT_ON_FAST_PATH,
    RODCUBE_ERR_UNKNOWN_PHASE_MODEL,
    RODCUBE_ERR_PHASE_MISMATCH,
    RODCUBE_ERR_NOT_PER_POINT,
    RODCUBE_ERR_TOO_MANY_PHASES,
    RODCUBE_ERR_NEXT_PHASE,
    RODCUBE_ERR_RESULT_NOT_FINITE,
    RODCUBE_ERR_NO_SUCH_PHASE,
    RODCUBE_ERR_IMPACT_GAINS_ENERGY,
    RODCUBE_ERR_NO_SENSITIVITY,
    RODCUBE_ERR_SCENE,
    RODCUBE_ERR_SCENE_READ,
    RODCUBE_ERR_SCENE_SYNTAX,
    RODCUBE_ERR_SCENE_UNKNOWN_KEY,
    RODCUBE_ERR_SCENE_STRUCTURE,
    RODCUBE_ERR_SCENE_UNKNOWN_MODEL,
    RODCUBE_ERR_SCENE_UNKNOWN_QUANTITY,
    RODCUBE_ERR_SCENE_UNAVAILABLE_QUANTITY,
    RODCUBE_ERR_SCENE_DUPLICATE_QUANTITY,
    RODCUBE_ERR_SCENE_MISSING_PARAMETER,
    RODCUBE_ERR_SCENE_UNKNOWN_PARAMETER,
    RODCUBE_ERR_SCENE_NOT_POSITIVE,
    RODCUBE_ERR_SCENE_NEGATIVE_FRICTION,
    RODCUBE_ERR_SCENE_NOT_FINITE,
    RODCUBE_ERR_SCENE_OUT_OF_RANGE,
    RODCUBE_ERR_SCENE_REQUIREMENT,
    RODCUBE_ERR_TAPE,
    RODCUBE_ERR_TAPE_READ,
    RODCUBE_ERR_TAPE_SYNTAX,
    RODCUBE_ERR_TAPE_FORMAT,
    RODCUBE_ERR_TAPE_VERSION,
    RODCUBE_ERR_TAPE_DIGEST,
    RODCUBE_ERR_TAPE_INFO,
    RODCUBE_ERR_TAPE_METHOD,
];

/// The code of a refused parameter set.
fn system_code(e: &SystemError) -> c_int {
    match e {
        SystemError::MissingParameter { .. } => RODCUBE_ERR_PARAM_MISSING,
        SystemError::UnknownParameter { .. } => RODCUBE_ERR_PARAM_UNKNOWN,
        SystemError::DuplicateParameter { .. } => RODCUBE_ERR_PARAM_DUPLICATE,
        SystemError::WrongCount { .. } => RODCUBE_ERR_PARAM_COUNT,
        SystemError::NotFinite { .. } => RODCUBE_ERR_PARAM_NOT_FINITE,
        SystemError::NotPositive { .. } => RODCUBE_ERR_PARAM_NOT_POSITIVE,
        SystemError::NegativeFriction { .. } => RODCUBE_ERR_PARAM_NEGATIVE_FRICTION,
        SystemError::Requirement { .. } => RODCUBE_ERR_PARAM_REQUIREMENT,
        SystemError::NoReduction { .. } => RODCUBE_ERR_PARAM_NO_REDUCTION,
        SystemError::BadConstant { .. } => RODCUBE_ERR_PARAM_BAD_CONSTANT,
        SystemError::StateShape { .. } => RODCUBE_ERR_PARAM_STATE_SHAPE,
        SystemError::Length { .. } => RODCUBE_ERR_PARAM_LENGTH,
        SystemError::NotFiniteInput { .. } => RODCUBE_ERR_PARAM_NOT_FINITE_INPUT,
        SystemError::Restitution { .. } => RODCUBE_ERR_PARAM_RESTITUTION,
        SystemError::ReducedIndex { .. } => RODCUBE_ERR_PARAM_REDUCED_INDEX,
        SystemError::NoTangents { .. } => RODCUBE_ERR_PARAM_NO_TANGENTS,
        SystemError::NoReducedCoordinate { .. }
        | SystemError::NoEndAngle { .. }
        | SystemError::NoFallingPoint { .. } => RODCUBE_ERR_PARAM_NO_REDUCTION,
    }
}

/// The code of a solver's failure: the parameters' own code for refused parameters.
fn solve_code(e: &SolveError) -> c_int {
    match e {
        SolveError::System(_) => RODCUBE_ERR_NEXT_PHASE,
        SolveError::Parameters(e) | SolveError::Input(e) => system_code(e),
        SolveError::NoSuchPhase { .. } => RODCUBE_ERR_NO_SUCH_PHASE,
        SolveError::NoContact { .. } => RODCUBE_ERR_NO_CONTACT,
        SolveError::BadPolynomial { .. } => RODCUBE_ERR_BAD_POLYNOMIAL,
        SolveError::NoSeparation { .. } => RODCUBE_ERR_NO_SEPARATION,
        SolveError::NoMotion { .. } => RODCUBE_ERR_NO_MOTION,
        SolveError::BeyondVertical { .. } => RODCUBE_ERR_BEYOND_VERTICAL,
        SolveError::Rising { .. } => RODCUBE_ERR_RISING,
        SolveError::TurningPoint { .. } => RODCUBE_ERR_TURNING_POINT,
        SolveError::NonFinite { .. } => RODCUBE_ERR_NON_FINITE,
        SolveError::BadPhaseEnd { .. } => RODCUBE_ERR_BAD_PHASE_END,
        SolveError::OutsidePhase { .. } => RODCUBE_ERR_OUTSIDE_PHASE,
        SolveError::QuadratureNotConverged { .. } => RODCUBE_ERR_QUADRATURE,
        SolveError::Inversion { .. } => RODCUBE_ERR_INVERSION,
        SolveError::ActiveSize { .. } => RODCUBE_ERR_ACTIVE_SIZE,
        SolveError::Indeterminate { .. } => RODCUBE_ERR_INDETERMINATE,
        SolveError::AboveFloor { .. } => RODCUBE_ERR_ABOVE_FLOOR,
        SolveError::Swings { .. } => RODCUBE_ERR_SWINGS,
        SolveError::AtRest { .. } => RODCUBE_ERR_AT_REST,
        SolveError::Overlap { .. } => RODCUBE_ERR_OVERLAP,
        SolveError::ImpactAtRelease { .. } => RODCUBE_ERR_IMPACT_AT_RELEASE,
        SolveError::ImpactGainsEnergy { .. } => RODCUBE_ERR_IMPACT_GAINS_ENERGY,
        SolveError::NotThisPhase { .. } => RODCUBE_ERR_NOT_THIS_PHASE,
        SolveError::SingularContacts { .. } => RODCUBE_ERR_SINGULAR_CONTACTS,
        SolveError::TooManySwitches { .. } => RODCUBE_ERR_TOO_MANY_SWITCHES,
        SolveError::SingularMassMatrix { .. } => RODCUBE_ERR_SINGULAR_MASS_MATRIX,
        SolveError::OdeNonFinite { .. } => RODCUBE_ERR_ODE_NON_FINITE,
        SolveError::StepSizeTooSmall { .. } => RODCUBE_ERR_STEP_SIZE_TOO_SMALL,
        SolveError::IllConditioned { .. } => RODCUBE_ERR_ILL_CONDITIONED,
        SolveError::TooManySteps { .. } => RODCUBE_ERR_TOO_MANY_STEPS,
        SolveError::NoEvent { .. } => RODCUBE_ERR_NO_EVENT,
        SolveError::NotOnFastPath { .. } => RODCUBE_ERR_NOT_ON_FAST_PATH,
        SolveError::UnknownPhaseModel { .. } => RODCUBE_ERR_UNKNOWN_PHASE_MODEL,
        SolveError::PhaseMismatch { .. } => RODCUBE_ERR_PHASE_MISMATCH,
        SolveError::NotPerPoint { .. } => RODCUBE_ERR_NOT_PER_POINT,
        SolveError::TooManyPhases { .. } => RODCUBE_ERR_TOO_MANY_PHASES,
        SolveError::TooFewSamples { .. } => RODCUBE_ERR_TOO_FEW_SAMPLES,
    }
}

/// The code of a planner's refusal or failure.
fn plan_code(e: &PlanError) -> c_int {
    match e {
        PlanError::UnknownModel { .. } => RODCUBE_ERR_MODEL,
        PlanError::NotASystem { .. } => RODCUBE_ERR_NOT_A_SYSTEM,
        PlanError::Unavailable { .. } => RODCUBE_ERR_UNAVAILABLE,
        PlanError::BadTolerance { .. } => RODCUBE_ERR_TOLERANCE,
        PlanError::TooFewSamples { .. } => RODCUBE_ERR_TOO_FEW_SAMPLES,
        PlanError::TooManySamples { .. } => RODCUBE_ERR_TOO_MANY_SAMPLES,
        PlanError::BadUntil { .. } => RODCUBE_ERR_UNTIL,
        PlanError::System(e) => system_code(e),
        PlanError::Solve(e) => solve_code(e),
        PlanError::NonFinite { .. } => RODCUBE_ERR_RESULT_NOT_FINITE,
    }
}

/// The code of one kind of scene problem.
fn scene_kind_code(kind: Kind) -> c_int {
    match kind {
        Kind::Read => RODCUBE_ERR_SCENE_READ,
        Kind::Syntax => RODCUBE_ERR_SCENE_SYNTAX,
        Kind::UnknownKey => RODCUBE_ERR_SCENE_UNKNOWN_KEY,
        Kind::Structure => RODCUBE_ERR_SCENE_STRUCTURE,
        Kind::UnknownModel => RODCUBE_ERR_SCENE_UNKNOWN_MODEL,
        Kind::UnknownQuantity => RODCUBE_ERR_SCENE_UNKNOWN_QUANTITY,
        Kind::UnavailableQuantity => RODCUBE_ERR_SCENE_UNAVAILABLE_QUANTITY,
        Kind::DuplicateQuantity => RODCUBE_ERR_SCENE_DUPLICATE_QUANTITY,
        Kind::MissingParameter => RODCUBE_ERR_SCENE_MISSING_PARAMETER,
        Kind::UnknownParameter => RODCUBE_ERR_SCENE_UNKNOWN_PARAMETER,
        Kind::NotPositive => RODCUBE_ERR_SCENE_NOT_POSITIVE,
        Kind::NegativeFriction => RODCUBE_ERR_SCENE_NEGATIVE_FRICTION,
        Kind::NotFinite => RODCUBE_ERR_SCENE_NOT_FINITE,
        Kind::OutOfRange => RODCUBE_ERR_SCENE_OUT_OF_RANGE,
        Kind::Requirement => RODCUBE_ERR_SCENE_REQUIREMENT,
    }
}

/// The code of a refused tape.
fn tape_code(e: &TapeError) -> c_int {
    match e {
        TapeError::Io { .. } => RODCUBE_ERR_TAPE_READ,
        TapeError::Syntax { .. } => RODCUBE_ERR_TAPE_SYNTAX,
        TapeError::Format { .. } => RODCUBE_ERR_TAPE_FORMAT,
        TapeError::Version { .. } => RODCUBE_ERR_TAPE_VERSION,
        TapeError::Digest { .. } => RODCUBE_ERR_TAPE_DIGEST,
        TapeError::Info { .. } => RODCUBE_ERR_TAPE_INFO,
        TapeError::Method { .. } => RODCUBE_ERR_TAPE_METHOD,
    }
}

/// One point's separation, as the per-point solver returns it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RodcubePoint {
    /// `theta_sep` (rad).
    pub separation_angle: f64,
    /// Time from release to separation (s).
    pub separation_time: f64,
    /// `theta_i - theta_sep` (rad).
    pub delta: f64,
}

/// A per-point solver of one model (opaque): made by `rodcube_solver_new`, released by
/// `rodcube_solver_free`.
pub struct RodcubeSolver {
    solver: LeanSolver<'static>,
    /// Scratch for parameters given by name.
    values: Vec<f64>,
    /// Scratch of `rodcube_sensitivities`, kept across points: the sensitivities before they
    /// are known to exist, then the integrals' buffers.
    sens: Vec<f64>,
    work: SensitivityWork,
}

/// A scene's results (opaque): the text of its `results.json`, made once by
/// `rodcube_run_scene`, read by `rodcube_results_json`, `rodcube_results_len` and
/// `rodcube_results_copy` (which never solve again), released by `rodcube_results_free`.
pub struct RodcubeResults {
    json: CString,
}

/// A failure: its code and message.
struct Failure(c_int, String);

fn failure(code: c_int, message: impl Into<String>) -> Failure {
    Failure(code, message.into())
}

impl From<SystemError> for Failure {
    fn from(e: SystemError) -> Self {
        Failure(system_code(&e), e.to_string())
    }
}

impl From<SolveError> for Failure {
    fn from(e: SolveError) -> Self {
        Failure(solve_code(&e), e.to_string())
    }
}

impl From<PlanError> for Failure {
    fn from(e: PlanError) -> Self {
        Failure(plan_code(&e), e.to_string())
    }
}

impl From<TapeError> for Failure {
    fn from(e: TapeError) -> Self {
        Failure(tape_code(&e), e.to_string())
    }
}

impl From<SensitivityGap> for Failure {
    fn from(gap: SensitivityGap) -> Self {
        let message = crate::report::prose::note(&Note::NoSensitivity(gap));
        Failure(RODCUBE_ERR_NO_SENSITIVITY, message)
    }
}

impl From<RunError> for Failure {
    fn from(e: RunError) -> Self {
        match e {
            RunError::Scene(e) => e.into(),
            RunError::Solve { error, .. } => error.into(),
        }
    }
}

impl From<SceneError> for Failure {
    fn from(e: SceneError) -> Self {
        let code = e
            .diagnostics
            .first()
            .map_or(RODCUBE_ERR_SCENE, |d| scene_kind_code(d.kind));
        Failure(code, e.to_string())
    }
}

/// Copies `message` into `err` (NUL-terminated, cut at a character boundary).
///
/// # Safety
/// `err` is NULL or points to `err_len` writable bytes.
unsafe fn write_message(err: *mut c_char, err_len: usize, message: &str) {
    if err.is_null() || err_len == 0 {
        return;
    }
    let mut n = message.len().min(err_len - 1);
    while !message.is_char_boundary(n) {
        n -= 1;
    }
    // SAFETY: the caller gives `err_len` writable bytes; `n < err_len`.
    unsafe {
        std::ptr::copy_nonoverlapping(message.as_ptr(), err.cast::<u8>(), n);
        *err.add(n) = 0;
    }
}

/// Runs `body`, turning a failure or a panic into its code and message.
///
/// # Safety
/// As [`write_message`].
unsafe fn guarded(
    err: *mut c_char,
    err_len: usize,
    body: impl FnOnce() -> Result<(), Failure>,
) -> c_int {
    let outcome = catch_unwind(AssertUnwindSafe(body)).unwrap_or_else(|_| {
        Err(failure(
            RODCUBE_ERR_PANIC,
            "internal error: rodcube panicked (please report it)",
        ))
    });
    match outcome {
        Ok(()) => {
            // SAFETY: forwarded from the caller.
            unsafe { write_message(err, err_len, "") };
            RODCUBE_OK
        }
        Err(Failure(code, message)) => {
            // SAFETY: forwarded from the caller.
            unsafe { write_message(err, err_len, &message) };
            code
        }
    }
}

/// A C string argument as `&str`.
///
/// # Safety
/// `s` is NULL or a NUL-terminated string that lives for `'a`.
unsafe fn text<'a>(s: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if s.is_null() {
        return Err(failure(RODCUBE_ERR_ARGUMENT, format!("{what} is NULL")));
    }
    // SAFETY: the caller gives a NUL-terminated string.
    unsafe { CStr::from_ptr(s) }
        .to_str()
        .map_err(|e| failure(RODCUBE_ERR_UTF8, format!("{what} is not UTF-8: {e}")))
}

/// A NULL pointer with a count above zero is refused by name.
fn counted<T>(p: *const T, n: usize, what: &str) -> Result<(), Failure> {
    if n > 0 && p.is_null() {
        return Err(failure(
            RODCUBE_ERR_ARGUMENT,
            format!("{what} is NULL with a count of {n}"),
        ));
    }
    Ok(())
}

/// `n` values at `p` as a slice (empty for `n == 0`, whatever `p`).
///
/// # Safety
/// For `n > 0`, `p` points to `n` readable values of `T`.
unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], Failure> {
    counted(p, n, what)?;
    if n == 0 {
        return Ok(&[]);
    }
    // SAFETY: the caller gives `n` readable values.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// `n` writable values at `p` as a slice (empty for `n == 0`, whatever `p`).
///
/// # Safety
/// For `n > 0`, `p` points to `n` writable values of `T`, not aliased by other arguments.
unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> Result<&'a mut [T], Failure> {
    counted(p.cast_const(), n, what)?;
    if n == 0 {
        return Ok(&mut []);
    }
    // SAFETY: the caller gives `n` writable values.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// The place behind an out pointer, set to NULL (what a failure leaves there).
///
/// # Safety
/// `out` is NULL or points to one writable pointer.
unsafe fn out_handle<'a, T>(out: *mut *mut T, what: &str) -> Result<&'a mut *mut T, Failure> {
    // SAFETY: as the caller promises.
    let slot = unsafe { out.as_mut() }
        .ok_or_else(|| failure(RODCUBE_ERR_ARGUMENT, format!("{what} is NULL")))?;
    *slot = std::ptr::null_mut();
    Ok(slot)
}

/// The solver behind a handle.
///
/// # Safety
/// `solver` is NULL or a live pointer from [`rodcube_solver_new`].
unsafe fn solver_mut<'a>(solver: *mut RodcubeSolver) -> Result<&'a mut RodcubeSolver, Failure> {
    // SAFETY: as the caller promises.
    unsafe { solver.as_mut() }.ok_or_else(|| failure(RODCUBE_ERR_ARGUMENT, "the solver is NULL"))
}

/// The caller's output.
///
/// # Safety
/// `out` is NULL or points to one writable [`RodcubePoint`].
unsafe fn output<'a>(out: *mut RodcubePoint) -> Result<&'a mut RodcubePoint, Failure> {
    // SAFETY: as the caller promises.
    unsafe { out.as_mut() }.ok_or_else(|| failure(RODCUBE_ERR_ARGUMENT, "the output is NULL"))
}

impl From<LeanPoint> for RodcubePoint {
    fn from(point: LeanPoint) -> Self {
        RodcubePoint {
            separation_angle: point.separation_angle,
            separation_time: point.separation_time,
            delta: point.delta(),
        }
    }
}

fn find_model(name: &str) -> Result<&'static dyn Model, Failure> {
    crate::models::find(name).ok_or_else(|| {
        let names: Vec<&str> = crate::models::all().iter().map(|m| m.info().name).collect();
        failure(
            RODCUBE_ERR_MODEL,
            format!("no model `{name}`; there are: {}", names.join(", ")),
        )
    })
}

/// A model's name and its parameters' names as C strings.
struct CNames {
    name: CString,
    parameters: Vec<CString>,
}

impl CNames {
    fn of(info: &ModelInfo) -> CNames {
        let c = |s: &str| CString::new(s).unwrap_or_default();
        CNames {
            name: c(info.name),
            parameters: info.parameters.iter().map(|p| c(p.name)).collect(),
        }
    }

    fn names(&self, info: &ModelInfo) -> bool {
        self.name.as_bytes() == info.name.as_bytes()
            && self.parameters.len() == info.parameters.len()
            && (self.parameters.iter().zip(info.parameters))
                .all(|(c, p)| c.as_bytes() == p.name.as_bytes())
    }
}

/// The names of the model at index `model` of the registry as it is now, made once per
/// distinct list of names and kept for the program's life: a pointer handed out stays valid
/// when `rodcube_models_load` later adds models or puts a tape in a model's place.
fn names(model: usize) -> Option<&'static CNames> {
    static MADE: Mutex<Vec<&'static CNames>> = Mutex::new(Vec::new());
    let info = crate::models::all().get(model)?.info();
    let mut made = MADE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(n) = made.iter().find(|n| n.names(info)) {
        return Some(n);
    }
    let leaked: &'static CNames = Box::leak(Box::new(CNames::of(info)));
    made.push(leaked);
    Some(leaked)
}

/// The name of status code `code` as the header spells it (`"RODCUBE_ERR_AT_REST"`, static
/// storage), or NULL for a number that is no code.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_error_name(code: c_int) -> *const c_char {
    CODES
        .iter()
        .find(|(c, _)| *c == code)
        .map_or(std::ptr::null(), |(_, name)| name.as_ptr())
}

/// The group of status code `code`: `RODCUBE_ERR_PARAMETERS`, `RODCUBE_ERR_REQUEST`,
/// `RODCUBE_ERR_SOLVE`, `RODCUBE_ERR_SCENE` or `RODCUBE_ERR_TAPE` for the codes of a group
/// (the group's own code included), the code itself for the others below 100 (`RODCUBE_OK`
/// included), -1 for a number that is no code.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_error_group(code: c_int) -> c_int {
    if rodcube_error_name(code).is_null() {
        -1
    } else if code < 100 {
        code
    } else {
        code - code % 100
    }
}

/// How many models are registered: those compiled into the library and those
/// `rodcube_models_load` added. Indices of the functions below run from 0 to this count
/// minus 1 and stay valid: a load appends the models it adds, and a model a tape replaces
/// keeps its index.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_model_count() -> usize {
    catch_unwind(|| crate::models::all().len()).unwrap_or(0)
}

/// The name of model `model` (an index below `rodcube_model_count()`; static storage), or
/// NULL past the end.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_model_name(model: usize) -> *const c_char {
    catch_unwind(|| names(model).map_or(std::ptr::null(), |n| n.name.as_ptr()))
        .unwrap_or(std::ptr::null())
}

/// How many parameters model `model` (an index) takes; 0 past the end.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_parameter_count(model: usize) -> usize {
    catch_unwind(|| names(model).map_or(0, |n| n.parameters.len())).unwrap_or(0)
}

/// The name of parameter `parameter` of model `model` (indices; static storage), in the
/// order `rodcube_solve` takes the values, or NULL past the end.
#[unsafe(no_mangle)]
pub extern "C" fn rodcube_parameter_name(model: usize, parameter: usize) -> *const c_char {
    catch_unwind(|| {
        names(model)
            .and_then(|n| n.parameters.get(parameter))
            .map_or(std::ptr::null(), |p| p.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// Loads every tape of the directory `dir` (its `*.tape.json` files, as `rodcube derive
/// --tapes-into DIR SPEC` or `cargo derive` writes them) into the registry, so that the models
/// they hold run at once, with no compiler: after it `rodcube_model_count` and
/// `rodcube_model_name` list them, `rodcube_solver_new` makes their per-point solvers and
/// `rodcube_run_scene` runs scenes that name them (the results' notes say the model ran from
/// its tape). A model not compiled into the library is added after the others; a tape of a
/// compiled model whose program differs (its spec was changed and derived again) takes its
/// place; a tape that holds a compiled model's own program is checked and the compiled code
/// kept. `*n_models`, when `n_models` is not NULL, gets the number of models the directory's
/// tapes hold (0 on failure). Loading the same directory again changes nothing.
///
/// Every tape is checked before anything runs: a tape refused fails the whole load with a
/// `RODCUBE_ERR_TAPE_*` code (a directory or file that cannot be read, text that is not a
/// tape, another format version, a body that does not match its digest, ...) and a message
/// naming the file, and nothing of the directory is loaded.
///
/// # Safety
/// `dir` is a NUL-terminated string (a path); `n_models` is NULL or points to a writable
/// `size_t`; `err` is NULL or points to `err_len` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_models_load(
    dir: *const c_char,
    n_models: *mut usize,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            if let Some(n) = n_models.as_mut() {
                *n = 0;
            }
            let dir = text(dir, "the directory")?;
            let loaded = crate::models::load(Path::new(dir))?;
            if let Some(n) = n_models.as_mut() {
                *n = loaded.models.len() + loaded.same_as_compiled.len();
            }
            Ok(())
        })
    }
}

/// Makes a per-point solver for the model named `model` into `*solver` (NULL on failure).
/// Release it with `rodcube_solver_free`. Fails with `RODCUBE_ERR_MODEL` for a name not in the
/// registry, and with `RODCUBE_ERR_NOT_PER_POINT` or `RODCUBE_ERR_NO_CONTACT` for a model the
/// per-point solver cannot solve (run it as a scene).
///
/// # Safety
/// `model` is a NUL-terminated string; `solver` points to a writable pointer; `err` is NULL
/// or points to `err_len` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_solver_new(
    model: *const c_char,
    solver: *mut *mut RodcubeSolver,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let slot = out_handle(solver, "the solver's out pointer")?;
            let m = find_model(text(model, "the model name")?)?;
            let lean = LeanSolver::new(m)?;
            *slot = Box::into_raw(Box::new(RodcubeSolver {
                solver: lean,
                values: vec![0.0; m.info().parameters.len()],
                sens: Vec::new(),
                work: SensitivityWork::default(),
            }));
            Ok(())
        })
    }
}

/// Releases a solver (NULL is ignored).
///
/// # Safety
/// `solver` is NULL or a pointer from `rodcube_solver_new` not yet released.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_solver_free(solver: *mut RodcubeSolver) {
    if !solver.is_null() {
        // SAFETY: made by `Box::into_raw` in `rodcube_solver_new`, released once.
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(solver) })));
    }
}

/// Solves one point: `n_params` values in the model's parameter order
/// (`rodcube_parameter_name`). Writes `*out` on success. Refused parameters fail with their
/// `RODCUBE_ERR_PARAM_*` code, a failed solve with its code from the solver group.
///
/// # Safety
/// `solver` comes from `rodcube_solver_new`; `params` points to `n_params` values; `out` to
/// one writable `rodcube_point`; `err` is NULL or points to `err_len` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_solve(
    solver: *mut RodcubeSolver,
    params: *const f64,
    n_params: usize,
    out: *mut RodcubePoint,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let s = solver_mut(solver)?;
            let out = output(out)?;
            let p = slice(params, n_params, "the parameters")?;
            *out = s.solver.solve(p)?.into();
            Ok(())
        })
    }
}

/// Solves one point with its parameters by name: `names[i]` is given `values[i]`, each of
/// the model's parameters exactly once, in any order.
///
/// # Safety
/// As `rodcube_solve`; `names` points to `n` NUL-terminated strings and `values` to `n`
/// values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_solve_named(
    solver: *mut RodcubeSolver,
    names: *const *const c_char,
    values: *const f64,
    n: usize,
    out: *mut RodcubePoint,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let s = solver_mut(solver)?;
            let given = slice(names, n, "the names")?;
            let vals = slice(values, n, "the values")?;
            let mut pairs = Vec::with_capacity(n);
            for (i, (&name, &value)) in given.iter().zip(vals).enumerate() {
                pairs.push((text(name, &format!("name {i}"))?, value));
            }
            ordered_values(s.solver.model().info(), &pairs, &mut s.values)?;
            let out = output(out)?;
            *out = s.solver.solve(&s.values)?.into();
            Ok(())
        })
    }
}

/// Solves one point as `rodcube_solve` does (`params`: `n_params` values in the model's
/// order; `*out`, when `out` is not NULL, gets the point) and writes its exact sensitivities:
/// `d_angle[i]` = d(separation_angle)/d(parameter i) (rad over the parameter's unit) and
/// `d_time[i]` = d(separation_time)/d(parameter i) (s over the parameter's unit), each array
/// `n_out` values long, `n_out` the model's parameter count (`rodcube_parameter_count`). They
/// are the numbers of a scene's `want: [sensitivities]` and of `rodcube sweep
/// --sensitivities`. Where the point solves but its sensitivities do not exist (the contact
/// opens at release, a double root, ...) it fails with `RODCUBE_ERR_NO_SENSITIVITY`, `*out`
/// written and the arrays left as they were; `n_out` other than the parameter count fails with
/// `RODCUBE_ERR_PARAM_LENGTH`; other failures are `rodcube_solve`'s.
///
/// # Safety
/// As `rodcube_solve`, with `out` NULL or pointing to one writable `rodcube_point`, and
/// `d_angle` and `d_time` each pointing to `n_out` writable values.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn rodcube_sensitivities(
    solver: *mut RodcubeSolver,
    params: *const f64,
    n_params: usize,
    out: *mut RodcubePoint,
    d_angle: *mut f64,
    d_time: *mut f64,
    n_out: usize,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let s = solver_mut(solver)?;
            let p = slice(params, n_params, "the parameters")?;
            let angle = slice_mut(d_angle, n_out, "d_angle")?;
            let time = slice_mut(d_time, n_out, "d_time")?;
            let point = s.solver.solve(p)?;
            if let Some(out) = out.as_mut() {
                *out = point.into();
            }
            // Into scratch first: a gap leaves the caller's arrays as they were.
            s.sens.resize(2 * n_out, 0.0);
            let (a, t) = s.sens.split_at_mut(n_out);
            s.solver.sensitivities(p, &point, &mut s.work, a, t)??;
            angle.copy_from_slice(a);
            time.copy_from_slice(t);
            Ok(())
        })
    }
}

/// Runs a scene given as YAML text (the format of the files in `scenes/`) once, and makes its
/// results (the `results.json` of `rodcube run`) into `*results` (NULL on failure): read them
/// with `rodcube_results_json`, `rodcube_results_len` or `rodcube_results_copy`, as often as
/// wanted without solving again, and release them with `rodcube_results_free`. A refused
/// scene fails with a `RODCUBE_ERR_SCENE_*` code (the kind of its first problem; the message
/// lists every problem with its line and column; a planner refusal of one of the scene's
/// values is placed at its field the same way), a failed solve with its code from the
/// solver group. The run is the one `rodcube run` makes.
///
/// # Safety
/// `scene_yaml` is a NUL-terminated string; `results` points to a writable pointer; `err` is
/// NULL or points to `err_len` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_run_scene(
    scene_yaml: *const c_char,
    results: *mut *mut RodcubeResults,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let slot = out_handle(results, "the results' out pointer")?;
            let yaml = text(scene_yaml, "the scene")?;
            let (_, run) = crate::scene::run(Source::Text {
                text: yaml,
                file: Path::new("<scene>"),
            })?;
            let json = crate::report::json::to_string(&run)
                .map_err(|e| failure(RODCUBE_ERR_JSON, e.to_string()))?;
            let json = CString::new(json).map_err(|e| failure(RODCUBE_ERR_JSON, e.to_string()))?;
            *slot = Box::into_raw(Box::new(RodcubeResults { json }));
            Ok(())
        })
    }
}

/// The results' JSON text, NUL-terminated, owned by `results` and valid until
/// `rodcube_results_free`; NULL for NULL.
///
/// # Safety
/// `results` is NULL or a live pointer from `rodcube_run_scene`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_results_json(results: *const RodcubeResults) -> *const c_char {
    // SAFETY: as the caller promises.
    unsafe { results.as_ref() }.map_or(std::ptr::null(), |r| r.json.as_ptr())
}

/// The length of the results' JSON text in bytes, without its NUL (as `strlen`); 0 for NULL.
///
/// # Safety
/// `results` is NULL or a live pointer from `rodcube_run_scene`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_results_len(results: *const RodcubeResults) -> usize {
    // SAFETY: as the caller promises.
    unsafe { results.as_ref() }.map_or(0, |r| r.json.as_bytes().len())
}

/// Copies the results' JSON text, NUL-terminated, into `json` of `json_len` bytes. Sets
/// `*needed` (when not NULL) to the bytes required, NUL included, and returns
/// `RODCUBE_ERR_BUFFER` when `json_len` is smaller (`json` may then be NULL).
///
/// # Safety
/// `results` is NULL or a live pointer from `rodcube_run_scene`; `json` is NULL or points to
/// `json_len` writable bytes; `needed` is NULL or points to a writable `size_t`; `err` is
/// NULL or points to `err_len` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_results_copy(
    results: *const RodcubeResults,
    json: *mut c_char,
    json_len: usize,
    needed: *mut usize,
    err: *mut c_char,
    err_len: usize,
) -> c_int {
    // SAFETY: forwarded from the caller.
    unsafe {
        guarded(err, err_len, || {
            let r = results
                .as_ref()
                .ok_or_else(|| failure(RODCUBE_ERR_ARGUMENT, "the results are NULL"))?;
            let text = r.json.as_bytes_with_nul();
            if let Some(n) = needed.as_mut() {
                *n = text.len();
            }
            if json.is_null() || json_len < text.len() {
                return Err(failure(
                    RODCUBE_ERR_BUFFER,
                    format!(
                        "the results need {} bytes; the buffer has {json_len}",
                        text.len()
                    ),
                ));
            }
            std::ptr::copy_nonoverlapping(text.as_ptr(), json.cast::<u8>(), text.len());
            Ok(())
        })
    }
}

/// Releases a scene's results (NULL is ignored).
///
/// # Safety
/// `results` is NULL or a pointer from `rodcube_run_scene` not yet released.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rodcube_results_free(results: *mut RodcubeResults) {
    if !results.is_null() {
        // SAFETY: made by `Box::into_raw` in `rodcube_run_scene`, released once.
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(results) })));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every reason a sensitivity does not exist is `RODCUBE_ERR_NO_SENSITIVITY`, with the
    /// words of results.json's note (no concrete point the per-point solver takes reaches one,
    /// so `tests/capi.rs` cannot call for it).
    #[test]
    fn every_sensitivity_gap_is_no_sensitivity_with_its_note() {
        for gap in [
            SensitivityGap::AtRelease,
            SensitivityGap::NoSeparation,
            SensitivityGap::NotBuilt,
            SensitivityGap::PastImpact,
            SensitivityGap::PastZeno,
            SensitivityGap::Grazing,
            SensitivityGap::RoutesDisagree,
            SensitivityGap::IntegrationFailed,
            SensitivityGap::NoPartials,
            SensitivityGap::NoFallPolynomial,
            SensitivityGap::DoubleRoot,
            SensitivityGap::NoUnit,
            SensitivityGap::OneSided,
        ] {
            let Failure(code, message) = gap.into();
            assert_eq!(code, RODCUBE_ERR_NO_SENSITIVITY, "{gap:?}");
            let note = crate::report::prose::note(&Note::NoSensitivity(gap));
            assert_eq!(message, note);
            assert!(message.contains("sensitivit"), "{gap:?}: {message}");
        }
        assert_eq!(
            rodcube_error_group(RODCUBE_ERR_NO_SENSITIVITY),
            RODCUBE_ERR_SOLVE
        );
    }
}
