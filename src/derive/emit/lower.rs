//! Lowers derived expressions to straight-line Rust: shared subexpressions become `let`s,
//! parameter-only subexpressions are hoisted into the prepared constants `k`.

use crate::derive::expr::{Expr, float_literal};
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// Names an expression's free symbols resolve to in generated code.
#[derive(Debug, Clone, Default)]
pub struct Scope {
    /// Symbols that live in the constant vector `k`, with their index.
    pub constants: BTreeMap<String, usize>,
    /// Symbols that are local variables (function arguments or earlier `let`s), with their
    /// Rust spelling.
    pub locals: BTreeMap<String, String>,
    /// Slots of `k` read through a local of this name (the parameters, bound by the method's
    /// preamble) rather than as `k[i]`.
    pub named: BTreeMap<usize, String>,
}

/// Parameter-only subexpressions collected across all functions, to be computed once in
/// `prepare` and read from `k`.
///
/// A constant is held once up to its sign: `-(ell/2)` reads the slot of `ell/2`, negated; one
/// that is another constant (`ell`, a start value) or its negative is read from that constant's
/// slot rather than copied.
#[derive(Debug, Clone, Default)]
pub struct Hoisted {
    /// (k index, defining expression over earlier constants) in evaluation order.
    pub entries: Vec<(usize, Expr)>,
    /// Magnitude's key -> (its slot, whether the slot holds its negative).
    by_key: HashMap<String, (usize, bool)>,
    /// Each slot a subexpression reads, with what it holds (for comments).
    definitions: HashMap<usize, Expr>,
    next: usize,
}

impl Hoisted {
    /// Starts numbering hoisted constants at `first`.
    pub fn new(first: usize) -> Hoisted {
        Hoisted {
            entries: Vec::new(),
            by_key: HashMap::new(),
            definitions: HashMap::new(),
            next: first,
        }
    }

    /// Makes a subexpression equal to `e` (or to its negative) read the constant already at
    /// `k[idx]` instead of hoisting a copy (a start constant that an initial value repeats, say).
    pub fn known(&mut self, e: &Expr, idx: usize) {
        let (neg, magnitude) = signed(e);
        self.definitions.entry(idx).or_insert_with(|| e.clone());
        self.by_key.entry(key(&magnitude)).or_insert((idx, neg));
    }

    /// `e` with every hoisted constant `rc_k<i>` it reads replaced by what that slot holds.
    pub fn defined(&self, e: &Expr) -> Expr {
        let rec = |v: &Vec<Expr>| v.iter().map(|x| self.defined(x)).collect();
        match e {
            Expr::Sym(s) => (hoisted_slot(s))
                .and_then(|i| self.definitions.get(&i))
                .map_or_else(|| e.clone(), |d| self.defined(d)),
            Expr::Add(v) => Expr::Add(rec(v)),
            Expr::Mul(v) => Expr::Mul(rec(v)),
            Expr::Pow(b, x) => Expr::Pow(Box::new(self.defined(b)), Box::new(self.defined(x))),
            Expr::Fun(f, v) => Expr::Fun(f.clone(), rec(v)),
            _ => e.clone(),
        }
    }

    /// Total length of `k` after hoisting.
    pub fn len(&self) -> usize {
        self.next
    }

    /// Whether nothing was hoisted.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The symbol that reads the constant `e` (over constants only), and whether it is to be
    /// negated: an existing constant's own symbol, an earlier hoisted slot, or a new slot.
    fn constant(&mut self, e: &Expr, scope: &Scope) -> (bool, Expr) {
        let (neg, magnitude) = signed(e);
        if let Expr::Sym(s) = &magnitude
            && (scope.constants.contains_key(s) || s.starts_with("rc_k"))
        {
            return (neg, magnitude);
        }
        let key = key(&magnitude);
        if let Some(&(i, held_negated)) = self.by_key.get(&key) {
            return (neg != held_negated, Expr::Sym(format!("rc_k{i}")));
        }
        // The roots and calls inside a new constant take slots of their own first (so that one
        // another constant holds too, in the same form, is computed once and read by both).
        let definition = self.calls_apart(&magnitude, scope, true);
        let i = self.next;
        self.next += 1;
        self.entries.push((i, definition.clone()));
        self.definitions.insert(i, definition);
        self.by_key.insert(key, (i, false));
        (neg, Expr::Sym(format!("rc_k{i}")))
    }

