//! The contract between generated model code (`generated/*.rs`) and the runtime solvers.
//!
//! A spec describes a *system* of bodies and contacts; each model is one *phase* of it
//! ([`Model`]): its Euler–Lagrange equations `M(q) qdd = F(q, qd)`, its contacts, monitors and
//! drawing. The system's **general model** (named as the spec) has every coordinate and treats
//! every contact as a constraint row (gap, Jacobian, bias) whose force the runtime solves along
//! with the motion, for whichever contacts are closed. A **fast phase** holds some contacts
//! closed by eliminating the coordinates they tie (their forces in closed form) and, when every
//! coordinate but the reduced one (`theta`, the rod's angle to the floor) is cyclic, has a fast
//! path on which the motion is a function of the angle ([`Reduction`]). Every function here is
//! emitted by `rodcube derive` from a spec in `derivations/*.yaml`; the runtime never knows
//! which model it is driving: it walks the contacts and phases the [`ModelInfo`] lists.
//!
//! # Conventions
//! - `p`: parameter values in the order of [`ModelInfo::parameters`] (SI units).
//! - `k`: the *prepared constants* returned by [`Model::prepare`]. `k[..n_params]` is `p`;
//!   on the fast path `k[ReductionInfo::k_theta_initial]` is the initial angle and
//!   `k[ReductionInfo::k_theta_dot_initial]` its rate; the rest are parameter-only
//!   subexpressions hoisted out of the per-point functions.
//! - `delta`: the angle fallen since the start, `delta = theta_initial - theta >= 0`. The reduced
//!   functions take `delta` rather than `theta` so that `sin(theta_i) - sin(theta)` is formed
//!   without cancellation near the start, where the energy integral vanishes.
//! - `q`, `qd`, `qdd`: the full (unreduced) coordinates, velocities and accelerations in the order
//!   of [`ModelInfo::coordinates`].
//! - `q_full`, `qd_full`: the system's coordinates and velocities, in the order of
//!   [`ModelInfo::system_coordinates`] (the general model's).
//! - Contact forces are one value per contact of [`ModelInfo::contacts`], in the unit of each
//!   ([`ContactInfo::unit`]), positive in the sense its meaning documents (a unilateral
//!   contact's pushes).

/// A model parameter as declared in its spec.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamInfo {
    /// Symbol used in the spec and in scenes (`m1`, `ell`, ...).
    pub name: &'static str,
    /// What it is, for people.
    pub meaning: &'static str,
    /// SI unit (`kg`, `m`, `m/s^2`, `rad`, ...).
    pub unit: &'static str,
    /// Whether the value must be strictly positive (masses, lengths, gravity).
    pub positive: bool,
}

/// A named quantity emitted by the generator (force or point).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NamedInfo {
    /// Identifier used in results, CSV columns and JSON keys.
    pub name: &'static str,
    /// What it means, for people (sign conventions included).
    pub meaning: &'static str,
}

/// A monitored assumption: its value must stay `>= 0` during the motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MonitorInfo {
    /// Identifier used in check keys (`<phase>.<name>`).
    pub name: &'static str,
    /// What it checks, for people.
    pub meaning: &'static str,
    /// The unit its value is in (`N`, `N m`, `m`, ...); empty when the spec gives none.
    pub unit: &'static str,
}

/// What a shape of the drawing is; the numbers [`Model::drawing`] writes for it, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeKind {
    /// A line: `x1, y1, x2, y2`.
    Segment,
    /// A rectangle with its sides along its frame's axes: centre `x, y`, `width, height`.
    Rectangle,
    /// A circle: centre `x, y`, `radius`.
    Circle,
}

impl ShapeKind {
    /// How many numbers describe a shape of this kind.
    pub const fn numbers(self) -> usize {
        match self {
            ShapeKind::Segment | ShapeKind::Rectangle => 4,
            ShapeKind::Circle => 3,
        }
    }
}

/// A shape of the drawing (a spec's body `shape` or `scenery`): its numbers are
/// `sizes[first..first + kind.numbers()]` of [`Model::drawing`], in its body's frame (the centre
/// of mass at the origin, x along the body's angle) or, for scenery, in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShapeInfo {
    /// What it is.
    pub kind: ShapeKind,
    /// Index in [`ModelInfo::bodies`] of the body it moves with; `None` for fixed scenery.
    pub body: Option<usize>,
    /// Index of its first number in the `sizes` of [`Model::drawing`].
    pub first: usize,
}

/// What a contact's gap measures, from the spec's units: its tolerances scale with the
/// system's length for a distance and not for an angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GapKind {
    /// A distance, in metres (its force in newtons).
    Length,
    /// An angle, in radians (its force a torque, in newton metres).
    Angle,
}

