//! The tape file's layout (`generated/<model>.tape.json`, format described in `docs/tape.md`):
//! the serde types the derivation tool writes and the loader reads, and the digest of a body.
//!
//! A tape holds the same straight-line program as the model's generated Rust: each method of
//! [`Model`](crate::model::Model) and [`Reduction`](crate::model::Reduction) as a list of
//! operations on registers, loading from the method's arguments and storing into its outputs.
//! This file only reads and writes that shape; what an instruction may name is checked by
//! `check.rs` against the model's [`ModelInfo`](crate::model::ModelInfo).

use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The value of a tape's `format` field.
pub const FORMAT: &str = "rodcube-tape";

/// The version of the format this build reads and writes. A tape of another version is
/// refused with the command that regenerates it.
pub const VERSION: u32 = 2;

/// A whole tape file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TapeFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`] of the writer.
    pub version: u32,
    /// The command that wrote it (never edit a tape by hand).
    pub generated_by: String,
    /// The model's name (also in the body's `info`).
    pub model: String,
    /// The spec it was derived from, relative to the project root (`derivations/x.yaml`).
    pub spec: String,
    /// FNV-1a digest of the spec's text when it was derived ([`digest`]).
    pub spec_digest: String,
    /// FNV-1a digest of the body as [`Body::digest`] computes it: a truncated or edited body
    /// does not match it.
    pub body_digest: String,
    /// The model: its description and its program.
    pub body: Body,
}

/// What a tape describes: the model's [`ModelInfo`](crate::model::ModelInfo) and its methods.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// The fields of the model's `ModelInfo`, as the generated Rust's `INFO` holds them.
    pub info: super::info::Info,
    /// One entry per method the model implements, in the generated Rust's order.
    pub functions: Vec<Function>,
}

impl Body {
    /// The digest of the body: FNV-1a of its compact JSON (fields in declaration order, so the
    /// same for every build of serde_json).
    pub fn digest(&self) -> String {
        digest(&serde_json::to_string(self).unwrap_or_default())
    }
}

/// One method's program.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Function {
    /// The method's name in the trait (`equations`, `reduced`, ...).
    pub name: String,
    /// Instructions run on every call.
    pub code: Vec<Instr>,
    /// For a method that matches on its `contact` argument (`force_polynomial`): the code of
    /// each contact, run after `code`; a contact without a case runs nothing more.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cases: Vec<Case>,
}

/// The code of one arm of a match on the contact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// The contact's index.
    pub contact: u32,
    /// Its instructions.
    pub code: Vec<Instr>,
}

/// An argument or output of a method, by its name in the trait.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Arg {
    /// Parameters.
    P,
    /// Prepared constants.
    K,
    /// Coordinates.
    Q,
    /// Velocities.
    Qd,
    /// Accelerations.
    Qdd,
    /// Contact forces.
    Forces,
    /// Friction forces.
    Fr,
    /// The angle fallen since the start (scalar).
    Delta,
    /// `sin(theta)` (scalar).
    S,
    /// `cos(theta)` (scalar).
    C,
    /// `sin(theta_i) - sin(theta)` (scalar).
    Ds,
    /// `cos(theta_i) - cos(theta)` (scalar).
    Dc,
    /// Time (scalar).
    T,
    /// The reduced rate (scalar).
    ThetaDot,
    /// The method's output vector.
    Out,
    /// Points' positions, two numbers a point.
    Pos,
    /// Points' velocities, two numbers a point.
    Vel,
    /// The mass matrix, row-major.
    Mass,
    /// The right-hand side.
    Rhs,
    /// A Jacobian, row-major.
    Jac,
    /// A bias.
    Bias,
    /// The system's coordinates.
    QFull,
    /// The system's velocities.
    QdFull,
    /// Bodies' poses, three numbers a body.
    Poses,
    /// The drawing's sizes.
    Sizes,
    /// A returned value (`energy`, `theta_dot_sq_sc`) or the fields of a returned `Reduced`.
    Ret,
}

