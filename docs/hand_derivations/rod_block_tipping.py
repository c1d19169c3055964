# Rod pushing a block of width w and height h on a frictionless floor: sympy checks of
# docs/hand_derivations.md, section C (the push, the block's floor pushes, the cube-never-tips
# bound, the tipping examples and the tipping-phase equations). Run: python3 rod_block_tipping.py
#
# sin(theta), cos(theta) are the symbols S, C (d/dtheta: S' = C, C' = -S); identities are proved
# by reducing numerators modulo S^2 + C^2 - 1.
import sympy as sp
import mpmath as mpm  # ships with sympy (a required dependency)

m1, m2, l, g, w, h = sp.symbols("m1 m2 ell g w h", positive=True)
n, r, M = sp.symbols("n r M", positive=True)  # n = m2/m1, r = h/ell, M = 1 + n
S, C = sp.symbols("S C", real=True)
thd, thdd, x1dd, P, N = sp.symbols("thetadot thetaddot x1dd P N", real=True)
I1 = m1 * l**2 / 12


def dth(f):
    return sp.diff(f, S) * C - sp.diff(f, C) * S


def zero(e, *gens):
    num = sp.expand(sp.numer(sp.together(e)))
    return sp.reduced(num, [S**2 + C**2 - 1], S, C, *gens)[1] == 0


# --- Flat phase: rod (foot x1 on the floor, tip on the block's near face x2 = x1 + ell C) -------
xGdd = x1dd - l / 2 * (S * thdd + C * thd**2)
yGdd = l / 2 * (C * thdd - S * thd**2)
x2dd = x1dd - l * (S * thdd + C * thd**2)
ne = [
    m1 * xGdd + P,                                  # rod, x: the block pushes it with -P
    m1 * yGdd - (N - m1 * g),                       # rod, y
    I1 * thdd - l / 2 * (S * P - C * N),            # rod, about its centre
    m2 * x2dd - P,                                  # block, x (it slides, flat)
]
A, b = sp.linear_eq_to_matrix(ne, [x1dd, thdd, P, N])
sol = dict(zip([x1dd, thdd, P, N], A.LUsolve(b)))

# Path from rest: horizontal momentum m1 xG' + m2 x2' = 0 and energy T + V = V(theta0).
x1d = sp.symbols("x1d")
xGd = x1d - l / 2 * S * thd
x2d = x1d - l * S * thd
x1d_sol = sp.solve(m1 * xGd + m2 * x2d, x1d)[0]
print("momentum: x1' = (1 + 2n)/(2(1 + n)) ell sin theta':",
      sp.simplify(x1d_sol - (m1 + 2 * m2) / (2 * (m1 + m2)) * l * S * thd) == 0)
T = (m1 * ((xGd)**2 + (l / 2 * C * thd)**2) + I1 * thd**2 + m2 * x2d**2) / 2
usym = sp.symbols("u", positive=True)  # theta'^2
energy = sp.expand(T.subs(x1d, x1d_sol)).subs(thd**2, usym) + m1 * g * l / 2 * S - m1 * g * l / 2 * r
u = sp.solve(energy, usym)[0]
u_paper = 4 * g / l * (r - S) / (sp.Rational(4, 3) - S**2 / (1 + m2 / m1))
print("energy: theta'^2 = 4 (g/ell)(r - s)/(4/3 - s^2/(1+n)) (paper eq. 9):", zero(u - u_paper))
print("Newton-Euler theta'' = (1/2) d(theta'^2)/dtheta on the path:",
      zero(sol[thdd].subs(thd, sp.sqrt(u)) - dth(u) / 2))
P_path = sol[P].subs(thd, sp.sqrt(u)).subs(m2, n * m1)
P_eq16 = m2 * (-3 * g * C * (8 * r * (1 + n) - 12 * (1 + n) * S + 3 * S**3) / (4 * (1 + n) - 3 * S**2)**2)
print("push = paper eq. (16) with a = h:", zero(P_path - P_eq16.subs(m2, n * m1)))

# --- The block while flat: floor pushes N_near at (xb - w/2, 0), N_far at (xb + w/2, 0). ------
Nn, Nf, yt = sp.symbols("N_near N_far y_tip", real=True)
# About the centre (xb, h/2), no rotation: -(y_tip - h/2) P - (w/2) N_near + (w/2) N_far = 0.
sol_c = sp.solve([Nn + Nf - m2 * g, -(yt - h / 2) * P - w / 2 * Nn + w / 2 * Nf], [Nn, Nf])
# About the far edge E (accelerating at P/m2): sum M_E = (G - E) x m2 a_G,
# G - E = (-w/2, h/2), a_G = (P/m2, 0): (G - E) x m2 a_G = -(h/2) P.
sol_e = sp.solve([Nn + Nf - m2 * g, sp.Eq(-yt * P - w * Nn + w * m2 * g / 2, -(h / 2) * P)], [Nn, Nf])
Nn_hand = m2 * g / 2 - P * (yt - h / 2) / w
print("N_near = m2 g/2 - P (y_tip - h/2)/w (about the centre):", sp.simplify(sol_c[Nn] - Nn_hand) == 0)
print("N_near the same about the far edge:", sp.simplify(sol_e[Nn] - Nn_hand) == 0)
print("N_far = m2 g/2 + P (y_tip - h/2)/w:", sp.simplify(sol_c[Nf] - (m2 * g / 2 + P * (yt - h / 2) / w)) == 0)

