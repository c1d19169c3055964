//! Tidy rules every file keeps: a `//!` line saying what it is for, no ignored tests, no
//! trailing whitespace (as rust-analyzer's tidy test does).

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn all() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in ["src", "tests", "benches", "examples", "generated"] {
        rust_files(&root.join(dir), &mut files);
    }
    assert!(files.len() > 20, "found only {} Rust files", files.len());
    files
}

#[test]
fn every_rust_file_starts_with_a_doc_line() {
    let missing: Vec<_> = all()
        .into_iter()
        .filter(|p| {
            !std::fs::read_to_string(p)
                .unwrap_or_default()
                .starts_with("//!")
        })
        .collect();
    assert!(
        missing.is_empty(),
        "files without a leading `//!` line: {missing:?}"
    );
}

/// Whether Rust source `text` ignores a test in any spelling: the `ignore` attribute alone or
/// with a reason, with spaces or line breaks anywhere in it, or through `cfg_attr`. (This
/// file spells none: the attribute is built from pieces.)
fn ignores_a_test(text: &str) -> bool {
    let squeezed: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    let word = ["ig", "nore"].concat();
    let head = format!("#[{word}");
    let direct = squeezed.match_indices(&head).any(|(i, _)| {
        matches!(
            squeezed[i + head.len()..].chars().next(),
            Some(']' | '=' | '(')
        )
    });
    if direct {
        return true;
    }
    // Through `cfg_attr(cond, <the attribute>)`, with or without a reason.
    squeezed.match_indices("#[cfg_attr(").any(|(i, m)| {
        let rest = &squeezed[i + m.len()..];
        let attr = rest.split("]").next().unwrap_or(rest);
        attr.split([',', '(', ')'])
            .any(|t| t == word || t.starts_with(&format!("{word}=")))
    })
}

#[test]
fn no_test_is_ignored() {
    let mut files = all();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["python/src", "fuzz/fuzz_targets"] {
        rust_files(&root.join(dir), &mut files);
    }
    let found: Vec<_> = files
        .into_iter()
        .filter(|p| ignores_a_test(&std::fs::read_to_string(p).unwrap_or_default()))
        .collect();
    assert!(found.is_empty(), "ignored tests in {found:?}");
    // The detector itself, on every spelling (built so that this file holds none).
    let word = ["ig", "nore"].concat();
    for spelling in [
        format!("#[{word}]"),
        format!("#[{word} = \"slow\"]"),
        format!("# [ {word} ]"),
        format!("#[\n    {word}\n]"),
        format!("#[cfg_attr(miri, {word})]"),
        format!("#[cfg_attr(not(target_os = \"linux\"), {word} = \"why\")]"),
    ] {
        assert!(ignores_a_test(&spelling), "{spelling:?} not caught");
    }
    for fine in [
        "#[test]".to_string(),
        format!("let {word}d = 1;"),
        format!("#[cfg_attr(miri, allow({word}d_lint))]"),
    ] {
        assert!(!ignores_a_test(&fine), "{fine:?} caught");
    }
}

/// Python tests skipped or expected to fail: `pytest.mark.skip`, `skipif`, `xfail`, or
/// `pytest.skip(...)` in a test body.
#[test]
fn no_python_test_is_skipped() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("python/tests");
    let entries = std::fs::read_dir(&root).expect("python/tests");
    let markers = [
        ["mark.", "skip"].concat(),
        ["x", "fail"].concat(),
        ["pytest.", "skip("].concat(),
    ];
    let mut read = 0;
    for e in entries.flatten() {
        let p = e.path();
        if p.extension().is_some_and(|x| x == "py") {
            read += 1;
            let text = std::fs::read_to_string(&p).unwrap_or_default();
            for m in &markers {
                assert!(!text.contains(m.as_str()), "{} contains {m}", p.display());
            }
        }
    }
    assert!(read > 0, "no Python test files in {}", root.display());
}

#[test]
fn no_trailing_whitespace() {
    let mut bad = Vec::new();
    for p in all() {
        let text = std::fs::read_to_string(&p).unwrap_or_default();
        for (i, line) in text.lines().enumerate() {
            if line.ends_with(' ') || line.ends_with('\t') {
                bad.push(format!("{}:{}", p.display(), i + 1));
            }
        }
    }
    assert!(bad.is_empty(), "trailing whitespace at {bad:?}");
}

