//! `rodcube derive` writes `generated/` all or nothing: a failed derivation or a failed write
//! leaves every file as it was, a partial derive names only generated models in the registry
//! and rewrites the manifest, and `io::write_all_atomic` (the transaction behind it) restores
//! what it replaced. Every test works on a copy of the project in a temporary directory.
#![cfg(feature = "derive")]

use rodcube::derive::{Error, MANIFEST, Options, digest, run};
use rodcube::io::write_all_atomic;
use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty directory for one test, outside the repository.
fn fresh(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "rodcube-derive-atomic-{tag}-{}",
        std::process::id()
    ));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// A copy of the project's `derivations/`, `templates/` and `generated/`.
fn project_copy(tag: &str) -> PathBuf {
    let dir = fresh(tag);
    for sub in ["derivations", "templates", "generated"] {
        fs::create_dir_all(dir.join(sub)).unwrap();
        for entry in fs::read_dir(root().join(sub)).unwrap() {
            let p = entry.unwrap().path();
            fs::copy(&p, dir.join(sub).join(p.file_name().unwrap())).unwrap();
        }
    }
    dir
}

/// A copy of the project whose `generated/` this process has just regenerated in full.
///
/// Symbolica orders the terms of a sum by the order in which its symbols were first defined in
/// the process, so a spec derived alone (or after other tests' derivations) can print
/// equivalent expressions in another order than a fresh full run does. Once a full run has
/// defined every symbol, later derivations in the process print alike; regenerating the copy
/// first makes the byte comparisons below independent of what this process derived before.
fn regenerated_copy(tag: &str) -> PathBuf {
    let dir = project_copy(tag);
    run(&Options {
        force: true,
        ..options(&dir, vec![])
    })
    .unwrap_or_else(|e| panic!("{e}"));
    dir
}

/// `derivations/wall_ladder.yaml` as a model `broken_model` whose contact gap is not linear in
/// the coordinate it eliminates (`wall_x - x1^2/ell - ...`): the spec parses and is checked, but its
/// derivation fails (as in tests/bad_specs.rs).
fn add_broken_spec(dir: &Path) -> PathBuf {
    let text = fs::read_to_string(root().join("derivations/wall_ladder.yaml")).unwrap();
    let replace_once = |text: String, old: &str, new: &str| {
        assert_eq!(text.matches(old).count(), 1, "`{old}` in wall_ladder.yaml");
        text.replace(old, new)
    };
    let text = replace_once(text, "name: wall_ladder\n", "name: broken_model\n");
    let text = replace_once(
        text,
        "gap: wall_x - x1 - ell*cos(theta)",
        "gap: wall_x - x1^2/ell - ell*cos(theta)",
    );
    let path = dir.join("derivations/broken_model.yaml");
    fs::write(&path, text).unwrap();
    if let Err(e) = rodcube::derive::spec::load(&path) {
        panic!("the broken spec must pass the checks and fail only to derive: {e}");
    }
    path
}

