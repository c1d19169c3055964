//! Static equilibrium: whether a system whose closed contacts and stuck frictions pin every
//! coordinate stays at rest, with the force family of redundant (statically indeterminate)
//! supports searched for one that every contact and friction law admits.
//!
//! A ladder stuck at both ends has four support forces for three equations of equilibrium:
//! its equations of motion are singular, yet the motion is determinate (it stays put) if some
//! member of the one-parameter family of forces pushes at both contacts and keeps both
//! frictions within `mu N`. That is a small linear feasibility problem, solved here by its
//! vertices.

use crate::model::ModelInfo;
use crate::results::Indeterminacy;
use crate::solve::SolveError;
use crate::solve::integrated::active::{Active, DECIDE_TOLERANCE, Mode, check_active};
use crate::system::{Bound, State};
use nalgebra::{DMatrix, DVector};

/// Largest number of vertices [`holds`] examines before it gives up (no decision).
pub const MAX_VERTICES: usize = 100_000;

/// Relative size below which a singular value counts as zero (rank decisions).
const RANK_TOLERANCE: f64 = 1e-10;

/// The support rows of an active set: the closed constraint rows (contact indices) and the
/// stuck frictions (friction indices), or `None` where a friction slides or acts at a contact
/// the model eliminates (its normal force is then no unknown here).
fn support_rows(info: &ModelInfo, active: &Active) -> Option<(Vec<usize>, Vec<usize>)> {
    let kkt: Vec<usize> = (0..info.contacts.len())
        .filter(|&i| active.closed[i] && !info.contacts[i].closed)
        .collect();
    let acting: Vec<usize> = (0..info.frictions.len())
        .filter(|&j| active.friction_acts(info, j))
        .collect();
    let all_stick = acting.iter().all(|&j| active.modes[j] == Mode::Stick);
    let rows_known = acting
        .iter()
        .all(|&j| kkt.contains(&info.frictions[j].contact_index));
    (all_stick && rows_known).then_some((kkt, acting))
}

/// The stacked support rows `G` (one per closed contact, then one per stuck friction).
fn stacked(
    sys: &Bound,
    state: &State,
    kkt: &[usize],
    acting: &[usize],
) -> Result<DMatrix<f64>, SolveError> {
    let n = sys.n_coordinates();
    let (jac, _) = sys.constraints(state)?;
    let (tjac, _) = sys.friction(state)?;
    let rows = kkt.len() + acting.len();
    Ok(DMatrix::from_fn(rows, n, |r, c| {
        if r < kkt.len() {
            jac[kkt[r] * n + c]
        } else {
            tjac[acting[r - kkt.len()] * n + c]
        }
    }))
}

/// Whether `active`'s closed contacts and stuck frictions pin every coordinate (their rows
/// have full column rank): then the only motion they allow from rest is none. A state or
/// active set that does not fit the model is an error.
pub fn pins(sys: &Bound, state: &State, active: &Active) -> Result<bool, SolveError> {
    let info = sys.info();
    sys.check_state(state)?;
    check_active(info, active)?;
    let Some((kkt, acting)) = support_rows(info, active) else {
        return Ok(false);
    };
    let n = sys.n_coordinates();
    if kkt.len() + acting.len() < n {
        return Ok(false);
    }
    let g = stacked(sys, state, &kkt, &acting)?;
    let sv = g.singular_values();
    let top = sv.iter().fold(0.0f64, |m, s| m.max(*s));
    Ok(top > 0.0 && sv.iter().filter(|s| **s > RANK_TOLERANCE * top).count() == n)
}

/// Support forces that hold a system at rest: every contact's (in the model's order), then
/// every friction's.
pub type Supports = (Vec<f64>, Vec<f64>);