/// The generated models (`generated/*.rs`, not the registry): no blanket `allow`, no constant
/// slot that copies another (`k[12] = k[2];`) or holds a negated copy, and every slot written
/// is read somewhere (by the generated code, or by the runtime through the model's
/// `ReductionInfo`: the start's angle, rate, sine and cosine).
#[test]
fn generated_models_hold_each_constant_once_and_need_no_blanket_allow() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
    let mut checked = 0;
    for entry in std::fs::read_dir(&root).expect("generated/").flatten() {
        let p = entry.path();
        if p.extension().is_none_or(|x| x != "rs") || p.ends_with("mod.rs") {
            continue;
        }
        let text = std::fs::read_to_string(&p).expect("readable");
        let file = p.display();
        assert!(!text.contains("#![allow("), "{file}: a blanket allow");
        assert!(
            !text.contains("allow(unused_variables") && !text.contains("allow(unused_parens"),
            "{file}: unused variables or parentheses allowed"
        );
        let slot =
            |s: &str| -> Option<usize> { s.strip_prefix("k[")?.strip_suffix(']')?.parse().ok() };
        let mut written = Vec::new();
        for line in text.lines().map(str::trim) {
            let Some((lhs, rhs)) = line.split_once(" = ") else {
                continue;
            };
            let Some(i) = slot(lhs) else { continue };
            written.push(i);
            let value = rhs.trim_end_matches(';').trim_start_matches('-');
            assert!(
                slot(value).is_none(),
                "{file}: `{line}` copies a constant another slot holds"
            );
        }
        let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
        let model = rodcube::models::find(stem).unwrap_or_else(|| panic!("{file}: no model"));
        let runtime: Vec<usize> = model.info().reduction.map_or(Vec::new(), |r| {
            vec![
                r.k_theta_initial,
                r.k_theta_dot_initial,
                r.k_sin_initial,
                r.k_cos_initial,
            ]
        });
        for i in written.into_iter().filter(|i| !runtime.contains(i)) {
            let reads = text.matches(&format!("k[{i}]")).count();
            let writes = text.matches(&format!("k[{i}] = ")).count();
            assert!(reads > writes, "{file}: k[{i}] is written and never read");
        }
        checked += 1;
    }
    assert!(checked >= 7, "checked only {checked} generated models");
}

/// The longest a function may run, in lines from its `fn` line to its closing brace.
const MAX_FUNCTION_LINES: usize = 150;

/// Where a line opens a function: its indentation and name (a declaration ending in `;` is
/// none).
fn function_start(line: &str) -> Option<(&str, &str)> {
    let body = line.trim_start();
    let indent = &line[..line.len() - body.len()];
    if line.trim_end().ends_with(';') {
        return None;
    }
    let mut rest = body;
    for prefix in [
        "pub(crate) ",
        "pub(super) ",
        "pub ",
        "const ",
        "async ",
        "unsafe ",
    ] {
        rest = rest.strip_prefix(prefix).unwrap_or(rest);
    }
    rest = rest.strip_prefix("extern \"C\" ").unwrap_or(rest);
    let name = rest.strip_prefix("fn ")?;
    let end = name
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(name.len());
    (end > 0).then(|| (indent, &name[..end]))
}

#[test]
fn no_function_in_src_passes_150_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    let mut long = Vec::new();
    for p in files {
        let text = std::fs::read_to_string(&p).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let Some((indent, name)) = function_start(line) else {
                continue;
            };
            let close = format!("{indent}}}");
            if let Some(j) = (i + 1..lines.len()).find(|&j| lines[j] == close)
                && j - i + 1 > MAX_FUNCTION_LINES
            {
                long.push(format!(
                    "{}:{} {name} ({} lines)",
                    p.display(),
                    i + 1,
                    j - i + 1
                ));
            }
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_FUNCTION_LINES} lines: {long:#?}"
    );
}

/// The library's top-level modules, bottom-up: a module imports only from layers below its
/// own (ARCHITECTURE.md draws the same graph). `lib.rs` and the binary (`main.rs`,
/// `numerics_cli.rs`) sit above them all.
const LAYERS: &[&[&str]] = &[
    &["io", "yaml", "reference"],
    &["model", "spec"],
    &["tape"],
    &["models", "system", "quantity", "axes"],
    &["results"],
    &["solve", "report"],
    &["plan"],
    &["scene", "sweep"],
    &["accuracy", "ffi", "fmu", "fuzzing", "derive"],
];

