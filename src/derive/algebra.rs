//! Algebra the derivation's stages share, on Symbolica atoms through [`cas`]: the
//! trigonometric rewriting that makes results unique modulo `sin^2 + cos^2 = 1`, the switch
//! between `sin(theta)`, `cos(theta)` and the internal symbols `rc_s`, `rc_c`, polynomial
//! coefficients in `sin(theta)`, and sign tests. Below every stage; imports only [`cas`],
//! [`expr`](super::expr) and [`types`](super::types).

use super::cas::{self, A};
use super::expr::{Expr, gcd, product, sum};
use super::types::{Constant, DeriveError, StepError, at};
use std::collections::{BTreeMap, BTreeSet};

/// A Symbolica atom as an expression, or the error of the step `what`.
pub fn to_expr(a: &A, what: &str) -> Result<Expr, DeriveError> {
    cas::expr(a).map_err(|m| at(&[], format!("{what}: {m}")))
}

/// `sqrt(1 - x^2)^sign` (`sign` 1 or -1) in the one form the derivation writes it,
/// `((1 - x)(1 + x))^(1/2)`: no cancellation in `1 - x^2` as `x -> 1`, and one root wherever
/// it appears (`cos(asin(x))`, the derivative of `asin(x)`), so the lowering shares it.
pub fn root_of_one_minus_square(x: &Expr, sign: i128) -> Expr {
    let minus_x = Expr::Mul(vec![Expr::int(-1), x.clone()]);
    Expr::Pow(
        Box::new(Expr::Mul(vec![
            Expr::Add(vec![Expr::int(1), minus_x]),
            Expr::Add(vec![Expr::int(1), x.clone()]),
        ])),
        Box::new(Expr::Rational(sign, 2)),
    )
}

/// `sin(asin(x)) = x`, `cos(asin(x)) = sqrt(1 - x^2)` and the like, applied bottom-up.
pub fn simplify_inverse_trig(e: &Expr) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(simplify_inverse_trig).collect::<Vec<_>>();
    match e {
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(simplify_inverse_trig(b)),
            Box::new(simplify_inverse_trig(x)),
        ),
        Expr::Fun(f, args) => {
            let args = rec(args);
            if let Some(Expr::Fun(g, inner)) = args.first() {
                let x = inner[0].clone();
                let one_minus_sq = || root_of_one_minus_square(&x, 1);
                match (f.as_str(), g.as_str()) {
                    ("sin", "asin") | ("cos", "acos") => return x,
                    ("cos", "asin") | ("sin", "acos") => return one_minus_sq(),
                    _ => {}
                }
            }
            Expr::Fun(f.clone(), args)
        }
        _ => e.clone(),
    }
}

/// Replaces `cos^k` by `cos^(k mod 2) (1 - sin^2)^(k div 2)` in an expanded polynomial of
/// `rc_s`, `rc_c`, so that results are unique modulo `sin^2 + cos^2 = 1`.
pub fn reduce_cos_sq(a: &A) -> A {
    thread_local! {
        /// The rules `rc_c^k -> rc_c^(k mod 2) (1 - rc_s^2)^(k div 2)`, highest `k` first, made
        /// once per thread (only the Symbolica thread calls this).
        static RULES: Vec<(A, A)> = cos_power_rules("rc_s", "rc_c");
    }
    cas::memo(cas::Memo::CosSquares, a, |a| {
        RULES.with(|rules| rewritten(a, rules))
    })
}

/// `a` expanded and rewritten by `rules` until nothing changes (at most 16 rounds).
fn rewritten(a: &A, rules: &[(A, A)]) -> A {
    let mut cur = cas::expand(a);
    for _ in 0..16 {
        let mut next = cur.clone();
        for (pat, rep) in rules {
            next = cas::subs(&next, pat, rep);
        }
        next = cas::expand(&next);
        if next == cur {
            break;
        }
        cur = next;
    }
    cur
}

/// The rules `c^k -> c^(k mod 2) (1 - s^2)^(k div 2)` for `k` from 12 down to 2.
fn cos_power_rules(s: &str, c: &str) -> Vec<(A, A)> {
    (2..=12).rev().map(|k| cos_power_rule(s, c, k)).collect()
}

