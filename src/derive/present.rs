//! Presentation forms: a derived result written as a person would write it, chosen among
//! candidates computed by Symbolica and checked equal to the result before it is printed.
//!
//! The candidates of a result over `rc_s = sin(theta)`, `rc_c = cos(theta)` and
//! theta-free symbols are: (1) `together`, numerator and denominator reduced with
//! `sin^2 + cos^2 = 1` and `factor`ed, each factor that is a sum collected in powers of sin and
//! cos with its coefficients factored; and, for a fraction whose denominator is one sum `D`
//! (to a power `k`), (2) the same with a theta-free factor `f` of the numerator (a divisor of
//! its number times some of its theta-free factors, `f^k` dividing it) moved into `D`, each of
//! `D`'s terms divided by `f` (so `12 (1 + n)(r - s)/(4 (1 + n) - 3 s^2)` becomes
//! `4 (r - s)/(4/3 - s^2/(1 + n))`, the paper's eq. (9)). [`RULE`] picks one.
//!
//! Order: a product is its number, then theta-free symbols in the declared order, then
//! theta-free sums, then `sin`, `cos`, then sums with theta. In a fraction a sum runs from its
//! theta-free term up, that term positive (`r - sin(theta)`, `4 (1 + n) - 3 sin(theta)^2`); a
//! polynomial condition (`... = 0`) runs from its highest power down, that term positive.
//! The candidate the rule picks is checked equal to the result before it is printed (their
//! difference is zero as a rational function modulo `sin^2 + cos^2 = 1`); one that is not is
//! a typed error, never printed. The others are not checked: they are never printed, and
//! checking each cost most of the derivation's time.
//!
//! What the generated code and the JSON record print is the derivation with
//! `sin^2 + cos^2 = 1` applied where it joins two terms into one ([`with_identities`]), each
//! expression checked equal.

use super::algebra::{is_zero_trig, reduce_cos_sq, with_pythagoras};
use super::cas::{self, A};
use super::expr::{Expr, PI, product, sum};
use super::types::{Derivation, DeriveError, StepError};

/// A candidate form ranked: operations, characters, order made, the form, and the constant
/// factor dropped from it.
type Ranked = (usize, usize, usize, Expr, (i128, i128));

/// The rule that picks a presentation form among the candidates, as stated in the outputs.
pub const RULE: &str = "fewest operations (each +, -, *, /, ^ and function call in the printed \
                        form counts one), then fewest characters; each form checked equal to \
                        the raw result by Symbolica before it is printed";

/// What a result is: a value (a fraction), or a polynomial set to zero (written without its
/// constant factor).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A value: sums run from their theta-free term up.
    Fraction,
    /// A condition `p = 0`: sums run from their highest power of theta down.
    Polynomial,
}

/// A chosen presentation form, over `rc_s` and `rc_c`.
#[derive(Debug, Clone)]
pub struct Form {
    /// The form.
    pub expr: Expr,
    /// Its operation count (see [`RULE`]).
    pub operations: usize,
    /// How many candidates were compared.
    pub candidates: usize,
}

/// Operations in the printed form: `+ - * / ^` and function calls.
pub fn operations(e: &Expr) -> usize {
    operations_in(&e.to_infix())
}

/// [`operations`] of a form's infix text.
fn operations_in(text: &str) -> usize {
    let mut n = text.chars().filter(|c| "+-*/^".contains(*c)).count();
    let bytes = text.as_bytes();
    for i in 1..bytes.len() {
        if bytes[i] == b'(' && bytes[i - 1].is_ascii_alphanumeric() {
            n += 1;
        }
    }
    n
}

/// How a theta-free symbol ranks in a product: its place in `order` (others after, by name).
struct Order<'a> {
    symbols: &'a [String],
}

impl Order<'_> {
    fn rank(&self, e: &Expr) -> (usize, usize, String) {
        let first = (self.symbols.iter())
            .position(|o| o != PI && e.mentions(o))
            .unwrap_or(self.symbols.len());
        let text = e.to_infix();
        (first, text.len(), text)
    }
}

