//! The tape writer: compiles a model's generated Rust (the text `model.rs.tera` rendered) into
//! its tape, the same straight-line program as operations on registers (`docs/tape.md`).
//!
//! The Rust is read with a real parser (syn), and every construct the emitter writes maps to
//! one operation with Rust's own semantics: `a * b * c` is `(a * b) * c`, `-x` is a negation
//! (never `0 - x`), `x.powi(n)` is binary powering, a literal is the `f64` Rust reads from it.
//! So the evaluator's results equal the compiled code's to the bit. Anything else the parser
//! meets is an error naming the method, never a guess.

use crate::tape::format::{
    Arg, Binary, Body, Case, FORMAT, Function, Instr, TapeFile, Unary, VERSION,
};
use serde_json::Value;
use std::collections::HashMap;
use syn::{BinOp, Expr, ImplItem, Item, Lit, Pat, Stmt, UnOp};

/// Methods of the generated code that are not programs: the model's description and its
/// capabilities, which the tape's info and its list of methods say.
const NOT_PROGRAMS: &[&str] = &["info", "reduction", "tangents", "partials"];

/// The named constants of `std::f64::consts` the generated code may use.
const CONSTS: &[(&str, f64)] = &[
    ("PI", std::f64::consts::PI),
    ("TAU", std::f64::consts::TAU),
    ("E", std::f64::consts::E),
    ("FRAC_PI_2", std::f64::consts::FRAC_PI_2),
    ("FRAC_PI_3", std::f64::consts::FRAC_PI_3),
    ("FRAC_PI_4", std::f64::consts::FRAC_PI_4),
    ("FRAC_PI_6", std::f64::consts::FRAC_PI_6),
    ("FRAC_PI_8", std::f64::consts::FRAC_PI_8),
    ("FRAC_1_PI", std::f64::consts::FRAC_1_PI),
    ("FRAC_2_PI", std::f64::consts::FRAC_2_PI),
    ("SQRT_2", std::f64::consts::SQRT_2),
    ("FRAC_1_SQRT_2", std::f64::consts::FRAC_1_SQRT_2),
    ("LN_2", std::f64::consts::LN_2),
    ("LN_10", std::f64::consts::LN_10),
    ("INFINITY", f64::INFINITY),
    ("NEG_INFINITY", f64::NEG_INFINITY),
];

/// What the tape records of where the model came from.
pub struct Origin<'a> {
    /// The model's name.
    pub model: &'a str,
    /// The spec's path relative to the project root.
    pub spec: &'a str,
    /// The spec's text.
    pub spec_text: &'a str,
}

/// The tape of a model from its generated Rust.
pub fn compile(rust: &str, origin: &Origin<'_>) -> Result<TapeFile, String> {
    let file =
        syn::parse_file(rust).map_err(|e| format!("the generated Rust does not parse: {e}"))?;
    let mut info = None;
    let mut methods: Vec<&syn::ImplItemFn> = Vec::new();
    for item in &file.items {
        match item {
            Item::Static(s) if s.ident == "INFO" => info = Some(to_json(&s.expr)?),
            Item::Impl(imp) => methods.extend(imp.items.iter().filter_map(|it| match it {
                ImplItem::Fn(f) => Some(f),
                _ => None,
            })),
            _ => {}
        }
    }
    let mut functions = Vec::new();
    for f in &methods {
        let name = f.sig.ident.to_string();
        if NOT_PROGRAMS.contains(&name.as_str()) {
            continue;
        }
        functions.push(function(f, &methods).map_err(|e| format!("method `{name}`: {e}"))?);
    }
    let info = info.ok_or("the generated Rust has no `static INFO`")?;
    let info = serde_json::from_value(info).map_err(|e| format!("`INFO`: {e}"))?;
    let body = Body { info, functions };
    Ok(TapeFile {
        format: FORMAT.into(),
        version: VERSION,
        generated_by: super::common::COMMAND.into(),
        model: origin.model.into(),
        spec: origin.spec.into(),
        spec_digest: crate::tape::format::digest(origin.spec_text),
        body_digest: body.digest(),
        body,
    })
}

