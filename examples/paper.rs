//! The paper's numbers (n = 3, a/ell = 1/4, ell = 1 m, g = 9.81 m/s^2) through the library API.
use rodcube::plan::{Request, run};
use rodcube::{models, quantity::Quantity};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = models::find("rod_cube").ok_or("rod_cube was not generated")?;
    let params = [
        ("m1", 1.0),
        ("m2", 3.0),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
    ];
    use Quantity::*;
    let want = [
        SeparationAngle,
        LinearisedSeparationAngle,
        SeparationTime,
        ContactTimeToFloor,
        PointMassFallTime,
        FloorImpact,
    ];
    let r = run(&Request::new(model, params).with_want(&want))?;
    let deg = |k: &str| r.results[k].value.to_degrees();
    println!(
        "theta_sep            {:.4} deg (paper 9.61)",
        deg("separation_angle")
    );
    println!(
        "linearised theta_sep {:.4} deg (paper 9.59)",
        deg("linearised_separation_angle")
    );
    for key in [
        "separation_time",
        "contact_time_to_floor",
        "point_mass_fall_time",
        "floor_impact_time",
    ] {
        println!("{key:<20} {:.6} s", r.results[key].value);
    }
    Ok(())
}
