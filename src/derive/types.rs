//! What the derivation produces, stage by stage: the typed values that every stage of
//! `derive/` hands to the next, and the layer's errors (`StepError` of a step, `DeriveError`
//! placed at a spec field) and `Unreducible` (why a phase has no fast path), below all of
//! them.
//!
//! A spec describes a *system*: its coordinates, bodies, potentials, obstacles and contacts.
//! Each derived model is one *phase* of it, named by the contacts it holds closed by
//! elimination: the general model (nothing eliminated, every contact a constraint row whose
//! force the runtime solves along with the motion) and the fast phases (some contacts closed by
//! elimination, the rest open, reduced to one coordinate).

use super::expr::Expr;
pub use crate::model::{GapKind, ShapeKind};
use std::collections::{BTreeMap, BTreeSet};

/// A derivation step that failed, before it is placed at a spec field ([`DeriveError`]) or
/// reported by the tool as a refused model: the derive layer's error.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum StepError {
    /// Symbolica gave back an atom that the derivation's expressions cannot hold.
    #[error("cannot read back Symbolica's `{atom}`: {why}")]
    Unreadable {
        /// The atom, as Symbolica prints it.
        atom: String,
        /// What could not be held (a complex number, a rational beyond 128 bits).
        why: Unheld,
    },
    /// A coefficient outgrew 128 bits.
    #[error("coefficient overflow")]
    Overflow,
    /// The generated Rust could not be compiled into a tape (`emit::tape`).
    #[error("cannot write the tape: {0}")]
    Tape(String),
    /// No presentation form could be made, or the one made is not equal to the result.
    #[error("{0}")]
    Presentation(String),
    /// The derivation lacks what the emitter needs (a constant, a point, a parameter, the
    /// presented steps).
    #[error("{0}")]
    Missing(String),
    /// Expressions of a generated method read symbols the method does not have.
    #[error("{what} {} besides {besides}", .symbols.join(", "))]
    Unbound {
        /// What depends on them (`the forces depend on`).
        what: &'static str,
        /// The symbols.
        symbols: Vec<String>,
        /// What the method has (`the state and the parameters`).
        besides: &'static str,
    },
    /// Named constants that nothing reads even after dropping the unread ones.
    #[error("constants still unread after dropping the unread ones: {0:?}")]
    Unread(BTreeSet<String>),
    /// Two symbols would be the same local in the generated code.
    #[error("two symbols of `{model}` would both be the local `{local}` in the generated code")]
    LocalClash {
        /// The model.
        model: String,
        /// The local.
        local: String,
    },
}

/// What a number Symbolica gave back is that the derivation's expressions cannot hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Unheld {
    /// A rational whose numerator or denominator exceeds 128 bits.
    #[error("a rational beyond 128 bits")]
    TooLarge,
    /// A complex, infinite or undefined number, or a finite-field element.
    #[error("a number that is not real and finite")]
    NotReal,
}

