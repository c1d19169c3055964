//! The derivation proper: Lagrangian, Euler–Lagrange equations, cyclic coordinates eliminated
//! through their conserved momenta, the energy integral, reaction forces and the separation
//! condition — every step by Symbolica from the spec.
//!
//! Internal symbols (never allowed in specs): `dot_q`, `ddot_q` for velocities and
//! accelerations; on the reduced motion `rc_s = sin(theta)`, `rc_c = cos(theta)`,
//! `rc_ds = sin(theta_i) - sin(theta)`, `rc_dc = cos(theta_i) - cos(theta)`,
//! `rc_delta = theta_i - theta`, `rc_t` time, `rc_w = theta_dot`, `rc_w2 = theta_dot^2`,
//! `rc_acc = theta_ddot`, `rc_f<i>` the i-th force; constants `rc_thi`, `rc_wi`, `rc_si`,
//! `rc_ci`, `rc_ai` (reduced inertia at the start), `rc_x<j>i` (initial cyclic positions) and
//! `rc_p<j>` (conserved momenta).

use super::cas::{self, A};
use super::expr::{Expr, product};
use super::spec::{Checked, Text};
use std::collections::BTreeMap;

/// Where a derivation error belongs in the spec: a dotted field path and a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeriveError {
    /// Field path (`coordinates[0]`), used to find the line.
    pub field: Vec<FieldStep>,
    /// What failed.
    pub message: String,
}

/// One step of a field path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldStep {
    /// Mapping key.
    Key(String),
    /// Sequence index.
    Index(usize),
}

fn at(path: &[FieldStep], message: String) -> DeriveError {
    DeriveError {
        field: path.to_vec(),
        message,
    }
}

fn key(k: &str) -> FieldStep {
    FieldStep::Key(k.to_string())
}

/// A constant computed once per parameter set (in `prepare`).
#[derive(Debug, Clone)]
pub struct Constant {
    /// Internal symbol.
    pub symbol: String,
    /// Definition over parameters and earlier constants.
    pub value: Expr,
}

/// The separation condition.
#[derive(Debug, Clone)]
pub struct Separation {
    /// Coefficients of the polynomial in `sin(theta)`, lowest degree first, over constants.
    pub coefficients: Vec<Expr>,
    /// The polynomial itself, in `rc_s`.
    pub polynomial: Expr,
}

/// Everything derived for one model, as plain expressions.
#[derive(Debug, Clone)]
pub struct Derivation {
    /// Parameter names in order.
    pub params: Vec<String>,
    /// Coordinate names in order.
    pub coords: Vec<String>,
    /// Index of the reduced coordinate.
    pub reduced: usize,
    /// Indices of the cyclic coordinates.
    pub cyclic: Vec<usize>,
    /// Kinetic energy (full state).
    pub kinetic: Expr,
    /// Potential energy (full state).
    pub potential: Expr,
    /// Euler–Lagrange expressions `d/dt dL/dqd - dL/dq` (each `= 0`).
    pub euler_lagrange: Vec<Expr>,
    /// Mass matrix `M(q)`, row-major.
    pub mass: Vec<Vec<Expr>>,
    /// Right-hand side `F(q, qd)` of `M qdd = F`.
    pub rhs: Vec<Expr>,
    /// Conjugate momenta of the cyclic coordinates (full state).
    pub momenta: Vec<Expr>,
    /// Point positions (full state).
    pub point_pos: Vec<[Expr; 2]>,
    /// Point velocities (full state).
    pub point_vel: Vec<[Expr; 2]>,
    /// Reaction forces (full state with accelerations).
    pub forces_full: Vec<Expr>,
    /// Constants computed in `prepare`, in order.
    pub constants: Vec<Constant>,
    /// Reduced inertia `A(theta)` in `T = A theta_dot^2 / 2 + ...`.
    pub reduced_inertia: Expr,
    /// Reduced kinetic-plus-potential energy with the cyclic velocities eliminated.
    pub reduced_energy: Expr,
    /// `theta_dot^2` over `rc_s, rc_c, rc_ds, rc_dc` and constants.
    pub theta_dot_sq: Expr,
    /// `theta_ddot` over the same symbols.
    pub theta_ddot: Expr,
    /// Cyclic velocities on the reduced motion (over `rc_s, rc_c, rc_w`).
    pub cyclic_velocity: Vec<Expr>,
    /// Cyclic positions on the reduced motion (over `rc_t, rc_ds, rc_dc, rc_delta`).
    pub cyclic_position: Vec<Expr>,
    /// Reaction forces on the reduced motion (over `rc_s, rc_c, rc_w2, rc_acc`).
    pub forces_reduced: Vec<Expr>,
    /// Monitors (over `rc_s, rc_c, rc_f<i>` and constants).
    pub monitors: Vec<Expr>,
    /// Parameter requirements (over parameters).
    pub requirements: Vec<Expr>,
    /// The separation condition, if the model has a contact.
    pub separation: Option<Separation>,
    /// Whether the contact surface point moves with the coordinates.
    pub surface_moves: bool,
    /// Fully substituted forms over parameters and `theta` for people and other tools.
    pub plain: BTreeMap<&'static str, Expr>,
}

