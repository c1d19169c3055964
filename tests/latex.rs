//! Every generated derivation (`generated/*.tex`) compiles with pdflatex, and no equation runs
//! visibly off the page. Needs `pdflatex` (Debian: `apt-get install texlive-latex-base`).

use std::path::{Path, PathBuf};
use std::process::Command;

/// An overfull line wider than this (in points) runs into the margin for all to see.
const OVERFULL_LIMIT_PT: f64 = 10.0;

fn generated_tex() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "tex"))
        .collect();
    files.sort();
    files
}

/// The last `n` lines of a text.
fn tail(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// Widths (pt) of the overfull boxes pdflatex reported.
fn overfull_widths(log: &str) -> Vec<(f64, String)> {
    log.lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("Overfull \\hbox (")?;
            let (pt, _) = rest.split_once("pt too wide")?;
            Some((pt.parse().ok()?, l.to_string()))
        })
        .collect()
}

#[test]
fn generated_latex_compiles() {
    let files = generated_tex();
    assert!(!files.is_empty(), "no generated/*.tex to compile");
    let out_root = std::env::temp_dir().join(format!("rodcube-latex-{}", std::process::id()));
    let mut failures = Vec::new();
    for tex in &files {
        let stem = tex
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let out = out_root.join(&stem);
        std::fs::create_dir_all(&out).unwrap_or_else(|e| panic!("{}: {e}", out.display()));
        let run = Command::new("pdflatex")
            .arg("-interaction=nonstopmode")
            .arg("-halt-on-error")
            .arg("-no-shell-escape")
            .arg(format!("-output-directory={}", out.display()))
            .arg(tex)
            .current_dir(&out)
            .output();
        let output = match run {
            Ok(o) => o,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => panic!(
                "pdflatex is not installed; it is needed to check generated/*.tex \
                 (Debian/Ubuntu: `apt-get install -y texlive-latex-base`)"
            ),
            Err(e) => panic!("cannot run pdflatex: {e}"),
        };
        let log = std::fs::read_to_string(out.join(format!("{stem}.log")))
            .unwrap_or_else(|_| String::from_utf8_lossy(&output.stdout).into_owned());
        if !output.status.success() || !out.join(format!("{stem}.pdf")).is_file() {
            failures.push(format!(
                "{} does not compile ({}); end of the log:\n{}",
                tex.display(),
                output.status,
                tail(&log, 30)
            ));
            continue;
        }
        for (pt, line) in overfull_widths(&log) {
            if pt > OVERFULL_LIMIT_PT {
                failures.push(format!(
                    "{}: a line runs {pt} pt into the margin (limit {OVERFULL_LIMIT_PT} pt): {line}",
                    tex.display()
                ));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&out_root);
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