/// Every argument with its name in a tape.
pub const ARGS: &[(Arg, &str)] = &[
    (Arg::P, "p"),
    (Arg::K, "k"),
    (Arg::Q, "q"),
    (Arg::Qd, "qd"),
    (Arg::Qdd, "qdd"),
    (Arg::Forces, "forces"),
    (Arg::Fr, "fr"),
    (Arg::Delta, "delta"),
    (Arg::S, "s"),
    (Arg::C, "c"),
    (Arg::Ds, "ds"),
    (Arg::Dc, "dc"),
    (Arg::T, "t"),
    (Arg::ThetaDot, "theta_dot"),
    (Arg::Out, "out"),
    (Arg::Pos, "pos"),
    (Arg::Vel, "vel"),
    (Arg::Mass, "mass"),
    (Arg::Rhs, "rhs"),
    (Arg::Jac, "jac"),
    (Arg::Bias, "bias"),
    (Arg::QFull, "q_full"),
    (Arg::QdFull, "qd_full"),
    (Arg::Poses, "poses"),
    (Arg::Sizes, "sizes"),
    (Arg::Ret, "ret"),
];

impl Arg {
    /// Its name in a tape.
    pub fn name(self) -> &'static str {
        ARGS.iter()
            .find(|(a, _)| *a == self)
            .map_or("?", |(_, n)| n)
    }

    /// The argument of this name.
    pub fn from_name(name: &str) -> Option<Arg> {
        ARGS.iter().find(|(_, n)| *n == name).map(|(a, _)| *a)
    }
}

/// A function of one register.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unary {
    /// `-a`.
    Neg,
    /// `a.sqrt()`.
    Sqrt,
    /// `a.sin()`.
    Sin,
    /// `a.cos()`.
    Cos,
    /// `a.tan()`.
    Tan,
    /// `a.asin()`.
    Asin,
    /// `a.acos()`.
    Acos,
    /// `a.atan()`.
    Atan,
    /// `a.exp()`.
    Exp,
    /// `a.ln()`.
    Ln,
    /// `a.abs()`.
    Abs,
}

/// Every unary operation with its operation code (the Rust method's name; `neg` for `-a`).
pub const UNARY: &[(Unary, &str)] = &[
    (Unary::Neg, "neg"),
    (Unary::Sqrt, "sqrt"),
    (Unary::Sin, "sin"),
    (Unary::Cos, "cos"),
    (Unary::Tan, "tan"),
    (Unary::Asin, "asin"),
    (Unary::Acos, "acos"),
    (Unary::Atan, "atan"),
    (Unary::Exp, "exp"),
    (Unary::Ln, "ln"),
    (Unary::Abs, "abs"),
];

/// A function of two registers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binary {
    /// `a + b`.
    Add,
    /// `a - b`.
    Sub,
    /// `a * b`.
    Mul,
    /// `a / b`.
    Div,
    /// `a.powf(b)`.
    Powf,
}

/// Every binary operation with its operation code.
pub const BINARY: &[(Binary, &str)] = &[
    (Binary::Add, "add"),
    (Binary::Sub, "sub"),
    (Binary::Mul, "mul"),
    (Binary::Div, "div"),
    (Binary::Powf, "powf"),
];