/// A struct literal of `ModelInfo` (and its parts) as JSON: fields by name, slices as arrays,
/// `Some(x)` as `x`, `None` as null, an enum's variant by its name.
fn to_json(e: &Expr) -> Result<Value, String> {
    Ok(match e {
        Expr::Struct(s) => {
            let mut map = serde_json::Map::new();
            for f in &s.fields {
                let syn::Member::Named(name) = &f.member else {
                    return Err("a tuple field in `INFO`".into());
                };
                map.insert(name.to_string(), to_json(&f.expr)?);
            }
            Value::Object(map)
        }
        Expr::Reference(r) => to_json(&r.expr)?,
        Expr::Array(a) => Value::Array(a.elems.iter().map(to_json).collect::<Result<_, _>>()?),
        Expr::Call(c) if path_is(&c.func, "Some") && c.args.len() == 1 => to_json(&c.args[0])?,
        Expr::Path(p) if path_is(e, "None") => {
            let _ = p;
            Value::Null
        }
        Expr::Path(p) => match constant(&p.path) {
            Some(x) => number(x)?,
            None => Value::from(last_segment(&p.path)),
        },
        Expr::Lit(l) => match &l.lit {
            Lit::Str(s) => Value::from(s.value()),
            Lit::Bool(b) => Value::from(b.value),
            Lit::Int(i) => Value::from(i.base10_parse::<u64>().map_err(|e| e.to_string())?),
            Lit::Float(f) => number(f.base10_parse::<f64>().map_err(|e| e.to_string())?)?,
            _ => return Err("an unexpected literal in `INFO`".into()),
        },
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => match to_json(&u.expr)?.as_f64() {
            Some(x) => number(-x)?,
            None => return Err("a negated value that is not a number in `INFO`".into()),
        },
        Expr::Paren(p) => to_json(&p.expr)?,
        _ => return Err("an expression `INFO` cannot hold".into()),
    })
}

fn number(x: f64) -> Result<Value, String> {
    serde_json::Number::from_f64(x)
        .map(Value::Number)
        .ok_or_else(|| format!("{x} in `INFO` is not a finite number"))
}

fn path_is(e: &Expr, name: &str) -> bool {
    matches!(e, Expr::Path(p) if p.path.is_ident(name))
}

fn last_segment(p: &syn::Path) -> String {
    p.segments
        .last()
        .map(|s| s.ident.to_string())
        .unwrap_or_default()
}

/// The value of `f64::INFINITY`, `std::f64::consts::PI` and the like.
fn constant(p: &syn::Path) -> Option<f64> {
    let names: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
    let last = names.last()?;
    let prefix_ok = names.len() >= 2 && names[names.len() - 2] == "f64"
        || names.len() >= 3 && names[names.len() - 2] == "consts";
    (prefix_ok).then(|| CONSTS.iter().find(|(n, _)| n == last).map(|(_, v)| *v))?
}

/// What a name of the method's body stands for.
#[derive(Clone, Copy)]
enum Binding {
    /// A register.
    Reg(u32),
    /// A slice argument or output, read and written by index.
    Slice(Arg),
    /// A scalar argument, read as its element 0.
    Scalar(Arg),
    /// The contact a `force_polynomial` matches on.
    Contact,
    /// A `&TangentPoint` argument: its fields' slices, in [`POINT_FIELDS`]' order.
    Point([Arg; 5]),
}

/// The fields of a `TangentPoint`, in the order the tape's arguments give them.
const POINT_FIELDS: [&str; 5] = ["q", "qd", "qdd", "forces", "friction"];

/// Whether a parameter's type is a reference to a `TangentPoint`.
fn is_point(ty: &syn::Type) -> bool {
    let syn::Type::Reference(r) = ty else {
        return false;
    };
    matches!(&*r.elem, syn::Type::Path(p) if last_segment(&p.path) == "TangentPoint")
}

/// The compiler of one method.
struct Compiler<'a> {
    /// Every method of the model, for a call of one by another (inlined).
    methods: &'a [&'a syn::ImplItemFn],
    names: HashMap<String, Binding>,
    next: u32,
    code: Vec<Instr>,
}

/// The arguments that are numbers rather than slices.
const SCALARS: &[Arg] = &[
    Arg::Delta,
    Arg::S,
    Arg::C,
    Arg::Ds,
    Arg::Dc,
    Arg::T,
    Arg::ThetaDot,
];

