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
    let value = |key: &str| -> Result<f64, String> {
        r.get(key)
            .map(|s| s.value)
            .ok_or_else(|| format!("no `{key}` in the results"))
    };
    println!(
        "theta_sep            {:.4} deg (paper 9.61)",
        value("separation_angle")?.to_degrees()
    );
    println!(
        "linearised theta_sep {:.4} deg (paper 9.59)",
        value("linearised_separation_angle")?.to_degrees()
    );
    for key in [
        "separation_time",
        "contact_time_to_floor",
        "point_mass_fall_time",
        "floor_impact_time",
    ] {
        println!("{key:<20} {:.6} s", value(key)?);
    }
    Ok(())
}
