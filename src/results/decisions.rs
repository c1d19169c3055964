//! What the solvers found when they decided which contacts are closed, as data: how a friction
//! moves ([`Mode`], [`Sign`]), a set of closed contacts and friction modes by name
//! ([`ContactSet`]), how supports hold a system at rest ([`Holding`]) and why no single set
//! could be decided ([`Indeterminacy`]). The report puts each into words.

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

/// A set of closed contacts, with the mode of each friction that acts, by name.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ContactSet {
    /// The closed contacts, in the system's order.
    pub closed: Vec<&'static str>,
    /// Each acting friction (its contact closed) and its mode, in the system's order.
    pub frictions: Vec<(&'static str, Mode)>,
}

/// How supports hold a system at rest.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Holding {
    /// Redundant supports, whatever share of the load each takes.
    Redundantly,
    /// Supports that pin every coordinate.
    Pinned,
    /// A set in which nothing accelerates beyond rounding.
    InEquilibrium,
}

/// Why no single set of closed contacts and friction modes, or of impulses, was decided.
#[derive(Debug, Clone, PartialEq)]
pub enum Indeterminacy {
    /// More combinations of contact states and friction modes than are tried.
    TooManyCombinations {
        /// The most tried.
        limit: usize,
    },
    /// No set is consistent (a contact would have to pull, or sticking needs more than `mu N`
    /// while no sliding direction accelerates the slip: Painlevé's inconsistency).
    NoneConsistent {
        /// The sets whose equations are singular.
        singular: Vec<ContactSet>,
    },
    /// Several consistent sets give different motions (Painlevé's indeterminacy).
    SeveralMotions {
        /// The sets with as many stuck frictions as any, which disagree.
        sets: Vec<ContactSet>,
        /// The consistent sets in all.
        of: usize,
    },
    /// Sliding reached Painlevé's singularity: the sliding equations' determinant fell to
    /// `floor` of the frictionless one.
    PainleveSingularity {
        /// The sliding set.
        set: ContactSet,
        /// The coordinates there.
        q: Vec<f64>,
        /// The determinants' ratio where sliding is given up.
        floor: f64,
    },
    /// The support rows pin every coordinate, yet their normal equations are singular.
    RestSingular,
    /// The redundant supports' forces form a family with more vertices than are searched.
    RestTooLarge {
        /// The most vertices searched.
        limit: usize,
    },
    /// More contacts take part in one impact than are solved together.
    ImpactTooManyContacts {
        /// The most contacts of one impact.
        limit: usize,
    },
    /// No set of impulses satisfies Newton's law and Coulomb's cone with the contacts pushing.
    ImpactNoImpulses,
    /// Several sets of impulses do, with different velocities after.
    ImpactSeveral {
        /// How many.
        count: usize,
    },
    /// A converging sequence of impacts ends while a contact outside it takes part.
    ZenoOutsideContact,
    /// The contacts of a converging sequence cannot all be held closed at once.
    ZenoCannotHold,
}
