//! `rodcube sweep`: separation angle and time over a grid of `(n, a/ell)` or a list of points,
//! on every core, with the lean per-point solver ([`LeanSolver`]); more quantities per point
//! through the planner; CSV out, and heat maps of a grid.
//!
//! Parameters map as `m1 = 1`, `m2 = n`, `ell`, `a = a_over_ell * ell`, `g` with `ell = g = 1`
//! unless given, so results are dimensionless (times in units of `sqrt(ell/g)`); the CSV's
//! first line says which. A model without `m2` (the wall ladder) refuses `n`.

pub mod heatmap;

use crate::model::Model;
use crate::plan::{self, Request};
use crate::quantity::Quantity;
use crate::solve::lean::LeanSolver;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// Points handed to one worker at a time (also the progress bar's step).
pub const CHUNK: usize = 2048;

/// Most points a sweep accepts.
pub const MAX_POINTS: usize = 100_000_000;

/// Why a sweep could not be set up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SweepError {
    /// An axis specification could not be read.
    #[error(
        "--{axis} {spec:?}: {reason} (expected START:STOP:lin|log:COUNT, a single value, or values separated by commas)"
    )]
    BadAxis {
        /// Which axis (`n` or `a-over-ell`).
        axis: &'static str,
        /// The text given.
        spec: String,
        /// What is wrong.
        reason: String,
    },
    /// A value outside its domain.
    #[error("{what} = {value} is outside {domain}")]
    OutOfDomain {
        /// Which value (with its line for a points file).
        what: String,
        /// The value.
        value: f64,
        /// The allowed range.
        domain: &'static str,
    },
    /// The points file could not be read.
    #[error("{path}: {reason}")]
    Points {
        /// The file.
        path: String,
        /// What went wrong (with line numbers).
        reason: String,
    },
    /// The model's parameters are not `m1, m2, ell, a, g` (or a subset with `a` and `ell`).
    #[error(
        "model `{model}` cannot be swept over n and a/ell: its parameters are {params} (a sweep sets m1 = 1, m2 = n, ell, a = a_over_ell * ell, g)"
    )]
    NotSweepable {
        /// Model name.
        model: &'static str,
        /// Its parameters.
        params: String,
    },
    /// `n` given to a model without a second mass.
    #[error(
        "model `{model}` has no mass ratio (no parameter m2), so n does not apply; drop --n (or the n column)"
    )]
    NoMassRatio {
        /// Model name.
        model: &'static str,
    },
    /// `n` missing for a model with a second mass.
    #[error("model `{model}` needs the mass ratio n = m2/m1: give --n (or an n column)")]
    NeedsMassRatio {
        /// Model name.
        model: &'static str,
    },
    /// A wanted quantity that is not a scalar or not offered.
    #[error("{0}")]
    Want(String),
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
    /// The values, in the order given.
    pub values: Vec<f64>,
    /// Whether they are spaced logarithmically (for plotting).
    pub log: bool,
}

/// Reads `START:STOP:lin|log:COUNT`, a single value, or a comma-separated list.
pub fn parse_axis(axis: &'static str, spec: &str) -> Result<Axis, SweepError> {
    let bad = |reason: String| SweepError::BadAxis {
        axis,
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
                values: (0..count).map(at).collect(),
                log,
            })
        }
        [_] => {
            let values = spec.split(',').map(num).collect::<Result<Vec<_>, _>>()?;
            Ok(Axis { values, log: false })
        }
        _ => Err(bad("wrong number of `:` fields".into())),
    }
}

/// One point of a sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Mass ratio `m2/m1` (ignored, and NaN, for a model without `m2`).
    pub n: f64,
    /// `a/ell`.
    pub a_over_ell: f64,
}

