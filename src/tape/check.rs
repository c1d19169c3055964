//! The loader's checks: each method of a tape against its signature, every index against the
//! lengths its model's `ModelInfo` gives, every register read after it is written. What passes
//! is a [`Program`] that cannot index out of bounds.

use super::format::{Arg, Binary, Function, Instr, Unary};
use super::info::Info;

/// The methods a tape may hold, in the order of [`METHODS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Method {
    Requirements,
    Restitutions,
    Prepare,
    InitialState,
    Points,
    Energy,
    Momenta,
    Equations,
    ForcesFull,
    Gaps,
    Constraints,
    Edges,
    Friction,
    MonitorsFull,
    ToFull,
    Drawing,
    TangentRows,
    InitialTangents,
    Reduced,
    ThetaDotSqSc,
    Forces,
    ForcePolynomial,
    PrepareLean,
    FallPolynomial,
    SeparationPartials,
    ThetaDotSqPartials,
    StartPartials,
    FallPartials,
    FullState,
}

/// How long an argument is, from the model's info.
#[derive(Debug, Clone, Copy)]
enum Len {
    One,
    Params,
    ParamsPlusOne,
    Constants,
    Coords,
    SystemCoords,
    Contacts,
    Frictions,
    Requirements,
    Cyclic,
    Monitors,
    PointPairs,
    BodyTriples,
    Sizes,
    CoordsSquared,
    ContactRows,
    FrictionRows,
    TangentTable,
    InitialTangentTable,
    Reduced,
    Fall,
    FallPartials,
}

use Arg as A;
use Len as L;

/// A method's name in the trait, its arguments and its outputs.
pub struct Signature {
    /// The method.
    pub method: Method,
    /// Its name.
    pub name: &'static str,
    inputs: &'static [(Arg, Len)],
    outputs: &'static [(Arg, Len)],
    /// Whether it belongs to the fast path ([`Reduction`](crate::model::Reduction)).
    pub reduction: bool,
}

const STATE: &[(Arg, Len)] = &[(A::K, L::Constants), (A::Q, L::Coords), (A::Qd, L::Coords)];

