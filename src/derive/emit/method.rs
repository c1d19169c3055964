//! The head and preamble of one generated method: arguments its body never reads are spelled
//! with a leading `_`, and a preamble line (the constant slice, the angle's sine and cosine, the
//! start offsets, a renamed argument, the parameters and the state by name) is written only
//! when the body reads what it defines, so the generated code compiles without
//! `allow(unused_variables)`.

/// A line a method's body may start with, kept only when the rest reads what it defines.
#[derive(Debug, Clone, Copy)]
pub enum Preamble<'a> {
    /// `let k = &k[..n];`: one bounds check for all constant loads.
    Slice(usize),
    /// `rc_s`, `rc_c`: the sine and cosine of the coordinate `q[i]` (none without a reduced
    /// coordinate, where no expression is written over them).
    Angle(Option<usize>),
    /// `rc_s`, `rc_c`, `rc_ds`, `rc_dc` from the start's angle, sine and cosine slots and
    /// `delta` (`model::start_offsets`).
    Offsets([usize; 3]),
    /// `let name = value;`.
    Let(&'a str, &'a str),
    /// `let name = slice[i];` for each `(i, name)`: the parameters by name, from `k` or `p`.
    Names(&'a [String], &'a str),
    /// `let c = q[i];`, `let c_dot = qd[i];`, `let c_ddot = qdd[i];`: the state by the
    /// coordinates' names.
    State(&'a [String]),
}

/// Whether `line` reads the identifier `word` (not as part of a longer identifier; comments
/// do not count).
fn mentions(line: &str, word: &str) -> bool {
    let code = line.split("//").next().unwrap_or("");
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    code.match_indices(word).any(|(at, _)| {
        let before = code[..at].chars().next_back();
        let after = code[at + word.len()..].chars().next();
        !before.is_some_and(ident) && !after.is_some_and(ident)
    })
}

/// `lines` without the `let name = ...;` lines whose name no later line reads (a force's
/// `theta_dot^2` in a model whose forces do not depend on it, and what only it read).
fn without_dead_lets(lines: Vec<String>) -> Vec<String> {
    let mut kept: Vec<String> = Vec::with_capacity(lines.len());
    for line in lines.into_iter().rev() {
        let name = line
            .strip_prefix("let ")
            .and_then(|rest| rest.split_once(" = "))
            .map(|(name, _)| name);
        let dead = name.is_some_and(|name| {
            name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                && !kept.iter().any(|l| mentions(l, name))
        });
        if !dead {
            kept.push(line);
        }
    }
    kept.reverse();
    kept
}

/// The argument list (without `&self`) and the body of a method whose statements and final
/// lines are `body`, with arguments `args` (name, type) and the `preamble` lines it may need.
pub fn method(
    args: &[(&str, &str)],
    preamble: &[Preamble],
    body: Vec<String>,
) -> (String, Vec<String>) {
    let reads = |lines: &[String], word: &str| lines.iter().any(|l| mentions(l, word));
    let body = without_dead_lets(body);
    // Later preamble lines first: an earlier one (the slice) may be read only by them.
    let mut head: Vec<String> = Vec::new();
    for p in preamble.iter().rev() {
        let uses = |w: &str| reads(&body, w) || reads(&head, w);
        let line = match *p {
            Preamble::Slice(n) => uses("k")
                .then(|| format!("let k = &k[..{n}]; // one bounds check for all constant loads")),
            Preamble::Angle(None) => None,
            Preamble::Angle(Some(i)) => match (uses("rc_s"), uses("rc_c")) {
                (true, true) => Some(format!("let (rc_s, rc_c) = q[{i}].sin_cos();")),
                (true, false) => Some(format!("let rc_s = q[{i}].sin();")),
                (false, true) => Some(format!("let rc_c = q[{i}].cos();")),
                (false, false) => None,
            },
            Preamble::Offsets([th, s, c]) => {
                let names =
                    ["rc_s", "rc_c", "rc_ds", "rc_dc"].map(|n| if uses(n) { n } else { "_" });
                (names != ["_"; 4]).then(|| {
                    format!(
                        "let ({}) = start_offsets(k[{th}], k[{s}], k[{c}], delta);",
                        names.join(", ")
                    )
                })
            }
            Preamble::Let(name, value) => uses(name).then(|| format!("let {name} = {value};")),
            Preamble::Names(names, slice) => {
                let lets: Vec<String> = (names.iter().enumerate())
                    .filter(|(_, name)| uses(name))
                    .map(|(i, name)| format!("let {name} = {slice}[{i}];"))
                    .collect();
                head.extend(lets.into_iter().rev());
                None
            }
            Preamble::State(coords) => {
                let lets = (coords.iter().enumerate()).flat_map(|(i, c)| {
                    [("", "q"), ("_dot", "qd"), ("_ddot", "qdd")]
                        .map(|(suffix, slice)| (format!("{c}{suffix}"), format!("{slice}[{i}]")))
                });
                let lets: Vec<String> = lets
                    .filter(|(name, _)| uses(name))
                    .map(|(name, value)| format!("let {name} = {value};"))
                    .collect();
                head.extend(lets.into_iter().rev());
                None
            }
        };
        head.extend(line);
    }
    head.reverse();
    head.extend(body);
    let args = args
        .iter()
        .map(|(name, ty)| {
            let read = reads(&head, name);
            format!("{}{name}: {ty}", if read { "" } else { "_" })
        })
        .collect::<Vec<_>>()
        .join(", ");
    (args, head)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_only_what_the_body_reads() {
        let (args, lines) = method(
            &[("k", "&[f64]"), ("q", "&[f64]"), ("qd", "&[f64]")],
            &[Preamble::Slice(9), Preamble::Angle(Some(1))],
            vec!["let x = rc_c * k[3];".into(), "x".into()],
        );
        assert_eq!(args, "k: &[f64], q: &[f64], _qd: &[f64]");
        assert_eq!(
            lines[0],
            "let k = &k[..9]; // one bounds check for all constant loads"
        );
        assert_eq!(lines[1], "let rc_c = q[1].cos();");
        assert_eq!(lines.len(), 4);
    }

    #[test]
    fn an_unread_start_is_not_formed() {
        let (args, lines) = method(
            &[("k", "&[f64]"), ("delta", "f64"), ("out", "&mut [f64]")],
            &[
                Preamble::Slice(9),
                Preamble::Offsets([5, 6, 7]),
                Preamble::Let("rc_delta", "delta"),
            ],
            vec!["out[0] = rc_ds * 2.0; // rc_s rc_delta".into()],
        );
        assert_eq!(args, "k: &[f64], delta: f64, out: &mut [f64]");
        assert_eq!(
            lines[1],
            "let (_, _, rc_ds, _) = start_offsets(k[5], k[6], k[7], delta);"
        );
        assert_eq!(lines.len(), 3, "{lines:?}");
    }

    #[test]
    fn a_let_nothing_reads_goes_with_what_only_it_read() {
        let (_, lines) = method(
            &[("k", "&[f64]")],
            &[],
            vec![
                "let r_t0 = k[1] * k[1];".into(),
                "let rc_w2 = r_t0 + 1.0;".into(),
                "let rc_acc = k[2];".into(),
                "rc_acc".into(),
            ],
        );
        assert_eq!(lines, ["let rc_acc = k[2];", "rc_acc"]);
    }

    #[test]
    fn words_inside_longer_identifiers_are_not_reads() {
        assert!(!mentions("let rc_k = qd[0];", "k"));
        assert!(!mentions("let x = qd[0];", "q"));
        assert!(mentions("x = -k[2] / 2.0;", "k"));
    }
}
