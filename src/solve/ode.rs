//! Explicit Dormand–Prince integrators with dense output and event location, sharing one step
//! loop:
//!
//! - [`dopri5`]: the 5(4) pair, 7 stages (6 derivative evaluations a step, the last stage being
//!   the derivative at the new point), with Hairer's fourth-order continuous extension.
//! - [`dop853`]: the eighth-order method of Dormand and Prince, 12 stages, with the 5th- and
//!   3rd-order error estimates combined as in Hairer's `dop853.f` (12 evaluations a step with
//!   the derivative at the new point), and its seventh-order continuous extension (`contd8`:
//!   three more evaluations an accepted step).
//!
//! [`integrate`] runs either ([`Method`]; [`Method::for_rtol`] picks one for a tolerance). Both
//! share the tolerances (absolute per component, or relative to a running peak), the step-size
//! control (exponent `1/order`), the starting step, the reuse of the derivative at the new
//! point as the next step's first stage, and the event location.
//!
//! Events are located by re-stepping: once an event function changes sign over an accepted step
//! `[t_n, t_n + h]`, its root `tau` is found by the Illinois method on `g(step(y_n, tau))`, where
//! each trial is a genuine step of the method from `y_n`, not the interpolant. The event time and
//! state are therefore as accurate as any step, and the final step is truncated to the event.

use crate::solve::SolveError;
use crate::solve::roots::{changes_sign, illinois, illinois_to};

/// A first-order system `y' = f(t, y)` with optional event functions.
pub trait OdeProblem {
    /// Dimension of `y`.
    fn dim(&self) -> usize;
    /// Fills `dy = f(t, y)`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError>;
    /// Number of event functions.
    fn n_events(&self) -> usize {
        0
    }
    /// Event values at a state (of a step, or of a step's continuous extension) and its
    /// derivative; a sign change is an event.
    fn events(
        &mut self,
        _t: f64,
        _y: &[f64],
        _dy: &[f64],
        _g: &mut [f64],
    ) -> Result<(), SolveError> {
        Ok(())
    }
}

/// Integration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct OdeOptions {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance per component (length `dim`); any other length means
    /// `rtol` times the running maximum of each component (relative control).
    pub atol: Vec<f64>,
    /// Time limit: the solution ends there when no event came first (its `event` is `None`;
    /// the caller decides whether that is an error).
    pub t_max: f64,
    /// Most steps (accepted plus rejected) before [`SolveError::TooManySteps`].
    pub max_steps: u64,
    /// Keep every step's continuous extension, so that the solution can be sampled between
    /// steps ([`OdeSolution::interpolate`]). Without it only the steps whose events are located
    /// compute one (DOP853 saves its three dense-output evaluations a step elsewhere) and the
    /// solution holds the states at the steps' ends; the steps and events are the same.
    pub dense_output: bool,
}

/// The Runge–Kutta method of an integration.
///
/// [`Method::for_rtol`] takes DOP853 below `rtol = 1e-10` ([`Method::CROSSOVER_RTOL`]): there
/// it costs fewer derivative evaluations than DOPRI5 at the same tolerance (both keep the event
/// times' relative errors below `rtol`, within a factor of 6 of each other). Evaluations DOPRI5
/// / DOP853 to the event, relative-only control (`atol` empty), counted by the
/// `step_counts_of_both_methods` unit test (the oscillator `y'' = -y` to `y' = -1/2`, the
/// pendulum `theta'' = -sin(theta)` from rest at 1.5 rad to `theta = 0`) and by
/// `both_integrators_find_the_separation` in `tests/ode.rs` (the rod and cube's unreduced
/// equations to separation):
///
/// | rtol  | oscillator | pendulum  | rod and cube |
/// |-------|------------|-----------|--------------|
/// | 1e-8  | 200 / 218  | 152 / 227 | 134 / 188    |
/// | 1e-9  | 260 / 233  | 200 / 253 | 146 / 260    |
/// | 1e-10 | 374 / 248  | 248 / 283 | 176 / 188    |
/// | 5e-11 | 422 / 284  | 290 / 274 | 188 / 200    |
/// | 3e-11 | 464 / 263  | 296 / 274 | 224 / 203    |
/// | 2e-11 | 494 / 299  | 320 / 310 | 230 / 239    |
/// | 1e-11 | 560 / 302  | 362 / 301 | 236 / 203    |
/// | 1e-12 | 854 / 308  | 536 / 335 | 356 / 242    |
/// | 1e-13 | 1322 / 368 | 830 / 408 | 506 / 233    |
///
/// At 1e-10 and above DOPRI5 is cheaper on two of the three; below it DOP853 is cheaper on the
/// oscillator and the pendulum at every tolerance measured, and on the rod and cube except at
/// 5e-11 and 2e-11 (by 6 % and 4 %, within the spread of the event location's trial count),
/// by 14 % to 54 % from 1e-11 down. DOP853 takes 1.4 to 12 times fewer accepted steps (more,
/// the tighter the tolerance), but a step costs 12 evaluations (15 with its dense output)
/// against DOPRI5's 6, and on these short integrations to an event the 6 to 14 trial steps of
/// the event location are a large share.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Dormand–Prince 5(4), [`dopri5`].
    Dopri5,
    /// Dormand–Prince 8(5,3), [`dop853`].
    Dop853,
}

impl Method {
    /// Relative tolerances below this are integrated with [`Method::Dop853`] by
    /// [`Method::for_rtol`] (see [`Method`] for the measurement).
    pub const CROSSOVER_RTOL: f64 = 1e-10;

    /// The cheaper method for a relative tolerance: [`Method::Dop853`] below
    /// [`Method::CROSSOVER_RTOL`], [`Method::Dopri5`] otherwise (also for NaN).
    pub fn for_rtol(rtol: f64) -> Method {
        if rtol < Self::CROSSOVER_RTOL {
            Method::Dop853
        } else {
            Method::Dopri5
        }
    }

    /// `"DOPRI5"` or `"DOP853"`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Dopri5 => "DOPRI5",
            Method::Dop853 => "DOP853",
        }
    }

    /// Order of the solution carried from step to step (5 or 8).
    pub fn order(self) -> u32 {
        self.tableau().order
    }

    fn tableau(self) -> &'static Tableau {
        match self {
            Method::Dopri5 => &DOPRI5,
            Method::Dop853 => &DOP853,
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One accepted step with its dense-output coefficients (none when the integration did not keep
/// them, [`OdeOptions::dense_output`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DenseStep {
    /// Start time.
    pub t0: f64,
    /// Step size.
    pub h: f64,
    /// `y(t0)`.
    pub y0: Vec<f64>,
    /// `y(t0 + h)`.
    pub y1: Vec<f64>,
    /// The method that took the step.
    method: Method,
    /// Continuous-extension coefficients `c_0..c_{m-1}` of
    /// `y0 + s (c_0 + (1 - s) (c_1 + s (c_2 + (1 - s) (c_3 + ...))))`, `s = (t - t0) / h`:
    /// `rcont2..rcont5` of Hairer's DOPRI5 (`m = 4`), `cont(2..8)` of DOP853's `contd8`
    /// (`m = 7`), each of length `y0.len()`. Empty: the step kept only its ends.
    coeffs: Vec<Vec<f64>>,
}

impl DenseStep {
    /// The interpolated state at `t` in `[t0, t0 + h]`; `None` when the step kept no
    /// continuous extension ([`OdeOptions::dense_output`]) and `t` is not one of its ends.
    pub fn interpolate(&self, t: f64) -> Option<Vec<f64>> {
        if self.coeffs.is_empty() {
            return if t == self.t0 {
                Some(self.y0.clone())
            } else if t == self.t1() {
                Some(self.y1.clone())
            } else {
                None
            };
        }
        Some(self.extension(t))
    }

    /// Whether the step kept its continuous extension.
    pub fn has_extension(&self) -> bool {
        !self.coeffs.is_empty()
    }

    /// The continuous extension at `t` (only for a step that has one). A component beyond a
    /// coefficient's length (only if the public `y0` was lengthened after the step) takes
    /// that coefficient as zero.
    fn extension(&self, t: f64) -> Vec<f64> {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        let m = self.coeffs.len();
        (self.y0.iter().enumerate())
            .map(|(i, y0)| {
                // Horner from the innermost coefficient; the factor before `c_j` is `s` for
                // even `j`, `1 - s` for odd.
                let mut acc = 0.0;
                for (j, c) in self.coeffs.iter().enumerate().rev() {
                    let cj = c.get(i).copied().unwrap_or(0.0);
                    let f = if (j + 1) % 2 == 0 { s } else { s1 };
                    acc = if j + 1 == m { cj } else { cj + f * acc };
                }
                y0 + s * acc
            })
            .collect()
    }

    /// End time.
    pub fn t1(&self) -> f64 {
        self.t0 + self.h
    }

    /// The method that took the step (and whose continuous extension this is).
    pub fn method(&self) -> Method {
        self.method
    }
}

/// Where an event function changed sign.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Index of the event function.
    pub index: usize,
    /// Time of the root.
    pub t: f64,
    /// State there.
    pub y: Vec<f64>,
}

