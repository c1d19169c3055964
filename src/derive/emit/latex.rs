//! The LaTeX printer of the derivation tool: an [`Expr`] as LaTeX, its printed width, and long
//! displays broken into lines between the terms of a sum (the runtime crate prints no LaTeX).

use crate::derive::expr::{Expr, wrap_in, write_signed_sum};
use std::fmt::Write as _;

impl Expr {
    /// LaTeX, with `name` mapping each symbol to its LaTeX spelling.
    pub fn to_latex(&self, name: &dyn Fn(&str) -> String) -> String {
        let mut s = String::new();
        self.latex(&mut s, 0, name);
        s
    }

    fn latex(&self, out: &mut String, parent: u8, name: &dyn Fn(&str) -> String) {
        match self {
            Expr::Rational(n, 1) => {
                wrap_latex(out, *n < 0 && parent > 1, |o| {
                    let _ = write!(o, "{n}");
                });
            }
            Expr::Rational(n, d) => wrap_latex(out, *n < 0 && parent > 1, |o| {
                let _ = write!(
                    o,
                    "{}\\frac{{{}}}{{{d}}}",
                    if *n < 0 { "-" } else { "" },
                    n.abs()
                );
            }),
            Expr::Float(x) => out.push_str(&format!("{x}")),
            Expr::Sym(s) => out.push_str(&name(s)),
            Expr::Add(v) => wrap_latex(out, parent > 1, |o| {
                write_signed_sum(o, v, |o, mag| mag.latex(o, 2, name));
            }),
            Expr::Mul(_) => {
                let (neg, mag) = self.split_sign();
                let (num, den) = mag.num_den();
                wrap_latex(out, neg && parent > 1, |o| {
                    if neg {
                        o.push('-');
                    }
                    let write_factors = |o: &mut String, fs: &[Expr]| {
                        if fs.is_empty() {
                            o.push('1');
                        }
                        for (i, f) in fs.iter().enumerate() {
                            if i > 0 {
                                let digit_next = matches!(f, Expr::Rational(..) | Expr::Float(_));
                                // After `\sin \theta` a thin space, so that the next factor does
                                // not read as part of the function's argument.
                                let after_function = trig_factor(&fs[i - 1]);
                                o.push_str(if digit_next {
                                    " \\cdot "
                                } else if after_function {
                                    " \\, "
                                } else {
                                    " "
                                });
                            }
                            // Alone above or below the line, a sum needs no brackets.
                            let alone = if den.is_empty() { 2 } else { 0 };
                            f.latex(o, if fs.len() > 1 { 3 } else { alone }, name);
                        }
                    };
                    if den.is_empty() {
                        write_factors(o, &num);
                    } else {
                        o.push_str("\\frac{");
                        write_factors(o, &num);
                        o.push_str("}{");
                        write_factors(o, &den);
                        o.push('}');
                    }
                });
            }
            Expr::Pow(b, e) => {
                if let Some(n) = e.as_integer()
                    && n < 0
                {
                    out.push_str("\\frac{1}{");
                    Expr::Pow(b.clone(), Box::new(Expr::int(-n))).latex(out, 0, name);
                    out.push('}');
                    return;
                }
                if let Expr::Rational(1, 2) = **e {
                    out.push_str("\\sqrt{");
                    b.latex(out, 0, name);
                    out.push('}');
                    return;
                }
                if let Expr::Fun(f, args) = &**b
                    && matches!(f.as_str(), "sin" | "cos" | "tan")
                {
                    let _ = write!(out, "\\{f}^{{");
                    e.latex(out, 0, name);
                    out.push('}');
                    args[0].latex_fn_arg(out, name);
                    return;
                }
                b.latex(out, 5, name);
                out.push_str("^{");
                e.latex(out, 0, name);
                out.push('}');
            }
            Expr::Fun(f, args) => match f.as_str() {
                "sqrt" => {
                    out.push_str("\\sqrt{");
                    args[0].latex(out, 0, name);
                    out.push('}');
                }
                "sin" | "cos" | "tan" | "exp" | "log" => {
                    let _ = write!(out, "\\{f}");
                    args[0].latex_fn_arg(out, name);
                }
                _ => {
                    let _ = write!(out, "\\operatorname{{{f}}}\\left(");
                    args[0].latex(out, 0, name);
                    out.push_str("\\right)");
                }
            },
        }
    }

    fn latex_fn_arg(&self, out: &mut String, name: &dyn Fn(&str) -> String) {
        if let Expr::Sym(_) = self {
            out.push(' ');
            self.latex(out, 5, name);
        } else {
            out.push_str("\\left(");
            self.latex(out, 0, name);
            out.push_str("\\right)");
        }
    }