/// Whether the system at rest at `state` stays there with `active` closed and stuck although
/// its supports are redundant: some member of the family of support forces that balances the
/// applied forces (`G^T y = -Q`) pushes at every closed unilateral contact and keeps every
/// stuck friction within `mu N`. Returns that member (contact forces in the model's order,
/// then friction forces), or `None` where none exists or the set does not pin the system. A
/// search that passes [`MAX_VERTICES`] decides nothing and is [`SolveError::Indeterminate`];
/// a state or active set that does not fit the model is an error.
pub fn holds(
    sys: &Bound,
    state: &State,
    active: &Active,
    t: f64,
) -> Result<Option<Supports>, SolveError> {
    let info = sys.info();
    if !pins(sys, state, active)? {
        return Ok(None);
    }
    let Some((kkt, acting)) = support_rows(info, active) else {
        return Ok(None);
    };
    let g = stacked(sys, state, &kkt, &acting)?;
    let (_, rhs) = sys.equations(state)?;
    let q = DVector::from_vec(rhs);
    let undecided = |why: Indeterminacy| SolveError::Indeterminate {
        model: info.name,
        t,
        contacts: active.closed_names(info),
        why: Box::new(why),
    };
    // Least-norm particular solution y = G (G^T G)^-1 (-Q) and the null space of G^T. `pins`
    // found G of full column rank, so G^T G is regular unless rounding made it exactly
    // singular.
    let gtg = g.transpose() * &g;
    let Some(w) = gtg.lu().solve(&(-&q)) else {
        return Err(undecided(Indeterminacy::RestSingular));
    };
    let particular = &g * w;
    let null = null_space(&g.transpose());
    let inequalities = admissible(info, sys, &kkt, &acting);
    let scale = particular.amax().max(f64::MIN_POSITIVE);
    let found = match feasible(
        &particular,
        &null,
        &inequalities,
        DECIDE_TOLERANCE * scale,
        MAX_VERTICES,
    ) {
        Search::Found(y) => y,
        Search::Infeasible => return Ok(None),
        Search::TooLarge => {
            return Err(undecided(Indeterminacy::RestTooLarge {
                limit: MAX_VERTICES,
            }));
        }
    };
    let mut forces = vec![0.0; info.contacts.len()];
    for (r, &i) in kkt.iter().enumerate() {
        forces[i] = found[r];
    }
    let mut fr = vec![0.0; info.frictions.len()];
    for (r, &j) in acting.iter().enumerate() {
        fr[j] = found[kkt.len() + r];
    }
    Ok(Some((forces, fr)))
}

/// An orthonormal basis (columns) of the null space of `gt` (`n x k`, `k >= n`): the right
/// singular vectors whose singular values are below [`RANK_TOLERANCE`] of the largest (the
/// matrix padded with zero rows to `k x k`, so that the decomposition gives all `k`).
fn null_space(gt: &DMatrix<f64>) -> DMatrix<f64> {
    let k = gt.ncols();
    let padded = DMatrix::from_fn(k, k, |r, c| if r < gt.nrows() { gt[(r, c)] } else { 0.0 });
    let svd = padded.svd(false, true);
    let Some(v_t) = svd.v_t else {
        return DMatrix::zeros(k, 0);
    };
    let top = svd.singular_values.iter().fold(0.0f64, |m, v| m.max(*v));
    let cols: Vec<DVector<f64>> = (0..k)
        .filter(|&i| svd.singular_values[i] <= RANK_TOLERANCE * top)
        .map(|i| v_t.row(i).transpose())
        .collect();
    if cols.is_empty() {
        DMatrix::zeros(k, 0)
    } else {
        DMatrix::from_columns(&cols)
    }
}

/// The laws the support forces `y` must obey, as rows `a . y >= 0`: a closed unilateral
/// contact pushes; a stuck friction stays within `mu N` either way.
fn admissible(info: &ModelInfo, sys: &Bound, kkt: &[usize], acting: &[usize]) -> Vec<Vec<f64>> {
    let k = kkt.len() + acting.len();
    let mu = sys.friction_coefficients();
    let mut rows = Vec::new();
    for (r, &i) in kkt.iter().enumerate() {
        if !info.contacts[i].bilateral {
            let mut a = vec![0.0; k];
            a[r] = 1.0;
            rows.push(a);
        }
    }
    for (r, &j) in acting.iter().enumerate() {
        let Some(normal) = kkt
            .iter()
            .position(|&i| i == info.frictions[j].contact_index)
        else {
            continue;
        };
        for sign in [1.0, -1.0] {
            let mut a = vec![0.0; k];
            a[normal] = mu[j];
            a[kkt.len() + r] = sign;
            rows.push(a);
        }
    }
    rows
}