impl GapKind {
    /// The unit of such a gap: `m` or `rad`.
    pub const fn unit(self) -> &'static str {
        match self {
            GapKind::Length => "m",
            GapKind::Angle => "rad",
        }
    }

    /// What a tolerance on such a gap, given relative to the system's `length`, is in the
    /// gap's unit: `length` times it for a distance, itself for an angle.
    pub fn scale(self, length: f64) -> f64 {
        match self {
            GapKind::Length => length,
            GapKind::Angle => 1.0,
        }
    }
}

/// A requirement on the parameters: a margin, formed from some of them, that must be strictly
/// positive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RequirementInfo {
    /// Identifier used in messages and reports.
    pub name: &'static str,
    /// What it means, for people.
    pub meaning: &'static str,
    /// Indices in [`ModelInfo::parameters`] of the parameters its margin is formed from,
    /// ascending (the derivation reads them off the spec's expression).
    pub parameters: &'static [usize],
}

/// A contact of the system: a unilateral constraint `gap(q) >= 0` (or a bilateral one,
/// `gap(q) = 0` for good) whose force is its Lagrange multiplier. Every model of a system lists
/// the same contacts, in the spec's order; [`ContactInfo::closed`] says whether this model
/// holds it closed by elimination.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactInfo {
    /// Name of the contact and of its force (a result key).
    pub name: &'static str,
    /// What its force is, with its sign convention.
    pub meaning: &'static str,
    /// What its gap measures: a distance (in `m`) or an angle (in `rad`).
    pub gap: GapKind,
    /// Unit of its force, conjugate to the gap (`N`; `N m` for a gap in radians).
    pub unit: &'static str,
    /// A joint: always closed, its force of either sign.
    pub bilateral: bool,
    /// Whether it can also end where its point runs off an edge ([`Model::edges`]).
    pub edge: bool,
    /// The coordinate the spec lets it eliminate while closed.
    pub eliminates: Option<&'static str>,
    /// Whether this model holds it closed by elimination (its force is in
    /// [`Model::forces_full`]); otherwise it is a constraint row ([`Model::gaps`],
    /// [`Model::constraints`]).
    pub closed: bool,
    /// Its coefficient of restitution as the spec writes it (`0` where it gives none);
    /// [`Model::restitutions`] evaluates it.
    pub restitution: &'static str,
}

/// Coulomb friction at a contact ([`Model::friction`] gives its slip velocity).
///
/// While the contact slides with slip velocity `v`, the friction force is
/// `f = -mu N sign(v)`; while it sticks (`v = 0`), `f` is the force that keeps it stuck, which
/// must stay within `|f| <= mu N`. `N` is the force of contact [`FrictionInfo::contact_index`] and
/// `mu` the parameter [`FrictionInfo::coefficient_index`]. Its generalized force is `f J`, with `J`
/// the row of [`Model::friction`]'s Jacobian (`v = J qd`). An open contact has no friction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrictionInfo {
    /// Identifier of the friction force (a result key, in newtons).
    pub name: &'static str,
    /// What it is, with its sign convention.
    pub meaning: &'static str,
    /// Index in [`ModelInfo::parameters`] of the friction coefficient `mu` (`>= 0`).
    pub coefficient_index: usize,
    /// Index in [`ModelInfo::contacts`] of the contact whose force is the normal force.
    pub contact_index: usize,
}

/// A fast phase of a system: the model that holds these contacts closed (and the others
/// open) on the fast path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PhaseInfo {
    /// Indices in [`ModelInfo::contacts`] of the contacts it holds closed, ascending.
    pub closed: &'static [usize],
    /// Its model's name in the registry.
    pub model: &'static str,
    /// Whether it starts from the spec's release state (otherwise from a state given as its
    /// start parameters).
    pub release: bool,
    /// The degree of its separation polynomial (the first contact's force polynomial; 0 when
    /// it has none).
    pub separation_degree: usize,
}