fn function(f: &syn::ImplItemFn, methods: &[&syn::ImplItemFn]) -> Result<Function, String> {
    let name = f.sig.ident.to_string();
    let (inputs, outputs) = crate::tape::signature(&name).ok_or("not a method a tape may hold")?;
    let mut c = Compiler {
        methods,
        names: HashMap::new(),
        next: 0,
        code: Vec::new(),
    };
    let args: Vec<Binding> = (inputs.into_iter())
        .chain(outputs.into_iter().filter(|a| *a != Arg::Ret))
        .map(|arg| {
            if SCALARS.contains(&arg) {
                Binding::Scalar(arg)
            } else {
                Binding::Slice(arg)
            }
        })
        .collect();
    c.bind_parameters(f, &name, args)?;
    let mut cases = Vec::new();
    let n = f.block.stmts.len();
    for (i, stmt) in f.block.stmts.iter().enumerate() {
        c.statement(stmt, i + 1 == n, &mut cases)?;
    }
    Ok(Function {
        name,
        code: c.code,
        cases,
    })
}

impl Compiler<'_> {
    /// Binds a method's parameters (after `&self`) to what they stand for, in order.
    fn bind_parameters(
        &mut self,
        f: &syn::ImplItemFn,
        name: &str,
        args: Vec<Binding>,
    ) -> Result<(), String> {
        let mut args = args.into_iter();
        for input in f.sig.inputs.iter().skip(1) {
            let syn::FnArg::Typed(t) = input else {
                return Err("a second receiver".into());
            };
            let Pat::Ident(id) = &*t.pat else {
                return Err("a parameter that is not a name".into());
            };
            let pname = id.ident.to_string();
            if name == "force_polynomial" && pname.trim_start_matches('_') == "contact" {
                self.names.insert(pname, Binding::Contact);
                continue;
            }
            let mut next = || {
                args.next()
                    .ok_or("more parameters than the trait's method has")
            };
            let b = if is_point(&t.ty) {
                let mut fields = [Arg::Out; 5];
                for f in &mut fields {
                    match next()? {
                        Binding::Slice(a) => *f = a,
                        _ => return Err("a `TangentPoint` of something other than slices".into()),
                    }
                }
                Binding::Point(fields)
            } else {
                next()?
            };
            self.names.insert(pname, b);
        }
        Ok(())
    }

    /// `Trait::method(self, a, b)`: the other method's body, inlined with its parameters
    /// bound to this one's arguments `a, b`.
    fn inline(&mut self, call: &syn::ExprCall) -> Result<(), String> {
        let Expr::Path(p) = &*call.func else {
            return Err("a call of something other than a method".into());
        };
        let callee = last_segment(&p.path);
        let f = (self.methods.iter())
            .find(|m| m.sig.ident == callee)
            .ok_or_else(|| format!("a call of `{callee}`, which the model does not have"))?;
        let mut args = call.args.iter();
        if !args.next().is_some_and(|a| path_is(a, "self")) {
            return Err(format!(
                "a call of `{callee}` on something other than `self`"
            ));
        }
        let bound: Vec<Binding> = (args)
            .map(|a| {
                let name = name_of(a).ok_or("an argument that is not a name")?;
                (self.names.get(&name).copied()).ok_or_else(|| format!("`{name}` is not in scope"))
            })
            .collect::<Result<_, _>>()?;
        let saved = std::mem::take(&mut self.names);
        self.bind_parameters(f, &callee, bound)?;
        let mut cases = Vec::new();
        for stmt in &f.block.stmts {
            self.statement(stmt, false, &mut cases)?;
        }
        self.names = saved;
        if cases.is_empty() {
            Ok(())
        } else {
            Err(format!("a call of `{callee}`, which matches on a contact"))
        }
    }

    fn fresh(&mut self) -> u32 {
        self.next += 1;
        self.next - 1
    }

    fn emit(&mut self, make: impl FnOnce(u32) -> Instr) -> u32 {
        let dst = self.fresh();
        self.code.push(make(dst));
        dst
    }

    fn statement(&mut self, stmt: &Stmt, last: bool, cases: &mut Vec<Case>) -> Result<(), String> {
        match stmt {
            Stmt::Local(local) => self.local(local),
            Stmt::Expr(e, semi) => {
                if semi.is_none() && last && !matches!(e, Expr::Match(_)) {
                    return self.returned(e);
                }
                self.effect(e, cases)
            }
            Stmt::Item(_) | Stmt::Macro(_) => Err("an item or macro in a method's body".into()),
        }
    }

    fn local(&mut self, local: &syn::Local) -> Result<(), String> {
        let init = &local.init.as_ref().ok_or("a `let` without a value")?.expr;
        match &local.pat {
            // `let k = &k[..N];`: one bounds check for the loads, nothing to compute.
            Pat::Ident(id) if matches!(&**init, Expr::Reference(_)) => {
                let Expr::Reference(r) = &**init else {
                    return Err("a reference".into());
                };
                let Expr::Index(ix) = &*r.expr else {
                    return Err("a reference to something other than a range of a slice".into());
                };
                if !matches!(&*ix.index, Expr::Range(_))
                    || !path_is(&ix.expr, &id.ident.to_string())
                {
                    return Err("a reference to something other than a range of a slice".into());
                }
                Ok(())
            }
            // `let q = at.q;`: a field of a `TangentPoint` argument, a slice.
            Pat::Ident(id) if matches!(&**init, Expr::Field(_)) => {
                let Expr::Field(f) = &**init else {
                    return Err("a field".into());
                };
                let point = name_of(&f.base).and_then(|n| self.names.get(&n).copied());
                let (Some(Binding::Point(args)), syn::Member::Named(field)) = (point, &f.member)
                else {
                    return Err("a field of something other than a `TangentPoint`".into());
                };
                let i = (POINT_FIELDS.iter().position(|x| field == x)).ok_or_else(|| {
                    format!("a field `{field}` that `TangentPoint` does not have")
                })?;
                self.names
                    .insert(id.ident.to_string(), Binding::Slice(args[i]));
                Ok(())
            }
            Pat::Ident(id) => {
                let r = self.expr(init)?;
                self.names.insert(id.ident.to_string(), Binding::Reg(r));
                Ok(())
            }
            Pat::Tuple(t) => {
                let names: Vec<Option<String>> = (t.elems.iter())
                    .map(|p| match p {
                        Pat::Ident(id) => Ok(Some(id.ident.to_string())),
                        Pat::Wild(_) => Ok(None),
                        _ => Err("a tuple of something other than names".to_string()),
                    })
                    .collect::<Result<_, _>>()?;
                let regs = self.tuple(init, names.len())?;
                for (n, r) in names.into_iter().zip(regs) {
                    if let Some(n) = n {
                        self.names.insert(n, Binding::Reg(r));
                    }
                }
                Ok(())
            }
            _ => Err("a `let` of a pattern the generated code never writes".into()),
        }
    }

    /// `x.sin_cos()` and `start_offsets(a, b, c, d)`, the calls that give tuples.
    fn tuple(&mut self, init: &Expr, n: usize) -> Result<Vec<u32>, String> {
        match init {
            Expr::MethodCall(m) if m.method == "sin_cos" && m.args.is_empty() && n == 2 => {
                let a = self.expr(&m.receiver)?;
                let (sin, cos) = (self.fresh(), self.fresh());
                self.code.push(Instr::SinCos { sin, cos, a });
                Ok(vec![sin, cos])
            }
            Expr::Call(c) if path_is(&c.func, "start_offsets") && c.args.len() == 4 && n == 4 => {
                let mut args = [0; 4];
                for (slot, a) in args.iter_mut().zip(&c.args) {
                    *slot = self.expr(a)?;
                }
                let dst = [self.fresh(), self.fresh(), self.fresh(), self.fresh()];
                self.code.push(Instr::StartOffsets { dst, args });
                Ok(dst.to_vec())
            }
            _ => Err("a tuple from a call other than `sin_cos` or `start_offsets`".into()),
        }
    }

    /// The method's returned value: a number, or a `Reduced`'s fields in order.
    fn returned(&mut self, e: &Expr) -> Result<(), String> {
        if let Expr::Struct(s) = e {
            const FIELDS: [&str; 4] = ["sin", "cos", "theta_dot_sq", "theta_ddot"];
            for f in &s.fields {
                let syn::Member::Named(name) = &f.member else {
                    return Err("a tuple field".into());
                };
                let index = (FIELDS.iter().position(|x| name == x))
                    .ok_or_else(|| format!("a field `{name}` that `Reduced` does not have"))?;
                let src = self.expr(&f.expr)?;
                self.code.push(Instr::Store {
                    arg: Arg::Ret,
                    index: index as u32,
                    src,
                });
            }
            return Ok(());
        }
        let src = self.expr(e)?;
        self.code.push(Instr::Store {
            arg: Arg::Ret,
            index: 0,
            src,
        });
        Ok(())
    }

    fn slice_of(&self, e: &Expr) -> Result<Arg, String> {
        let name = name_of(e).ok_or("an index into something other than an argument")?;
        match self.names.get(&name) {
            Some(Binding::Slice(a)) => Ok(*a),
            _ => Err(format!("`{name}` indexed, but it is not a slice argument")),
        }
    }

    /// A statement for its effect: a store, a fill, a copy of the parameters, a match.
    fn effect(&mut self, e: &Expr, cases: &mut Vec<Case>) -> Result<(), String> {
        match e {
            Expr::Assign(a) => {
                let Expr::Index(ix) = &*a.left else {
                    return Err("an assignment to something other than an output's element".into());
                };
                let arg = self.slice_of(&ix.expr)?;
                let index = int(&ix.index)?;
                if let Expr::Array(arr) = &*a.right {
                    let width = arr.elems.len() as u32;
                    for (j, el) in arr.elems.iter().enumerate() {
                        let src = self.expr(el)?;
                        self.code.push(Instr::Store {
                            arg,
                            index: index * width + j as u32,
                            src,
                        });
                    }
                } else {
                    let src = self.expr(&a.right)?;
                    self.code.push(Instr::Store { arg, index, src });
                }
                Ok(())
            }
            Expr::MethodCall(m) if m.method == "fill" && m.args.len() == 1 => {
                let arg = self.slice_of(&m.receiver)?;
                let value = literal(&m.args[0])?;
                self.code.push(Instr::Fill { arg, value });
                Ok(())
            }
            // `k[..N].copy_from_slice(p)`: the parameters at the head of the constants.
            Expr::MethodCall(m) if m.method == "copy_from_slice" && m.args.len() == 1 => {
                let Expr::Index(ix) = &*m.receiver else {
                    return Err("a copy into something other than a range".into());
                };
                let Expr::Range(range) = &*ix.index else {
                    return Err("a copy into something other than a range".into());
                };
                if range.start.is_some() {
                    return Err("a copy into a range that does not start at 0".into());
                }
                let end = int(range.end.as_deref().ok_or("a copy into an open range")?)?;
                let to = self.slice_of(&ix.expr)?;
                let from = self.slice_of(&m.args[0])?;
                for index in 0..end {
                    let r = self.emit(|dst| Instr::Load {
                        dst,
                        arg: from,
                        index,
                    });
                    self.code.push(Instr::Store {
                        arg: to,
                        index,
                        src: r,
                    });
                }
                Ok(())
            }
            Expr::Match(m) => self.cases(m, cases),
            Expr::Call(call) => self.inline(call),
            _ => Err("a statement the generated code never writes".into()),
        }
    }

    /// `match contact { 0 => { .. } .. _ => {} }`: one case per contact.
    fn cases(&mut self, m: &syn::ExprMatch, cases: &mut Vec<Case>) -> Result<(), String> {
        let name = name_of(&m.expr).unwrap_or_default();
        if !matches!(self.names.get(&name), Some(Binding::Contact)) {
            return Err("a match on something other than the contact".into());
        }
        for arm in &m.arms {
            let contact = match &arm.pat {
                Pat::Lit(l) => match &l.lit {
                    Lit::Int(i) => i.base10_parse::<u32>().map_err(|e| e.to_string())?,
                    _ => return Err("a match arm that is not a contact's index".into()),
                },
                Pat::Wild(_) => {
                    if !matches!(&*arm.body, Expr::Block(b) if b.block.stmts.is_empty()) {
                        return Err("a match's fallback arm that does something".into());
                    }
                    continue;
                }
                _ => return Err("a match arm that is not a contact's index".into()),
            };
            let Expr::Block(b) = &*arm.body else {
                return Err("a match arm that is not a block".into());
            };
            let saved = (self.names.clone(), std::mem::take(&mut self.code));
            let mut nested = Vec::new();
            for stmt in &b.block.stmts {
                self.statement(stmt, false, &mut nested)?;
            }
            if !nested.is_empty() {
                return Err("a match inside a match".into());
            }
            let code = std::mem::replace(&mut self.code, saved.1);
            self.names = saved.0;
            cases.push(Case { contact, code });
        }
        Ok(())
    }

    /// An arithmetic expression's value, in a register.
    fn expr(&mut self, e: &Expr) -> Result<u32, String> {
        match e {
            Expr::Paren(p) => self.expr(&p.expr),
            Expr::Lit(_) => {
                let value = literal(e)?;
                Ok(self.emit(|dst| Instr::Const { dst, value }))
            }
            Expr::Path(p) => {
                if let Some(value) = constant(&p.path) {
                    return Ok(self.emit(|dst| Instr::Const { dst, value }));
                }
                let name = name_of(e).unwrap_or_default();
                match self.names.get(&name) {
                    Some(Binding::Reg(r)) => Ok(*r),
                    Some(Binding::Scalar(arg)) => {
                        let arg = *arg;
                        Ok(self.emit(|dst| Instr::Load { dst, arg, index: 0 }))
                    }
                    _ => Err(format!("`{name}` is not a number in scope")),
                }
            }
            Expr::Index(ix) => {
                let arg = self.slice_of(&ix.expr)?;
                let index = int(&ix.index)?;
                Ok(self.emit(|dst| Instr::Load { dst, arg, index }))
            }
            Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => {
                let a = self.expr(&u.expr)?;
                Ok(self.emit(|dst| Instr::Unary {
                    op: Unary::Neg,
                    dst,
                    a,
                }))
            }
            Expr::Binary(b) => {
                let op = match b.op {
                    BinOp::Add(_) => Binary::Add,
                    BinOp::Sub(_) => Binary::Sub,
                    BinOp::Mul(_) => Binary::Mul,
                    BinOp::Div(_) => Binary::Div,
                    _ => return Err("an operator other than + - * /".into()),
                };
                let a = self.expr(&b.left)?;
                let bb = self.expr(&b.right)?;
                Ok(self.emit(|dst| Instr::Binary { op, dst, a, b: bb }))
            }
            Expr::MethodCall(m) => self.call(m),
            _ => Err("an expression the generated code never writes".into()),
        }
    }

    fn call(&mut self, m: &syn::ExprMethodCall) -> Result<u32, String> {
        let method = m.method.to_string();
        let a = self.expr(&m.receiver)?;
        match (method.as_str(), m.args.len()) {
            ("powi", 1) => {
                let n = signed_int(&m.args[0])?;
                Ok(self.emit(|dst| Instr::Powi { dst, a, n }))
            }
            ("powf", 1) => {
                let b = self.expr(&m.args[0])?;
                Ok(self.emit(|dst| Instr::Binary {
                    op: Binary::Powf,
                    dst,
                    a,
                    b,
                }))
            }
            (name, 0) => {
                let op = (crate::tape::format::UNARY.iter())
                    .find(|(_, code)| *code == name && *code != "neg")
                    .map(|(op, _)| *op)
                    .ok_or_else(|| format!("a call of `{name}`, which a tape does not have"))?;
                Ok(self.emit(|dst| Instr::Unary { op, dst, a }))
            }
            (name, _) => Err(format!("a call of `{name}` with arguments")),
        }
    }
}