/// A finished integration.
#[derive(Debug, Clone, PartialEq)]
pub struct OdeSolution {
    /// Accepted steps, the last truncated at the event if one stopped the integration.
    pub steps: Vec<DenseStep>,
    /// The event that stopped the integration, if any.
    pub event: Option<Event>,
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Trial steps taken while locating the event.
    pub event_trials: u64,
}

impl OdeSolution {
    /// Every step counted: accepted, rejected and event trials.
    pub fn total_steps(&self) -> u64 {
        self.accepted + self.rejected + self.event_trials
    }

    /// The state at `t` from dense output, if `t` lies in the integrated range and its step
    /// kept its continuous extension (or `t` is a step's end).
    pub fn interpolate(&self, t: f64) -> Option<Vec<f64>> {
        let first = self.steps.first()?;
        let last = self.steps.last()?;
        if !(t >= first.t0 && t <= last.t1()) {
            return None;
        }
        let i = self
            .steps
            .partition_point(|s| s.t1() < t)
            .min(self.steps.len() - 1);
        let step = &self.steps[i];
        if t == step.t1() {
            return Some(step.y1.clone());
        }
        step.interpolate(t)
    }

    /// Time and state at the end of every accepted step, the initial state first.
    pub fn nodes(&self) -> Vec<(f64, &[f64])> {
        let mut out = Vec::with_capacity(self.steps.len() + 1);
        if let Some(first) = self.steps.first() {
            out.push((first.t0, first.y0.as_slice()));
        }
        out.extend(self.steps.iter().map(|s| (s.t1(), s.y1.as_slice())));
        out
    }

    /// Final time.
    pub fn t_final(&self) -> f64 {
        self.steps.last().map_or(0.0, DenseStep::t1)
    }
}

/// A method's coefficients and step-size control.
struct Tableau {
    method: Method,
    /// Order of the solution: the step-size exponent is `1 / order`.
    order: u32,
    /// Nodes of the rows of `a`.
    c: &'static [f64],
    /// The Runge–Kutta matrix by rows, row `s` holding `a_{s,0..s}`. Row `solution` is the
    /// weights `b` of the new point, so its stage is the derivative there (the next step's
    /// first stage); rows after it are the dense-output stages.
    a: &'static [&'static [f64]],
    /// Index of the row of `b` in `a`.
    solution: usize,
    /// Rows `d` of the last dense-output coefficients, each `h sum_j d_j k_j`.
    d: &'static [&'static [f64]],
    /// Whether the error estimate reads the derivative at the new point (DOPRI5's seventh
    /// stage), so that every step evaluates it, or only accepted steps and event trials do.
    error_needs_end: bool,
    /// Bounds of the step-size factor.
    fac_min: f64,
    fac_max: f64,
}

impl Tableau {
    /// Step-size factor after a step with error norm `err`, accepted (`err <= 1`) or not.
    fn factor(&self, err: f64, accepted: bool) -> f64 {
        let expo = -1.0 / f64::from(self.order);
        if accepted {
            (0.9 * err.max(1e-10).powf(expo)).clamp(self.fac_min, self.fac_max)
        } else if err.is_finite() {
            (0.9 * err.powf(expo)).clamp(self.fac_min, 1.0)
        } else {
            self.fac_min
        }
    }
}