/// One operation. Registers are numbered from 0; an argument's index counts its numbers
/// (a point's `pos` row `i` is indices `2 i` and `2 i + 1`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Instr {
    /// `["ld", dst, arg, index]`: `r[dst] = arg[index]`.
    Load {
        /// Destination register.
        dst: u32,
        /// The argument read.
        arg: Arg,
        /// Its index.
        index: u32,
    },
    /// `["st", arg, index, src]`: `arg[index] = r[src]`.
    Store {
        /// The output written.
        arg: Arg,
        /// Its index.
        index: u32,
        /// Source register.
        src: u32,
    },
    /// `["fill", arg, value]`: every number of the output set to `value`.
    Fill {
        /// The output.
        arg: Arg,
        /// The value.
        value: f64,
    },
    /// `["const", dst, value]`: `r[dst] = value` (`"inf"`, `"-inf"` for the infinities).
    Const {
        /// Destination register.
        dst: u32,
        /// The value.
        value: f64,
    },
    /// `[op, dst, a]`: `r[dst] = op(r[a])`.
    Unary {
        /// The function.
        op: Unary,
        /// Destination register.
        dst: u32,
        /// Operand register.
        a: u32,
    },
    /// `[op, dst, a, b]`: `r[dst] = r[a] op r[b]`.
    Binary {
        /// The function.
        op: Binary,
        /// Destination register.
        dst: u32,
        /// First operand's register.
        a: u32,
        /// Second operand's register.
        b: u32,
    },
    /// `["powi", dst, a, n]`: `r[dst] = r[a].powi(n)`, by binary powering (as `powi` is).
    Powi {
        /// Destination register.
        dst: u32,
        /// Base's register.
        a: u32,
        /// The integer exponent.
        n: i32,
    },
    /// `["sin_cos", sin_dst, cos_dst, a]`: `(r[sin_dst], r[cos_dst]) = r[a].sin_cos()`.
    SinCos {
        /// Register of the sine.
        sin: u32,
        /// Register of the cosine.
        cos: u32,
        /// Operand register.
        a: u32,
    },
    /// `["start_offsets", s, c, ds, dc, theta_i, sin_i, cos_i, delta]`: the four results of
    /// [`start_offsets`](crate::model::start_offsets) of the four operand registers.
    StartOffsets {
        /// Destination registers of `sin`, `cos`, `ds`, `dc`.
        dst: [u32; 4],
        /// Operand registers `theta_i`, `sin_i`, `cos_i`, `delta`.
        args: [u32; 4],
    },
}

impl Instr {
    /// The registers it writes.
    pub fn writes(&self) -> Vec<u32> {
        match *self {
            Instr::Load { dst, .. }
            | Instr::Const { dst, .. }
            | Instr::Unary { dst, .. }
            | Instr::Binary { dst, .. }
            | Instr::Powi { dst, .. } => vec![dst],
            Instr::SinCos { sin, cos, .. } => vec![sin, cos],
            Instr::StartOffsets { dst, .. } => dst.to_vec(),
            Instr::Store { .. } | Instr::Fill { .. } => Vec::new(),
        }
    }

    /// The registers it reads.
    pub fn reads(&self) -> Vec<u32> {
        match *self {
            Instr::Store { src, .. } => vec![src],
            Instr::Unary { a, .. } | Instr::Powi { a, .. } | Instr::SinCos { a, .. } => vec![a],
            Instr::Binary { a, b, .. } => vec![a, b],
            Instr::StartOffsets { args, .. } => args.to_vec(),
            Instr::Load { .. } | Instr::Fill { .. } | Instr::Const { .. } => Vec::new(),
        }
    }
}

/// A number as a tape writes it: JSON's own, and the infinities and NaN as strings.
fn number(x: f64) -> Value {
    match serde_json::Number::from_f64(x) {
        Some(n) => Value::Number(n),
        None if x.is_nan() => Value::from("nan"),
        None if x > 0.0 => Value::from("inf"),
        None => Value::from("-inf"),
    }
}

fn read_number(v: &Value) -> Result<f64, String> {
    match v {
        Value::Number(n) => n.as_f64().ok_or_else(|| format!("{n} is not a number")),
        Value::String(s) if s == "inf" => Ok(f64::INFINITY),
        Value::String(s) if s == "-inf" => Ok(f64::NEG_INFINITY),
        Value::String(s) if s == "nan" => Ok(f64::NAN),
        other => Err(format!("{other} is not a number")),
    }
}

fn read_index(v: &Value, what: &str) -> Result<u32, String> {
    v.as_u64()
        .and_then(|n| u32::try_from(n).ok())
        .ok_or_else(|| {
            format!(
                "{what} {v} is not an index (an integer from 0 to {})",
                u32::MAX
            )
        })
}

