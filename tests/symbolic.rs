//! The symbolic derivation, run in-process on the specs in `derivations/`, reproduces the paper's
//! equations (5), (9), (14), (16), (18) and the corrected (12) in rod_cube's contact phase
//! (`rod_cube_closed`, both contacts closed) *by equivalence*: each difference is zero as a
//! rational function of sin(theta), cos(theta) modulo sin^2 + cos^2 = 1 (never by comparing
//! strings); and the floor's push under the foot. Also the contact phases of the hinged rod (with
//! its hinge's two forces), the ladder on a wall, and the loaded rod against hand computations,
//! and negative controls showing a wrong formula is caught.
#![cfg(feature = "derive")]

use rodcube::derive::cas;
use rodcube::derive::expr::Expr;
use rodcube::derive::mechanics::{self, Derivation, Reduction};
use rodcube::derive::positivity::{push_proof, release_proof};
use rodcube::derive::types::ProofStep;
use rodcube::derive::{derive_all, on_cas_thread, spec};
use std::path::Path;

/// Derives the spec `derivations/<spec>.yaml` and returns its contact phase `<spec>_closed`
/// (every contact closed, the coordinates they tie eliminated).
fn derive(spec: &str) -> Derivation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("derivations")
        .join(format!("{spec}.yaml"));
    let checked = spec::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut out = derive_all(&[checked]).unwrap_or_else(|e| panic!("{e}"));
    let phases = out.remove(0).0;
    let name = format!("{spec}_closed");
    let names: Vec<String> = phases.iter().map(|d| d.name.clone()).collect();
    let d = (phases.into_iter())
        .find(|d| d.name == name)
        .unwrap_or_else(|| panic!("no phase {name} among {names:?}"));
    assert_eq!(d.system, spec);
    assert!(d.contacts.iter().all(|c| c.closed), "{name}");
    d
}

/// The fast path of a derived phase.
fn red(d: &Derivation) -> &Reduction {
    d.reduction
        .as_ref()
        .unwrap_or_else(|why| panic!("{} has no fast path: {why}", d.name))
}

/// Replaces `sin(theta)`, `cos(theta)` by the derivation's symbols `rc_s`, `rc_c`.
fn sc(e: &Expr) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(sc).collect::<Vec<_>>();
    match e {
        Expr::Fun(f, args) if args.len() == 1 && args[0] == Expr::sym("theta") => {
            match f.as_str() {
                "sin" => Expr::sym("rc_s"),
                "cos" => Expr::sym("rc_c"),
                _ => e.clone(),
            }
        }
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(Box::new(sc(b)), Box::new(sc(x))),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), rec(v)),
        _ => e.clone(),
    }
}

/// A plain derived form over the parameters, `rc_s` and `rc_c`.
fn plain(d: &Derivation, key: &str) -> Expr {
    let e = red(d)
        .plain
        .get(key)
        .unwrap_or_else(|| panic!("no plain form `{key}`"));
    let e = sc(e);
    assert!(
        !e.symbols().contains("theta"),
        "`{key}` still has a bare theta: {}",
        e.to_infix()
    );
    e
}

fn parse(text: &str) -> Expr {
    Expr::parse(text).unwrap_or_else(|e| panic!("test formula `{text}`: {}", e.message))
}

/// Replaces shorthand symbols by their definitions.
fn expand_shorthands(text: &str, defs: &[(&str, &str)]) -> Expr {
    defs.iter().fold(parse(text), |e, (name, value)| {
        subs(&e, name, &parse(value))
    })
}

/// A formula in the paper's shorthands: `n = m2/m1`, `r = a/ell`, `S = sin`, `C = cos`.
fn paper(text: &str) -> Expr {
    expand_shorthands(
        text,
        &[("n", "m2/m1"), ("r", "a/ell"), ("S", "rc_s"), ("C", "rc_c")],
    )
}

/// Whether `a - b` is zero as a rational function modulo sin^2 + cos^2 = 1.
fn equivalent(a: &Expr, b: &Expr) -> bool {
    let diff = Expr::Add(vec![a.clone(), Expr::Mul(vec![Expr::int(-1), b.clone()])]);
    on_cas_thread(move || mechanics::is_zero_trig(&cas::atom(&diff)))
        .expect("Symbolica worker")
        .expect("is_zero_trig")
}

