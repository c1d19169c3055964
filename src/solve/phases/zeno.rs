//! Converging (Zeno) sequences of impacts: the bounces of one contact, or the strikes of two
//! contacts in turn (a block rocking from corner to corner), whose intervals shrink
//! geometrically. Their limit (the accumulation time) is summed as a geometric series over the
//! sequence's period, from its times or from its last impact's velocities, and differentiated
//! in the parameters from its last times' derivatives.

use super::motion::ImpactAt;

/// Intervals that shrink by a steady ratio (the last [`ZENO_RATIOS`] ratios below one and
/// within this fraction of each other) converge: once the time left to their limit is within
/// the run's tolerance of the time from release, the rest of them is summed as a geometric
/// series: one plastic impact, listed at their limit.
pub const ZENO_RATIO_SPREAD: f64 = 0.1;

/// How many successive ratios (each interval over the one two before it) must agree before
/// impacts count as converging.
pub const ZENO_RATIOS: usize = 3;

/// How closely (relative to the time left) the series summed from a sequence's last four times
/// must agree with the accumulation time found from its last impact's velocities for the
/// former's derivatives to stand for the latter's.
pub const ZENO_AGREE: f64 = 1e-6;

/// The trailing impacts of a motion that form one sequence, with the impact at `t`: each
/// closed by the same contact as the impact two after it (one contact bouncing, or two in
/// turn).
#[derive(Debug, Clone, PartialEq)]
pub struct Sequence {
    /// The impacts' indices in the motion's list (the impact at `t`, not listed yet, is not
    /// among them).
    pub listed: Vec<usize>,
    /// Their times (s from release), then `t`.
    pub times: Vec<f64>,
    /// The contacts that close in it, each once, in order of index.
    pub contacts: Vec<usize>,
}

/// The sequence that the impact of contact `closing` at `t` ends, after `impacts`.
pub fn sequence(impacts: &[ImpactAt], closing: usize, t: f64) -> Sequence {
    let closings: Vec<usize> = (impacts.iter().map(|i| i.closing))
        .chain([closing])
        .collect();
    let n = closings.len();
    let first = (0..n)
        .rev()
        .take_while(|&i| i + 2 >= n || closings[i] == closings[i + 2])
        .last()
        .unwrap_or(n - 1);
    let listed: Vec<usize> = (first..n - 1).collect();
    let times = (listed.iter().map(|&i| impacts[i].t)).chain([t]).collect();
    let mut contacts = closings[first..].to_vec();
    contacts.sort_unstable();
    contacts.dedup();
    Sequence {
        listed,
        times,
        contacts,
    }
}

/// The limit of the last four `times` of a sequence whose every interval is `rho` times the
/// one two before it (a period of one interval or two): `t_n + (dt_{n-1} + dt_n) rho / (1 -
/// rho)`, with `rho`. `None` with fewer than four times or a ratio not in `(0, 1)`.
pub fn extrapolate(times: &[f64]) -> Option<(f64, f64)> {
    let [t0, t1, t2, t3] = *times.last_chunk::<4>()?;
    let rho = (t3 - t2) / (t1 - t0);
    let inside = rho > 0.0 && rho < 1.0;
    inside.then(|| (t3 + (t3 - t1) * rho / (1.0 - rho), rho))
}

/// The derivatives of [`extrapolate`]'s limit in every parameter, from those of its four times
/// (`d[i][j] = d t_i / d p_j`, the times in order).
pub fn extrapolate_derivatives(times: &[f64], d: [&[f64]; 4]) -> Option<Vec<f64>> {
    let [t0, t1, t2, t3] = *times.last_chunk::<4>()?;
    let (a, b) = (t3 - t2, t1 - t0);
    let rho = a / b;
    let span = t3 - t1;
    let np = d[3].len();
    if d.iter().any(|di| di.len() != np) {
        return None;
    }
    Some(
        (0..np)
            .map(|j| {
                let (d0, d1, d2, d3) = (d[0][j], d[1][j], d[2][j], d[3][j]);
                let d_rho = ((d3 - d2) * b - a * (d1 - d0)) / (b * b);
                d3 + (d3 - d1) * rho / (1.0 - rho) + span * d_rho / ((1.0 - rho) * (1.0 - rho))
            })
            .collect(),
    )
}