/// Where the fast path of a model keeps its start in `k`, and its polynomials' degrees.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReductionInfo {
    /// Index in `k` of the initial reduced angle `theta_i`.
    pub k_theta_initial: usize,
    /// Index in `k` of the initial reduced rate `theta_dot_i`.
    pub k_theta_dot_initial: usize,
    /// Index in `k` of `sin(theta_i)`, formed from the parameters (exact where `theta_i` is
    /// given by its sine, as for a rod leaning on a cube: `a / ell`).
    pub k_sin_initial: usize,
    /// Index in `k` of `cos(theta_i)`, formed from the parameters without cancellation.
    pub k_cos_initial: usize,
    /// Per contact, the degree of the polynomial in `sin(theta)` whose root is its force's zero
    /// ([`Reduction::force_polynomial`]); 0 where there is none (an open or bilateral contact,
    /// or a force whose zero is found as a bracketed root of [`Reduction::forces`]).
    pub force_degrees: &'static [usize],
    /// Per contact, whether the derivation proved its push positive over the whole phase
    /// (`0 <= sin(theta) <= sin(theta_i)`) for every admissible parameter (the proof is in the
    /// model's LaTeX): [`Model::lean_start`] then leaves its force polynomial out, and the
    /// per-point route does not certify it point by point. Never the first contact.
    pub pushes_proven: &'static [bool],
    /// Whether the derivation proved that the first contact pushes at release
    /// (`0 < sin(theta_i) <= 1`) for every admissible parameter (the proof is in the model's
    /// LaTeX): [`Model::lean_start`] then does not evaluate its polynomial there.
    pub release_push_proven: bool,
    /// Degree of the fall polynomial [`Reduction::fall_polynomial`], where the phase has one.
    pub fall_degree: Option<usize>,
    /// Indices in `k` (beyond the parameters) that [`Reduction::prepare_lean`] fills: the start's
    /// sine, cosine and rate (not the angle `theta_i`, which only [`Model::prepare`] forms) and
    /// the polynomials' coefficients with what they are computed from.
    pub lean_constants: &'static [usize],
}

impl ReductionInfo {
    /// The degree of the separation polynomial: the first contact's force polynomial (0 when
    /// it has none).
    pub fn separation_degree(&self) -> usize {
        self.force_degrees.first().copied().unwrap_or(0)
    }

    /// Whether the first contact's force has its zero as a polynomial root.
    pub fn polynomial_separation(&self) -> bool {
        self.separation_degree() > 0
    }
}

/// Static description of a generated model.
#[derive(Debug, Clone, Copy)]
pub struct ModelInfo {
    /// Model name (a plain identifier; also the stem of its generated files).
    pub name: &'static str,
    /// One-line description from the spec.
    pub description: &'static str,
    /// Spec file the model was derived from, relative to the project root.
    pub spec: &'static str,
    /// The system it is a phase of: the spec's name, which is its general model's name.
    pub system: &'static str,
    /// Parameters in the order every function expects them.
    pub parameters: &'static [ParamInfo],
    /// Requirements on the parameters, each a margin that must be strictly positive.
    pub requirements: &'static [RequirementInfo],
    /// Length of the prepared-constant vector `k`.
    pub n_constants: usize,
    /// Generalized coordinates of this model (the system's, without those it eliminates).
    pub coordinates: &'static [&'static str],
    /// The system's coordinates (the general model's), which [`Model::to_full`] fills.
    pub system_coordinates: &'static [&'static str],
    /// Index in `coordinates` of the reduced coordinate (`theta`), the angle the motion is
    /// reported in; none for a system whose spec names none (it has no fast phase and no
    /// angle among its results).
    pub reduced_index: Option<usize>,
    /// Indices in `coordinates` of the cyclic coordinates (the Lagrangian does not depend on
    /// them); on the fast path their conserved momenta eliminate them.
    pub cyclic: &'static [usize],
    /// The value of the reduced coordinate at which the motion ends (the rod lies on the
    /// floor), in radians; none for a motion with no end of its own, which runs to its end
    /// time (a scene's `until`).
    pub end_angle: Option<f64>,
    /// Every contact of the system, in the spec's order.
    pub contacts: &'static [ContactInfo],
    /// Coulomb frictions (at contacts; only the general model has them).
    pub frictions: &'static [FrictionInfo],
    /// Named points whose trajectories can be asked for.
    pub points: &'static [NamedInfo],
    /// Index in `points` of the centre of mass whose free fall is the reference time (none:
    /// no such reference).
    pub falling_point_index: Option<usize>,
    /// Index in `parameters` of the gravitational acceleration.
    pub gravity_index: usize,
    /// Physical assumptions to monitor; each value must stay `>= 0` during the motion.
    pub monitors: &'static [MonitorInfo],
    /// The bodies, in the order of the poses [`Model::drawing`] writes.
    pub bodies: &'static [&'static str],
    /// The shapes that draw the bodies and the obstacles (the floor `y = 0` is not among them).
    pub shapes: &'static [ShapeInfo],
    /// Whether the parameters after the spec's are this phase's start state: `<q>_0` for each
    /// of its coordinates, then `<q>_dot_0` (otherwise it starts from the spec's `initial`).
    pub start_params: bool,
    /// The system's fast phases (the same list in every model of the system).
    pub phases: &'static [PhaseInfo],
    /// The fast path's layout, when the model has one ([`Model::reduction`] is `Some`).
    pub reduction: Option<ReductionInfo>,
    /// Why the model has no fast path (empty when it has one): it is then solved by
    /// integrating `M(q) qdd = F(q, qd)`.
    pub route_note: &'static str,
}