/// The pattern `c^k` and its replacement `c^(k mod 2) (1 - s^2)^(k div 2)`.
fn cos_power_rule(s: &str, c: &str, k: i128) -> (A, A) {
    let pow = |base: &str, n: i128| Expr::Pow(Box::new(Expr::sym(base)), Box::new(Expr::int(n)));
    let one_minus_s2 = Expr::Add(vec![
        Expr::int(1),
        Expr::Mul(vec![Expr::int(-1), pow(s, 2)]),
    ]);
    let rep = Expr::Mul(vec![
        pow(c, k % 2),
        Expr::Pow(Box::new(one_minus_s2), Box::new(Expr::int(k / 2))),
    ]);
    (cas::atom(&pow(c, k)), cas::atom(&rep))
}

/// `e` with `sin(x)`, `cos(x)` of every argument `x` replaced by the symbols `rc_ts<i>`,
/// `rc_tc<i>` (`i` the argument's place in `arguments`, which collects them as they are met).
fn trig_symbols(e: &Expr, arguments: &mut Vec<Expr>) -> Expr {
    let mut rec = |v: &Vec<Expr>| v.iter().map(|x| trig_symbols(x, arguments)).collect();
    match e {
        Expr::Fun(f, args) if args.len() == 1 && (f == "sin" || f == "cos") => {
            let i = match arguments.iter().position(|a| *a == args[0]) {
                Some(i) => i,
                None => {
                    arguments.push(args[0].clone());
                    arguments.len() - 1
                }
            };
            Expr::Sym(format!("rc_t{}{i}", if f == "sin" { 's' } else { 'c' }))
        }
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(trig_symbols(b, arguments)),
            Box::new(trig_symbols(x, arguments)),
        ),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), rec(v)),
        _ => e.clone(),
    }
}

/// The powers of `sin(x)` and `cos(x)` of one argument `x` in a term, for [`pythagoras`]
/// (`x` is `None` for the internal `rc_s = sin(theta)`, `rc_c = cos(theta)`).
#[derive(Debug, Clone, PartialEq)]
struct Trig {
    argument: Option<Expr>,
    sin: i128,
    cos: i128,
}

/// A term of a sum as `coefficient * rest * prod_x sin(x)^a cos(x)^b`, for [`pythagoras`].
#[derive(Debug, Clone)]
struct Term {
    /// The term as written, kept while no rule rewrote it.
    written: Option<Expr>,
    /// Its rational coefficient `(numerator, denominator)`, denominator positive.
    coefficient: (i128, i128),
    /// Its other factors, sorted by their infix text.
    rest: Vec<Expr>,
    /// Its integer powers (of either sign) of `sin` and `cos`, by their argument's infix
    /// text (`""` for `rc_s`, `rc_c`); none with both powers zero.
    trig: BTreeMap<String, Trig>,
}

/// `(argument's key, argument, whether it is a sine, power)` when `f` is an integer power of
/// a sine or cosine (`rc_s`, `rc_c`, or a call of one argument).
fn trig_power(f: &Expr) -> Option<(String, Option<Expr>, bool, i128)> {
    let (base, power) = match f {
        Expr::Pow(b, x) => (&**b, x.as_integer().filter(|&n| n != 0)?),
        f => (f, 1),
    };
    match base {
        Expr::Sym(s) if s == "rc_s" || s == "rc_c" => {
            Some((String::new(), None, s == "rc_s", power))
        }
        Expr::Fun(name, args) if args.len() == 1 && (name == "sin" || name == "cos") => Some((
            args[0].to_infix(),
            Some(args[0].clone()),
            name == "sin",
            power,
        )),
        _ => None,
    }
}