    /// `e` (over constants only) with each root (a power whose exponent is no integer, a
    /// negative one read as the reciprocal of the positive one) and each function call below
    /// its top read from a slot of its own.
    fn calls_apart(&mut self, e: &Expr, scope: &Scope, top: bool) -> Expr {
        let mut rec = |x: &Expr| self.calls_apart(x, scope, false);
        match e {
            Expr::Pow(b, x) if x.as_integer().is_none() && reads_negative(x) => {
                let root = Expr::Pow(b.clone(), Box::new(negated(x)));
                Expr::Pow(Box::new(rec(&root)), Box::new(Expr::int(-1)))
            }
            Expr::Pow(_, x) if !top && x.as_integer().is_none() => self.read(e, scope),
            Expr::Fun(..) if !top => self.read(e, scope),
            Expr::Pow(b, x) => Expr::Pow(Box::new(rec(b)), Box::new(rec(x))),
            Expr::Fun(f, args) => Expr::Fun(f.clone(), args.iter().map(rec).collect()),
            Expr::Add(v) => Expr::Add(v.iter().map(rec).collect()),
            Expr::Mul(v) => Expr::Mul(v.iter().map(rec).collect()),
            _ => e.clone(),
        }
    }

    /// The constant `e` as the symbol that reads it, signed.
    fn read(&mut self, e: &Expr, scope: &Scope) -> Expr {
        let (neg, x) = self.constant(e, scope);
        with_sign(neg, x)
    }
}

/// The slot `rc_k<i>` names, if it names one.
pub fn hoisted_slot(symbol: &str) -> Option<usize> {
    symbol.strip_prefix("rc_k")?.parse().ok()
}

/// The key two constants share when they are equal up to flattening, folded numbers and the
/// order of the terms of a sum and the factors of a product (`(1 + x)*(1 - x)` and
/// `(1 - x)*(1 + x)` take one slot).
fn key(magnitude: &Expr) -> String {
    ordered(&magnitude.tidy()).to_infix()
}

/// `e` with the terms of every sum and the factors of every product sorted by their infix text,
/// and `sqrt(x)` (as a spec writes it) read as `x^(1/2)` (as Symbolica writes it).
fn ordered(e: &Expr) -> Expr {
    let sorted = |v: &Vec<Expr>| {
        let mut v: Vec<Expr> = v.iter().map(ordered).collect();
        v.sort_by_cached_key(Expr::to_infix);
        v
    };
    match e {
        Expr::Add(v) => Expr::Add(sorted(v)),
        Expr::Mul(v) => Expr::Mul(sorted(v)),
        Expr::Pow(b, x) => Expr::Pow(Box::new(ordered(b)), Box::new(ordered(x))),
        Expr::Fun(f, v) if f == "sqrt" && v.len() == 1 => {
            Expr::Pow(Box::new(ordered(&v[0])), Box::new(Expr::Rational(1, 2)))
        }
        Expr::Fun(f, v) => Expr::Fun(f.clone(), v.iter().map(ordered).collect()),
        _ => e.clone(),
    }
}

/// Whether `e` reads as negative: a negative number, a product with an odd number of negative
/// numeric factors (in nested products too), a sum whose first term is negative.
fn reads_negative(e: &Expr) -> bool {
    match e {
        Expr::Rational(n, _) => *n < 0,
        Expr::Float(x) => *x < 0.0,
        Expr::Mul(v) => v
            .iter()
            .filter(|f| matches!(f, Expr::Rational(..) | Expr::Float(_) | Expr::Mul(_)))
            .fold(false, |neg, f| neg != reads_negative(f)),
        Expr::Add(v) => v.first().is_some_and(reads_negative),
        _ => false,
    }
}