impl ModelInfo {
    /// Whether this is its system's general model (nothing eliminated).
    pub fn is_general(&self) -> bool {
        self.name == self.system
    }

    /// Indices of the contacts this model holds closed by elimination.
    pub fn closed(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.contacts.len()).filter(|&i| self.contacts[i].closed)
    }

    /// How many numbers [`Model::drawing`] writes into `sizes`.
    pub fn drawing_sizes(&self) -> usize {
        self.shapes
            .iter()
            .map(|s| s.first + s.kind.numbers())
            .max()
            .unwrap_or(0)
    }
}

/// What the per-point solver's unchecked route reads of one point, formed straight from the
/// parameters by [`Model::lean_start`]: the start and the closed contacts' force polynomials
/// and the fall polynomial's coefficients (lowest degree first, zero past each degree).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeanStart {
    /// `sin(theta_i)`.
    pub sin_initial: f64,
    /// `cos(theta_i)`.
    pub cos_initial: f64,
    /// `theta_dot_i`.
    pub theta_dot_initial: f64,
    /// The separation polynomial (the first contact's force), degree at most 3.
    pub separation: [f64; 4],
    /// The fall polynomial, degree at most 2.
    pub fall: [f64; 3],
    /// The other closed unilateral contacts' force polynomials: none may reach zero between
    /// the start and the separation (the phase would end there first).
    pub others: [[f64; LEAN_OTHER_COEFFICIENTS]; LEAN_MAX_OTHERS],
    /// How many rows of `others` hold a polynomial.
    pub n_others: usize,
}

/// Most constants `k` of a model that [`Model::lean_start`] serves (its scratch lives on the
/// stack); a model with more takes the checked route.
pub const LEAN_MAX_CONSTANTS: usize = 64;

/// Most requirements of a model that [`Model::lean_start`] serves.
pub const LEAN_MAX_REQUIREMENTS: usize = 8;

/// Most closed unilateral contacts besides the first that [`Model::lean_start`] serves.
pub const LEAN_MAX_OTHERS: usize = 2;

/// Most coefficients of such a contact's force polynomial that [`Model::lean_start`] serves
/// (a quartic: the floor's push of every generated model is one at most; a higher degree takes
/// the checked route, and every spare coefficient would cost the route's bound of the push a
/// Horner step and a curvature term on every point).
pub const LEAN_OTHER_COEFFICIENTS: usize = 5;

/// Evaluation functions of one generated model over its full state. All are allocation-free
/// and evaluate each shared subexpression once per call.
///
/// # Contract
/// These are the low-level, unchecked functions the solvers' inner loops call. The caller
/// passes every slice at the length [`ModelInfo`] gives it: `p` one value per parameter, `k`
/// [`ModelInfo::n_constants`] values (from [`Model::prepare`] of parameters that passed
/// [`check_parameters`](crate::system::check_parameters)), `q`, `qd` and `qdd` one per
/// coordinate, `q_full` and `qd_full` one per system coordinate, `forces` one per contact, and
/// each output as its method says. A slice of another length makes the generated code index out
/// of bounds and panic. Non-finite numbers never panic here; they give non-finite results.
///
/// [`Bound`](crate::system::Bound) and [`System`](crate::system::System) are the checked way to
/// call them: they hold checked parameters and prepared constants, size every output, and
/// refuse a [`State`](crate::system::State) or slice of the wrong length (or a value that is
/// not finite) with a typed [`SystemError`](crate::system::SystemError) instead of panicking.
pub trait Model: Send + Sync {
    /// Static description.
    fn info(&self) -> &'static ModelInfo;

