//! `rodcube sweep`: separation angle and time over a grid or a list of points, on every core,
//! with the lean per-point solver ([`crate::solve::fast::lean::LeanSolver`]); more quantities per
//! point through the planner ([`planned`], which also sweeps any model's scalar results
//! alone: the Python package's engine); CSV out, and heat maps of a two-axis grid. Without
//! the feature `cli` (the feature `sweep` alone) the module holds the points, their axes and
//! [`planned`].
//!
//! Axes are named by the model's own parameters or by ratios of two of them
//! ([`crate::axes`]: `a_over_ell`, and `n` for `m2_over_m1`); every other parameter is fixed
//! (`--set`; no value is assumed: a parameter on no axis and not set is an error naming it). The
//! CSV's first line says how each parameter was set.

#[cfg(feature = "cli")]
pub mod heatmap;
pub mod planned;

use crate::axes::{AxisError, Mapping};
use crate::model::{Model, ModelInfo};
use crate::quantity::Quantity;
use crate::system::check_parameters;
use rayon::prelude::*;
use std::fmt::Write as _;
#[cfg(feature = "cli")]
use {
    crate::plan::{self, Request},
    crate::report::prose,
    crate::results::Note,
    crate::solve::fast::lean::{LeanPoint, LeanSolver},
    crate::solve::fast::sensitivity::SensitivityWork,
    indicatif::{ProgressBar, ProgressStyle},
    std::path::Path,
};

/// Points handed to one worker at a time (also the progress bar's step).
pub const CHUNK: usize = 2048;

/// Most points a sweep accepts.
pub const MAX_POINTS: usize = 100_000_000;

/// Why a sweep could not be set up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SweepError {
    /// An axis specification could not be read.
    #[error(
        "axis `{axis}` = {spec:?}: {reason} (expected START:STOP:lin|log:COUNT, a single value, or values separated by commas)"
    )]
    BadAxis {
        /// Which axis (`n`, `a_over_ell`, a parameter).
        axis: String,
        /// The text given.
        spec: String,
        /// What is wrong.
        reason: String,
    },
    /// The points file could not be read.
    #[error("{path}: {reason}")]
    Points {
        /// The file.
        path: String,
        /// What went wrong (with line numbers).
        reason: String,
    },
    /// An axis or a fixed value does not fit the model.
    #[error(transparent)]
    Axes(#[from] AxisError),
    /// A point whose parameters the model refuses.
    #[error("point {index} ({coordinates}): {reason}")]
    Point {
        /// 1-based index of the point (its line in a points file is given in `coordinates`).
        index: usize,
        /// The point's coordinates, `name = value` each.
        coordinates: String,
        /// Why the model refuses it.
        reason: String,
    },
    /// A wanted quantity that is not a scalar or not offered.
    #[error("{0}")]
    Want(String),
    /// A wanted name that is no quantity of the model.
    #[error(transparent)]
    UnknownQuantity(#[from] crate::quantity::UnknownQuantity),
    /// Neither a grid nor points, or both.
    #[error("{0}")]
    Layout(String),
    /// The model has no contact, so no separation.
    #[error("model `{model}` has no contact, so it has no separation to sweep")]
    NoContact {
        /// Model name.
        model: &'static str,
    },
}

/// Values along one axis of a grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The axis's name: a parameter or a ratio ([`crate::axes::resolve`]).
    pub name: String,
    /// The values, in the order given.
    pub values: Vec<f64>,
    /// Whether they are spaced logarithmically (for plotting).
    pub log: bool,
}