fn assert_equivalent(what: &str, derived: &Expr, expected: &Expr) {
    assert!(
        equivalent(derived, expected),
        "{what}: derived\n  {}\nis not equivalent to\n  {}",
        derived.to_infix(),
        expected.to_infix()
    );
}

/// Structurally positive for positive symbols: sums, products and powers of positive parts.
fn positive(e: &Expr, pos: &[&str]) -> bool {
    match e {
        Expr::Rational(n, d) => *n > 0 && *d > 0,
        Expr::Float(x) => *x > 0.0,
        Expr::Sym(s) => pos.contains(&s.as_str()),
        Expr::Add(v) | Expr::Mul(v) => v.iter().all(|x| positive(x, pos)),
        Expr::Pow(b, _) => positive(b, pos),
        Expr::Fun(..) => false,
    }
}

/// `derived / expected` as one rational function, if it is free of theta (no `rc_s`, `rc_c`,
/// and its derivative in `rc_s` vanishes) and structurally positive.
fn positive_multiple(derived: &Expr, expected: &Expr, pos: &[&str]) -> Result<Expr, String> {
    let quotient = Expr::Mul(vec![
        derived.clone(),
        Expr::Pow(Box::new(expected.clone()), Box::new(Expr::int(-1))),
    ]);
    let (ratio, d_ratio) = on_cas_thread(move || {
        let q = cas::together(&cas::atom(&quotient));
        let dq = cas::together(&cas::d(&q, "rc_s"));
        (cas::expr(&q), mechanics::is_zero_trig(&dq))
    })
    .map_err(|e| e.to_string())?;
    let ratio = ratio.map_err(|e| e.to_string())?;
    let syms = ratio.symbols();
    if syms.contains("rc_s") || syms.contains("rc_c") || d_ratio != Ok(true) {
        return Err(format!("ratio depends on theta: {}", ratio.to_infix()));
    }
    if !positive(&ratio, pos) {
        return Err(format!(
            "ratio {} is not a positive expression of {pos:?}",
            ratio.to_infix()
        ));
    }
    Ok(ratio)
}

fn assert_positive_multiple(what: &str, derived: &Expr, expected: &Expr, pos: &[&str]) -> Expr {
    positive_multiple(derived, expected, pos).unwrap_or_else(|e| {
        panic!(
            "{what}: {e}\n  derived  {}\n  expected {}",
            derived.to_infix(),
            expected.to_infix()
        )
    })
}

const MASSES: &[&str] = &["m1", "m2", "m3", "ell", "a", "g"];

// ---------------------------------------------------------------------------------------------
// rod_cube: the paper's model
// ---------------------------------------------------------------------------------------------

/// Eq (9): theta'^2 = 4 (g/ell) (a/ell - sin) / (4/3 - sin^2/(1+n)).
const EQ9: &str = "4*(g/ell)*(r - S)/(4/3 - S^2/(1 + n))";
/// Eq (14), the separation cubic.
const EQ14: &str = "3*S^3 - 12*(1 + n)*S + 8*r*(1 + n)";
/// Eq (14) with the push's sign: eq (16) is `-3 g m2 cos(theta) / (4(1+n) - 3 S^2)^2` times eq
/// (14), and a separation condition has its force's sign on the phase (`Reduction::
/// force_polynomial`).
const EQ14_PUSH: &str = "-(3*S^3 - 12*(1 + n)*S + 8*r*(1 + n))";
/// Eq (16), the contact force.
const EQ16: &str = "m2*(-3*g*C*(8*r*(1 + n) - 12*(1 + n)*S + 3*S^3)/(4*(1 + n) - 3*S^2)^2)";
/// PHYSICS.md erratum 2: the corrected eq (12), with D = 4/3 - sin^2/(1+n), sin 2theta = 2 S C.
const EQ12_CORRECTED: &str =
    "(2*g/ell)*(-C/(4/3 - S^2/(1 + n)) + (r - S)*2*S*C/((1 + n)*(4/3 - S^2/(1 + n))^2))";
/// Eq (12) as printed: its `(1 - 4 sin)` is `4 (r - sin)` at r = 1/4 only.
const EQ12_PRINTED: &str =
    "(g/(2*ell))*(-4*C/(4/3 - S^2/(1 + n)) + (1/(1 + n))*(1 - 4*S)*2*S*C/(4/3 - S^2/(1 + n))^2)";