// Dormand–Prince 5(4) tableau (Hairer, Nørsett, Wanner, dopri5.f).
const DOPRI5: Tableau = Tableau {
    method: Method::Dopri5,
    order: 5,
    c: &[0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0],
    a: &[
        &[],
        &[0.2],
        &[3.0 / 40.0, 9.0 / 40.0],
        &[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
        &[
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
        ],
        &[
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
        ],
        &[
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
        ],
    ],
    solution: 6,
    d: &[&[
        -12715105075.0 / 11282082432.0,
        0.0,
        87487479700.0 / 32700410799.0,
        -10690763975.0 / 1880347072.0,
        701980252875.0 / 199316789632.0,
        -1453857185.0 / 822651844.0,
        69997945.0 / 29380423.0,
    ]],
    error_needs_end: true,
    fac_min: 0.2,
    fac_max: 5.0,
};

// DOPRI5's error weights (`b - b_hat`).
const DOPRI5_E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

const DOP853: Tableau = Tableau {
    method: Method::Dop853,
    order: 8,
    c: &dop853_coefficients::C,
    a: &dop853_coefficients::A,
    solution: 12,
    d: &dop853_coefficients::D,
    error_needs_end: false,
    fac_min: 0.333,
    fac_max: 6.0,
};

/// The coefficients of DOP853 as published (Hairer, Nørsett & Wanner, *Solving Ordinary
/// Differential Equations I*, and the public-domain `dop853.f`), to 30 digits; stages are
/// numbered from 0 here (`k[0]` is Hairer's `k1`), stage 12 is the derivative at the new point
/// and stages 13..15 are `contd8`'s (Hairer's `k14..k16`).
// The published digits are kept as typed; the compiler rounds them to the nearest `f64`.
#[allow(clippy::excessive_precision)]
mod dop853_coefficients {
    /// Nodes.
    pub(super) const C: [f64; 16] = [
        0.0,
        0.526001519587677318785587544488e-01,
        0.789002279381515978178381316732e-01,
        0.118350341907227396726757197510,
        0.281649658092772603273242802490,
        0.333333333333333333333333333333,
        0.25,
        0.307692307692307692307692307692,
        0.651282051282051282051282051282,
        0.6,
        0.857142857142857142857142857142,
        1.0,
        1.0,
        0.1,
        0.2,
        0.777777777777777777777777777778,
    ];

    /// Weights of the eighth-order solution.
    pub(super) const B: [f64; 12] = [
        5.42937341165687622380535766363e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        4.45031289275240888144113950566,
        1.89151789931450038304281599044,
        -5.8012039600105847814672114227,
        3.1116436695781989440891606237e-1,
        -1.52160949662516078556178806805e-1,
        2.01365400804030348374776537501e-1,
        4.47106157277725905176885569043e-2,
    ];

    /// The third-order embedded weights `bhh1, bhh2, bhh3` (at stages 0, 8 and 11).
    const BHH: [f64; 3] = [
        0.244094488188976377952755905512,
        0.733846688281611857341361741547,
        0.220588235294117647058823529412e-1,
    ];

    /// Weights of the fifth-order error estimate (`er1..er12`).
    pub(super) const E5: [f64; 12] = [
        0.1312004499419488073250102996e-01,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.1225156446376204440720569753e+01,
        -0.4957589496572501915214079952,
        0.1664377182454986536961530415e+01,
        -0.3503288487499736816886487290,
        0.3341791187130174790297318841,
        0.8192320648511571246570742613e-01,
        -0.2235530786388629525884427845e-01,
    ];

    /// Weights of the third-order error estimate (`b - bhh`).
    pub(super) const E3: [f64; 12] = [
        B[0] - BHH[0],
        0.0,
        0.0,
        0.0,
        0.0,
        B[5],
        B[6],
        B[7],
        B[8] - BHH[1],
        B[9],
        B[10],
        B[11] - BHH[2],
    ];

    /// The Runge–Kutta matrix by rows (row `s` has `s` entries), `B` as row 12.
    pub(super) const A: [&[f64]; 16] = [
        &[],
        &[5.26001519587677318785587544488e-2],
        &[
            1.97250569845378994544595329183e-2,
            5.91751709536136983633785987549e-2,
        ],
        &[
            2.95875854768068491816892993775e-2,
            0.0,
            8.87627564304205475450678981324e-2,
        ],
        &[
            2.41365134159266685502369798665e-1,
            0.0,
            -8.84549479328286085344864962717e-1,
            9.24834003261792003115737966543e-1,
        ],
        &[
            3.7037037037037037037037037037e-2,
            0.0,
            0.0,
            1.70828608729473871279604482173e-1,
            1.25467687566822425016691814123e-1,
        ],
        &[
            3.7109375e-2,
            0.0,
            0.0,
            1.70252211019544039314978060272e-1,
            6.02165389804559606850219397283e-2,
            -1.7578125e-2,
        ],
        &[
            3.70920001185047927108779319836e-2,
            0.0,
            0.0,
            1.70383925712239993810214054705e-1,
            1.07262030446373284651809199168e-1,
            -1.53194377486244017527936158236e-2,
            8.27378916381402288758473766002e-3,
        ],
        &[
            6.24110958716075717114429577812e-1,
            0.0,
            0.0,
            -3.36089262944694129406857109825,
            -8.68219346841726006818189891453e-1,
            2.75920996994467083049415600797e1,
            2.01540675504778934086186788979e1,
            -4.34898841810699588477366255144e1,
        ],
        &[
            4.77662536438264365890433908527e-1,
            0.0,
            0.0,
            -2.48811461997166764192642586468,
            -5.90290826836842996371446475743e-1,
            2.12300514481811942347288949897e1,
            1.52792336328824235832596922938e1,
            -3.32882109689848629194453265587e1,
            -2.03312017085086261358222928593e-2,
        ],
        &[
            -9.3714243008598732571704021658e-1,
            0.0,
            0.0,
            5.18637242884406370830023853209,
            1.09143734899672957818500254654,
            -8.14978701074692612513997267357,
            -1.85200656599969598641566180701e1,
            2.27394870993505042818970056734e1,
            2.49360555267965238987089396762,
            -3.0467644718982195003823669022,
        ],
        &[
            2.27331014751653820792359768449,
            0.0,
            0.0,
            -1.05344954667372501984066689879e1,
            -2.00087205822486249909675718444,
            -1.79589318631187989172765950534e1,
            2.79488845294199600508499808837e1,
            -2.85899827713502369474065508674,
            -8.87285693353062954433549289258,
            1.23605671757943030647266201528e1,
            6.43392746015763530355970484046e-1,
        ],
        &B,
        &[
            5.61675022830479523392909219681e-2,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            2.53500210216624811088794765333e-1,
            -2.46239037470802489917441475441e-1,
            -1.24191423263816360469010140626e-1,
            1.5329179827876569731206322685e-1,
            8.20105229563468988491666602057e-3,
            7.56789766054569976138603589584e-3,
            -8.298e-3,
        ],
        &[
            3.18346481635021405060768473261e-2,
            0.0,
            0.0,
            0.0,
            0.0,
            2.83009096723667755288322961402e-2,
            5.35419883074385676223797384372e-2,
            -5.49237485713909884646569340306e-2,
            0.0,
            0.0,
            -1.08347328697249322858509316994e-4,
            3.82571090835658412954920192323e-4,
            -3.40465008687404560802977114492e-4,
            1.41312443674632500278074618366e-1,
        ],
        &[
            -4.28896301583791923408573538692e-1,
            0.0,
            0.0,
            0.0,
            0.0,
            -4.69762141536116384314449447206,
            7.68342119606259904184240953878,
            4.06898981839711007970213554331,
            3.56727187455281109270669543021e-1,
            0.0,
            0.0,
            0.0,
            -1.39902416515901462129418009734e-3,
            2.9475147891527723389556272149,
            -9.15095847217987001081870187138,
        ],
    ];

    /// `contd8`'s `d4*..d7*` (the last four dense-output coefficients), over all 16 stages.
    pub(super) const D: [&[f64]; 4] = [
        &[
            -0.84289382761090128651353491142e+01,
            0.0,
            0.0,
            0.0,
            0.0,
            0.56671495351937776962531783590,
            -0.30689499459498916912797304727e+01,
            0.23846676565120698287728149680e+01,
            0.21170345824450282767155149946e+01,
            -0.87139158377797299206789907490,
            0.22404374302607882758541771650e+01,
            0.63157877876946881815570249290,
            -0.88990336451333310820698117400e-01,
            0.18148505520854727256656404962e+02,
            -0.91946323924783554000451984436e+01,
            -0.44360363875948939664310572000e+01,
        ],
        &[
            0.10427508642579134603413151009e+02,
            0.0,
            0.0,
            0.0,
            0.0,
            0.24228349177525818288430175319e+03,
            0.16520045171727028198505394887e+03,
            -0.37454675472269020279518312152e+03,
            -0.22113666853125306036270938578e+02,
            0.77334326684722638389603898808e+01,
            -0.30674084731089398182061213626e+02,
            -0.93321305264302278729567221706e+01,
            0.15697238121770843886131091075e+02,
            -0.31139403219565177677282850411e+02,
            -0.93529243588444783865713862664e+01,
            0.35816841486394083752465898540e+02,
        ],
        &[
            0.19985053242002433820987653617e+02,
            0.0,
            0.0,
            0.0,
            0.0,
            -0.38703730874935176555105901742e+03,
            -0.18917813819516756882830838328e+03,
            0.52780815920542364900561016686e+03,
            -0.11573902539959630126141871134e+02,
            0.68812326946963000169666922661e+01,
            -0.10006050966910838403183860980e+01,
            0.77771377980534432092869265740,
            -0.27782057523535084065932004339e+01,
            -0.60196695231264120758267380846e+02,
            0.84320405506677161018159903784e+02,
            0.11992291136182789328035130030e+02,
        ],
        &[
            -0.25693933462703749003312586129e+02,
            0.0,
            0.0,
            0.0,
            0.0,
            -0.15418974869023643374053993627e+03,
            -0.23152937917604549567536039109e+03,
            0.35763911791061412378285349910e+03,
            0.93405324183624310003907691704e+02,
            -0.37458323136451633156875139351e+02,
            0.10409964950896230045147246184e+03,
            0.29840293426660503123344363579e+02,
            -0.43533456590011143754432175058e+02,
            0.96324553959188282948394950600e+02,
            -0.39177261675615439165231486172e+02,
            -0.14972683625798562581422125276e+03,
        ],
    ];
}

/// `out = y + h sum_j row_j k_j` (the products in stage order).
///
/// Every buffer here has the problem's dimension `n`: the stages and `out` are allocated with
/// it and the entry points check `y0.len() == n`. The sums run stage by stage over whole
/// vectors (each component's terms still added in stage order, from `-0.0` as `Iterator::sum`
/// does), which the compiler vectorises.
fn combine(out: &mut [f64], y: &[f64], h: f64, row: &[f64], k: &[Vec<f64>]) {
    weighted_sum(out, row, k);
    for (o, yi) in out.iter_mut().zip(y) {
        *o = yi + h * *o;
    }
}

/// `out = sum_j w_j k_j`, stage by stage.
fn weighted_sum(out: &mut [f64], w: &[f64], k: &[Vec<f64>]) {
    out.fill(-0.0);
    for (wj, kj) in w.iter().zip(k) {
        for (o, v) in out.iter_mut().zip(kj) {
            *o += wj * v;
        }
    }
}

/// Stage derivatives of one step of a method.
///
/// `k[0]` is the derivative at the step's start and is written only by [`Stages::fsal`], so a
/// step can be re-taken from the same start (event trials) without re-evaluating it.
struct Stages {
    tab: &'static Tableau,
    /// One derivative per row of the tableau, each of length `n`.
    k: Vec<Vec<f64>>,
    /// The new point of the last step.
    y1: Vec<f64>,
    tmp: Vec<f64>,
    /// Size and end time of the last step.
    h: f64,
    t1: f64,
    /// Whether `k[solution]` holds the derivative at `(t1, y1)`.
    at_end: bool,
}

impl Stages {
    fn new(tab: &'static Tableau, n: usize) -> Self {
        Stages {
            tab,
            k: vec![vec![0.0; n]; tab.a.len()],
            y1: vec![0.0; n],
            tmp: vec![0.0; n],
            h: 0.0,
            t1: 0.0,
            at_end: false,
        }
    }

    /// The derivative at the step's start.
    fn first(&self) -> &[f64] {
        &self.k[0]
    }

    /// The derivative at the new point (after [`Stages::end_derivative`]).
    fn end(&self) -> &[f64] {
        &self.k[self.tab.solution]
    }

    /// One step from `(t, y)` with `k[0] = f(t, y)` already set: fills the stages up to the
    /// new point `y1` (and, for DOPRI5, its derivative, which the error estimate reads).
    fn step<P: OdeProblem>(
        &mut self,
        p: &mut P,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<(), SolveError> {
        let sol = self.tab.solution;
        for s in 1..sol {
            combine(&mut self.tmp, y, h, self.tab.a[s], &self.k);
            p.rhs(t + self.tab.c[s] * h, &self.tmp, &mut self.k[s])?;
        }
        combine(&mut self.y1, y, h, self.tab.a[sol], &self.k);
        self.h = h;
        self.t1 = t + h;
        self.at_end = false;
        if self.tab.error_needs_end {
            p.rhs(t + self.tab.c[sol] * h, &self.y1, &mut self.k[sol])?;
            self.at_end = true;
        }
        check_finite("state", self.t1, &self.y1)?;
        if self.at_end {
            check_finite("derivative", self.t1, self.end())?;
        }
        Ok(())
    }

    /// Evaluates the derivative at the new point if the step has not.
    fn end_derivative<P: OdeProblem>(&mut self, p: &mut P) -> Result<(), SolveError> {
        if !self.at_end {
            let sol = self.tab.solution;
            p.rhs(self.t1, &self.y1, &mut self.k[sol])?;
            self.at_end = true;
            check_finite("derivative", self.t1, self.end())?;
        }
        Ok(())
    }

    /// Makes the derivative at the new point the next step's first stage.
    fn fsal(&mut self) {
        self.k.swap(0, self.tab.solution);
        self.at_end = false;
    }

    /// The step's error norm relative to the tolerances (accept when at most 1).
    fn error(&self, y: &[f64], h: f64, tol: &Tolerance) -> f64 {
        let n = y.len();
        let scale = |i: usize| tol.atol[i] + tol.rtol * y[i].abs().max(self.y1[i].abs());
        let weighted =
            |w: &[f64], i: usize| -> f64 { w.iter().zip(&self.k).map(|(e, k)| e * k[i]).sum() };
        match self.tab.method {
            Method::Dopri5 => {
                let mut sum = 0.0;
                for i in 0..n {
                    let e: f64 = h * weighted(&DOPRI5_E, i);
                    sum += (e / scale(i)).powi(2);
                }
                (sum / n as f64).sqrt()
            }
            Method::Dop853 => {
                // dop853.f: err5^2 / sqrt(err5^2 + 0.01 err3^2), both RMS norms.
                let (mut err5, mut err3) = (0.0, 0.0);
                for i in 0..n {
                    let sc = scale(i);
                    err5 += (weighted(&dop853_coefficients::E5, i) / sc).powi(2);
                    err3 += (weighted(&dop853_coefficients::E3, i) / sc).powi(2);
                }
                let deno = err5 + 0.01 * err3;
                let deno = if deno > 0.0 { deno } else { 1.0 };
                h.abs() * err5 * (1.0 / (n as f64 * deno)).sqrt()
            }
        }
    }

    /// The dense output of the step just taken to `(t0 + h, y1)` (its end derivative
    /// evaluated): DOP853 evaluates its three dense-output stages here.
    fn dense<P: OdeProblem>(
        &mut self,
        p: &mut P,
        t0: f64,
        y: &[f64],
        h: f64,
    ) -> Result<DenseStep, SolveError> {
        let sol = self.tab.solution;
        for s in sol + 1..self.tab.a.len() {
            combine(&mut self.tmp, y, h, self.tab.a[s], &self.k);
            let t = t0 + self.tab.c[s] * h;
            p.rhs(t, &self.tmp, &mut self.k[s])?;
            check_finite("derivative", t, &self.k[s])?;
        }
        let n = y.len();
        let mut coeffs = vec![vec![0.0; n]; 3 + self.tab.d.len()];
        for i in 0..n {
            let ydiff = self.y1[i] - y[i];
            let bspl = h * self.k[0][i] - ydiff;
            coeffs[0][i] = ydiff;
            coeffs[1][i] = bspl;
            coeffs[2][i] = ydiff - h * self.k[sol][i] - bspl;
        }
        for (c, d) in coeffs[3..].iter_mut().zip(self.tab.d) {
            weighted_sum(c, d, &self.k);
            for v in c.iter_mut() {
                *v *= h;
            }
        }
        Ok(DenseStep {
            t0,
            h,
            y0: y.to_vec(),
            y1: self.y1.clone(),
            method: self.tab.method,
            coeffs,
        })
    }

    /// The step just taken to `(t0 + h, y1)` with its ends only (no continuous extension).
    fn ends(&self, t0: f64, y: &[f64], h: f64) -> DenseStep {
        DenseStep {
            t0,
            h,
            y0: y.to_vec(),
            y1: self.y1.clone(),
            method: self.tab.method,
            coeffs: Vec::new(),
        }
    }
}

fn check_finite(what: &'static str, t: f64, v: &[f64]) -> Result<(), SolveError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(SolveError::OdeNonFinite {
            what,
            t,
            y: v.to_vec(),
        })
    }
}