# --- The tipping ratio rho = P (y_tip - h/2) / (m2 g w/2), y_tip = ell S, r = h/ell. -----------
rho_cube = sp.simplify((P_eq16 / (m2 * g)) * (2 * S - r) / r).subs(n, M - 1)
K = M * (12 * S - 8 * r) - 3 * S**3              # P > 0 <=> K > 0 (contact)
print("rho_cube = 3 C K (2S - r)/(r (4M - 3S^2)^2):",
      sp.simplify(rho_cube - 3 * C * K * (2 * S - r) / (r * (4 * M - 3 * S**2)**2)) == 0)
# In contact: S <= r and K > 0 with K(S = 2r/3) = -8 r^3/9 < 0, so S > 2r/3 > r/2: 0 < 2S - r <= r.
print("K at S = 2r/3:", sp.factor(K.subs(S, 2 * r / 3)))
# Step 1: K <= S (4M - 3 S^2) because the difference is 8 M (r - S) >= 0.
print("S (4M - 3S^2) - K =", sp.factor(sp.expand(S * (4 * M - 3 * S**2) - K)))
# Step 2: so rho <= 3 C S/(4M - 3S^2) <= 3 C S/(4 - 3 S^2) = 3 C S/(1 + 3 C^2)   (M >= 1).
bnd = 3 * C * S / (1 + 3 * C**2)
print("4 - 3S^2 = 1 + 3C^2:", zero(4 - 3 * S**2 - (1 + 3 * C**2)))
# Step 3: with t = C^2, f(t) = (3CS/(1+3C^2))^2 = 9 t (1 - t)/(1 + 3t)^2, f'(t) ∝ (1 - 5t).
t = sp.symbols("t", positive=True)
f = 9 * t * (1 - t) / (1 + 3 * t)**2
print("f'(t) =", sp.factor(sp.diff(f, t)), "; f(1/5) =", f.subs(t, sp.Rational(1, 5)))
print("9/16 - (3CS/(1+3C^2))^2 =", sp.factor(sp.Rational(9, 16) - f),
      ">= 0, so 3CS/(1+3C^2) <= 3/4 and rho <= 3/4, strictly below for n > 0")
# The bound is the supremum: at release (S = r), n -> 0 (M = 1), C^2 = 1/5 every step is tight.
rho_rel = sp.simplify(rho_cube.subs(S, r))
print("rho at release =", sp.factor(rho_rel))
r_star = 2 / sp.sqrt(5)
print("rho(M=1, release, r = 2/sqrt5) =", sp.nsimplify(rho_rel.subs({M: 1, r: r_star, C: 1 / sp.sqrt(5)})))

# --- Examples (ell = 1, m1 = 1, g = 9.81) ------------------------------------------------------
mpm.mp.dps = 30
def ratio(nv, rv, wv, sv):
    cv = mpm.sqrt(1 - sv**2)
    Mv = 1 + nv
    Kv = Mv * (12 * sv - 8 * rv) - 3 * sv**3
    return 3 * cv * Kv * (2 * sv - rv) / (rv * (4 * Mv - 3 * sv**2)**2) * (rv / wv)
print("tall light block w = 0.05, h = 0.5, m2 = 0.1: ratio at release =",
      ratio(mpm.mpf("0.1"), mpm.mpf("0.5"), mpm.mpf("0.05"), mpm.mpf("0.5")), "(> 1: tips at once)")
nv, rv, wv = mpm.mpf(1), mpm.mpf("0.99"), mpm.mpf("0.099")
print("block w = 0.099, h = 0.99, m2 = 1: ratio at release =", ratio(nv, rv, wv, rv))
# First crossing below the release: step down in sin(theta) from r, then bisect.
hi = rv
lo = hi - mpm.mpf("0.0005")
while ratio(nv, rv, wv, lo) < 1:
    hi, lo = lo, lo - mpm.mpf("0.0005")
