//! A small expression tree for the derivation tool: parsed from spec text and from Symbolica's
//! printed output, printed back as plain infix, Rust and LaTeX, and evaluated for self-checks.

use std::collections::BTreeSet;
use std::fmt::Write as _;

/// An expression over `f64` with named symbols and the elementary functions used by specs.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A rational constant `num / den` (den > 0), kept exact for printing.
    Rational(i128, i128),
    /// A floating constant written in a spec (`0.5`).
    Float(f64),
    /// A symbol (parameter, coordinate, or an internal name).
    Sym(String),
    /// Sum of terms.
    Add(Vec<Expr>),
    /// Product of factors.
    Mul(Vec<Expr>),
    /// Power `base ^ exponent`.
    Pow(Box<Expr>, Box<Expr>),
    /// Function call (`sin`, `cos`, `sqrt`, `asin`, ...).
    Fun(String, Vec<Expr>),
}

/// Functions a spec may use, with their arity.
pub const FUNCTIONS: &[(&str, usize)] = &[
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("asin", 1),
    ("acos", 1),
    ("atan", 1),
    ("sqrt", 1),
    ("exp", 1),
    ("log", 1),
];

/// The name of the constant `pi` in spec expressions: not a free symbol ([`Expr::symbols`]
/// leaves it out), dimensionless, `std::f64::consts::PI` in the generated code and `\pi` in the
/// LaTeX; no parameter or coordinate may take the name.
pub const PI: &str = "pi";

/// A parse error with the byte offset where it was found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParseError {
    /// Byte offset in the parsed text.
    pub offset: usize,
    /// What went wrong.
    pub message: String,
}

impl Expr {
    /// Integer constant.
    pub fn int(n: i128) -> Expr {
        Expr::Rational(n, 1)
    }

    /// Symbol.
    pub fn sym(name: &str) -> Expr {
        Expr::Sym(name.to_string())
    }

    /// Parses infix text: numbers, identifiers, `+ - * / ^`, parentheses and function calls.
    pub fn parse(text: &str) -> Result<Expr, ParseError> {
        let mut p = Parser {
            s: text.as_bytes(),
            i: 0,
            depth: 0,
        };
        let e = p.expr()?;
        p.ws();
        if p.i < p.s.len() {
            return Err(p.err(format!("unexpected `{}`", p.s[p.i] as char)));
        }
        if e.depth() > MAX_DEPTH {
            return Err(ParseError {
                offset: 0,
                message: format!("the expression is nested more than {MAX_DEPTH} deep"),
            });
        }
        Ok(e)
    }

    /// Levels of the tree: 1 for a number or a symbol.
    pub fn depth(&self) -> usize {
        1 + match self {
            Expr::Add(v) | Expr::Mul(v) | Expr::Fun(_, v) => {
                v.iter().map(Expr::depth).max().unwrap_or(0)
            }
            Expr::Pow(b, e) => b.depth().max(e.depth()),
            _ => 0,
        }
    }

    /// Flattens nested sums and products, folds numeric factors into one rational, and drops
    /// factors of one and terms of zero.
    pub fn tidy(&self) -> Expr {
        match self {
            Expr::Add(v) => {
                let mut terms = Vec::new();
                for t in v.iter().map(Expr::tidy) {
                    match t {
                        Expr::Add(inner) => terms.extend(inner),
                        t if t.is_zero() => {}
                        t => terms.push(t),
                    }
                }
                sum(terms)
            }
            Expr::Mul(v) => {
                let (mut n, mut d) = (1i128, 1i128);
                let mut rest = Vec::new();
                let mut flat = Vec::new();
                for f in v.iter().map(Expr::tidy) {
                    match f {
                        Expr::Mul(inner) => flat.extend(inner),
                        f => flat.push(f),
                    }
                }
                for f in flat {
                    // A factor whose folding would overflow `i128` stays a factor.
                    let folded = match &f {
                        Expr::Rational(a, b) => mul_exact(n, *a).zip(mul_exact(d, *b)),
                        Expr::Pow(b, e) if e.as_integer() == Some(-1) => match **b {
                            Expr::Rational(a, 1) if a != 0 => Some(n).zip(mul_exact(d, a)),
                            _ => None,
                        },
                        _ => None,
                    };
                    match folded {
                        Some((a, b)) => {
                            let g = gcd(a.abs(), b.abs());
                            (n, d) = (a / g, b / g);
                        }
                        None => rest.push(f),
                    }
                }
                if n == 0 {
                    return Expr::int(0);
                }
                if d < 0 {
                    n = -n;
                    d = -d;
                }
                let g = gcd(n.abs(), d);
                let (n, d) = (n / g, d / g);
                if !(n == 1 && d == 1) {
                    rest.insert(0, Expr::Rational(n, d));
                }
                product(rest)
            }
            Expr::Pow(b, e) => {
                let (b, e) = (b.tidy(), e.tidy());
                match (&b, e.as_integer()) {
                    (_, Some(1)) => b,
                    (Expr::Rational(a, 1), Some(-1)) if *a != 0 => {
                        if *a < 0 {
                            Expr::Rational(-1, -a)
                        } else {
                            Expr::Rational(1, *a)
                        }
                    }
                    _ => Expr::Pow(Box::new(b), Box::new(e)),
                }
            }
            Expr::Fun(f, v) => Expr::Fun(f.clone(), v.iter().map(Expr::tidy).collect()),
            e => e.clone(),
        }
    }

