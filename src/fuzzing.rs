//! Harnesses shared by the fuzz targets (`fuzz/fuzz_targets/`) and their regression test
//! (`tests/fuzz_regressions.rs`): each feeds arbitrary bytes to one text parser and uses the
//! result the way the command line would, so a panic anywhere on that path is a finding. The
//! tape loader's ([`tape`]) reads its bytes as edits to a compiled model's tape and runs every
//! method of a tape it accepts.

use crate::scene::Scene;
use crate::spec::{self, expr::Expr};
use std::path::Path;

/// The longest input the harnesses pass on (libFuzzer's default `-max_len` is 4096).
pub const MAX_LEN: usize = 1 << 16;

fn text(data: &[u8]) -> Option<&str> {
    if data.len() > MAX_LEN {
        return None;
    }
    std::str::from_utf8(data).ok()
}

/// The scene parser against the shipped models; errors are formatted as `rodcube run` does.
pub fn scene(data: &[u8]) {
    let Some(text) = text(data) else { return };
    match Scene::parse(text, Path::new("fuzz.yaml"), crate::models::all()) {
        Ok(scene) => {
            let _ = (scene.stem(), scene.parameter_map(), scene.info().name);
        }
        Err(e) => {
            let shown = e.to_string();
            assert!(!shown.is_empty(), "an empty scene error");
        }
    }
}

/// The model-spec parser and checker; errors must name the file.
pub fn spec(data: &[u8]) {
    let Some(text) = text(data) else { return };
    match spec::parse(Path::new("fuzz.yaml"), text) {
        Ok(checked) => {
            assert!(spec::is_identifier(&checked.spec.name));
        }
        Err(e) => {
            let shown = e.to_string();
            assert!(shown.starts_with("fuzz.yaml:"), "{shown}");
        }
    }
}

/// The spec expression parser, then everything the derivation tool does with a parsed
/// expression that needs no Symbolica: print (infix; LaTeX, broken into lines, with the
/// `derive` feature), tidy, evaluate. The infix form must parse again, since Symbolica reads it back.
pub fn expr(data: &[u8]) {
    let Some(text) = text(data) else { return };
    let Ok(e) = Expr::parse(text) else { return };
    let value = |_: &str| Some(0.5);
    for e in [e.clone(), e.tidy()] {
        let infix = e.to_infix();
        if let Err(err) = Expr::parse(&infix) {
            panic!("`{text}` prints as `{infix}`, which does not parse: {err:?}");
        }
        // The LaTeX printer belongs to the derivation tool.
        #[cfg(feature = "derive")]
        {
            let name = |s: &str| s.to_string();
            let _ = e.to_latex(&name);
            let _ = e.to_latex_lines(&name, 60, 0);
        }
        let _ = e.eval(&value);
        let _ = (e.symbols(), e.functions());
    }
}

/// What [`tape`] made of an input.
#[derive(Debug)]
pub enum TapeOutcome {
    /// Too long to try (over [`MAX_LEN`]).
    Skipped,
    /// The loader refused the tape with this error (which names the file).
    Refused(crate::tape::TapeError),
    /// The loader accepted the tape and every method ran on it.
    Accepted,
}

/// The file name the tape harness gives the loader.
pub const TAPE_FILE: &str = "fuzz.tape.json";

/// The tape loader (`tape::parse`), then every method of an accepted model. `data` is either a
/// tape's text (when it starts with `{`) or edits to a compiled model's embedded tape: its first
/// byte picks the model (by index in `models::compiled()`), the rest is a list of edits
/// ([`edit_tape`]: an operand, an operation, an instruction deleted, duplicated or moved, a
/// method dropped or renamed, a number or list of the info, a digit of the text). Unless an
/// edit says otherwise, `body_digest` is then made to match the body, so that the checks behind
/// the digest are what decides. A refusal must name the file; an accepted tape's model must run
/// every `Model` and `Reduction` method, with slices of the lengths its info gives, without a
/// panic.
pub fn tape(data: &[u8]) -> TapeOutcome {
    if data.len() > MAX_LEN {
        return TapeOutcome::Skipped;
    }
    let text = if data.first() == Some(&b'{') {
        let Ok(text) = std::str::from_utf8(data) else {
            return TapeOutcome::Skipped;
        };
        match serde_json::from_str::<serde_json::Value>(text) {
            Ok(mut v) => {
                fix_digest(&mut v);
                v.to_string()
            }
            Err(_) => text.to_string(),
        }
    } else {
        let compiled = crate::models::compiled();
        let (pick, edits) = data.split_first().unwrap_or((&0, &[]));
        let name = compiled[*pick as usize % compiled.len()].info().name;
        let Some(seed) = crate::models::embedded_tape(name) else {
            return TapeOutcome::Skipped;
        };
        edit_tape(seed, edits)
    };
    match crate::tape::parse(&text, TAPE_FILE) {
        Err(e) => {
            let shown = e.to_string();
            assert!(shown.starts_with(TAPE_FILE), "{shown}");
            TapeOutcome::Refused(e)
        }
        Ok(model) => {
            exercise(&model);
            TapeOutcome::Accepted
        }
    }
}