fn parse_text(t: &Text, path: &[FieldStep]) -> Result<Expr, DeriveError> {
    Expr::parse(&t.text()).map_err(|e| at(path, e.message))
}

fn to_expr(a: &A, what: &str) -> Result<Expr, DeriveError> {
    cas::expr(a).map_err(|m| at(&[], format!("{what}: {m}")))
}

/// `sin(asin(x)) = x`, `cos(asin(x)) = sqrt(1 - x^2)` and the like, applied bottom-up.
pub fn simplify_inverse_trig(e: &Expr) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(simplify_inverse_trig).collect::<Vec<_>>();
    match e {
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(simplify_inverse_trig(b)),
            Box::new(simplify_inverse_trig(x)),
        ),
        Expr::Fun(f, args) => {
            let args = rec(args);
            if let Some(Expr::Fun(g, inner)) = args.first() {
                let x = inner[0].clone();
                // sqrt((1 - x)(1 + x)): no cancellation in 1 - x^2 as x -> 1.
                let one_minus_sq = || {
                    let minus_x = Expr::Mul(vec![Expr::int(-1), x.clone()]);
                    Expr::Pow(
                        Box::new(Expr::Mul(vec![
                            Expr::Add(vec![Expr::int(1), minus_x]),
                            Expr::Add(vec![Expr::int(1), x.clone()]),
                        ])),
                        Box::new(Expr::Rational(1, 2)),
                    )
                };
                match (f.as_str(), g.as_str()) {
                    ("sin", "asin") | ("cos", "acos") => return x,
                    ("cos", "asin") | ("sin", "acos") => return one_minus_sq(),
                    _ => {}
                }
            }
            Expr::Fun(f.clone(), args)
        }
        _ => e.clone(),
    }
}

/// The total time derivative along the full state.
struct Kin {
    coords: Vec<String>,
}

impl Kin {
    fn dt(&self, f: &A) -> A {
        let mut out = cas::num(0);
        for c in &self.coords {
            out = out
                + cas::d(f, c) * cas::var(&format!("dot_{c}"))
                + cas::d(f, &format!("dot_{c}")) * cas::var(&format!("ddot_{c}"));
        }
        cas::expand(&out)
    }
}

/// Replaces `cos^k` by `cos^(k mod 2) (1 - sin^2)^(k div 2)` in an expanded polynomial of
/// `rc_s`, `rc_c`, so that results are unique modulo `sin^2 + cos^2 = 1`.
pub fn reduce_cos_sq(a: &A) -> A {
    let mut cur = cas::expand(a);
    for _ in 0..16 {
        let mut next = cur.clone();
        for k in (2..=12).rev() {
            let pat = cas::atom(&Expr::parse(&format!("rc_c^{k}")).unwrap_or(Expr::int(0)));
            let rep = cas::atom(
                &Expr::parse(&format!("rc_c^{}*(1 - rc_s^2)^{}", k % 2, k / 2))
                    .unwrap_or(Expr::int(0)),
            );
            next = cas::subs(&next, &pat, &rep);
        }
        next = cas::expand(&next);
        if next == cur {
            break;
        }
        cur = next;
    }
    cur
}

/// Whether a rational expression of `rc_s`, `rc_c` (and anything else) is zero modulo
/// `sin^2 + cos^2 = 1`.
pub fn is_zero_trig(a: &A) -> Result<bool, String> {
    let t = cas::together(a);
    let e = cas::expr(&t)?;
    let (num, _) = e.num_den();
    let n = cas::atom(&product(num));
    Ok(cas::is_zero(&reduce_cos_sq(&n)))
}

/// Replaces `sin(theta)`, `cos(theta)` by `rc_s`, `rc_c`.
fn to_sc(a: &A, theta: &str) -> A {
    let s = cas::subs(
        a,
        &cas::atom(&Expr::Fun("sin".into(), vec![Expr::sym(theta)])),
        &cas::var("rc_s"),
    );
    cas::subs(
        &s,
        &cas::atom(&Expr::Fun("cos".into(), vec![Expr::sym(theta)])),
        &cas::var("rc_c"),
    )
}

/// Replaces `rc_s`, `rc_c` by `sin(theta)`, `cos(theta)` in a plain expression.
pub fn from_sc(e: &Expr, theta: &str) -> Expr {
    match e {
        Expr::Sym(s) if s == "rc_s" => Expr::Fun("sin".into(), vec![Expr::sym(theta)]),
        Expr::Sym(s) if s == "rc_c" => Expr::Fun("cos".into(), vec![Expr::sym(theta)]),
        Expr::Add(v) => Expr::Add(v.iter().map(|x| from_sc(x, theta)).collect()),
        Expr::Mul(v) => Expr::Mul(v.iter().map(|x| from_sc(x, theta)).collect()),
        Expr::Pow(b, x) => Expr::Pow(Box::new(from_sc(b, theta)), Box::new(from_sc(x, theta))),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), v.iter().map(|x| from_sc(x, theta)).collect()),
        _ => e.clone(),
    }
}

