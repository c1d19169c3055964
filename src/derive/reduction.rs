//! Stage 6 of the derivation, the reduction: the fast path of a phase in which every
//! coordinate but the reduced one (`theta`) is cyclic. The cyclic velocities follow from their
//! conserved momenta, the energy integral gives `theta_dot^2` as a function of the angle, the
//! cyclic positions have closed forms, and every closed contact's force on the reduced motion
//! is `F0 + F2 theta_dot^2` (with `theta_ddot` from the integral); where a force's zero is a
//! root of a polynomial in `sin(theta)`, that polynomial.
//!
//! The energy integral holds for any conservative phase whose effective potential is a
//! rational function of `sin(theta)` and `cos(theta)` (springs included):
//! `theta_dot^2 = (A_i theta_dot_i^2 + 2 (V(theta_i) - V(theta))) / A(theta)`, with the drop
//! `V(theta_i) - V(theta)` written in the drops `rc_ds = sin(theta_i) - sin(theta)` and
//! `rc_dc = cos(theta_i) - cos(theta)` (the difference's constant terms cancel symbolically,
//! so it is formed without cancellation near the start). A phase outside that class is not an
//! error: it is solved by integrating `M(q) qdd = F`, and the reason is recorded.

use super::algebra::{
    coefficients_in_s, collect_over, constant_value, d_theta, fall_polynomial, free_of, from_sc,
    gap_vars, is_zero_trig, positive, reduce_cos_sq, simplify_inverse_trig, solve_linear,
    strip_signed, to_expr, to_sc,
};
use super::cas::{self, A};
use super::constraints::ContactAtoms;
use super::equations::Equations;
use super::expr::{Expr, product};
use super::lagrangian::Lagrangian;
use super::positivity::{push_proof, release_proof};
use super::setup::Setup;
use super::spec::Spec;
use super::types::{
    Constant, DeriveError, Partials, PushProof, Reduction, ReleaseProof, Separation, Unreducible,
    at, key,
};
use std::collections::BTreeMap;

/// Stage 6, the reduction: the fast path of a phase, from its Lagrangian and equations.
pub struct Reducer<'a> {
    /// The spec (its contacts' names and kinds).
    pub spec: &'a Spec,
    /// The phase.
    pub st: &'a Setup,
    /// Its reduced coordinate's index and name.
    pub reduced: (usize, &'a str),
    /// Its Lagrangian.
    pub lag: &'a Lagrangian,
    /// Its equations.
    pub eqs: &'a Equations,
    /// The initial state of its coordinates, over its parameters.
    pub initial: &'a BTreeMap<String, [Expr; 2]>,
    /// Symbols known to be strictly positive (positive parameters).
    pub positive: Vec<String>,
}

/// The reduced motion's building blocks, shared by the steps of the reduction.
struct Reduced {
    constants: Vec<Constant>,
    cyc_vel: Vec<A>,
    wsq: A,
    acc: A,
    inertia: A,
    e_red: A,
}

