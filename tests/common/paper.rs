//! Hand-typed models of the seed paper, for testing the solvers before (and independently of)
//! the generated ones: the system `rod_cube` as a general model (the foot's height a coordinate,
//! the tip on the cube and the floor under the foot two contacts, typed from the Lagrangian by
//! hand), its fast phase `rod_cube_closed` from eqs. (5), (9), (12 as corrected in PHYSICS.md
//! erratum 2), (14), (16), (18), (22), and `rod_cube_free`, the rod sliding alone and the cube
//! gliding on after they part.
//!
//! Both follow the `k`/`delta` conventions of `rodcube::model`; every `sin(theta_i) - sin(theta)`
//! and `cos(theta) - cos(theta_i)` is formed from `delta` without cancellation. Their
//! `theta_dot_sq_sc` recovers `delta` from the drops and calls `reduced`, an independent route
//! that the tests compare with the generated one.

/// The paper's separation time (`scenes/paper.yaml`: `m1 = 1`, `m2 = 3`, `ell = 1`, `a = 0.25`,
/// `g = 9.81`) to 15 digits, held to the 256-bit reference and to the paper's 0.108 s by
/// `tests/hard_cases.rs` (`the_quoted_paper_separation_time_is_the_references`).
pub const PAPER_T_SEP: f64 = 0.108493254170856;

use rodcube::model::{
    ContactInfo, GapKind, Model, ModelInfo, MonitorInfo, NamedInfo, ParamInfo, Partials, PhaseInfo,
    Reduced, Reduction, ReductionInfo, RequirementInfo, ShapeInfo, ShapeKind, Tangents,
};

const fn param(
    name: &'static str,
    meaning: &'static str,
    unit: &'static str,
    positive: bool,
) -> ParamInfo {
    ParamInfo {
        name,
        meaning,
        unit,
        positive,
    }
}

const fn named(name: &'static str, meaning: &'static str) -> NamedInfo {
    NamedInfo { name, meaning }
}

/// The paper's one requirement, `a < ell`, over `ell` and `a` (parameters 2 and 3).
const fn a_below_ell(meaning: &'static str) -> RequirementInfo {
    RequirementInfo {
        name: "a_below_ell",
        meaning,
        parameters: &[2, 3],
    }
}

const fn monitor(name: &'static str, meaning: &'static str, unit: &'static str) -> MonitorInfo {
    MonitorInfo {
        name,
        meaning,
        unit,
    }
}

/// The system's contacts as a phase holding `closed` (by elimination) sees them: the tip on the
/// cube (eliminating `x2`) and the floor under the foot (eliminating `y1`).
const fn contacts(tip: bool, floor: bool) -> [ContactInfo; 2] {
    [
        ContactInfo {
            name: "contact_force",
            meaning: "push of the rod on the cube (N), positive while touching, eq. (16)",
            gap: GapKind::Length,
            unit: "N",
            bilateral: false,
            edge: false,
            eliminates: Some("x2"),
            closed: tip,
            restitution: "0",
        },
        ContactInfo {
            name: "floor_normal",
            meaning: "floor reaction on the rod's foot (N), m1 (g + y_cm'')",
            gap: GapKind::Length,
            unit: "N",
            bilateral: false,
            edge: false,
            eliminates: Some("y1"),
            closed: floor,
            restitution: "0",
        },
    ]
}

static GENERAL_CONTACTS: [ContactInfo; 2] = contacts(false, false);
static CLOSED_CONTACTS: [ContactInfo; 2] = contacts(true, true);
static FREE_CONTACTS: [ContactInfo; 2] = contacts(false, true);

/// The system's fast phases (the same list in every model of the hand-typed system).
static PHASES: &[PhaseInfo] = &[
    PhaseInfo {
        closed: &[0, 1],
        model: "rod_cube_closed",
        release: true,
        separation_degree: 3,
    },
    PhaseInfo {
        closed: &[1],
        model: "rod_cube_free",
        release: false,
        separation_degree: 0,
    },
];

/// The system's coordinates.
const SYSTEM_COORDINATES: &[&str] = &["x1", "y1", "theta", "x2"];

/// The system's monitor, in every phase (the push, zero where the tip is off the cube).
const MONITORS: &[MonitorInfo] = &[monitor(
    "cube_does_not_tip",
    "m2 g a/2 - F (y_tip - a/2) >= 0",
    "N m",
)];

/// The rod (a segment from end to end through its centre) and the cube (a square of side `a`).
const SHAPES: &[ShapeInfo] = &[
    ShapeInfo {
        kind: ShapeKind::Segment,
        body: Some(0),
        first: 0,
    },
    ShapeInfo {
        kind: ShapeKind::Rectangle,
        body: Some(1),
        first: 4,
    },
];

/// The drawing of rod and cube from the rod's centre, its angle and the cube's near face.
fn draw(k: &[f64], rod: [f64; 3], x2: f64, poses: &mut [[f64; 3]], sizes: &mut [f64]) {
    let (ell, a) = (k[2], k[3]);
    poses[0] = rod;
    poses[1] = [x2 + 0.5 * a, 0.5 * a, 0.0];
    sizes[..8].copy_from_slice(&[-0.5 * ell, 0.0, 0.5 * ell, 0.0, 0.0, 0.0, a, a]);
}