impl Term {
    fn of(t: &Expr) -> Term {
        let factors = match t {
            Expr::Mul(v) => v.clone(),
            other => vec![other.clone()],
        };
        let mut term = Term {
            written: Some(t.clone()),
            coefficient: (1, 1),
            rest: Vec::new(),
            trig: BTreeMap::new(),
        };
        for f in factors {
            let (n, d) = term.coefficient;
            if let Some((key, argument, is_sin, k)) = trig_power(&f) {
                let entry = term.trig.entry(key).or_insert(Trig {
                    argument,
                    sin: 0,
                    cos: 0,
                });
                *(if is_sin {
                    &mut entry.sin
                } else {
                    &mut entry.cos
                }) += k;
                continue;
            }
            match &f {
                Expr::Rational(a, b) => match n.checked_mul(*a).zip(d.checked_mul(*b)) {
                    Some(c) => term.coefficient = c,
                    None => term.rest.push(f.clone()),
                },
                _ => term.rest.push(f.clone()),
            }
        }
        term.trig.retain(|_, t| (t.sin, t.cos) != (0, 0));
        term.rest.sort_by_cached_key(Expr::to_infix);
        term
    }

    /// Whether `self`'s coefficient is `sign` times `other`'s.
    fn scales(&self, other: &Term, sign: i128) -> bool {
        let ((a, b), (c, d)) = (self.coefficient, other.coefficient);
        a.checked_mul(d) == c.checked_mul(b).and_then(|x| x.checked_mul(sign))
    }

    /// The powers `(sin, cos)` of the argument `key` (zero where the term has none).
    fn powers(&self, key: &str) -> (i128, i128) {
        self.trig.get(key).map_or((0, 0), |t| (t.sin, t.cos))
    }

    /// The one term that `self + other` is by `sin^2 + cos^2 = 1` of one argument, if it is
    /// one: `X sin^2 + X cos^2 = X`, `X - X cos^2 = X sin^2`, `X - X sin^2 = X cos^2`.
    fn combined(&self, other: &Term) -> Option<Term> {
        if self.rest != other.rest {
            return None;
        }
        if self.trig == other.trig {
            // Like terms, which a join above can leave: their coefficients add.
            let ((a, b), (c, d)) = (self.coefficient, other.coefficient);
            let n = a.checked_mul(d)?.checked_add(c.checked_mul(b)?)?;
            let d = b.checked_mul(d)?;
            let g = gcd(n.abs(), d).max(1);
            return Some(Term {
                written: None,
                coefficient: (n / g, d / g),
                ..self.clone()
            });
        }
        // The terms must differ in the powers of one argument only.
        let keys: BTreeSet<&String> = self.trig.keys().chain(other.trig.keys()).collect();
        let mut differing = keys
            .into_iter()
            .filter(|k| self.powers(k) != other.powers(k));
        let key = differing.next()?;
        if differing.next().is_some() {
            return None;
        }
        let ((s1, c1), (s2, c2)) = (self.powers(key), other.powers(key));
        let (sin, cos) = if self.scales(other, 1) && s1 == s2 + 2 && c2 == c1 + 2 {
            (s2, c1)
        } else if self.scales(other, -1) && s2 == s1 && c2 == c1 + 2 {
            (s1 + 2, c1)
        } else if self.scales(other, -1) && c2 == c1 && s2 == s1 + 2 {
            (s1, c1 + 2)
        } else {
            return None;
        };
        let argument =
            (self.trig.get(key).or_else(|| other.trig.get(key))).map(|t| t.argument.clone())?;
        let mut trig = self.trig.clone();
        trig.insert(key.clone(), Trig { argument, sin, cos });
        trig.retain(|_, t| (t.sin, t.cos) != (0, 0));
        Some(Term {
            written: None,
            coefficient: self.coefficient,
            rest: self.rest.clone(),
            trig,
        })
    }

    fn expr(self) -> Expr {
        if let Some(t) = self.written {
            return t;
        }
        let (n, d) = self.coefficient;
        let mut factors = vec![Expr::Rational(n, d)];
        factors.extend(self.rest);
        for t in self.trig.into_values() {
            for (is_sin, k) in [(true, t.sin), (false, t.cos)] {
                if k == 0 {
                    continue;
                }
                let base = match (&t.argument, is_sin) {
                    (None, true) => Expr::sym("rc_s"),
                    (None, false) => Expr::sym("rc_c"),
                    (Some(x), true) => Expr::Fun("sin".into(), vec![x.clone()]),
                    (Some(x), false) => Expr::Fun("cos".into(), vec![x.clone()]),
                };
                factors.push(match k {
                    1 => base,
                    k => Expr::Pow(Box::new(base), Box::new(Expr::int(k))),
                });
            }
        }
        Expr::Mul(factors).tidy()
    }
}