/// Groups the terms of an expanded expression by their factors in `motion` symbols and brings
/// each group's coefficient over one denominator: `sum_m together(sum c_i) * m`.
///
/// Expanded, the reduced forces of a model with a cyclic coordinate hold parameter-only terms
/// that nearly cancel (`m1 ell m2/(2(m1+m2)) - ell m2 + ell m2^2/(m1+m2)` in rod_cube's contact
/// force is `-m1 m2 ell/(2(m1+m2))`): emitted as they are, the force loses `log10(m2/m1)`
/// digits for a heavy cube. Together, each coefficient is one term and keeps them.
fn collect_over(a: &A, motion: &[&str]) -> Result<A, DeriveError> {
    let e = to_expr(a, "expression to collect")?;
    let terms = match e {
        Expr::Add(v) => v,
        e => vec![e],
    };
    // (key, motion factors, coefficient terms), in order of first appearance.
    let mut groups: Vec<(String, Vec<Expr>, Vec<Expr>)> = Vec::new();
    for t in terms {
        let factors = match t {
            Expr::Mul(v) => v,
            t => vec![t],
        };
        let (mut moving, coefficient): (Vec<Expr>, Vec<Expr>) = factors
            .into_iter()
            .partition(|f| f.symbols().iter().any(|s| motion.contains(&s.as_str())));
        moving.sort_by_key(|f| f.to_infix());
        let key = moving
            .iter()
            .map(|f| f.to_infix())
            .collect::<Vec<_>>()
            .join("*");
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.2.push(product(coefficient)),
            None => groups.push((key, moving, vec![product(coefficient)])),
        }
    }
    let mut out = cas::num(0);
    for (_, moving, coefficients) in groups {
        let c = cas::together(&cas::atom(&Expr::Add(coefficients)));
        out += c * cas::atom(&product(moving));
    }
    Ok(out)
}

fn free_of(a: &A, names: &[&str]) -> bool {
    names.iter().all(|n| cas::is_zero(&cas::d(a, n)))
}