/// `body_digest` set to the digest of the body, where the body has a tape's shape.
fn fix_digest(v: &mut serde_json::Value) {
    let Ok(body) = serde_json::from_value::<crate::tape::format::Body>(v["body"].clone()) else {
        return;
    };
    if let Some(o) = v.as_object_mut() {
        o.insert("body_digest".into(), body.digest().into());
    }
}

/// The bytes of an edit list, read front to back (zeros once they run out).
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn byte(&mut self) -> u8 {
        let Some((&b, rest)) = self.0.split_first() else {
            return 0;
        };
        self.0 = rest;
        b
    }

    fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.byte(), self.byte()])
    }

    /// One bit.
    fn coin(&mut self) -> bool {
        self.byte() & 1 == 0
    }

    /// An index below `n` (0 when `n` is 0).
    fn below(&mut self, n: usize) -> usize {
        if n == 0 { 0 } else { self.u16() as usize % n }
    }

    /// A value to put where a number, a name or an operand was: mostly small indices, and
    /// the bounds the loader enforces (registers, indices, 32-bit operands) on either side.
    fn value(&mut self) -> serde_json::Value {
        use serde_json::json;
        let b = self.byte();
        match b % 16 {
            0..=5 => json!(self.byte() % 64),
            6 => json!(self.u16()),
            7 => json!((1u64 << 20) - 1),
            8 => json!(1u64 << 20),
            9 => json!(u32::MAX),
            10 => json!(u64::from(u32::MAX) + 1),
            11 => json!(u64::MAX),
            12 => json!(-1),
            13 => json!(2.5),
            14 => {
                let args = crate::tape::format::ARGS;
                json!(args[self.below(args.len())].1)
            }
            _ => [json!(null), json!("inf"), json!("nan"), json!([])][b as usize / 16 % 4].clone(),
        }
    }
}

/// The operation names of the format, and one that is not.
const OPERATIONS: &[&str] = &[
    "ld",
    "st",
    "fill",
    "const",
    "add",
    "sub",
    "mul",
    "div",
    "powf",
    "powi",
    "neg",
    "sqrt",
    "sin",
    "cos",
    "tan",
    "asin",
    "acos",
    "atan",
    "exp",
    "ln",
    "abs",
    "sin_cos",
    "start_offsets",
    "jump",
];

/// The JSON pointers of `v`'s leaves (numbers, strings, booleans, nulls) or, with `lists`, of
/// its arrays, under `at`.
fn pointers(v: &serde_json::Value, at: String, lists: bool, out: &mut Vec<String>) {
    use serde_json::Value;
    match v {
        Value::Object(o) => {
            for (k, x) in o {
                pointers(x, format!("{at}/{k}"), lists, out);
            }
        }
        Value::Array(a) => {
            if lists {
                out.push(at.clone());
            }
            for (i, x) in a.iter().enumerate() {
                pointers(x, format!("{at}/{i}"), lists, out);
            }
        }
        _ if !lists => out.push(at),
        _ => {}
    }
}