/// Why a phase has no fast path: not an error, the phase is integrated instead. Its text is the
/// reason the LaTeX write-up, the JSON record and the model's `route_note` give.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Unreducible {
    /// The spec names no reduced coordinate for a fast phase to keep.
    #[error("the spec names no `reduced` coordinate")]
    NoReducedCoordinate,
    /// A closed contact's edge depends on coordinates besides the angle.
    #[error(
        "the edge of contact `{contact}` depends on {others} besides `{theta}`, which only the \
         integrated path follows"
    )]
    EdgeOffTheAngle {
        /// The contact.
        contact: String,
        /// The other coordinates, comma-separated.
        others: String,
        /// The reduced coordinate.
        theta: String,
    },
    /// A coordinate besides the angle on which the Lagrangian depends.
    #[error(
        "coordinate `{coordinate}` is not cyclic (the Lagrangian depends on it), so it cannot \
         be eliminated through a conserved momentum"
    )]
    NotCyclic {
        /// The coordinate.
        coordinate: String,
    },
    /// A cyclic coordinate whose inertia depends on the angle.
    #[error("the inertia of cyclic coordinate `{coordinate}` depends on `{theta}`")]
    InertiaOnTheAngle {
        /// The cyclic coordinate.
        coordinate: String,
        /// The reduced coordinate.
        theta: String,
    },
    /// The cyclic velocities do not follow from their momenta.
    #[error("the cyclic velocities cannot be solved from their momenta (singular inertia)")]
    SingularCyclicInertia,
    /// The reduced energy is not even in the angular velocity.
    #[error("the reduced energy has a term linear in the angular velocity")]
    LinearInRate,
    /// The effective potential is no function of the angle's sine and cosine.
    #[error(
        "the effective potential depends on {theta} otherwise than through sin({theta}) \
         and cos({theta})"
    )]
    PotentialOffTrig {
        /// The reduced coordinate.
        theta: String,
    },
    /// A cyclic velocity whose integral in time has no closed form.
    #[error(
        "the velocity of `{coordinate}` is not affine in sin and cos of `{theta}`; its position \
         has no closed form"
    )]
    OpenPosition {
        /// The cyclic coordinate.
        coordinate: String,
        /// The reduced coordinate.
        theta: String,
    },
    /// A contact's force that does not reduce, and why.
    #[error("force `{contact}`: {why}")]
    Force {
        /// The contact.
        contact: String,
        /// Why its force does not reduce.
        why: Box<Unreducible>,
    },
    /// A force that is not `F0 + F2 theta_dot^2` on the reduced motion.
    #[error("not of the form F0 + F2 theta_dot^2 on the reduced motion")]
    NotQuadraticInRate,
    /// A force whose denominator has no evident sign (its zero is then bracketed).
    #[error("the sign of the force's denominator is not evident, so its zero is bracketed")]
    DenominatorSign,
    /// A force whose numerator is not linear in `cos(theta)`.
    #[error("the contact force's numerator is not linear in cos(theta) after sin^2 + cos^2 = 1")]
    NumeratorNotLinearInCos,
    /// A separation condition that mixes the sine and the cosine.
    #[error(
        "the separation condition mixes sin(theta) and cos(theta); it is not a polynomial in sin(theta)"
    )]
    MixedSinCos,
    /// A separation polynomial of degree above 16.
    #[error("the separation polynomial has a degree above 16")]
    DegreeAbove16,
}

/// Where a derivation error belongs in the spec: a dotted field path and a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeriveError {
    /// Field path (`coordinates[0]`), used to find the line.
    pub field: Vec<FieldStep>,
    /// What failed.
    pub message: String,
}

/// One step of a field path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldStep {
    /// Mapping key.
    Key(String),
    /// Sequence index.
    Index(usize),
}

/// A derivation error at `path`.
pub fn at(path: &[FieldStep], message: String) -> DeriveError {
    DeriveError {
        field: path.to_vec(),
        message,
    }
}

/// A mapping key as a field step.
pub fn key(k: &str) -> FieldStep {
    FieldStep::Key(k.to_string())
}

/// The field of the `i`-th entry of list `list`, key `sub` (`contacts[1].gap`).
pub fn entry(list: &str, i: usize, sub: &str) -> [FieldStep; 3] {
    [key(list), FieldStep::Index(i), key(sub)]
}

/// Which contacts a phase holds closed by elimination (indices into the spec's `contacts`,
/// ascending), and what it is called.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhasePlan {
    /// Model name.
    pub name: String,
    /// The contacts eliminated (closed for the whole phase).
    pub closed: Vec<usize>,
    /// Whether the phase starts from a state given as parameters (`<q>_0`, `<q>_dot_0`) rather
    /// than from the spec's initial state.
    pub start_params: bool,
}

impl PhasePlan {
    /// Whether this is the general model (nothing eliminated).
    pub fn is_general(&self) -> bool {
        self.closed.is_empty()
    }
}

/// A constant computed once per parameter set (in `prepare`).
#[derive(Debug, Clone)]
pub struct Constant {
    /// Internal symbol.
    pub symbol: String,
    /// Definition over parameters and earlier constants.
    pub value: Expr,
}