impl Reducer<'_> {
    /// The reduced coordinate.
    fn theta(&self) -> &str {
        self.reduced.1
    }

    fn init(&self, c: &str, what: usize) -> Result<Expr, DeriveError> {
        self.initial.get(c).map(|v| v[what].clone()).ok_or_else(|| {
            at(
                &[key("initial")],
                format!("no initial value for coordinate `{c}`"),
            )
        })
    }

    /// The fast path, or why there is none (an `Err` of the outer result is a real error).
    pub fn reduce(
        &self,
        contacts: &[ContactAtoms],
    ) -> Result<Result<Reduction, Unreducible>, DeriveError> {
        if let Some(why) = self.edges_off_the_angle(contacts) {
            return Ok(Err(why));
        }
        if let Some(why) = self.unreducible_coordinates() {
            return Ok(Err(why));
        }
        let mut constants = self.start_constants()?;
        let cyc_vel = match self.cyclic_velocities(&mut constants)? {
            Ok(v) => v,
            Err(why) => return Ok(Err(why)),
        };
        let red = match self.energy_integral(constants, cyc_vel)? {
            Ok(r) => r,
            Err(why) => return Ok(Err(why)),
        };
        let (cyclic_position, cyc_acc) = match self.cyclic_positions(&red.cyc_vel)? {
            Ok(v) => v,
            Err(why) => return Ok(Err(why)),
        };
        let mut forces_reduced = Vec::new();
        for (c, row) in self.spec.contacts.iter().zip(contacts) {
            match &row.force {
                None => forces_reduced.push(cas::num(0)),
                Some(f) => match self.reduced_force(
                    &start_values_read(f, &red.constants),
                    &red.cyc_vel,
                    &cyc_acc,
                )? {
                    Ok(r) => forces_reduced.push(start_as_drops(&r)?),
                    Err(why) => {
                        return Ok(Err(Unreducible::Force {
                            contact: c.name.clone(),
                            why: Box::new(why),
                        }));
                    }
                },
            }
        }
        // Where a unilateral contact's force has no polynomial zero, the runtime finds it as a
        // bracketed root of the reduced force itself.
        let mut force_polynomials = Vec::new();
        for ((c, row), f) in self.spec.contacts.iter().zip(contacts).zip(&forces_reduced) {
            force_polynomials.push(match row.force {
                Some(_) if !c.bilateral => self.separation(&red, f)?.ok(),
                _ => None,
            });
        }
        let (push_proofs, release_proof) = self.push_proofs(&force_polynomials)?;
        let fall = fall_polynomial(&red.wsq, &self.st.coords, self.theta())?;
        let plain = self.plain_forms(&red, contacts, &forces_reduced, &force_polynomials)?;
        Ok(Ok(Reduction {
            reduced_inertia: to_expr(&red.inertia, "inertia")?,
            reduced_energy: to_expr(&red.e_red, "reduced energy")?,
            theta_dot_sq: to_expr(&red.wsq, "theta_dot_sq")?,
            theta_ddot: to_expr(&red.acc, "theta_ddot")?,
            cyclic_velocity: (red.cyc_vel.iter())
                .map(|e| to_expr(e, "cyclic velocity"))
                .collect::<Result<_, _>>()?,
            cyclic_position,
            forces_reduced: (forces_reduced.iter())
                .map(|e| to_expr(e, "force"))
                .collect::<Result<_, _>>()?,
            constants: red.constants,
            force_polynomials,
            push_proofs,
            release_proof,
            fall,
            plain,
            partials: Partials::default(),
        }))
    }

    /// On the fast path an edge is located as a root in the angle: a closed contact's edge may
    /// depend on `theta` and the parameters only.
    fn edges_off_the_angle(&self, contacts: &[ContactAtoms]) -> Option<Unreducible> {
        let others: Vec<&str> = (self.st.coords.iter())
            .filter(|c| *c != self.theta())
            .map(String::as_str)
            .collect();
        for (c, row) in self.spec.contacts.iter().zip(contacts) {
            if let (Some(_), Some(edge)) = (&row.force, &row.edge)
                && !free_of(edge, &others)
            {
                return Some(Unreducible::EdgeOffTheAngle {
                    contact: c.name.clone(),
                    others: others.join(", "),
                    theta: self.theta().to_string(),
                });
            }
        }
        None
    }

    /// Every coordinate but the reduced one must be cyclic, with an inertia free of `theta`.
    fn unreducible_coordinates(&self) -> Option<Unreducible> {
        let (st, eqs) = (self.st, self.eqs);
        for (i, c) in st.coords.iter().enumerate() {
            if i != self.reduced.0 && !eqs.cyclic.contains(&i) {
                return Some(Unreducible::NotCyclic {
                    coordinate: c.clone(),
                });
            }
        }
        for &i in &eqs.cyclic {
            for &j in &eqs.cyclic {
                if !free_of(&eqs.mass[i][j], &[self.theta()]) {
                    return Some(Unreducible::InertiaOnTheAngle {
                        coordinate: st.coords[i].clone(),
                        theta: self.theta().to_string(),
                    });
                }
            }
        }
        None
    }

    /// `theta_i`, `theta_dot_i`, their sine and cosine, the initial cyclic positions and the
    /// conserved momenta, as constants over the parameters.
    fn start_constants(&self) -> Result<Vec<Constant>, DeriveError> {
        let theta = self.theta();
        // sin and cos of the start are formed from the start's own expression where it is an
        // inverse function (sin(asin(a/ell)) = a/ell exactly; cos(asin(x)) = sqrt((1-x)(1+x)),
        // which keeps full relative accuracy near upright, unlike cos of an angle near pi/2).
        let theta_i = self.init(theta, 0)?;
        let start_trig = |f: &str| match &theta_i {
            Expr::Fun(g, _) if g == "asin" || g == "acos" => {
                simplify_inverse_trig(&Expr::Fun(f.into(), vec![theta_i.clone()]))
            }
            _ => Expr::Fun(f.into(), vec![Expr::sym("rc_thi")]),
        };
        let mut constants = vec![
            Constant {
                symbol: "rc_thi".into(),
                value: theta_i.clone(),
            },
            Constant {
                symbol: "rc_wi".into(),
                value: self.init(theta, 1)?,
            },
            Constant {
                symbol: "rc_si".into(),
                value: start_trig("sin"),
            },
            Constant {
                symbol: "rc_ci".into(),
                value: start_trig("cos"),
            },
        ];
        let (st, eqs) = (self.st, self.eqs);
        let wi = self.start_rate(&constants);
        let initial_state = |a: &A| -> A {
            let mut out = to_sc(a, theta);
            out = cas::subs_var(&out, "rc_s", &cas::var("rc_si"));
            out = cas::subs_var(&out, "rc_c", &cas::var("rc_ci"));
            out = cas::subs_var(&out, theta, &cas::var("rc_thi"));
            out = cas::subs_var(&out, &format!("dot_{theta}"), &wi);
            for (j, &i) in eqs.cyclic.iter().enumerate() {
                out = cas::subs_var(&out, &st.coords[i], &cas::var(&format!("rc_x{j}i")));
            }
            out
        };
        let mut cyclic_init_vel = Vec::new();
        for (j, &i) in eqs.cyclic.iter().enumerate() {
            constants.push(Constant {
                symbol: format!("rc_x{j}i"),
                value: self.init(&st.coords[i], 0)?,
            });
            cyclic_init_vel.push(cas::atom(&self.init(&st.coords[i], 1)?));
        }
        for (j, p) in eqs.momenta.iter().enumerate() {
            let mut v = initial_state(p);
            for (jj, &i) in eqs.cyclic.iter().enumerate() {
                v = cas::subs_var(&v, &format!("dot_{}", st.coords[i]), &cyclic_init_vel[jj]);
            }
            constants.push(Constant {
                symbol: format!("rc_p{j}"),
                value: to_expr(&cas::expand(&v), "momentum")?,
            });
        }
        Ok(constants)
    }

    /// The start's rate: a number when it is one (a start from rest), so that the derived
    /// forms simplify exactly as a person would simplify them.
    fn start_rate(&self, constants: &[Constant]) -> A {
        constant_value(constants, "rc_wi")
    }

    /// Cyclic velocities from the conserved momenta: `M_CC qd_C = P - M_Cr theta_dot`.
    fn cyclic_velocities(
        &self,
        constants: &mut [Constant],
    ) -> Result<Result<Vec<A>, Unreducible>, DeriveError> {
        let (eqs, theta) = (self.eqs, self.theta());
        let w = cas::var("rc_w");
        let k = eqs.cyclic.len();
        let momentum: Vec<A> = (0..k)
            .map(|j| constant_value(constants, &format!("rc_p{j}")))
            .collect();
        let mat: Vec<Vec<A>> = (eqs.cyclic.iter())
            .map(|&i| {
                eqs.cyclic
                    .iter()
                    .map(|&j| to_sc(&eqs.mass[i][j], theta))
                    .collect()
            })
            .collect();
        let vec_b: Vec<A> = (eqs.cyclic.iter().enumerate())
            .map(|(jj, &i)| {
                momentum[jj].clone() - to_sc(&eqs.mass[i][self.reduced.0], theta) * w.clone()
            })
            .collect();
        Ok(match solve_linear(mat, vec_b) {
            Some(v) => Ok(v.iter().map(|x| cas::expand(&cas::together(x))).collect()),
            None => Err(Unreducible::SingularCyclicInertia),
        })
    }

    /// The energy integral: `theta_dot^2` and `theta_ddot` over the start's drops, with the
    /// reduced inertia `A(theta)` and the effective potential `alpha + beta s + gamma c`.
    fn energy_integral(
        &self,
        mut constants: Vec<Constant>,
        cyc_vel: Vec<A>,
    ) -> Result<Result<Reduced, Unreducible>, DeriveError> {
        let (st, eqs, theta) = (self.st, self.eqs, self.theta());
        let w = cas::var("rc_w");
        let reduce_state = |a: &A| -> A {
            let mut out = to_sc(a, theta);
            for (jj, &i) in eqs.cyclic.iter().enumerate() {
                out = cas::subs_var(&out, &format!("dot_{}", st.coords[i]), &cyc_vel[jj]);
            }
            cas::subs_var(&out, &format!("dot_{theta}"), &w)
        };
        let total = self.lag.kinetic.clone() + self.lag.potential.clone();
        let total = start_values_read(&total, &constants);
        let e_red = cas::expand(&reduce_state(&total));
        let e_red = cas::expand(&cas::together(&e_red));
        let inertia = reduce_cos_sq(&cas::expand(&cas::d(&cas::d(&e_red, "rc_w"), "rc_w")));
        let inertia = cas::expand(&cas::together(&inertia));
        let linear = cas::subs_var(&cas::d(&e_red, "rc_w"), "rc_w", &cas::num(0));
        if !is_zero_trig(&linear).map_err(|m| at(&[], m.to_string()))? {
            return Ok(Err(Unreducible::LinearInRate));
        }
        let v_eff = cas::subs_var(&e_red, "rc_w", &cas::num(0));
        let mut motion: Vec<&str> = vec![theta];
        motion.extend(st.coords.iter().map(String::as_str));
        if !free_of(&v_eff, &motion) {
            return Ok(Err(Unreducible::PotentialOffTrig {
                theta: theta.to_string(),
            }));
        }
        let ai = cas::subs_var(
            &cas::subs_var(&inertia, "rc_s", &cas::var("rc_si")),
            "rc_c",
            &cas::var("rc_ci"),
        );
        constants.push(Constant {
            symbol: "rc_ai".into(),
            value: to_expr(&cas::expand(&ai), "initial inertia")?,
        });
        let wi = self.start_rate(&constants);
        let two = cas::num(2);
        let wsq =
            (cas::var("rc_ai") * wi.clone() * wi + two * potential_drop(&v_eff)?) / inertia.clone();
        let wsq = cas::together(&wsq);
        let half = cas::atom(&Expr::Rational(1, 2));
        let acc = cas::together(&(half * d_theta(&wsq)));
        Ok(Ok(Reduced {
            constants,
            cyc_vel,
            wsq,
            acc,
            inertia,
            e_red,
        }))
    }

    /// Cyclic positions in closed form (the velocities must be affine in sin and cos of
    /// `theta`) and the cyclic accelerations, over the reduced motion.
    #[allow(clippy::type_complexity)]
    fn cyclic_positions(
        &self,
        cyc_vel: &[A],
    ) -> Result<Result<(Vec<Expr>, Vec<A>), Unreducible>, DeriveError> {
        let (st, eqs, theta) = (self.st, self.eqs, self.theta());
        let mut positions = Vec::new();
        let mut accelerations = Vec::new();
        for (jj, v) in cyc_vel.iter().enumerate() {
            let a0 = cas::expand(&cas::subs_var(v, "rc_w", &cas::num(0)));
            let b = cas::expand(&cas::d(v, "rc_w"));
            let bs = cas::expand(&cas::d(&b, "rc_s"));
            let bc = cas::expand(&cas::d(&b, "rc_c"));
            let b0 = cas::expand(
                &(b.clone() - bs.clone() * cas::var("rc_s") - bc.clone() * cas::var("rc_c")),
            );
            let motion = ["rc_s", "rc_c", "rc_w"];
            let ok = [&a0, &bs, &bc, &b0].iter().all(|x| free_of(x, &motion));
            if !ok {
                return Ok(Err(Unreducible::OpenPosition {
                    coordinate: st.coords[eqs.cyclic[jj]].clone(),
                    theta: theta.to_string(),
                }));
            }
            let pos = cas::var(&format!("rc_x{jj}i"))
                + a0 * cas::var("rc_t")
                + bs.clone() * cas::var("rc_dc")
                - bc.clone() * cas::var("rc_ds")
                - b0 * cas::var("rc_delta");
            positions.push(to_expr(&cas::expand(&pos), "cyclic position")?);
            let bprime = bs * cas::var("rc_c") - bc * cas::var("rc_s");
            accelerations.push(cas::expand(
                &(bprime * cas::var("rc_w2") + b * cas::var("rc_acc")),
            ));
        }
        Ok(Ok((positions, accelerations)))
    }

    /// A force on the reduced motion, which must be `F0 + F2 theta_dot^2` (with `theta_ddot`
    /// kept as a symbol), each coefficient collected over one denominator.
    fn reduced_force(
        &self,
        full: &A,
        cyc_vel: &[A],
        cyc_acc: &[A],
    ) -> Result<Result<A, Unreducible>, DeriveError> {
        let (st, eqs, theta) = (self.st, self.eqs, self.theta());
        let mut r = to_sc(full, theta);
        for (jj, &ci) in eqs.cyclic.iter().enumerate() {
            let c = &st.coords[ci];
            r = cas::subs_var(&r, &format!("ddot_{c}"), &cyc_acc[jj]);
            r = cas::subs_var(&r, &format!("dot_{c}"), &cyc_vel[jj]);
        }
        r = cas::subs_var(&r, &format!("ddot_{theta}"), &cas::var("rc_acc"));
        r = cas::expand(&cas::subs_var(
            &r,
            &format!("dot_{theta}"),
            &cas::var("rc_w"),
        ));
        let half = cas::atom(&Expr::Rational(1, 2));
        let f0 = cas::subs_var(&r, "rc_w", &cas::num(0));
        let f1 = cas::subs_var(&cas::d(&r, "rc_w"), "rc_w", &cas::num(0));
        let f2 = cas::expand(&(half * cas::d(&cas::d(&r, "rc_w"), "rc_w")));
        let f3 = cas::d(&f2, "rc_w");
        if !cas::is_zero(&f1) || !cas::is_zero(&f3) {
            return Ok(Err(Unreducible::NotQuadraticInRate));
        }
        Ok(Ok(collect_over(
            &cas::expand(&(f0 + f2 * cas::var("rc_w2"))),
            &["rc_s", "rc_c", "rc_w2", "rc_acc"],
        )?))
    }

    /// The separation polynomial in `sin(theta)`: the contact force's numerator on the
    /// reduced motion, with `sin^2 + cos^2 = 1` and positive factors removed.
    fn separation(
        &self,
        red: &Reduced,
        contact_force: &A,
    ) -> Result<Result<Separation, Unreducible>, DeriveError> {
        let f = cas::together(&gap_vars(&self.on_motion(red, contact_force)));
        let fe = to_expr(&f, "contact force")?;
        let (num, den) = fe.num_den();
        let mut positive_symbols = self.positive.clone();
        positive_symbols.push("rc_si".into());
        positive_symbols.push("rc_ci".into());
        // The polynomial keeps the force's sign only where its denominator is evidently
        // positive (a square, positive parameters); otherwise the zero is bracketed instead.
        if !positive(&product(den), &positive_symbols) {
            return Ok(Err(Unreducible::DenominatorSign));
        }
        let numer = reduce_cos_sq(&cas::atom(&product(num)));
        let p0 = cas::expand(&cas::subs_var(&numer, "rc_c", &cas::num(0)));
        let p1 = cas::expand(&cas::subs_var(
            &cas::d(&numer, "rc_c"),
            "rc_c",
            &cas::num(0),
        ));
        let check = cas::expand(&(numer.clone() - p0.clone() - p1.clone() * cas::var("rc_c")));
        if !cas::is_zero(&check) {
            return Ok(Err(Unreducible::NumeratorNotLinearInCos));
        }
        // A factor cos(theta) is positive on the phase (0 < theta < pi/2).
        let poly = if cas::is_zero(&p1) {
            p0
        } else if cas::is_zero(&p0) {
            p1
        } else {
            return Ok(Err(Unreducible::MixedSinCos));
        };
        let (poly, negated) = strip_signed(&poly, &positive_symbols)?;
        let poly = if negated {
            cas::expand(&(cas::num(0) - poly))
        } else {
            poly
        };
        match coefficients_in_s(&poly, "coefficient")? {
            Some(coefficients) => Ok(Ok(Separation {
                coefficients,
                polynomial: to_expr(&poly, "separation polynomial")?,
            })),
            None => Ok(Err(Unreducible::DegreeAbove16)),
        }
    }

    /// Per contact, the proof that its push stays positive over the phase
    /// ([`push_proof`]), for every closed contact but the first (whose force's zero ends the
    /// phase) with a force polynomial; and the proof that the first pushes at release
    /// ([`release_proof`]). Both hold for `s = sin(theta) >= 0` (so `sin(theta_i) > 0` where
    /// the phase falls): a phase whose end angle is negative or unknown gets none.
    fn push_proofs(
        &self,
        force_polynomials: &[Option<Separation>],
    ) -> Result<(Vec<Option<PushProof>>, Option<ReleaseProof>), DeriveError> {
        let above_flat = self
            .spec
            .end_angle
            .is_some_and(|e| (0.0..std::f64::consts::FRAC_PI_2).contains(&e));
        let mut proofs = Vec::with_capacity(force_polynomials.len());
        for (i, p) in force_polynomials.iter().enumerate() {
            proofs.push(match p {
                Some(sep) if i > 0 && above_flat => push_proof(&sep.coefficients, &self.positive)?,
                _ => None,
            });
        }
        let release = match force_polynomials.first() {
            Some(Some(sep)) if above_flat => release_proof(&sep.coefficients, &self.positive)?,
            _ => None,
        };
        Ok((proofs, release))
    }

    /// A reduced expression with `theta_dot^2` and `theta_ddot` substituted.
    fn on_motion(&self, red: &Reduced, a: &A) -> A {
        let out = cas::subs_var(a, "rc_w2", &red.wsq);
        cas::subs_var(&out, "rc_acc", &red.acc)
    }

    /// Fully substituted forms over parameters and `theta`, for people and other tools.
    fn plain_forms(
        &self,
        red: &Reduced,
        contacts: &[ContactAtoms],
        forces_reduced: &[A],
        force_polynomials: &[Option<Separation>],
    ) -> Result<BTreeMap<String, Expr>, DeriveError> {
        let theta = self.theta();
        let const_plain = plain_constants(&red.constants)?;
        let plainify = |a: &A| -> Result<Expr, DeriveError> {
            let v = over_parameters(a, &const_plain);
            let v = to_expr(&cas::together(&v), "plain form")?;
            let (num, den) = v.num_den();
            let num = reduce_cos_sq(&cas::atom(&product(num)));
            let den = reduce_cos_sq(&cas::atom(&product(den)));
            let v = cas::together(&cas::factor(&(num / den)));
            Ok(from_sc(&to_expr(&v, "plain form")?, theta))
        };
        let mut plain = BTreeMap::new();
        plain.insert("theta_dot_sq".to_string(), plainify(&red.wsq)?);
        plain.insert("theta_ddot".to_string(), plainify(&red.acc)?);
        plain.insert("reduced_inertia".to_string(), plainify(&red.inertia)?);
        for ((c, row), f) in self.spec.contacts.iter().zip(contacts).zip(forces_reduced) {
            if row.force.is_some() {
                plain.insert(c.name.clone(), plainify(&self.on_motion(red, f))?);
            }
        }
        if let Some(Some(sep)) = force_polynomials.first() {
            plain.insert(
                "separation_condition".to_string(),
                plainify(&cas::atom(&sep.polynomial))?,
            );
        }
        Ok(plain)
    }
}

