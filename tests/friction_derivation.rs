//! The derivation of Coulomb friction at both kinds of contact the spec allows: the rod's foot on
//! the fixed floor and the rod's tip rubbing on the cube's face (`against: cube`, with the
//! contact force as its normal force). Derived in-process from the shipped `rod_cube_friction`
//! spec with a second friction added (a system with friction has only its general model: every
//! coordinate, both contacts constraint rows), and checked against a hand Newton–Euler balance
//! of the rod and the cube at random states with arbitrary friction forces: with both contacts
//! held closed by their rows, the generalized friction forces, the floor's normal force (from
//! which the tip's friction must be taken out) and the contact force all follow.
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
        "  - name: tip_friction\n    meaning: the cube face's friction on the rod's tip, along +y\n    coefficient: mu2\n    contact: contact_force\n    body: rod\n    against: cube\n    point: [x1 + ell*cos(theta), y1 + ell*sin(theta)]\n    direction: [0, 1]\nmonitors:\n",
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

/// Solves `a x = b` by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..n {
            let f = a[row][col] / a[col][col];
            let pivot_row = a[col].clone();
            for (x, p) in a[row].iter_mut().zip(&pivot_row).skip(col) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let rest: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - rest) / a[row][row];
    }
    x
}

#[test]
fn tip_and_foot_friction_balance_the_rod_and_the_cube_by_hand() {
    let phases = derive();
    // Friction makes no phase fast: the system is its general model alone.
    assert_eq!(
        phases.len(),
        1,
        "{:?}",
        phases.iter().map(|d| &d.name).collect::<Vec<_>>()
    );
    let d = &phases[0];
    assert!(d.is_general());
    assert_eq!(d.coords, ["x1", "y1", "theta", "x2"]);
    assert!(d.reduction.is_err(), "a system with friction is integrated");
    let names: Vec<&str> = d.contacts.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["contact_force", "floor_normal"]);
    assert!(d.contacts.iter().all(|c| !c.closed && c.force.is_none()));
    // Each friction acts at its contact, whose force is its normal force: the foot's at the
    // floor, the tip's at the cube's face (an open contact has no friction).
    assert_eq!(d.frictions.len(), 2);
    assert_eq!(d.frictions[0].named.name, "foot_friction");
    assert_eq!(d.frictions[0].contact, 1);
    assert_eq!(d.frictions[1].named.name, "tip_friction");
    assert_eq!(d.frictions[1].contact, 0);

    let (m1, m2, ell, a, g) = (1.3, 2.1, 0.9, 0.3, 9.81);
    let inertia = m1 * ell * ell / 12.0;
    let mut worst = 0.0f64;
    for (x1, theta, v1, omega, f0, f1) in [
        (0.1f64, 0.3f64, 0.0, 0.0, 0.7, -0.4),
        (-0.2, 0.25, -0.3, -1.2, -1.1, 0.9),
        (0.4, 0.12, 0.5, -2.3, 2.0, 1.5),
    ] {
        let (s, c) = (theta.sin(), theta.cos());
        // Both contacts closed: the foot on the floor, the cube's face at the tip, moving with it.
        let values: BTreeMap<String, f64> = [
            ("m1", m1),
            ("m2", m2),
            ("ell", ell),
            ("a", a),
            ("g", g),
            ("mu", 0.5),
            ("mu2", 0.3),
            ("x1", x1),
            ("y1", 0.0),
            ("theta", theta),
            ("x2", x1 + ell * c),
            ("dot_x1", v1),
            ("dot_y1", 0.0),
            ("dot_theta", omega),
            ("dot_x2", v1 - ell * s * omega),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        let n = d.coords.len();
        let m: Vec<Vec<f64>> = (d.mass.iter())
            .map(|row| row.iter().map(|e| eval(e, &values)).collect())
            .collect();
        let jac: Vec<Vec<f64>> = (d.frictions.iter())
            .map(|f| f.jacobian.iter().map(|e| eval(e, &values)).collect())
            .collect();
        // The foot slips with x1'; the tip along +y against the cube with y1' + ell cos theta'.
        let want = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, ell * c, 0.0]];
        for (row, want) in jac.iter().zip(want) {
            for (j, w) in row.iter().zip(want) {
                assert!((j - w).abs() < 1e-15, "{jac:?}");
            }
        }
        let rows: Vec<Vec<f64>> = (d.contacts.iter())
            .map(|r| r.jacobian.iter().map(|e| eval(e, &values)).collect())
            .collect();
        let bias: Vec<f64> = d.contacts.iter().map(|r| eval(&r.bias, &values)).collect();
        // M qdd - J^T lambda = F + T^T f, J qdd + bias = 0: unknowns qdd, then the push P and
        // the floor's N.
        let mut kkt = vec![vec![0.0; n + 2]; n + 2];
        let mut rhs = vec![0.0; n + 2];
        for i in 0..n {
            kkt[i][..n].copy_from_slice(&m[i]);
            for r in 0..2 {
                kkt[i][n + r] = -rows[r][i];
                kkt[n + r][i] = rows[r][i];
            }
            rhs[i] = eval(&d.rhs[i], &values) + jac[0][i] * f0 + jac[1][i] * f1;
        }
        for r in 0..2 {
            rhs[n + r] = -bias[r];
        }
        let x = solve(kkt, rhs);
        let (x1dd, y1dd, thdd, x2dd) = (x[0], x[1], x[2], x[3]);
        let (push, floor) = (x[n], x[n + 1]);
        let ax = x1dd - 0.5 * ell * (s * thdd + c * omega * omega);
        let ay = y1dd + 0.5 * ell * (c * thdd - s * omega * omega);
        let tip_ax = x1dd - ell * (s * thdd + c * omega * omega);
        // The floor acts at the foot (f0, N), the cube at the tip (-P, f1); the cube feels P.
        let torque =
            -0.5 * ell * c * floor + 0.5 * ell * s * f0 + 0.5 * ell * c * f1 + 0.5 * ell * s * push;
        let residuals = [
            (m1 * ax - (f0 - push)) / (m1 * g),
            (m1 * ay - (floor + f1 - m1 * g)) / (m1 * g),
            (inertia * thdd - torque) / (m1 * g * ell),
            (m2 * x2dd - push) / (m1 * g),
            (x2dd - tip_ax) / g,
            y1dd / g,
        ];
        for (i, r) in residuals.iter().enumerate() {
            assert!(r.abs() < 1e-13, "theta {theta}: balance {i} off by {r:e}");
            worst = worst.max(r.abs());
        }
    }
    println!("largest Newton-Euler residual: {worst:.1e} (relative to m1 g)");
}