/// Every method, in the order a [`TapeModel`](super::TapeModel) keeps them.
pub const METHODS: &[Signature] = &[
    sig(
        Method::Requirements,
        "requirements",
        &[(A::P, L::Params)],
        &[(A::Out, L::Requirements)],
    ),
    sig(
        Method::Restitutions,
        "restitutions",
        &[(A::P, L::Params)],
        &[(A::Out, L::Contacts)],
    ),
    sig(
        Method::Prepare,
        "prepare",
        &[(A::P, L::Params)],
        &[(A::K, L::Constants)],
    ),
    sig(
        Method::InitialState,
        "initial_state",
        &[(A::K, L::Constants)],
        &[(A::Q, L::Coords), (A::Qd, L::Coords)],
    ),
    sig(
        Method::Points,
        "points",
        STATE,
        &[(A::Pos, L::PointPairs), (A::Vel, L::PointPairs)],
    ),
    sig(Method::Energy, "energy", STATE, &[(A::Ret, L::One)]),
    sig(Method::Momenta, "momenta", STATE, &[(A::Out, L::Cyclic)]),
    sig(
        Method::Equations,
        "equations",
        STATE,
        &[(A::Mass, L::CoordsSquared), (A::Rhs, L::Coords)],
    ),
    sig(
        Method::ForcesFull,
        "forces_full",
        &[
            (A::K, L::Constants),
            (A::Q, L::Coords),
            (A::Qd, L::Coords),
            (A::Qdd, L::Coords),
        ],
        &[(A::Out, L::Contacts)],
    ),
    sig(
        Method::Gaps,
        "gaps",
        &[(A::K, L::Constants), (A::Q, L::Coords)],
        &[(A::Out, L::Contacts)],
    ),
    sig(
        Method::Constraints,
        "constraints",
        STATE,
        &[(A::Jac, L::ContactRows), (A::Bias, L::Contacts)],
    ),
    sig(
        Method::Edges,
        "edges",
        &[(A::K, L::Constants), (A::Q, L::Coords)],
        &[(A::Out, L::Contacts)],
    ),
    sig(
        Method::Friction,
        "friction",
        STATE,
        &[(A::Jac, L::FrictionRows), (A::Bias, L::Frictions)],
    ),
    sig(
        Method::MonitorsFull,
        "monitors_full",
        &[
            (A::K, L::Constants),
            (A::Q, L::Coords),
            (A::Qd, L::Coords),
            (A::Forces, L::Contacts),
        ],
        &[(A::Out, L::Monitors)],
    ),
    sig(
        Method::ToFull,
        "to_full",
        STATE,
        &[(A::QFull, L::SystemCoords), (A::QdFull, L::SystemCoords)],
    ),
    sig(
        Method::Drawing,
        "drawing",
        &[(A::K, L::Constants), (A::Q, L::Coords)],
        &[(A::Poses, L::BodyTriples), (A::Sizes, L::Sizes)],
    ),
    sig(
        Method::TangentRows,
        "tangent_rows",
        &[
            (A::K, L::Constants),
            (A::Q, L::Coords),
            (A::Qd, L::Coords),
            (A::Qdd, L::Coords),
            (A::Forces, L::Contacts),
            (A::Fr, L::Frictions),
        ],
        &[(A::Out, L::TangentTable)],
    ),
    sig(
        Method::InitialTangents,
        "initial_tangents",
        &[(A::K, L::Constants)],
        &[(A::Out, L::InitialTangentTable)],
    ),
    red(
        Method::Reduced,
        "reduced",
        &[(A::K, L::Constants), (A::Delta, L::One)],
        &[(A::Ret, L::Reduced)],
    ),
    red(
        Method::ThetaDotSqSc,
        "theta_dot_sq_sc",
        &[
            (A::K, L::Constants),
            (A::S, L::One),
            (A::C, L::One),
            (A::Ds, L::One),
            (A::Dc, L::One),
        ],
        &[(A::Ret, L::One)],
    ),
    red(
        Method::Forces,
        "forces",
        &[(A::K, L::Constants), (A::Delta, L::One)],
        &[(A::Out, L::Contacts)],
    ),
    // Its output's length depends on the case: checked against the contact's degree.
    red(
        Method::ForcePolynomial,
        "force_polynomial",
        &[(A::K, L::Constants)],
        &[(A::Out, L::One)],
    ),
    red(
        Method::PrepareLean,
        "prepare_lean",
        &[(A::P, L::Params)],
        &[(A::K, L::Constants)],
    ),
    red(
        Method::FallPolynomial,
        "fall_polynomial",
        &[(A::K, L::Constants)],
        &[(A::Out, L::Fall)],
    ),
    red(
        Method::SeparationPartials,
        "separation_partials",
        &[(A::K, L::Constants), (A::S, L::One), (A::C, L::One)],
        &[(A::Out, L::ParamsPlusOne)],
    ),
    red(
        Method::ThetaDotSqPartials,
        "theta_dot_sq_partials",
        &[(A::K, L::Constants), (A::S, L::One), (A::C, L::One)],
        &[(A::Out, L::Params)],
    ),
    red(
        Method::StartPartials,
        "start_partials",
        &[(A::K, L::Constants)],
        &[(A::Out, L::Params)],
    ),
    red(
        Method::FallPartials,
        "fall_partials",
        &[(A::K, L::Constants)],
        &[(A::Out, L::FallPartials)],
    ),
    red(
        Method::FullState,
        "full_state",
        &[
            (A::K, L::Constants),
            (A::T, L::One),
            (A::Delta, L::One),
            (A::ThetaDot, L::One),
        ],
        &[(A::Q, L::Coords), (A::Qd, L::Coords)],
    ),
];

const fn sig(
    method: Method,
    name: &'static str,
    inputs: &'static [(Arg, Len)],
    outputs: &'static [(Arg, Len)],
) -> Signature {
    Signature {
        method,
        name,
        inputs,
        outputs,
        reduction: false,
    }
}

const fn red(
    method: Method,
    name: &'static str,
    inputs: &'static [(Arg, Len)],
    outputs: &'static [(Arg, Len)],
) -> Signature {
    Signature {
        method,
        name,
        inputs,
        outputs,
        reduction: true,
    }
}

/// The methods every model has; a tape without one of them is refused.
pub const REQUIRED: &[Method] = &[
    Method::Requirements,
    Method::Restitutions,
    Method::Prepare,
    Method::InitialState,
    Method::Points,
    Method::Energy,
    Method::Momenta,
    Method::Equations,
    Method::ForcesFull,
    Method::Gaps,
    Method::Constraints,
    Method::Edges,
    Method::Friction,
    Method::MonitorsFull,
    Method::ToFull,
    Method::Drawing,
];

