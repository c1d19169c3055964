//! Stage 4 of the derivation: a phase's Euler–Lagrange equations as `M(q) qdd = F(q, qd)`,
//! its cyclic coordinates and their conserved momenta.

use super::cas::{self, A};
use super::lagrangian::Lagrangian;
use super::setup::Setup;

/// The Euler–Lagrange equations of a phase.
pub struct Equations {
    /// Euler–Lagrange expressions, one per coordinate.
    pub el: Vec<A>,
    /// `M(q)`, row-major by coordinate.
    pub mass: Vec<Vec<A>>,
    /// `F(q, qd)`.
    pub rhs: Vec<A>,
    /// The cyclic coordinates (not the reduced one, no friction acting on them).
    pub cyclic: Vec<usize>,
    /// Their conjugate momenta.
    pub momenta: Vec<A>,
}

/// Stage 4: `M(q) qdd = F(q, qd)`, the cyclic coordinates and their momenta. A coordinate
/// that a friction's slip moves (`frictions`: each slip's Jacobian row) is not cyclic.
pub fn equations(st: &Setup, lag: &Lagrangian, frictions: &[Vec<A>]) -> Equations {
    let dots: Vec<String> = st.coords.iter().map(|c| format!("dot_{c}")).collect();
    let ddots: Vec<String> = st.coords.iter().map(|c| format!("ddot_{c}")).collect();
    let (mut el, mut mass, mut rhs) = (Vec::new(), Vec::new(), Vec::new());
    for c in &st.coords {
        let (e, spring) = lag.euler_lagrange(&st.kin, c);
        let mut row = Vec::new();
        let mut at_rest = e.clone();
        for dd in &ddots {
            row.push(cas::expand(&cas::d(&e, dd)));
            at_rest = cas::subs_var(&at_rest, dd, &cas::num(0));
        }
        rhs.push(cas::expand(&(cas::num(0) - at_rest)) - spring.clone());
        let e = e + spring;
        mass.push(row);
        el.push(e);
    }
    let cyclic: Vec<usize> = (0..st.coords.len())
        .filter(|&i| Some(i) != st.reduced && cas::is_zero(&cas::d(&lag.lag, &st.coords[i])))
        .filter(|&i| {
            frictions
                .iter()
                .all(|row| row.get(i).is_none_or(cas::is_zero))
        })
        .collect();
    let momenta = cyclic
        .iter()
        .map(|&i| cas::expand(&cas::d(&lag.lag, &dots[i])))
        .collect();
    Equations {
        el,
        mass,
        rhs,
        cyclic,
        momenta,
    }
}