/// The name an expression is, where it is a bare name (`k`, `delta`, `contact`).
fn name_of(e: &Expr) -> Option<String> {
    match e {
        Expr::Path(p) => p.path.get_ident().map(|i| i.to_string()),
        _ => None,
    }
}

/// An index written as an integer literal.
fn int(e: &Expr) -> Result<u32, String> {
    match e {
        Expr::Lit(l) => match &l.lit {
            Lit::Int(i) => i.base10_parse::<u32>().map_err(|e| e.to_string()),
            _ => Err("an index that is not an integer".into()),
        },
        _ => Err("an index that is not an integer literal".into()),
    }
}

/// `powi`'s exponent: an integer literal, maybe negated.
fn signed_int(e: &Expr) -> Result<i32, String> {
    match e {
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => Ok(-signed_int(&u.expr)?),
        Expr::Paren(p) => signed_int(&p.expr),
        _ => i32::try_from(int(e)?).map_err(|e| e.to_string()),
    }
}

/// A number literal (or a named constant such as `f64::INFINITY`), as Rust reads it.
fn literal(e: &Expr) -> Result<f64, String> {
    match e {
        Expr::Lit(l) => match &l.lit {
            Lit::Float(f) => f.base10_parse::<f64>().map_err(|e| e.to_string()),
            Lit::Int(i) => i.base10_parse::<f64>().map_err(|e| e.to_string()),
            _ => Err("a literal that is not a number".into()),
        },
        Expr::Path(p) => constant(&p.path).ok_or_else(|| "a name where a number is due".into()),
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => Ok(-literal(&u.expr)?),
        _ => Err("a value that is not a literal".into()),
    }
}