/// A contact force's zero on the reduced motion as a polynomial in `sin(theta)`.
#[derive(Debug, Clone)]
pub struct Separation {
    /// Coefficients of the polynomial in `sin(theta)`, lowest degree first, over constants.
    pub coefficients: Vec<Expr>,
    /// The polynomial itself, in `rc_s`.
    pub polynomial: Expr,
}

/// How a [`PushProof`]'s quadratic bound is shown positive on `0 <= s <= 1`.
#[derive(Debug, Clone)]
pub enum ProofStep {
    /// `a > 0`, `b >= 0` and `c >= 0`.
    Signs,
    /// `a > 0`, `c <= 0` and the value at `s = 1`, `a + b + c` (expanded), `> 0`.
    Ends(Expr),
    /// `a > 0` and `4 a c - b^2` (expanded) `> 0`: no real root.
    Discriminant(Expr),
}

/// A proof that a closed contact's push is positive for `0 <= s = sin(theta) <=
/// sin(theta_i)` and every admissible parameter: a quadratic `a + b s + c s^2` below its
/// force polynomial there, and why that quadratic is positive (each sign that of an expanded
/// polynomial in the positive parameters whose terms all have it).
#[derive(Debug, Clone)]
pub struct PushProof {
    /// `[a, b, c]`, expanded.
    pub bound: [Expr; 3],
    /// Why the bound is positive.
    pub step: ProofStep,
}

/// A proof that the first contact pushes at release for every admissible parameter: its
/// force polynomial at `s = sin(theta_i)` is `sin(theta_i)^power R(sin(theta_i))`, and `R` is
/// positive on `0 <= sin(theta_i) <= 1` by `proof` (a [`PushProof`] of `R`, whose coefficients
/// hold no `sin(theta_i)`).
#[derive(Debug, Clone)]
pub struct ReleaseProof {
    /// The power of `sin(theta_i) > 0` factored out.
    pub power: usize,
    /// `R`, expanded, over `rc_s` standing for `sin(theta_i)`.
    pub polynomial: Expr,
    /// Why `R` is positive.
    pub proof: PushProof,
}

/// A parameter of a derived model.
#[derive(Debug, Clone)]
pub struct Param {
    /// Symbol.
    pub name: String,
    /// What it is.
    pub meaning: String,
    /// SI unit.
    pub unit: String,
    /// Whether it must be strictly positive.
    pub positive: bool,
}

/// A named output with its meaning.
#[derive(Debug, Clone)]
pub struct Named {
    /// Identifier.
    pub name: String,
    /// What it means.
    pub meaning: String,
}

/// A monitored assumption of a phase.
#[derive(Debug, Clone)]
pub struct Monitor {
    /// Identifier.
    pub name: String,
    /// What it checks.
    pub meaning: String,
    /// The unit of its value (empty when the spec gives none).
    pub unit: String,
}

/// A shape of the drawing, from a body's `shape` or an obstacle.
#[derive(Debug, Clone)]
pub struct Shape {
    /// What it is.
    pub kind: ShapeKind,
    /// Index in [`Derivation::bodies`] of the body it moves with (`None`: an obstacle).
    pub body: Option<usize>,
    /// Its numbers over the parameters, in the order [`ShapeKind`] documents.
    pub numbers: Vec<Expr>,
}

/// One contact of the spec as a phase sees it.
#[derive(Debug, Clone)]
pub struct ContactRow {
    /// Its name (the name of its force).
    pub name: String,
    /// What its force is.
    pub meaning: String,
    /// What its gap measures (a length, in `m`, or an angle, in `rad`).
    pub gap_kind: GapKind,
    /// The unit of its force, conjugate to the gap.
    pub force_unit: String,
    /// A joint: always closed, its force of either sign.
    pub bilateral: bool,
    /// The coordinate the spec lets it eliminate.
    pub eliminates: Option<String>,
    /// Whether this phase holds it closed by elimination.
    pub closed: bool,
    /// Its gap over the phase's coordinates (zero where closed).
    pub gap: Expr,
    /// `d gap / d q_j` for each coordinate of the phase (zeros where closed).
    pub jacobian: Vec<Expr>,
    /// `d/dt (J qd)` with the accelerations zero: the normal acceleration is `J qdd + bias`.
    pub bias: Expr,
    /// Its edge margin over the phase's coordinates, if it can end at an edge.
    pub edge: Option<Expr>,
    /// Where closed: its force (the Lagrange multiplier) over the phase's `q`, `qd`, `qdd`.
    pub force: Option<Expr>,
}

