//! Harnesses shared by the fuzz targets (`fuzz/fuzz_targets/`) and their regression test
//! (`tests/fuzz_regressions.rs`): each feeds arbitrary bytes to one text parser and uses the
//! result the way the command line would, so a panic anywhere on that path is a finding.

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