fn has_theta(e: &Expr) -> bool {
    e.mentions("rc_s") || e.mentions("rc_c")
}

/// The degree of a monomial in `rc_s` and `rc_c` (sine first: `sin^a cos^b` as `(a + b, b)`).
fn theta_degree(e: &Expr) -> (i128, i128) {
    let factors = match e {
        Expr::Mul(v) => v.clone(),
        e => vec![e.clone()],
    };
    let (mut s, mut c) = (0, 0);
    for f in factors {
        let (base, k) = match &f {
            Expr::Pow(b, k) => ((**b).clone(), k.as_integer().unwrap_or(1)),
            f => (f.clone(), 1),
        };
        match base {
            Expr::Sym(n) if n == "rc_s" => s += k,
            Expr::Sym(n) if n == "rc_c" => c += k,
            _ => {}
        }
    }
    (s + c, c)
}

/// Terms collected over one monomial in sin and cos: the monomial's factors, its degree and
/// the coefficients' terms.
type Collected = (Vec<Expr>, (i128, i128), Vec<Expr>);

/// A factor and its integer power (negative below the line).
type Factor = (Expr, i128);

/// Denominator sums divided by a theta-free factor: (the factor, the sum, the sum divided).
type Divided = Vec<(Expr, Expr, Expr)>;

/// A factorised expression: a rational number and factors.
struct Factored {
    coefficient: (i128, i128),
    factors: Vec<Factor>,
}

/// The factors of a product as Symbolica's `factor` prints them.
fn factors_of(e: &Expr, sign: i128, out: &mut Factored) -> Result<(), StepError> {
    let list = match e {
        Expr::Mul(v) => v.clone(),
        e => vec![e.clone()],
    };
    for f in list {
        match f {
            Expr::Rational(n, d) => {
                let (cn, cd) = out.coefficient;
                let (n, d) = if sign > 0 { (n, d) } else { (d, n) };
                let num = cn.checked_mul(n).ok_or(StepError::Overflow)?;
                let den = cd.checked_mul(d).ok_or(StepError::Overflow)?;
                out.coefficient = reduced(num, den);
            }
            Expr::Pow(b, k) => match k.as_integer() {
                Some(k) => out.factors.push(((*b).clone(), sign * k)),
                None => out.factors.push((Expr::Pow(b, k), sign)),
            },
            f => out.factors.push((f, sign)),
        }
    }
    Ok(())
}

fn gcd(a: i128, b: i128) -> i128 {
    if b == 0 {
        a.abs().max(1)
    } else {
        gcd(b, a % b)
    }
}

fn reduced(n: i128, d: i128) -> (i128, i128) {
    let g = gcd(n, d);
    let (n, d) = (n / g, d / g);
    if d < 0 { (-n, -d) } else { (n, d) }
}

/// Writes a presentation form of `a`, see the module's documentation.
pub struct Presenter<'a> {
    order: Order<'a>,
    /// [`arrange_coefficient`](Self::arrange_coefficient)'s results by its input: the same
    /// coefficients recur in every candidate of a result and in many results.
    coefficients: std::cell::RefCell<std::collections::HashMap<A, Vec<Expr>>>,
}

impl<'a> Presenter<'a> {
    /// A presenter ranking theta-free symbols in `symbols`' order.
    pub fn new(symbols: &'a [String]) -> Self {
        Presenter {
            order: Order { symbols },
            coefficients: Default::default(),
        }
    }

