//! Lowers derived expressions to straight-line Rust: shared subexpressions become `let`s,
//! parameter-only subexpressions are hoisted into the prepared constants `k`.

use super::expr::{Expr, float_literal};
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// Names an expression's free symbols resolve to in generated code.
#[derive(Debug, Clone, Default)]
pub struct Scope {
    /// Symbols that live in the constant vector `k`, with their index.
    pub constants: BTreeMap<String, usize>,
    /// Symbols that are local variables (function arguments or earlier `let`s), with their
    /// Rust spelling.
    pub locals: BTreeMap<String, String>,
}

/// Parameter-only subexpressions collected across all functions, to be computed once in
/// `prepare` and read from `k`.
#[derive(Debug, Clone, Default)]
pub struct Hoisted {
    /// (k index, defining expression over earlier constants) in evaluation order.
    pub entries: Vec<(usize, Expr)>,
    by_key: HashMap<String, usize>,
    next: usize,
}

impl Hoisted {
    /// Starts numbering hoisted constants at `first`.
    pub fn new(first: usize) -> Hoisted {
        Hoisted {
            entries: Vec::new(),
            by_key: HashMap::new(),
            next: first,
        }
    }

    /// Makes a subexpression equal to `e` read the constant already at `k[idx]` instead of
    /// hoisting a copy (a start constant that an initial value repeats, say).
    pub fn known(&mut self, e: &Expr, idx: usize) {
        self.by_key.entry(e.to_infix()).or_insert(idx);
    }

    /// Total length of `k` after hoisting.
    pub fn len(&self) -> usize {
        self.next
    }

    /// Whether nothing was hoisted.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    fn index_of(&mut self, e: &Expr) -> usize {
        let key = e.to_infix();
        if let Some(i) = self.by_key.get(&key) {
            return *i;
        }
        let i = self.next;
        self.next += 1;
        self.by_key.insert(key, i);
        self.entries.push((i, e.clone()));
        i
    }
}

/// A lowered function body: `let` lines and the final output expressions, all Rust text.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Body {
    /// `(name, rust expression)` pairs, in order.
    pub lets: Vec<(String, String)>,
    /// One Rust expression per requested output.
    pub outputs: Vec<String>,
}

/// Lowers `outputs` (which may refer to each other's names only through `scope.locals`).
///
/// Subexpressions over constants only are hoisted (when `hoist` is given); other repeated
/// subexpressions become `let`s named `t0, t1, ...` (prefixed with `prefix`).
pub fn lower(outputs: &[Expr], scope: &Scope, hoist: Option<&mut Hoisted>, prefix: &str) -> Body {
    let mut hoist = hoist;
    // 1. Replace constant-only subtrees by k-symbols.
    let outputs: Vec<Expr> = outputs
        .iter()
        .map(|e| match hoist.as_deref_mut() {
            Some(h) => hoist_constants(e, scope, h),
            None => e.clone(),
        })
        .collect();
    // 2. Count repeated non-trivial subtrees.
    let mut counts: HashMap<String, usize> = HashMap::new();
    for e in &outputs {
        count(e, &mut counts);
    }
    let mut lets: Vec<(String, String)> = Vec::new();
    let mut named: HashMap<String, String> = HashMap::new();
    let mut lowered = Vec::new();
    for e in &outputs {
        let text = emit(e, scope, &counts, &mut named, &mut lets, prefix);
        lowered.push(text);
    }
    Body {
        lets,
        outputs: lowered,
    }
}

fn is_trivial(e: &Expr) -> bool {
    matches!(e, Expr::Rational(..) | Expr::Float(_) | Expr::Sym(_))
        || matches!(e, Expr::Pow(b, x) if matches!(**b, Expr::Sym(_)) && x.as_integer() == Some(-1))
}

fn count(e: &Expr, counts: &mut HashMap<String, usize>) {
    if is_trivial(e) {
        return;
    }
    let key = e.to_infix();
    let n = counts.entry(key).or_insert(0);
    *n += 1;
    if *n > 1 {
        return; // children were counted the first time
    }
    match e {
        Expr::Add(v) | Expr::Mul(v) | Expr::Fun(_, v) => v.iter().for_each(|c| count(c, counts)),
        Expr::Pow(b, x) => {
            count(b, counts);
            count(x, counts);
        }
        _ => {}
    }
}