/// A Coulomb friction in one phase.
#[derive(Debug, Clone)]
pub struct Friction {
    /// Identifier and meaning.
    pub named: Named,
    /// Index of the coefficient in [`Derivation::params`].
    pub coefficient: usize,
    /// Index of its contact in [`Derivation::contacts`].
    pub contact: usize,
    /// Slip velocity `v = J qd` over the phase's state.
    pub slip: Expr,
    /// `J`: `dv/dqd_j`, one per coordinate (the generalized force per unit friction force).
    pub jacobian: Vec<Expr>,
    /// `dv/dt` with the accelerations set to zero.
    pub bias: Expr,
}

/// The fast path of a phase: the cyclic coordinates eliminated through their conserved momenta.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// Constants computed in `prepare`, in order.
    pub constants: Vec<Constant>,
    /// Reduced inertia `A(theta)` in `T = A theta_dot^2 / 2 + ...`.
    pub reduced_inertia: Expr,
    /// Reduced kinetic-plus-potential energy with the cyclic velocities eliminated.
    pub reduced_energy: Expr,
    /// `theta_dot^2` over `rc_s, rc_c, rc_ds, rc_dc` and constants.
    pub theta_dot_sq: Expr,
    /// `theta_ddot` over the same symbols.
    pub theta_ddot: Expr,
    /// Cyclic velocities on the reduced motion (over `rc_s, rc_c, rc_w`).
    pub cyclic_velocity: Vec<Expr>,
    /// Cyclic positions on the reduced motion (over `rc_t, rc_ds, rc_dc, rc_delta`).
    pub cyclic_position: Vec<Expr>,
    /// Every contact's force on the reduced motion (over `rc_s, rc_c, rc_w2, rc_acc`; zero
    /// for a contact that is open in the phase).
    pub forces_reduced: Vec<Expr>,
    /// Per contact: its force's zero as a polynomial in `sin(theta)`, where it is one (else the
    /// runtime finds that zero numerically, from the reduced force).
    pub force_polynomials: Vec<Option<Separation>>,
    /// Per contact: the proof that its push stays positive over the whole phase for every
    /// admissible parameter ([`positivity`](super::positivity)), where the derivation found one
    /// (never for the first contact, whose force's zero ends the phase).
    pub push_proofs: Vec<Option<PushProof>>,
    /// The proof that the first contact pushes at release for every admissible parameter,
    /// where the derivation found one.
    pub release_proof: Option<ReleaseProof>,
    /// Coefficients in `sin(theta)` (lowest degree first, over constants) of the fall
    /// polynomial `P(s) = (sin theta_i - s) / theta_dot^2`, where that ratio is a polynomial in
    /// `s` alone: the phase starts from rest, its potential is linear in `sin(theta)` and its
    /// reduced inertia a polynomial in `sin(theta)`. Its zeros and `s = -1` are then the only
    /// singularities of the time integrand, which lets the runtime choose its quadrature rule
    /// a priori.
    pub fall: Option<Vec<Expr>>,
    /// Fully substituted forms over parameters and `theta` for people and other tools.
    pub plain: BTreeMap<String, Expr>,
    /// The partial derivatives behind the sensitivities (filled in by `partials.rs`).
    pub partials: Partials,
}

/// The partial derivatives of a fast path in every parameter (in the phase's parameter order),
/// over the parameters, `rc_s` and `rc_c`.
#[derive(Debug, Clone, Default)]
pub struct Partials {
    /// `[dF/dtheta, dF/dp_1, ...]` of the separation condition `F = 0` divided by one of its
    /// coefficients; empty without a separation polynomial.
    pub separation: Vec<Expr>,
    /// `d(theta_dot^2)/dp_i` at a fixed angle.
    pub theta_dot_sq: Vec<Expr>,
    /// `d(sin theta_i)/dp_i`.
    pub start_sine: Vec<Expr>,
    /// `dP_j/dp_i` of the fall polynomial's coefficients, parameter by parameter (`j` fastest);
    /// empty without a fall polynomial.
    pub fall: Vec<Expr>,
}

