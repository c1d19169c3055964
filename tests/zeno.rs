//! A ball dropped on a floor with restitution `e` (tests/specs/ball.yaml, derived at test time
//! into its tape) against the closed forms of a body bouncing under constant gravity, its
//! lowest point dropped from `h = H - R` (docs/PHYSICS.md): `t_1 = sqrt(2 h/g)`, the n-th impact at
//! `t_n = t_1 + 2 t_1 sum_{k=1}^{n-1} e^k`, the bounces accumulating (Zeno) at
//! `t_1 (1 + e)/(1 - e)`. The run lists the impact that closes the sequence at that time and the
//! ball comes to rest there; every impact's time has its sensitivities, which are the closed
//! form's derivatives in `e`, `H`, `R` and `g`, and the run's own central differences.
#![cfg(feature = "derive")]

use rodcube::model::Model;
use rodcube::plan::{self, Request};
use rodcube::quantity::Quantity;
use rodcube::results::{Halt, Note, RunResults, UntilNote};
use std::collections::BTreeMap;

const SPEC: &str = include_str!("specs/ball.yaml");

/// The ball's model, derived from its spec into a tape by `rodcube derive --tapes-into` (no
/// model of it is compiled in) and loaded, once for the tests here.
fn ball() -> &'static dyn Model {
    static DISK: std::sync::OnceLock<&'static rodcube::tape::TapeModel> =
        std::sync::OnceLock::new();
    *DISK.get_or_init(derive)
}

fn derive() -> &'static rodcube::tape::TapeModel {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("zeno_ball");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    std::fs::write(dir.join("ball.yaml"), SPEC).expect("spec");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .args(["derive", "--tapes-into", "models", "ball.yaml"])
        .current_dir(&dir)
        .output()
        .expect("rodcube runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    rodcube::tape::load_file(&dir.join("models/ball.tape.json")).expect("its tape")
}

const G: f64 = 9.81;
/// The ball's radius: its centre starts at `H = h + R`.
const R: f64 = 0.1;