/// `sin^2 + cos^2 = 1` applied to the terms of every sum in `e` where it joins two terms into
/// one, for `theta` (`rc_s`, `rc_c`) and for every argument of a `sin` or `cos` call alike:
/// `X sin^2 + X cos^2 = X`, `X - X cos^2 = X sin^2` and `X - X sin^2 = X cos^2`, `X` the same
/// factors and coefficient in both (integer powers of either sign of the sine and cosine
/// included, so `R + R cos^2/sin^2` is `R/sin^2`), and like terms that a join leaves are added.
/// Nothing is expanded, and no term is rewritten that no other joins, so no `1 - sin^2` cancels
/// where `cos^2` was.
pub fn pythagoras(e: &Expr) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(pythagoras).collect::<Vec<_>>();
    match e {
        Expr::Add(v) => {
            let mut terms: Vec<Term> = rec(v).iter().map(Term::of).collect();
            'joined: loop {
                for i in 0..terms.len() {
                    for j in (0..terms.len()).filter(|&j| j != i) {
                        if let Some(t) = terms[i].combined(&terms[j]) {
                            terms[i] = t;
                            terms.remove(j);
                            terms.retain(|t| t.coefficient.0 != 0);
                            continue 'joined;
                        }
                    }
                }
                break;
            }
            sum(terms.into_iter().map(Term::expr).collect())
        }
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(Box::new(pythagoras(b)), Box::new(pythagoras(x))),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), rec(v)),
        _ => e.clone(),
    }
}

/// `e` (over `sin(theta)`, `cos(theta)` where the phase reduces to `theta`, and any other
/// angle) with [`pythagoras`] applied, checked by Symbolica to be equal to `e` (their
/// difference zero modulo `sin^2 + cos^2 = 1`); an error naming `what` if it is not, or if the
/// check could not be made.
pub fn with_pythagoras(e: &Expr, theta: Option<&str>, what: &str) -> Result<Expr, DeriveError> {
    let sc = to_sc_over(e, theta);
    let simpler = pythagoras(&sc);
    if simpler == sc {
        return Ok(e.clone());
    }
    let difference = Expr::Add(vec![
        simpler.clone(),
        Expr::Mul(vec![Expr::int(-1), sc.clone()]),
    ]);
    match is_zero_trig(&cas::atom(&difference)) {
        Ok(true) => Ok(from_sc_over(&simpler, theta)),
        Ok(false) => Err(at(
            &[],
            format!(
                "{what}: sin^2 + cos^2 = 1 rewrote {} as {}, which Symbolica finds different",
                sc.to_infix(),
                simpler.to_infix()
            ),
        )),
        Err(m) => Err(at(&[], format!("{what}: checking sin^2 + cos^2 = 1: {m}"))),
    }
}

/// Whether a rational expression of `rc_s`, `rc_c` (and anything else) is zero modulo
/// `sin^2 + cos^2 = 1`, of `theta` (`rc_s`, `rc_c`) and of every other argument that a
/// `sin` or `cos` call in it has.
pub fn is_zero_trig(a: &A) -> Result<bool, StepError> {
    let t = cas::together(a);
    let e = cas::expr(&t)?;
    let (num, _) = e.num_den();
    let mut arguments = Vec::new();
    let numerator = trig_symbols(&product(num), &mut arguments);
    let mut n = reduce_cos_sq(&cas::atom(&numerator));
    for i in 0..arguments.len() {
        n = ARGUMENT_RULES.with(|rules| {
            let mut rules = rules.borrow_mut();
            while rules.len() <= i {
                let j = rules.len();
                rules.push(cos_power_rules(&format!("rc_ts{j}"), &format!("rc_tc{j}")));
            }
            rewritten(&n, &rules[i])
        });
    }
    Ok(cas::is_zero(&n))
}

thread_local! {
    /// The rules of [`cos_power_rules`] for the `i`-th other argument (`rc_ts<i>`, `rc_tc<i>`)
    /// at index `i`, made once per thread (only the Symbolica thread calls this).
    static ARGUMENT_RULES: std::cell::RefCell<Vec<Vec<(A, A)>>> = Default::default();
}