#[test]
fn rod_cube_theta_dot_squared_is_eq_9() {
    let d = derive("rod_cube");
    assert_equivalent("theta_dot_sq", &plain(&d, "theta_dot_sq"), &paper(EQ9));
}

#[test]
fn rod_cube_separation_condition_is_eq_14_with_the_push_s_sign() {
    let d = derive("rod_cube");
    let ratio = assert_positive_multiple(
        "separation_condition",
        &plain(&d, "separation_condition"),
        &paper(EQ14_PUSH),
        MASSES,
    );
    // The factor is the rod's mass (the cubic is -m1 times eq 14).
    assert_equivalent("the factor", &ratio, &Expr::sym("m1"));
    // The generated coefficients are the same cubic: rc_si = sin(theta_i) = a/ell.
    let sep = red(&d).separation().expect("rod_cube_closed has a contact");
    assert_eq!(sep.coefficients.len(), 4);
    let poly = polynomial(&sep.coefficients);
    let poly = subs(&poly, "rc_si", &parse("a/ell"));
    assert_positive_multiple("coefficients", &poly, &paper(EQ14_PUSH), MASSES);
}

/// The polynomial `sum c_k rc_s^k` from its coefficients.
fn polynomial(coefficients: &[Expr]) -> Expr {
    Expr::Add(
        coefficients
            .iter()
            .enumerate()
            .map(|(k, c)| {
                Expr::Mul(vec![
                    c.clone(),
                    Expr::Pow(Box::new(Expr::sym("rc_s")), Box::new(Expr::int(k as i128))),
                ])
            })
            .collect(),
    )
}

/// Replaces a symbol by an expression.
fn subs(e: &Expr, name: &str, value: &Expr) -> Expr {
    let rec = |v: &Vec<Expr>| v.iter().map(|x| subs(x, name, value)).collect::<Vec<_>>();
    match e {
        Expr::Sym(s) if s == name => value.clone(),
        Expr::Add(v) => Expr::Add(rec(v)),
        Expr::Mul(v) => Expr::Mul(rec(v)),
        Expr::Pow(b, x) => Expr::Pow(
            Box::new(subs(b, name, value)),
            Box::new(subs(x, name, value)),
        ),
        Expr::Fun(f, v) => Expr::Fun(f.clone(), rec(v)),
        _ => e.clone(),
    }
}

#[test]
fn rod_cube_contact_force_is_eq_16() {
    let d = derive("rod_cube");
    assert_equivalent("contact_force", &plain(&d, "contact_force"), &paper(EQ16));
}

/// The floor's push under the foot, N = m1 (g + y_cm'') with eqs (9) and (12): a quartic in
/// sin(theta) over D^2, D = 4/3 - mu S^2, mu = 1/(1+n) (tests/common/paper.rs).
#[test]
fn rod_cube_floor_push_is_the_hand_quartic() {
    let d = derive("rod_cube");
    let quartic = expand_shorthands(
        "m1*g*(4/9 + (2*mu*r - 8*r/3)*S + (4 - 11*mu/3)*S^2 + (mu^2 - mu)*S^4)/(4/3 - mu*S^2)^2",
        &[
            ("mu", "1/(1 + n)"),
            ("n", "m2/m1"),
            ("r", "a/ell"),
            ("S", "rc_s"),
        ],
    );
    assert_equivalent("floor_normal", &plain(&d, "floor_normal"), &quartic);
    // And the same from Newton for the rod's centre, with the derived theta'^2 and theta''.
    let newton = Expr::Mul(vec![
        Expr::sym("m1"),
        Expr::Add(vec![
            Expr::sym("g"),
            Expr::Mul(vec![
                parse("ell/2"),
                Expr::Add(vec![
                    Expr::Mul(vec![Expr::sym("rc_c"), plain(&d, "theta_ddot")]),
                    Expr::Mul(vec![
                        Expr::int(-1),
                        Expr::sym("rc_s"),
                        plain(&d, "theta_dot_sq"),
                    ]),
                ]),
            ]),
        ]),
    ]);
    assert_equivalent(
        "floor_normal by Newton",
        &plain(&d, "floor_normal"),
        &newton,
    );
    // Its zero is the floor force polynomial's (up to a positive factor).
    let floor = red(&d).force_polynomials[1]
        .as_ref()
        .expect("the floor's push has a polynomial");
    assert_eq!(floor.coefficients.len(), 5);
    let poly = subs(&polynomial(&floor.coefficients), "rc_si", &parse("a/ell"));
    let numerator = expand_shorthands(
        "4/9 + (2*mu*r - 8*r/3)*S + (4 - 11*mu/3)*S^2 + (mu^2 - mu)*S^4",
        &[
            ("mu", "1/(1 + n)"),
            ("n", "m2/m1"),
            ("r", "a/ell"),
            ("S", "rc_s"),
        ],
    );
    assert_positive_multiple("floor coefficients", &poly, &numerator, MASSES);
}