/// `sin(theta_i) - sin(theta_i - delta)` from `sin(theta_i)`, `cos(theta_i)`.
fn sin_drop(s0: f64, c0: f64, delta: f64) -> f64 {
    let h = (0.5 * delta).sin();
    s0 * 2.0 * h * h + c0 * delta.sin()
}

/// `cos(theta_i - delta) - cos(theta_i)` from `sin(theta_i)`, `cos(theta_i)`.
fn cos_rise(s0: f64, c0: f64, delta: f64) -> f64 {
    let h = (0.5 * delta).sin();
    s0 * delta.sin() - c0 * 2.0 * h * h
}

/// The rod's foot, tip and centre (points 0, 1, 2) from `x1 = q[0]`, `theta = q[1]`.
fn rod_points(ell: f64, q: &[f64], qd: &[f64], pos: &mut [[f64; 2]], vel: &mut [[f64; 2]]) {
    let (x1, th, v1, w) = (q[0], q[1], qd[0], qd[1]);
    let (s, c) = (th.sin(), th.cos());
    pos[0] = [x1, 0.0];
    vel[0] = [v1, 0.0];
    pos[1] = [x1 + ell * c, ell * s];
    vel[1] = [v1 - ell * s * w, ell * c * w];
    pos[2] = [x1 + 0.5 * ell * c, 0.5 * ell * s];
    vel[2] = [v1 - 0.5 * ell * s * w, 0.5 * ell * c * w];
}

/// `delta` from the drops `ds = sin(theta_i) - s`, `dc = cos(theta_i) - c` without
/// cancellation: `atan2(cos(theta_i) ds - sin(theta_i) dc, cos(theta_i) c + sin(theta_i) s)`.
fn delta_from_drops(si: f64, ci: f64, s: f64, c: f64, ds: f64, dc: f64) -> f64 {
    (ci * ds - si * dc).atan2(ci * c + si * s)
}

// ---------------------------------------------------------------------------------------------
// rod_cube
// ---------------------------------------------------------------------------------------------

/// The rod leaning on a cube that slides on a frictionless floor (the paper's system), both
/// contacts closed: the fast phase `rod_cube_closed`.
pub struct RodCube;

/// The `rod_cube_closed` model.
pub static ROD_CUBE: RodCube = RodCube;

// k layout
const RC_THETA_I: usize = 5;
const RC_THETA_DOT_I: usize = 6;
const RC_R: usize = 7; // a / ell = sin(theta_i)
const RC_C0: usize = 8; // cos(theta_i)
const RC_MU: usize = 9; // 1 / (1 + n) = m1 / (m1 + m2)
const RC_G_ELL: usize = 10; // g / ell
const RC_KX: usize = 11; // (1 + 2n) / (2 (1 + n))

static RC_INFO: ModelInfo = ModelInfo {
    name: "rod_cube_closed",
    description: "uniform rod leaning on a sliding cube, frictionless floor (hand-typed from the paper)",
    spec: "tests/common/paper.rs",
    system: "rod_cube",
    parameters: &[
        param("m1", "rod mass", "kg", true),
        param("m2", "cube mass", "kg", true),
        param("ell", "rod length", "m", true),
        param("a", "cube side", "m", true),
        param("g", "gravitational acceleration", "m/s^2", true),
    ],
    requirements: &[a_below_ell(
        "the cube is lower than the rod is long: (ell - a) / ell > 0",
    )],
    n_constants: 12,
    coordinates: &["x1", "theta"],
    system_coordinates: SYSTEM_COORDINATES,
    reduced_index: Some(1),
    cyclic: &[0],
    end_angle: Some(0.0),
    contacts: &CLOSED_CONTACTS,
    frictions: &[],
    points: &[
        named("foot", "rod end on the floor"),
        named("tip", "rod end on the cube"),
        named("rod_centre", "rod centre of mass"),
        named("cube", "cube's bottom-left corner"),
    ],
    falling_point_index: Some(2),
    gravity_index: 4,
    monitors: MONITORS,
    bodies: &["rod", "cube"],
    shapes: SHAPES,
    start_params: false,
    phases: PHASES,
    reduction: Some(ReductionInfo {
        k_theta_initial: RC_THETA_I,
        k_theta_dot_initial: RC_THETA_DOT_I,
        k_sin_initial: RC_R,
        k_cos_initial: RC_C0,
        force_degrees: &[3, 4],
        pushes_proven: &[false, false],
        release_push_proven: false,
        fall_degree: Some(2),
        lean_constants: &[5, 6, 7, 8, 9, 10, 11],
    }),
    route_note: "",
};

impl RodCube {
    fn sc(k: &[f64], delta: f64) -> (f64, f64) {
        let theta = k[RC_THETA_I] - delta;
        (theta.sin(), theta.cos())
    }