/// Every instruction list of a tape: each method's `code`, then its cases' (`cases/i/code`).
fn code_lists(v: &mut serde_json::Value) -> Vec<&mut Vec<serde_json::Value>> {
    let mut out = Vec::new();
    let Some(functions) = v["body"]["functions"].as_array_mut() else {
        return out;
    };
    for f in functions.iter_mut().filter_map(|f| f.as_object_mut()) {
        for (key, x) in f.iter_mut() {
            match (key.as_str(), x) {
                ("code", serde_json::Value::Array(code)) => out.push(code),
                ("cases", serde_json::Value::Array(cases)) => {
                    for case in cases.iter_mut().filter_map(|c| c.as_object_mut()) {
                        if let Some(serde_json::Value::Array(code)) = case.get_mut("code") {
                            out.push(code);
                        }
                    }
                }
                _ => {}
            }
        }
    }
    out
}

/// A tape's text with the edits `data` describes (see [`tape`]), its digest made to match its
/// body unless an edit said not to. An edit that leaves the text no longer JSON (a digit
/// replaced by another character) ends the list: that text is the result.
pub fn edit_tape(seed: &str, data: &[u8]) -> String {
    let Ok(mut v) = serde_json::from_str::<serde_json::Value>(seed) else {
        return seed.to_string();
    };
    let mut r = Reader(data);
    let mut fix = true;
    while !r.0.is_empty() {
        let kind = r.byte() % 16;
        match kind {
            0..=6 | 15 => edit_code(kind, &mut r, &mut v),
            7 | 11 => edit_methods(kind, &mut r, &mut v),
            8..=10 => edit_info(kind, &mut r, &mut v),
            12 => {
                if let Err(text) = edit_digit(&mut r, &mut v) {
                    return text;
                }
            }
            // A header field changed.
            13 => {
                let key = ["format", "version", "model", "body_digest"][r.below(4)];
                v[key] = r.value();
            }
            // The digest left as the seed's.
            _ => fix = false,
        }
    }
    if fix {
        fix_digest(&mut v);
    }
    v.to_string()
}

/// An edit of the instructions: an operand replaced (0) or moved by one (1: an off-by-one
/// register or index), an operation renamed (2), an instruction deleted (3), duplicated into
/// its own list or another (4), two swapped (5), an operand dropped or added (6), a `const` or
/// `fill` value made extreme (15).
fn edit_code(kind: u8, r: &mut Reader, v: &mut serde_json::Value) {
    use serde_json::Value;
    let mut lists = code_lists(v);
    let n = lists.len();
    let (from, to) = (r.below(n), r.below(n));
    let Some(code) = lists.get_mut(from) else {
        return;
    };
    let (i, j) = (r.below(code.len()), r.below(code.len()));
    match kind {
        3 => {
            if i < code.len() {
                code.remove(i);
            }
            return;
        }
        4 => {
            let Some(copy) = code.get(i).cloned() else {
                return;
            };
            let dest = &mut lists[to];
            let at = r.below(dest.len() + 1);
            dest.insert(at, copy);
            return;
        }
        5 => {
            if i < code.len() && j < code.len() {
                code.swap(i, j);
            }
            return;
        }
        _ => {}
    }
    let Some(Value::Array(instr)) = code.get_mut(i) else {
        return;
    };
    match kind {
        0 | 1 if instr.len() >= 2 => {
            let at = 1 + r.below(instr.len() - 1);
            instr[at] = match instr[at].as_u64() {
                Some(x) if kind == 1 && r.coin() => x.wrapping_add(1).into(),
                Some(x) if kind == 1 => x.wrapping_sub(1).into(),
                _ => r.value(),
            };
        }
        2 => {
            if let Some(first) = instr.first_mut() {
                *first = OPERATIONS[r.below(OPERATIONS.len())].into();
            }
        }
        6 => {
            if r.coin() {
                instr.push(r.value());
            } else if instr.len() > 1 {
                instr.pop();
            }
        }
        15 => {
            let value = [
                Value::from("nan"),
                Value::from("inf"),
                Value::from("-inf"),
                Value::from(f64::MAX),
                Value::from(-0.0),
                Value::from(5e-324),
            ][r.below(6)]
            .clone();
            if instr.len() == 3 && matches!(instr[0].as_str(), Some("const" | "fill")) {
                instr[2] = value;
            }
        }
        _ => {}
    }
}