/// `-e`, formed by flipping a sign already written (a numeric factor, every term of a sum)
/// rather than by a new factor where one exists; exact in floating point either way.
fn negated(e: &Expr) -> Expr {
    match e {
        Expr::Rational(n, d) => Expr::Rational(-n, *d),
        Expr::Float(x) => Expr::Float(-x),
        Expr::Add(v) => Expr::Add(v.iter().map(negated).collect()),
        Expr::Mul(v) => {
            let flip = v.iter().position(|f| {
                matches!(f, Expr::Rational(..) | Expr::Float(_) | Expr::Mul(_)) && reads_negative(f)
            });
            let mut v = v.clone();
            match flip {
                Some(i) if v[i] == Expr::int(-1) => {
                    v.remove(i);
                }
                Some(i) => v[i] = negated(&v[i]),
                None => v.insert(0, Expr::int(-1)),
            }
            crate::derive::expr::product(v)
        }
        _ => Expr::Mul(vec![Expr::int(-1), e.clone()]),
    }
}

/// `e` as a sign and a magnitude that does not read as negative.
fn signed(e: &Expr) -> (bool, Expr) {
    if reads_negative(e) {
        (true, negated(e))
    } else {
        (false, e.clone())
    }
}

/// `-x` where `neg`, else `x`.
fn with_sign(neg: bool, x: Expr) -> Expr {
    if neg {
        Expr::Mul(vec![Expr::int(-1), x])
    } else {
        x
    }
}

/// A lowered function body: `let` lines and the final output expressions, all Rust text.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Body {
    /// `(name, rust expression)` pairs, in order.
    pub lets: Vec<(String, String)>,
    /// One Rust expression per requested output.
    pub outputs: Vec<String>,
    /// What each `let` holds, over the spec's symbols (hoisted constants by their
    /// definitions): the comment that explains its name.
    pub holds: Vec<Expr>,
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
    let mut lets: Vec<(String, String, Expr)> = Vec::new();
    let mut named: HashMap<String, String> = HashMap::new();
    let mut lowered = Vec::new();
    for e in &outputs {
        let text = emit(e, scope, &counts, &mut named, &mut lets, prefix);
        lowered.push(bare(text));
    }
    let defined = |e: &Expr| match hoist.as_deref() {
        Some(h) => h.defined(e),
        None => e.clone(),
    };
    Body {
        holds: lets.iter().map(|(_, _, e)| defined(e).tidy()).collect(),
        lets: lets.into_iter().map(|(n, v, _)| (n, bare(v))).collect(),
        outputs: lowered,
    }
}