/// Replaces `sin(theta)`, `cos(theta)` by `rc_s`, `rc_c`.
pub fn to_sc(a: &A, theta: &str) -> A {
    let s = cas::subs(
        a,
        &cas::atom(&Expr::Fun("sin".into(), vec![Expr::sym(theta)])),
        &cas::var("rc_s"),
    );
    cas::subs(
        &s,
        &cas::atom(&Expr::Fun("cos".into(), vec![Expr::sym(theta)])),
        &cas::var("rc_c"),
    )
}

/// [`to_sc_expr`] over a phase's reduced coordinate where it has one; without one no
/// expression is written over `rc_s`, `rc_c`, and `e` is returned as it is.
pub fn to_sc_over(e: &Expr, theta: Option<&str>) -> Expr {
    theta.map_or_else(|| e.clone(), |t| to_sc_expr(e, t))
}

/// [`from_sc`] over a phase's reduced coordinate where it has one (see [`to_sc_over`]).
pub fn from_sc_over(e: &Expr, theta: Option<&str>) -> Expr {
    theta.map_or_else(|| e.clone(), |t| from_sc(e, t))
}

/// Replaces `rc_s`, `rc_c` by `sin(theta)`, `cos(theta)` in a plain expression.
pub fn from_sc(e: &Expr, theta: &str) -> Expr {
    match e {
        Expr::Sym(s) if s == "rc_s" => Expr::Fun("sin".into(), vec![Expr::sym(theta)]),
        Expr::Sym(s) if s == "rc_c" => Expr::Fun("cos".into(), vec![Expr::sym(theta)]),
        Expr::Add(v) => Expr::Add(v.iter().map(|x| from_sc(x, theta)).collect()),
        Expr::Mul(v) => Expr::Mul(v.iter().map(|x| from_sc(x, theta)).collect()),
        Expr::Pow(b, x) => Expr::Pow(Box::new(from_sc(b, theta)), Box::new(from_sc(x, theta))),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), v.iter().map(|x| from_sc(x, theta)).collect()),
        _ => e.clone(),
    }
}

/// Replaces `sin(theta)`, `cos(theta)` by `rc_s`, `rc_c` in a plain expression (the inverse
/// of [`from_sc`]).
pub fn to_sc_expr(e: &Expr, theta: &str) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(|x| to_sc_expr(x, theta)).collect();
    match e {
        Expr::Fun(f, args) if args.len() == 1 && args[0] == Expr::sym(theta) && f == "sin" => {
            Expr::sym("rc_s")
        }
        Expr::Fun(f, args) if args.len() == 1 && args[0] == Expr::sym(theta) && f == "cos" => {
            Expr::sym("rc_c")
        }
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(to_sc_expr(b, theta)),
            Box::new(to_sc_expr(x, theta)),
        ),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), rec(v)),
        _ => e.clone(),
    }
}

/// Groups the terms of an expanded expression by their factors in `motion` symbols and brings
/// each group's coefficient over one denominator: `sum_m together(sum c_i) * m`.
///
/// Expanded, the reduced forces of a model with a cyclic coordinate hold parameter-only terms
/// that nearly cancel (`m1 ell m2/(2(m1+m2)) - ell m2 + ell m2^2/(m1+m2)` in rod_cube's contact
/// force is `-m1 m2 ell/(2(m1+m2))`): emitted as they are, the force loses `log10(m2/m1)`
/// digits for a heavy cube. Together, each coefficient is one term and keeps them.
pub fn collect_over(a: &A, motion: &[&str]) -> Result<A, DeriveError> {
    let e = to_expr(a, "expression to collect")?;
    let terms = match e {
        Expr::Add(v) => v,
        e => vec![e],
    };
    // (key, motion factors, coefficient terms), in order of first appearance.
    let mut groups: Vec<(String, Vec<Expr>, Vec<Expr>)> = Vec::new();
    for t in terms {
        let factors = match t {
            Expr::Mul(v) => v,
            t => vec![t],
        };
        let (mut moving, coefficient): (Vec<Expr>, Vec<Expr>) = factors
            .into_iter()
            .partition(|f| f.symbols().iter().any(|s| motion.contains(&s.as_str())));
        moving.sort_by_cached_key(|f| f.to_infix());
        let key = moving
            .iter()
            .map(|f| f.to_infix())
            .collect::<Vec<_>>()
            .join("*");
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.2.push(product(coefficient)),
            None => groups.push((key, moving, vec![product(coefficient)])),
        }
    }
    let mut out = cas::num(0);
    for (_, moving, coefficients) in groups {
        let c = cas::together(&cas::atom(&Expr::Add(coefficients)));
        out += c * cas::atom(&product(moving));
    }
    Ok(out)
}