fn read_arg(v: &Value) -> Result<Arg, String> {
    v.as_str().and_then(Arg::from_name).ok_or_else(|| {
        let names: Vec<&str> = ARGS.iter().map(|(_, n)| *n).collect();
        format!("{v} is not an argument (one of {})", names.join(", "))
    })
}

impl From<Instr> for Value {
    fn from(i: Instr) -> Value {
        let r = |x: u32| Value::from(x);
        let items: Vec<Value> = match i {
            Instr::Load { dst, arg, index } => {
                vec!["ld".into(), r(dst), arg.name().into(), r(index)]
            }
            Instr::Store { arg, index, src } => {
                vec!["st".into(), arg.name().into(), r(index), r(src)]
            }
            Instr::Fill { arg, value } => vec!["fill".into(), arg.name().into(), number(value)],
            Instr::Const { dst, value } => vec!["const".into(), r(dst), number(value)],
            Instr::Unary { op, dst, a } => vec![unary_code(op).into(), r(dst), r(a)],
            Instr::Binary { op, dst, a, b } => vec![binary_code(op).into(), r(dst), r(a), r(b)],
            Instr::Powi { dst, a, n } => vec!["powi".into(), r(dst), r(a), Value::from(n)],
            Instr::SinCos { sin, cos, a } => vec!["sin_cos".into(), r(sin), r(cos), r(a)],
            Instr::StartOffsets { dst, args } => std::iter::once(Value::from("start_offsets"))
                .chain(dst.iter().chain(&args).map(|&x| r(x)))
                .collect(),
        };
        Value::Array(items)
    }
}

fn unary_code(op: Unary) -> &'static str {
    UNARY.iter().find(|(u, _)| *u == op).map_or("?", |(_, c)| c)
}

fn binary_code(op: Binary) -> &'static str {
    BINARY
        .iter()
        .find(|(b, _)| *b == op)
        .map_or("?", |(_, c)| c)
}

impl TryFrom<Value> for Instr {
    type Error = String;

    fn try_from(v: Value) -> Result<Instr, String> {
        let Value::Array(items) = &v else {
            return Err(format!(
                "an instruction is an array `[operation, ...]`, not {v}"
            ));
        };
        let Some(code) = items.first().and_then(Value::as_str) else {
            return Err(format!(
                "an instruction starts with its operation's name: {v}"
            ));
        };
        let operands = &items[1..];
        let arity = |n: usize| {
            if operands.len() == n {
                Ok(())
            } else {
                Err(format!(
                    "operation `{code}` takes {n} operands, not {}: {v}",
                    operands.len()
                ))
            }
        };
        let reg = |i: usize| read_index(&operands[i], "register");
        if let Some((op, _)) = UNARY.iter().find(|(_, c)| *c == code) {
            arity(2)?;
            return Ok(Instr::Unary {
                op: *op,
                dst: reg(0)?,
                a: reg(1)?,
            });
        }
        if let Some((op, _)) = BINARY.iter().find(|(_, c)| *c == code) {
            arity(3)?;
            return Ok(Instr::Binary {
                op: *op,
                dst: reg(0)?,
                a: reg(1)?,
                b: reg(2)?,
            });
        }
        match code {
            "ld" => {
                arity(3)?;
                Ok(Instr::Load {
                    dst: reg(0)?,
                    arg: read_arg(&operands[1])?,
                    index: read_index(&operands[2], "index")?,
                })
            }
            "st" => {
                arity(3)?;
                Ok(Instr::Store {
                    arg: read_arg(&operands[0])?,
                    index: read_index(&operands[1], "index")?,
                    src: reg(2)?,
                })
            }
            "fill" => {
                arity(2)?;
                Ok(Instr::Fill {
                    arg: read_arg(&operands[0])?,
                    value: read_number(&operands[1])?,
                })
            }
            "const" => {
                arity(2)?;
                Ok(Instr::Const {
                    dst: reg(0)?,
                    value: read_number(&operands[1])?,
                })
            }
            "powi" => {
                arity(3)?;
                let n = (operands[2].as_i64())
                    .and_then(|n| i32::try_from(n).ok())
                    .ok_or_else(|| format!("exponent {} is not a 32-bit integer", operands[2]))?;
                Ok(Instr::Powi {
                    dst: reg(0)?,
                    a: reg(1)?,
                    n,
                })
            }
            "sin_cos" => {
                arity(3)?;
                Ok(Instr::SinCos {
                    sin: reg(0)?,
                    cos: reg(1)?,
                    a: reg(2)?,
                })
            }
            "start_offsets" => {
                arity(8)?;
                Ok(Instr::StartOffsets {
                    dst: [reg(0)?, reg(1)?, reg(2)?, reg(3)?],
                    args: [reg(4)?, reg(5)?, reg(6)?, reg(7)?],
                })
            }
            other => Err(format!("unknown operation `{other}`")),
        }
    }
}