    /// The per-point solver's inputs for the parameters `p` in one call: `Some` only when the
    /// parameters pass `parameters_pass`, the quick test of
    /// [`check_parameters`](crate::system::check_parameters) (so that the full check would accept
    /// them too), the model holds every contact of its system closed, has a fast path whose first
    /// contact's force is a polynomial of degree at most 3 and whose other closed unilateral
    /// contacts' forces are polynomials too, a fall polynomial of degree at most 2 and at most
    /// [`LEAN_MAX_CONSTANTS`] constants, and its first contact pushes at release (evaluated
    /// unless [`ReductionInfo::release_push_proven`]); `None` says nothing about why (the checked route then
    /// decides and names it). A default method, so that each model's copy calls its own
    /// generated functions directly and the compiler fuses them: the generated
    /// [`Reduction::prepare_lean`] is always inlined, so the constants' scratch on the stack
    /// lives in registers (its zeros are never stored, no constant makes a trip through memory
    /// and there is no virtual call); a model whose functions cannot be inlined (one loaded
    /// from a tape) zeroes the scratch once per call.
    #[inline(always)]
    fn lean_start(&self, p: &[f64]) -> Option<LeanStart> {
        let info = self.info();
        let layout = info.reduction.as_ref()?;
        let sep_len = layout.separation_degree() + 1;
        let fall_len = layout.fall_degree? + 1;
        let mut margins = [0.0; LEAN_MAX_REQUIREMENTS];
        let margins = margins.get_mut(..info.requirements.len())?;
        if !parameters_pass(self, p, margins) {
            return None;
        }
        let red = self.reduction()?;
        let mut scratch = [0.0; LEAN_MAX_CONSTANTS];
        let k = scratch.get_mut(..info.n_constants)?;
        red.prepare_lean(p, k);
        let (mut separation, mut fall) = ([0.0; 4], [0.0; 3]);
        red.force_polynomial(k, 0, separation.get_mut(..sep_len)?);
        red.fall_polynomial(k, fall.get_mut(..fall_len)?);
        let sin_initial = *k.get(layout.k_sin_initial)?;
        // The first contact pushes at release, unless the derivation proved it does for every
        // parameter.
        if !layout.release_push_proven && !pushes(&separation, sin_initial) {
            return None;
        }
        let mut others = [[0.0; LEAN_OTHER_COEFFICIENTS]; LEAN_MAX_OTHERS];
        let mut n_others = 0;
        for (i, c) in info.contacts.iter().enumerate().skip(1) {
            if !c.closed {
                return None;
            }
            if c.bilateral || *layout.pushes_proven.get(i)? {
                continue;
            }
            let degree = *layout.force_degrees.get(i)?;
            let row = others.get_mut(n_others)?;
            red.force_polynomial(k, i, row.get_mut(..degree.checked_add(1)?)?);
            n_others += 1;
        }
        Some(LeanStart {
            sin_initial,
            cos_initial: *k.get(layout.k_cos_initial)?,
            theta_dot_initial: *k.get(layout.k_theta_dot_initial)?,
            separation,
            fall,
            others,
            n_others,
        })
    }

    /// Requirement margins from the parameters alone (each must be `> 0`), in the order of
    /// [`ModelInfo::requirements`]. `out.len()` must equal that list's length.
    fn requirements(&self, p: &[f64], out: &mut [f64]);

    /// Each contact's coefficient of restitution from the parameters alone (the spec's
    /// `restitution`, `0` where it gives none), in the order of [`ModelInfo::contacts`].
    /// `out.len()` must equal that list's length; [`Bound`](crate::system::Bound) checks that
    /// each lies in `[0, 1]`.
    fn restitutions(&self, p: &[f64], out: &mut [f64]);

    /// Prepared constants for a parameter set: `k.len()` must be [`ModelInfo::n_constants`].
    /// Call only after [`Model::requirements`] passed.
    fn prepare(&self, p: &[f64], k: &mut [f64]);

    /// The state at release (from the spec's `initial`, where a coordinate a contact
    /// eliminates starts where `gap = 0` puts it; or a phase's start parameters).
    fn initial_state(&self, k: &[f64], q: &mut [f64], qd: &mut [f64]);

    /// Positions and velocities of the named points for a full state.
    fn points(&self, k: &[f64], q: &[f64], qd: &[f64], pos: &mut [[f64; 2]], vel: &mut [[f64; 2]]);

    /// Total energy (kinetic plus potential) of a full state.
    fn energy(&self, k: &[f64], q: &[f64], qd: &[f64]) -> f64;

    /// Momenta conjugate to the cyclic coordinates, in the order of [`ModelInfo::cyclic`].
    fn momenta(&self, k: &[f64], q: &[f64], qd: &[f64], out: &mut [f64]);

    /// The unreduced Euler–Lagrange equations `M(q) qdd = F(q, qd)` (before the forces of the
    /// contacts this model does not eliminate, and of friction): `mass` is row-major `n x n`,
    /// `rhs` has length `n`, with `n` the number of coordinates.
    fn equations(&self, k: &[f64], q: &[f64], qd: &[f64], mass: &mut [f64], rhs: &mut [f64]);

