//! Build script of the Python bindings: embeds every model's derivation (`generated/<model>.tex`
//! and `generated/<model>.json`, as the derivation tool wrote them) in the extension, so that
//! `rodcube.derivation(model)` works from an installed wheel without the source tree. Writes
//! `$OUT_DIR/derivations.rs`: `DERIVATIONS`, `(model, tex, json)` sorted by model name.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR")?);
    let generated = manifest.join("../generated");
    println!("cargo:rerun-if-changed={}", generated.display());
    let mut models: Vec<String> = Vec::new();
    for entry in std::fs::read_dir(&generated)? {
        let path = entry?.path();
        if path.extension().and_then(|e| e.to_str()) == Some("tex")
            && let Some(stem) = path.file_stem().and_then(|s| s.to_str())
        {
            models.push(stem.to_string());
        }
    }
    models.sort();
    let mut out = String::from(
        "/// Every model's derivation: `(model, LaTeX write-up, JSON record)`, by model name.\n\
         pub static DERIVATIONS: &[(&str, &str, &str)] = &[\n",
    );
    for model in &models {
        let tex = existing(&generated.join(format!("{model}.tex")))?;
        let json = existing(&generated.join(format!("{model}.json")))?;
        println!("cargo:rerun-if-changed={tex}");
        println!("cargo:rerun-if-changed={json}");
        writeln!(
            out,
            "    ({model:?}, include_str!({tex:?}), include_str!({json:?})),"
        )?;
    }
    out.push_str("];\n");
    let dest = PathBuf::from(std::env::var("OUT_DIR")?).join("derivations.rs");
    std::fs::write(dest, out)?;
    Ok(())
}

/// The path of a file that must exist, as text for `include_str!`.
fn existing(path: &Path) -> Result<String, Box<dyn std::error::Error>> {
    let path = path
        .canonicalize()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let text = path.to_str().ok_or("a path that is not UTF-8")?;
    Ok(text.to_string())
}
