//! The tape's evaluator: [`TapeModel`] implements [`Model`], [`Reduction`], [`Tangents`] and
//! [`Partials`] by running each
//! method's checked program on a register file, with the same `f64` operations in the same
//! order as the generated Rust, so both routes give equal results to the bit.
//!
//! Registers live in one buffer per thread, grown to the largest program a thread has run
//! (sized once; no allocation per call).

use super::check::{Method, Op, Program};
use crate::model::{
    Model, ModelInfo, Partials, Reduced, Reduction, TangentPoint, Tangents, start_offsets,
};
use std::cell::RefCell;

thread_local! {
    static REGISTERS: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// A model run from its tape.
#[derive(Debug)]
pub struct TapeModel {
    pub(super) info: &'static ModelInfo,
    /// One program per entry of [`METHODS`], `None` where the tape has none.
    pub(super) programs: Vec<Option<Program>>,
    /// The digest of the tape's body.
    pub(super) digest: String,
    /// Where it was read from, for notes and errors.
    pub(super) source: String,
    /// The spec it was derived from and its digest then.
    pub(super) spec: (String, String),
}

impl TapeModel {
    /// The digest of its tape's body (equal for equal programs).
    pub fn digest(&self) -> &str {
        &self.digest
    }

    /// Where its tape was read from.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The spec it was derived from (relative to the project root) and the digest of the
    /// spec's text when it was.
    pub fn spec(&self) -> (&str, &str) {
        (&self.spec.0, &self.spec.1)
    }

    fn program(&self, m: Method) -> Option<&Program> {
        self.programs.get(m as usize).and_then(Option::as_ref)
    }

    /// Runs a method (nothing where the tape has none) with its inputs and outputs in the
    /// order of its signature; `case` selects `force_polynomial`'s contact.
    #[inline]
    fn call(&self, m: Method, ins: &[&[f64]], outs: &mut [&mut [f64]], case: Option<usize>) {
        let Some(p) = self.program(m) else {
            return;
        };
        REGISTERS.with(|cell| {
            let mut regs = cell.borrow_mut();
            if regs.len() < p.registers {
                regs.resize(p.registers, 0.0);
            }
            execute(&p.code, &mut regs, ins, outs);
            if let Some(c) = case
                && let Some((_, code)) = p.cases.iter().find(|(contact, _)| *contact == c)
            {
                execute(code, &mut regs, ins, outs);
            }
        });
    }
}

/// `a.powi(n)` as the generated code's `powi` computes it: binary powering from the lowest
/// bit, the reciprocal taken last for a negative exponent (LLVM's expansion of a constant
/// exponent and compiler-rt's `__powidf2` both do exactly this).
fn powi(mut a: f64, n: i32) -> f64 {
    let mut b = n;
    let mut r = 1.0;
    loop {
        if b & 1 != 0 {
            r *= a;
        }
        b /= 2;
        if b == 0 {
            break;
        }
        a *= a;
    }
    if n < 0 { 1.0 / r } else { r }
}

fn execute(code: &[Op], r: &mut [f64], ins: &[&[f64]], outs: &mut [&mut [f64]]) {
    for op in code {
        match *op {
            Op::Ld { dst, slot, index } => r[dst as usize] = ins[slot as usize][index as usize],
            Op::LdOut { dst, slot, index } => {
                r[dst as usize] = outs[slot as usize][index as usize];
            }
            Op::St { slot, index, src } => outs[slot as usize][index as usize] = r[src as usize],
            Op::Fill { slot, value } => outs[slot as usize].fill(value),
            Op::Const { dst, value } => r[dst as usize] = value,
            Op::Add { dst, a, b } => r[dst as usize] = r[a as usize] + r[b as usize],
            Op::Sub { dst, a, b } => r[dst as usize] = r[a as usize] - r[b as usize],
            Op::Mul { dst, a, b } => r[dst as usize] = r[a as usize] * r[b as usize],
            Op::Div { dst, a, b } => r[dst as usize] = r[a as usize] / r[b as usize],
            Op::Neg { dst, a } => r[dst as usize] = -r[a as usize],
            Op::Sqrt { dst, a } => r[dst as usize] = r[a as usize].sqrt(),
            Op::Unary { op, dst, a } => r[dst as usize] = unary(op, r[a as usize]),
            Op::Powf { dst, a, b } => r[dst as usize] = r[a as usize].powf(r[b as usize]),
            Op::Powi { dst, a, n } => r[dst as usize] = powi(r[a as usize], n),
            Op::SinCos { sin, cos, a } => {
                let (s, c) = r[a as usize].sin_cos();
                r[sin as usize] = s;
                r[cos as usize] = c;
            }
            Op::StartOffsets { dst, args } => {
                let [t, s, c, d] = args.map(|i| r[i as usize]);
                let (a, b, e, f) = start_offsets(t, s, c, d);
                for (i, v) in dst.into_iter().zip([a, b, e, f]) {
                    r[i as usize] = v;
                }
            }
        }
    }
}

fn unary(op: super::format::Unary, x: f64) -> f64 {
    use super::format::Unary as U;
    match op {
        U::Neg => -x,
        U::Sqrt => x.sqrt(),
        U::Sin => x.sin(),
        U::Cos => x.cos(),
        U::Tan => x.tan(),
        U::Asin => x.asin(),
        U::Acos => x.acos(),
        U::Atan => x.atan(),
        U::Exp => x.exp(),
        U::Ln => x.ln(),
        U::Abs => x.abs(),
    }
}

impl Model for TapeModel {
    fn info(&self) -> &'static ModelInfo {
        self.info
    }

    fn requirements(&self, p: &[f64], out: &mut [f64]) {
        self.call(Method::Requirements, &[p], &mut [out], None);
    }

    fn restitutions(&self, p: &[f64], out: &mut [f64]) {
        self.call(Method::Restitutions, &[p], &mut [out], None);
    }

    fn prepare(&self, p: &[f64], k: &mut [f64]) {
        self.call(Method::Prepare, &[p], &mut [k], None);
    }

    fn initial_state(&self, k: &[f64], q: &mut [f64], qd: &mut [f64]) {
        self.call(Method::InitialState, &[k], &mut [q, qd], None);
    }

    fn points(&self, k: &[f64], q: &[f64], qd: &[f64], pos: &mut [[f64; 2]], vel: &mut [[f64; 2]]) {
        let outs: &mut [&mut [f64]] = &mut [pos.as_flattened_mut(), vel.as_flattened_mut()];
        self.call(Method::Points, &[k, q, qd], outs, None);
    }

    fn energy(&self, k: &[f64], q: &[f64], qd: &[f64]) -> f64 {
        let mut ret = [0.0];
        self.call(Method::Energy, &[k, q, qd], &mut [&mut ret], None);
        ret[0]
    }

    fn momenta(&self, k: &[f64], q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.call(Method::Momenta, &[k, q, qd], &mut [out], None);
    }

    fn equations(&self, k: &[f64], q: &[f64], qd: &[f64], mass: &mut [f64], rhs: &mut [f64]) {
        self.call(Method::Equations, &[k, q, qd], &mut [mass, rhs], None);
    }

    fn forces_full(&self, k: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        self.call(Method::ForcesFull, &[k, q, qd, qdd], &mut [out], None);
    }

    fn gaps(&self, k: &[f64], q: &[f64], out: &mut [f64]) {
        self.call(Method::Gaps, &[k, q], &mut [out], None);
    }

    fn constraints(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        self.call(Method::Constraints, &[k, q, qd], &mut [jac, bias], None);
    }

    fn edges(&self, k: &[f64], q: &[f64], out: &mut [f64]) {
        self.call(Method::Edges, &[k, q], &mut [out], None);
    }

    fn friction(&self, k: &[f64], q: &[f64], qd: &[f64], jac: &mut [f64], bias: &mut [f64]) {
        self.call(Method::Friction, &[k, q, qd], &mut [jac, bias], None);
    }

    fn monitors_full(&self, k: &[f64], q: &[f64], qd: &[f64], forces: &[f64], out: &mut [f64]) {
        self.call(Method::MonitorsFull, &[k, q, qd, forces], &mut [out], None);
    }

    fn to_full(&self, k: &[f64], q: &[f64], qd: &[f64], q_full: &mut [f64], qd_full: &mut [f64]) {
        self.call(Method::ToFull, &[k, q, qd], &mut [q_full, qd_full], None);
    }

    fn drawing(&self, k: &[f64], q: &[f64], poses: &mut [[f64; 3]], sizes: &mut [f64]) {
        self.call(
            Method::Drawing,
            &[k, q],
            &mut [poses.as_flattened_mut(), sizes],
            None,
        );
    }

    fn tangents(&self) -> Option<&dyn Tangents> {
        let has = |m| self.program(m).is_some();
        (has(Method::TangentRows) && has(Method::InitialTangents)).then_some(self as &dyn Tangents)
    }

    fn reduction(&self) -> Option<&dyn Reduction> {
        self.info.reduction.map(|_| self as &dyn Reduction)
    }
}

