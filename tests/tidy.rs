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