    /// `M11, M12, M22` of the unreduced Lagrangian (eq. 3 with I = m1 ell^2 / 12).
    fn mass(k: &[f64], s: f64) -> (f64, f64, f64) {
        let (m1, m2, ell) = (k[0], k[1], k[2]);
        (
            m1 + m2,
            -ell * s * (0.5 * m1 + m2),
            m1 * ell * ell / 3.0 + m2 * ell * ell * s * s,
        )
    }
}

impl Model for RodCube {
    fn info(&self) -> &'static ModelInfo {
        &RC_INFO
    }

    fn requirements(&self, p: &[f64], out: &mut [f64]) {
        out[0] = (p[2] - p[3]) / p[2];
    }

    fn restitutions(&self, _p: &[f64], out: &mut [f64]) {
        // The paper's contacts are plastic (the spec gives no restitution).
        out.fill(0.0);
    }

    fn prepare(&self, p: &[f64], k: &mut [f64]) {
        let (m1, m2, ell, a, g) = (p[0], p[1], p[2], p[3], p[4]);
        k[..5].copy_from_slice(p);
        // cos(theta_i) = sqrt((ell - a)(ell + a)) / ell: no loss as a/ell -> 1.
        let c0 = ((ell - a) * (ell + a)).sqrt() / ell;
        k[RC_THETA_I] = a.atan2(((ell - a) * (ell + a)).sqrt());
        k[RC_THETA_DOT_I] = 0.0;
        k[RC_R] = a / ell;
        k[RC_C0] = c0;
        k[RC_MU] = m1 / (m1 + m2);
        k[RC_G_ELL] = g / ell;
        k[RC_KX] = (0.5 * m1 + m2) / (m1 + m2);
    }

    fn initial_state(&self, k: &[f64], q: &mut [f64], qd: &mut [f64]) {
        q.copy_from_slice(&[0.0, k[RC_THETA_I]]);
        qd.copy_from_slice(&[0.0, 0.0]);
    }

    fn points(&self, k: &[f64], q: &[f64], qd: &[f64], pos: &mut [[f64; 2]], vel: &mut [[f64; 2]]) {
        rod_points(k[2], q, qd, pos, vel);
        // The cube's corner is where the tip touches it.
        pos[3] = [pos[1][0], 0.0];
        vel[3] = [vel[1][0], 0.0];
    }

    fn energy(&self, k: &[f64], q: &[f64], qd: &[f64]) -> f64 {
        let (m1, m2, ell, a, g) = (k[0], k[1], k[2], k[3], k[4]);
        let s = q[1].sin();
        let (m11, m12, m22) = Self::mass(k, s);
        let (v, w) = (qd[0], qd[1]);
        0.5 * (m11 * v * v + 2.0 * m12 * v * w + m22 * w * w)
            + m1 * g * ell * s / 2.0
            + m2 * g * a / 2.0
    }

    fn momenta(&self, k: &[f64], q: &[f64], qd: &[f64], out: &mut [f64]) {
        let (m11, m12, _) = Self::mass(k, q[1].sin());
        out[0] = m11 * qd[0] + m12 * qd[1];
    }

    fn equations(&self, k: &[f64], q: &[f64], qd: &[f64], mass: &mut [f64], rhs: &mut [f64]) {
        let (m1, m2, ell, g) = (k[0], k[1], k[2], k[4]);
        let (s, c) = (q[1].sin(), q[1].cos());
        let (m11, m12, m22) = Self::mass(k, s);
        let w = qd[1];
        mass.copy_from_slice(&[m11, m12, m12, m22]);
        rhs[0] = ell * c * (0.5 * m1 + m2) * w * w;
        rhs[1] = -m2 * ell * ell * s * c * w * w - m1 * g * ell * c / 2.0;
    }

    fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        let (m1, m2, ell, g) = (k[0], k[1], k[2], k[4]);
        let (s, c) = (q[1].sin(), q[1].cos());
        let (w, x1dd, wd) = (qd[1], qdd[0], qdd[1]);
        // F = m2 x2'', x2 = x1 + ell cos(theta)
        out[0] = m2 * (x1dd - ell * s * wd - ell * c * w * w);
        out[1] = m1 * (g + 0.5 * ell * (c * wd - s * w * w));
    }

    fn gaps(&self, _k: &[f64], _q: &[f64], out: &mut [f64]) {
        out.fill(0.0);
    }

    fn constraints(&self, _k: &[f64], _q: &[f64], _qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        jac.fill(0.0);
        bias.fill(0.0);
    }

    fn edges(&self, _k: &[f64], _q: &[f64], out: &mut [f64]) {
        out.fill(f64::INFINITY);
    }

    fn friction(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        // Frictionless: no rows.
        let _ = (k, q, qd, jac, bias);
    }

    fn monitors_full(&self, k: &[f64], q: &[f64], _qd: &[f64], f: &[f64], out: &mut [f64]) {
        let (m2, ell, a, g) = (k[1], k[2], k[3], k[4]);
        out[0] = m2 * g * a / 2.0 - f[0] * (ell * q[1].sin() - a / 2.0);
    }

    fn to_full(&self, k: &[f64], q: &[f64], qd: &[f64], q_full: &mut [f64], qd_full: &mut [f64]) {
        let ell = k[2];
        let (s, c) = q[1].sin_cos();
        q_full.copy_from_slice(&[q[0], 0.0, q[1], q[0] + ell * c]);
        qd_full.copy_from_slice(&[qd[0], 0.0, qd[1], qd[0] - ell * s * qd[1]]);
    }

    fn drawing(&self, k: &[f64], q: &[f64], poses: &mut [[f64; 3]], sizes: &mut [f64]) {
        let (x1, th, ell) = (q[0], q[1], k[2]);
        let rod = [x1 + 0.5 * ell * th.cos(), 0.5 * ell * th.sin(), th];
        draw(k, rod, x1 + ell * th.cos(), poses, sizes);
    }

    fn tangents(&self) -> Option<&dyn Tangents> {
        None
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        Some(self)
    }
}