impl Reduction for TapeModel {
    fn reduced(&self, k: &[f64], delta: f64) -> Reduced {
        let mut ret = [0.0; 4];
        self.call(Method::Reduced, &[k, &[delta]], &mut [&mut ret], None);
        Reduced {
            sin: ret[0],
            cos: ret[1],
            theta_dot_sq: ret[2],
            theta_ddot: ret[3],
        }
    }

    fn theta_dot_sq_sc(&self, k: &[f64], s: f64, c: f64, ds: f64, dc: f64) -> f64 {
        let mut ret = [0.0];
        let ins: &[&[f64]] = &[k, &[s], &[c], &[ds], &[dc]];
        self.call(Method::ThetaDotSqSc, ins, &mut [&mut ret], None);
        ret[0]
    }

    fn forces(&self, k: &[f64], delta: f64, out: &mut [f64]) {
        self.call(Method::Forces, &[k, &[delta]], &mut [out], None);
    }

    fn force_polynomial(&self, k: &[f64], contact: usize, out: &mut [f64]) {
        self.call(Method::ForcePolynomial, &[k], &mut [out], Some(contact));
    }

    fn fall_polynomial(&self, k: &[f64], out: &mut [f64]) {
        self.call(Method::FallPolynomial, &[k], &mut [out], None);
    }