/// The error scale: `atol + rtol |y|` per component, where `atol` is given or, for an `atol`
/// of another length than `dim`, `rtol` times the component's running peak (floored at `1e-8`
/// of the largest peak).
struct Tolerance {
    rtol: f64,
    atol: Vec<f64>,
    relative_only: bool,
    peak: Vec<f64>,
}

impl Tolerance {
    fn new(opts: &OdeOptions, y0: &[f64]) -> Self {
        let n = y0.len();
        let relative_only = opts.atol.len() != n;
        Tolerance {
            rtol: opts.rtol,
            atol: if relative_only {
                vec![0.0; n]
            } else {
                opts.atol.clone()
            },
            relative_only,
            peak: y0.iter().map(|v| v.abs()).collect(),
        }
    }

    /// Seeds the peaks with one unit of time of the initial derivative, so a start from rest
    /// has a scale.
    fn seed(&mut self, f0: &[f64]) {
        for (p, d) in self.peak.iter_mut().zip(f0) {
            *p = p.max(d.abs() * 1e-3);
        }
        self.floor();
    }

    /// Takes an accepted state into the peaks.
    fn observe(&mut self, y: &[f64]) {
        for (p, v) in self.peak.iter_mut().zip(y) {
            *p = p.max(v.abs());
        }
        self.floor();
    }

    fn floor(&mut self) {
        if self.relative_only {
            let top = self.peak.iter().cloned().fold(0.0, f64::max);
            for (a, p) in self.atol.iter_mut().zip(&self.peak) {
                *a = self.rtol * p.max(1e-8 * top).max(f64::MIN_POSITIVE);
            }
        }
    }
}

/// Integrates `problem` from `(t0, y0)` with DOPRI5 until an event function changes sign or
/// `t_max`; [`integrate`] with [`Method::Dopri5`].
pub fn dopri5<P: OdeProblem>(
    problem: &mut P,
    t0: f64,
    y0: &[f64],
    opts: &OdeOptions,
) -> Result<OdeSolution, SolveError> {
    integrate(Method::Dopri5, problem, t0, y0, opts)
}