    /// The presentation form of `a` (over `rc_s`, `rc_c` and theta-free symbols), checked equal
    /// to it.
    pub fn present(&self, a: &A, shape: Shape) -> Result<Form, StepError> {
        let parts = self.parts(a)?;
        let mut candidates = vec![self.arranged(&parts, shape, shape)?];
        if shape == Shape::Fraction {
            // The numerator's sums also as polynomials (highest power first), which can spare
            // a leading minus sign.
            candidates.push(self.arranged(&parts, Shape::Fraction, Shape::Polynomial)?);
            // Both share their denominator and theta-free factors: each sum divided once.
            let mut divided = Divided::default();
            let mut moved = Vec::new();
            for c in &candidates {
                moved.extend(self.moved_into_denominator(c, &mut divided)?);
            }
            candidates.extend(moved);
        }
        let count = candidates.len();
        // Ranked by the rule (fewest operations, then fewest characters; the first made wins a
        // tie), each with the constant factor a condition `= 0` is written without.
        let mut ranked: Vec<Ranked> = (candidates.into_iter())
            .enumerate()
            .map(|(i, mut f)| {
                let dropped = match shape {
                    Shape::Polynomial => std::mem::replace(&mut f.coefficient, (1, 1)),
                    Shape::Fraction => (1, 1),
                };
                let e = self.assemble(&f);
                let text = e.to_infix();
                (operations_in(&text), text.len(), i, e, dropped)
            })
            .collect();
        ranked.sort_by_key(|r| (r.0, r.1, r.2));
        // The best form is printed only once Symbolica finds it equal to the result; a form
        // that is not is a bug in its maker, reported rather than skipped.
        let (ops, _, _, expr, dropped) = ranked
            .into_iter()
            .next()
            .ok_or_else(|| StepError::Presentation("no presentation form".into()))?;
        let factor = cas::atom(&Expr::Rational(dropped.0, dropped.1));
        let diff = cas::atom(&expr) * factor - a.clone();
        if !is_zero_trig(&diff)? {
            return Err(StepError::Presentation(format!(
                "the presentation form `{}` is not equal to the result `{}`",
                expr.to_infix(),
                cas::expr(a)?.to_infix()
            )));
        }
        Ok(Form {
            expr,
            operations: ops,
            candidates: count,
        })
    }

    /// The factors of `a` as Symbolica gives them: together, `sin^2 + cos^2 = 1` applied to
    /// the numerator and the denominator, each factored (what candidates (1) arrange).
    fn parts(&self, a: &A) -> Result<Factored, StepError> {
        let t = cas::expr(&cas::together(a))?;
        let (num, den) = t.num_den();
        let mut out = Factored {
            coefficient: (1, 1),
            factors: Vec::new(),
        };
        for (part, sign) in [(num, 1), (den, -1)] {
            let p = reduce_cos_sq(&cas::atom(&product(part)));
            factors_of(&cas::expr(&cas::factor(&p))?, sign, &mut out)?;
        }
        Ok(out)
    }

    /// Candidate (1): the [`parts`](Self::parts) of a result with its sums collected and
    /// signed, the denominator's as `shape` says, the numerator's as `top` says.
    fn arranged(&self, parts: &Factored, shape: Shape, top: Shape) -> Result<Factored, StepError> {
        let mut out = Factored {
            coefficient: parts.coefficient,
            factors: Vec::with_capacity(parts.factors.len()),
        };
        for (base, k) in &parts.factors {
            let k = *k;
            if !matches!(base, Expr::Add(_)) {
                out.factors.push((self.arrange_product(base), k));
                continue;
            }
            let (negative, arranged) = self.arrange_sum(base, if k > 0 { top } else { shape })?;
            if negative && k % 2 != 0 {
                out.coefficient.0 = -out.coefficient.0;
            }
            out.factors.push((arranged, k));
        }
        Ok(out)
    }