/// Reads `START:STOP:lin|log:COUNT`, a single value, or a comma-separated list.
pub fn parse_axis(axis: &str, spec: &str) -> Result<Axis, SweepError> {
    let bad = |reason: String| SweepError::BadAxis {
        axis: axis.to_string(),
        spec: spec.to_string(),
        reason,
    };
    let num = |s: &str| {
        s.trim()
            .parse::<f64>()
            .map_err(|_| bad(format!("{s:?} is not a number")))
    };
    let parts: Vec<&str> = spec.split(':').collect();
    match parts.as_slice() {
        [start, stop, kind, count] => {
            let (start, stop) = (num(start)?, num(stop)?);
            let count: usize = count
                .trim()
                .parse()
                .map_err(|_| bad(format!("{count:?} is not a count")))?;
            if count == 0 || count > MAX_POINTS {
                return Err(bad(format!("the count must be 1 to {MAX_POINTS}")));
            }
            if !(start.is_finite() && stop.is_finite()) {
                return Err(bad("the ends must be finite".into()));
            }
            let log = match kind.trim() {
                "lin" => false,
                "log" => true,
                other => return Err(bad(format!("spacing {other:?} is neither lin nor log"))),
            };
            if log && !(start > 0.0 && stop > 0.0) {
                return Err(bad("log spacing needs positive ends".into()));
            }
            let at = |i: usize| {
                if count == 1 || i == 0 {
                    return start;
                }
                if i == count - 1 {
                    return stop;
                }
                let f = i as f64 / (count - 1) as f64;
                if log {
                    (start.ln() + f * (stop.ln() - start.ln())).exp()
                } else {
                    start + f * (stop - start)
                }
            };
            Ok(Axis {
                name: axis.to_string(),
                values: (0..count).map(at).collect(),
                log,
            })
        }
        [_] => {
            let values = spec.split(',').map(num).collect::<Result<Vec<_>, _>>()?;
            Ok(Axis {
                name: axis.to_string(),
                values,
                log: false,
            })
        }
        _ => Err(bad("wrong number of `:` fields".into())),
    }
}

/// The points of a sweep: one coordinate per axis, point after point.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Points {
    /// The axes' names (parameters or ratios).
    pub names: Vec<String>,
    /// `names.len()` values per point, row after row.
    pub values: Vec<f64>,
    /// Where each point came from, for messages (`line 7` of a points file); empty for a grid.
    pub lines: Vec<usize>,
}