/// The derivation proves the floor's push positive over the contact phase for every mass
/// (`derive::positivity`), as by hand: with `s^4 <= s^2` and `sin(theta_i) <= 1` the quartic is
/// above `4 M^2 - 6 M (m1 + 4 m2) s + 3 (m1^2 + 10 m1 m2 + 12 m2^2) s^2` (`M = m1 + m2`), whose
/// `4 a c - b^2 = M^2 (12 m1^2 + 192 m1 m2)` is positive. The contact on the cube, whose zero
/// ends the phase, gets no proof.
#[test]
fn rod_cube_floor_push_is_proved_positive_as_by_hand() {
    let d = derive("rod_cube");
    let r = red(&d);
    assert!(r.push_proofs[0].is_none());
    let proof = r.push_proofs[1]
        .as_ref()
        .expect("the floor's push is proved positive");
    let [a, b, c] = &proof.bound;
    assert_equivalent("a", a, &parse("4*(m1 + m2)^2"));
    assert_equivalent("b", b, &parse("-6*(m1 + m2)*(m1 + 4*m2)"));
    assert_equivalent("c", c, &parse("3*(m1^2 + 10*m1*m2 + 12*m2^2)"));
    let ProofStep::Discriminant(disc) = &proof.step else {
        panic!(
            "the floor's push is proved by a discriminant: {:?}",
            proof.step
        );
    };
    assert_equivalent(
        "4 a c - b^2",
        disc,
        &parse("(m1 + m2)^2*(12*m1^2 + 192*m1*m2)"),
    );
}

/// The tip pushes on the cube at release for every mass (`derive::positivity::release_proof`):
/// eq. (14)'s polynomial at `s = sin(theta_i)` is `sin(theta_i) (4 (m1 + m2) - 3 m1
/// sin(theta_i)^2)`, concave in `sin(theta_i)` and `m1 + 4 m2 > 0` at `sin(theta_i) = 1`.
#[test]
fn rod_cube_tip_is_proved_to_push_at_release() {
    let d = derive("rod_cube");
    let release = red(&d)
        .release_proof
        .as_ref()
        .expect("the tip pushes at release");
    assert_eq!(release.power, 1);
    assert_equivalent(
        "R",
        &release.polynomial,
        &parse("4*(m1 + m2) - 3*m1*rc_s^2"),
    );
    let ProofStep::Ends(end) = &release.proof.step else {
        panic!("concave: {:?}", release.proof.step);
    };
    assert_equivalent("a + b + c", end, &parse("m1 + 4*m2"));
}

/// `derive::positivity::release_proof` on hand-written polynomials: proved where the value at
/// `s = sin(theta_i)` is positive for `0 < sin(theta_i) <= 1`, refused where it is not.
#[test]
fn the_release_prover_claims_only_what_holds() {
    let cases: &[(&[&str], Option<usize>)] = &[
        // 12 M s - 8 M si - 3 m1 s^3 at s = si: si (4 M - 3 m1 si^2).
        (
            &["-8*(m1 + m2)*rc_si", "12*(m1 + m2)", "0", "-3*m1"],
            Some(1),
        ),
        // rc_si - 2 s at s = si: -si.
        (&["rc_si", "-2"], None),
        // 1 - 2 s: zero at si = 1/2.
        (&["1", "-2"], None),
        // m1 - m2 s: negative where m2 si > m1.
        (&["m1", "-m2"], None),
        // 2 - s^2 - s^4: zero at si = 1.
        (&["2", "0", "-1", "0", "-1"], None),
        // s^2 (m1 + rc_ci): si^2 (m1 + ci), ci = cos(theta_i) >= 0.
        (&["0", "0", "m1 + rc_ci"], Some(2)),
    ];
    let powers = on_cases(cases.iter().map(|c| c.0), |c, pos| {
        release_proof(c, pos)
            .unwrap_or_else(|e| panic!("{e:?}"))
            .map(|p| p.power)
    });
    for ((c, want), power) in cases.iter().zip(powers) {
        assert_eq!(power, *want, "{c:?}");
    }
}

