//! Every phase of the specs in a folder, derived in-process (through the one Symbolica worker).

use rodcube::derive::mechanics::Derivation;
use rodcube::derive::{derive_all, spec};
use std::path::Path;

/// Every phase of the specs in `dir` (under the crate's root), in the order of their files.
/// Call it off the Symbolica worker: `derive_all` queues its own job there.
pub fn phases_in(dir: &str) -> Vec<Derivation> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    paths.sort();
    let checked: Vec<_> = (paths.iter())
        .map(|p| spec::load(p).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    derive_all(&checked)
        .unwrap_or_else(|e| panic!("{e}"))
        .into_iter()
        .flat_map(|(phases, _)| phases)
        .collect()
}