/// Integrates `problem` from `(t0, y0)` with DOP853 until an event function changes sign or
/// `t_max`; [`integrate`] with [`Method::Dop853`].
pub fn dop853<P: OdeProblem>(
    problem: &mut P,
    t0: f64,
    y0: &[f64],
    opts: &OdeOptions,
) -> Result<OdeSolution, SolveError> {
    integrate(Method::Dop853, problem, t0, y0, opts)
}

/// Integrates `problem` from `(t0, y0)` with `method` until an event function changes sign
/// (the solution then ends with a step truncated at the [`Event`]) or `t_max` (then its
/// `event` is `None`). Errors: a non-finite state, derivative
/// or event value, or a `y0` whose length is not `problem.dim()`
/// ([`SolveError::OdeNonFinite`]), [`SolveError::StepSizeTooSmall`],
/// [`SolveError::TooManySteps`], and the problem's own errors.
pub fn integrate<P: OdeProblem>(
    method: Method,
    problem: &mut P,
    t0: f64,
    y0: &[f64],
    opts: &OdeOptions,
) -> Result<OdeSolution, SolveError> {
    let tab = method.tableau();
    let n = problem.dim();
    if y0.len() != n {
        // No dedicated variant: the state is refused as unusable, with its values.
        return Err(SolveError::OdeNonFinite {
            what: "initial state (its length is not dim())",
            t: t0,
            y: y0.to_vec(),
        });
    }
    let m = problem.n_events();
    let mut tol = Tolerance::new(opts, y0);
    let mut st = Stages::new(tab, n);
    let mut t = t0;
    let mut y = y0.to_vec();
    check_finite("initial state", t, &y)?;
    problem.rhs(t, &y, &mut st.k[0])?;
    check_finite("initial derivative", t, st.first())?;
    tol.seed(st.first());
    let mut g = vec![0.0; m];
    problem.events(t, &y, st.first(), &mut g)?;
    check_finite("event function", t, &g)?;

    let span = opts.t_max - t0;
    let mut h = initial_step(problem, t, &y, st.first(), &tol, span, tab.order)?;
    let mut sol = OdeSolution {
        steps: Vec::new(),
        event: None,
        accepted: 0,
        rejected: 0,
        event_trials: 0,
    };
    let mut g_new = vec![0.0; m];
    loop {
        if sol.accepted + sol.rejected >= opts.max_steps {
            return Err(SolveError::TooManySteps {
                t,
                steps: sol.accepted + sol.rejected,
                t_max: opts.t_max,
            });
        }
        let last = t + h >= opts.t_max;
        if last {
            h = opts.t_max - t;
        }
        if h <= 8.0 * f64::EPSILON * t.abs().max(f64::MIN_POSITIVE) {
            return Err(SolveError::StepSizeTooSmall { t, h });
        }
        st.step(problem, t, &y, h)?;
        let err = st.error(&y, h, &tol);
        if err.is_nan() || err > 1.0 {
            sol.rejected += 1;
            h *= tab.factor(err, false);
            continue;
        }
        sol.accepted += 1;
        st.end_derivative(problem)?;
        problem.events(t + h, &st.y1, st.end(), &mut g_new)?;
        check_finite("event function", t + h, &g_new)?;
        let crossed: Vec<usize> = (0..m).filter(|&i| changes_sign(g[i], g_new[i])).collect();
        // The extension estimates the events' roots: every step that crossed one needs it.
        let dense = if opts.dense_output || !crossed.is_empty() {
            st.dense(problem, t, &y, h)?
        } else {
            st.ends(t, &y, h)
        };
        let step = Trial {
            t,
            y: &y,
            h,
            rtol: opts.rtol,
        };
        let located = locate(
            problem, &mut st, &mut sol, step, &dense, &crossed, &g, &g_new,
        )?;
        if let Some((tau, index)) = located {
            // The step exactly to the event for its state and the truncated dense step (the
            // last trial's, when it was that step).
            if st.h != tau {
                st.step(problem, t, &y, tau)?;
                st.end_derivative(problem)?;
                sol.event_trials += 1;
            }
            sol.steps.push(if opts.dense_output {
                st.dense(problem, t, &y, tau)?
            } else {
                st.ends(t, &y, tau)
            });
            sol.event = Some(Event {
                index,
                t: t + tau,
                y: st.y1.clone(),
            });
            return Ok(sol);
        }
        sol.steps.push(dense);
        t += h;
        y.copy_from_slice(&st.y1);
        st.fsal();
        g.copy_from_slice(&g_new);
        tol.observe(&y);
        if last {
            return Ok(sol);
        }
        h *= tab.factor(err, true);
    }
}

/// A step from `(t, y)` of size `h` whose events are being located.
#[derive(Clone, Copy)]
struct Trial<'a> {
    t: f64,
    y: &'a [f64],
    h: f64,
    /// The relative tolerance it was taken at.
    rtol: f64,
}

/// The earliest root among the crossed event functions (none crossed: `None`), to adjacent
/// floats of genuine re-steps from the step's start (each trial a step to `t + x`, not the
/// interpolant: the event's state is the integrator's own). The step's continuous extension
/// `dense` gives each root's first estimate ([`bracket`] then closes in on it with few trials).
#[allow(clippy::too_many_arguments)]
fn locate<P: OdeProblem>(
    problem: &mut P,
    st: &mut Stages,
    sol: &mut OdeSolution,
    step: Trial,
    dense: &DenseStep,
    crossed: &[usize],
    g0: &[f64],
    g1: &[f64],
) -> Result<Option<(f64, usize)>, SolveError> {
    let Trial { t, y, h, rtol } = step;
    let mut g = vec![0.0; g0.len()];
    let mut dz = vec![0.0; y.len()];
    let mut best: Option<(f64, usize)> = None;
    for &idx in crossed {
        let mut on_extension = |x: f64| -> Result<f64, SolveError> {
            let z = dense.extension(t + x);
            problem.rhs(t + x, &z, &mut dz)?;
            problem.events(t + x, &z, &dz, &mut g)?;
            check_finite("event function", t + x, &g)?;
            Ok(g[idx])
        };
        let estimate = illinois(&mut on_extension, (0.0, g0[idx]), (h, g1[idx]))?;
        let mut genuine = |x: f64| -> Result<f64, SolveError> {
            st.step(problem, t, y, x)?;
            st.end_derivative(problem)?;
            sol.event_trials += 1;
            problem.events(t + x, &st.y1, st.end(), &mut g)?;
            check_finite("event function", t + x, &g)?;
            Ok(g[idx])
        };
        // Close in on the genuine root: around the extension's at the local error's distance,
        // then around the secant root of that bracket at a few ulps.
        let local = rtol.max(f64::EPSILON) * h;
        let (a, b) = bracket(&mut genuine, estimate, local, (0.0, g0[idx]), (h, g1[idx]))?;
        let secant = (a.0 * b.1 - b.0 * a.1) / (b.1 - a.1);
        let ulps = 4.0 * f64::EPSILON * secant.abs();
        let (a, b) = bracket(&mut genuine, secant, ulps, a, b)?;
        // To two ulps of the event's time `t + x`, the most it can hold.
        let root = illinois_to(genuine, a, b, 2.0 * f64::EPSILON * (t + h).abs())?;
        if best.is_none_or(|(tb, ib)| root < tb || (root == tb && idx < ib)) {
            best = Some((root, idx));
        }
    }
    Ok(best)
}

/// A point and the function's value there.
type Point = (f64, f64);

/// How much [`bracket`]'s distance from its estimate grows at each look that finds no sign
/// change.
const BRACKET_GROWTH: f64 = 16.0;

/// Most looks of one [`bracket`]: from an ulp, sixteen-fold growth covers any interval of
/// floats in 14.
const BRACKET_LOOKS: usize = 16;

