//! Reports of a run: the human table, results.json, one CSV per series, `impacts.csv` when the
//! run wanted impacts, SVG plots and the animated motion (`motion.svg`).
//!
//! Every writer here is a pure function from `RunResults` to text; only `write_all` touches
//! the file system, through `OutDir` (atomic writes, checked names). Only [`json`], [`prose`] and
//! [`motion`] (the animation computed from [`crate::results::Drawing`], then hand-written SVG
//! text, no dependency) are built without the `cli` feature (the C ABI returns results.json).
//!
//! `impacts.csv` (`csv::impacts`) has one row per contact taking part in each impact:
//! `time [s]`, `contact`, `closing` (`true` for the contact whose gap closed),
//! `normal_velocity_before`, `normal_velocity_after`, `velocity_unit`, `impulse`,
//! `impulse_unit` (the units in their own columns, as they may differ from contact to
//! contact), `tangential_impulse` (its friction's, in the impulse's unit), `energy_lost [J]`,
//! `normal_energy_lost [J]` and `friction_energy_lost [J]` (the impact's, on each of its rows)
//! and `zeno_limit` (`true` for the impact that closed a converging sequence of bounces).

#[cfg(feature = "cli")]
mod checks;
#[cfg(feature = "cli")]
pub mod csv;
pub mod json;
#[cfg(feature = "cli")]
mod layout;
pub mod motion;
#[cfg(feature = "cli")]
pub mod plot;
pub mod prose;
#[cfg(feature = "cli")]
mod sequence;
#[cfg(feature = "cli")]
pub mod table;
mod touch;

#[cfg(feature = "cli")]
use crate::io::OutDir;
#[cfg(feature = "cli")]
use crate::results::RunResults;
#[cfg(feature = "cli")]
use std::path::PathBuf;

/// Name of the JSON file written beside the series.
pub const RESULTS_JSON: &str = "results.json";
/// Name of the animation of the bodies' motion ([`motion::svg`]).
pub const MOTION_SVG: &str = "motion.svg";
/// Name of the table of impacts (`csv::impacts`), written when the run wanted them.
pub const IMPACTS_CSV: &str = "impacts.csv";

/// Why a report could not be produced or written.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Writing a file failed or its name was refused.
    #[error(transparent)]
    Io(#[from] crate::io::Error),
    /// JSON serialization failed.
    #[error("cannot serialize the results to JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// A series whose columns differ in length.
    #[error("series `{series}`: column `{column}` has {len} values but `{first}` has {expected}")]
    Ragged {
        /// Series name.
        series: String,
        /// The first column.
        first: String,
        /// Its length.
        expected: usize,
        /// The offending column.
        column: String,
        /// Its length.
        len: usize,
    },
    /// CSV encoding failed.
    #[error("cannot write `{series}` as CSV: {message}")]
    Csv {
        /// The series' name, or `impacts` for [`IMPACTS_CSV`].
        series: String,
        /// What went wrong.
        message: String,
    },
    /// Drawing a plot failed.
    #[error("cannot plot series `{series}`: {message}")]
    Plot {
        /// Series name.
        series: String,
        /// What went wrong.
        message: String,
    },
}

/// Writes `results.json`, `<series>.csv` for every series and `<series>.svg` for every series
/// that can be plotted, then `impacts.csv` when the run has impacts ([`RunResults::impacts`]:
/// it wanted them; a header alone when there were none), then `motion.svg` when it has the
/// bodies' drawing ([`RunResults::drawing`]: it wanted a trajectory). Returns the paths written,
/// in that order.
#[cfg(feature = "cli")]
pub fn write_all(out: &OutDir, results: &RunResults) -> Result<Vec<PathBuf>, Error> {
    let mut written = vec![out.write(RESULTS_JSON, json::to_string(results)?.as_bytes())?];
    for (name, series) in &results.series {
        written.push(out.write(
            &format!("{name}.csv"),
            csv::to_string(name, series)?.as_bytes(),
        )?);
        if let Some(svg) = plot::svg(name, series, &results.model)? {
            written.push(out.write(&format!("{name}.svg"), svg.as_bytes())?);
        }
    }
    if let Some(impacts) = &results.impacts {
        written.push(out.write(IMPACTS_CSV, csv::impacts(impacts)?.as_bytes())?);
    }
    if let Some(drawing) = &results.drawing {
        let animation = motion::Animation::build(drawing);
        written.push(out.write(MOTION_SVG, motion::svg(&animation).as_bytes())?);
    }
    Ok(written)
}
