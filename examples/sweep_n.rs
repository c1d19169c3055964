//! Separation angle and time of the paper's rod (a/ell = 1/4) as the cube gets heavier.
use rodcube::models;
use rodcube::plan::{Request, run};
use rodcube::quantity::Quantity::{SeparationAngle, SeparationTime};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = models::find("rod_cube").ok_or("rod_cube was not generated")?;
    println!("{:>10} {:>12} {:>12}", "n", "theta_sep", "t_sep");
    for i in 0..=12 {
        let n = 10f64.powf(-3.0 + 0.5 * i as f64);
        let params = [
            ("m1", 1.0),
            ("m2", n),
            ("ell", 1.0),
            ("a", 0.25),
            ("g", 9.81),
        ];
        let r = run(&Request::new(model, params).with_want(&[SeparationAngle, SeparationTime]))?;
        let (Some(theta), Some(t)) = (r.separation_angle(), r.separation_time()) else {
            println!("{n:>10.3e}  no separation before the floor");
            continue;
        };
        println!("{n:>10.3e} {:>9.4} deg {t:>10.6} s", theta.to_degrees());
    }
    Ok(())
}