/// Reads a CSV with a header naming `a_over_ell` and (for a model with `m2`) `n`; other
/// columns are ignored. Lines starting with `#` are comments.
pub fn read_points(path: &Path) -> Result<(Vec<Point>, bool), SweepError> {
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
    let col = |name: &str| headers.iter().position(|h| h == name);
    let r_col = col("a_over_ell").ok_or_else(|| {
        fail(format!(
            "no `a_over_ell` column (the header has: {})",
            headers.iter().collect::<Vec<_>>().join(", ")
        ))
    })?;
    let n_col = col("n");
    let mut points = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| fail(e.to_string()))?;
        let line = record.position().map_or(i + 2, |p| p.line() as usize);
        let field = |c: usize, name: &str| -> Result<f64, SweepError> {
            let s = record
                .get(c)
                .ok_or_else(|| fail(format!("line {line}: no `{name}` value")))?;
            s.parse::<f64>()
                .map_err(|_| fail(format!("line {line}: `{name}` = {s:?} is not a number")))
        };
        let a_over_ell = field(r_col, "a_over_ell")?;
        let n = match n_col {
            Some(c) => field(c, "n")?,
            None => f64::NAN,
        };
        points.push(Point { n, a_over_ell });
        if points.len() > MAX_POINTS {
            return Err(fail(format!("more than {MAX_POINTS} points")));
        }
    }
    if points.is_empty() {
        return Err(fail("no points".into()));
    }
    Ok((points, n_col.is_some()))
}

/// How a sweep's model parameters are formed from a point.
#[derive(Clone)]
pub struct Mapping {
    /// The model.
    pub model: &'static dyn Model,
    /// Index of `m2`, if the model has it.
    pub m2: Option<usize>,
    /// Index of `a`.
    pub a: usize,
    /// The parameter vector with everything but `m2` and `a` filled in.
    pub template: Vec<f64>,
    /// `ell` used.
    pub ell: f64,
    /// `g` used.
    pub g: f64,
    /// Whether `ell` and `g` are both 1 (the default: dimensionless results).
    pub dimensionless: bool,
}

impl std::fmt::Debug for Mapping {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mapping")
            .field("model", &self.model.info().name)
            .field("template", &self.template)
            .finish()
    }
}