    /// The forces of the contacts this model holds closed, from a full state and its
    /// acceleration, one per contact of [`ModelInfo::contacts`] (zero for the others, whose
    /// forces the runtime solves).
    fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]);

    /// Every contact's gap (`>= 0` while apart), one per contact (zero for those this model
    /// holds closed).
    fn gaps(&self, k: &[f64], q: &[f64], out: &mut [f64]);

    /// Every contact's constraint row: `jac` (row-major `m x n`, `m` contacts by `n`
    /// coordinates) is `d gap / dq` and `bias` is `dJ/dt qd`, so that a contact's normal
    /// acceleration is `J qdd + bias` and its force `lambda` acts as `lambda J^T` (rows of
    /// closed contacts are zero).
    fn constraints(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]);

    /// Every contact's edge margin (`>= 0` while its contact point is on the body), one per
    /// contact; `f64::INFINITY` for a contact without an edge.
    fn edges(&self, k: &[f64], q: &[f64], out: &mut [f64]);

    /// The slip velocities of the frictions, `v = J(q) qd`, as the Jacobian `jac` (row-major
    /// `m x n`, `m` frictions by `n` coordinates) and `bias = dJ/dt qd`, the part of the slip
    /// acceleration `dv/dt = J qdd + bias` free of `qdd`. Both empty without friction.
    fn friction(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]);

    /// Monitor values (each must stay `>= 0`), in the order of [`ModelInfo::monitors`], from a
    /// full state and the contacts' forces at it (one per contact).
    fn monitors_full(&self, k: &[f64], q: &[f64], qd: &[f64], forces: &[f64], out: &mut [f64]);

    /// The system's state (the general model's coordinates and velocities, in the order of
    /// [`ModelInfo::system_coordinates`]) that this model's state stands for: its own
    /// coordinates, and those it eliminates where their contacts' ties put them.
    fn to_full(&self, k: &[f64], q: &[f64], qd: &[f64], q_full: &mut [f64], qd_full: &mut [f64]);

    /// The drawing of a full state: each body's pose `[x, y, angle]` (its centre of mass and
    /// orientation, in the order of [`ModelInfo::bodies`]) and the numbers of every shape of
    /// [`ModelInfo::shapes`] (parameter-only: the same for every state).
    /// `poses.len()` is the number of bodies, `sizes.len()` [`ModelInfo::drawing_sizes`].
    fn drawing(&self, k: &[f64], q: &[f64], poses: &mut [[f64; 3]], sizes: &mut [f64]);

    /// The forward-sensitivity rows of the model, if it has them (every generated general
    /// model does: the integrated phases' forward sensitivities need them; a fast phase or a
    /// hand-written test model has none).
    fn tangents(&self) -> Option<&dyn Tangents>;

    /// The fast path, if the model has one ([`ModelInfo::reduction`] describes it).
    fn reduction(&self) -> Option<&dyn Reduction>;
}

/// The fast path of a model whose coordinates other than `theta` are cyclic: the motion as a
/// function of the angle fallen `delta`, from the energy integral.
///
/// The same contract as [`Model`]'s: the caller passes `k` and every output at the lengths
/// [`ModelInfo`] and [`ReductionInfo`] give; [`System`](crate::system::System) is the checked
/// way to call these.
pub trait Reduction: Send + Sync {
    /// Reduced state at `delta`: returns `(sin theta, cos theta, theta_dot^2, theta_ddot)`.
    fn reduced(&self, k: &[f64], delta: f64) -> Reduced;

    /// `theta_dot^2` alone, at the angle given by its sine `s` and cosine `c` and their drops from
    /// the start, `ds = sin(theta_i) - s` and `dc = cos(theta_i) - c`: no trigonometric call and
    /// no `theta_ddot`. This is the integrand of the per-point solver
    /// [`LeanSolver`](crate::solve::fast::lean::LeanSolver), which parametrises the motion by
    /// `sin(theta)` and forms `ds` and `dc` exactly. Equal to
    /// `reduced(k, delta).theta_dot_sq` at the same angle.
    fn theta_dot_sq_sc(&self, k: &[f64], s: f64, c: f64, ds: f64, dc: f64) -> f64;

    /// Every contact's force at `delta` along the reduced motion (zero for a contact open in
    /// the phase), in the order of [`ModelInfo::contacts`].
    fn forces(&self, k: &[f64], delta: f64, out: &mut [f64]);

    /// Coefficients of contact `contact`'s force polynomial in `s = sin(theta)`, lowest degree
    /// first (`out.len() == force_degrees[contact] + 1`): its roots are the force's zeros, and
    /// it has the force's sign on the phase. Writes nothing for a contact without one. The
    /// first contact's is the separation polynomial: its root in `(0, sin theta_i)` is the
    /// separation.
    fn force_polynomial(&self, k: &[f64], contact: usize, out: &mut [f64]);

