//! Parameter validation when binding a model: every refusal is a typed error naming the
//! parameter or requirement and its value, and an accepted system has finite constants.

mod common;

use common::paper::{FREE_ROD, GENERAL, ROD_CUBE, paper};
use rodcube::system::{Bound, System, SystemError};
use std::collections::BTreeMap;

#[test]
fn paper_parameters_bind() {
    let sys = System::new(&ROD_CUBE, &paper(9.81)).unwrap();
    assert_eq!(sys.name(), "rod_cube_closed");
    assert_eq!(sys.param("a"), Some(0.25));
    assert_eq!(sys.param("nope"), None);
    assert_eq!(sys.gravity(), 9.81);
    assert!((sys.theta_initial() - 0.25f64.asin()).abs() < 1e-16);
    assert_eq!(sys.theta_dot_initial(), 0.0);
    assert!(sys.starts_at_rest());
    assert_eq!(
        sys.reduced_at_theta(0.1),
        sys.reduced(sys.theta_initial() - 0.1)
    );
    assert!(sys.k().iter().all(|v| v.is_finite()));
    // Named, ordered and map forms agree.
    let ordered = System::from_values(&ROD_CUBE, &[1.0, 3.0, 1.0, 0.25, 9.81]).unwrap();
    let map: BTreeMap<String, f64> = paper(9.81)
        .iter()
        .map(|(k, v)| (k.to_string(), *v))
        .collect();
    let mapped = System::from_map(&ROD_CUBE, &map).unwrap();
    assert_eq!(sys.k(), ordered.k());
    assert_eq!(sys.k(), mapped.k());
    assert_eq!(sys.parameter_map(), map);
    // The system's general model binds the same parameters, but has no fast path of its own:
    // it is integrated (its fast phases are other models).
    let general = Bound::new(&GENERAL, &paper(9.81)).unwrap();
    assert_eq!(general.name(), "rod_cube");
    assert_eq!(general.p(), sys.bound().p());
    let err = System::new(&GENERAL, &paper(9.81)).unwrap_err();
    assert!(
        matches!(
            err,
            SystemError::NoReduction {
                model: "rod_cube",
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn missing_unknown_and_duplicate_parameters() {
    let err = System::new(
        &ROD_CUBE,
        &[("m1", 1.0), ("m2", 3.0), ("ell", 1.0), ("g", 9.81)],
    )
    .unwrap_err();
    assert_eq!(
        err,
        SystemError::MissingParameter {
            model: "rod_cube_closed",
            name: "a"
        }
    );
    let mut params = paper(9.81).to_vec();
    params.push(("mass", 2.0));
    let err = System::new(&ROD_CUBE, &params).unwrap_err();
    assert!(
        matches!(&err, SystemError::UnknownParameter { name, value, .. } if name == "mass" && *value == 2.0)
    );
    assert!(err.to_string().contains("m1, m2, ell, a, g"), "{err}");
    let mut params = paper(9.81).to_vec();
    params.push(("a", 0.3));
    let err = System::new(&ROD_CUBE, &params).unwrap_err();
    assert!(matches!(
        err,
        SystemError::DuplicateParameter {
            first: 0.25,
            second: 0.3,
            ..
        }
    ));
    let err = System::from_values(&ROD_CUBE, &[1.0, 2.0]).unwrap_err();
    assert_eq!(
        err,
        SystemError::WrongCount {
            model: "rod_cube_closed",
            expected: 5,
            got: 2
        }
    );
}

#[test]
fn non_finite_and_non_positive_values() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut p = paper(9.81);
        p[1].1 = bad;
        let err = System::new(&ROD_CUBE, &p).unwrap_err();
        assert!(
            matches!(err, SystemError::NotFinite { name: "m2", .. }),
            "{err}"
        );
    }
    for bad in [0.0, -1.0] {
        let mut p = paper(9.81);
        p[4].1 = bad;
        let err = System::new(&ROD_CUBE, &p).unwrap_err();
        assert_eq!(
            err,
            SystemError::NotPositive {
                model: "rod_cube_closed",
                name: "g",
                value: bad
            }
        );
    }
    // Parameters not declared positive may be zero or negative.
    let free = common::paper::free_after(0.2, -1.0, -0.5, 0.0);
    assert!(System::new(&FREE_ROD, &free).is_ok());
}

#[test]
fn requirement_margins_must_be_positive() {
    for a in [1.0, 1.5] {
        let mut p = paper(9.81);
        p[3].1 = a;
        let err = System::new(&ROD_CUBE, &p).unwrap_err();
        match &err {
            SystemError::Requirement {
                name,
                margin,
                parameters,
                ..
            } => {
                assert_eq!(*name, "a_below_ell");
                assert!(*margin <= 0.0);
                assert!(parameters.contains(&format!("a = {a}")), "{parameters}");
            }
            other => panic!("unexpected {other:?}"),
        }
        assert!(err.to_string().contains("a_below_ell"));
    }
    // Just below the limit is accepted, with finite constants.
    let mut p = paper(9.81);
    p[3].1 = 1.0 - 1e-9;
    assert!(System::new(&ROD_CUBE, &p).is_ok());
}