/// A bracket `(a', b')` inside `(a, b)` of a root of `f` near `estimate` (`f(a')` of `fa`'s
/// sign, `f(b')` across zero from it or zero), found by looking at distances from the estimate
/// growing from `delta` (at least an ulp of it), on the side where the root lies. `a < b`, and
/// `fa` and `fb` differ in sign; an estimate outside `(a, b)` (or not a number) leaves the
/// bracket as it is.
fn bracket<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    estimate: f64,
    delta: f64,
    (a, fa): Point,
    (b, fb): Point,
) -> Result<(Point, Point), E> {
    if !(estimate > a && estimate < b) {
        return Ok(((a, fa), (b, fb)));
    }
    let (mut x, mut fx) = (estimate, f(estimate)?);
    let below = changes_sign(fa, fx);
    let mut delta = delta
        .max(f64::EPSILON * estimate.abs())
        .max(f64::MIN_POSITIVE);
    for _ in 0..BRACKET_LOOKS {
        if fx == 0.0 {
            break;
        }
        let next = if below { x - delta } else { x + delta };
        if (below && next <= a) || (!below && next >= b) {
            break;
        }
        let fn_ = f(next)?;
        match (below, changes_sign(fa, fn_)) {
            (true, false) => return Ok(((next, fn_), (x, fx))),
            (false, true) => return Ok(((x, fx), (next, fn_))),
            _ => (x, fx) = (next, fn_),
        }
        delta *= BRACKET_GROWTH;
    }
    // The root lies between the last point and the end on its side.
    Ok(if below {
        ((a, fa), (x, fx))
    } else {
        ((x, fx), (b, fb))
    })
}