    /// Candidates (2): a theta-free factor of the numerator moved into the denominator's sum.
    /// `divided` keeps each denominator divided so far, by what it was divided by.
    fn moved_into_denominator(
        &self,
        f: &Factored,
        divided: &mut Divided,
    ) -> Result<Vec<Factored>, StepError> {
        let below: Vec<&Factor> = f.factors.iter().filter(|x| x.1 < 0).collect();
        let [(d_sum, d_pow)] = below.as_slice() else {
            return Ok(Vec::new());
        };
        let Expr::Add(terms) = d_sum else {
            return Ok(Vec::new());
        };
        let k = -*d_pow;
        let free: Vec<&Factor> = (f.factors.iter())
            .filter(|x| x.1 > 0 && !has_theta(&x.0))
            .collect();
        let number = f.coefficient.0.abs();
        let Ok(k_u32) = u32::try_from(k) else {
            return Ok(Vec::new());
        };
        let divisors: Vec<(i128, i128)> = (1..=number.min(10_000))
            .filter_map(|d: i128| d.checked_pow(k_u32).map(|dk| (d, dk)))
            .filter(|(_, dk)| number % dk == 0)
            .collect();
        let mut out = Vec::new();
        for mask in 0u32..(1 << free.len().min(8)) {
            let chosen: Vec<&Factor> = (free.iter().enumerate())
                .filter(|(i, x)| mask & (1 << i) != 0 && x.1 >= k)
                .map(|(_, x)| *x)
                .collect();
            if chosen.len() != mask.count_ones() as usize {
                continue;
            }
            for &(d, dk) in &divisors {
                if d == 1 && chosen.is_empty() {
                    continue;
                }
                let by = product(
                    std::iter::once(Expr::int(d))
                        .chain(chosen.iter().map(|x| x.0.clone()))
                        .collect(),
                );
                let new_sum = self.divided_sum(d_sum, terms, by, divided)?;
                let mut factors: Vec<Factor> = Vec::new();
                for x in &f.factors {
                    if x.1 < 0 {
                        factors.push((new_sum.clone(), x.1));
                    } else if let Some(c) = chosen.iter().find(|c| c.0 == x.0) {
                        factors.push((c.0.clone(), x.1 - k));
                    } else {
                        factors.push(x.clone());
                    }
                }
                out.push(Factored {
                    coefficient: reduced(f.coefficient.0 / dk, f.coefficient.1),
                    factors: factors.into_iter().filter(|x| x.1 != 0).collect(),
                });
            }
        }
        Ok(out)
    }

    /// The sum `d_sum` (its `terms`) with each term's theta-free coefficient divided by `by`,
    /// taken from `divided` when that sum was divided by `by` before.
    fn divided_sum(
        &self,
        d_sum: &Expr,
        terms: &[Expr],
        by: Expr,
        divided: &mut Divided,
    ) -> Result<Expr, StepError> {
        if let Some((_, _, done)) = (divided.iter()).find(|(b, s, _)| *b == by && s == d_sum) {
            return Ok(done.clone());
        }
        let by_a = cas::atom(&by);
        let mut new_terms = Vec::with_capacity(terms.len());
        for t in terms {
            let (theta, coefficient): (Vec<Expr>, Vec<Expr>) = match t {
                Expr::Mul(v) => v.iter().cloned().partition(has_theta),
                t if has_theta(t) => (vec![t.clone()], Vec::new()),
                t => (Vec::new(), vec![t.clone()]),
            };
            let c = cas::together(&(cas::atom(&product(coefficient)) / by_a.clone()));
            let c = self.arrange_coefficient(&c)?;
            new_terms.push(product(c.into_iter().chain(theta).collect()));
        }
        let done = sum(new_terms);
        divided.push((by, d_sum.clone(), done.clone()));
        Ok(done)
    }

    /// A theta-free coefficient as ordered factors (number first).
    fn arrange_coefficient(&self, c: &A) -> Result<Vec<Expr>, StepError> {
        if let Some(done) = self.coefficients.borrow().get(c) {
            return Ok(done.clone());
        }
        let done = self.arrange_coefficient_anew(c)?;
        self.coefficients
            .borrow_mut()
            .insert(c.clone(), done.clone());
        Ok(done)
    }