/// The partial derivatives of the general model's rows over `x = [q, qd, p]` (the layout of
/// `Tangents::tangent_rows`), each row-major.
#[derive(Debug, Clone, Default)]
pub struct Tangents {
    /// `(n + 3 m + 2 nf) (2 n + np)` entries over the state, the accelerations `ddot_<q>`, the
    /// contacts' forces `rc_f<i>`, the frictions' forces `rc_fr<j>` and the parameters: the
    /// residual `M qdd - F - J^T f - T^T fr`, the contacts' normal accelerations, the
    /// frictions' slip accelerations, the gaps, the edge margins and the slip velocities.
    pub rows: Vec<Expr>,
    /// `2 n np` entries over the parameters: the `n` rows `d q_0/dp`, then the `n` rows
    /// `d qd_0/dp` of the initial state (`Tangents::initial_tangents`).
    pub initial: Vec<Expr>,
}

impl Reduction {
    /// The separation polynomial: that of the spec's first contact, where it is closed in the
    /// phase and its zero is a polynomial root.
    pub fn separation(&self) -> Option<&Separation> {
        self.force_polynomials.first().and_then(Option::as_ref)
    }
}

/// Everything derived for one phase (one generated model), as plain expressions.
#[derive(Debug, Clone)]
pub struct Derivation {
    /// Model name (`rod_cube`, `rod_cube_closed`, `rod_cube_free`).
    pub name: String,
    /// The spec's name: the system this phase belongs to (its general model's name).
    pub system: String,
    /// Which contacts it holds closed, and how it starts.
    pub plan: PhasePlan,
    /// One line for people.
    pub description: String,
    /// Parameters in order (a phase with `start_params` adds its start state).
    pub params: Vec<Param>,
    /// Coordinate names in order.
    pub coords: Vec<String>,
    /// The spec's coordinates (the general model's), in order.
    pub full_coords: Vec<String>,
    /// Index of the reduced coordinate (none where the spec names none).
    pub reduced: Option<usize>,
    /// Indices of the cyclic coordinates (whose momenta are conserved).
    pub cyclic: Vec<usize>,
    /// Kinetic energy (full state).
    pub kinetic: Expr,
    /// Potential energy (full state), gravity and the spec's potentials.
    pub potential: Expr,
    /// The Lagrangian `T - V`.
    pub lagrangian: Expr,
    /// Euler–Lagrange expressions `d/dt dL/dqd - dL/dq` (each `= 0`, with the contacts'
    /// generalized forces on the right).
    pub euler_lagrange: Vec<Expr>,
    /// Mass matrix `M(q)`, row-major.
    pub mass: Vec<Vec<Expr>>,
    /// Right-hand side `F(q, qd)` of `M qdd = F` (before the contacts' and frictions' forces).
    pub rhs: Vec<Expr>,
    /// Conjugate momenta of the cyclic coordinates (full state).
    pub momenta: Vec<Expr>,
    /// Initial position and velocity of every coordinate, over the parameters.
    pub initial: Vec<[Expr; 2]>,
    /// Point positions (full state).
    pub point_pos: Vec<[Expr; 2]>,
    /// Point velocities (full state).
    pub point_vel: Vec<[Expr; 2]>,
    /// Every contact of the spec, in its order.
    pub contacts: Vec<ContactRow>,
    /// Monitors (each `>= 0` while the assumption holds).
    pub monitors: Vec<Monitor>,
    /// Monitors over the full state, parameters and the contacts' forces `rc_f<i>`.
    pub monitors_full: Vec<Expr>,
    /// Parameter requirements (over parameters).
    pub requirements: Vec<Expr>,
    /// Each contact's coefficient of restitution (over parameters).
    pub restitutions: Vec<Expr>,
    /// The bodies' names, in the spec's order.
    pub bodies: Vec<String>,
    /// Each body's pose `[x, y, angle]` (centre of mass and orientation) over the full state.
    pub body_pose: Vec<[Expr; 3]>,
    /// The shapes of the drawing: the bodies' (in their order), then the obstacles'.
    pub shapes: Vec<Shape>,
    /// The frictions (all of the spec's; a phase with friction is never a fast phase).
    pub frictions: Vec<Friction>,
    /// Each of the spec's coordinates, value and rate, over this phase's state: the state of
    /// the general model this phase's state stands for.
    pub to_full: Vec<[Expr; 2]>,
    /// The fast path, or why the phase is integrated instead.
    pub reduction: Result<Reduction, Unreducible>,
    /// The partial derivatives behind the integrated route's forward sensitivities (the
    /// general model's only; filled in by `tangents.rs`).
    pub tangents: Option<Tangents>,
    /// The results without units, if the spec gives groups and scales.
    pub dimensionless: Option<Dimensionless>,
    /// The steps as the LaTeX derivation shows them ([`super::steps`]), once presented.
    pub steps: Option<Steps>,
}