fn constant_only(e: &Expr, scope: &Scope) -> bool {
    e.symbols().iter().all(|s| scope.constants.contains_key(s))
}

fn hoist_constants(e: &Expr, scope: &Scope, h: &mut Hoisted) -> Expr {
    if is_trivial(e) {
        return e.clone();
    }
    if constant_only(e, scope) && !e.symbols().is_empty() {
        let i = h.index_of(e);
        return Expr::Sym(format!("rc_k{i}"));
    }
    // Sums: collect like terms first (`k1*s*c + k2*s*c` -> `(k1 + k2)*s*c`), so each
    // monomial of the motion costs one hoisted coefficient.
    if let Expr::Add(v) = e {
        let mut groups: Vec<(String, Expr, Vec<Expr>)> = Vec::new();
        for t in v {
            let factors = match t {
                Expr::Mul(f) => f.clone(),
                x => vec![x.clone()],
            };
            let (coef, rest): (Vec<Expr>, Vec<Expr>) =
                factors.into_iter().partition(|f| constant_only(f, scope));
            let rest = super::expr::product(rest);
            let key = rest.to_infix();
            match groups.iter_mut().find(|g| g.0 == key) {
                Some(g) => g.2.push(super::expr::product(coef)),
                None => groups.push((key, rest, vec![super::expr::product(coef)])),
            }
        }
        if groups.len() < v.len() {
            let terms = groups
                .into_iter()
                .map(|(_, rest, coefs)| Expr::Mul(vec![super::expr::sum(coefs), rest]).tidy())
                .collect();
            return hoist_constants(&super::expr::sum(terms), scope, h);
        }
    }
    // Products and sums: hoist the constant part as one factor / term.
    match e {
        Expr::Mul(v) | Expr::Add(v) => {
            let (consts, rest): (Vec<&Expr>, Vec<&Expr>) = v
                .iter()
                .partition(|c| constant_only(c, scope) && !c.symbols().is_empty());
            let mut out: Vec<Expr> = Vec::new();
            let numeric: Vec<&Expr> = rest
                .iter()
                .copied()
                .filter(|c| c.symbols().is_empty())
                .collect();
            let rest: Vec<&Expr> = rest
                .into_iter()
                .filter(|c| !c.symbols().is_empty())
                .collect();
            let mut group: Vec<Expr> = numeric.into_iter().cloned().collect();
            group.extend(consts.into_iter().cloned());
            let has_const = group.iter().any(|c| !c.symbols().is_empty());
            if has_const {
                let g = if matches!(e, Expr::Mul(_)) {
                    super::expr::product(group)
                } else {
                    super::expr::sum(group)
                };
                let i = h.index_of(&g);
                out.push(Expr::Sym(format!("rc_k{i}")));
            } else {
                out.extend(group);
            }
            out.extend(rest.into_iter().map(|c| hoist_constants(c, scope, h)));
            if matches!(e, Expr::Mul(_)) {
                super::expr::product(out)
            } else {
                super::expr::sum(out)
            }
        }
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(hoist_constants(b, scope, h)),
            Box::new(hoist_constants(x, scope, h)),
        ),
        Expr::Fun(f, args) => Expr::Fun(
            f.clone(),
            args.iter().map(|a| hoist_constants(a, scope, h)).collect(),
        ),
        _ => e.clone(),
    }
}

fn emit(
    e: &Expr,
    scope: &Scope,
    counts: &HashMap<String, usize>,
    named: &mut HashMap<String, String>,
    lets: &mut Vec<(String, String)>,
    prefix: &str,
) -> String {
    if !is_trivial(e) {
        let key = e.to_infix();
        if let Some(name) = named.get(&key) {
            return name.clone();
        }
        if counts.get(&key).copied().unwrap_or(0) > 1 {
            let text = emit_node(e, scope, counts, named, lets, prefix);
            let name = format!("{prefix}t{}", lets.len());
            lets.push((name.clone(), text));
            named.insert(key, name.clone());
            return name;
        }
    }
    emit_node(e, scope, counts, named, lets, prefix)
}