impl Reduction for RodCube {
    fn reduced(&self, k: &[f64], delta: f64) -> Reduced {
        let (s, c) = Self::sc(k, delta);
        let (r, mu, g_ell) = (k[RC_R], k[RC_MU], k[RC_G_ELL]);
        let drop = sin_drop(r, k[RC_C0], delta); // r - s
        let d = 4.0 / 3.0 - mu * s * s;
        let theta_dot_sq = 4.0 * g_ell * drop / d; // eq. (9)
        // PHYSICS.md erratum 2: theta'' = (2g/ell) [ -c/D + (r - s) sin(2 theta) / ((1+n) D^2) ]
        let theta_ddot = 2.0 * g_ell * (-c / d + drop * 2.0 * s * c * mu / (d * d));
        Reduced {
            sin: s,
            cos: c,
            theta_dot_sq,
            theta_ddot,
        }
    }

    fn theta_dot_sq_sc(&self, k: &[f64], s: f64, c: f64, ds: f64, dc: f64) -> f64 {
        let delta = delta_from_drops(k[RC_R], k[RC_C0], s, c, ds, dc);
        self.reduced(k, delta).theta_dot_sq
    }

    fn forces(&self, k: &[f64], delta: f64, out: &mut [f64]) {
        let (m1, m2, ell, g) = (k[0], k[1], k[2], k[4]);
        let red = self.reduced(k, delta);
        let (s, c) = (red.sin, red.cos);
        let (r, mu) = (k[RC_R], k[RC_MU]);
        // eq. (16) divided through by (1 + n)^2
        let den = 4.0 - 3.0 * mu * s * s;
        out[0] = -3.0 * g * m2 * mu * c * (8.0 * r - 12.0 * s + 3.0 * mu * s * s * s) / (den * den);
        out[1] = m1 * (g + 0.5 * ell * (c * red.theta_ddot - s * red.theta_dot_sq));
    }

    fn force_polynomial(&self, k: &[f64], contact: usize, out: &mut [f64]) {
        let (r, mu) = (k[RC_R], k[RC_MU]);
        match contact {
            // eq. (14) divided by (1 + n), with the push's sign: F is -(8r - 12s + 3 mu s^3)
            // times a positive factor (eq. 16).
            0 => out.copy_from_slice(&[-8.0 * r, 12.0, 0.0, -3.0 * mu]),
            // N D^2 / (m1 g) with D = 4/3 - mu s^2, from N = m1 (g + ell/2 (c theta'' - s
            // theta'^2)) and eqs. (9), (12): a quartic with no cubic term.
            1 => out.copy_from_slice(&[
                4.0 / 9.0,
                2.0 * mu * r - 8.0 * r / 3.0,
                4.0 - 11.0 * mu / 3.0,
                0.0,
                mu * mu - mu,
            ]),
            _ => {}
        }
    }

    fn prepare_lean(&self, p: &[f64], k: &mut [f64]) {
        self.prepare(p, k);
    }

    fn fall_polynomial(&self, k: &[f64], out: &mut [f64]) {
        // (a/ell - sin theta) / theta_dot^2 from eq. (9): (ell / 4g) (4/3 - sin^2 theta / (1 + n))
        let (ell, g) = (k[2], k[4]);
        out.copy_from_slice(&[ell / (3.0 * g), 0.0, -ell * k[RC_MU] / (4.0 * g)]);
    }

    fn partials(&self) -> Option<&dyn Partials> {
        None
    }

    fn full_state(
        &self,
        k: &[f64],
        _t: f64,
        delta: f64,
        theta_dot: f64,
        q: &mut [f64],
        qd: &mut [f64],
    ) {
        let (s, _) = Self::sc(k, delta);
        let ell = k[2];
        // eq. (18): x1 = -(1+2n)/(2(1+n)) ell (cos theta - cos theta_i); eq. (5) for x1'.
        q[0] = -k[RC_KX] * ell * cos_rise(k[RC_R], k[RC_C0], delta);
        q[1] = k[RC_THETA_I] - delta;
        qd[0] = k[RC_KX] * ell * s * theta_dot;
        qd[1] = theta_dot;
    }
}