/// `prove` on each case's coefficients (parsed), on the Symbolica thread, with `m1` and `m2`
/// the positive symbols.
fn on_cases<'a, T: Send + 'static>(
    cases: impl Iterator<Item = &'a [&'a str]>,
    prove: fn(&[Expr], &[String]) -> T,
) -> Vec<T> {
    let cases: Vec<Vec<Expr>> = cases
        .map(|c| c.iter().map(|t| parse(t)).collect())
        .collect();
    on_cas_thread(move || {
        let pos = vec!["m1".to_string(), "m2".to_string()];
        cases.iter().map(|c| prove(c, &pos)).collect::<Vec<_>>()
    })
    .expect("the Symbolica worker")
}

/// `derive::positivity::push_proof` on pushes written by hand: what it proves holds, and a
/// push that reaches zero on `0 <= s <= sin(theta_i)`, or whose sign turns on a parameter of
/// unknown sign, is refused.
#[test]
fn the_push_prover_claims_only_what_holds() {
    // (coefficients, lowest degree first; what the proof must be: None for a refusal).
    let cases: &[(&[&str], Option<&str>)] = &[
        (&["m1", "0", "m2"], Some("signs")),
        (&["4*m1", "-4*m1", "2*m1"], Some("discriminant")),
        (&["2*m1", "-m1", "-m1/2"], Some("ends")),
        // sin(theta_i) - s is zero at the start.
        (&["rc_si", "-1"], None),
        // 1 - 3 s + s^2: a root at 0.38.
        (&["1", "-3", "1"], None),
        // (1 - 3 s)^2: a double root at 1/3.
        (&["1", "-6", "9"], None),
        // m1 - m2 s: negative for m2 > m1.
        (&["m1", "-m2"], None),
        // x of unknown sign.
        (&["1", "x"], None),
        // 2 - s^3 - s^4 is 0 at s = 1.
        (&["2", "0", "0", "-1", "-1"], None),
        // 3 - rc_si s - s^4 >= 3 - s - s^2 >= 1: concave, least at an end.
        (&["3", "-rc_si", "0", "0", "-1"], Some("ends")),
    ];
    let kinds = on_cases(cases.iter().map(|c| c.0), |c, pos| {
        let proof = push_proof(c, pos).unwrap_or_else(|e| panic!("{e:?}"));
        proof.map(|p| match p.step {
            ProofStep::Signs => "signs",
            ProofStep::Ends(_) => "ends",
            ProofStep::Discriminant(_) => "discriminant",
        })
    });
    for ((c, want), kind) in cases.iter().zip(kinds) {
        assert_eq!(kind, *want, "{c:?}");
    }
}