    /// Every symbol the expression mentions.
    pub fn symbols(&self) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        self.visit(&mut |e| {
            if let Expr::Sym(s) = e
                && s != PI
            {
                out.insert(s.clone());
            }
        });
        out
    }

    /// Every function name the expression calls, with the argument counts used.
    pub fn functions(&self) -> Vec<(String, usize)> {
        let mut out = Vec::new();
        self.visit(&mut |e| {
            if let Expr::Fun(f, args) = e {
                out.push((f.clone(), args.len()));
            }
        });
        out
    }

    fn visit(&self, f: &mut dyn FnMut(&Expr)) {
        f(self);
        match self {
            Expr::Add(v) | Expr::Mul(v) | Expr::Fun(_, v) => v.iter().for_each(|e| e.visit(f)),
            Expr::Pow(b, e) => {
                b.visit(f);
                e.visit(f);
            }
            _ => {}
        }
    }

    /// Evaluates with a symbol lookup; unknown symbols and functions give NaN.
    pub fn eval(&self, lookup: &dyn Fn(&str) -> Option<f64>) -> f64 {
        match self {
            Expr::Rational(n, d) => *n as f64 / *d as f64,
            Expr::Float(x) => *x,
            Expr::Sym(s) if s == PI => std::f64::consts::PI,
            Expr::Sym(s) => lookup(s).unwrap_or(f64::NAN),
            Expr::Add(v) => v.iter().map(|e| e.eval(lookup)).sum(),
            Expr::Mul(v) => v.iter().map(|e| e.eval(lookup)).product(),
            Expr::Pow(b, e) => {
                let b = b.eval(lookup);
                match e.as_integer() {
                    Some(n) if n.unsigned_abs() < 64 => b.powi(n as i32),
                    _ => b.powf(e.eval(lookup)),
                }
            }
            Expr::Fun(f, args) => {
                let x = args.first().map(|a| a.eval(lookup)).unwrap_or(f64::NAN);
                match f.as_str() {
                    "sin" => x.sin(),
                    "cos" => x.cos(),
                    "tan" => x.tan(),
                    "asin" => x.asin(),
                    "acos" => x.acos(),
                    "atan" => x.atan(),
                    "sqrt" => x.sqrt(),
                    "exp" => x.exp(),
                    "log" => x.ln(),
                    _ => f64::NAN,
                }
            }
        }
    }

    /// The value if this is an integer constant.
    pub fn as_integer(&self) -> Option<i128> {
        match self {
            Expr::Rational(n, 1) => Some(*n),
            _ => None,
        }
    }

    /// Whether this is the constant zero.
    pub fn is_zero(&self) -> bool {
        matches!(self, Expr::Rational(0, _))
    }

    /// Plain infix text (`sin(theta)^2`, `*`, `/`, `^`), readable by Symbolica and most CASes.
    pub fn to_infix(&self) -> String {
        let mut s = String::new();
        self.infix(&mut s, 0);
        s
    }

    fn infix(&self, out: &mut String, parent: u8) {
        // precedence: 1 sum, 2 product, 3 unary minus, 4 power, 5 atom
        match self {
            Expr::Rational(n, 1) => {
                let paren = *n < 0 && parent > 1;
                wrap(out, paren, |o| {
                    let _ = write!(o, "{n}");
                });
            }
            Expr::Rational(n, d) => wrap(out, parent > 2 || (*n < 0 && parent > 1), |o| {
                let _ = write!(o, "{n}/{d}");
            }),
            Expr::Float(x) => {
                let paren = *x < 0.0 && parent > 1;
                wrap(out, paren, |o| o.push_str(&float_literal(*x)));
            }
            Expr::Sym(s) => out.push_str(s),
            Expr::Add(v) => wrap(out, parent > 1, |o| {
                write_signed_sum(o, v, |o, mag| mag.infix(o, 2));
            }),
            Expr::Mul(v) => {
                if self.negative_factors() {
                    let (_, mag) = self.split_sign();
                    wrap(out, parent > 1, |o| {
                        o.push('-');
                        mag.infix(o, 3);
                    });
                    return;
                }
                let (num, den) = parts_num_den(v);
                wrap(out, parent > 2, |o| {
                    if num.is_empty() {
                        o.push('1');
                    }
                    for (i, f) in num.iter().enumerate() {
                        if i > 0 {
                            o.push('*');
                        }
                        f.infix(o, 3);
                    }
                    if !den.is_empty() {
                        o.push('/');
                        parts_infix(&den, o);
                    }
                });
            }
            Expr::Pow(b, e) => pow_infix(b, e, out, parent),
            Expr::Fun(f, args) => {
                out.push_str(f);
                out.push('(');
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    a.infix(out, 0);
                }
                out.push(')');
            }
        }
    }

    /// Whether this is a negative number (a factor whose sign [`split_sign`](Self::split_sign)
    /// splits off).
    fn is_negative_number(&self) -> bool {
        match self {
            Expr::Rational(n, _) => *n < 0,
            Expr::Float(x) => *x < 0.0,
            _ => false,
        }
    }

    /// Whether a product has an odd number of negative number factors (the sign
    /// [`split_sign`](Self::split_sign) splits off it).
    fn negative_factors(&self) -> bool {
        let Expr::Mul(v) = self else {
            return false;
        };
        v.iter().filter(|f| f.is_negative_number()).count() % 2 == 1
    }

    /// [`split_sign`](Self::split_sign), borrowing the term where nothing is split off it.
    fn split_sign_borrowed(&self) -> (bool, std::borrow::Cow<'_, Expr>) {
        let unchanged = match self {
            Expr::Mul(v) => v.len() > 1 && !v.iter().any(Expr::is_negative_number),
            e => !e.is_negative_number(),
        };
        if unchanged {
            return (false, std::borrow::Cow::Borrowed(self));
        }
        let (neg, mag) = self.split_sign();
        (neg, std::borrow::Cow::Owned(mag))
    }

    /// Whether a symbol named `name` occurs in the expression.
    pub fn mentions(&self, name: &str) -> bool {
        match self {
            Expr::Sym(s) => s == name,
            Expr::Add(v) | Expr::Mul(v) | Expr::Fun(_, v) => v.iter().any(|e| e.mentions(name)),
            Expr::Pow(b, e) => b.mentions(name) || e.mentions(name),
            _ => false,
        }
    }

    /// Splits a leading negative sign off a term: `-3*x` gives `(true, 3*x)`.
    pub fn split_sign(&self) -> (bool, Expr) {
        match self {
            Expr::Rational(n, d) if *n < 0 => (true, Expr::Rational(-n, *d)),
            Expr::Float(x) if *x < 0.0 => (true, Expr::Float(-x)),
            Expr::Mul(v) => {
                let mut neg = false;
                let mut out = Vec::with_capacity(v.len());
                for f in v {
                    match f {
                        Expr::Rational(n, d) if *n < 0 => {
                            neg = !neg;
                            if !(*n == -1 && *d == 1) {
                                out.push(Expr::Rational(-n, *d));
                            }
                        }
                        Expr::Float(x) if *x < 0.0 => {
                            neg = !neg;
                            out.push(Expr::Float(-x));
                        }
                        _ => out.push(f.clone()),
                    }
                }
                (neg, product(out))
            }
            _ => (false, self.clone()),
        }
    }

    /// Splits a product into numerator and denominator factors (negative powers and the
    /// denominators of rational constants go below the line).
    pub fn num_den(&self) -> (Vec<Expr>, Vec<Expr>) {
        let factors = match self {
            Expr::Mul(v) => v.as_slice(),
            e => std::slice::from_ref(e),
        };
        let (num, den) = parts_num_den(factors);
        let owned = |v: Vec<Part<'_>>| v.iter().map(Part::owned).collect();
        (owned(num), owned(den))
    }
}