// ---------------------------------------------------------------------------------------------
// rod_cube_free
// ---------------------------------------------------------------------------------------------

/// The rod alone, its foot sliding on the frictionless floor, and the cube gliding on at the
/// speed it had, after they part.
pub struct FreeRod;

/// The `rod_cube_free` model.
pub static FREE_ROD: FreeRod = FreeRod;

// k layout: the 11 parameters, then these.
const FR_THETA_I: usize = 11;
const FR_THETA_DOT_I: usize = 12;
const FR_S0: usize = 13;
const FR_C0: usize = 14;
const FR_G_ELL: usize = 15;
const FR_VCM: usize = 16; // constant horizontal velocity of the rod's centre of mass
const FR_A0: usize = 17; // omega_s^2 (1 + 3 cos^2 theta_s)

static FR_INFO: ModelInfo = ModelInfo {
    name: "rod_cube_free",
    description: "uniform rod sliding on a frictionless floor after leaving the cube (hand-typed)",
    spec: "tests/common/paper.rs",
    system: "rod_cube",
    parameters: &[
        param("m1", "rod mass", "kg", true),
        param("m2", "cube mass", "kg", true),
        param("ell", "rod length", "m", true),
        param("a", "cube side", "m", true),
        param("g", "gravitational acceleration", "m/s^2", true),
        param("x1_0", "foot position at separation", "m", false),
        param("theta_0", "angle at separation", "rad", false),
        param("x2_0", "cube face position at separation", "m", false),
        param("x1_dot_0", "foot velocity at separation", "m/s", false),
        param(
            "theta_dot_0",
            "angular velocity at separation",
            "rad/s",
            false,
        ),
        param("x2_dot_0", "cube velocity at separation", "m/s", false),
    ],
    requirements: &[a_below_ell("(ell - a) / ell > 0")],
    n_constants: 18,
    coordinates: &["x1", "theta", "x2"],
    system_coordinates: SYSTEM_COORDINATES,
    reduced_index: Some(1),
    cyclic: &[0, 2],
    end_angle: Some(0.0),
    contacts: &FREE_CONTACTS,
    frictions: &[],
    points: &[
        named("foot", "rod end on the floor"),
        named("tip", "free rod end"),
        named("rod_centre", "rod centre of mass"),
        named("cube", "cube's bottom-left corner"),
    ],
    falling_point_index: Some(2),
    gravity_index: 4,
    monitors: MONITORS,
    bodies: &["rod", "cube"],
    shapes: SHAPES,
    start_params: true,
    phases: PHASES,
    reduction: Some(ReductionInfo {
        k_theta_initial: FR_THETA_I,
        k_theta_dot_initial: FR_THETA_DOT_I,
        k_sin_initial: FR_S0,
        k_cos_initial: FR_C0,
        force_degrees: &[0, 0],
        pushes_proven: &[false, false],
        release_push_proven: false,
        fall_degree: None,
        lean_constants: &[],
    }),
    route_note: "",
};

impl FreeRod {
    fn sc(k: &[f64], delta: f64) -> (f64, f64) {
        let theta = k[FR_THETA_I] - delta;
        (theta.sin(), theta.cos())
    }
}

