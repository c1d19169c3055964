//! The derivation of Coulomb friction at both kinds of contact the spec allows: the rod's foot on
//! the fixed floor and the rod's tip rubbing on the cube's face (`against: cube`, with the
//! contact force as its normal force). Derived in-process from the shipped `rod_cube_friction`
//! spec with a second friction added, and checked against a hand Newton–Euler balance of the
//! rod and the cube at random states with arbitrary friction forces: the generalized friction
//! forces, the floor's normal force (from which the tip's friction must be taken out) and the
//! contact force all follow.
#![cfg(feature = "derive")]

use rodcube::derive::derive_all;
use rodcube::derive::expr::Expr;
use rodcube::derive::mechanics::Derivation;
use rodcube::derive::spec;
use std::collections::BTreeMap;
use std::path::Path;

/// `rod_cube_friction` with friction `mu2` between the rod's tip and the cube's face.
fn spec_text() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("derivations/rod_cube_friction.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    let text = text.replace(
        "  - {name: mu, ",
        "  - {name: mu2, meaning: tip-cube friction coefficient, unit: \"1\", positive: false}\n  - {name: mu, ",
    );
    text.replace(
        "monitors:\n",
        "  - name: tip_friction\n    meaning: the cube face's friction on the rod's tip, along +y\n    coefficient: mu2\n    normal: contact_force\n    body: rod\n    against: cube\n    point: [x1 + ell*cos(theta), ell*sin(theta)]\n    direction: [0, 1]\nmonitors:\n",
    )
}

fn derive() -> Vec<Derivation> {
    let text = spec_text();
    assert!(text.contains("tip_friction") && text.contains("mu2"));
    let checked = spec::parse(Path::new("derivations/rod_cube_tip_friction.yaml"), &text)
        .unwrap_or_else(|e| panic!("{e}"));
    derive_all(&[checked])
        .unwrap_or_else(|e| panic!("{e}"))
        .remove(0)
        .0
}

fn eval(e: &Expr, values: &BTreeMap<String, f64>) -> f64 {
    let v = e.eval(&|s| values.get(s).copied());
    assert!(
        v.is_finite(),
        "{} is not finite at {values:?}",
        e.to_infix()
    );
    v
}

#[test]
fn tip_and_foot_friction_balance_the_rod_and_the_cube_by_hand() {
    let phases = derive();
    let d = &phases[0];
    assert_eq!(d.coords, ["x1", "theta"]);
    assert_eq!(d.frictions.len(), 2);
    assert!(
        d.cyclic.is_empty(),
        "friction on x1: its momentum is not conserved"
    );
    assert!(d.reduction.is_err(), "a phase with friction is integrated");
    // After the contact ends the tip no longer rubs: only the foot's friction is left.
    assert_eq!(phases[1].frictions.len(), 1);
    assert_eq!(phases[1].frictions[0].named.name, "foot_friction");

    let (m1, m2, ell, a, g) = (1.3, 2.1, 0.9, 0.3, 9.81);
    let inertia = m1 * ell * ell / 12.0;
    let mut worst = 0.0f64;
    for (x1, theta, v1, omega, f0, f1) in [
        (0.1, 0.3, 0.0, 0.0, 0.7, -0.4),
        (-0.2, 0.25, -0.3, -1.2, -1.1, 0.9),
        (0.4, 0.12, 0.5, -2.3, 2.0, 1.5),
    ] {
        let mut values: BTreeMap<String, f64> = [
            ("m1", m1),
            ("m2", m2),
            ("ell", ell),
            ("a", a),
            ("g", g),
            ("mu", 0.5),
            ("mu2", 0.3),
            ("x1", x1),
            ("theta", theta),
            ("dot_x1", v1),
            ("dot_theta", omega),
            ("rc_fr0", f0),
            ("rc_fr1", f1),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        // M qdd = F + J^T f, solved by hand (2 x 2).
        let m: Vec<Vec<f64>> = (d.mass.iter())
            .map(|row| row.iter().map(|e| eval(e, &values)).collect())
            .collect();
        let jac: Vec<Vec<f64>> = (d.frictions.iter())
            .map(|f| f.jacobian.iter().map(|e| eval(e, &values)).collect())
            .collect();
        let (s, c) = (theta.sin(), theta.cos());
        assert!(
            (jac[0][0] - 1.0).abs() < 1e-15 && jac[0][1].abs() < 1e-15,
            "{jac:?}"
        );
        assert!(
            jac[1][0].abs() < 1e-15 && (jac[1][1] - ell * c).abs() < 1e-15,
            "{jac:?}"
        );
        let b: Vec<f64> = (0..2)
            .map(|i| eval(&d.rhs[i], &values) + jac[0][i] * f0 + jac[1][i] * f1)
            .collect();
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        let x1dd = (b[0] * m[1][1] - m[0][1] * b[1]) / det;
        let thdd = (m[0][0] * b[1] - m[1][0] * b[0]) / det;
        values.insert("ddot_x1".into(), x1dd);
        values.insert("ddot_theta".into(), thdd);
        let push = eval(&d.forces_full[0], &values);
        let floor = eval(&d.forces_full[1], &values);
        let ax = x1dd - 0.5 * ell * (s * thdd + c * omega * omega);
        let ay = 0.5 * ell * (c * thdd - s * omega * omega);
        let ax2 = x1dd - ell * (s * thdd + c * omega * omega);
        // The floor acts at the foot (f0, N), the cube at the tip (-P, f1); the cube feels P.
        let torque =
            -0.5 * ell * c * floor + 0.5 * ell * s * f0 + 0.5 * ell * c * f1 + 0.5 * ell * s * push;
        let residuals = [
            (m1 * ax - (f0 - push)) / (m1 * g),
            (m1 * ay - (floor + f1 - m1 * g)) / (m1 * g),
            (inertia * thdd - torque) / (m1 * g * ell),
            (m2 * ax2 - push) / (m1 * g),
        ];
        for (i, r) in residuals.iter().enumerate() {
            assert!(r.abs() < 1e-13, "theta {theta}: balance {i} off by {r:e}");
            worst = worst.max(r.abs());
        }
    }
    println!("largest Newton-Euler residual: {worst:.1e} (relative to m1 g)");
}