/// Runs the derivation for one checked spec.
pub fn derive(checked: &Checked) -> Result<Derivation, DeriveError> {
    let spec = &checked.spec;
    let params: Vec<String> = spec.parameters.iter().map(|p| p.name.clone()).collect();
    let coords: Vec<String> = spec.coordinates.iter().map(|c| c.name.clone()).collect();
    let reduced = coords.iter().position(|c| *c == spec.reduced).unwrap_or(0);
    let theta = coords[reduced].clone();
    let kin = Kin {
        coords: coords.clone(),
    };
    let g = cas::var(&spec.gravity);
    let half = cas::atom(&Expr::Rational(1, 2));

    // --- Energies and the Lagrangian -------------------------------------------------------
    let mut t_kin = cas::num(0);
    let mut v_pot = cas::num(0);
    let mut body_pos: BTreeMap<String, [A; 2]> = BTreeMap::new();
    let mut body_mass: BTreeMap<String, A> = BTreeMap::new();
    for (i, b) in spec.bodies.iter().enumerate() {
        let path = [key("bodies"), FieldStep::Index(i)];
        let m = cas::atom(&parse_text(&b.mass, &path)?);
        let inertia = cas::atom(&parse_text(&b.inertia, &path)?);
        let x = cas::atom(&parse_text(&b.position[0], &path)?);
        let y = cas::atom(&parse_text(&b.position[1], &path)?);
        let angle = cas::atom(&parse_text(&b.angle, &path)?);
        let (vx, vy, w) = (kin.dt(&x), kin.dt(&y), kin.dt(&angle));
        t_kin = t_kin
            + half.clone() * m.clone() * (vx.clone() * vx + vy.clone() * vy)
            + half.clone() * inertia * w.clone() * w;
        v_pot += m.clone() * g.clone() * y.clone();
        body_pos.insert(b.name.clone(), [x, y]);
        body_mass.insert(b.name.clone(), m);
    }
    let t_kin = cas::expand(&t_kin);
    let v_pot = cas::expand(&v_pot);
    let lag = t_kin.clone() - v_pot.clone();

    // --- Euler–Lagrange equations: M(q) qdd = F(q, qd) -----------------------------------
    let n = coords.len();
    let dots: Vec<String> = coords.iter().map(|c| format!("dot_{c}")).collect();
    let ddots: Vec<String> = coords.iter().map(|c| format!("ddot_{c}")).collect();
    let mut el = Vec::new();
    let mut mass = Vec::new();
    let mut rhs = Vec::new();
    for i in 0..n {
        let e = cas::expand(&(kin.dt(&cas::d(&lag, &dots[i])) - cas::d(&lag, &coords[i])));
        let mut row = Vec::new();
        let mut at_rest = e.clone();
        for dd in &ddots {
            row.push(cas::expand(&cas::d(&e, dd)));
            at_rest = cas::subs_var(&at_rest, dd, &cas::num(0));
        }
        rhs.push(cas::expand(&(cas::num(0) - at_rest)));
        mass.push(row);
        el.push(e);
    }

    // --- Cyclic coordinates and their conserved momenta ----------------------------------
    let mut cyclic = Vec::new();
    for (i, c) in coords.iter().enumerate() {
        if i == reduced {
            continue;
        }
        let dl = cas::d(&lag, c);
        if !cas::is_zero(&dl) {
            let shown = to_expr(&cas::expand(&dl), "dL/dq")?.to_infix();
            return Err(at(
                &[key("coordinates"), FieldStep::Index(i)],
                format!(
                    "coordinate `{c}` cannot be eliminated: the Lagrangian depends on it \
                     (dL/d{c} = {shown}); only cyclic coordinates besides `{theta}` are supported"
                ),
            ));
        }
        cyclic.push(i);
    }
    let momenta: Vec<A> = cyclic
        .iter()
        .map(|&i| cas::expand(&cas::d(&lag, &dots[i])))
        .collect();
    for &i in &cyclic {
        for &j in &cyclic {
            if !free_of(&mass[i][j], &[theta.as_str()]) {
                return Err(at(
                    &[key("coordinates"), FieldStep::Index(i)],
                    format!(
                        "the inertia of cyclic coordinate `{}` depends on `{theta}`; the closed-form \
                         reduction needs it constant",
                        coords[i]
                    ),
                ));
            }
        }
    }

    // --- Constants of the motion -----------------------------------------------------------
    let init = |c: &str, what: usize| -> Result<Expr, DeriveError> {
        let s = &spec.initial[c];
        let path = [key("initial"), key(c)];
        parse_text(if what == 0 { &s.position } else { &s.velocity }, &path)
    };
    // sin and cos of the start are formed from the start's own expression where it is an
    // inverse function (sin(asin(a/ell)) = a/ell exactly; cos(asin(x)) = sqrt((1-x)(1+x)),
    // which keeps full relative accuracy near upright, unlike cos of an angle near pi/2).
    let theta_i = init(&theta, 0)?;
    let start_trig = |f: &str| match &theta_i {
        Expr::Fun(g, _) if g == "asin" || g == "acos" => {
            simplify_inverse_trig(&Expr::Fun(f.into(), vec![theta_i.clone()]))
        }
        _ => Expr::Fun(f.into(), vec![Expr::sym("rc_thi")]),
    };
    let mut constants = vec![
        Constant {
            symbol: "rc_thi".into(),
            value: theta_i.clone(),
        },
        Constant {
            symbol: "rc_wi".into(),
            value: init(&theta, 1)?,
        },
        Constant {
            symbol: "rc_si".into(),
            value: start_trig("sin"),
        },
        Constant {
            symbol: "rc_ci".into(),
            value: start_trig("cos"),
        },
    ];
    // A constant whose definition is a number (a start from rest) is used as that number, so
    // that the derived forms simplify exactly as a person would simplify them.
    let numeric = |c: &Constant| -> Option<A> {
        let t = c.value.tidy();
        t.symbols().is_empty().then(|| cas::atom(&t))
    };
    let wi = numeric(&constants[1]).unwrap_or_else(|| cas::var("rc_wi"));
    // The initial full state as substitutions.
    let initial_state = |a: &A| -> A {
        let mut out = to_sc(a, &theta);
        out = cas::subs_var(&out, "rc_s", &cas::var("rc_si"));
        out = cas::subs_var(&out, "rc_c", &cas::var("rc_ci"));
        out = cas::subs_var(&out, &theta, &cas::var("rc_thi"));
        out = cas::subs_var(&out, &format!("dot_{theta}"), &wi);
        for (j, &i) in cyclic.iter().enumerate() {
            out = cas::subs_var(&out, &coords[i], &cas::var(&format!("rc_x{j}i")));
        }
        out
    };
    let mut cyclic_init_vel = Vec::new();
    for (j, &i) in cyclic.iter().enumerate() {
        constants.push(Constant {
            symbol: format!("rc_x{j}i"),
            value: init(&coords[i], 0)?,
        });
        cyclic_init_vel.push(cas::atom(&init(&coords[i], 1)?));
    }
    for (j, p) in momenta.iter().enumerate() {
        let mut v = initial_state(p);
        for (jj, &i) in cyclic.iter().enumerate() {
            v = cas::subs_var(&v, &dots[i], &cyclic_init_vel[jj]);
        }
        constants.push(Constant {
            symbol: format!("rc_p{j}"),
            value: to_expr(&cas::expand(&v), "momentum")?,
        });
    }
    let momentum_value: Vec<A> = (0..cyclic.len())
        .map(|j| {
            let c = constants.iter().find(|c| c.symbol == format!("rc_p{j}"));
            c.and_then(&numeric)
                .unwrap_or_else(|| cas::var(&format!("rc_p{j}")))
        })
        .collect();

    // --- Cyclic velocities from the conserved momenta: M_CC qd_C = P - M_Cr w --------------
    let w = cas::var("rc_w");
    let k = cyclic.len();
    let mut mat: Vec<Vec<A>> = cyclic
        .iter()
        .map(|&i| cyclic.iter().map(|&j| to_sc(&mass[i][j], &theta)).collect())
        .collect();
    let mut vec_b: Vec<A> = cyclic
        .iter()
        .enumerate()
        .map(|(jj, &i)| momentum_value[jj].clone() - to_sc(&mass[i][reduced], &theta) * w.clone())
        .collect();
    for col in 0..k {
        let pivot = (col..k)
            .find(|&r| !cas::is_zero(&mat[r][col]))
            .ok_or_else(|| {
                at(
                    &[key("coordinates")],
                    "the cyclic velocities cannot be solved from their momenta (singular inertia)"
                        .into(),
                )
            })?;
        mat.swap(col, pivot);
        vec_b.swap(col, pivot);
        let p = mat[col][col].clone();
        let pivot_row = mat[col].clone();
        for r in 0..k {
            if r == col {
                continue;
            }
            let f = cas::together(&(mat[r][col].clone() / p.clone()));
            for (m, pc) in mat[r].iter_mut().zip(&pivot_row) {
                *m = cas::together(&(m.clone() - f.clone() * pc.clone()));
            }
            vec_b[r] = cas::together(&(vec_b[r].clone() - f.clone() * vec_b[col].clone()));
        }
    }
    let cyc_vel: Vec<A> = (0..k)
        .map(|r| cas::expand(&cas::together(&(vec_b[r].clone() / mat[r][r].clone()))))
        .collect();

    // --- Reduced energy, inertia, effective potential -------------------------------------
    let reduce_state = |a: &A| -> A {
        let mut out = to_sc(a, &theta);
        for (jj, &i) in cyclic.iter().enumerate() {
            out = cas::subs_var(&out, &dots[i], &cyc_vel[jj]);
        }
        cas::subs_var(&out, &dots[reduced], &w)
    };
    let e_red = cas::expand(&reduce_state(&(t_kin.clone() + v_pot.clone())));
    let e_red = cas::expand(&cas::together(&e_red));
    let inertia = reduce_cos_sq(&cas::expand(&cas::d(&cas::d(&e_red, "rc_w"), "rc_w")));
    let inertia = cas::expand(&cas::together(&inertia));
    let linear = cas::subs_var(&cas::d(&e_red, "rc_w"), "rc_w", &cas::num(0));
    if !is_zero_trig(&linear).map_err(|m| at(&[], m))? {
        return Err(at(
            &[key("coordinates")],
            "the reduced energy has a term linear in the angular velocity".into(),
        ));
    }
    let v_eff = cas::subs_var(&e_red, "rc_w", &cas::num(0));
    let beta = cas::expand(&cas::d(&v_eff, "rc_s"));
    let gamma = cas::expand(&cas::d(&v_eff, "rc_c"));
    let rest = cas::expand(
        &(v_eff.clone() - beta.clone() * cas::var("rc_s") - gamma.clone() * cas::var("rc_c")),
    );
    if !(free_of(&beta, &["rc_s", "rc_c", &theta])
        && free_of(&gamma, &["rc_s", "rc_c", &theta])
        && free_of(&rest, &["rc_s", "rc_c", &theta]))
    {
        return Err(at(
            &[key("bodies")],
            format!(
                "the effective potential is not of the form alpha + beta sin({theta}) + gamma cos({theta}); such models are not supported"
            ),
        ));
    }
    let ai = cas::subs_var(
        &cas::subs_var(&inertia, "rc_s", &cas::var("rc_si")),
        "rc_c",
        &cas::var("rc_ci"),
    );
    constants.push(Constant {
        symbol: "rc_ai".into(),
        value: to_expr(&cas::expand(&ai), "initial inertia")?,
    });
    let two = cas::num(2);
    let wsq = (cas::var("rc_ai") * wi.clone() * wi.clone()
        + two.clone() * beta.clone() * cas::var("rc_ds")
        + two.clone() * gamma.clone() * cas::var("rc_dc"))
        / inertia.clone();
    let wsq = cas::together(&wsq);
    let d_theta = |f: &A| -> A {
        cas::d(f, "rc_s") * cas::var("rc_c")
            - cas::d(f, "rc_c") * cas::var("rc_s")
            - cas::d(f, "rc_ds") * cas::var("rc_c")
            + cas::d(f, "rc_dc") * cas::var("rc_s")
    };
    let acc = cas::together(&(half.clone() * d_theta(&wsq)));

    // --- Cyclic positions and accelerations on the reduced motion -------------------------
    let mut cyclic_position = Vec::new();
    let mut cyc_acc = Vec::new();
    for (jj, v) in cyc_vel.iter().enumerate() {
        let a0 = cas::expand(&cas::subs_var(v, "rc_w", &cas::num(0)));
        let b = cas::expand(&cas::d(v, "rc_w"));
        let bs = cas::expand(&cas::d(&b, "rc_s"));
        let bc = cas::expand(&cas::d(&b, "rc_c"));
        let b0 = cas::expand(
            &(b.clone() - bs.clone() * cas::var("rc_s") - bc.clone() * cas::var("rc_c")),
        );
        let ok = free_of(&a0, &["rc_s", "rc_c", "rc_w"])
            && free_of(&bs, &["rc_s", "rc_c", "rc_w"])
            && free_of(&bc, &["rc_s", "rc_c", "rc_w"])
            && free_of(&b0, &["rc_s", "rc_c", "rc_w"]);
        if !ok {
            return Err(at(
                &[key("coordinates"), FieldStep::Index(cyclic[jj])],
                format!(
                    "the velocity of `{}` is not affine in sin/cos of `{theta}`; its position has no closed form here",
                    coords[cyclic[jj]]
                ),
            ));
        }
        let pos = cas::var(&format!("rc_x{jj}i"))
            + a0 * cas::var("rc_t")
            + bs.clone() * cas::var("rc_dc")
            - bc.clone() * cas::var("rc_ds")
            - b0 * cas::var("rc_delta");
        cyclic_position.push(to_expr(&cas::expand(&pos), "cyclic position")?);
        let bprime = bs * cas::var("rc_c") - bc * cas::var("rc_s");
        cyc_acc.push(cas::expand(
            &(bprime * cas::var("rc_w2") + b * cas::var("rc_acc")),
        ));
    }

    // --- Reaction forces ------------------------------------------------------------------
    let mut forces_full = Vec::new();
    let mut forces_reduced = Vec::new();
    for (i, f) in spec.forces.iter().enumerate() {
        let [x, y] = &body_pos[&f.body];
        let m = &body_mass[&f.body];
        let (ax, ay) = (kin.dt(&kin.dt(x)), kin.dt(&kin.dt(y)));
        let d0 = cas::atom(&Expr::Float(f.direction[0]));
        let d1 = cas::atom(&Expr::Float(f.direction[1]));
        let d0 = rationalize(&d0, f.direction[0]);
        let d1 = rationalize(&d1, f.direction[1]);
        let full =
            cas::expand(&(m.clone() * (d0 * ax + d1.clone() * ay) + m.clone() * g.clone() * d1));
        // reduced: cyclic accelerations, then theta's
        let mut r = to_sc(&full, &theta);
        for (jj, &ci) in cyclic.iter().enumerate() {
            r = cas::subs_var(&r, &ddots[ci], &cyc_acc[jj]);
            r = cas::subs_var(&r, &dots[ci], &cyc_vel[jj]);
        }
        r = cas::subs_var(&r, &ddots[reduced], &cas::var("rc_acc"));
        r = cas::expand(&cas::subs_var(&r, &dots[reduced], &w));
        let f0 = cas::subs_var(&r, "rc_w", &cas::num(0));
        let f1 = cas::subs_var(&cas::d(&r, "rc_w"), "rc_w", &cas::num(0));
        let f2 = cas::expand(&(half.clone() * cas::d(&cas::d(&r, "rc_w"), "rc_w")));
        let f3 = cas::d(&f2, "rc_w");
        if !cas::is_zero(&f1) || !cas::is_zero(&f3) {
            return Err(at(
                &[key("forces"), FieldStep::Index(i)],
                format!(
                    "force `{}` is not of the form F0 + F2 theta_dot^2 on the reduced motion",
                    f.name
                ),
            ));
        }
        let red = collect_over(
            &cas::expand(&(f0 + f2 * cas::var("rc_w2"))),
            &["rc_s", "rc_c", "rc_w2", "rc_acc"],
        )?;
        forces_full.push(to_expr(&full, "force")?);
        forces_reduced.push(red);
    }

    // --- Monitors and requirements --------------------------------------------------------
    let mut monitors = Vec::new();
    for (i, m) in spec.monitors.iter().enumerate() {
        let mut e = cas::atom(&parse_text(
            &m.expr,
            &[key("monitors"), FieldStep::Index(i)],
        )?);
        for (fi, f) in spec.forces.iter().enumerate() {
            e = cas::subs_var(&e, &f.name, &cas::var(&format!("rc_f{fi}")));
        }
        e = to_sc(&e, &theta);
        monitors.push(to_expr(&e, "monitor")?);
    }
    let mut requirements = Vec::new();
    for (i, r) in spec.requirements.iter().enumerate() {
        requirements.push(parse_text(
            &r.expr,
            &[key("requirements"), FieldStep::Index(i)],
        )?);
    }

    // --- Points ---------------------------------------------------------------------------
    let mut point_pos = Vec::new();
    let mut point_vel = Vec::new();
    for (i, p) in spec.points.iter().enumerate() {
        let path = [key("points"), FieldStep::Index(i)];
        let x = cas::atom(&parse_text(&p.position[0], &path)?);
        let y = cas::atom(&parse_text(&p.position[1], &path)?);
        point_vel.push([
            to_expr(&kin.dt(&x), "point velocity")?,
            to_expr(&kin.dt(&y), "point velocity")?,
        ]);
        point_pos.push([
            to_expr(&cas::expand(&x), "point")?,
            to_expr(&cas::expand(&y), "point")?,
        ]);
    }
    let surface_moves = spec.contact.as_ref().is_some_and(|c| {
        let idx = spec
            .points
            .iter()
            .position(|p| p.name == c.surface)
            .unwrap_or(0);
        point_pos[idx]
            .iter()
            .any(|e| e.symbols().iter().any(|s| coords.contains(s)))
    });

    // --- Separation condition -------------------------------------------------------------
    let subst_reduced = |a: &A| -> A {
        let mut out = cas::subs_var(a, "rc_w2", &wsq);
        out = cas::subs_var(&out, "rc_acc", &acc);
        out
    };
    let gap_vars = |a: &A| -> A {
        let out = cas::subs_var(a, "rc_ds", &(cas::var("rc_si") - cas::var("rc_s")));
        cas::subs_var(&out, "rc_dc", &(cas::var("rc_ci") - cas::var("rc_c")))
    };
    let separation = match &spec.contact {
        None => None,
        Some(c) => {
            let fi = spec
                .forces
                .iter()
                .position(|f| f.name == c.force)
                .unwrap_or(0);
            let f = cas::together(&gap_vars(&subst_reduced(&forces_reduced[fi])));
            let fe = to_expr(&f, "contact force")?;
            let (num, _) = fe.num_den();
            let numer = reduce_cos_sq(&cas::atom(&product(num)));
            let p0 = cas::expand(&cas::subs_var(&numer, "rc_c", &cas::num(0)));
            let p1 = cas::expand(&cas::subs_var(
                &cas::d(&numer, "rc_c"),
                "rc_c",
                &cas::num(0),
            ));
            let check = cas::expand(&(numer.clone() - p0.clone() - p1.clone() * cas::var("rc_c")));
            if !cas::is_zero(&check) {
                return Err(at(&[key("contact")], "the contact force's numerator is not linear in cos(theta) after sin^2 + cos^2 = 1".into()));
            }
            let poly = if cas::is_zero(&p1) {
                p0
            } else if cas::is_zero(&p0) {
                p1
            } else {
                return Err(at(
                    &[key("contact")],
                    "the separation condition mixes sin(theta) and cos(theta); it is not a polynomial in sin(theta)".into(),
                ));
            };
            let poly = strip_positive_factors(&poly, &spec_positive(checked))?;
            let mut coefficients = Vec::new();
            let mut deriv = poly.clone();
            let mut factorial: i64 = 1;
            for deg in 0..=16i64 {
                if deg > 0 {
                    factorial *= deg;
                }
                let c0 = cas::expand(
                    &(cas::subs_var(&deriv, "rc_s", &cas::num(0)) / cas::num(factorial)),
                );
                coefficients.push(c0);
                deriv = cas::expand(&cas::d(&deriv, "rc_s"));
                if cas::is_zero(&deriv) {
                    break;
                }
            }
            if !cas::is_zero(&deriv) {
                return Err(at(
                    &[key("contact")],
                    "the separation polynomial has a degree above 16".into(),
                ));
            }
            let coefficients = coefficients
                .iter()
                .map(|c| to_expr(c, "coefficient"))
                .collect::<Result<Vec<_>, _>>()?;
            Some(Separation {
                coefficients,
                polynomial: to_expr(&poly, "separation polynomial")?,
            })
        }
    };

    // --- Plain forms over parameters and theta --------------------------------------------
    let mut const_plain: Vec<(String, A)> = Vec::new();
    for c in &constants {
        let mut v = cas::atom(&simplify_inverse_trig(&c.value));
        for (s, val) in &const_plain {
            v = cas::subs_var(&v, s, val);
        }
        let v = cas::atom(&simplify_inverse_trig(&to_expr(&v, "constant")?));
        const_plain.push((c.symbol.clone(), v));
    }
    let plainify = |a: &A| -> Result<Expr, DeriveError> {
        let mut v = gap_vars(a);
        for (s, val) in const_plain.iter().rev() {
            v = cas::subs_var(&v, s, val);
        }
        let v = to_expr(&cas::together(&v), "plain form")?;
        let (num, den) = v.num_den();
        let num = reduce_cos_sq(&cas::atom(&product(num)));
        let den = reduce_cos_sq(&cas::atom(&product(den)));
        let v = cas::together(&cas::factor(&(num / den)));
        Ok(from_sc(&to_expr(&v, "plain form")?, &theta))
    };
    let mut plain = BTreeMap::new();
    plain.insert("theta_dot_sq", plainify(&wsq)?);
    plain.insert("theta_ddot", plainify(&acc)?);
    plain.insert("reduced_inertia", plainify(&inertia)?);
    plain.insert("lagrangian", to_expr(&lag, "lagrangian")?);
    if let Some(c) = &spec.contact {
        let fi = spec
            .forces
            .iter()
            .position(|f| f.name == c.force)
            .unwrap_or(0);
        plain.insert(
            "contact_force",
            plainify(&subst_reduced(&forces_reduced[fi]))?,
        );
    }
    if let Some(sep) = &separation {
        plain.insert(
            "separation_condition",
            plainify(&cas::atom(&sep.polynomial))?,
        );
    }
    for (i, f) in spec.forces.iter().enumerate() {
        if spec.contact.as_ref().is_some_and(|c| c.force == f.name) {
            continue;
        }
        let key: &'static str = Box::leak(f.name.clone().into_boxed_str());
        plain.insert(key, plainify(&subst_reduced(&forces_reduced[i]))?);
    }

    Ok(Derivation {
        params,
        coords,
        reduced,
        cyclic,
        kinetic: to_expr(&t_kin, "kinetic energy")?,
        potential: to_expr(&v_pot, "potential energy")?,
        euler_lagrange: el
            .iter()
            .map(|e| to_expr(e, "equation"))
            .collect::<Result<_, _>>()?,
        mass: mass
            .iter()
            .map(|r| {
                r.iter()
                    .map(|e| to_expr(e, "mass matrix"))
                    .collect::<Result<Vec<_>, _>>()
            })
            .collect::<Result<_, _>>()?,
        rhs: rhs
            .iter()
            .map(|e| to_expr(e, "forces"))
            .collect::<Result<_, _>>()?,
        momenta: momenta
            .iter()
            .map(|e| to_expr(e, "momentum"))
            .collect::<Result<_, _>>()?,
        point_pos,
        point_vel,
        forces_full,
        constants,
        reduced_inertia: to_expr(&inertia, "inertia")?,
        reduced_energy: to_expr(&e_red, "reduced energy")?,
        theta_dot_sq: to_expr(&wsq, "theta_dot_sq")?,
        theta_ddot: to_expr(&acc, "theta_ddot")?,
        cyclic_velocity: cyc_vel
            .iter()
            .map(|e| to_expr(e, "cyclic velocity"))
            .collect::<Result<_, _>>()?,
        cyclic_position,
        forces_reduced: forces_reduced
            .iter()
            .map(|e| to_expr(e, "force"))
            .collect::<Result<_, _>>()?,
        monitors,
        requirements,
        separation,
        surface_moves,
        plain,
    })
}