/// `a` with each start constant that is a root or a call (`rc_ci = ((1 - x)(1 + x))^(1/2)`
/// for a start `asin(x)`, `rc_thi = asin(x)`) read as its symbol where `a` holds its value in
/// the same form, or expanded: a spring unstretched at the start (`ell*cos(asin(a/ell))`)
/// then leaves no `rc_ci - root`, zero at every point, in the potential's drop, and no second
/// slot of `rc_ci`'s value in the forces.
fn start_values_read(a: &A, constants: &[Constant]) -> A {
    let mut out = a.clone();
    for c in constants {
        let root_or_call = match &c.value {
            Expr::Fun(..) => true,
            Expr::Pow(_, x) => x.as_integer().is_none(),
            _ => false,
        };
        if root_or_call {
            // As written, and expanded (as an expanded force holds it).
            let value = cas::atom(&c.value);
            out = cas::subs(&out, &value, &cas::var(&c.symbol));
            out = cas::subs(&out, &cas::expand(&value), &cas::var(&c.symbol));
        }
    }
    out
}

/// A reduced force with the start's sine and cosine written as their value now plus the drop
/// (`rc_si = rc_s + rc_ds`, `rc_ci = rc_c + rc_dc`), so that a difference from the start
/// cancels symbolically. A spring unstretched at the start pushes with `k ell (rc_c - rc_ci)`:
/// formed as written, a nearly flat rod (`theta_i = 1e-7`) loses that push (`1e-14` of
/// `k ell`) to the rounding of `cos` (`1e-16`), and the contact's end moved by `3e-6`; as
/// `-k ell rc_dc` it keeps every digit.
fn start_as_drops(force: &A) -> Result<A, DeriveError> {
    let now_plus_drop = |now: &str, drop: &str| cas::var(now) + cas::var(drop);
    let out = cas::subs_var(force, "rc_ci", &now_plus_drop("rc_c", "rc_dc"));
    let out = cas::subs_var(&out, "rc_si", &now_plus_drop("rc_s", "rc_ds"));
    collect_over(
        &cas::expand(&out),
        &["rc_s", "rc_c", "rc_ds", "rc_dc", "rc_w2", "rc_acc"],
    )
}