/// The methods a fast path has besides its partial derivatives (every one of them, where the
/// info has a `reduction`).
pub const FAST_PATH: &[Method] = &[
    Method::Reduced,
    Method::ThetaDotSqSc,
    Method::Forces,
    Method::ForcePolynomial,
    Method::PrepareLean,
    Method::FallPolynomial,
    Method::FullState,
];

/// The fast path's partial derivatives: all of them or none.
pub const PARTIALS: &[Method] = &[
    Method::SeparationPartials,
    Method::ThetaDotSqPartials,
    Method::StartPartials,
    Method::FallPartials,
];

/// Every kind of length, for [`lengths`].
const LENS: &[Len] = &[
    L::One,
    L::Params,
    L::ParamsPlusOne,
    L::Constants,
    L::Coords,
    L::SystemCoords,
    L::Contacts,
    L::Frictions,
    L::Requirements,
    L::Cyclic,
    L::Monitors,
    L::PointPairs,
    L::BodyTriples,
    L::Sizes,
    L::CoordsSquared,
    L::ContactRows,
    L::FrictionRows,
    L::TangentTable,
    L::InitialTangentTable,
    L::Reduced,
    L::Fall,
    L::FallPartials,
];

/// How many numbers an argument or output of this kind has, from the info; `None` where that
/// overflows (an info [`lengths`] refuses).
fn length(len: Len, info: &Info) -> Option<usize> {
    let n = info.coordinates.len();
    let np = info.parameters.len();
    let m = info.contacts.len();
    let nf = info.frictions.len();
    let fall = match info.reduction.as_ref().and_then(|r| r.fall_degree) {
        Some(d) => d.checked_add(1)?,
        None => 0,
    };
    Some(match len {
        L::One => 1,
        L::Params => np,
        L::ParamsPlusOne => np.checked_add(1)?,
        L::Constants => info.n_constants,
        L::Coords => n,
        L::SystemCoords => info.system_coordinates.len(),
        L::Contacts => m,
        L::Frictions => nf,
        L::Requirements => info.requirements.len(),
        L::Cyclic => info.cyclic.len(),
        L::Monitors => info.monitors.len(),
        L::PointPairs => info.points.len().checked_mul(2)?,
        L::BodyTriples => info.bodies.len().checked_mul(3)?,
        L::Sizes => (info.shapes.iter()).try_fold(0, |most: usize, s| {
            let numbers = match s.kind {
                super::info::Kind::Circle => 3,
                _ => 4,
            };
            Some(most.max(s.first.checked_add(numbers)?))
        })?,
        L::CoordsSquared => n.checked_mul(n)?,
        L::ContactRows => m.checked_mul(n)?,
        L::FrictionRows => nf.checked_mul(n)?,
        L::TangentTable => {
            let rows = n
                .checked_add(m.checked_mul(3)?)?
                .checked_add(nf.checked_mul(2)?)?;
            rows.checked_mul(n.checked_mul(2)?.checked_add(np)?)?
        }
        L::InitialTangentTable => n.checked_mul(2)?.checked_mul(np)?,
        L::Reduced => 4,
        L::Fall => fall,
        L::FallPartials => fall.checked_mul(np)?,
    })
}

/// What has a length of this kind, for messages.
fn describe(len: Len) -> &'static str {
    match len {
        L::One | L::Reduced => "a scalar",
        L::Params => "`p`",
        L::ParamsPlusOne => "`separation_partials`' output",
        L::Constants => "`k`",
        L::Coords => "`q`",
        L::SystemCoords => "`q_full`",
        L::Contacts => "`forces`",
        L::Frictions => "`fr`",
        L::Requirements => "`requirements`' output",
        L::Cyclic => "`momenta`' output",
        L::Monitors => "`monitors_full`' output",
        L::PointPairs => "`pos`",
        L::BodyTriples => "`poses`",
        L::Sizes => "the drawing's `sizes` (a shape's `first` and its numbers)",
        L::CoordsSquared => "`mass`",
        L::ContactRows => "`constraints`' `jac`",
        L::FrictionRows => "`friction`'s `jac`",
        L::TangentTable => "`tangents`' output",
        L::InitialTangentTable => "`initial_tangents`' output",
        L::Fall => "`fall_polynomial`'s output",
        L::FallPartials => "`fall_partials`' output",
    }
}

