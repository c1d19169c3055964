//! The printed report fits a terminal: with `COLUMNS=100` (or piped, without it) no line of
//! `rodcube run` or `rodcube models` is longer than 100 characters, for every shipped scene;
//! `--wide` lifts the limit and `--verbose` adds the meanings; checks come phase by phase in
//! the order the phases happen; numbers never carry an `e0`; the paper's figures and equation
//! numbers appear only on the paper's case. A run of 92 bounces prints under 200 lines within
//! the width (its phases with repeats counted, its checks that passed at their worst, its
//! impacts' ends), and `--verbose` still prints everything.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `rodcube` with `COLUMNS` set to `columns` (or unset), stdout piped; returns stdout.
fn rodcube(args: &[&str], columns: Option<&str>) -> String {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_rodcube"));
    cmd.args(args);
    match columns {
        Some(c) => cmd.env("COLUMNS", c),
        None => cmd.env_remove("COLUMNS"),
    };
    let out = cmd.output().expect("run rodcube");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

fn out_dir(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_layout")
        .join(name)
}

fn scenes() -> Vec<PathBuf> {
    let mut all: Vec<PathBuf> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
            .collect();
    all.sort();
    all
}

/// The longest line, in characters (not bytes: the tables' borders are multi-byte).
fn widest(text: &str) -> (usize, &str) {
    text.lines()
        .map(|l| (l.chars().count(), l))
        .max_by_key(|(n, _)| *n)
        .unwrap_or((0, ""))
}

#[test]
fn every_scene_fits_100_columns_plain_and_verbose() {
    for scene in scenes() {
        let stem = scene.file_stem().unwrap().to_str().unwrap().to_string();
        let dir = out_dir(&stem);
        let path = scene.to_str().unwrap();
        let out = dir.to_str().unwrap();
        for (columns, verbose) in [(Some("100"), false), (None, false), (Some("100"), true)] {
            let mut args = vec!["run", path, "--out", out];
            if verbose {
                args.push("--verbose");
            }
            let text = rodcube(&args, columns);
            let (n, line) = widest(&text);
            assert!(
                n <= 100,
                "{stem} {args:?}: a line of {n} characters:\n{line}"
            );
            assert!(
                !text.contains("e0 ") && !text.contains("e0\n"),
                "{stem}: an `e0` exponent in\n{text}"
            );
        }
    }
}

#[test]
fn narrow_terminals_and_wide_output() {
    let dir = out_dir("paper-width");
    let out = dir.to_str().unwrap();
    let text = rodcube(&["run", "--out", out, "--verbose"], Some("80"));
    assert!(widest(&text).0 <= 80, "{}", widest(&text).1);
    // --wide: nothing is wrapped, so the verbose legend's long meanings run past 100.
    let wide = rodcube(&["run", "--out", out, "--verbose", "--wide"], Some("100"));
    assert!(widest(&wide).0 > 100, "--wide still wrapped:\n{wide}");
}

#[test]
fn the_models_listing_fits_100_columns() {
    let text = rodcube(&["models"], Some("100"));
    let (n, line) = widest(&text);
    assert!(n <= 100, "{n} characters:\n{line}");
    // The paper's equation numbers belong to the paper's case, not to every model's list.
    assert!(!text.contains("eq. ("), "{text}");
}

#[test]
fn meanings_go_to_the_verbose_legend() {
    let dir = out_dir("paper-verbose");
    let out = dir.to_str().unwrap();
    let plain = rodcube(&["run", "--out", out], Some("100"));
    let verbose = rodcube(&["run", "--out", out, "--verbose"], Some("100"));
    let meaning = "is conserved by construction on the reduced path";
    assert!(!plain.contains(meaning), "{plain}");
    assert!(plain.contains("rodcube run --verbose"), "{plain}");
    // Wrapped, so the sentence may break across lines: compare without line breaks.
    let flat: String = verbose
        .lines()
        .map(|l| l.trim_matches(|c: char| c == '│' || c.is_whitespace()))
        .collect::<Vec<_>>()
        .join(" ");
    assert!(flat.contains("conserved by construction"), "{verbose}");
}

#[test]
fn checks_come_phase_by_phase_with_their_own_units_and_bounds() {
    let dir = out_dir("paper-checks");
    let text = rodcube(&["run", "--out", dir.to_str().unwrap()], Some("100"));
    let at = |needle: &str| {
        text.find(needle)
            .unwrap_or_else(|| panic!("no {needle:?} in\n{text}"))
    };
    // The contact phase, its ODE cross-check, then the free phase.
    assert!(at("\nrod_cube_closed:\n") < at("\nrod_cube (ODE cross-check):\n"));
    assert!(at("\nrod_cube (ODE cross-check):\n") < at("\nrod_cube_free:\n"));
    // A monitor reports its smallest value with its unit and when; a conservation law on the
    // reduced path says it holds by construction; the integrated one, its drift and bound.
    // The floor's push is smallest at the separation, m1 g / 4 = 9.81/4 N
    // (docs/hand_derivations.md, section D).
    assert!(text.contains("min 2.4525 N"), "{text}");
    assert!(text.contains("(built in)"), "{text}");
    assert!(text.contains("<= 1e-12"), "{text}");
}

#[test]
fn other_models_get_no_paper_figures_or_floor_wording() {
    let dir = out_dir("ladder-words");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/ladder.yaml");
    let text = rodcube(
        &[
            "run",
            scene.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
            "--verbose",
        ],
        None,
    );
    for word in ["paper", "eq.", "rod lies"] {
        assert!(!text.contains(word), "{word:?} in\n{text}");
    }
}

/// The paper's rod carried through its bounces (`scenes/bounce.yaml` with restitution 0.9,
/// followed until the bounces converge): 92 impacts and 94 phases.
const MANY_BOUNCES: &str = "model: rod_cube_liftoff
parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81, e: 0.9}
want: [floor_impact, impacts, theta_series, checks]
tolerance: 1.0e-12
until: 12.0
";