/// Over random pushes `sum c_k m^i sin(theta_i)^j s^k` with small integer `c_k`, every one the
/// prover proves is positive at every point of a grid of `0 <= s <= sin(theta_i) <= 1` and
/// masses from 1e-3 to 1e3, and every one it proves to push at release is positive at `s =
/// sin(theta_i)` for `0 < sin(theta_i) <= 1` (a soundness check against plain evaluation);
/// some of each are proved.
#[test]
fn every_push_the_prover_proves_is_positive_where_evaluated() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move |n: u64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state % n
    };
    let mut polys = Vec::new();
    for _ in 0..400 {
        let degree = 1 + next(4) as usize;
        let coefficients: Vec<Expr> = (0..=degree)
            .map(|k| {
                let c = next(13) as i128 - 6 + i128::from(k == 0) * 6;
                let mass = ["", "*m1", "*m1^2"][next(3) as usize];
                let start = ["", "*rc_si", "*rc_si^2", "*rc_ci"][next(4) as usize];
                parse(&format!("{c}{mass}{start}"))
            })
            .collect();
        polys.push(coefficients);
    }
    let checked = polys.clone();
    let proofs = on_cas_thread(move || {
        let pos = vec!["m1".to_string()];
        (polys.iter())
            .map(|c| {
                let over_phase = push_proof(c, &pos).unwrap_or_else(|e| panic!("{e:?}"));
                let at_release = release_proof(c, &pos).unwrap_or_else(|e| panic!("{e:?}"));
                (over_phase.is_some(), at_release.is_some())
            })
            .collect::<Vec<_>>()
    })
    .expect("the Symbolica worker");
    let value = |c: &[Expr], m1: f64, si: f64, s: f64| -> f64 {
        let ci = ((1.0 - si) * (1.0 + si)).sqrt();
        (c.iter().enumerate())
            .map(|(k, e)| {
                let at = |name: &str| match name {
                    "m1" => Some(m1),
                    "rc_si" => Some(si),
                    "rc_ci" => Some(ci),
                    _ => None,
                };
                e.eval(&at) * s.powi(k as i32)
            })
            .sum()
    };
    let (mut proved, mut at_release) = (0, 0);
    for (c, (proof, release)) in checked.iter().zip(proofs) {
        if release {
            at_release += 1;
            for m1 in [1e-3, 0.5, 1.0, 7.0, 1e3] {
                for i in 1..=40 {
                    let si = f64::from(i) / 40.0;
                    let v = value(c, m1, si, si);
                    assert!(v > 0.0, "{c:?} at release, m1 = {m1}, si = {si}: {v}");
                }
            }
        }
        if !proof {
            continue;
        }
        proved += 1;
        for m1 in [1e-3, 0.5, 1.0, 7.0, 1e3] {
            for i in 0..=20 {
                let si = f64::from(i) / 20.0;
                for j in 0..=40 {
                    let s = si * f64::from(j) / 40.0;
                    let v = value(c, m1, si, s);
                    assert!(v > 0.0, "{c:?} at m1 = {m1}, si = {si}, s = {s}: {v}");
                }
            }
        }
    }
    assert!(proved >= 20, "only {proved} of 400 proved");
    assert!(
        at_release >= 20,
        "only {at_release} of 400 proved at release"
    );
}

#[test]
fn rod_cube_theta_ddot_is_the_corrected_eq_12() {
    let d = derive("rod_cube");
    let acc = plain(&d, "theta_ddot");
    assert_equivalent("theta_ddot", &acc, &paper(EQ12_CORRECTED));
    // theta'' = (1/2) d(theta'^2)/d(theta) holds for the derived pair as well.
    let w2 = plain(&d, "theta_dot_sq");
    let half_derivative = on_cas_thread(move || {
        let a = cas::atom(&w2);
        let dt = cas::d(&a, "rc_s") * cas::var("rc_c") - cas::d(&a, "rc_c") * cas::var("rc_s");
        cas::expr(&cas::together(&(dt / cas::num(2))))
    })
    .unwrap()
    .unwrap();
    assert_equivalent("(1/2) d(theta_dot_sq)/dtheta", &acc, &half_derivative);
}

#[test]
fn printed_eq_12_holds_only_at_a_over_ell_one_quarter() {
    let d = derive("rod_cube");
    let acc = plain(&d, "theta_ddot");
    let printed = paper(EQ12_PRINTED);
    assert!(
        !equivalent(&acc, &printed),
        "the printed eq (12) must not match for general a/ell"
    );
    for (a, matches) in [("ell/4", true), ("ell/3", false), ("ell/2", false)] {
        let at = |e: &Expr| subs(e, "a", &parse(a));
        assert_eq!(
            equivalent(&at(&acc), &at(&printed)),
            matches,
            "printed eq (12) at a = {a}"
        );
    }
    // The corrected form holds at every a/ell, including those.
    for a in ["ell/4", "ell/3"] {
        let at = |e: &Expr| subs(e, "a", &parse(a));
        assert_equivalent("corrected eq (12)", &at(&acc), &at(&paper(EQ12_CORRECTED)));
    }
}