/// What is wrong with the lengths the info gives the methods' arguments and outputs: one
/// past [`MAX_LENGTH`] (a caller sizes them from the info: a tape may not make it allocate
/// without bound), the drawing's sizes and each contact's force polynomial included.
pub fn lengths(info: &Info) -> Result<(), String> {
    let too_long = |what: &str| {
        format!("{what} would have more than the {MAX_LENGTH} numbers a method's output may have")
    };
    for &len in LENS {
        if length(len, info).is_none_or(|l| l > MAX_LENGTH) {
            return Err(too_long(describe(len)));
        }
    }
    if let Some(r) = &info.reduction {
        for (contact, &degree) in r.force_degrees.iter().enumerate() {
            if degree >= MAX_LENGTH {
                return Err(too_long(&format!(
                    "the force polynomial of contact {contact} (degree {degree})"
                )));
            }
        }
    }
    Ok(())
}

/// The most numbers an argument or output of a tape's method may have (every length a caller
/// sizes from the model's info: a tape whose info asks for more is refused).
pub const MAX_LENGTH: usize = 1 << 20;

/// The most registers one method may use (a bound on what a load allocates).
pub const MAX_REGISTERS: usize = 1 << 20;

/// A method's checked program: its instructions with each argument resolved to its place in
/// the call's inputs or outputs.
#[derive(Debug, Clone, Default)]
pub struct Program {
    /// The instructions run on every call.
    pub code: Vec<Op>,
    /// Per contact, the code run after `code` (only `force_polynomial` has cases).
    pub cases: Vec<(usize, Vec<Op>)>,
    /// How many registers it uses.
    pub registers: usize,
}

/// An instruction with its argument resolved (`Ld`, `St` and `Fill` name their slot in the
/// call's input and output lists) and the common arithmetic as variants of its own, so that
/// the evaluator dispatches once per instruction.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs)]
pub enum Op {
    Ld { dst: u32, slot: u8, index: u32 },
    LdOut { dst: u32, slot: u8, index: u32 },
    St { slot: u8, index: u32, src: u32 },
    Fill { slot: u8, value: f64 },
    Const { dst: u32, value: f64 },
    Add { dst: u32, a: u32, b: u32 },
    Sub { dst: u32, a: u32, b: u32 },
    Mul { dst: u32, a: u32, b: u32 },
    Div { dst: u32, a: u32, b: u32 },
    Neg { dst: u32, a: u32 },
    Sqrt { dst: u32, a: u32 },
    Unary { op: Unary, dst: u32, a: u32 },
    Powf { dst: u32, a: u32, b: u32 },
    Powi { dst: u32, a: u32, n: i32 },
    SinCos { sin: u32, cos: u32, a: u32 },
    StartOffsets { dst: [u32; 4], args: [u32; 4] },
}

/// The operation of an instruction that names no argument (`None` for one that does).
fn plain(i: Instr) -> Option<Op> {
    Some(match i {
        Instr::Const { dst, value } => Op::Const { dst, value },
        Instr::Binary { op, dst, a, b } => match op {
            Binary::Add => Op::Add { dst, a, b },
            Binary::Sub => Op::Sub { dst, a, b },
            Binary::Mul => Op::Mul { dst, a, b },
            Binary::Div => Op::Div { dst, a, b },
            Binary::Powf => Op::Powf { dst, a, b },
        },
        Instr::Unary {
            op: Unary::Neg,
            dst,
            a,
        } => Op::Neg { dst, a },
        Instr::Unary {
            op: Unary::Sqrt,
            dst,
            a,
        } => Op::Sqrt { dst, a },
        Instr::Unary { op, dst, a } => Op::Unary { op, dst, a },
        Instr::Powi { dst, a, n } => Op::Powi { dst, a, n },
        Instr::SinCos { sin, cos, a } => Op::SinCos { sin, cos, a },
        Instr::StartOffsets { dst, args } => Op::StartOffsets { dst, args },
        Instr::Load { .. } | Instr::Store { .. } | Instr::Fill { .. } => return None,
    })
}