impl Points {
    /// The grid of all combinations, the first axis varying slowest.
    pub fn grid(axes: &[Axis]) -> Result<Points, SweepError> {
        let total = axes
            .iter()
            .try_fold(1usize, |n, a| n.checked_mul(a.values.len()))
            .filter(|&n| n <= MAX_POINTS)
            .ok_or_else(|| SweepError::Layout(format!("more than {MAX_POINTS} points")))?;
        let mut values = Vec::with_capacity(total * axes.len());
        for k in 0..total {
            let mut rest = k;
            let start = values.len();
            values.resize(start + axes.len(), 0.0);
            for (j, axis) in axes.iter().enumerate().rev() {
                let n = axis.values.len();
                values[start + j] = axis.values[rest % n];
                rest /= n;
            }
        }
        Ok(Points {
            names: axes.iter().map(|a| a.name.clone()).collect(),
            values,
            lines: Vec::new(),
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.values.len().checked_div(self.names.len()).unwrap_or(0)
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `k`'s coordinates.
    pub fn point(&self, k: usize) -> &[f64] {
        let d = self.names.len();
        &self.values[k * d..(k + 1) * d]
    }

    /// Point `k` for people: `n = 3, a_over_ell = 0.25` (and its line in a file).
    pub fn describe(&self, k: usize) -> String {
        let coordinates: Vec<String> = self
            .names
            .iter()
            .zip(self.point(k))
            .map(|(n, v)| format!("{n} = {v}"))
            .collect();
        match self.lines.get(k) {
            Some(line) => format!("line {line}: {}", coordinates.join(", ")),
            None => coordinates.join(", "),
        }
    }
}

/// Reads a CSV whose header names the axes: every column that is a parameter of the model or a
/// ratio of two ([`crate::axes::resolve`]) is one; other columns are ignored. Lines starting
/// with `#` are comments.
#[cfg(feature = "cli")]
pub fn read_points(path: &Path, info: &'static ModelInfo) -> Result<Points, SweepError> {
    let fail = |reason: String| SweepError::Points {
        path: path.display().to_string(),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = reader
        .headers()
        .map_err(|e| fail(format!("cannot read the header: {e}")))?
        .clone();
    let columns: Vec<(usize, &str)> = headers
        .iter()
        .enumerate()
        .filter(|(_, h)| crate::axes::resolve(h, info).is_ok())
        .collect();
    if columns.is_empty() {
        return Err(fail(format!(
            "no column names a parameter of `{}` or a ratio of two (the header has: {})",
            info.name,
            headers.iter().collect::<Vec<_>>().join(", ")
        )));
    }
    let mut points = Points {
        names: columns.iter().map(|(_, h)| h.to_string()).collect(),
        ..Points::default()
    };
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| fail(e.to_string()))?;
        let line = record.position().map_or(i + 2, |p| p.line() as usize);
        for &(c, name) in &columns {
            let s = record
                .get(c)
                .ok_or_else(|| fail(format!("line {line}: no `{name}` value")))?;
            let v = s
                .parse::<f64>()
                .map_err(|_| fail(format!("line {line}: `{name}` = {s:?} is not a number")))?;
            points.values.push(v);
        }
        points.lines.push(line);
        if points.lines.len() > MAX_POINTS {
            return Err(fail(format!("more than {MAX_POINTS} points")));
        }
    }
    if points.is_empty() {
        return Err(fail("no points".into()));
    }
    Ok(points)
}

/// Checks every point against the model's rules (the one validation,
/// [`check_parameters`]) before anything is solved: the first point refused is the error.
pub fn check(mapping: &Mapping, model: &dyn Model, points: &Points) -> Result<(), SweepError> {
    let info = model.info();
    let mut p = vec![0.0; info.parameters.len()];
    let mut margins = vec![0.0; info.requirements.len()];
    for k in 0..points.len() {
        mapping.fill(points.point(k), &mut p);
        if let Err(e) = check_parameters(model, &p, &mut margins) {
            return Err(SweepError::Point {
                index: k + 1,
                coordinates: points.describe(k),
                reason: e.to_string(),
            });
        }
    }
    Ok(())
}

/// The CSV's comment line: how each parameter was set, and the units.
pub fn header_comment(mapping: &Mapping) -> String {
    format!(
        "# rodcube sweep, model {}: {}; SI units of the parameters (times in s, angles in rad)",
        mapping.info().name,
        mapping.describe()
    )
}

/// The results of a sweep, one entry per point in the order given.
#[derive(Debug, Clone, Default)]
pub struct SweepResults {
    /// `theta_sep` (rad), NaN where the point failed.
    pub angle: Vec<f64>,
    /// `t_sep`, NaN where the point failed.
    pub time: Vec<f64>,
    /// Names of the extra columns.
    pub extra_names: Vec<String>,
    /// Extra values, `extra_names.len()` per point, row after row (NaN where missing).
    pub extra: Vec<f64>,
    /// Failed points: index and message.
    pub errors: Vec<(usize, String)>,
    /// Seconds spent solving.
    pub seconds: f64,
}

/// Resolves `--want` names to quantities computed through the planner, as
/// [`planned::wanted`] does (scalars only); the separation angle and time are always there.
pub fn parse_want(model: &dyn Model, names: &[String]) -> Result<Vec<Quantity>, SweepError> {
    let info = model.info();
    let mut out = Vec::new();
    for name in names {
        match Quantity::parse(name, info) {
            Ok(Quantity::SeparationAngle | Quantity::SeparationTime) => continue,
            Ok(Quantity::Sensitivities) => {
                return Err(SweepError::Want(
                    "`sensitivities` are columns of their own in a sweep: pass `--sensitivities`"
                        .into(),
                ));
            }
            _ => {}
        }
        for q in planned::wanted(model, std::slice::from_ref(name))?.quantities {
            if !out.contains(&q) {
                out.push(q);
            }
        }
    }
    Ok(out)
}

/// One chunk's angles, times, extra values and failures.
#[cfg(feature = "cli")]
type ChunkResult = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<(usize, String)>);

/// Solves every point in parallel (rayon), advancing `progress` per chunk.
#[cfg(feature = "cli")]
pub fn run(
    model: &'static dyn Model,
    mapping: &Mapping,
    points: &Points,
    extra: &[Quantity],
    tolerance: f64,
    progress: &ProgressBar,
) -> SweepResults {
    let start = std::time::Instant::now();
    let np = model.info().parameters.len();
    let dims = points.names.len().max(1);
    // `sensitivities` are columns of their own, after the planner's.
    let sens = extra.contains(&Quantity::Sensitivities);
    let extra: Vec<Quantity> = (extra.iter().copied())
        .filter(|q| *q != Quantity::Sensitivities)
        .collect();
    // The extra columns: the quantities' scalar results, whatever the points.
    let want = planned::Wanted::of(model.info(), &extra);
    let settings = planned::Settings {
        tolerance,
        until: None,
    };
    let mut extra_names: Vec<String> = want.columns.iter().map(|c| c.key.clone()).collect();
    let ne = extra_names.len();
    let sens_names = if sens {
        sensitivity_columns(model.info())
    } else {
        Vec::new()
    };
    let ns = sens_names.len();
    let chunks: Vec<ChunkResult> = points
        .values
        .par_chunks(CHUNK * dims)
        .enumerate()
        .map(|(c, chunk)| {
            let mut solver = LeanSolver::new(model).ok();
            let mut p = vec![0.0; np];
            let (mut angle, mut time) = (
                Vec::with_capacity(chunk.len() / dims),
                Vec::with_capacity(chunk.len() / dims),
            );
            let mut values = Vec::with_capacity(chunk.len() / dims * (ne + ns));
            let mut errors = Vec::new();
            let mut work = SensitivityWork::default();
            for (i, point) in chunk.chunks(dims).enumerate() {
                let index = c * CHUNK + i;
                mapping.fill(point, &mut p);
                let (a, t, lean) = match solver.as_mut() {
                    Some(s) => s
                        .solve(&p)
                        .map(|r| (r.separation_angle, r.separation_time, Some(r)))
                        .map_err(|e| e.to_string()),
                    None => separation_by_planner(model, &p, tolerance).map(|(a, t)| (a, t, None)),
                }
                .unwrap_or_else(|e| {
                    errors.push((index, e));
                    (f64::NAN, f64::NAN, None)
                });
                angle.push(a);
                time.push(t);
                if ne > 0 {
                    let before = values.len();
                    values.resize(before + ne, f64::NAN);
                    let row = &mut values[before..];
                    if let Err(e) = planned::solve_point(model, &p, &want, settings, row) {
                        errors.push((index, e));
                    }
                }
                if sens {
                    let row = Row {
                        model,
                        p: &p,
                        tolerance,
                    };
                    let before = values.len();
                    let outcome = match (solver.as_mut(), &lean) {
                        (Some(s), Some(point)) => row.lean(s, point, &mut work, &mut values),
                        (Some(_), None) => Err(String::new()),
                        (None, _) => row.planned(&sens_names, &mut values),
                    };
                    values.resize(before + ns, f64::NAN);
                    if let Err(e) = outcome.map_err(|e| e.to_string())
                        && !e.is_empty()
                    {
                        errors.push((index, e));
                    }
                }
            }
            progress.inc((chunk.len() / dims) as u64);
            (angle, time, values, errors)
        })
        .collect();
    extra_names.extend(sens_names);
    let mut out = SweepResults {
        extra_names,
        ..SweepResults::default()
    };
    for (a, t, v, e) in chunks {
        out.angle.extend(a);
        out.time.extend(t);
        out.extra.extend(v);
        out.errors.extend(e);
    }
    out.errors.sort_by_key(|e| e.0);
    out.errors.dedup_by_key(|e| e.0);
    out.seconds = start.elapsed().as_secs_f64();
    out
}

/// The columns of `--sensitivities`: `d(<result>)/d(<p>)` of the separation angle and time,
/// then their elasticities, for every parameter in the model's order.
pub fn sensitivity_columns(info: &ModelInfo) -> Vec<String> {
    let mut out = Vec::new();
    for of in ["separation_angle", "separation_time"] {
        out.extend((info.parameters.iter()).map(|p| format!("d({of})/d({})", p.name)));
    }
    for of in ["separation_angle", "separation_time"] {
        out.extend((info.parameters.iter()).map(|p| format!("elasticity({of};{})", p.name)));
    }
    out
}

/// One point's sensitivities for the sweep.
#[cfg(feature = "cli")]
struct Row<'a> {
    model: &'static dyn Model,
    p: &'a [f64],
    tolerance: f64,
}