#[test]
fn cyclic_elimination_gives_eq_5_and_eq_18() {
    let d = derive("rod_cube");
    assert_eq!(d.coords, ["x1", "theta"]);
    assert_eq!(d.cyclic, [0]);
    // Eq (5): x1' = (1+2n)/(2(1+n)) ell sin(theta) theta', with rc_w = theta'.
    assert_equivalent(
        "x1_dot",
        &red(&d).cyclic_velocity[0],
        &paper("(1 + 2*n)/(2*(1 + n))*ell*S*rc_w"),
    );
    // Eq (18): x1 = -(1+2n)/(2(1+n)) ell (cos(theta) - beta), beta = cos(theta_i), with
    // rc_dc = cos(theta_i) - cos(theta); x1 starts at the spec's initial position.
    let x1i = red(&d)
        .constants
        .iter()
        .find(|c| c.symbol == "rc_x0i")
        .expect("initial x1 constant");
    assert_eq!(
        x1i.value.eval(&|_| None),
        0.0,
        "x1 starts at {}",
        x1i.value.to_infix()
    );
    let x1 = subs(&red(&d).cyclic_position[0], "rc_x0i", &Expr::int(0));
    assert_equivalent("x1", &x1, &paper("-(1 + 2*n)/(2*(1 + n))*ell*(-rc_dc)"));
}

#[test]
fn a_wrong_formula_is_not_equivalent() {
    // Negative controls: the comparison can fail.
    let d = derive("rod_cube");
    assert!(!equivalent(
        &plain(&d, "theta_dot_sq"),
        &paper("4*(g/ell)*(r - S)/(4/3 - S^2/(2 + n))")
    ));
    assert!(!equivalent(
        &plain(&d, "contact_force"),
        &paper("m2*(-3*g*C*(8*r*(1 + n) - 11*(1 + n)*S + 3*S^3)/(4*(1 + n) - 3*S^2)^2)")
    ));
    // cos^2 = 1 - sin^2 is used, but cos is not sin.
    assert!(equivalent(&paper("C^2"), &paper("1 - S^2")));
    assert!(!equivalent(&paper("C"), &paper("1 - S^2")));
}

#[test]
fn a_theta_dependent_or_negative_factor_is_refused() {
    let d = derive("rod_cube");
    let derived = plain(&d, "separation_condition");
    let ok = |expected: &str| positive_multiple(&derived, &paper(expected), MASSES).is_ok();
    assert!(ok(EQ14_PUSH));
    assert!(!ok(EQ14));
    assert!(!ok("-S*(3*S^3 - 12*(1 + n)*S + 8*r*(1 + n))"));
    assert!(!ok("-(3*S^3 - 12*(1 + n)*S + 7*r*(1 + n))"));
}

// ---------------------------------------------------------------------------------------------
// The other models
// ---------------------------------------------------------------------------------------------

#[test]
fn hinged_rod_separates_where_3_n_s3_plus_3_s_equals_2_r() {
    let d = derive("hinged_rod");
    assert_eq!(d.coords, ["theta"]);
    assert_positive_multiple(
        "hinged_rod separation_condition",
        &plain(&d, "separation_condition"),
        &paper("3*n*S^3 + 3*S - 2*r"),
        MASSES,
    );
    // theta'^2 from energy: m1 g ell (r - s) / (ell^2 (m1/3 + m2 s^2)).
    assert_equivalent(
        "hinged_rod theta_dot_sq",
        &plain(&d, "theta_dot_sq"),
        &paper("3*(g/ell)*(r - S)/(1 + 3*n*S^2)"),
    );
    // Contact force: (3/2) m2 g cos (3 n s^3 + 3 s - 2 r) / (1 + 3 n s^2)^2.
    assert_equivalent(
        "hinged_rod contact_force",
        &plain(&d, "contact_force"),
        &paper("3/2*m2*g*C*(3*n*S^3 + 3*S - 2*r)/(1 + 3*n*S^2)^2"),
    );
    // The hinge holds the foot: Newton for the rod's centre (ell/2)(C, S), the cube pushing
    // back at the tip, with theta'^2 above and theta'' = (1/2) d(theta'^2)/d(theta).
    let hinged = |text: &str| {
        expand_shorthands(
            text,
            &[
                ("F", "3/2*m2*g*C*(3*n*S^3 + 3*S - 2*r)/DD^2"),
                ("W", "3*(g/ell)*(r - S)/DD"),
                ("A", "3/2*(g/ell)*C*(-DD - 6*n*S*(r - S))/DD^2"),
                ("DD", "1 + 3*n*S^2"),
                ("n", "m2/m1"),
                ("r", "a/ell"),
                ("S", "rc_s"),
                ("C", "rc_c"),
            ],
        )
    };
    assert_equivalent(
        "hinged_rod hinge_vertical",
        &plain(&d, "hinge_vertical"),
        &hinged("m1*(g + ell/2*(C*A - S*W))"),
    );
    assert_equivalent(
        "hinged_rod hinge_horizontal",
        &plain(&d, "hinge_horizontal"),
        &hinged("F - m1*ell/2*(S*A + C*W)"),
    );
    assert!(!equivalent(
        &plain(&d, "hinge_horizontal"),
        &hinged("-m1*ell/2*(S*A + C*W)")
    ));
}

