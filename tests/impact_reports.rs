//! Impacts in the reports, from impacts built here: `impacts.csv` has its documented header and
//! reads back exactly, the printed table has a row per contact with the closing one and the
//! Zeno limit marked, `write_all` writes `impacts.csv` only when the run has impacts, and
//! `motion.svg` has a star per impact with a place; and for `fixed_cylinder` run through its
//! impact, the animation marks that impact where the rod meets the cylinder.

use rodcube::io::OutDir;
use rodcube::report::motion::{self, Animation, Frame, ImpactMark, PhaseSpan};
use rodcube::report::{self, csv, table};
use rodcube::results::{ContactImpulse, ImpactRecord, RunResults};
use std::fs;
use std::path::{Path, PathBuf};

const HEADER: &str = "time [s],contact,closing,normal_velocity_before,normal_velocity_after,\
                      velocity_unit,impulse,impulse_unit,tangential_impulse,energy_lost [J],\
                      normal_energy_lost [J],friction_energy_lost [J],zeno_limit";

fn part(
    contact: &str,
    before: f64,
    after: f64,
    impulse: f64,
    units: (&'static str, &'static str),
) -> ContactImpulse {
    ContactImpulse {
        contact: contact.into(),
        normal_velocity_before: before,
        normal_velocity_after: after,
        impulse,
        tangential_impulse: 0.0,
        velocity_unit: units.0,
        impulse_unit: units.1,
    }
}

/// Two impacts: the rod striking the cylinder while its foot lifts off the floor (numbers as
/// `fixed_cylinder` gives them), then a made-up plastic Zeno limit at an angular contact with
/// numbers small enough to be written in exponent form.
fn fixture() -> Vec<ImpactRecord> {
    vec![
        ImpactRecord {
            time: 0.2173103556284601,
            closing: "cylinder_push".into(),
            contacts: vec!["cylinder_push".into(), "floor_normal".into()],
            per_contact: vec![
                part(
                    "cylinder_push",
                    -0.4711682834422034,
                    4.440892098500626e-16,
                    0.45152894910262864,
                    ("m/s", "N s"),
                ),
                part("floor_normal", 0.0, 0.4039804004205225, 0.0, ("m/s", "N s")),
            ],
            energy_lost: 0.10637305993657369,
            normal_energy_lost: 0.10637305993657369,
            friction_energy_lost: 0.0,
            zeno_limit: false,
        },
        ImpactRecord {
            time: 0.6180339887498949,
            closing: "hinge_angle".into(),
            contacts: vec!["hinge_angle".into()],
            per_contact: vec![part(
                "hinge_angle",
                -3.5e-7,
                1.75e-7,
                2.5e-8,
                ("rad/s", "N m s"),
            )],
            energy_lost: 1e-20,
            normal_energy_lost: 1e-20,
            friction_energy_lost: 0.0,
            zeno_limit: true,
        },
    ]
}

#[test]
fn impacts_csv_has_its_header_and_reads_back_exactly() {
    let text = csv::impacts(&fixture()).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "{text}");
    assert_eq!(lines[0], HEADER);
    assert_eq!(csv::IMPACTS_HEADER.join(","), HEADER);
    assert_eq!(
        lines[3],
        "0.6180339887498949,hinge_angle,true,-3.5e-7,1.75e-7,rad/s,2.5e-8,N m s,0,1e-20,1e-20,0,true"
    );
    assert!(text.ends_with('\n'));
    // Every number back to its bits, every word as it was.
    let rows: Vec<Vec<&str>> = lines[1..].iter().map(|l| l.split(',').collect()).collect();
    type Row<'a> = (
        f64,
        &'a str,
        &'a str,
        [f64; 3],
        (&'a str, &'a str),
        f64,
        &'a str,
    );
    let expected: [Row; 3] = [
        (
            0.2173103556284601,
            "cylinder_push",
            "true",
            [
                -0.4711682834422034,
                4.440892098500626e-16,
                0.45152894910262864,
            ],
            ("m/s", "N s"),
            0.10637305993657369,
            "false",
        ),
        (
            0.2173103556284601,
            "floor_normal",
            "false",
            [0.0, 0.4039804004205225, 0.0],
            ("m/s", "N s"),
            0.10637305993657369,
            "false",
        ),
        (
            0.6180339887498949,
            "hinge_angle",
            "true",
            [-3.5e-7, 1.75e-7, 2.5e-8],
            ("rad/s", "N m s"),
            1e-20,
            "true",
        ),
    ];
    let bits = |s: &str| s.parse::<f64>().unwrap().to_bits();
    for (row, (t, contact, closing, v, units, energy, zeno)) in rows.iter().zip(expected) {
        assert_eq!(row.len(), 13, "{row:?}");
        assert_eq!(bits(row[0]), t.to_bits());
        assert_eq!((row[1], row[2]), (contact, closing));
        assert_eq!(bits(row[3]), v[0].to_bits());
        assert_eq!(bits(row[4]), v[1].to_bits());
        assert_eq!(row[5], units.0);
        assert_eq!(bits(row[6]), v[2].to_bits());
        assert_eq!(row[7], units.1);
        assert_eq!(bits(row[8]), 0f64.to_bits());
        assert_eq!(bits(row[9]), energy.to_bits());
        assert_eq!(bits(row[10]), energy.to_bits());
        assert_eq!(bits(row[11]), 0f64.to_bits());
        assert_eq!(row[12], zeno);
    }
    // No impacts: the header alone.
    assert_eq!(csv::impacts(&[]).unwrap(), format!("{HEADER}\n"));
}