fn emit_node(
    e: &Expr,
    scope: &Scope,
    counts: &HashMap<String, usize>,
    named: &mut HashMap<String, String>,
    lets: &mut Vec<(String, String)>,
    prefix: &str,
) -> String {
    let mut sub = |x: &Expr| emit(x, scope, counts, named, lets, prefix);
    match e {
        Expr::Rational(n, 1) => float_literal(*n as f64),
        Expr::Rational(n, d) => format!(
            "({} / {})",
            float_literal(*n as f64),
            float_literal(*d as f64)
        ),
        Expr::Float(x) => float_literal(*x),
        Expr::Sym(s) => {
            if let Some(i) = s.strip_prefix("rc_k").and_then(|i| i.parse::<usize>().ok()) {
                format!("k[{i}]")
            } else if let Some(i) = scope.constants.get(s) {
                format!("k[{i}]")
            } else if let Some(l) = scope.locals.get(s) {
                l.clone()
            } else {
                // The deriver guarantees every symbol is in scope; an unknown one is a bug
                // that the compile step of the generated code would catch.
                format!("UNBOUND_{s}")
            }
        }
        Expr::Add(v) => {
            let mut out = String::from("(");
            super::expr::write_signed_sum(&mut out, v, |o, mag| o.push_str(&sub(mag)));
            out.push(')');
            out
        }
        Expr::Mul(_) => {
            let (neg, mag) = e.split_sign();
            let (num, den) = mag.num_den();
            let mut out = String::from("(");
            if neg {
                out.push('-');
            }
            if num.is_empty() {
                out.push_str("1.0");
            }
            for (i, f) in num.iter().enumerate() {
                if i > 0 {
                    out.push_str(" * ");
                }
                out.push_str(&sub(f));
            }
            for f in &den {
                out.push_str(" / ");
                out.push_str(&sub(f));
            }
            out.push(')');
            out
        }
        Expr::Pow(b, x) => {
            let base = sub(b);
            match x.as_integer() {
                Some(-1) => format!("(1.0 / {base})"),
                Some(1) => base,
                Some(2) => format!("({base} * {base})"),
                Some(n) if n < 0 => format!("(1.0 / {base}.powi({}))", -n),
                Some(n) => format!("{base}.powi({n})"),
                None => match &**x {
                    Expr::Rational(1, 2) => format!("{base}.sqrt()"),
                    Expr::Rational(-1, 2) => format!("(1.0 / {base}.sqrt())"),
                    Expr::Rational(3, 2) => format!("({base} * {base}.sqrt())"),
                    _ => format!("{base}.powf({})", sub(x)),
                },
            }
        }
        Expr::Fun(f, args) => {
            let a = sub(&args[0]);
            match f.as_str() {
                "log" => format!("{a}.ln()"),
                _ => format!("{a}.{f}()"),
            }
        }
    }
}

/// Every symbol in `exprs` that is neither a constant nor a local of `scope`.
pub fn unbound(exprs: &[Expr], scope: &Scope) -> BTreeSet<String> {
    exprs
        .iter()
        .flat_map(|e| e.symbols())
        .filter(|s| {
            !scope.constants.contains_key(s)
                && !scope.locals.contains_key(s)
                && !s.starts_with("rc_k")
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_repeated_subexpressions_and_hoists_constants() {
        let e = Expr::parse("(m1 + m2)*s^2 + (m1 + m2)*s^2/c").unwrap();
        let mut scope = Scope::default();
        scope.constants.insert("m1".into(), 0);
        scope.constants.insert("m2".into(), 1);
        scope.locals.insert("s".into(), "s".into());
        scope.locals.insert("c".into(), "c".into());
        let mut h = Hoisted::new(2);
        let body = lower(&[e], &scope, Some(&mut h), "");
        assert_eq!(h.entries.len(), 1, "{:?}", h.entries);
        assert_eq!(h.len(), 3);
        assert_eq!(body.lets.len(), 1, "{body:?}");
        assert!(body.outputs[0].contains("t0"), "{body:?}");
    }
}
