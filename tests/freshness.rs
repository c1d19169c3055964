//! `generated/` is what `rodcube derive` makes of `derivations/` and `templates/` today (the
//! check compares, it never writes), and regenerating is deterministic: byte-identical twice.
#![cfg(feature = "derive")]

use rodcube::derive::{Options, render_all, run};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn generated_files_are_up_to_date() {
    let outcome = run(&Options {
        root: root(),
        specs: vec![],
        check: true,
        force: false,
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        outcome.stale.is_empty(),
        "stale generated files {:?}: run `{}`",
        outcome.stale,
        rodcube::derive::emit::COMMAND
    );
    assert!(
        outcome.written.is_empty(),
        "check mode wrote {:?}",
        outcome.written
    );
    // Every model of every spec (its general model and the fast phases that reduce, as the
    // compiled registry lists them) gives .rs, .tex, .json and .tape.json, plus the registry
    // and the digest manifest; every spec gives its general model.
    let specs = rodcube::derive::spec_files(&root()).unwrap();
    let models = rodcube::models::all();
    for spec in &specs {
        let name = spec.file_stem().and_then(|s| s.to_str()).unwrap();
        assert!(
            models
                .iter()
                .any(|m| m.info().name == name && m.info().is_general()),
            "no general model for {}",
            spec.display()
        );
    }
    let phases = models.len();
    assert_eq!(outcome.unchanged.len(), 4 * phases + 2);
    assert!(
        outcome
            .unchanged
            .contains(&PathBuf::from("generated/mod.rs"))
    );
}

#[test]
fn deriving_one_spec_gives_the_same_bytes_as_deriving_all() {
    // Symbolica orders terms by when the process first defined each symbol; the tool declares
    // every spec's symbols in one order first, so a partial derive matches the full one.
    for spec in rodcube::derive::spec_files(&root()).unwrap() {
        let outcome = run(&Options {
            root: root(),
            specs: vec![spec.clone()],
            check: true,
            force: false,
        })
        .unwrap_or_else(|e| panic!("{e}"));
        assert!(
            outcome.stale.is_empty(),
            "deriving {} alone would change {:?}",
            spec.display(),
            outcome.stale
        );
    }
}

#[test]
fn regeneration_is_deterministic() {
    let (first, _) = render_all(&root(), &[]).unwrap_or_else(|e| panic!("{e}"));
    let (second, _) = render_all(&root(), &[]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(first.len(), second.len());
    for (a, b) in first.iter().zip(&second) {
        assert_eq!(a.path, b.path);
        assert!(
            a.text == b.text,
            "{} differs between two renders",
            a.path.display()
        );
    }
    // Every generated file names its source and says not to edit it.
    for f in &first {
        let head: String = f.text.lines().take(3).collect::<Vec<_>>().join("\n");
        let json = f.path.extension() == Some("json".as_ref());
        assert!(
            json || head.contains("do not edit by hand"),
            "{} has no do-not-edit header:\n{head}",
            f.path.display()
        );
        assert!(Path::new(&f.path).starts_with("generated"));
    }
}

#[test]
fn a_stale_file_is_reported_and_not_rewritten() {
    // A copy of the project with one generated file altered: the check finds it, leaves it.
    let dir = project_copy("check");
    let victim = dir.join("generated/wall_ladder.tex");
    let altered = std::fs::read_to_string(&victim).unwrap() + "% edited by hand\n";
    std::fs::write(&victim, &altered).unwrap();
    let outcome = run(&Options {
        root: dir.clone(),
        specs: vec![],
        check: true,
        force: false,
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        outcome
            .stale
            .contains(&PathBuf::from("generated/wall_ladder.tex")),
        "{:?}",
        outcome.stale
    );
    assert!(outcome.written.is_empty());
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), altered);
    let _ = std::fs::remove_dir_all(&dir);
}

fn project_copy(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rodcube-freshness-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for sub in ["derivations", "templates", "generated"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        for entry in std::fs::read_dir(root().join(sub)).unwrap() {
            let p = entry.unwrap().path();
            std::fs::copy(&p, dir.join(sub).join(p.file_name().unwrap())).unwrap();
        }
    }
    dir
}

#[test]
fn a_hand_edited_file_is_not_overwritten_without_force() {
    let dir = project_copy("force");
    let victim = dir.join("generated/wall_ladder.rs");
    let altered = std::fs::read_to_string(&victim).unwrap() + "// my precious edit\n";
    std::fs::write(&victim, &altered).unwrap();
    // The spec changes, so regenerating would rewrite the edited file: refused, nothing written.
    let spec = dir.join("derivations/wall_ladder.yaml");
    let text = std::fs::read_to_string(&spec).unwrap();
    std::fs::write(
        &spec,
        text.replace("sliding down a fixed", "sliding down a rigid"),
    )
    .unwrap();
    let opts = Options {
        root: dir.clone(),
        specs: vec![],
        check: false,
        force: false,
    };
    let err = run(&opts).expect_err("a hand-edited file must not be overwritten");
    let message = err.to_string();
    assert!(
        message.contains("generated/wall_ladder.rs") && message.contains("--force"),
        "{message}"
    );
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), altered);
    let tex = std::fs::read_to_string(dir.join("generated/wall_ladder.tex")).unwrap();
    assert!(
        tex.contains("fixed"),
        "nothing may be written when one file is refused"
    );
    // With --force the tool regenerates everything and the project is fresh again.
    run(&Options {
        force: true,
        ..opts.clone()
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        !std::fs::read_to_string(&victim)
            .unwrap()
            .contains("my precious edit")
    );
    let again = run(&Options {
        check: true,
        ..opts
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(again.stale.is_empty(), "{:?}", again.stale);
    let _ = std::fs::remove_dir_all(&dir);
}