#[test]
fn an_impact_without_its_contacts_still_has_a_row() {
    let mut bare = fixture();
    bare.truncate(1);
    bare[0].per_contact.clear();
    let text = csv::impacts(&bare).unwrap();
    assert_eq!(
        text.lines().nth(1),
        Some(
            "0.2173103556284601,cylinder_push,true,,,,,,,0.10637305993657369,0.10637305993657369,0,false"
        )
    );
}

/// The line of the table that has `cell`.
fn line_with<'a>(text: &'a str, cell: &str) -> &'a str {
    text.lines()
        .find(|l| l.contains(cell))
        .unwrap_or_else(|| panic!("no line with {cell:?} in\n{text}"))
}

#[test]
fn the_table_has_a_row_per_contact_in_each_impact() {
    let results = RunResults {
        model: "fixed_cylinder".into(),
        impacts: Some(fixture()),
        ..RunResults::default()
    };
    let text = table::render(&results, None, &table::Layout::default());
    assert!(text.contains("\nImpacts (2)\n"), "{text}");
    // The first impact: its time and energy on the closing contact's row (the first).
    let strike = line_with(&text, "cylinder_push *");
    for cell in ["0.21731", "-0.471168 m/s", "0.451529 N s", "0.106373"] {
        assert!(strike.contains(cell), "{cell:?} not in {strike}");
    }
    let lift = line_with(&text, "floor_normal");
    for cell in ["0 m/s", "0.40398 m/s", "0 N s"] {
        assert!(lift.contains(cell), "{cell:?} not in {lift}");
    }
    assert!(!lift.contains('*') && !lift.contains("0.21731") && !lift.contains("0.106373"));
    // The second: engineering notation, angular units, the Zeno limit marked.
    let zeno = line_with(&text, "hinge_angle *");
    for cell in [
        "0.618034",
        "-350e-9 rad/s",
        "175e-9 rad/s",
        "25e-9 N m s",
        "10e-21 (Zeno)",
    ] {
        assert!(zeno.contains(cell), "{cell:?} not in {zeno}");
    }
    assert!(text.contains("* the contact whose gap closed"));
    assert!(
        text.contains(
            "(Zeno): the limit of a converging sequence of bounces, at its accumulation time"
        ),
        "{text}"
    );
    assert!(text.lines().all(|l| l.chars().count() <= 100), "{text}");
    // No impacts, or none wanted: no table.
    for impacts in [None, Some(Vec::new())] {
        let none = RunResults {
            impacts,
            ..results.clone()
        };
        let text = table::render(&none, None, &table::Layout::default());
        assert!(!text.contains("Impacts"), "{text}");
    }
}

/// A fresh, empty directory for one test.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("impact_reports")
        .join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn names(written: &[PathBuf]) -> Vec<String> {
    (written.iter())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect()
}

#[test]
fn write_all_writes_impacts_csv_only_when_the_run_has_impacts() {
    let dir = fresh("write_all");
    let without = RunResults {
        model: "fixed_cylinder".into(),
        ..RunResults::default()
    };
    let out = OutDir::create(dir.join("without")).unwrap();
    let written = report::write_all(&out, &without).unwrap();
    assert_eq!(names(&written), ["results.json"]);
    assert!(!out.root().join(report::IMPACTS_CSV).exists());

    let with = RunResults {
        impacts: Some(fixture()),
        ..without.clone()
    };
    let out = OutDir::create(dir.join("with")).unwrap();
    let written = report::write_all(&out, &with).unwrap();
    assert_eq!(names(&written), ["results.json", "impacts.csv"]);
    let text = fs::read_to_string(&written[1]).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!((lines.len(), lines[0]), (4, HEADER));
    assert!(lines[1].starts_with("0.2173103556284601,cylinder_push,true,"));
    let mut on_disk: Vec<String> = fs::read_dir(out.root())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    on_disk.sort();
    assert_eq!(
        on_disk,
        ["impacts.csv", "results.json"],
        "no temporary files"
    );
}