    /// [`arrange_coefficient`](Self::arrange_coefficient), computed.
    fn arrange_coefficient_anew(&self, c: &A) -> Result<Vec<Expr>, StepError> {
        let mut f = Factored {
            coefficient: (1, 1),
            factors: Vec::new(),
        };
        factors_of(&cas::expr(&cas::factor(c))?, 1, &mut f)?;
        for x in &mut f.factors {
            if matches!(x.0, Expr::Add(_)) {
                let (negative, arranged) = self.arrange_sum(&x.0, Shape::Fraction)?;
                if negative && x.1 % 2 != 0 {
                    f.coefficient.0 = -f.coefficient.0;
                }
                x.0 = arranged;
            }
        }
        Ok(self.ordered(&f))
    }

    /// The factors of a product in order (the number first), powers written as powers.
    fn ordered(&self, f: &Factored) -> Vec<Expr> {
        let mut factors = f.factors.clone();
        factors.sort_by_cached_key(|(b, _)| self.factor_key(b));
        let (n, d) = f.coefficient;
        let mut out = Vec::new();
        if (n, d) != (1, 1) {
            out.push(Expr::Rational(n, d));
        }
        for (b, k) in factors {
            out.push(if k == 1 {
                b
            } else {
                Expr::Pow(Box::new(b), Box::new(Expr::int(k)))
            });
        }
        out
    }

    /// Sort key of a factor: theta-free symbols, theta-free sums, sin, cos, sums with theta.
    fn factor_key(&self, b: &Expr) -> (u8, (usize, usize, String)) {
        let class = match (has_theta(b), matches!(b, Expr::Add(_))) {
            (false, false) => 0,
            (false, true) => 1,
            (true, false) if b.mentions("rc_s") => 2,
            (true, false) => 3,
            (true, true) => 4,
        };
        (class, self.order.rank(b))
    }

    /// A product (a monomial) in the conventional order.
    fn arrange_product(&self, e: &Expr) -> Expr {
        let Expr::Mul(v) = e.tidy() else {
            return e.tidy();
        };
        let (mut numbers, mut rest): (Vec<Expr>, Vec<Expr>) = v
            .into_iter()
            .partition(|x| matches!(x, Expr::Rational(..) | Expr::Float(_)));
        rest.sort_by_cached_key(|b| {
            let base = match b {
                Expr::Pow(base, _) => base,
                b => b,
            };
            self.factor_key(base)
        });
        numbers.extend(rest);
        product(numbers)
    }

    /// A sum collected in powers of sin and cos (each coefficient factored), in the order of
    /// `shape`, and whether its sign was flipped to make its first term positive.
    fn arrange_sum(&self, e: &Expr, shape: Shape) -> Result<(bool, Expr), StepError> {
        let Expr::Add(terms) = e else {
            return Ok((false, e.clone()));
        };
        // (theta monomial, its degree, coefficient terms), in order of appearance.
        let mut groups: Vec<Collected> = Vec::new();
        for t in terms {
            let (mut theta, coefficient): (Vec<Expr>, Vec<Expr>) = match t {
                Expr::Mul(v) => v.iter().cloned().partition(has_theta),
                t if has_theta(t) => (vec![t.clone()], Vec::new()),
                t => (Vec::new(), vec![t.clone()]),
            };
            theta.sort_by_cached_key(|x| self.factor_key(x));
            let degree = theta_degree(&product(theta.clone()));
            match groups.iter_mut().find(|g| g.0 == theta) {
                Some(g) => g.2.push(product(coefficient)),
                None => groups.push((theta, degree, vec![product(coefficient)])),
            }
        }
        let theta_free_sum = groups.len() == 1 && groups[0].0.is_empty();
        let mut out = Vec::new();
        if theta_free_sum {
            // A sum of parameters: numbers first, then by the symbols' order and degree.
            let mut v: Vec<Expr> = groups[0]
                .2
                .iter()
                .map(|t| self.arrange_product(t))
                .collect();
            v.sort_by_cached_key(|t| {
                let syms = t.symbols().len();
                (syms, self.order.rank(t))
            });
            out = v;
        } else {
            match shape {
                Shape::Fraction => groups.sort_by_key(|g| g.1),
                Shape::Polynomial => groups.sort_by_key(|g| std::cmp::Reverse(g.1)),
            }
            for (theta, _, coefficient) in groups {
                let c = cas::atom(&sum(coefficient));
                if cas::is_zero(&c) {
                    continue;
                }
                let c = self.arrange_coefficient(&c)?;
                match (theta.is_empty(), c.as_slice()) {
                    // A theta-free part that is a sum (or minus one) joins the sum's terms.
                    (true, [Expr::Add(terms)]) => out.extend(terms.iter().cloned()),
                    (true, [number @ Expr::Rational(-1, 1), Expr::Add(terms)]) => {
                        out.extend(terms.iter().map(|t| {
                            self.arrange_product(&Expr::Mul(vec![number.clone(), t.clone()]))
                        }))
                    }
                    _ => out.push(product(c.into_iter().chain(theta).collect())),
                }
            }
        }
        let negative = out.first().is_some_and(|t| t.split_sign().0);
        if negative {
            out = out
                .into_iter()
                .map(|t| Expr::Mul(vec![Expr::int(-1), t]).tidy())
                .map(|t| self.arrange_product(&t))
                .collect();
        }
        Ok((negative, sum(out)))
    }