    /// Rough printed width of this expression's LaTeX, in characters of math italic: enough to
    /// decide where a long display must break (a fraction counts its wider part only).
    pub fn latex_width(&self, name: &dyn Fn(&str) -> String) -> usize {
        let paren = |e: &Expr| e.latex_width(name) + if matches!(e, Expr::Add(_)) { 2 } else { 0 };
        match self {
            Expr::Rational(n, 1) => n.to_string().len(),
            Expr::Rational(n, d) => n.to_string().len().max(d.to_string().len()) + 1,
            Expr::Float(x) => format!("{x}").len(),
            Expr::Sym(s) => visible_width(&name(s)),
            Expr::Add(v) => v
                .iter()
                .map(|t| t.split_sign().1.latex_width(name) + 3)
                .sum(),
            Expr::Mul(_) => {
                let (neg, mag) = self.split_sign();
                let (num, den) = mag.num_den();
                let wide = |fs: &[Expr]| fs.iter().map(paren).sum::<usize>().max(1);
                let w = if den.is_empty() {
                    wide(&num)
                } else {
                    wide(&num).max(wide(&den)) + 1
                };
                w + usize::from(neg)
            }
            Expr::Pow(b, e) => match e.as_integer() {
                Some(n) if n < 0 => {
                    Expr::Pow(b.clone(), Box::new(Expr::int(-n))).latex_width(name) + 1
                }
                _ if **e == Expr::Rational(1, 2) => b.latex_width(name) + 2,
                _ => paren(b) + e.latex_width(name).div_ceil(2),
            },
            Expr::Fun(f, args) => {
                let arg = args.first().map_or(0, |a| {
                    a.latex_width(name) + if matches!(a, Expr::Sym(_)) { 1 } else { 2 }
                });
                match f.as_str() {
                    "sqrt" => arg + 1,
                    f => f.len() + arg,
                }
            }
        }
    }

    /// This expression's LaTeX in display lines of about `width` characters (as counted by
    /// [`Expr::latex_width`]), `first` of them already taken on the first line. A sum breaks
    /// between its terms; a fraction whose numerator holds a long sum is written
    /// `\frac{c}{d} \Bigl( ... \Bigr)` so that the sum can break. One line when it fits.
    /// Join the lines with `\\` inside a `multline*`.
    pub fn to_latex_lines(
        &self,
        name: &dyn Fn(&str) -> String,
        width: usize,
        first: usize,
    ) -> Vec<String> {
        if first + self.latex_width(name) <= width {
            return vec![self.to_latex(name)];
        }
        match self {
            Expr::Add(terms) => {
                let (mut lines, last, _) = break_sum(terms, String::new(), first, "", name, width);
                lines.push(last);
                lines
            }
            Expr::Mul(_) => {
                let (neg, mag) = self.split_sign();
                let (mut num, den) = mag.num_den();
                // The numerator's widest sum breaks inside `\Bigl( \Bigr)`; so do long sums of
                // the denominator, written after it as `\Bigl( \Bigr)^{-k}`.
                let widest = num
                    .iter()
                    .enumerate()
                    .filter(|(_, f)| matches!(f, Expr::Add(_)))
                    .max_by_key(|(_, f)| f.latex_width(name))
                    .map(|(i, _)| i);
                let top = widest.and_then(|i| match num.remove(i) {
                    Expr::Add(terms) => Some(terms),
                    _ => None,
                });
                // A denominator `(a b)^k` is the factors `a^k`, `b^k`.
                let den = den.into_iter().flat_map(|d| match d {
                    Expr::Mul(v) => v,
                    Expr::Pow(b, k) if matches!(*b, Expr::Mul(_)) => match *b {
                        Expr::Mul(v) => v
                            .into_iter()
                            .map(|f| Expr::Pow(Box::new(f), k.clone()))
                            .collect(),
                        b => vec![Expr::Pow(Box::new(b), k)],
                    },
                    d => vec![d],
                });
                let (long, short): (Vec<Expr>, Vec<Expr>) =
                    den.partition(|f| sum_power(f).is_some() && f.latex_width(name) > width / 3);
                if top.is_none() && long.is_empty() {
                    return vec![self.to_latex(name)];
                }
                let mut factors = num;
                factors.extend(
                    short
                        .into_iter()
                        .map(|d| Expr::Pow(Box::new(d), Box::new(Expr::int(-1)))),
                );
                // Kept a product even of one factor, so that `1/d^2` prints as a fraction.
                let coefficient = if factors.is_empty() {
                    Expr::int(1)
                } else {
                    Expr::Mul(factors)
                };
                let mut line = String::from(if neg { "-" } else { "" });
                let mut used = first + usize::from(neg);
                if coefficient != Expr::int(1) {
                    coefficient.latex(&mut line, 0, name);
                    line.push(' ');
                    used += coefficient.latex_width(name) + 1;
                }
                let mut lines = Vec::new();
                if let Some(terms) = top {
                    (lines, line, used) =
                        break_sum(&terms, line + "\\Bigl(", used + 1, "\\Bigr)", name, width);
                }
                for f in &long {
                    let Some((terms, k)) = sum_power(f) else {
                        continue;
                    };
                    let (done, last, last_used) = break_sum(
                        terms,
                        line + " \\Bigl(",
                        used + 1,
                        &format!("\\Bigr)^{{-{k}}}"),
                        name,
                        width,
                    );
                    lines.extend(done);
                    (line, used) = (last, last_used);
                }
                lines.push(line);
                lines
            }
            _ => vec![self.to_latex(name)],
        }
    }
}