/// Each reduction constant's value over the parameters alone, in the constants' order (the
/// earlier ones substituted into the later ones, inverse trigonometric pairs simplified).
pub fn plain_constants(constants: &[Constant]) -> Result<Vec<(String, A)>, DeriveError> {
    let mut const_plain: Vec<(String, A)> = Vec::new();
    for c in constants {
        let mut v = cas::atom(&simplify_inverse_trig(&c.value));
        for (s, val) in &const_plain {
            v = cas::subs_var(&v, s, val);
        }
        let v = cas::atom(&simplify_inverse_trig(&to_expr(&v, "constant")?));
        const_plain.push((c.symbol.clone(), v));
    }
    Ok(const_plain)
}

/// A reduced expression over the parameters, `rc_s` and `rc_c`: the drops written out and
/// every constant replaced by its value from [`plain_constants`].
pub fn over_parameters(a: &A, const_plain: &[(String, A)]) -> A {
    let mut v = gap_vars(a);
    for (s, val) in const_plain.iter().rev() {
        v = cas::subs_var(&v, s, val);
    }
    v
}

/// `V(theta_i) - V(theta)` in the drops `rc_ds`, `rc_dc` for an effective potential over
/// `rc_s`, `rc_c`: `2 beta rc_ds + 2 gamma rc_dc`'s halves for the usual
/// `alpha + beta sin + gamma cos`; otherwise `V(rc_si, rc_ci) - V(rc_si - rc_ds, rc_ci - rc_dc)`
/// brought over one denominator, whose terms free of the drops cancel symbolically.
fn potential_drop(v_eff: &A) -> Result<A, DeriveError> {
    let beta = cas::expand(&cas::d(v_eff, "rc_s"));
    let gamma = cas::expand(&cas::d(v_eff, "rc_c"));
    let rest = cas::expand(
        &(v_eff.clone() - beta.clone() * cas::var("rc_s") - gamma.clone() * cas::var("rc_c")),
    );
    let trig = ["rc_s", "rc_c"];
    if free_of(&beta, &trig) && free_of(&gamma, &trig) && free_of(&rest, &trig) {
        return Ok(beta * cas::var("rc_ds") + gamma * cas::var("rc_dc"));
    }
    let at = |s: A, c: A| cas::subs_var(&cas::subs_var(v_eff, "rc_s", &s), "rc_c", &c);
    let start = at(cas::var("rc_si"), cas::var("rc_ci"));
    let now = at(
        cas::var("rc_si") - cas::var("rc_ds"),
        cas::var("rc_ci") - cas::var("rc_dc"),
    );
    let drop = cas::together(&(start - now));
    let at_start = cas::subs_var(
        &cas::subs_var(&drop, "rc_ds", &cas::num(0)),
        "rc_dc",
        &cas::num(0),
    );
    if !cas::is_zero(&cas::together(&at_start)) {
        return Err(at_err(
            "the potential's drop from the start does not vanish at the start".into(),
        ));
    }
    Ok(drop)
}

fn at_err(message: String) -> DeriveError {
    at(&[key("potentials")], message)
}
