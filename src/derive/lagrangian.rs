//! Stage 3 of the derivation: a phase's kinetic and potential energies (gravity and the
//! spec's potentials) and its Lagrangian, with each body's position, angle and mass over the
//! phase's coordinates; the Euler–Lagrange expression of any coordinate and the velocity of a
//! material point.

use super::cas::{self, A};
use super::expr::Expr;
use super::read::Parsed;
use super::setup::{Kin, Setup};
use super::spec::Spec;
use std::collections::BTreeMap;

/// Energies and the Lagrangian of a phase, with each body's position and mass.
pub struct Lagrangian {
    /// Kinetic energy, expanded.
    pub kinetic: A,
    /// Potential energy: gravity expanded, plus the spec's potentials as written.
    pub potential: A,
    /// The spec's potentials (part of `potential`), unexpanded.
    pub springs: A,
    /// `L = T - V`.
    pub lag: A,
    /// Each body's centre of mass over the phase's coordinates.
    pub body_pos: BTreeMap<String, [A; 2]>,
    /// Each body's angle.
    pub body_angle: BTreeMap<String, A>,
    /// Each body's mass.
    pub body_mass: BTreeMap<String, A>,
}

/// Stage 3: `T`, `V` (gravity and the spec's potentials) and `L = T - V`.
pub fn lagrangian(spec: &Spec, parsed: &Parsed, st: &Setup) -> Lagrangian {
    let g = cas::var(&spec.gravity);
    let half = cas::atom(&Expr::Rational(1, 2));
    let mut t_kin = cas::num(0);
    let mut v_pot = cas::num(0);
    let mut body_pos = BTreeMap::new();
    let mut body_angle = BTreeMap::new();
    let mut body_mass = BTreeMap::new();
    for b in &parsed.bodies {
        let m = cas::atom(&b.mass);
        let inertia = cas::atom(&b.inertia);
        let (x, y) = (st.at(&b.position[0]), st.at(&b.position[1]));
        let angle = st.at(&b.angle);
        let (vx, vy, w) = (st.kin.dt(&x), st.kin.dt(&y), st.kin.dt(&angle));
        t_kin = t_kin
            + half.clone() * m.clone() * (vx.clone() * vx + vy.clone() * vy)
            + half.clone() * inertia * w.clone() * w;
        v_pot += m.clone() * g.clone() * y.clone();
        body_pos.insert(b.name.clone(), [x, y]);
        body_angle.insert(b.name.clone(), angle);
        body_mass.insert(b.name.clone(), m);
    }
    // The spec's potentials stay as written: expanded, a spring's `(x - x0)^2` would be
    // evaluated as `x^2 - 2 x x0 + x0^2`, which cancels to nothing near its rest length.
    let mut springs = cas::num(0);
    for p in &parsed.potentials {
        springs += st.at(p);
    }
    let kinetic = cas::expand(&t_kin);
    let potential = cas::expand(&v_pot) + springs.clone();
    Lagrangian {
        lag: kinetic.clone() - potential.clone(),
        kinetic,
        potential,
        springs,
        body_pos,
        body_angle,
        body_mass,
    }
}

impl Lagrangian {
    /// The velocity of `body`'s material point at `p` (`v_cm + w x (p - cm)`).
    pub fn material_velocity(&self, kin: &Kin, body: &str, p: &[A; 2]) -> Option<[A; 2]> {
        let [x, y] = self.body_pos.get(body)?;
        let w = kin.dt(self.body_angle.get(body)?);
        Some([
            kin.dt(x) - w.clone() * (p[1].clone() - y.clone()),
            kin.dt(y) + w * (p[0].clone() - x.clone()),
        ])
    }

    /// The Euler–Lagrange expression `d/dt dL/dqd - dL/dq` of coordinate `c` in two parts:
    /// the kinetic and gravitational part expanded, and the gradient of the spec's potentials
    /// as differentiated (a spring's force `k (x - x0)`, not `k x - k x0`).
    pub fn euler_lagrange(&self, kin: &Kin, c: &str) -> (A, A) {
        let dot = format!("dot_{c}");
        let inertial = self.kinetic.clone() - (self.potential.clone() - self.springs.clone());
        let expanded = cas::expand(&(kin.dt(&cas::d(&inertial, &dot)) - cas::d(&inertial, c)));
        (expanded, cas::d(&self.springs, c))
    }
}