impl Mapping {
    /// The mapping for a model, with `ell` and `g` (default 1).
    pub fn new(
        model: &'static dyn Model,
        ell: Option<f64>,
        g: Option<f64>,
    ) -> Result<Mapping, SweepError> {
        let info = model.info();
        if info.contact.is_none() {
            return Err(SweepError::NoContact { model: info.name });
        }
        let not = || SweepError::NotSweepable {
            model: info.name,
            params: info
                .parameters
                .iter()
                .map(|p| p.name)
                .collect::<Vec<_>>()
                .join(", "),
        };
        let (ell_v, g_v) = (ell.unwrap_or(1.0), g.unwrap_or(1.0));
        for (what, v) in [("--ell", ell_v), ("--g", g_v)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(SweepError::OutOfDomain {
                    what: what.into(),
                    value: v,
                    domain: "(0, infinity)",
                });
            }
        }
        let mut template = vec![0.0; info.parameters.len()];
        let (mut m2, mut a, mut has_ell) = (None, None, false);
        for (i, p) in info.parameters.iter().enumerate() {
            match p.name {
                "m1" => template[i] = 1.0,
                "m2" => m2 = Some(i),
                "ell" => {
                    template[i] = ell_v;
                    has_ell = true;
                }
                "a" => a = Some(i),
                "g" => template[i] = g_v,
                _ => return Err(not()),
            }
        }
        let a = match (a, has_ell) {
            (Some(a), true) => a,
            _ => return Err(not()),
        };
        Ok(Mapping {
            model,
            m2,
            a,
            template,
            ell: ell_v,
            g: g_v,
            dimensionless: ell.is_none() && g.is_none(),
        })
    }

    /// Fills `p` (the template's length) for a point.
    pub fn fill(&self, point: &Point, p: &mut [f64]) {
        p.copy_from_slice(&self.template);
        if let Some(i) = self.m2 {
            p[i] = point.n;
        }
        p[self.a] = point.a_over_ell * self.ell;
    }

    /// Checks that the points fit the model: `n` present (and positive) exactly when the model
    /// has `m2`, `a/ell` in `(0, 1)`. `has_n` says whether the input gave `n` at all.
    pub fn check(&self, points: &[Point], has_n: bool) -> Result<(), SweepError> {
        let name = self.model.info().name;
        match (self.m2.is_some(), has_n) {
            (true, false) => return Err(SweepError::NeedsMassRatio { model: name }),
            (false, true) => return Err(SweepError::NoMassRatio { model: name }),
            _ => {}
        }
        for (i, p) in points.iter().enumerate() {
            if !(p.a_over_ell > 0.0 && p.a_over_ell < 1.0) {
                return Err(SweepError::OutOfDomain {
                    what: format!(
                        "point {} a_over_ell (a >= ell: the rod stands upright or cannot lean)",
                        i + 1
                    ),
                    value: p.a_over_ell,
                    domain: "(0, 1)",
                });
            }
            if self.m2.is_some() && !(p.n > 0.0 && p.n.is_finite()) {
                return Err(SweepError::OutOfDomain {
                    what: format!("point {} n", i + 1),
                    value: p.n,
                    domain: "(0, infinity)",
                });
            }
        }
        Ok(())
    }

    /// The CSV's comment line: the mapping and the units.
    pub fn header_comment(&self) -> String {
        let name = self.model.info().name;
        let m2 = if self.m2.is_some() {
            "m2 = n, "
        } else {
            "(no m2: n does not apply), "
        };
        if self.dimensionless {
            format!(
                "# rodcube sweep, model {name}: m1 = 1, {m2}a = a_over_ell * ell, ell = 1, g = 1; dimensionless results: times in units of sqrt(ell/g), angles in rad"
            )
        } else {
            format!(
                "# rodcube sweep, model {name}: m1 = 1 kg, {m2}a = a_over_ell * ell, ell = {} m, g = {} m/s^2; SI units: times in s, angles in rad",
                self.ell, self.g
            )
        }
    }
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

/// Resolves `--want` names to quantities computed through the planner (scalars only; the
/// separation angle and time are always there).
pub fn parse_want(model: &dyn Model, names: &[String]) -> Result<Vec<Quantity>, SweepError> {
    let info = model.info();
    let mut out = Vec::new();
    for name in names {
        let q = Quantity::parse(name, info).map_err(SweepError::Want)?;
        match q {
            Quantity::SeparationAngle | Quantity::SeparationTime => {}
            Quantity::LinearisedSeparationAngle
            | Quantity::ContactTimeToFloor
            | Quantity::PointMassFallTime
            | Quantity::FloorImpact
            | Quantity::CrossCheck => {
                if !q.available(info) {
                    return Err(SweepError::Want(format!(
                        "model `{}` cannot provide `{name}`",
                        info.name
                    )));
                }
                if !out.contains(&q) {
                    out.push(q);
                }
            }
            _ => {
                return Err(SweepError::Want(format!(
                    "`{name}` is a series or a set of checks, not a number per point; a sweep takes scalar quantities (linearised_separation_angle, contact_time_to_floor, point_mass_fall_time, floor_impact, cross_check)"
                )));
            }
        }
    }
    Ok(out)
}

/// One chunk's angles, times, extra values and failures.
type ChunkResult = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<(usize, String)>);