impl Model for FreeRod {
    fn info(&self) -> &'static ModelInfo {
        &FR_INFO
    }

    fn requirements(&self, p: &[f64], out: &mut [f64]) {
        out[0] = (p[2] - p[3]) / p[2];
    }

    fn restitutions(&self, _p: &[f64], out: &mut [f64]) {
        // The paper's contacts are plastic (the spec gives no restitution).
        out.fill(0.0);
    }

    fn prepare(&self, p: &[f64], k: &mut [f64]) {
        let (ell, g, th, v1, om) = (p[2], p[4], p[6], p[8], p[9]);
        k[..11].copy_from_slice(p);
        let (s0, c0) = th.sin_cos();
        k[FR_THETA_I] = th;
        k[FR_THETA_DOT_I] = om;
        k[FR_S0] = s0;
        k[FR_C0] = c0;
        k[FR_G_ELL] = g / ell;
        k[FR_VCM] = v1 - 0.5 * ell * s0 * om;
        k[FR_A0] = om * om * (1.0 + 3.0 * c0 * c0);
    }

    fn initial_state(&self, k: &[f64], q: &mut [f64], qd: &mut [f64]) {
        q.copy_from_slice(&[k[5], k[6], k[7]]);
        qd.copy_from_slice(&[k[8], k[9], k[10]]);
    }

    fn points(&self, k: &[f64], q: &[f64], qd: &[f64], pos: &mut [[f64; 2]], vel: &mut [[f64; 2]]) {
        rod_points(k[2], q, qd, pos, vel);
        pos[3] = [q[2], 0.0];
        vel[3] = [qd[2], 0.0];
    }

    fn energy(&self, k: &[f64], q: &[f64], qd: &[f64]) -> f64 {
        let (m1, m2, ell, a, g) = (k[0], k[1], k[2], k[3], k[4]);
        let s = q[1].sin();
        let (v, w) = (qd[0], qd[1]);
        0.5 * m1 * v * v - 0.5 * m1 * ell * s * v * w
            + m1 * ell * ell * w * w / 6.0
            + m1 * g * ell * s / 2.0
            + 0.5 * m2 * qd[2] * qd[2]
            + m2 * g * a / 2.0
    }

    fn momenta(&self, k: &[f64], q: &[f64], qd: &[f64], out: &mut [f64]) {
        let (m1, m2, ell) = (k[0], k[1], k[2]);
        out[0] = m1 * qd[0] - 0.5 * m1 * ell * q[1].sin() * qd[1];
        out[1] = m2 * qd[2];
    }

    fn equations(&self, k: &[f64], q: &[f64], qd: &[f64], mass: &mut [f64], rhs: &mut [f64]) {
        let (m1, m2, ell, g) = (k[0], k[1], k[2], k[4]);
        let (s, c) = (q[1].sin(), q[1].cos());
        let w = qd[1];
        let m12 = -0.5 * m1 * ell * s;
        mass.copy_from_slice(&[m1, m12, 0.0, m12, m1 * ell * ell / 3.0, 0.0, 0.0, 0.0, m2]);
        rhs[0] = 0.5 * m1 * ell * c * w * w;
        rhs[1] = -0.5 * m1 * g * ell * c;
        rhs[2] = 0.0;
    }

    fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        let (m1, ell, g) = (k[0], k[2], k[4]);
        let (s, c) = (q[1].sin(), q[1].cos());
        out[0] = 0.0;
        out[1] = m1 * (g + 0.5 * ell * (c * qdd[1] - s * qd[1] * qd[1]));
    }

    fn gaps(&self, k: &[f64], q: &[f64], out: &mut [f64]) {
        out[0] = q[2] - q[0] - k[2] * q[1].cos();
        out[1] = 0.0;
    }

    fn constraints(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        let ell = k[2];
        let (s, c) = q[1].sin_cos();
        jac.copy_from_slice(&[-1.0, ell * s, 1.0, 0.0, 0.0, 0.0]);
        bias.copy_from_slice(&[ell * c * qd[1] * qd[1], 0.0]);
    }

    fn edges(&self, _k: &[f64], _q: &[f64], out: &mut [f64]) {
        out.fill(f64::INFINITY);
    }

    fn friction(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        // Frictionless: no rows.
        let _ = (k, q, qd, jac, bias);
    }

    fn monitors_full(&self, k: &[f64], q: &[f64], _qd: &[f64], f: &[f64], out: &mut [f64]) {
        let (m2, ell, a, g) = (k[1], k[2], k[3], k[4]);
        out[0] = m2 * g * a / 2.0 - f[0] * (ell * q[1].sin() - a / 2.0);
    }

    fn to_full(&self, _k: &[f64], q: &[f64], qd: &[f64], q_full: &mut [f64], qd_full: &mut [f64]) {
        q_full.copy_from_slice(&[q[0], 0.0, q[1], q[2]]);
        qd_full.copy_from_slice(&[qd[0], 0.0, qd[1], qd[2]]);
    }

    fn drawing(&self, k: &[f64], q: &[f64], poses: &mut [[f64; 3]], sizes: &mut [f64]) {
        let (x1, th, ell) = (q[0], q[1], k[2]);
        let rod = [x1 + 0.5 * ell * th.cos(), 0.5 * ell * th.sin(), th];
        draw(k, rod, q[2], poses, sizes);
    }

    fn tangents(&self) -> Option<&dyn Tangents> {
        None
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        Some(self)
    }
}

impl Reduction for FreeRod {
    fn reduced(&self, k: &[f64], delta: f64) -> Reduced {
        let (s, c) = Self::sc(k, delta);
        // Energy of the rod about its centre (the centre's horizontal velocity is constant):
        // theta'^2 (1 + 3 c^2) = omega_s^2 (1 + 3 c_s^2) + 12 (g/ell) (s_s - s)
        let b = 1.0 + 3.0 * c * c;
        let theta_dot_sq =
            (k[FR_A0] + 12.0 * k[FR_G_ELL] * sin_drop(k[FR_S0], k[FR_C0], delta)) / b;
        let theta_ddot = c * (3.0 * s * theta_dot_sq - 6.0 * k[FR_G_ELL]) / b;
        Reduced {
            sin: s,
            cos: c,
            theta_dot_sq,
            theta_ddot,
        }
    }

    fn theta_dot_sq_sc(&self, k: &[f64], s: f64, c: f64, ds: f64, dc: f64) -> f64 {
        let delta = delta_from_drops(k[FR_S0], k[FR_C0], s, c, ds, dc);
        self.reduced(k, delta).theta_dot_sq
    }

    fn forces(&self, k: &[f64], delta: f64, out: &mut [f64]) {
        let (m1, ell, g) = (k[0], k[2], k[4]);
        let r = self.reduced(k, delta);
        out[0] = 0.0;
        out[1] = m1 * (g + 0.5 * ell * (r.cos * r.theta_ddot - r.sin * r.theta_dot_sq));
    }

    fn force_polynomial(&self, _k: &[f64], _contact: usize, _out: &mut [f64]) {}

