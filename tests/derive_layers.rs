//! The derivation tool's modules read in order: each file of `src/derive/` (and of
//! `src/derive/emit/`) imports only modules listed before it below, so the stages run one way
//! (spec → setup → Lagrangian → equations → constraints → reduction → forces → presentation →
//! emit) and no two modules import each other. Reads the source only; needs no Symbolica.

use std::fs;
use std::path::Path;

/// `src/derive/`'s modules bottom-up: the shared helpers, the stages in order, their runner,
/// the presentation, the emission, and `mod` (the tool itself) on top. `spec` and `expr` are the
/// runtime's, re-exported, below them all.
const DERIVE: &[&str] = &[
    "spec",
    "expr",
    "types",
    "cas",
    "algebra",
    "positivity",
    "read",
    "setup",
    "lagrangian",
    "equations",
    "constraints",
    "reduction",
    "partials",
    "forces",
    "tangents",
    "mechanics",
    "present",
    "steps",
    "dimensionless",
    "emit",
    "mod",
];

/// `src/derive/emit/`'s modules bottom-up: the helpers below the writers, the parts of the Rust
/// writer, the writers, and `mod` (the re-exports) on top.
const EMIT: &[&str] = &[
    "latex",
    "lower",
    "method",
    "common",
    "code",
    "info",
    "docs",
    "reduced",
    "constants",
    "state",
    "tangents",
    "rust",
    "tex",
    "json",
    "tape",
    "mod",
];

/// Every module a file's code (not its comments, not its unit tests) names through `super::`
/// or `crate::derive::`, as (layer, module): layer `false` for `src/derive/`, `true` for
/// `src/derive/emit/`.
fn imports(text: &str, in_emit: bool) -> Vec<(bool, String)> {
    let code = text.split("#[cfg(test)]").next().unwrap_or_default();
    let mut out = Vec::new();
    for line in code.lines().filter(|l| !l.trim_start().starts_with("//")) {
        for (prefix, emit_level) in [("crate::derive::emit::", true), ("crate::derive::", false)]
            .into_iter()
            .chain([("super::", in_emit)])
        {
            let mut rest = line;
            while let Some(at) = rest.find(prefix) {
                let after = &rest[at + prefix.len()..];
                let before = &rest[..at];
                rest = after;
                // `crate::derive::emit::x` is matched by its own prefix; `crate::derive::` and
                // `super::` only where they start the path.
                if before.ends_with("crate::derive::") || before.ends_with("::") {
                    continue;
                }
                let name: String = after
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if prefix == "crate::derive::" && name == "emit" && after.starts_with("emit::") {
                    continue;
                }
                if !name.is_empty() {
                    out.push((emit_level, name));
                }
            }
        }
    }
    out
}

/// The offences of one file: every import of a module not listed before it.
fn offences(dir: &str, layer: &[&str], in_emit: bool) -> Vec<String> {
    let mut bad = Vec::new();
    let mut entries: Vec<_> = fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(dir))
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .collect();
    entries.sort();
    for path in entries {
        let module = path.file_stem().unwrap_or_default().to_string_lossy();
        let Some(rank) = layer.iter().position(|m| *m == module) else {
            bad.push(format!(
                "{dir}/{module}.rs is not in this test's list of layers"
            ));
            continue;
        };
        let text = fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
        for (emit_level, name) in imports(&text, in_emit) {
            let ok = match (in_emit, emit_level) {
                // A module of emit/ may use any of derive/ below emit.
                (true, false) => (DERIVE.iter().position(|m| *m == name))
                    .is_some_and(|r| DERIVE[r..].contains(&"emit") && DERIVE[r] != "emit"),
                (false, true) => module == "mod",
                (_, _) => layer
                    .iter()
                    .position(|m| *m == name)
                    .is_some_and(|r| r < rank),
            };
            if !ok {
                bad.push(format!(
                    "{dir}/{module}.rs imports `{name}`, which is not below it"
                ));
            }
        }
    }
    bad
}

#[test]
fn derive_modules_import_only_earlier_ones() {
    let mut bad = offences("src/derive", DERIVE, false);
    bad.extend(offences("src/derive/emit", EMIT, true));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