    /// The candidate as one expression: the number and numerator factors, then the
    /// denominator's as negative powers.
    fn assemble(&self, f: &Factored) -> Expr {
        product(self.ordered(f))
    }
}

/// `sin^2 + cos^2 = 1` applied to every expression of `d` over the full state, its initial
/// state and its tangents, of every angle, as the generated code and the JSON record print
/// them (each checked equal by [`with_pythagoras`]): `k T sin^2 + k T cos^2` is `k T`. Run
/// after the steps
/// ([`super::steps`]), which show the expressions as derived.
pub fn with_identities(d: &mut Derivation) -> Result<(), DeriveError> {
    let theta = d.theta().map(str::to_string);
    let one = |e: &mut Expr, what: &str| -> Result<(), DeriveError> {
        *e = with_pythagoras(e, theta.as_deref(), what)?;
        Ok(())
    };
    let all = |v: &mut [Expr], what: &str| v.iter_mut().try_for_each(|e| one(e, what));
    one(&mut d.kinetic, "kinetic energy")?;
    one(&mut d.potential, "potential energy")?;
    one(&mut d.lagrangian, "lagrangian")?;
    all(&mut d.euler_lagrange, "equation")?;
    for row in &mut d.mass {
        all(row, "mass matrix")?;
    }
    all(&mut d.rhs, "forces")?;
    all(&mut d.momenta, "momentum")?;
    for p in d.point_pos.iter_mut().chain(&mut d.point_vel) {
        all(p, "point")?;
    }
    for c in &mut d.contacts {
        one(&mut c.gap, "gap")?;
        all(&mut c.jacobian, "gap Jacobian")?;
        one(&mut c.bias, "gap bias")?;
        for e in c.edge.iter_mut().chain(&mut c.force) {
            one(e, "contact")?;
        }
    }
    all(&mut d.monitors_full, "monitor")?;
    for pose in &mut d.body_pose {
        all(pose, "body pose")?;
    }
    for f in &mut d.frictions {
        one(&mut f.slip, "slip velocity")?;
        all(&mut f.jacobian, "slip Jacobian")?;
        one(&mut f.bias, "slip bias")?;
    }
    for state in &mut d.to_full {
        all(state, "full state")?;
    }
    for initial in &mut d.initial {
        all(initial, "initial state")?;
    }
    if let Some(t) = &mut d.tangents {
        all(&mut t.rows, "tangent")?;
        all(&mut t.initial, "initial tangent")?;
    }
    Ok(())
}