/// Writes the terms of a sum as `t0 + t1 - t2 ...`, each term's leading minus sign moved into
/// the operator; `term` writes a term's magnitude. Shared by the infix, LaTeX and Rust printers.
pub fn write_signed_sum(
    out: &mut String,
    terms: &[Expr],
    mut term: impl FnMut(&mut String, &Expr),
) {
    for (i, t) in terms.iter().enumerate() {
        let (neg, mag) = t.split_sign_borrowed();
        if i == 0 {
            if neg {
                out.push('-');
            }
        } else {
            out.push_str(if neg { " - " } else { " + " });
        }
        term(out, &mag);
    }
}

/// A factor as [`Expr::num_den`] files it, borrowed from the product it is in.
enum Part<'a> {
    /// The factor itself (or, below the line, the base of a power `-1`).
    Is(&'a Expr),
    /// A power below the line, its exponent's sign flipped.
    Pow(&'a Expr, Expr),
    /// An integer: a rational constant's numerator or denominator.
    Int(i128),
}

impl Part<'_> {
    fn infix(&self, out: &mut String, parent: u8) {
        match self {
            Part::Is(e) => e.infix(out, parent),
            Part::Pow(b, e) => pow_infix(b, e, out, parent),
            Part::Int(n) => Expr::int(*n).infix(out, parent),
        }
    }

    fn owned(&self) -> Expr {
        match self {
            Part::Is(e) => (*e).clone(),
            Part::Pow(b, e) => Expr::Pow(Box::new((*b).clone()), Box::new(e.clone())),
            Part::Int(n) => Expr::int(*n),
        }
    }
}