impl Serialize for Instr {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        Value::from(*self).serialize(s)
    }
}

impl<'de> Deserialize<'de> for Instr {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Instr, D::Error> {
        Instr::try_from(Value::deserialize(d)?).map_err(serde::de::Error::custom)
    }
}

/// FNV-1a 64-bit digest of a text, as 16 hex digits (the one the manifest of `generated/`
/// uses; stable across platforms and Rust versions).
pub fn digest(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// The text of a tape as the derivation writes it: the header's fields one a line, then the
/// body with one instruction a line (so that a change to a model reads as a small diff).
pub fn render(tape: &TapeFile) -> String {
    let j = |v: &dyn erased::Json| v.json();
    let mut out = String::from("{\n");
    let header: [(&str, String); 7] = [
        ("format", j(&tape.format)),
        ("version", j(&tape.version)),
        ("generated_by", j(&tape.generated_by)),
        ("model", j(&tape.model)),
        ("spec", j(&tape.spec)),
        ("spec_digest", j(&tape.spec_digest)),
        ("body_digest", j(&tape.body_digest)),
    ];
    for (name, value) in header {
        out.push_str(&format!("  \"{name}\": {value},\n"));
    }
    out.push_str("  \"body\": {\n");
    let info = serde_json::to_string_pretty(&tape.body.info).unwrap_or_default();
    out.push_str(&format!(
        "    \"info\": {},\n",
        info.replace('\n', "\n    ")
    ));
    out.push_str("    \"functions\": [");
    for (i, f) in tape.body.functions.iter().enumerate() {
        out.push_str(if i == 0 { "\n" } else { ",\n" });
        out.push_str(&format!("      {{\"name\": {}, \"code\": ", j(&f.name)));
        write_code(&mut out, &f.code, "        ");
        if !f.cases.is_empty() {
            out.push_str(", \"cases\": [");
            for (c, case) in f.cases.iter().enumerate() {
                out.push_str(if c == 0 { "\n" } else { ",\n" });
                out.push_str(&format!(
                    "        {{\"contact\": {}, \"code\": ",
                    case.contact
                ));
                write_code(&mut out, &case.code, "          ");
                out.push('}');
            }
            out.push_str("\n      ]");
        }
        out.push('}');
    }
    out.push_str("\n    ]\n  }\n}\n");
    out
}

fn write_code(out: &mut String, code: &[Instr], indent: &str) {
    if code.is_empty() {
        out.push_str("[]");
        return;
    }
    out.push('[');
    for (i, instr) in code.iter().enumerate() {
        out.push_str(if i == 0 { "\n" } else { ",\n" });
        out.push_str(indent);
        out.push_str(&Value::from(*instr).to_string());
    }
    out.push(']');
}

/// Compact JSON of the header's values.
mod erased {
    /// A value printed as compact JSON.
    pub trait Json {
        /// Its JSON text.
        fn json(&self) -> String;
    }

    impl<T: serde::Serialize> Json for T {
        fn json(&self) -> String {
            serde_json::to_string(self).unwrap_or_default()
        }
    }
}