/// Exact rational for the small direction components specs use (0, ±1, ±1/2, ...).
fn rationalize(a: &A, x: f64) -> A {
    for den in 1..=12i64 {
        let num = x * den as f64;
        if (num - num.round()).abs() < 1e-14 {
            return cas::atom(&Expr::Rational(num.round() as i128, den as i128));
        }
    }
    a.clone()
}

/// Symbols known to be strictly positive: positive parameters and the start's sin and cos.
fn spec_positive(checked: &Checked) -> Vec<String> {
    let mut v: Vec<String> = checked
        .spec
        .parameters
        .iter()
        .filter(|p| p.positive)
        .map(|p| p.name.clone())
        .collect();
    v.push("rc_si".into());
    v.push("rc_ci".into());
    v
}

fn positive(e: &Expr, pos: &[String]) -> bool {
    match e {
        Expr::Rational(n, _) => *n > 0,
        Expr::Float(x) => *x > 0.0,
        Expr::Sym(s) => pos.contains(s),
        Expr::Add(v) | Expr::Mul(v) => v.iter().all(|x| positive(x, pos)),
        Expr::Pow(b, x) => positive(b, pos) || x.as_integer().is_some_and(|n| n % 2 == 0),
        Expr::Fun(..) => false,
    }
}

/// Factorises and drops the factors free of `rc_s` that are strictly positive (or negative
/// constants), so that what is left is the separation polynomial up to a positive factor.
fn strip_positive_factors(poly: &A, pos: &[String]) -> Result<A, DeriveError> {
    let f = to_expr(&cas::factor(poly), "factorised separation polynomial")?;
    let factors = match f {
        Expr::Mul(v) => v,
        e => vec![e],
    };
    let mut kept = Vec::new();
    for x in factors {
        let has_s = x.symbols().contains("rc_s");
        if has_s {
            kept.push(x);
            continue;
        }
        let (neg, mag) = x.split_sign();
        if positive(&mag, pos) || (neg && mag.symbols().is_empty()) {
            continue;
        }
        kept.push(x);
    }
    Ok(cas::expand(&cas::atom(&product(kept))))
}