/// Where the sequence ended by the impact of contact `closing` at `t` converges: its last
/// [`ZENO_RATIOS`] ratios (each interval over the one two before) below one and agreeing
/// within [`ZENO_RATIO_SPREAD`], and the time left to their limit within `tol` of `t`.
pub fn limit(impacts: &[ImpactAt], closing: usize, t: f64, tol: f64) -> Option<Limit> {
    let seq = sequence(impacts, closing, t);
    let times = &seq.times;
    if times.len() < ZENO_RATIOS + 3 {
        return None;
    }
    let dt: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    let ratios: Vec<f64> = dt.windows(3).map(|w| w[2] / w[0]).collect();
    let recent = &ratios[ratios.len() - ZENO_RATIOS..];
    let r = recent[recent.len() - 1];
    let steady =
        (recent.iter()).all(|q| *q > 0.0 && *q < 1.0 && (q - r).abs() <= ZENO_RATIO_SPREAD * r);
    let (t_limit, rho) = extrapolate(times)?;
    (steady && t_limit - t <= tol * t).then(|| Limit {
        ratio: rho.sqrt(),
        t_limit,
        bounces: times.len(),
        contacts: seq.contacts,
    })
}

/// A converging sequence found from its times ([`limit`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Limit {
    /// The mean ratio of successive intervals (the square root of the ratio over two).
    pub ratio: f64,
    /// The accumulation time (s from release).
    pub t_limit: f64,
    /// How many impacts of the sequence were resolved one by one (the closing one among them).
    pub bounces: usize,
    /// The contacts that close in it: held closed by the impact that ends it.
    pub contacts: Vec<usize>,
}

/// One flight of a contact lifted by an impact: it leaves at `lift` (m/s or rad/s, its normal
/// velocity after) and is pulled back at `pull` (its normal acceleration's opposite), so it is
/// back after `2 lift / pull`, approaching at `lift`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flight {
    /// Its normal velocity after the impact that lifted it.
    pub lift: f64,
    /// The normal velocity, approaching, of the contact whose impact lifted it.
    pub approach: f64,
    /// How fast it is pulled back.
    pub pull: f64,
}

impl Flight {
    /// Its duration.
    pub fn time(&self) -> f64 {
        2.0 * self.lift / self.pull
    }

    /// The ratio of the lift to the approach that caused it: the impact's gain, the same at
    /// every impact of that kind (the impact map is linear in the velocities).
    pub fn gain(&self) -> f64 {
        self.lift / self.approach
    }
}

/// The time left, after a flight `now` just begun, to the limit of a sequence that repeats
/// what happened: the same contact bouncing (`before` is `None`), or two contacts in turn,
/// `before` the previous flight (of the contact whose strike began `now`, lifted by the
/// contact now flying). Each flight lasts `2 lift / pull`; the next one's lift is the gain of
/// the impact that ends this one times its lift. `None` where the gains over a period do not
/// shrink the flights.
pub fn time_left(now: Flight, before: Option<Flight>) -> Option<f64> {
    // One period's flights, and the factor each period shrinks them by.
    let (period, rho) = match before {
        None => (now.time(), now.gain()),
        Some(b) => {
            // The next flight: the contact flown before, lifted by this one's strike with the
            // gain its own lift had.
            let next = Flight {
                lift: b.gain() * now.lift,
                approach: now.lift,
                pull: b.pull,
            };
            (now.time() + next.time(), now.gain() * b.gain())
        }
    };
    (rho > 0.0 && rho < 1.0 && period.is_finite()).then(|| period / (1.0 - rho))
}