/// Whether a factor prints as a function of a bare symbol (`\sin \theta`, `\cos^{2} \theta`),
/// whose argument the next factor would seem to continue.
fn trig_factor(f: &Expr) -> bool {
    let bare_call = |e: &Expr| {
        matches!(e, Expr::Fun(name, args)
            if matches!(name.as_str(), "sin" | "cos" | "tan" | "exp" | "log")
                && matches!(args.first(), Some(Expr::Sym(_))))
    };
    match f {
        Expr::Pow(b, _) => bare_call(b),
        f => bare_call(f),
    }
}

/// The terms of a sum on display lines of about `width` characters: the first line starts with
/// `line` (`used` characters taken), the last ends with `close`; a continued line starts with
/// `{}` so its leading sign is spaced as a binary operator. Returns the lines before the
/// last, the last (which a caller may go on) and the width used on it.
fn break_sum(
    terms: &[Expr],
    mut line: String,
    mut used: usize,
    close: &str,
    name: &dyn Fn(&str) -> String,
    width: usize,
) -> (Vec<String>, String, usize) {
    let mut lines = Vec::new();
    let mut in_line = 0;
    for (i, t) in terms.iter().enumerate() {
        let (neg, mag) = t.split_sign();
        let w = mag.latex_width(name) + 3;
        if in_line > 0 && used + w > width {
            lines.push(std::mem::replace(&mut line, String::from("{}")));
            used = 0;
            in_line = 0;
        }
        if i == 0 {
            if neg {
                line.push('-');
            }
        } else {
            line.push_str(if neg { " - " } else { " + " });
        }
        mag.latex(&mut line, 2, name);
        used += w;
        in_line += 1;
    }
    line.push_str(close);
    (lines, line, used + 2)
}

/// A sum or a sum raised to a positive integer power: its terms and the power.
fn sum_power(e: &Expr) -> Option<(&[Expr], i128)> {
    match e {
        Expr::Add(terms) => Some((terms, 1)),
        Expr::Pow(b, k) => match (&**b, k.as_integer()) {
            (Expr::Add(terms), Some(k)) if k > 0 => Some((terms, k)),
            _ => None,
        },
        _ => None,
    }
}

/// Characters a LaTeX fragment shows: letters and digits count one each, `\sin`-like
/// operators three, Greek letters one, and markup (`\mathrm`, `\dot`, braces, `_`) nothing.
fn visible_width(latex: &str) -> usize {
    let mut n = 0;
    let mut chars = latex.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '\\' {
            let mut cmd = String::new();
            while let Some(&d) = chars.peek() {
                if !d.is_ascii_alphabetic() {
                    break;
                }
                cmd.push(d);
                chars.next();
            }
            n += match cmd.as_str() {
                "sin" | "cos" | "tan" | "exp" | "log" => 3,
                "mathrm" | "dot" | "ddot" | "operatorname" | "left" | "right" | "" => 0,
                _ => 1,
            };
        } else if c.is_ascii_alphanumeric() {
            n += 1;
        }
    }
    n
}

fn wrap_latex(out: &mut String, paren: bool, f: impl FnOnce(&mut String)) {
    wrap_in(out, paren.then_some(("\\left(", "\\right)")), f);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_displays_break_between_terms() {
        let name = |s: &str| s.to_string();
        let terms: Vec<String> = (1..=30).map(|i| format!("{i}*x^{i}")).collect();
        let sum = Expr::parse(&terms.join(" + ")).unwrap();
        assert_eq!(
            Expr::parse("x + y")
                .unwrap()
                .to_latex_lines(&name, 40, 0)
                .len(),
            1
        );
        let lines = sum.to_latex_lines(&name, 40, 0);
        assert!(lines.len() > 2, "{lines:?}");
        assert!(
            lines[1..].iter().all(|l| l.starts_with("{} + ")),
            "{lines:?}"
        );
        // A fraction with a long numerator and denominator keeps both sums breakable.
        let frac = Expr::parse(&format!(
            "3*({})/(y*({})^2)",
            terms.join(" + "),
            terms.join(" - ")
        ))
        .unwrap()
        .tidy();
        let lines = frac.to_latex_lines(&name, 40, 0);
        let text = lines.join(" ");
        assert!(lines[0].starts_with("\\frac{3}{y} \\Bigl("), "{lines:?}");
        assert!(text.ends_with("\\Bigr)^{-2}"), "{text}");
        assert!(lines.iter().all(|l| !l.contains("\\left(")), "{lines:?}");
    }
}