/// A rod falling by its centre over 21 frames of two phases, with an impact at the phase
/// boundary and one at the end.
fn animation(impacts: Vec<ImpactMark>) -> Animation {
    let frames = (0..=20)
        .map(|i| {
            let t = 0.01 * i as f64;
            Frame {
                t,
                phase: usize::from(i > 10),
                poses: vec![[0.0, 1.0 - t, 0.3]],
                traced: None,
            }
        })
        .collect();
    Animation {
        model: "falling".into(),
        bodies: vec!["rod".into()],
        shapes: vec![motion::Shape {
            kind: rodcube::model::ShapeKind::Segment,
            body: Some(0),
            numbers: vec![-0.5, 0.0, 0.5, 0.0],
        }],
        phases: vec![
            PhaseSpan {
                name: "first".into(),
                t_start: 0.0,
            },
            PhaseSpan {
                name: "second".into(),
                t_start: 0.1,
            },
        ],
        frames,
        impacts,
        ..Animation::default()
    }
}

#[test]
fn motion_svg_has_a_star_per_impact() {
    let marks = vec![
        ImpactMark {
            t: 0.1,
            contact: "floor_normal".into(),
            at: Some([-0.4, 0.8]),
        },
        ImpactMark {
            t: 0.2,
            contact: "floor_normal".into(),
            at: Some([0.4, 0.9]),
        },
    ];
    let svg = motion::svg(&animation(marks.clone()));
    assert_eq!(svg.matches(r#"class="impact-mark""#).count(), 2);
    assert!(svg.contains(r#"id="impact-1""#) && svg.contains(r#"id="impact-2""#));
    assert!(svg.contains(">impact 1 of 2 at t = 0.1 s (floor_normal)<"));
    assert!(svg.contains(">impact 2 of 2 at t = 0.2 s (floor_normal)<"));
    assert_eq!(
        svg.matches("<polygon").count(),
        svg.matches("</polygon>").count()
    );
    // Without impacts: neither stars nor captions.
    let none = motion::svg(&animation(Vec::new()));
    assert!(!none.contains("impact"), "{none}");
    // An impact without a place: its caption only.
    let mut unplaced = marks;
    unplaced[1].at = None;
    let svg = motion::svg(&animation(unplaced));
    assert_eq!(svg.matches(r#"class="impact-mark""#).count(), 1);
    assert_eq!(svg.matches(r#"class="impact-label""#).count(), 2);
}

const FIXED_CYLINDER: &str = "model: fixed_cylinder
parameters: {m1: 1.0, ell: 1.0, R: 0.2, th0: 1.2, g: 9.81}
want: [impacts, tip_trajectory]
tolerance: 1.0e-10
until: 1.0
";

#[test]
fn the_rod_striking_the_cylinder_is_marked_where_they_meet() {
    let scene =
        rodcube::scene::Scene::parse(FIXED_CYLINDER, Path::new("<scene>"), rodcube::models::all())
            .unwrap();
    let results = rodcube::plan::run(&scene.request()).unwrap();
    let impacts = results.impacts.as_ref().unwrap();
    let anim = &Animation::build(results.drawing.as_ref().unwrap());
    assert!(!impacts.is_empty());
    assert_eq!(anim.impacts.len(), impacts.len());
    for (mark, record) in anim.impacts.iter().zip(impacts) {
        assert_eq!(mark.t.to_bits(), record.time.to_bits());
        assert_eq!(mark.contact, record.closing);
    }
    // The rod strikes the cylinder (axis (0, R), radius R = 0.2): the star is on its surface.
    let strike = &anim.impacts[0];
    assert_eq!(strike.contact, "cylinder_push");
    let [x, y] = strike.at.unwrap();
    assert!((x.hypot(y - 0.2) - 0.2).abs() < 1e-6, "{x} {y}");
    let svg = motion::svg(anim);
    assert_eq!(
        svg.matches(r#"class="impact-mark""#).count(),
        anim.impacts.len()
    );
}