/// `text` without the parentheses around the whole of it, if it has them: a `let`'s value or
/// an assignment's right-hand side needs none.
fn bare(text: String) -> String {
    let inner = match text.strip_prefix('(').and_then(|t| t.strip_suffix(')')) {
        Some(inner) => inner,
        None => return text,
    };
    // The outer pair encloses everything only if the depth never returns to zero inside.
    let mut depth = 0usize;
    for c in inner.chars() {
        match c {
            '(' => depth += 1,
            ')' if depth == 0 => return text,
            ')' => depth -= 1,
            _ => {}
        }
    }
    inner.to_string()
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
        let (neg, x) = h.constant(e, scope);
        return with_sign(neg, x);
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
            let rest = crate::derive::expr::product(rest);
            let key = rest.to_infix();
            match groups.iter_mut().find(|g| g.0 == key) {
                Some(g) => g.2.push(crate::derive::expr::product(coef)),
                None => groups.push((key, rest, vec![crate::derive::expr::product(coef)])),
            }
        }
        if groups.len() < v.len() {
            let terms = groups
                .into_iter()
                .map(|(_, rest, coefs)| {
                    Expr::Mul(vec![crate::derive::expr::sum(coefs), rest]).tidy()
                })
                .collect();
            let grouped = crate::derive::expr::sum(terms);
            // Only a sum the grouping shortened is taken apart again (tidying a grouped term
            // may spread it back into as many terms, which would recurse for ever).
            let shorter = match &grouped {
                Expr::Add(w) => w.len() < v.len(),
                _ => true,
            };
            if shorter {
                return hoist_constants(&grouped, scope, h);
            }
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
                    crate::derive::expr::product(group)
                } else {
                    crate::derive::expr::sum(group)
                };
                let (neg, x) = h.constant(&g, scope);
                if matches!(e, Expr::Mul(_)) {
                    if neg {
                        out.push(Expr::int(-1));
                    }
                    out.push(x);
                } else {
                    out.push(with_sign(neg, x));
                }
            } else {
                out.extend(group);
            }
            out.extend(rest.into_iter().map(|c| hoist_constants(c, scope, h)));
            if matches!(e, Expr::Mul(_)) {
                crate::derive::expr::product(out)
            } else {
                crate::derive::expr::sum(out)
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
    lets: &mut Vec<(String, String, Expr)>,
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
            lets.push((name.clone(), text, e.clone()));
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
    lets: &mut Vec<(String, String, Expr)>,
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
        Expr::Sym(s) if s == crate::derive::expr::PI => "std::f64::consts::PI".to_string(),
        Expr::Sym(s) => {
            if let Some(i) = hoisted_slot(s) {
                format!("k[{i}]")
            } else if let Some(i) = scope.constants.get(s) {
                match scope.named.get(i) {
                    Some(name) => name.clone(),
                    None => format!("k[{i}]"),
                }
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
            crate::derive::expr::write_signed_sum(&mut out, v, |o, mag| o.push_str(&sub(mag)));
            out.push(')');
            out
        }
        Expr::Mul(_) => {
            let (mut neg, mut mag) = e.split_sign();
            // A product left with one factor that is itself a signed product (`-(-x y)` after
            // hoisting) gives up that sign too, so that no sign follows a sign (`--x`).
            loop {
                let (inner, rest) = mag.split_sign();
                if !inner {
                    break;
                }
                (neg, mag) = (!neg, rest);
            }
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
    fn a_sign_never_follows_a_sign() {
        let x = || Expr::sym("x");
        let inner = Expr::Mul(vec![Expr::int(-1), x(), x()]);
        let e = Expr::Mul(vec![Expr::int(-1), inner]);
        let mut scope = Scope::default();
        scope.locals.insert("x".into(), "x".into());
        let body = lower(&[e], &scope, None, "q");
        assert_eq!(body.outputs, ["x * x"]);
    }

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

    /// The parameters `a`, `ell` in `k[0]`, `k[1]` and a local `s`.
    fn a_ell_scope() -> Scope {
        let mut scope = Scope::default();
        for (i, name) in ["a", "ell"].into_iter().enumerate() {
            scope.constants.insert(name.into(), i);
        }
        scope.locals.insert("s".into(), "s".into());
        scope
    }

    #[test]
    fn a_root_two_constants_hold_in_either_order_takes_one_slot() {
        let scope = a_ell_scope();
        let exprs = [
            "ell*((1 - a/ell)*(1 + a/ell))^(1/2)*s",
            "a/(ell^2*((1 + a/ell)*(1 - a/ell))^(1/2))*s^2",
        ]
        .map(|t| Expr::parse(t).unwrap().tidy());
        let mut h = Hoisted::new(2);
        let body = lower(&exprs, &scope, Some(&mut h), "");
        let roots: Vec<_> = (h.entries.iter())
            .filter(|(_, e)| matches!(e, Expr::Pow(_, x) if **x == Expr::Rational(1, 2)))
            .collect();
        assert_eq!(roots.len(), 1, "{:?}", h.entries);
        let root = format!("rc_k{}", roots[0].0);
        let reading = (h.entries.iter())
            .filter(|(_, e)| e.symbols().contains(&root))
            .count();
        assert_eq!(reading, 2, "{:?} {body:?}", h.entries);
    }

    #[test]
    fn a_root_written_as_sqrt_and_as_a_half_power_takes_one_slot() {
        let scope = a_ell_scope();
        let exprs = [
            "sqrt((ell - a)*(ell + a))*s",
            "((a + ell)*(-a + ell))^(1/2)*s^2",
        ]
        .map(|t| Expr::parse(t).unwrap().tidy());
        let mut h = Hoisted::new(2);
        let body = lower(&exprs, &scope, Some(&mut h), "");
        assert_eq!(h.entries.len(), 1, "{:?} {body:?}", h.entries);
    }
}