/// An edit of the methods: one dropped, given twice or renamed (7), or a case of
/// `force_polynomial` given another contact, dropped or given twice (11).
fn edit_methods(kind: u8, r: &mut Reader, v: &mut serde_json::Value) {
    let Some(functions) = v["body"]["functions"].as_array_mut() else {
        return;
    };
    if kind == 7 {
        if functions.is_empty() {
            return;
        }
        let i = r.below(functions.len());
        match r.byte() % 3 {
            0 => {
                functions.remove(i);
            }
            1 => {
                let copy = functions[i].clone();
                functions.push(copy);
            }
            _ => {
                let names: Vec<&str> = crate::tape::method_names().collect();
                let name = names.get(r.below(names.len() + 1));
                functions[i]["name"] = name.copied().unwrap_or("format_disk").into();
            }
        }
        return;
    }
    let with_cases: Vec<usize> = (0..functions.len())
        .filter(|&i| functions[i]["cases"].is_array())
        .collect();
    let Some(&f) = with_cases.get(r.below(with_cases.len())) else {
        return;
    };
    let Some(cases) = functions[f]["cases"].as_array_mut() else {
        return;
    };
    if cases.is_empty() {
        return;
    }
    let i = r.below(cases.len());
    match r.byte() % 3 {
        0 => cases[i]["contact"] = r.value(),
        1 => {
            cases.remove(i);
        }
        _ => {
            let copy = cases[i].clone();
            cases.push(copy);
        }
    }
}

/// An edit of the info: a leaf (an index, a count, a degree, a name, a flag) replaced by any
/// value (8) or a small count (9), or an entry of one of its lists (parameters, coordinates,
/// contacts, shapes, degrees...) removed or given twice (10).
fn edit_info(kind: u8, r: &mut Reader, v: &mut serde_json::Value) {
    let mut found = Vec::new();
    pointers(
        &v["body"]["info"],
        "/body/info".into(),
        kind == 10,
        &mut found,
    );
    let at = found.get(r.below(found.len())).cloned().unwrap_or_default();
    if kind != 10 {
        let value = if kind == 8 {
            r.value()
        } else {
            (r.byte() % 8).into()
        };
        if let Some(x) = v.pointer_mut(&at) {
            *x = value;
        }
        return;
    }
    let remove = r.coin();
    let i = r.u16() as usize;
    if let Some(serde_json::Value::Array(list)) = v.pointer_mut(&at)
        && !list.is_empty()
    {
        let i = i % list.len();
        if remove {
            list.remove(i);
        } else {
            let copy = list[i].clone();
            list.push(copy);
        }
    }
}

/// A digit of the compact text replaced by another character; `Err` with the text where it is
/// no longer JSON.
fn edit_digit(r: &mut Reader, v: &mut serde_json::Value) -> Result<(), String> {
    let text = v.to_string();
    let digits: Vec<usize> = (text.bytes().enumerate())
        .filter(|(_, b)| b.is_ascii_digit())
        .map(|(i, _)| i)
        .collect();
    let Some(&at) = digits.get(r.below(digits.len())) else {
        return Ok(());
    };
    let mut bytes = text.into_bytes();
    bytes[at] = b"0123456789-.e "[r.below(14)];
    let text = String::from_utf8(bytes).unwrap_or_default();
    match serde_json::from_str(&text) {
        Ok(x) => {
            *v = x;
            Ok(())
        }
        Err(_) => Err(text),
    }
}