impl Derivation {
    /// The reduced coordinate's name (none where the spec names none).
    pub fn theta(&self) -> Option<&str> {
        self.reduced.map(|i| self.coords[i].as_str())
    }

    /// Whether this is the general model of its system.
    pub fn is_general(&self) -> bool {
        self.plan.is_general()
    }
}

// What the presentation stages add to a phase ([`super::dimensionless`], [`super::steps`]).

/// A dimensionless group.
#[derive(Debug, Clone)]
pub struct Group {
    /// Its symbol.
    pub name: String,
    /// Its definition over the parameters.
    pub definition: Expr,
    /// What it is.
    pub meaning: String,
    /// The parameter it is solved for.
    pub solves: String,
}

/// A result without units.
#[derive(Debug, Clone)]
pub struct Scaled {
    /// Key, as in the JSON record's `expressions` (`theta_dot_sq`, `contact_force`, ...).
    pub key: String,
    /// What it is, in words.
    pub meaning: String,
    /// The unit it is written in (`g/ell`, `m2*g`); none for a condition `= 0`.
    pub unit: Option<Expr>,
    /// The presentation form over the groups and `sin(theta)`, `cos(theta)`.
    pub form: Expr,
    /// Operations in the form (see [`RULE`](super::present::RULE)).
    pub operations: usize,
    /// The paper's equation number, where the spec gives one.
    pub paper: Option<String>,
}

/// A phase's results without units.
#[derive(Debug, Clone)]
pub struct Dimensionless {
    /// The groups, in the spec's order (a free phase's `omega_0` last).
    pub groups: Vec<Group>,
    /// The time scale.
    pub time: Expr,
    /// The force scale.
    pub force: Expr,
    /// The results (none on the integrated route, which has no closed forms).
    pub results: Vec<Scaled>,
    /// `d theta_sep / d <group>` for each group the separation condition depends on (keys
    /// `dtheta_sep_d<group>`), at the separation angle, by the implicit-function theorem.
    pub sensitivities: Vec<Scaled>,
}

/// One step as shown, over `rc_s`, `rc_c` like the derivation.
#[derive(Debug, Clone, PartialEq)]
pub struct Shown {
    /// The expression shown.
    pub expr: Expr,
    /// The expression as derived (what `expr` equals).
    pub derived: Expr,
    /// Why it is shown as derived rather than in a grouped form, if it is.
    pub as_derived: Option<String>,
}

/// Every step of a phase as shown.
#[derive(Debug, Clone, PartialEq)]
pub struct Steps {
    /// `T`.
    pub kinetic: Shown,
    /// `V`.
    pub potential: Shown,
    /// `L = T - V`.
    pub lagrangian: Shown,
    /// One Euler–Lagrange expression per coordinate (each `= 0`).
    pub euler_lagrange: Vec<Shown>,
    /// The conjugate momenta of the cyclic coordinates.
    pub momenta: Vec<Shown>,
    /// The reduced results by their key in `Reduction::plain`.
    pub reduced: BTreeMap<String, Shown>,
}