/// Hairer's starting step size for a method of order `order`.
fn initial_step<P: OdeProblem>(
    problem: &mut P,
    t: f64,
    y: &[f64],
    f0: &[f64],
    tol: &Tolerance,
    span: f64,
    order: u32,
) -> Result<f64, SolveError> {
    let n = y.len();
    let sc: Vec<f64> = (0..n)
        .map(|i| tol.atol[i] + tol.rtol * y[i].abs())
        .collect();
    let norm = |v: &[f64]| {
        (v.iter().zip(&sc).map(|(x, s)| (x / s).powi(2)).sum::<f64>() / n as f64).sqrt()
    };
    let d0 = norm(y);
    let d1 = norm(f0);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6 * span.abs().max(1e-300)
    } else {
        0.01 * d0 / d1
    };
    let h0 = h0.min(span.abs());
    let y1: Vec<f64> = (0..n).map(|i| y[i] + h0 * f0[i]).collect();
    let mut f1 = vec![0.0; n];
    problem.rhs(t + h0, &y1, &mut f1)?;
    let diff: Vec<f64> = (0..n).map(|i| f1[i] - f0[i]).collect();
    let d2 = norm(&diff) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / f64::from(order))
    };
    Ok((100.0 * h0).min(h1).min(span.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `y'' = -y` from `y(0) = 0`, `y'(0) = 1`, with the event `y' = -1/2` (at `t = 2 pi / 3`).
    struct Oscillator;

    impl OdeProblem for Oscillator {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
            dy[0] = y[1];
            dy[1] = -y[0];
            Ok(())
        }
        fn n_events(&self) -> usize {
            1
        }
        fn events(
            &mut self,
            _t: f64,
            y: &[f64],
            _dy: &[f64],
            g: &mut [f64],
        ) -> Result<(), SolveError> {
            g[0] = y[1] + 0.5; // y' = -1/2 first at t = 2 pi / 3
            Ok(())
        }
    }

    #[test]
    fn oscillator_event_and_dense_output() {
        let opts = OdeOptions {
            rtol: 1e-12,
            atol: vec![1e-14; 2],
            t_max: 10.0,
            max_steps: 100_000,
            dense_output: true,
        };
        let sol = dopri5(&mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap();
        let ev = sol.event.clone().unwrap();
        let want = 2.0 * std::f64::consts::PI / 3.0;
        assert!((ev.t - want).abs() < 1e-11, "{} vs {want}", ev.t);
        for t in [0.3, 1.0, 1.7, 2.0] {
            let y = sol.interpolate(t).unwrap();
            assert!(
                (y[0] - t.sin()).abs() < 1e-10,
                "t = {t}: {} vs {}",
                y[0],
                t.sin()
            );
        }
        assert!(sol.accepted > 10 && sol.rejected < sol.accepted);
    }

    #[test]
    fn tighter_tolerance_is_more_accurate() {
        // Without events: a tighter tolerance takes more steps and lands closer to sin(1).
        let run = |rtol: f64| {
            let opts = OdeOptions {
                rtol,
                atol: vec![rtol; 2],
                t_max: 1.0,
                max_steps: 100_000,
                dense_output: true,
            };
            struct Free;
            impl OdeProblem for Free {
                fn dim(&self) -> usize {
                    2
                }
                fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
                    dy[0] = y[1];
                    dy[1] = -y[0];
                    Ok(())
                }
            }
            let sol = dopri5(&mut Free, 0.0, &[0.0, 1.0], &opts).unwrap();
            let y = &sol.steps.last().unwrap().y1;
            ((y[0] - 1f64.sin()).abs(), sol.accepted)
        };
        let (e1, n1) = run(1e-6);
        let (e2, n2) = run(1e-11);
        assert!(e2 < e1 && e2 < 1e-10, "{e1} {e2}");
        assert!(n2 > n1);
    }

    /// `theta'' = -sin(theta)` from rest at `theta = 1.5`, with the event `theta = 0`.
    struct Pendulum;

    impl OdeProblem for Pendulum {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
            dy[0] = y[1];
            dy[1] = -y[0].sin();
            Ok(())
        }
        fn n_events(&self) -> usize {
            1
        }
        fn events(
            &mut self,
            _t: f64,
            y: &[f64],
            _dy: &[f64],
            g: &mut [f64],
        ) -> Result<(), SolveError> {
            g[0] = y[0];
            Ok(())
        }
    }

    const THETA0: f64 = 1.5;

    /// The pendulum's quarter period `K(sin(theta0 / 2))`, by the arithmetic-geometric mean.
    fn quarter_period() -> f64 {
        let k = (0.5 * THETA0).sin();
        let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
        for _ in 0..10 {
            (a, b) = (0.5 * (a + b), (a * b).sqrt());
        }
        std::f64::consts::PI / (2.0 * a)
    }

    /// Counts the derivative evaluations of a problem.
    struct Counted<P> {
        inner: P,
        evals: u64,
    }

    impl<P: OdeProblem> OdeProblem for Counted<P> {
        fn dim(&self) -> usize {
            self.inner.dim()
        }
        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
            self.evals += 1;
            self.inner.rhs(t, y, dy)
        }
        fn n_events(&self) -> usize {
            self.inner.n_events()
        }
        fn events(
            &mut self,
            t: f64,
            y: &[f64],
            dy: &[f64],
            g: &mut [f64],
        ) -> Result<(), SolveError> {
            self.inner.events(t, y, dy, g)
        }
    }

    fn options(rtol: f64, atol: Vec<f64>, t_max: f64) -> OdeOptions {
        OdeOptions {
            rtol,
            atol,
            t_max,
            max_steps: 100_000,
            dense_output: true,
        }
    }

    const METHODS: [Method; 2] = [Method::Dopri5, Method::Dop853];

    #[test]
    fn dop853_oscillator_event_and_dense_output() {
        let opts = options(1e-13, vec![1e-15; 2], 10.0);
        let sol = dop853(&mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap();
        let ev = sol.event.clone().unwrap();
        let want = 2.0 * std::f64::consts::PI / 3.0;
        assert!((ev.t - want).abs() < 1e-13, "{} vs {want}", ev.t);
        assert!((ev.y[1] + 0.5).abs() < 1e-13 && (ev.y[0] - want.sin()).abs() < 1e-13);
        let last = sol.steps.last().unwrap();
        assert_eq!(last.t1(), ev.t);
        assert!(sol.steps.iter().all(|s| s.method() == Method::Dop853));
        // Inside the truncated event step, then across the whole range.
        let mut times = vec![last.t0 + 0.25 * last.h, last.t0 + 0.7 * last.h, ev.t];
        times.extend([0.05, 0.3, 1.0, 1.7, 2.0]);
        for t in times {
            let y = sol.interpolate(t).unwrap();
            let (e0, e1) = ((y[0] - t.sin()).abs(), (y[1] - t.cos()).abs());
            assert!(e0 < 1e-11 && e1 < 1e-11, "t = {t}: errors {e0:e}, {e1:e}");
        }
        assert!(sol.interpolate(ev.t + 1e-9).is_none());
        assert!(sol.accepted > 3 && sol.rejected < sol.accepted);
    }

    /// Without dense output the steps, their ends and the event are the same to the bit; only
    /// the steps' ends can then be read, and the steps that crossed the event kept their
    /// extension to locate it (evaluations: DOP853's three a step fewer elsewhere).
    #[test]
    fn without_dense_output_the_steps_and_event_are_the_same() {
        for method in METHODS {
            let mut opts = options(1e-12, vec![1e-14; 2], 10.0);
            let count = |opts: &OdeOptions| {
                let mut p = Counted {
                    inner: Oscillator,
                    evals: 0,
                };
                let sol = integrate(method, &mut p, 0.0, &[0.0, 1.0], opts).unwrap();
                (sol, p.evals)
            };
            let (with, evals_with) = count(&opts);
            opts.dense_output = false;
            let (without, evals_without) = count(&opts);
            assert_eq!(with.event, without.event, "{method:?}");
            assert_eq!(with.steps.len(), without.steps.len(), "{method:?}");
            for (a, b) in with.steps.iter().zip(&without.steps) {
                assert_eq!((a.t0, a.h, &a.y0, &a.y1), (b.t0, b.h, &b.y0, &b.y1));
            }
            let step = &without.steps[1];
            assert!(!step.has_extension() && with.steps[1].has_extension());
            assert_eq!(without.interpolate(step.t1()), Some(step.y1.clone()));
            assert_eq!(without.interpolate(step.t0 + 0.5 * step.h), None);
            // DOP853: three evaluations fewer on every accepted step but the one that crossed
            // the event, and on the truncated step to it; DOPRI5's extension costs none.
            let per_step = if method == Method::Dop853 { 3 } else { 0 };
            let saved = evals_with - evals_without;
            assert_eq!(saved, per_step * with.accepted, "{method:?}");
        }
    }

    /// `y0' = -y0^2` (`y0 = 1 / (1 + t)`) and `y1' = cos(t) y1` (`y1 = exp(sin t)`): smooth,
    /// nonlinear and non-autonomous, without events.
    struct Smooth;

    impl OdeProblem for Smooth {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
            dy[0] = -y[0] * y[0];
            dy[1] = t.cos() * y[1];
            Ok(())
        }
    }

    fn smooth_exact(t: f64) -> [f64; 2] {
        [1.0 / (1.0 + t), t.sin().exp()]
    }

    /// `steps` equal steps of `method` over `[0, 2]` through the integrator's stage code: the
    /// largest error at the end and the largest dense-output error at a third of each step.
    fn fixed_steps(method: Method, steps: usize) -> (f64, f64) {
        let mut st = Stages::new(method.tableau(), 2);
        let h = 2.0 / steps as f64;
        let mut y = vec![1.0, 1.0];
        Smooth.rhs(0.0, &y, &mut st.k[0]).unwrap();
        let mut dense_err = 0.0f64;
        for i in 0..steps {
            let t = i as f64 * h;
            st.step(&mut Smooth, t, &y, h).unwrap();
            st.end_derivative(&mut Smooth).unwrap();
            let d = st.dense(&mut Smooth, t, &y, h).unwrap();
            let tm = t + h / 3.0;
            for (a, b) in d.interpolate(tm).unwrap().iter().zip(smooth_exact(tm)) {
                dense_err = dense_err.max((a - b).abs());
            }
            y.copy_from_slice(&st.y1);
            st.fsal();
        }
        let end = smooth_exact(2.0);
        let err = (y[0] - end[0]).abs().max((y[1] - end[1]).abs());
        (err, dense_err)
    }

    #[test]
    fn observed_orders_on_fixed_steps() {
        // Halving the step divides DOP853's global error by about 2^8 (DOPRI5's by 2^5, a check
        // of the helper), and the dense output's error at a third of every step by about
        // 2^(q + 1) for a continuous extension of order q (7 and 4): its local error.
        for (method, steps, extension) in [
            (Method::Dopri5, [40, 80, 160], 4.0),
            (Method::Dop853, [5, 10, 20], 7.0),
        ] {
            let want = f64::from(method.order());
            let runs: Vec<(f64, f64)> = steps.iter().map(|&s| fixed_steps(method, s)).collect();
            for (w, pair) in steps.windows(2).zip(runs.windows(2)) {
                let order = (pair[0].0 / pair[1].0).log2();
                let dense = (pair[0].1 / pair[1].1).log2();
                println!(
                    "{method}: {} -> {} steps: errors {:.3e} -> {:.3e} (order {order:.2}), dense {:.3e} -> {:.3e} ({dense:.2})",
                    w[0], w[1], pair[0].0, pair[1].0, pair[0].1, pair[1].1
                );
                assert!((order - want).abs() < 0.5, "{method}: order {order}");
                assert!(dense > extension, "{method}: dense output's order {dense}");
            }
        }
    }

    /// Accepted, rejected and event-trial steps, derivative evaluations and the event time's
    /// relative error of one method on one of the two problems with events.
    fn counts(method: Method, pendulum: bool, rtol: f64) -> (OdeSolution, u64, f64) {
        let opts = options(rtol, Vec::new(), 10.0);
        let (sol, evals, want) = if pendulum {
            let mut p = Counted {
                inner: Pendulum,
                evals: 0,
            };
            let sol = integrate(method, &mut p, 0.0, &[THETA0, 0.0], &opts).unwrap();
            (sol, p.evals, quarter_period())
        } else {
            let mut p = Counted {
                inner: Oscillator,
                evals: 0,
            };
            let sol = integrate(method, &mut p, 0.0, &[0.0, 1.0], &opts).unwrap();
            (sol, p.evals, 2.0 * std::f64::consts::PI / 3.0)
        };
        let t = sol.event.as_ref().unwrap().t;
        (sol, evals, ((t - want) / want).abs())
    }

    /// The measurement behind [`Method::CROSSOVER_RTOL`]: prints steps, evaluations and the
    /// event time's error of both methods on the oscillator and the pendulum, and holds the
    /// crossover to it at `rtol` 1e-6, 1e-8, 1e-10, 1e-12 and 1e-13.
    #[test]
    fn step_counts_of_both_methods() {
        println!("problem    rtol  | DOPRI5 accepted rejected trials evals rel.err | DOP853 ...");
        for pendulum in [false, true] {
            for rtol in [
                1e-6, 1e-8, 1e-9, 1e-10, 5e-11, 3e-11, 2e-11, 1e-11, 1e-12, 1e-13,
            ] {
                let name = if pendulum { "pendulum" } else { "oscillator" };
                let mut line = format!("{name:10} {rtol:.0e} ");
                let mut evals = [0; 2];
                for (e, method) in evals.iter_mut().zip(METHODS) {
                    let (sol, n, err) = counts(method, pendulum, rtol);
                    *e = n;
                    line += &format!(
                        "| {:4} {:3} {:3} {:5} {err:7.1e} ",
                        sol.accepted, sol.rejected, sol.event_trials, n
                    );
                }
                println!("{line}");
                if ![1e-6, 1e-8, 1e-10, 1e-12, 1e-13].contains(&rtol) {
                    continue;
                }
                // Where DOP853 is chosen it costs fewer evaluations on both problems; where
                // DOPRI5 is, it costs fewer on the pendulum (the oscillator favours DOP853
                // from 1e-9 on).
                match Method::for_rtol(rtol) {
                    Method::Dop853 => assert!(evals[1] < evals[0], "{name} {rtol:e}: {evals:?}"),
                    Method::Dopri5 if pendulum => {
                        assert!(evals[0] < evals[1], "{name} {rtol:e}: {evals:?}")
                    }
                    Method::Dopri5 => {}
                }
            }
        }
    }

    #[test]
    fn dop853_takes_several_times_fewer_steps_at_tight_tolerance() {
        for pendulum in [false, true] {
            let (a, _, ea) = counts(Method::Dopri5, pendulum, 1e-12);
            let (b, _, eb) = counts(Method::Dop853, pendulum, 1e-12);
            let ratio = a.total_steps() as f64 / b.total_steps() as f64;
            println!(
                "{}: DOPRI5 {} steps (error {ea:.1e}), DOP853 {} steps (error {eb:.1e}): ratio {ratio:.2}",
                if pendulum { "pendulum" } else { "oscillator" },
                a.total_steps(),
                b.total_steps()
            );
            assert!(ratio > 3.0, "ratio {ratio}");
            let (accepted_a, accepted_b) = (a.accepted as f64, b.accepted as f64);
            assert!(
                accepted_a > 3.0 * accepted_b,
                "{accepted_a} vs {accepted_b}"
            );
        }
    }

    #[test]
    fn both_methods_locate_events_to_1e12() {
        for method in METHODS {
            for pendulum in [false, true] {
                let (sol, _, err) = counts(method, pendulum, 1e-13);
                assert!(
                    err < 1e-12,
                    "{method} (pendulum: {pendulum}): relative error {err:e}"
                );
                let ev = sol.event.unwrap();
                let at = if pendulum { ev.y[0] } else { ev.y[1] + 0.5 };
                assert!(
                    at.abs() < 1e-12,
                    "{method}: event function {at:e} at the event"
                );
            }
        }
    }

    /// `y' = 1` from `y = 0`, with the event `y = 3e-5` (inside the first step, of `1e-4`).
    struct Early;

    impl OdeProblem for Early {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, _y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
            dy[0] = 1.0;
            Ok(())
        }
        fn n_events(&self) -> usize {
            1
        }
        fn events(
            &mut self,
            _t: f64,
            y: &[f64],
            _dy: &[f64],
            g: &mut [f64],
        ) -> Result<(), SolveError> {
            g[0] = y[0] - 3e-5;
            Ok(())
        }
    }

    #[test]
    fn an_event_in_the_first_step() {
        for method in METHODS {
            let sol = integrate(
                method,
                &mut Early,
                0.0,
                &[0.0],
                &options(1e-6, vec![1e-9], 1.0),
            )
            .unwrap();
            let ev = sol.event.clone().unwrap();
            assert_eq!((sol.accepted, sol.steps.len()), (1, 1), "{method}");
            assert!((ev.t - 3e-5).abs() < 1e-18, "{method}: {}", ev.t);
            let mid = sol.interpolate(1.5e-5).unwrap()[0];
            assert!((mid - 1.5e-5).abs() < 1e-18, "{method}: {mid}");
        }
    }

    #[test]
    fn no_event_before_t_max() {
        for method in METHODS {
            let opts = options(1e-10, Vec::new(), 1.0);
            // With events that do not fire, the solution ends at t_max without one.
            let sol = integrate(method, &mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap();
            assert_eq!(sol.t_final(), 1.0, "{method}");
            assert!(sol.event.is_none(), "{method}");
            // Without event functions, reaching t_max is the end.
            let sol = integrate(method, &mut Smooth, 0.0, &[1.0, 1.0], &opts).unwrap();
            assert_eq!(sol.t_final(), 1.0);
            assert!(sol.event.is_none());
            let y = &sol.steps.last().unwrap().y1;
            assert!((y[0] - 0.5).abs() < 1e-9 && (y[1] - 1f64.sin().exp()).abs() < 1e-9);
        }
    }

    /// `y' = y` whose derivative is NaN from `t = 0.5` on, or at the start.
    struct Broken {
        from: f64,
    }

    impl OdeProblem for Broken {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SolveError> {
            dy[0] = if t >= self.from { f64::NAN } else { y[0] };
            Ok(())
        }
    }

    #[test]
    fn non_finite_derivatives_are_the_same_typed_error() {
        let opts = options(1e-8, Vec::new(), 2.0);
        for (from, want) in [(0.5, "state"), (0.0, "initial derivative")] {
            let errs: Vec<SolveError> = METHODS
                .iter()
                .map(|&m| integrate(m, &mut Broken { from }, 0.0, &[1.0], &opts).unwrap_err())
                .collect();
            for e in &errs {
                match e {
                    SolveError::OdeNonFinite { what, t, .. } => {
                        assert_eq!(*what, want);
                        assert!(*t >= from && *t <= 2.0, "{e}");
                    }
                    other => panic!("{other:?}"),
                }
            }
        }
        // A non-finite initial state, and one of the wrong length, are refused without a panic.
        for method in METHODS {
            let e = integrate(method, &mut Oscillator, 0.0, &[f64::NAN, 1.0], &opts).unwrap_err();
            assert!(matches!(
                e,
                SolveError::OdeNonFinite {
                    what: "initial state",
                    ..
                }
            ));
            let e = integrate(method, &mut Oscillator, 0.0, &[0.0, 1.0, 2.0], &opts).unwrap_err();
            assert!(matches!(e, SolveError::OdeNonFinite { .. }), "{e}");
        }
    }

    #[test]
    fn step_limits_are_the_same_typed_errors() {
        for method in METHODS {
            let opts = OdeOptions {
                max_steps: 3,
                dense_output: true,
                ..options(1e-12, Vec::new(), 10.0)
            };
            let e = integrate(method, &mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap_err();
            assert!(
                matches!(e, SolveError::TooManySteps { steps: 3, .. }),
                "{e}"
            );
            let opts = options(1e-12, Vec::new(), 0.0);
            let e = integrate(method, &mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap_err();
            assert!(matches!(e, SolveError::StepSizeTooSmall { .. }), "{e}");
        }
    }

    #[test]
    fn method_dispatch_and_names() {
        assert_eq!(Method::for_rtol(1e-3), Method::Dopri5);
        assert_eq!(Method::for_rtol(1e-13), Method::Dop853);
        assert_eq!(Method::for_rtol(Method::CROSSOVER_RTOL), Method::Dopri5);
        assert_eq!(Method::for_rtol(f64::NAN), Method::Dopri5);
        assert_eq!(
            (Method::Dopri5.name(), Method::Dop853.name()),
            ("DOPRI5", "DOP853")
        );
        assert_eq!(Method::Dop853.to_string(), "DOP853");
        assert_eq!((Method::Dopri5.order(), Method::Dop853.order()), (5, 8));
        let opts = options(1e-9, Vec::new(), 10.0);
        let a = integrate(Method::Dop853, &mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap();
        let b = dop853(&mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap();
        assert_eq!(a, b);
        let c = integrate(Method::Dopri5, &mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap();
        assert_eq!(c, dopri5(&mut Oscillator, 0.0, &[0.0, 1.0], &opts).unwrap());
        assert!(c.steps.iter().all(|s| s.method() == Method::Dopri5));
        assert!(a.accepted < c.accepted);
    }

    #[test]
    fn dop853_tableau_is_consistent() {
        // Row sums equal the nodes, the weights sum to one, and the error weights to zero.
        for tab in [&DOPRI5, &DOP853] {
            assert_eq!(tab.a.len(), tab.c.len());
            for (s, (row, c)) in tab.a.iter().zip(tab.c).enumerate() {
                assert_eq!(row.len(), s);
                let sum: f64 = row.iter().sum();
                assert!(
                    (sum - c).abs() < 1e-14,
                    "{}: row {s}: {sum} vs {c}",
                    tab.method
                );
            }
            for d in tab.d {
                assert_eq!(d.len(), tab.a.len());
            }
        }
        let e5: f64 = dop853_coefficients::E5.iter().sum();
        let e3: f64 = dop853_coefficients::E3.iter().sum();
        assert!(e5.abs() < 1e-14 && e3.abs() < 1e-14, "{e5:e} {e3:e}");
    }
}