    fn fall_polynomial(&self, _k: &[f64], _out: &mut [f64]) {}

    fn prepare_lean(&self, p: &[f64], k: &mut [f64]) {
        self.prepare(p, k);
    }

    fn partials(&self) -> Option<&dyn Partials> {
        None
    }

    fn full_state(
        &self,
        k: &[f64],
        t: f64,
        delta: f64,
        theta_dot: f64,
        q: &mut [f64],
        qd: &mut [f64],
    ) {
        let (s, _) = Self::sc(k, delta);
        let (ell, x1s, vcm) = (k[2], k[5], k[FR_VCM]);
        q[0] = x1s + vcm * t - 0.5 * ell * cos_rise(k[FR_S0], k[FR_C0], delta);
        q[1] = k[FR_THETA_I] - delta;
        q[2] = k[7] + k[10] * t;
        qd[0] = vcm + 0.5 * ell * s * theta_dot;
        qd[1] = theta_dot;
        qd[2] = k[10];
    }
}

// ---------------------------------------------------------------------------------------------
// rod_cube, the general model
// ---------------------------------------------------------------------------------------------

/// The system itself: rod and cube with every coordinate (`x1`, `y1`, `theta`, `x2`) and the
/// two contacts as constraint rows, from `T = m1 (v_cm^2)/2 + m1 ell^2 theta'^2 / 24 +
/// m2 x2'^2 / 2`, `V = m1 g (y1 + ell s / 2) + m2 g a / 2` by hand.
pub struct General;

/// The general `rod_cube` model.
pub static GENERAL: General = General;

static GEN_INFO: ModelInfo = ModelInfo {
    name: "rod_cube",
    description: "uniform rod leaning on a sliding cube, its foot free to lift (hand-typed)",
    spec: "tests/common/paper.rs",
    system: "rod_cube",
    parameters: &[
        param("m1", "rod mass", "kg", true),
        param("m2", "cube mass", "kg", true),
        param("ell", "rod length", "m", true),
        param("a", "cube side", "m", true),
        param("g", "gravitational acceleration", "m/s^2", true),
    ],
    requirements: &[a_below_ell(
        "the cube is lower than the rod is long: (ell - a) / ell > 0",
    )],
    n_constants: 6,
    coordinates: SYSTEM_COORDINATES,
    system_coordinates: SYSTEM_COORDINATES,
    reduced_index: Some(2),
    cyclic: &[0, 3],
    end_angle: Some(0.0),
    contacts: &GENERAL_CONTACTS,
    frictions: &[],
    points: &[
        named("foot", "rod end on the floor"),
        named("tip", "rod end on the cube"),
        named("rod_centre", "rod centre of mass"),
        named("cube", "cube's bottom-left corner"),
    ],
    falling_point_index: Some(2),
    gravity_index: 4,
    monitors: MONITORS,
    bodies: &["rod", "cube"],
    shapes: SHAPES,
    start_params: false,
    phases: PHASES,
    reduction: None,
    route_note: "coordinate `y1` is not cyclic",
};