/// Every method of `model`, with every slice at the length its info gives (checked to be at
/// most `tape::MAX_LENGTH`, so that any caller can size it), on inputs made from its prepared
/// constants.
pub fn exercise(model: &dyn crate::model::Model) {
    use crate::model::TangentPoint;
    use crate::tape::MAX_LENGTH;
    let info = model.info();
    let (n, np, m) = (
        info.coordinates.len(),
        info.parameters.len(),
        info.contacts.len(),
    );
    let nf = info.frictions.len();
    let points = info.points.len();
    let nb = info.bodies.len();
    let ns = info.system_coordinates.len();
    let checked = |what: &str, len: Option<usize>| -> usize {
        match len {
            Some(len) if len <= MAX_LENGTH => len,
            _ => panic!(
                "{}: `{what}` is longer than {MAX_LENGTH} numbers",
                info.name
            ),
        }
    };
    let fall = info.reduction.as_ref().and_then(|r| r.fall_degree);
    let fall = checked(
        "fall_polynomial",
        fall.map_or(Some(0), |d| d.checked_add(1)),
    );
    let rows = (m.checked_mul(3))
        .and_then(|x| x.checked_add(n))
        .and_then(|x| x.checked_add(nf.checked_mul(2)?));
    let columns = n.checked_mul(2).and_then(|x| x.checked_add(np));
    let tangents = checked(
        "tangents",
        rows.zip(columns).and_then(|(a, b)| a.checked_mul(b)),
    );
    let sizes = checked(
        "sizes",
        (info.shapes.iter())
            .map(|s| s.first.checked_add(s.kind.numbers()))
            .try_fold(0, |m, x| x.map(|x| m.max(x))),
    );
    let mass = checked("mass", n.checked_mul(n));
    let jac = checked("jac", m.checked_mul(n));
    let tjac = checked("friction jac", nf.checked_mul(n));
    let initial_tangents = checked(
        "initial_tangents",
        n.checked_mul(2).and_then(|x| x.checked_mul(np)),
    );
    let p: Vec<f64> = (0..np).map(|i| 0.5 + 0.25 * i as f64).collect();
    let mut k = vec![0.0; checked("k", Some(info.n_constants))];
    model.prepare(&p, &mut k);
    let q: Vec<f64> = (0..n).map(|i| 0.1 + 0.2 * i as f64).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.3 - 0.1 * i as f64).collect();
    let qdd = vec![-0.5; n];
    let forces = vec![1.5; m];
    let fr = vec![0.25; nf];
    let out = |len: usize| vec![0.0; len];
    model.requirements(&p, &mut out(info.requirements.len()));
    model.restitutions(&p, &mut out(m));
    model.initial_state(&k, &mut out(n), &mut out(n));
    model.points(
        &k,
        &q,
        &qd,
        &mut vec![[0.0; 2]; points],
        &mut vec![[0.0; 2]; points],
    );
    let _ = model.energy(&k, &q, &qd);
    model.momenta(&k, &q, &qd, &mut out(info.cyclic.len()));
    model.equations(&k, &q, &qd, &mut out(mass), &mut out(n));
    model.forces_full(&k, &q, &qd, &qdd, &mut out(m));
    model.gaps(&k, &q, &mut out(m));
    model.constraints(&k, &q, &qd, &mut out(jac), &mut out(m));
    model.edges(&k, &q, &mut out(m));
    model.friction(&k, &q, &qd, &mut out(tjac), &mut out(nf));
    model.monitors_full(&k, &q, &qd, &forces, &mut out(info.monitors.len()));
    model.to_full(&k, &q, &qd, &mut out(ns), &mut out(ns));
    model.drawing(&k, &q, &mut vec![[0.0; 3]; nb], &mut out(sizes));
    if let Some(t) = model.tangents() {
        let at = TangentPoint {
            q: &q,
            qd: &qd,
            qdd: &qdd,
            forces: &forces,
            friction: &fr,
        };
        t.tangent_rows(&k, &at, &mut out(tangents));
        t.initial_tangents(&k, &mut out(initial_tangents));
    }
    let _ = model.lean_start(&p);
    let (Some(red), Some(layout)) = (model.reduction(), info.reduction.as_ref()) else {
        return;
    };
    let _ = red.reduced(&k, 0.1);
    let _ = red.theta_dot_sq_sc(&k, 0.2, 0.9, 0.01, 0.02);
    red.forces(&k, 0.1, &mut out(m));
    for (contact, &degree) in layout.force_degrees.iter().enumerate() {
        let len = checked("force_polynomial", degree.checked_add(1));
        red.force_polynomial(&k, contact, &mut out(len));
    }
    red.fall_polynomial(&k, &mut out(fall));
    let mut lean = out(info.n_constants);
    red.prepare_lean(&p, &mut lean);
    if let Some(d) = red.partials() {
        d.separation_partials(&k, 0.2, 0.9, &mut out(np + 1));
        d.theta_dot_sq_partials(&k, 0.2, 0.9, &mut out(np));
        d.start_partials(&k, &mut out(np));
        d.fall_partials(&k, &mut out(checked("fall_partials", fall.checked_mul(np))));
    }
    red.full_state(&k, 0.05, 0.1, -0.3, &mut out(n), &mut out(n));
}