    /// Coefficients of the fall polynomial `P(s) = (sin theta_i - s) / theta_dot^2` in
    /// `s = sin(theta)`, lowest degree first (`out.len() == fall_degree + 1`), for a phase
    /// with [`ReductionInfo::fall_degree`]: one that starts from rest with a potential linear in
    /// `sin(theta)` and a reduced inertia polynomial in it. The time integrand is then
    /// `sqrt(P(s) / (1 + s))` up to the substitution's factor, singular only at the zeros of
    /// `P` and at `s = -1`, which lets the per-point solver choose its rule a priori. Writes
    /// nothing for a phase without one.
    fn fall_polynomial(&self, k: &[f64], out: &mut [f64]);

    /// The partial derivatives behind the fast path's sensitivities, if it has them (every
    /// generated one does; a hand-written test phase may not, and then has no sensitivities).
    fn partials(&self) -> Option<&dyn Partials>;

    /// [`Model::prepare`] for the per-point solver: copies the parameters into `k` and computes
    /// only the constants of [`ReductionInfo::lean_constants`] (the start's sine, cosine and rate,
    /// and the force and fall polynomials), leaving the others as they were.
    fn prepare_lean(&self, p: &[f64], k: &mut [f64]);

    /// The full state on the reduced motion at time `t`, angle fallen `delta` and rate
    /// `theta_dot` (negative while falling): fills `q` and `qd`.
    fn full_state(
        &self,
        k: &[f64],
        t: f64,
        delta: f64,
        theta_dot: f64,
        q: &mut [f64],
        qd: &mut [f64],
    );
}

/// The state at which [`Tangents::tangent_rows`] differentiates a model's rows: the full
/// state, its accelerations and the forces, each held fixed.
#[derive(Debug, Clone, Copy)]
pub struct TangentPoint<'a> {
    /// The coordinates, one per [`ModelInfo::coordinates`].
    pub q: &'a [f64],
    /// The velocities.
    pub qd: &'a [f64],
    /// The accelerations.
    pub qdd: &'a [f64],
    /// Every contact's force, one per contact of [`ModelInfo::contacts`] (zero where open).
    pub forces: &'a [f64],
    /// Every friction's force, one per friction of [`ModelInfo::frictions`].
    pub friction: &'a [f64],
}

/// A general model's forward-sensitivity rows ([`Model::tangents`]): partial derivatives of
/// its rows and of its initial state over the state and the parameters.
///
/// The same contract as [`Model`]'s: every slice at the length [`ModelInfo`] gives it.
pub trait Tangents: Send + Sync {
    /// Partial derivatives over `x = [q, qd, p]` (`2 n + np` columns, `np` the parameters of
    /// [`ModelInfo::parameters`] in order; row-major) of these rows, at the point `at` (the
    /// state, the accelerations `qdd`, every contact's force and every friction's force `fr`,
    /// each of `qdd`, the forces and `fr` held fixed):
    ///
    /// 1. `n` rows: the equations of motion's residual `M qdd - F - J^T forces - T^T fr`
    ///    ([`Model::equations`], [`Model::constraints`], [`Model::friction`]);
    /// 2. one row per contact: its normal acceleration `J qdd + bias`;
    /// 3. one row per friction: its slip acceleration `T qdd + c`;
    /// 4. one row per contact: its gap ([`Model::gaps`]; a zero row where it is zero);
    /// 5. one row per contact: its edge margin ([`Model::edges`]; a zero row without an edge);
    /// 6. one row per friction: its slip velocity `T qd`.
    ///
    /// `out.len()` is `(n + 3 m + 2 nf) (2 n + np)` with `m` contacts and `nf` frictions.
    /// The parameters' columns are total derivatives through `k` (which must be
    /// [`Model::prepare`]'s for the same parameters). A friction coefficient's column is zero
    /// (the friction forces are held): it acts through a sliding friction's law
    /// `f = -s mu lambda`, which the caller differentiates.
    fn tangent_rows(&self, k: &[f64], at: &TangentPoint<'_>, out: &mut [f64]);

    /// `d(initial state)/dp`: `2 n` rows over the parameters (`np` columns, row-major), rows
    /// `0..n` the coordinates' `dq_i/dp`, rows `n..2 n` the velocities' `dqd_i/dp` (grouped, not
    /// interleaved as [`Model::initial_state`] assigns them).
    fn initial_tangents(&self, k: &[f64], out: &mut [f64]);
}

/// The partial derivatives behind a fast path's sensitivities ([`Reduction::partials`]), read
/// from `k`'s parameters alone.
///
/// The same contract as [`Model`]'s: every slice at the length [`ModelInfo`] and
/// [`ReductionInfo`] give it.
pub trait Partials: Send + Sync {
    /// `[dF/dtheta, dF/dp_1, ...]` (`out.len() == 1 + parameters`) at the angle of sine `s` and
    /// cosine `c`, of the separation condition `F = 0` divided by a coefficient (any nonzero
    /// factor gives the same `d theta_sep/dp = -F_p / F_theta` at the separation). Writes
    /// nothing for a phase without a separation polynomial.
    fn separation_partials(&self, k: &[f64], s: f64, c: f64, out: &mut [f64]);