/// [`Expr::num_den`] of the product of `factors`, borrowing them.
fn parts_num_den(factors: &[Expr]) -> (Vec<Part<'_>>, Vec<Part<'_>>) {
    let mut num = Vec::new();
    let mut den = Vec::new();
    for f in factors {
        match f {
            Expr::Pow(b, e) => match e.as_integer() {
                Some(-1) => den.push(Part::Is(b)),
                Some(n) if n < 0 => den.push(Part::Pow(b, Expr::int(-n))),
                _ => match &**e {
                    Expr::Rational(n, d) if *n < 0 => {
                        den.push(Part::Pow(b, Expr::Rational(-n, *d)))
                    }
                    _ => num.push(Part::Is(f)),
                },
            },
            Expr::Rational(n, d) if *d != 1 => {
                if *n != 1 {
                    num.push(Part::Int(*n));
                }
                den.push(Part::Int(*d));
            }
            _ => num.push(Part::Is(f)),
        }
    }
    (num, den)
}

/// The denominator `den` of a product as infix below its `/`: what `product(den)` prints
/// at precedence 4. Factors that all stay above the line of that product are written as they
/// are; any other product is made and printed.
fn parts_infix(den: &[Part<'_>], out: &mut String) {
    if let [one] = den {
        return one.infix(out, 4);
    }
    // Every factor here is printed as a factor of the numerator of `product(den)`: no negative
    // number (no sign to split off) and nothing that `num_den` puts below the line.
    let plain = den.iter().all(|p| match p {
        Part::Is(Expr::Rational(_, d)) if *d != 1 => false,
        Part::Is(Expr::Pow(_, x)) => !x.is_negative_number(),
        Part::Is(e) => !e.is_negative_number(),
        Part::Pow(..) => true,
        Part::Int(n) => *n >= 0,
    });
    if !plain || den.is_empty() {
        return product(den.iter().map(Part::owned).collect()).infix(out, 4);
    }
    wrap(out, true, |o| {
        for (i, f) in den.iter().enumerate() {
            if i > 0 {
                o.push('*');
            }
            f.infix(o, 3);
        }
    });
}

/// `b ^ e` as infix at precedence `parent`.
fn pow_infix(b: &Expr, e: &Expr, out: &mut String, parent: u8) {
    if let Some(-1) = e.as_integer() {
        wrap(out, parent > 2, |o| {
            o.push_str("1/");
            b.infix(o, 4);
        });
        return;
    }
    wrap(out, parent > 4, |o| {
        b.infix(o, 5);
        o.push('^');
        e.infix(o, 5);
    });
}

/// A product of factors, simplified for 0 and 1 factors.
pub fn product(v: Vec<Expr>) -> Expr {
    match <[Expr; 1]>::try_from(v) {
        Ok([only]) => only,
        Err(v) if v.is_empty() => Expr::int(1),
        Err(v) => Expr::Mul(v),
    }
}

/// A sum of terms, simplified for 0 and 1 terms.
pub fn sum(v: Vec<Expr>) -> Expr {
    match <[Expr; 1]>::try_from(v) {
        Ok([only]) => only,
        Err(v) if v.is_empty() => Expr::int(0),
        Err(v) => Expr::Add(v),
    }
}

fn wrap(out: &mut String, paren: bool, f: impl FnOnce(&mut String)) {
    wrap_in(out, paren.then_some(("(", ")")), f);
}

/// What `f` writes, between `brackets` (opening, closing) when there are any: the printers'
/// one way of bracketing a part.
pub fn wrap_in(out: &mut String, brackets: Option<(&str, &str)>, f: impl FnOnce(&mut String)) {
    if let Some((open, _)) = brackets {
        out.push_str(open);
    }
    f(out);
    if let Some((_, close)) = brackets {
        out.push_str(close);
    }
}

/// A float written so that Rust reads it back as the same `f64` and as a float literal.
pub fn float_literal(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

/// How deeply parentheses, signs and exponents may nest in text: far below what would overflow
/// the stack (a fuzzed `((((...` used to abort the process).
pub const MAX_NESTING: usize = 600;

/// How deep a parsed expression tree may be: far beyond any model, and shallow enough that its
/// printed infix form (at most two levels of nesting per level of tree, as in `a^(b^(c))`)
/// stays within [`MAX_NESTING`] and parses again.
pub const MAX_DEPTH: usize = 250;

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    /// Open calls of `unary`, through which every recursion of the grammar passes.
    depth: usize,
}

impl Parser<'_> {
    fn err(&self, message: String) -> ParseError {
        ParseError {
            offset: self.i,
            message,
        }
    }

    fn ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.ws();
        self.s.get(self.i).copied()
    }

    fn expr(&mut self) -> Result<Expr, ParseError> {
        let mut terms = vec![self.term()?];
        while let Some(c @ (b'+' | b'-')) = self.peek() {
            self.i += 1;
            let t = self.term()?;
            terms.push(if c == b'-' { negate(t) } else { t });
        }
        Ok(sum(terms))
    }

    fn term(&mut self) -> Result<Expr, ParseError> {
        let mut factors = vec![self.unary()?];
        while let Some(c @ (b'*' | b'/')) = self.peek() {
            self.i += 1;
            let f = self.unary()?;
            factors.push(if c == b'/' {
                Expr::Pow(Box::new(f), Box::new(Expr::int(-1)))
            } else {
                f
            });
        }
        Ok(product(factors))
    }

    fn unary(&mut self) -> Result<Expr, ParseError> {
        if self.depth >= MAX_NESTING {
            return Err(self.err(format!("nested more than {MAX_NESTING} deep")));
        }
        self.depth += 1;
        let e = self.unary_inner();
        self.depth -= 1;
        e
    }

    fn unary_inner(&mut self) -> Result<Expr, ParseError> {
        match self.peek() {
            Some(b'-') => {
                self.i += 1;
                Ok(negate(self.unary()?))
            }
            Some(b'+') => {
                self.i += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Expr, ParseError> {
        let base = self.atom()?;
        if self.peek() == Some(b'^') {
            self.i += 1;
            let e = self.unary()?;
            return Ok(Expr::Pow(Box::new(base), Box::new(e)));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Expr, ParseError> {
        match self.peek() {
            None => Err(self.err("expression ends too early".into())),
            Some(b'(') => {
                self.i += 1;
                let e = self.expr()?;
                if self.peek() != Some(b')') {
                    return Err(self.err("missing `)`".into()));
                }
                self.i += 1;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => self.number(),
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i].is_ascii_alphanumeric() || self.s[self.i] == b'_')
                {
                    self.i += 1;
                }
                let name = String::from_utf8_lossy(&self.s[start..self.i]).into_owned();
                if self.peek() == Some(b'(') {
                    self.i += 1;
                    let mut args = vec![self.expr()?];
                    while self.peek() == Some(b',') {
                        self.i += 1;
                        args.push(self.expr()?);
                    }
                    if self.peek() != Some(b')') {
                        return Err(self.err(format!("missing `)` after arguments of `{name}`")));
                    }
                    self.i += 1;
                    return Ok(Expr::Fun(name, args));
                }
                Ok(Expr::Sym(name))
            }
            Some(c) => Err(self.err(format!("unexpected `{}`", c as char))),
        }
    }

    fn number(&mut self) -> Result<Expr, ParseError> {
        let start = self.i;
        let mut float = false;
        while self.i < self.s.len() {
            let c = self.s[self.i];
            if c.is_ascii_digit() {
                self.i += 1;
            } else if c == b'.' {
                float = true;
                self.i += 1;
            } else if (c == b'e' || c == b'E')
                && self.s.get(self.i + 1).is_some_and(|d| {
                    d.is_ascii_digit()
                        || ((*d == b'-' || *d == b'+')
                            && self.s.get(self.i + 2).is_some_and(u8::is_ascii_digit))
                })
            {
                float = true;
                self.i += 2;
            } else {
                break;
            }
        }
        // In range: the loop moved `i` from `start` only over bytes that exist, and each is
        // ASCII (a digit, `.`, `e`, `E` or a sign), so each byte is its own character.
        let text: String = self.s[start..self.i]
            .iter()
            .map(|&b| char::from(b))
            .collect();
        if float {
            text.parse::<f64>()
                .map(Expr::Float)
                .map_err(|_| ParseError {
                    offset: start,
                    message: format!("bad number `{text}`"),
                })
        } else {
            text.parse::<i128>().map(Expr::int).map_err(|_| ParseError {
                offset: start,
                message: format!("number `{text}` is too large"),
            })
        }
    }
}

/// `a * b`, or `None` when it overflows or is `i128::MIN`: every rational in an [`Expr`] keeps
/// its numerator and denominator above `i128::MIN`, so that negating them cannot overflow.
fn mul_exact(a: i128, b: i128) -> Option<i128> {
    a.checked_mul(b).filter(|&p| p != i128::MIN)
}

/// Greatest common divisor of two non-negative integers, at least 1.
pub(crate) fn gcd(a: i128, b: i128) -> i128 {
    if b == 0 { a.max(1) } else { gcd(b, a % b) }
}

fn negate(e: Expr) -> Expr {
    match e {
        Expr::Rational(n, d) => Expr::Rational(-n, d),
        Expr::Float(x) => Expr::Float(-x),
        Expr::Mul(mut v) => {
            v.insert(0, Expr::int(-1));
            Expr::Mul(v)
        }
        e => Expr::Mul(vec![Expr::int(-1), e]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(text: &str) -> f64 {
        Expr::parse(text).unwrap().eval(&|s| match s {
            "x" => Some(0.3),
            "y" => Some(-1.7),
            _ => None,
        })
    }

    #[test]
    fn parses_precedence_and_functions() {
        assert!(
            (ev("1 + 2*x^2/y - sin(x)") - (1.0 + 2.0 * 0.09 / -1.7 - 0.3f64.sin())).abs() < 1e-15
        );
        assert!((ev("-x^2") + 0.09).abs() < 1e-15);
        assert!((ev("2^-1*x") - 0.15).abs() < 1e-15);
        assert!((ev("1.5e-3*x") - 4.5e-4).abs() < 1e-18);
    }

    #[test]
    fn infix_round_trips_by_value() {
        for text in [
            "1 - x*(y + 2)^3/(x - y)",
            "-(x + y)^(1/2)",
            "x^-2 - 3/4*y",
            "sin(x)^2*cos(y)/(1 + x)",
        ] {
            let e = Expr::parse(text).unwrap();
            let back = Expr::parse(&e.to_infix()).unwrap();
            let at = |s: &str| Some(if s == "x" { 0.7 } else { -0.3 });
            let (a, b) = (e.eval(&at), back.eval(&at));
            assert!(
                (a - b).abs() <= 1e-14 * a.abs().max(1.0),
                "{text} -> {}",
                e.to_infix()
            );
        }
    }

    #[test]
    fn reports_offsets() {
        let err = Expr::parse("x + * y").unwrap_err();
        assert_eq!(err.offset, 4);
        assert!(Expr::parse("sin(x").is_err());
        assert!(Expr::parse("x y").is_err());
    }

    #[test]
    fn infix_of_signs_powers_and_denominators() {
        let (x, y, z) = (Expr::sym("x"), Expr::sym("y"), Expr::sym("z"));
        let pow = |b: &Expr, k: Expr| Expr::Pow(Box::new(b.clone()), Box::new(k));
        let s = Expr::Add(vec![x.clone(), Expr::Mul(vec![Expr::int(-2), y.clone()])]);
        // Each printed as the printer has always printed it (checked against its earlier,
        // cloning form); the borrowed path and its fallbacks are all reached.
        let cases: Vec<(Expr, &str)> = vec![
            (Expr::Mul(vec![Expr::int(-3), x.clone()]), "-(3*x)"),
            (
                Expr::Mul(vec![Expr::int(-2), Expr::int(-3), x.clone()]),
                "(-2)*(-3)*x",
            ),
            (
                Expr::Mul(vec![
                    Expr::Rational(3, 4),
                    x.clone(),
                    pow(&y, Expr::int(-1)),
                ]),
                "3*x/(4*y)",
            ),
            (
                Expr::Mul(vec![
                    x.clone(),
                    pow(&s, Expr::int(-2)),
                    pow(&z, Expr::int(-1)),
                ]),
                "x/((x - 2*y)^2*z)",
            ),
            (
                Expr::Mul(vec![
                    x.clone(),
                    pow(&y, Expr::Rational(-1, 2)),
                    pow(&Expr::int(-2), Expr::int(-1)),
                ]),
                "x/(-(y^(1/2)*2))",
            ),
            (
                Expr::Mul(vec![
                    x.clone(),
                    pow(&pow(&y, Expr::int(-2)), Expr::int(-1)),
                    pow(&z, Expr::int(-3)),
                ]),
                "x/(z^3/y^2)",
            ),
            (
                Expr::Mul(vec![
                    pow(&x, Expr::int(-1)),
                    pow(&Expr::Rational(1, 2), Expr::int(-1)),
                ]),
                "1/(x/2)",
            ),
            (Expr::Mul(vec![pow(&x, Expr::int(-1))]), "1/x"),
            (Expr::Mul(vec![Expr::Rational(-1, 3)]), "-(1/3)"),
            (Expr::Mul(vec![]), "1"),
            (
                Expr::Add(vec![
                    Expr::Mul(vec![Expr::int(-1), x.clone()]),
                    Expr::Mul(vec![Expr::Float(-0.5), y.clone(), pow(&s, Expr::int(-1))]),
                    Expr::Mul(vec![Expr::int(-1), Expr::int(-1), z.clone()]),
                    Expr::Mul(vec![z.clone()]),
                    Expr::Rational(-5, 2),
                ]),
                "-x - 0.5*y/(x - 2*y) + z + z - 5/2",
            ),
            (pow(&s, Expr::int(-1)), "1/(x - 2*y)"),
            (
                Expr::Mul(vec![
                    Expr::Rational(2, 3),
                    pow(&s, Expr::int(-1)),
                    pow(&x, Expr::Rational(1, 2)),
                ]),
                "2*x^(1/2)/(3*(x - 2*y))",
            ),
            (
                Expr::Mul(vec![
                    Expr::Rational(5, 3),
                    pow(&x, Expr::int(-2)),
                    Expr::Float(-1.5),
                ]),
                "-(5*1.5/(3*x^2))",
            ),
        ];
        for (e, want) in cases {
            assert_eq!(e.to_infix(), want, "{e:?}");
        }
    }
}