/// Solves every point in parallel (rayon), advancing `progress` per chunk.
pub fn run(
    mapping: &Mapping,
    points: &[Point],
    extra: &[Quantity],
    tolerance: f64,
    progress: &ProgressBar,
) -> SweepResults {
    let start = std::time::Instant::now();
    let model = mapping.model;
    let np = mapping.template.len();
    // The extra columns' names, from the first point the planner solves.
    let mut extra_names: Vec<String> = Vec::new();
    if !extra.is_empty() {
        let mut p = vec![0.0; np];
        for point in points.iter().take(16) {
            mapping.fill(point, &mut p);
            let request = Request::new(model, p.clone())
                .with_want(extra)
                .with_tolerance(tolerance);
            if let Ok(res) = plan::run(&request) {
                extra_names = res.results.keys().cloned().collect();
                break;
            }
        }
    }
    let ne = extra_names.len();
    let chunks: Vec<ChunkResult> = points
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut solver = LeanSolver::new(model).ok();
            let mut p = vec![0.0; np];
            let (mut angle, mut time) = (
                Vec::with_capacity(chunk.len()),
                Vec::with_capacity(chunk.len()),
            );
            let mut values = Vec::with_capacity(chunk.len() * ne);
            let mut errors = Vec::new();
            for (i, point) in chunk.iter().enumerate() {
                let index = c * CHUNK + i;
                mapping.fill(point, &mut p);
                match solver.as_mut().map(|s| s.solve(&p)) {
                    Some(Ok(r)) => {
                        angle.push(r.separation_angle);
                        time.push(r.separation_time);
                    }
                    Some(Err(e)) => {
                        angle.push(f64::NAN);
                        time.push(f64::NAN);
                        errors.push((index, e.to_string()));
                    }
                    None => {
                        angle.push(f64::NAN);
                        time.push(f64::NAN);
                        errors.push((index, "the lean solver does not apply to this model".into()));
                    }
                }
                if ne > 0 {
                    let request = Request::new(model, p.clone())
                        .with_want(extra)
                        .with_tolerance(tolerance);
                    match plan::run(&request) {
                        Ok(res) => values.extend(
                            extra_names
                                .iter()
                                .map(|k| res.results.get(k).map_or(f64::NAN, |s| s.value)),
                        ),
                        Err(e) => {
                            values.extend(std::iter::repeat_n(f64::NAN, ne));
                            errors.push((index, e.to_string()));
                        }
                    }
                }
            }
            progress.inc(chunk.len() as u64);
            (angle, time, values, errors)
        })
        .collect();
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

/// A progress bar on stderr for `len` points (drawn only when stderr is a terminal).
pub fn progress_bar(len: usize) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} [{elapsed_precise}] {wide_bar} {human_pos}/{human_len} points (eta {eta})",
    ) {
        bar.set_style(style);
    }
    bar
}

/// The CSV text: the comment line, the header
/// `n,a_over_ell,separation_angle,separation_time[,extra...]` (no `n` for a model without `m2`),
/// then one row per point in shortest round-trip scientific notation; a failed value is empty.
pub fn to_csv(mapping: &Mapping, points: &[Point], results: &SweepResults) -> String {
    let with_n = mapping.m2.is_some();
    let mut header = String::new();
    if with_n {
        header.push_str("n,");
    }
    header.push_str("a_over_ell,separation_angle,separation_time");
    for name in &results.extra_names {
        header.push(',');
        header.push_str(name);
    }
    let ne = results.extra_names.len();
    let rows: Vec<String> = points
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut s = String::with_capacity(chunk.len() * 96);
            for (i, point) in chunk.iter().enumerate() {
                let k = c * CHUNK + i;
                if with_n {
                    cell(&mut s, point.n);
                    s.push(',');
                }
                cell(&mut s, point.a_over_ell);
                s.push(',');
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
    out.push_str(&mapping.header_comment());
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

/// A heat map SVG of `values` over a grid (`values[i * a.len() + j]` at `n[i]`, `a_over_ell[j]`).
pub fn heatmap_svg(
    title: &str,
    unit: &str,
    n: &Axis,
    a_over_ell: &Axis,
    values: &[f64],
) -> Result<String, String> {
    heatmap::svg(title, unit, n, a_over_ell, values)
}