#[test]
fn wall_ladder_separates_at_two_thirds_of_a_over_ell() {
    let d = derive("wall_ladder");
    assert_positive_multiple(
        "wall_ladder separation_condition",
        &plain(&d, "separation_condition"),
        &paper("3*S - 2*r"),
        MASSES,
    );
    assert_equivalent(
        "wall_ladder theta_dot_sq",
        &plain(&d, "theta_dot_sq"),
        &paper("3*(g/ell)*(r - S)"),
    );
    assert_equivalent(
        "wall_ladder contact_force",
        &plain(&d, "contact_force"),
        &paper("3/4*m1*g*C*(3*S - 2*r)"),
    );
    // The floor: N = m1 (g + y_cm'') with theta'' = -3 g C / (2 ell).
    assert_equivalent(
        "wall_ladder floor_normal",
        &plain(&d, "floor_normal"),
        &paper("m1*g*(1/4 - 3/2*r*S + 9/4*S^2)"),
    );
}

/// The loaded rod by hand. With M = m1+m2+m3, h = m1/2+m3, P = m1/3+m3 and
/// K = ((m1/2+m3)^2 + m2 m3)/M, zero horizontal momentum gives the reduced inertia
/// ell^2 (P - K s^2), so theta'^2 = 2 g h (r - s) / (ell (P - K s^2)). The cube moves with
/// x2' = -(m1 ell / 2M) s theta', so F = -m2 (m1 ell/2M) (c theta'^2 + s theta'') and the
/// contact ends where d(s^2 theta'^2)/ds = 0, i.e. K s^3 - 3 P s + 2 P r = 0.
fn loaded(text: &str) -> Expr {
    expand_shorthands(
        text,
        &[
            ("K", "((m1/2 + m3)^2 + m2*m3)/M"),
            ("P", "m1/3 + m3"),
            ("H", "m1/2 + m3"),
            ("M", "m1 + m2 + m3"),
            ("r", "a/ell"),
            ("S", "rc_s"),
            ("C", "rc_c"),
        ],
    )
}

#[test]
fn loaded_rod_matches_the_hand_computation() {
    let d = derive("loaded_rod");
    assert_equivalent(
        "loaded_rod theta_dot_sq",
        &plain(&d, "theta_dot_sq"),
        &loaded("2*g*H*(r - S)/(ell*(P - K*S^2))"),
    );
    // With the push's sign, as the contact force below.
    assert_positive_multiple(
        "loaded_rod separation_condition",
        &plain(&d, "separation_condition"),
        &loaded("-(K*S^3 - 3*P*S + 2*P*r)"),
        MASSES,
    );
    // F = -m2 m1 g h c (K s^3 - 3 P s + 2 P r) / (2 M (P - K s^2)^2).
    assert_equivalent(
        "loaded_rod contact_force",
        &plain(&d, "contact_force"),
        &loaded("-m2*m1*g*H*C*(K*S^3 - 3*P*S + 2*P*r)/(2*M*(P - K*S^2)^2)"),
    );
    // With m3 = 0 the loaded rod is the paper's rod.
    let at0 = |e: &Expr| subs(e, "m3", &Expr::int(0));
    assert_equivalent(
        "loaded_rod at m3 = 0",
        &at0(&plain(&d, "theta_dot_sq")),
        &paper(EQ9),
    );
    assert_equivalent(
        "loaded_rod contact force at m3 = 0",
        &at0(&plain(&d, "contact_force")),
        &paper(EQ16),
    );
    // Its cube velocity x1' - ell s theta' is -(m1 ell/2M) s theta'.
    assert_equivalent(
        "loaded_rod x1_dot",
        &red(&d).cyclic_velocity[0],
        &loaded("(1 - m1/(2*M))*ell*S*rc_w"),
    );
}