#[cfg(feature = "cli")]
impl Row<'_> {
    /// The columns of [`sensitivity_columns`] from the per-point solver's point: appended to
    /// `values` (none where there are no sensitivities, and the message why).
    fn lean(
        &self,
        solver: &mut LeanSolver,
        point: &LeanPoint,
        work: &mut SensitivityWork,
        values: &mut Vec<f64>,
    ) -> Result<(), String> {
        let np = self.p.len();
        let (mut angle, mut time) = (vec![0.0; np], vec![0.0; np]);
        match solver.sensitivities(self.p, point, work, &mut angle, &mut time) {
            Ok(Ok(())) => {}
            Ok(Err(gap)) => return Err(prose::note(&Note::NoSensitivity(gap))),
            Err(e) => return Err(e.to_string()),
        }
        let (theta, t) = (point.separation_angle, point.separation_time);
        values.extend(angle.iter().chain(&time));
        values.extend(self.p.iter().zip(&angle).map(|(x, d)| x / theta * d));
        values.extend(self.p.iter().zip(&time).map(|(x, d)| x / t * d));
        Ok(())
    }

    /// The columns of [`sensitivity_columns`] (`names`) through the planner, for a model the
    /// per-point solver does not take.
    fn planned(&self, names: &[String], values: &mut Vec<f64>) -> Result<(), String> {
        let want = [
            Quantity::SeparationAngle,
            Quantity::SeparationTime,
            Quantity::Sensitivities,
        ];
        let request = Request::new(self.model, self.p.to_vec())
            .with_want(&want)
            .with_tolerance(self.tolerance);
        let res = plan::run(&request).map_err(|e| e.to_string())?;
        values
            .extend((names.iter()).map(|k| res.sensitivities.get(k).map_or(f64::NAN, |s| s.value)));
        match res
            .notes
            .iter()
            .find(|(k, _)| k.starts_with("sensitivities."))
        {
            Some((_, n)) => Err(prose::note(n)),
            None => Ok(()),
        }
    }
}