/// Every entry under `dir` (recursively, hidden ones included): relative path → contents, or
/// `None` for a directory.
fn snapshot(dir: &Path) -> BTreeMap<String, Option<Vec<u8>>> {
    fn walk(base: &Path, dir: &Path, out: &mut BTreeMap<String, Option<Vec<u8>>>) {
        for entry in fs::read_dir(dir).unwrap() {
            let p = entry.unwrap().path();
            let rel = p.strip_prefix(base).unwrap().display().to_string();
            if p.is_dir() {
                out.insert(rel, None);
                walk(base, &p, out);
            } else {
                out.insert(rel, Some(fs::read(&p).unwrap()));
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// Asserts that two snapshots hold the same entries with the same bytes, naming the first
/// difference.
fn assert_same(
    before: &BTreeMap<String, Option<Vec<u8>>>,
    after: &BTreeMap<String, Option<Vec<u8>>>,
) {
    let names = |s: &BTreeMap<String, Option<Vec<u8>>>| s.keys().cloned().collect::<Vec<_>>();
    assert_eq!(names(before), names(after), "entries of generated/ changed");
    for (name, old) in before {
        assert!(old == &after[name], "generated/{name} changed");
    }
}

fn options(dir: &Path, specs: Vec<PathBuf>) -> Options {
    Options {
        root: dir.to_path_buf(),
        specs,
        check: false,
        force: false,
    }
}

/// Removes the outputs of the models `models` and their manifest rows, as if they had never
/// been generated (the registry still names them).
fn forget_models(dir: &Path, models: &[&str]) {
    let mut manifest = String::new();
    for line in fs::read_to_string(dir.join(MANIFEST)).unwrap().lines() {
        let forgotten = models.iter().any(|m| {
            ["rs", "tex", "json"]
                .iter()
                .any(|ext| line.ends_with(&format!("  generated/{m}.{ext}")))
        });
        if !forgotten {
            manifest.push_str(line);
            manifest.push('\n');
        }
    }
    fs::write(dir.join(MANIFEST), manifest).unwrap();
    for m in models {
        for ext in ["rs", "tex", "json"] {
            fs::remove_file(dir.join(format!("generated/{m}.{ext}"))).unwrap();
        }
    }
}

#[test]
fn a_failed_derivation_leaves_generated_untouched() {
    let dir = project_copy("failed_full");
    let broken = add_broken_spec(&dir);
    // A stale file a successful run would rewrite.
    let tex = dir.join("generated/wall_ladder.tex");
    let stale = fs::read_to_string(&tex).unwrap() + "% stale\n";
    fs::write(&tex, &stale).unwrap();
    let before = snapshot(&dir.join("generated"));
    for force in [false, true] {
        let err = run(&Options {
            force,
            ..options(&dir, vec![])
        })
        .expect_err("a spec that cannot be derived must fail the run");
        match &err {
            Error::Spec(e) => {
                assert_eq!(e.file, broken, "{err}");
                assert_eq!(e.field, "contacts[0].gap", "{err}");
            }
            other => panic!("expected the broken spec's error, got {other}"),
        }
        assert_same(&before, &snapshot(&dir.join("generated")));
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_partial_derive_of_a_fresh_project_changes_nothing() {
    // With every model recorded in the manifest, deriving one spec gives the registry and the
    // manifest of the full run, byte for byte.
    let dir = regenerated_copy("partial_fresh");
    let before = snapshot(&dir.join("generated"));
    let spec = dir.join("derivations/wall_ladder.yaml");
    let outcome = run(&options(&dir, vec![spec])).unwrap_or_else(|e| panic!("{e}"));
    assert!(outcome.written.is_empty(), "{:?}", outcome.written);
    for f in ["generated/mod.rs", MANIFEST, "generated/wall_ladder.rs"] {
        assert!(outcome.unchanged.contains(&PathBuf::from(f)), "{f}");
    }
    assert_same(&before, &snapshot(&dir.join("generated")));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_partial_derive_names_only_generated_models_and_rewrites_the_manifest() {
    let dir = regenerated_copy("partial");
    let full = snapshot(&dir.join("generated"));
    add_broken_spec(&dir);
    // hinged_rod has a spec but no outputs any more; wall_ladder is about to be generated.
    forget_models(
        &dir,
        &[
            "hinged_rod",
            "hinged_rod_closed",
            "hinged_rod_free",
            "wall_ladder",
            "wall_ladder_closed",
            "wall_ladder_free",
        ],
    );
    let spec = dir.join("derivations/wall_ladder.yaml");
    let opts = options(&dir, vec![spec]);
    let outcome = run(&opts).unwrap_or_else(|e| panic!("{e}"));
    for f in ["generated/wall_ladder.rs", "generated/mod.rs", MANIFEST] {
        assert!(
            outcome.written.contains(&PathBuf::from(f)),
            "{f} not in {:?}",
            outcome.written
        );
    }
    // The model files are those of the full run.
    for m in ["wall_ladder", "wall_ladder_closed", "wall_ladder_free"] {
        for ext in ["rs", "tex", "json"] {
            let name = format!("{m}.{ext}");
            let written = fs::read(dir.join("generated").join(&name)).unwrap();
            assert!(Some(written) == full[&name], "generated/{name}");
        }
    }
    // The registry names the models whose files exist, and nothing else.
    let registry = fs::read_to_string(dir.join("generated/mod.rs")).unwrap();
    assert!(!registry.contains("broken_model"), "{registry}");
    for m in ["hinged_rod", "hinged_rod_closed", "hinged_rod_free"] {
        assert!(!registry.contains(&format!("pub mod {m};")), "{registry}");
    }
    for m in [
        "wall_ladder",
        "wall_ladder_closed",
        "wall_ladder_free",
        "rod_cube",
        "loaded_rod",
        "hinged_rod_spring",
    ] {
        assert!(
            registry.contains(&format!("pub mod {m};")),
            "{m}:\n{registry}"
        );
    }
    for line in registry.lines() {
        if let Some(m) = line
            .strip_prefix("pub mod ")
            .and_then(|l| l.strip_suffix(';'))
        {
            assert!(dir.join(format!("generated/{m}.rs")).is_file(), "{m}");
        }
    }
    // The manifest: the full run's rows without hinged_rod's, the registry's new digest.
    let mut expected = String::new();
    let full_manifest = full["manifest.txt"].clone().unwrap_or_default();
    for line in String::from_utf8(full_manifest).unwrap().lines() {
        let forgotten = ["hinged_rod", "hinged_rod_closed", "hinged_rod_free"]
            .iter()
            .any(|m| {
                ["rs", "tex", "json"]
                    .iter()
                    .any(|e| line.ends_with(&format!("generated/{m}.{e}")))
            });
        if forgotten {
            continue;
        }
        if line.ends_with("  generated/mod.rs") {
            expected.push_str(&format!("{}  generated/mod.rs\n", digest(&registry)));
        } else {
            expected.push_str(line);
            expected.push('\n');
        }
    }
    assert_eq!(fs::read_to_string(dir.join(MANIFEST)).unwrap(), expected);
    // So the next run does not take the new registry for a hand edit, and nothing is stale.
    let again = run(&opts).unwrap_or_else(|e| panic!("the next run failed: {e}"));
    assert!(again.written.is_empty(), "{:?}", again.written);
    let check = run(&Options {
        check: true,
        ..opts.clone()
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(check.stale.is_empty(), "{:?}", check.stale);
    for f in ["generated/wall_ladder.rs", "generated/mod.rs", MANIFEST] {
        assert!(check.unchanged.contains(&PathBuf::from(f)), "{f}");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_failed_rename_restores_the_files_already_replaced() {
    // Two stale files are written first; then the rename over a directory standing in for a
    // later output fails, and the two must get their old contents back.
    for victim in ["wall_ladder.json", "mod.rs"] {
        let dir = project_copy(&format!("rename_{}", victim.replace('.', "_")));
        for name in ["wall_ladder.rs", "wall_ladder.tex"] {
            let path = dir.join("generated").join(name);
            let stale = fs::read_to_string(&path).unwrap() + "\n// stale\n";
            fs::write(&path, stale).unwrap();
        }
        let blocked = dir.join("generated").join(victim);
        fs::remove_file(&blocked).unwrap();
        fs::create_dir(&blocked).unwrap();
        fs::write(blocked.join("inside"), "keep").unwrap();
        let before = snapshot(&dir.join("generated"));
        let spec = dir.join("derivations/wall_ladder.yaml");
        let err = run(&Options {
            force: true,
            ..options(&dir, vec![spec])
        })
        .expect_err("the rename over a directory must fail");
        match &err {
            Error::Io { path, .. } => assert_eq!(path, &blocked, "{err}"),
            other => panic!("expected a write error, got {other}"),
        }
        assert_same(&before, &snapshot(&dir.join("generated")));
        let _ = fs::remove_dir_all(&dir);
    }
}

#[test]
fn write_all_atomic_writes_every_file() {
    let dir = fresh("io_all");
    fs::write(dir.join("a"), "old a").unwrap();
    write_all_atomic(&[(dir.join("a"), "new a"), (dir.join("b"), "new b")])
        .unwrap_or_else(|e| panic!("{e}"));
    let after = snapshot(&dir);
    assert_eq!(after.len(), 2, "{:?}", after.keys());
    assert_eq!(after["a"].as_deref(), Some(&b"new a"[..]));
    assert_eq!(after["b"].as_deref(), Some(&b"new b"[..]));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn write_all_atomic_touches_nothing_when_a_file_cannot_be_staged() {
    let dir = fresh("io_stage");
    fs::write(dir.join("a"), "old a").unwrap();
    let before = snapshot(&dir);
    // The second target's directory does not exist: its temporary file cannot be created.
    let missing = dir.join("no_such_dir").join("b");
    let err = write_all_atomic(&[(dir.join("a"), "new a"), (missing.clone(), "new b")])
        .expect_err("a target in a missing directory");
    match &err {
        rodcube::io::Error::Write { path, .. } => assert_eq!(path, &missing, "{err}"),
        other => panic!("expected a write error, got {other}"),
    }
    assert_same(&before, &snapshot(&dir));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn write_all_atomic_restores_after_a_failed_rename() {
    let dir = fresh("io_rename");
    fs::write(dir.join("a"), "old a").unwrap();
    fs::create_dir(dir.join("taken")).unwrap();
    fs::write(dir.join("taken").join("inside"), "keep").unwrap();
    let before = snapshot(&dir);
    // `a` is replaced and `new` created before the rename over the directory fails; both are
    // undone, and the last temporary file is removed.
    let err = write_all_atomic(&[
        (dir.join("a"), "new a"),
        (dir.join("new"), "new file"),
        (dir.join("taken"), "never"),
        (dir.join("z"), "never either"),
    ])
    .expect_err("a rename over a directory");
    match &err {
        rodcube::io::Error::Write { path, .. } => assert_eq!(path, &dir.join("taken"), "{err}"),
        other => panic!("expected a write error, got {other}"),
    }
    assert_same(&before, &snapshot(&dir));
    let _ = fs::remove_dir_all(&dir);
}