/// Whether `a` does not depend on any of `names` (each partial derivative is zero).
pub fn free_of(a: &A, names: &[&str]) -> bool {
    names.iter().all(|n| cas::is_zero(&cas::d(a, n)))
}

/// A constant's value where it is a plain number, its symbol otherwise.
pub fn constant_value(constants: &[Constant], symbol: &str) -> A {
    constants
        .iter()
        .find(|c| c.symbol == symbol)
        .and_then(|c| {
            let t = c.value.tidy();
            t.symbols().is_empty().then(|| cas::atom(&t))
        })
        .unwrap_or_else(|| cas::var(symbol))
}

/// `d/dtheta` of an expression over `rc_s`, `rc_c`, `rc_ds`, `rc_dc`.
pub fn d_theta(f: &A) -> A {
    cas::d(f, "rc_s") * cas::var("rc_c")
        - cas::d(f, "rc_c") * cas::var("rc_s")
        - cas::d(f, "rc_ds") * cas::var("rc_c")
        + cas::d(f, "rc_dc") * cas::var("rc_s")
}

/// Most coefficients of a polynomial in `sin(theta)` the derivation writes (separation and fall
/// polynomials).
pub const MAX_POLY_COEFFICIENTS: usize = 17;

/// The coefficients in `rc_s` of `a`, lowest degree first, if `a` is a polynomial in `rc_s` of
/// degree below [`MAX_POLY_COEFFICIENTS`] over symbols free of `rc_s` (checked by comparing
/// `a` with the sum of its Taylor terms).
pub fn coefficients_in_s(a: &A, what: &str) -> Result<Option<Vec<Expr>>, DeriveError> {
    let mut coefficients = Vec::new();
    let mut terms = Vec::new();
    let mut deriv = a.clone();
    let mut factorial: i64 = 1;
    for deg in 0..MAX_POLY_COEFFICIENTS as i64 {
        if deg > 0 {
            factorial *= deg;
        }
        let c0 = cas::expand(&(cas::subs_var(&deriv, "rc_s", &cas::num(0)) / cas::num(factorial)));
        let power = (0..deg).fold(cas::num(1), |acc, _| acc * cas::var("rc_s"));
        terms.push(c0.clone() * power);
        coefficients.push(to_expr(&c0, what)?);
        deriv = cas::expand(&cas::d(&deriv, "rc_s"));
        if cas::is_zero(&deriv) {
            let sum = terms.iter().fold(cas::num(0), |acc, t| acc + t.clone());
            return Ok(cas::is_zero(&cas::expand(&(a.clone() - sum))).then_some(coefficients));
        }
    }
    Ok(None)
}

/// The fall polynomial `(sin theta_i - s) / theta_dot^2` in `s = rc_s`, where it is one (see
/// [`Reduction::fall`](super::types::Reduction::fall)); `None` for a phase that does not start from
/// rest, whose potential has a `cos(theta)` term, or whose inertia is no polynomial in
/// `sin(theta)`.
pub fn fall_polynomial(
    wsq: &A,
    coords: &[String],
    theta: &str,
) -> Result<Option<Vec<Expr>>, DeriveError> {
    if cas::is_zero(wsq) {
        return Ok(None);
    }
    let ratio = reduce_cos_sq(&cas::together(&(cas::var("rc_ds") / wsq.clone())));
    let ratio = cas::expand(&ratio);
    let mut motion = vec!["rc_ds", "rc_dc", "rc_c", theta];
    motion.extend(coords.iter().map(String::as_str));
    if !free_of(&ratio, &motion) {
        return Ok(None);
    }
    // Each coefficient over one denominator, common factors cancelled (`l (m1 + m2) / (3 g
    // (m1 + m2))` is `l / (3 g)`).
    let Some(coefficients) = coefficients_in_s(&ratio, "fall polynomial coefficient")? else {
        return Ok(None);
    };
    let tidy = |c: &Expr| to_expr(&cas::together(&cas::atom(c)), "fall polynomial coefficient");
    Ok(Some(
        coefficients.iter().map(tidy).collect::<Result<_, _>>()?,
    ))
}