/// Every `src/` module (`a::b` for `src/a/b.rs` and `src/a/b/mod.rs`) with its text outside
/// comments and before its unit tests.
fn src_modules() -> Vec<(String, String)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut out = Vec::new();
    for p in files {
        let rel = p.strip_prefix(&src).expect("under src").with_extension("");
        let mut parts: Vec<String> = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        if parts.last().is_some_and(|l| l == "mod") {
            parts.pop();
        }
        let text = std::fs::read_to_string(&p).unwrap_or_default();
        let code = text.split("#[cfg(test)]\nmod ").next().unwrap_or_default();
        let code: String = code
            .lines()
            .map(|l| l.split("//").next().unwrap_or_default())
            .collect::<Vec<_>>()
            .join("\n");
        out.push((parts.join("::"), code));
    }
    out
}

/// The modules `code` (of module `this`) names through `crate::` and `super::` paths, each
/// resolved to the longest module that exists.
fn imports(this: &str, code: &str, modules: &[String]) -> Vec<String> {
    let resolve = |path: &str| -> Option<String> {
        let parts: Vec<&str> = path.split("::").collect();
        (1..=parts.len())
            .rev()
            .map(|k| parts[..k].join("::"))
            .find(|m| modules.contains(m))
    };
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
            .collect::<String>()
            .trim_end_matches(':')
            .to_string()
    };
    let mut out = Vec::new();
    for (prefix, base) in [("crate::", String::new()), ("super::", parent(this))] {
        for (at, _) in code.match_indices(prefix) {
            let rest = &code[at + prefix.len()..];
            let path = ident(rest);
            let full = if base.is_empty() {
                path.clone()
            } else {
                format!("{base}::{path}")
            };
            out.extend(resolve(&full));
            // `use crate::a::{b, c::d}`: each item may be a module of its own.
            if let Some(group) = rest[path.len()..].strip_prefix("::{") {
                for item in group.split('}').next().unwrap_or_default().split(',') {
                    let item = ident(item.trim());
                    if !item.is_empty() && item != "self" {
                        out.extend(resolve(&format!("{full}::{item}")));
                    }
                }
            }
        }
    }
    out.retain(|m| m != this);
    out.sort();
    out.dedup();
    out
}

/// The module above `this` (`a` for `a::b`; empty at the top).
fn parent(this: &str) -> String {
    this.rsplit_once("::")
        .map_or(String::new(), |(p, _)| p.to_string())
}

fn layer_of(module: &str) -> Option<usize> {
    let top = module.split("::").next().unwrap_or_default();
    LAYERS.iter().position(|l| l.contains(&top))
}

#[test]
fn modules_import_only_from_lower_layers() {
    let modules = src_modules();
    let names: Vec<String> = modules.iter().map(|(m, _)| m.clone()).collect();
    let mut wrong = Vec::new();
    for (this, code) in &modules {
        if ["lib", "main", "numerics_cli"].contains(&this.as_str()) {
            continue;
        }
        let Some(own) = layer_of(this) else {
            wrong.push(format!("{this}: a top-level module missing from LAYERS"));
            continue;
        };
        let top = this.split("::").next().unwrap_or_default();
        for target in imports(this, code, &names) {
            if target.split("::").next() == Some(top) {
                continue;
            }
            match layer_of(&target) {
                Some(l) if l < own => {}
                _ => wrong.push(format!("{this} imports {target}, not from a lower layer")),
            }
        }
    }
    assert!(wrong.is_empty(), "imports against the layers: {wrong:#?}");
}

#[test]
fn no_two_modules_import_each_other() {
    let modules = src_modules();
    let names: Vec<String> = modules.iter().map(|(m, _)| m.clone()).collect();
    let graph: Vec<(String, Vec<String>)> = modules
        .iter()
        .map(|(m, code)| (m.clone(), imports(m, code, &names)))
        .collect();
    let edges = |m: &str| -> &[String] {
        graph
            .iter()
            .find(|(n, _)| n == m)
            .map_or(&[][..], |(_, e)| e.as_slice())
    };
    // A cycle of any length: a module that reaches itself through its imports.
    let mut cycles = Vec::new();
    for (start, _) in &graph {
        let mut seen = vec![start.clone()];
        let mut frontier = edges(start).to_vec();
        while let Some(m) = frontier.pop() {
            if &m == start {
                cycles.push(start.clone());
                break;
            }
            if !seen.contains(&m) {
                frontier.extend(edges(&m).iter().cloned());
                seen.push(m);
            }
        }
    }
    assert!(cycles.is_empty(), "modules on an import cycle: {cycles:#?}");
}