/// The separation angle and time through the planner, for a model the per-point solver does
/// not take (no polynomial separation condition, several coordinates): slower, but any model
/// with a contact. A point without a separation is an error saying why.
#[cfg(feature = "cli")]
fn separation_by_planner(
    model: &'static dyn Model,
    p: &[f64],
    tolerance: f64,
) -> Result<(f64, f64), String> {
    let want = [Quantity::SeparationAngle, Quantity::SeparationTime];
    let request = Request::new(model, p.to_vec())
        .with_want(&want)
        .with_tolerance(tolerance);
    let res = plan::run(&request).map_err(|e| e.to_string())?;
    match (res.separation_angle(), res.separation_time()) {
        (Some(a), Some(t)) => Ok((a, t)),
        _ => Err(res
            .notes
            .values()
            .next()
            .map(prose::note)
            .unwrap_or_else(|| "no separation".into())),
    }
}

/// A progress bar on stderr for `len` points (drawn only when stderr is a terminal).
#[cfg(feature = "cli")]
pub fn progress_bar(len: usize) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} [{elapsed_precise}] {wide_bar} {human_pos}/{human_len} points (eta {eta})",
    ) {
        bar.set_style(style);
    }
    bar
}

/// The CSV text: the comment line, the header (the axes' names, then
/// `separation_angle,separation_time` and the extra quantities), then one row per point in
/// shortest round-trip scientific notation; a failed value is empty.
pub fn to_csv(mapping: &Mapping, points: &Points, results: &SweepResults) -> String {
    let mut header = points.names.join(",");
    header.push_str(",separation_angle,separation_time");
    for name in &results.extra_names {
        header.push(',');
        header.push_str(name);
    }
    let ne = results.extra_names.len();
    let dims = points.names.len().max(1);
    let rows: Vec<String> = points
        .values
        .par_chunks(CHUNK * dims)
        .enumerate()
        .map(|(c, chunk)| {
            let mut s = String::with_capacity(chunk.len() / dims * 96);
            for (i, point) in chunk.chunks(dims).enumerate() {
                let k = c * CHUNK + i;
                for v in point {
                    cell(&mut s, *v);
                    s.push(',');
                }
                cell(&mut s, results.angle[k]);
                s.push(',');
                cell(&mut s, results.time[k]);
                for j in 0..ne {
                    s.push(',');
                    cell(&mut s, results.extra[k * ne + j]);
                }
                s.push('\n');
            }
            s
        })
        .collect();
    let mut out = String::with_capacity(rows.iter().map(String::len).sum::<usize>() + 512);
    out.push_str(&header_comment(mapping));
    out.push('\n');
    out.push_str(&header);
    out.push('\n');
    for r in rows {
        out.push_str(&r);
    }
    out
}

/// One CSV value: shortest round-trip scientific notation, empty when not finite.
fn cell(s: &mut String, v: f64) {
    if v.is_finite() {
        let _ = write!(s, "{v:e}");
    }
}

/// A heat map SVG of `values` over a two-axis grid (`values[i * x.len() + j]` at `y[i]`,
/// `x[j]`).
#[cfg(feature = "cli")]
pub fn heatmap_svg(
    title: &str,
    unit: &str,
    y: &Axis,
    x: &Axis,
    values: &[f64],
) -> Result<String, heatmap::HeatmapError> {
    heatmap::svg(title, unit, y, x, values)
}