/// `rc_ds`, `rc_dc` written as differences from the start.
pub fn gap_vars(a: &A) -> A {
    let out = cas::subs_var(a, "rc_ds", &(cas::var("rc_si") - cas::var("rc_s")));
    cas::subs_var(&out, "rc_dc", &(cas::var("rc_ci") - cas::var("rc_c")))
}

/// Whether an expression is structurally positive when the symbols `pos` are.
pub fn positive(e: &Expr, pos: &[String]) -> bool {
    match e {
        Expr::Rational(n, _) => *n > 0,
        Expr::Float(x) => *x > 0.0,
        Expr::Sym(s) => pos.contains(s),
        Expr::Add(v) | Expr::Mul(v) => v.iter().all(|x| positive(x, pos)),
        Expr::Pow(b, x) => positive(b, pos) || x.as_integer().is_some_and(|n| n % 2 == 0),
        Expr::Fun(..) => false,
    }
}

/// Factorises and drops the factors free of `rc_s` that are strictly positive (or negative
/// constants), so that what is left is the separation polynomial up to a positive factor.
pub fn strip_positive_factors(poly: &A, pos: &[String]) -> Result<A, DeriveError> {
    Ok(strip_signed(poly, pos)?.0)
}

/// [`strip_positive_factors`], and whether the factors dropped were negative overall (the
/// polynomial left then has the opposite sign of `poly`).
pub fn strip_signed(poly: &A, pos: &[String]) -> Result<(A, bool), DeriveError> {
    let f = to_expr(&cas::factor(poly), "factorised separation polynomial")?;
    let factors = match f {
        Expr::Mul(v) => v,
        e => vec![e],
    };
    let mut kept = Vec::new();
    let mut negated = false;
    for x in factors {
        let has_s = x.symbols().contains("rc_s");
        if has_s {
            kept.push(x);
            continue;
        }
        let (neg, mag) = x.split_sign();
        if positive(&mag, pos) || (neg && mag.symbols().is_empty()) {
            negated ^= neg;
            continue;
        }
        kept.push(x);
    }
    Ok((cas::expand(&cas::atom(&product(kept))), negated))
}

/// Solves `mat x = rhs` symbolically by Gauss–Jordan elimination (entries brought over one
/// denominator as they are formed); `None` when a column has no nonzero pivot. Each solution is
/// `b_r / m_rr` as formed, left for the caller to simplify.
pub fn solve_linear(mut mat: Vec<Vec<A>>, mut rhs: Vec<A>) -> Option<Vec<A>> {
    let k = rhs.len();
    if mat.len() != k || mat.iter().any(|row| row.len() != k) {
        return None;
    }
    for col in 0..k {
        let pivot = (col..k).find(|&r| !cas::is_zero(&mat[r][col]))?;
        mat.swap(col, pivot);
        rhs.swap(col, pivot);
        let p = mat[col][col].clone();
        let pivot_row = mat[col].clone();
        for r in 0..k {
            if r == col || cas::is_zero(&mat[r][col]) {
                continue;
            }
            let f = cas::together(&(mat[r][col].clone() / p.clone()));
            for (m, pc) in mat[r].iter_mut().zip(&pivot_row) {
                *m = cas::together(&(m.clone() - f.clone() * pc.clone()));
            }
            rhs[r] = cas::together(&(rhs[r].clone() - f.clone() * rhs[col].clone()));
        }
    }
    Some((0..k).map(|r| rhs[r].clone() / mat[r][r].clone()).collect())
}