fn parameters(h: f64, e: f64, u: f64) -> BTreeMap<String, f64> {
    [
        ("m", 1.0),
        ("R", R),
        ("H", h + R),
        ("v0", u),
        ("g", G),
        ("e", e),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}

fn run(model: &'static dyn Model, p: &BTreeMap<String, f64>, want: &[Quantity]) -> RunResults {
    let request = Request::new(model, p)
        .with_want(want)
        .with_tolerance(1e-12)
        .with_until(Some(10.0));
    plan::run(&request).unwrap_or_else(|e| panic!("{e}"))
}

/// `t_n` by the closed form, and its derivatives in `e` and `H`.
fn closed_form(n: usize, h: f64, e: f64) -> (f64, f64, f64) {
    let t1 = (2.0 * h / G).sqrt();
    let sum: f64 = (1..n).map(|k| e.powi(k as i32)).sum();
    let d_sum: f64 = (1..n).map(|k| k as f64 * e.powi(k as i32 - 1)).sum();
    let t = t1 * (1.0 + 2.0 * sum);
    (t, 2.0 * t1 * d_sum, t / (2.0 * h))
}

#[test]
fn the_bounces_accumulate_at_the_closed_form_and_every_impact_time_moves_as_it_says() {
    let model = ball();
    let (h, e) = (1.0, 0.9);
    let want = [Quantity::Impacts, Quantity::Sensitivities];
    let res = run(model, &parameters(h, e, 0.0), &want);
    let impacts = res.impacts.as_ref().expect("impacts");
    let (last, bounces) = impacts.split_last().expect("impacts");
    // The limit: listed at the accumulation time, marked, and the ball at rest from then on.
    let t1 = (2.0 * h / G).sqrt();
    let zeno = t1 * (1.0 + e) / (1.0 - e);
    assert!(last.zeno_limit && bounces.iter().all(|b| !b.zeno_limit));
    assert!(
        (last.time - zeno).abs() <= 1e-9 * zeno,
        "{} vs {zeno}",
        last.time
    );
    assert!((last.time - 8.578949).abs() < 5e-7, "the issue's figure");
    match res.notes.get("until") {
        Some(Note::Until(UntilNote::Halted(Halt::AtRest { t, .. }))) => {
            assert!((t - zeno).abs() <= 1e-9 * zeno, "at rest at {t}")
        }
        other => panic!("{other:?}"),
    }
    // The note says how many impacts were resolved before the rest were summed.
    let Some(Note::Zeno(notes)) = res.notes.get("zeno") else {
        panic!("{:?}", res.notes)
    };
    assert_eq!(notes.len(), 1);
    let words = rodcube::report::prose::note(&Note::Zeno(notes.clone()));
    assert!(
        words.contains(&format!("bounced {} times", impacts.len())),
        "{words}"
    );
    // Every impact resolved one by one, at the closed form's time, with its derivatives.
    assert!(bounces.len() > 50, "{}", bounces.len());
    for (k, b) in bounces.iter().enumerate() {
        let n = k + 1;
        let (t, dt_de, dt_dh) = closed_form(n, h, e);
        assert!(
            (b.time - t).abs() <= 1e-9 * t,
            "impact {n}: {} vs {t}",
            b.time
        );
        let d = |p: &str| res.sensitivities[&format!("d(impact_{n}_time)/d({p})")].value;
        for (p, want) in [
            ("e", dt_de),
            ("H", dt_dh),
            ("g", -t / (2.0 * G)),
            ("R", -dt_dh),
            ("m", 0.0),
        ] {
            assert!(
                (d(p) - want).abs() <= 1e-7 * t.max(want.abs()),
                "impact {n}, d/d{p}: {} vs {want}",
                d(p)
            );
        }
    }
    // The limit's derivatives: the closed form `t_1 (1 + e) / (1 - e)` differentiated, in `e`
    // `2 t_1 / (1 - e)^2`, in `H` and `g` as `t_1`'s (`t / (2H)`, `-t / (2g)`).
    let n = impacts.len();
    let d = |p: &str| res.sensitivities[&format!("d(impact_{n}_time)/d({p})")].value;
    for (p, want) in [
        ("e", 2.0 * t1 / (1.0 - e).powi(2)),
        ("H", zeno / (2.0 * h)),
        ("g", -zeno / (2.0 * G)),
        ("R", -zeno / (2.0 * h)),
        ("m", 0.0),
    ] {
        assert!(
            (d(p) - want).abs() <= 1e-7 * zeno.max(want.abs()),
            "the limit, d/d{p}: {} vs {want}",
            d(p)
        );
    }
}

#[test]
fn impact_time_sensitivities_match_central_differences_of_the_run() {
    let model = ball();
    // Sideways too: the floor, frictionless, leaves that motion alone.
    let (h, e, u) = (0.7, 0.6, 0.3);
    let want = [Quantity::Impacts, Quantity::Sensitivities];
    let p = parameters(h, e, u);
    let res = run(model, &p, &want);
    let times = |q: &BTreeMap<String, f64>| -> Vec<f64> {
        let r = run(model, q, &[Quantity::Impacts]);
        r.impacts.expect("impacts").iter().map(|i| i.time).collect()
    };
    for name in ["e", "H", "g"] {
        let step = 1e-5 * p[name];
        let at = |k: f64| {
            let mut q = p.clone();
            *q.get_mut(name).expect("a parameter") += k * step;
            times(&q)
        };
        let (a, b, c, d) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
        for n in 1..=6 {
            let diff = (8.0 * (a[n - 1] - b[n - 1]) - (c[n - 1] - d[n - 1])) / (12.0 * step);
            let s = res.sensitivities[&format!("d(impact_{n}_time)/d({name})")].value;
            assert!(
                (s - diff).abs() <= 1e-7 * diff.abs().max(1.0),
                "impact {n}, d/d{name}: {s} vs differences {diff}"
            );
        }
    }
}