/// What the search of [`feasible`] found.
#[derive(Debug, Clone, PartialEq)]
enum Search {
    /// A point that obeys every row.
    Found(Vec<f64>),
    /// No vertex obeys every row: the polyhedron is empty.
    Infeasible,
    /// More vertices than the limit: nothing decided.
    TooLarge,
}

/// A point `y = p + N z` with every `a . y >= -tol`, searched among the vertices of that
/// polyhedron in `z` (it has one wherever it is not empty: its rows bound every force, so it
/// holds no line), examining at most `limit` of them.
fn feasible(
    p: &DVector<f64>,
    null: &DMatrix<f64>,
    rows: &[Vec<f64>],
    tol: f64,
    limit: usize,
) -> Search {
    let d = null.ncols();
    let at = |z: &DVector<f64>| -> DVector<f64> { p + null * z };
    let ok = |y: &DVector<f64>| {
        rows.iter()
            .all(|a| a.iter().zip(y.iter()).map(|(a, y)| a * y).sum::<f64>() >= -tol)
    };
    if d == 0 {
        let y = at(&DVector::zeros(0));
        return if ok(&y) {
            Search::Found(y.iter().copied().collect())
        } else {
            Search::Infeasible
        };
    }
    // Each row in z: (a^T N) z >= -a^T p.
    let reduced: Vec<(DVector<f64>, f64)> = rows
        .iter()
        .map(|a| {
            let a = DVector::from_column_slice(a);
            (null.transpose() * &a, -a.dot(p))
        })
        .collect();
    let mut examined = 0usize;
    let mut pick = Vec::with_capacity(d);
    let found = vertices(&reduced, d, 0, &mut pick, &mut |chosen: &[usize]| {
        examined += 1;
        if examined > limit {
            return Some(Search::TooLarge);
        }
        let m = DMatrix::from_fn(d, d, |r, c| reduced[chosen[r]].0[c]);
        let b = DVector::from_fn(d, |r, _| reduced[chosen[r]].1);
        // Rows that meet in no single point are no vertex: the next subset.
        let z = m.lu().solve(&b)?;
        let y = at(&z);
        ok(&y).then(|| Search::Found(y.iter().copied().collect()))
    });
    found.unwrap_or(Search::Infeasible)
}

/// Calls `visit` on every `d`-subset of the rows (in order) until it returns `Some`.
fn vertices<T>(
    rows: &[(DVector<f64>, f64)],
    d: usize,
    from: usize,
    pick: &mut Vec<usize>,
    visit: &mut impl FnMut(&[usize]) -> Option<T>,
) -> Option<T> {
    if pick.len() == d {
        return visit(pick);
    }
    for r in from..rows.len() {
        pick.push(r);
        let found = vertices(rows, d, r + 1, pick, visit);
        pick.pop();
        if found.is_some() {
            return found;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::{Search, feasible};
    use nalgebra::{DMatrix, DVector};

    /// `y = (-3, 3) + z (1, 1)` with `y_0 >= -1` and `y_1 <= 1`: `z >= 2` and `z <= -2`, an
    /// empty family. Its two candidate vertices are both examined before it is called
    /// infeasible; a search cut short says so instead.
    #[test]
    fn a_search_past_its_limit_is_no_verdict() {
        let p = DVector::from_vec(vec![-3.0, 3.0]);
        let null = DMatrix::from_column_slice(2, 1, &[1.0, 1.0]);
        let rows = vec![vec![1.0, 0.0], vec![0.0, -1.0]];
        // One row alone: z = 3 gives y = (0, 6), which obeys it.
        assert_eq!(
            feasible(&p, &null, &rows[..1], 1.0, 10),
            Search::Found(vec![0.0, 6.0])
        );
        assert_eq!(feasible(&p, &null, &rows, 1.0, 10), Search::Infeasible);
        assert_eq!(feasible(&p, &null, &rows, 1.0, 1), Search::TooLarge);
    }
}