impl Model for General {
    fn info(&self) -> &'static ModelInfo {
        &GEN_INFO
    }

    fn requirements(&self, p: &[f64], out: &mut [f64]) {
        out[0] = (p[2] - p[3]) / p[2];
    }

    fn restitutions(&self, _p: &[f64], out: &mut [f64]) {
        // The paper's contacts are plastic (the spec gives no restitution).
        out.fill(0.0);
    }

    fn prepare(&self, p: &[f64], k: &mut [f64]) {
        let (ell, a) = (p[2], p[3]);
        k[..5].copy_from_slice(p);
        k[5] = a.atan2(((ell - a) * (ell + a)).sqrt());
    }

    fn initial_state(&self, k: &[f64], q: &mut [f64], qd: &mut [f64]) {
        let (ell, a) = (k[2], k[3]);
        q.copy_from_slice(&[0.0, 0.0, k[5], ((ell - a) * (ell + a)).sqrt()]);
        qd.fill(0.0);
    }

    fn points(&self, k: &[f64], q: &[f64], qd: &[f64], pos: &mut [[f64; 2]], vel: &mut [[f64; 2]]) {
        let ell = k[2];
        let (x1, y1, th, v1, u1, w) = (q[0], q[1], q[2], qd[0], qd[1], qd[2]);
        let (s, c) = th.sin_cos();
        pos[0] = [x1, y1];
        vel[0] = [v1, u1];
        pos[1] = [x1 + ell * c, y1 + ell * s];
        vel[1] = [v1 - ell * s * w, u1 + ell * c * w];
        pos[2] = [x1 + 0.5 * ell * c, y1 + 0.5 * ell * s];
        vel[2] = [v1 - 0.5 * ell * s * w, u1 + 0.5 * ell * c * w];
        pos[3] = [q[3], 0.0];
        vel[3] = [qd[3], 0.0];
    }

    fn energy(&self, k: &[f64], q: &[f64], qd: &[f64]) -> f64 {
        let (m1, m2, ell, a, g) = (k[0], k[1], k[2], k[3], k[4]);
        let (s, c) = q[2].sin_cos();
        let (v1, u1, w) = (qd[0], qd[1], qd[2]);
        let (vx, vy) = (v1 - 0.5 * ell * s * w, u1 + 0.5 * ell * c * w);
        0.5 * m1 * (vx * vx + vy * vy)
            + m1 * ell * ell * w * w / 24.0
            + 0.5 * m2 * qd[3] * qd[3]
            + m1 * g * (q[1] + 0.5 * ell * s)
            + m2 * g * a / 2.0
    }

    fn momenta(&self, k: &[f64], q: &[f64], qd: &[f64], out: &mut [f64]) {
        let (m1, m2, ell) = (k[0], k[1], k[2]);
        out[0] = m1 * (qd[0] - 0.5 * ell * q[2].sin() * qd[2]);
        out[1] = m2 * qd[3];
    }

    fn equations(&self, k: &[f64], q: &[f64], qd: &[f64], mass: &mut [f64], rhs: &mut [f64]) {
        let (m1, m2, ell, g) = (k[0], k[1], k[2], k[4]);
        let (s, c) = q[2].sin_cos();
        let w = qd[2];
        let (hs, hc) = (0.5 * m1 * ell * s, 0.5 * m1 * ell * c);
        mass.copy_from_slice(&[
            m1,
            0.0,
            -hs,
            0.0, //
            0.0,
            m1,
            hc,
            0.0, //
            -hs,
            hc,
            m1 * ell * ell / 3.0,
            0.0, //
            0.0,
            0.0,
            0.0,
            m2,
        ]);
        rhs.copy_from_slice(&[hc * w * w, hs * w * w - m1 * g, -hc * g, 0.0]);
    }

    fn forces_full(&self, _k: &[f64], _q: &[f64], _qd: &[f64], _qdd: &[f64], out: &mut [f64]) {
        out.fill(0.0);
    }

    fn gaps(&self, k: &[f64], q: &[f64], out: &mut [f64]) {
        out[0] = q[3] - q[0] - k[2] * q[2].cos();
        out[1] = q[1];
    }

    fn constraints(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        let ell = k[2];
        let (s, c) = q[2].sin_cos();
        jac.copy_from_slice(&[-1.0, 0.0, ell * s, 1.0, 0.0, 1.0, 0.0, 0.0]);
        bias.copy_from_slice(&[ell * c * qd[2] * qd[2], 0.0]);
    }

    fn edges(&self, _k: &[f64], _q: &[f64], out: &mut [f64]) {
        out.fill(f64::INFINITY);
    }

    fn friction(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        // Frictionless: no rows.
        let _ = (k, q, qd, jac, bias);
    }

    fn monitors_full(&self, k: &[f64], q: &[f64], _qd: &[f64], f: &[f64], out: &mut [f64]) {
        let (m2, ell, a, g) = (k[1], k[2], k[3], k[4]);
        out[0] = m2 * g * a / 2.0 - f[0] * (q[1] + ell * q[2].sin() - a / 2.0);
    }

    fn to_full(&self, _k: &[f64], q: &[f64], qd: &[f64], q_full: &mut [f64], qd_full: &mut [f64]) {
        q_full.copy_from_slice(q);
        qd_full.copy_from_slice(qd);
    }

    fn drawing(&self, k: &[f64], q: &[f64], poses: &mut [[f64; 3]], sizes: &mut [f64]) {
        let (x1, y1, th, ell) = (q[0], q[1], q[2], k[2]);
        let rod = [x1 + 0.5 * ell * th.cos(), y1 + 0.5 * ell * th.sin(), th];
        draw(k, rod, q[3], poses, sizes);
    }

    fn tangents(&self) -> Option<&dyn Tangents> {
        None
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        None
    }
}

/// The local registry: the hand-typed system and its two fast phases, as
/// `rodcube::models::all()` holds the generated ones.
pub static MODELS: &[&dyn Model] = &[&GENERAL, &ROD_CUBE, &FREE_ROD];

/// The paper's parameters (n = 3, r = 1/4, ell = 1 m) with a chosen `g`.
pub fn paper(g: f64) -> [(&'static str, f64); 5] {
    [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", g),
    ]
}

/// `rod_cube_free` from a state after separation (the paper's rod and cube, the cube's face at
/// 1 m gliding at 0.1 m/s): angle and rate, foot position and velocity.
pub fn free_after(theta: f64, omega: f64, x1: f64, v1: f64) -> [(&'static str, f64); 11] {
    [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
        ("x1_0", x1),
        ("theta_0", theta),
        ("x2_0", 1.0),
        ("x1_dot_0", v1),
        ("theta_dot_0", omega),
        ("x2_dot_0", 0.1),
    ]
}

/// Parameters for mass ratio `n` and `r = a/ell` (ell = 1 m, m1 = 1 kg, g = 9.81).
pub fn ratios(n: f64, r: f64) -> [(&'static str, f64); 5] {
    [("m1", 1.0), ("m2", n), ("ell", 1.0), ("a", r), ("g", 9.81)]
}