#[test]
fn a_run_of_many_bounces_fits_and_verbose_still_has_everything() {
    let dir = out_dir("many-bounces");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.yaml");
    std::fs::write(&scene, MANY_BOUNCES).unwrap();
    let (scene, out) = (scene.to_str().unwrap(), dir.join("out"));
    let out = out.to_str().unwrap();
    let plain = rodcube(&["run", scene, "--out", out], Some("100"));
    // What the run did, from results.json (the JSON keeps everything).
    let json: serde_json::Value =
        serde_json::from_str(&rodcube(&["run", scene, "--out", out, "--json"], None)).unwrap();
    let phases: Vec<&str> = (json["work"]["phases"].as_array().unwrap().iter())
        .map(|p| p.as_str().unwrap())
        .collect();
    let impacts = json["results"]["impacts"]["value"].as_array().unwrap();
    let checks = json["checks"].as_object().unwrap();
    assert!(
        impacts.len() > 50 && phases.len() == impacts.len() + 2,
        "{phases:?}"
    );
    assert_eq!(checks.len(), 659, "the JSON's checks, every one");

    assert!(
        plain.lines().count() < 200,
        "{} lines:\n{plain}",
        plain.lines().count()
    );
    let (n, line) = widest(&plain);
    assert!(n <= 100, "a line of {n} characters:\n{line}");
    // The phases with their repeats counted: the bounces between the first and the last.
    let bouncing = phases[1];
    assert!(phases[1..phases.len() - 1].iter().all(|p| *p == bouncing));
    let flat: String = (plain.lines())
        .map(|l| l.trim_matches(|c: char| c == '│' || c == '┆' || c.is_whitespace()))
        .collect::<Vec<_>>()
        .join(" ");
    let counted = format!("{bouncing} ×{}", phases.len() - 2);
    assert!(flat.contains(&counted), "no {counted:?} in\n{plain}");
    // Impacts: units in the header, the first and last five, and how many are left out.
    assert!(
        plain.contains(&format!("Impacts ({})", impacts.len())),
        "{plain}"
    );
    assert!(
        plain.contains("v before (m/s)") && plain.contains("impulse (N s)"),
        "{plain}"
    );
    let time =
        |i: &serde_json::Value| rodcube::results::format_number(i["time"].as_f64().unwrap(), 6);
    // An impact's row: its time in the first cell.
    let listed = |text: &str, i: &serde_json::Value| {
        let first = |l: &str| (l.split('┆').next()).map(|c| c.trim_matches(['│', ' ']).to_string());
        text.lines().any(|l| first(l) == Some(time(i)))
    };
    let shown = impacts.iter().filter(|i| listed(&plain, i)).count();
    assert_eq!(shown, 10, "{plain}");
    assert!(listed(&plain, &impacts[0]) && listed(&plain, &impacts[impacts.len() - 1]));
    assert!(
        plain.contains(&format!("… {} more", impacts.len() - 10)),
        "{plain}"
    );
    // Checks: one table of the passes, each check at its worst, with where.
    assert!(
        plain.contains(&format!(
            "Checks (659 passed, 0 failed) in {} phases and {} impacts",
            phases.len(),
            impacts.len()
        )),
        "{plain}"
    );
    assert!(
        flat.contains(&format!("{} impacts", impacts.len())),
        "{plain}"
    );
    assert!(
        flat.contains(&format!("{} phases", phases.len())),
        "{plain}"
    );
    let names: std::collections::BTreeSet<&str> = checks
        .keys()
        .map(|k| k.rsplit('.').next().unwrap())
        .collect();
    for name in &names {
        assert!(
            plain.contains(&format!("│ {name} ")),
            "no row for {name}:\n{plain}"
        );
    }
    assert!(!plain.contains("phase by phase\n"), "{plain}");

    // --wide: one line per row; the phases' is as short as its summary (the widest line is
    // the Zeno note's sentence, some 450 characters).
    let wide = rodcube(&["run", scene, "--out", out, "--wide"], Some("100"));
    let work = (wide.lines().find(|l| l.contains(&counted))).expect("the phases' line");
    assert!(work.chars().count() < 200, "{work}");
    assert!(widest(&wide).0 < 600, "{}", widest(&wide).1);

    // --verbose: every phase and impact its own table of checks, every impact listed, every
    // phase named.
    let verbose = rodcube(&["run", scene, "--out", out, "--verbose"], Some("100"));
    assert!(widest(&verbose).0 <= 100, "{}", widest(&verbose).1);
    assert!(verbose.contains("phase by phase\n"));
    for (key, check) in checks {
        let title = format!("\n{}:\n", check["phase"].as_str().unwrap());
        assert!(
            verbose.contains(&title),
            "no table of {key}'s phase {title}"
        );
    }
    let tables = verbose.matches("\nimpact ").count();
    assert_eq!(tables, impacts.len(), "the impacts' tables of checks");
    assert!(
        impacts.iter().all(|i| listed(&verbose, i)),
        "an impact missing:\n{verbose}"
    );
    let named = phases.iter().filter(|p| **p == bouncing).count();
    let verbose_flat: String = (verbose.lines())
        .map(|l| l.trim_matches(|c: char| c == '│' || c == '┆' || c.is_whitespace()))
        .collect::<Vec<_>>()
        .join(" ");
    assert!(verbose_flat.matches(bouncing).count() >= named, "{verbose}");
}