/// Checks one function against its signature and the model's info, and resolves it.
pub fn program(f: &Function, s: &Signature, info: &Info) -> Result<Program, String> {
    if !f.cases.is_empty() && s.method != Method::ForcePolynomial {
        return Err("only `force_polynomial` may have cases".into());
    }
    let mut registers = 0;
    let mut written = Vec::new();
    let code = block(&f.code, s, info, None, &mut written, &mut registers)?;
    let mut cases = Vec::new();
    for case in &f.cases {
        let contact = case.contact as usize;
        let degree = (info.reduction.as_ref())
            .and_then(|r| r.force_degrees.get(contact))
            .ok_or_else(|| format!("a case for contact {contact}, which has no force degree"))?;
        if cases.iter().any(|(c, _)| *c == contact) {
            return Err(format!("two cases for contact {contact}"));
        }
        let mut written = written.clone();
        let ops = block(
            &case.code,
            s,
            info,
            Some(degree.saturating_add(1)),
            &mut written,
            &mut registers,
        )?;
        cases.push((contact, ops));
    }
    Ok(Program {
        code,
        cases,
        registers,
    })
}

fn block(
    code: &[Instr],
    s: &Signature,
    info: &Info,
    out_len: Option<usize>,
    written: &mut Vec<bool>,
    registers: &mut usize,
) -> Result<Vec<Op>, String> {
    let slot = |list: &[(Arg, Len)], arg: Arg, what: &str| {
        let i = (list.iter().position(|(a, _)| *a == arg))
            .ok_or_else(|| format!("`{}` is not {what} of `{}`", arg.name(), s.name))?;
        let len = match (out_len, arg) {
            (Some(n), Arg::Out) => n,
            _ => length(list[i].1, info).ok_or("a length that overflows")?,
        };
        Ok::<_, String>((i as u8, len))
    };
    let mut ops = Vec::with_capacity(code.len());
    for (at, instr) in code.iter().enumerate() {
        let fail = |m: String| {
            format!(
                "instruction {at} ({}): {m}",
                serde_json::Value::from(*instr)
            )
        };
        for r in instr.reads() {
            if !written.get(r as usize).copied().unwrap_or(false) {
                return Err(fail(format!(
                    "reads register {r} before anything writes it"
                )));
            }
        }
        for r in instr.writes() {
            let r = r as usize;
            if r >= MAX_REGISTERS {
                return Err(fail(format!(
                    "register {r} is past the {MAX_REGISTERS} a tape may use"
                )));
            }
            if r >= written.len() {
                written.resize(r + 1, false);
            }
            written[r] = true;
            *registers = (*registers).max(r + 1);
        }
        let in_range = |index: u32, len: usize, arg: Arg| {
            if (index as usize) < len {
                Ok(())
            } else {
                Err(fail(format!(
                    "index {index} is past `{}`'s {len} numbers",
                    arg.name()
                )))
            }
        };
        ops.push(match *instr {
            // An output may be read back (`prepare_lean` reads the constants it formed).
            Instr::Load { dst, arg, index } => match slot(s.inputs, arg, "an argument") {
                Ok((slot, len)) => {
                    in_range(index, len, arg)?;
                    Op::Ld { dst, slot, index }
                }
                Err(_) => {
                    let (slot, len) =
                        slot(s.outputs, arg, "an argument or output").map_err(fail)?;
                    in_range(index, len, arg)?;
                    Op::LdOut { dst, slot, index }
                }
            },
            Instr::Store { arg, index, src } => {
                let (slot, len) = slot(s.outputs, arg, "an output").map_err(fail)?;
                in_range(index, len, arg)?;
                Op::St { slot, index, src }
            }
            Instr::Fill { arg, value } => {
                let (slot, _) = slot(s.outputs, arg, "an output").map_err(fail)?;
                Op::Fill { slot, value }
            }
            other => plain(other).ok_or_else(|| fail("an argument left unresolved".into()))?,
        });
    }
    Ok(ops)
}

impl Signature {
    /// Its arguments, in the trait's order.
    pub fn inputs(&self) -> impl Iterator<Item = Arg> + '_ {
        self.inputs.iter().map(|(a, _)| *a)
    }

    /// Its outputs, in the trait's order (after the arguments).
    pub fn outputs(&self) -> impl Iterator<Item = Arg> + '_ {
        self.outputs.iter().map(|(a, _)| *a)
    }
}