s_on = mpm.findroot(lambda x: ratio(nv, rv, wv, x) - 1, (lo, hi), solver="bisect")
th0v, thon = mpm.asin(rv), mpm.asin(s_on)
uu = lambda x: 4 * mpm.mpf("9.81") * (rv - mpm.sin(x)) / (mpm.mpf(4) / 3 - mpm.sin(x)**2 / (1 + nv))
t_on = mpm.re(mpm.quad(lambda v: 2 * v / mpm.sqrt(uu(th0v - v**2)), [0, mpm.sqrt(th0v - thon) / 2, mpm.sqrt(th0v - thon)]))
print("  tipping onset: sin(theta) =", s_on, " theta =", thon, " t =", t_on)

# --- Tipping phase: the tip T on the near face, u = (cos phi, sin phi), gap = -(T - B).u - w/2.
tt = sp.symbols("t")
dx, dy, ph = [sp.Function(k)(tt) for k in ("dx", "dy", "phi")]
uvec = sp.Matrix([sp.cos(ph), sp.sin(ph)])
uperp = sp.Matrix([-sp.sin(ph), sp.cos(ph)])
dvec = sp.Matrix([dx, dy])
lhs = sp.diff(dvec.dot(uvec), tt, 2)
rhs = (sp.diff(dvec, tt, 2).dot(uvec) + 2 * sp.diff(dvec, tt).dot(uperp) * sp.diff(ph, tt)
       + dvec.dot(uperp * sp.diff(ph, tt, 2) - uvec * sp.diff(ph, tt)**2))
print("(d.u)'' = d''.u + 2 phi' d'.u_perp + d.(u_perp phi'' - u phi'^2):", sp.simplify(lhs - rhs) == 0)
# The far corner's height yb + (w/2) sin phi - (h/2) cos phi and its second derivative.
yb = sp.Function("yb")(tt)
yfar = yb + w / 2 * sp.sin(ph) - h / 2 * sp.cos(ph)
rhs2 = (sp.diff(yb, tt, 2) + w / 2 * (sp.cos(ph) * sp.diff(ph, tt, 2) - sp.sin(ph) * sp.diff(ph, tt)**2)
        + h / 2 * (sp.sin(ph) * sp.diff(ph, tt, 2) + sp.cos(ph) * sp.diff(ph, tt)**2))
print("far corner height'' as used:", sp.simplify(sp.diff(yfar, tt, 2) - rhs2) == 0)
# Torques about the block's centre: near/far corners Rot(phi)(-+w/2, -h/2), forces vertical.
cp, sp_ = sp.cos(ph), sp.sin(ph)
near = sp.Matrix([-w / 2 * cp + h / 2 * sp_, -w / 2 * sp_ - h / 2 * cp])
far = sp.Matrix([w / 2 * cp + h / 2 * sp_, w / 2 * sp_ - h / 2 * cp])
print("near corner = Rot(phi)(-w/2, -h/2):",
      sp.simplify(near - sp.Matrix([[cp, -sp_], [sp_, cp]]) * sp.Matrix([-w / 2, -h / 2])) == sp.zeros(2, 1))
print("far corner = Rot(phi)(w/2, -h/2):",
      sp.simplify(far - sp.Matrix([[cp, -sp_], [sp_, cp]]) * sp.Matrix([w / 2, -h / 2])) == sp.zeros(2, 1))
# Lagrange with multipliers for the block alone: forces P u at T, N_near, N_far vertical at the
# corners; generalized forces in (xb, yb, phi) equal the Newton-Euler ones (force, torque about B).
xb_, yb_, phs = sp.symbols("xb yb phis", real=True)
Tx, Ty, Pm = sp.symbols("Tx Ty Pm", real=True)
dvec_s = sp.Matrix([Tx - xb_, Ty - yb_])
us = sp.Matrix([sp.cos(phs), sp.sin(phs)])
gface = -dvec_s.dot(us) - w / 2          # the rod's tip T held fixed: the block's Jacobian
nearh = yb_ + (-w / 2 * sp.sin(phs) - h / 2 * sp.cos(phs))
farh = yb_ + (w / 2 * sp.sin(phs) - h / 2 * sp.cos(phs))
Qb = [sp.diff(gface, v) * Pm + sp.diff(nearh, v) * Nn + sp.diff(farh, v) * Nf for v in (xb_, yb_, phs)]
torque_ne = (dvec_s[0] * Pm * sp.sin(phs) - dvec_s[1] * Pm * sp.cos(phs)
             + Nn * (-w / 2 * sp.cos(phs) + h / 2 * sp.sin(phs)) + Nf * (w / 2 * sp.cos(phs) + h / 2 * sp.sin(phs)))
print("J^T lambda = (P cos phi, P sin phi + N_near + N_far, torque about B):",
      [sp.simplify(Qb[0] - Pm * sp.cos(phs)), sp.simplify(Qb[1] - (Pm * sp.sin(phs) + Nn + Nf)),
       sp.simplify(Qb[2] - torque_ne)] == [0, 0, 0])