    /// `d(theta_dot^2)/dp` for every parameter (`out.len() == parameters`) at the fixed angle
    /// of sine `s` and cosine `c`.
    fn theta_dot_sq_partials(&self, k: &[f64], s: f64, c: f64, out: &mut [f64]);

    /// `d(sin theta_i)/dp` for every parameter (`out.len() == parameters`).
    fn start_partials(&self, k: &[f64], out: &mut [f64]);

    /// `dP_j/dp_i` of the fall polynomial's coefficients, parameter by parameter with `j`
    /// fastest (`out.len() == parameters * (fall_degree + 1)`). Writes nothing without one.
    fn fall_partials(&self, k: &[f64], out: &mut [f64]);
}

/// The quick test of a model's parameter values (the full check with its messages is
/// [`check_parameters`](crate::system::check_parameters)): the right counts, every value
/// positive and finite and every requirement's margin (written to `margins`, one entry per
/// requirement) positive. Passing it means the full check accepts; failing it leaves the
/// verdict to the full check.
#[inline(always)]
pub(crate) fn parameters_pass<M: Model + ?Sized>(
    model: &M,
    p: &[f64],
    margins: &mut [f64],
) -> bool {
    let info = model.info();
    if p.len() != info.parameters.len()
        || margins.len() != info.requirements.len()
        || !p.iter().all(|&v| positive_finite(v))
    {
        return false;
    }
    model.requirements(p, margins);
    margins.iter().all(|&m| m > 0.0)
}

/// `p(x)` by Horner's rule (coefficients lowest degree first), with separate multiplies and
/// adds (without a hardware FMA target feature `f64::mul_add` is a library call several times
/// slower than the arithmetic). The crate's one copy (`solve::fast::poly` re-exports it).
#[inline]
pub fn horner(coeffs: &[f64], x: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, &c| acc * x + c)
}

/// Whether the force polynomial `p` pushes at `x` (a NaN is no push: `partial_cmp` is `None`,
/// not `Greater`).
#[inline(always)]
pub(crate) fn pushes(p: &[f64], x: f64) -> bool {
    horner(p, x).partial_cmp(&0.0) == Some(std::cmp::Ordering::Greater)
}

/// Whether `v` is positive and finite, by one integer comparison: as bits, the positive finite
/// floats are exactly `1..=f64::MAX.to_bits()` (zero is 0, negatives have the sign bit set,
/// infinity and NaN lie above `f64::MAX`).
#[inline(always)]
pub(crate) fn positive_finite(v: f64) -> bool {
    v.to_bits().wrapping_sub(1) < f64::MAX.to_bits()
}

/// The reduced state at one angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reduced {
    /// `sin(theta)`.
    pub sin: f64,
    /// `cos(theta)`.
    pub cos: f64,
    /// `theta_dot^2` from the energy integral (eq. 9 for the paper's model).
    pub theta_dot_sq: f64,
    /// `theta_ddot = (1/2) d(theta_dot^2)/d(theta)`.
    pub theta_ddot: f64,
}

/// `(sin theta, cos theta, sin theta_i - sin theta, cos theta_i - cos theta)` at
/// `theta = theta_i - delta`. `sin` and `cos` come from the angle itself (full relative
/// accuracy down to the floor); the two differences are formed without cancellation as
/// `sin theta_i - sin theta = sin theta_i (1 - cos delta) + cos theta_i sin delta` and
/// `cos theta_i - cos theta = cos theta_i (1 - cos delta) - sin theta_i sin delta`, with
/// `1 - cos delta = 2 sin^2(delta/2)`.
#[inline]
pub fn start_offsets(theta_i: f64, sin_i: f64, cos_i: f64, delta: f64) -> (f64, f64, f64, f64) {
    let (sh, ch) = (0.5 * delta).sin_cos();
    let sin_delta = 2.0 * sh * ch;
    let vers = 2.0 * sh * sh;
    let ds = sin_i * vers + cos_i * sin_delta;
    let dc = cos_i * vers - sin_i * sin_delta;
    let (s, c) = (theta_i - delta).sin_cos();
    (s, c, ds, dc)
}

#[cfg(test)]
mod tests {
    use super::positive_finite;

    #[test]
    fn positive_finite_is_the_two_comparisons() {
        let values = [
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            f64::from_bits(1),
            1.0,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
            -1.0,
            -f64::from_bits(1),
            -f64::MAX,
        ];
        for v in values {
            assert_eq!(positive_finite(v), v > 0.0 && v < f64::INFINITY, "{v:e}");
        }
    }
}