    fn partials(&self) -> Option<&dyn Partials> {
        (self.program(Method::SeparationPartials).is_some()).then_some(self as &dyn Partials)
    }

    fn prepare_lean(&self, p: &[f64], k: &mut [f64]) {
        self.call(Method::PrepareLean, &[p], &mut [k], None);
    }

    fn full_state(
        &self,
        k: &[f64],
        t: f64,
        delta: f64,
        theta_dot: f64,
        q: &mut [f64],
        qd: &mut [f64],
    ) {
        let ins: &[&[f64]] = &[k, &[t], &[delta], &[theta_dot]];
        self.call(Method::FullState, ins, &mut [q, qd], None);
    }
}

impl Tangents for TapeModel {
    fn tangent_rows(&self, k: &[f64], at: &TangentPoint<'_>, out: &mut [f64]) {
        let ins: &[&[f64]] = &[k, at.q, at.qd, at.qdd, at.forces, at.friction];
        self.call(Method::TangentRows, ins, &mut [out], None);
    }

    fn initial_tangents(&self, k: &[f64], out: &mut [f64]) {
        self.call(Method::InitialTangents, &[k], &mut [out], None);
    }
}

impl Partials for TapeModel {
    fn separation_partials(&self, k: &[f64], s: f64, c: f64, out: &mut [f64]) {
        self.call(
            Method::SeparationPartials,
            &[k, &[s], &[c]],
            &mut [out],
            None,
        );
    }

    fn theta_dot_sq_partials(&self, k: &[f64], s: f64, c: f64, out: &mut [f64]) {
        self.call(
            Method::ThetaDotSqPartials,
            &[k, &[s], &[c]],
            &mut [out],
            None,
        );
    }

    fn start_partials(&self, k: &[f64], out: &mut [f64]) {
        self.call(Method::StartPartials, &[k], &mut [out], None);
    }

    fn fall_partials(&self, k: &[f64], out: &mut [f64]) {
        self.call(Method::FallPartials, &[k], &mut [out], None);
    }
}

#[cfg(test)]
mod tests {
    use super::super::check::METHODS;
    use super::*;

    #[test]
    fn methods_are_listed_in_the_order_of_their_enum() {
        for (i, s) in METHODS.iter().enumerate() {
            assert_eq!(s.method as usize, i, "{}", s.name);
        }
    }

    /// As in the generated code, the base is only known at run time (a literal base would be
    /// folded by the compiler with the host's `pow`, which the generated code never meets).
    #[test]
    fn powi_matches_the_compiled_powi_for_constant_exponents() {
        for x in [0.3_f64, 1.7, -2.9, 1e-3, 123.456] {
            let x = std::hint::black_box(x);
            assert_eq!(powi(x, 2).to_bits(), x.powi(2).to_bits());
            assert_eq!(powi(x, 3).to_bits(), x.powi(3).to_bits());
            assert_eq!(powi(x, 4).to_bits(), x.powi(4).to_bits());
            assert_eq!(powi(x, 5).to_bits(), x.powi(5).to_bits());
            assert_eq!(powi(x, 7).to_bits(), x.powi(7).to_bits());
            assert_eq!(powi(x, -3).to_bits(), x.powi(-3).to_bits());
        }
    }
}
