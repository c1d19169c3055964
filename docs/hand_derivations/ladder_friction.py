# Ladder with Coulomb friction at the floor (mu_f) and at the wall (mu_w): sympy checks of the
# hand derivation in docs/hand_derivations.md, section A. Run: python3 ladder_friction.py
import sympy as sp
import mpmath as mp  # ships with sympy (a required dependency)

m, l, g, muf, muw = sp.symbols("m ell g mu_f mu_w", positive=True)
th, thd, thdd, s0 = sp.symbols("theta thetadot thetaddot s0", real=True)
Nf, Nw = sp.symbols("N_f N_w", real=True)
s, c = sp.sin(th), sp.cos(th)
I = m * l**2 / 12

# Kinematics with both contacts closed: foot (-ell c, 0), top (0, ell s), centre (-ell c/2, ell s/2).
xc, yc = -l * c / 2, l * s / 2
def dd(expr):
    """Second time derivative of a function of theta(t)."""
    d1 = sp.diff(expr, th)
    return sp.diff(d1, th) * thd**2 + d1 * thdd
xcdd, ycdd = dd(xc), dd(yc)

# Newton-Euler while both ends slide (foot to -x, top down): friction on the foot +x, on the top +y.
Ff, Fw = muf * Nf, muw * Nw
eqs = [
    sp.Eq(m * xcdd, Ff - Nw),                                   # horizontal
    sp.Eq(m * ycdd, Nf + Fw - m * g),                           # vertical
    sp.Eq(I * thdd, (l / 2) * (-c * Nf + s * Ff + c * Fw + s * Nw)),  # about the centre
]
sol = sp.solve(eqs, [Nf, Nw, thdd], dict=True)[0]

# The hand result: A thdd = G - B thd^2 with D = 1 + mu_f mu_w, k1 = (1 - mu_f mu_w)/D,
# alpha = 2 mu_f/D, beta = 2 mu_w/D.
D = 1 + muf * muw
k1, al, be = (1 - muf * muw) / D, 2 * muf / D, 2 * muw / D
A = l * (sp.Rational(1, 6) + (k1 - (al - be) * s * c) / 2)
G = g * (al * s - k1 * c)
B = l / 2 * (al * s**2 + be * c**2)
print("theta'' = (G - B theta'^2)/A:", sp.simplify(sol[thdd] - (G - B * thd**2) / A) == 0)
Nf_hand = m * (g + ycdd + muw * xcdd) / D
Nw_hand = m * (muf * (g + ycdd) - xcdd) / D
print("N_f = m (g + yc'' + mu_w xc'')/D:", sp.simplify((sol[Nf] - Nf_hand).subs(thdd, sol[thdd])) == 0)
print("N_w = m (mu_f (g + yc'') - xc'')/D:", sp.simplify((sol[Nw] - Nw_hand).subs(thdd, sol[thdd])) == 0)
print("6 D A / ell = 4 - 2 mu_f mu_w - 3 (mu_f - mu_w) sin(2 theta):",
      sp.simplify(6 * D * A / l - (4 - 2 * muf * muw - 3 * (muf - muw) * sp.sin(2 * th))) == 0)

# Check 1 (Lagrange with generalized friction forces): T = m ell^2 thd^2 / 6, V = m g ell s / 2,
# Q = F_f d(x_foot)/dtheta + F_w d(y_top)/dtheta, the normal forces doing no virtual work.
T = sp.Rational(1, 2) * m * (sp.diff(xc, th)**2 + sp.diff(yc, th)**2) * thd**2 + I * thd**2 / 2
print("T = m ell^2 theta'^2/6:", sp.simplify(T - m * l**2 * thd**2 / 6) == 0)
V = m * g * yc
x_foot, y_top = -l * c, l * s
Q = muf * Nf_hand * sp.diff(x_foot, th) + muw * Nw_hand * sp.diff(y_top, th)
dT = sp.diff(T, thd)
lag = sp.diff(dT, thd) * thdd + sp.diff(dT, th) * thd - sp.diff(T, th) + sp.diff(V, th) - Q
thdd_lag = sp.solve(lag, thdd)[0]
print("Lagrange (with generalized friction force) = Newton-Euler:",
      sp.simplify(thdd_lag - sol[thdd]) == 0)

# Check 2 (energy balance): dE/dt = F_f x_foot' + F_w y_top' along the sliding solution.
E = T + V
dE = sp.diff(E, th) * thd + sp.diff(E, thd) * thdd
power = muf * Nf_hand * sp.diff(x_foot, th) * thd + muw * Nw_hand * sp.diff(y_top, th) * thd
print("dE/dt = friction power:", sp.simplify((dE - power).subs(thdd, sol[thdd])) == 0)

# Start from rest: the sliding mode needs theta'' < 0 at theta_dot = 0, i.e. G < 0 (A > 0):
# 2 mu_f sin < (1 - mu_f mu_w) cos  <=>  tan(theta0) < (1 - mu_f mu_w)/(2 mu_f).
print("G D / g =", sp.simplify(G * D / g), "(< 0 <=> sliding starts)")
# Statics at the limit (both frictions saturated): N_w = mu_f N_f, N_f = m g - mu_w N_w, moments
# about the foot: N_w ell s + F_w ell c = m g ell c / 2.
# No Painleve paradox while sliding: with tan(theta) < (1 - mu_f mu_w)/(2 mu_f) (which holds from
# theta0 down, theta'' < 0 keeping theta decreasing) and sin(2 theta) <= 2 tan(theta),
# 6 D A/ell = 4 - 2 mu_f mu_w - 3 (mu_f - mu_w) sin(2 theta)
#          >= 4 - 2 mu_f mu_w - 6 mu_f tan(theta) > 4 - 2 mu_f mu_w - 3 (1 - mu_f mu_w) = 1 + mu_f mu_w.
tq = sp.symbols("tq", positive=True)
print("sin(2 theta) <= 2 tan(theta): 2 tan - sin 2theta =",
      sp.factor(sp.simplify(2 * tq - 2 * tq / (1 + tq**2))), "(tq = tan theta >= 0)")
print("4 - 2 mu_f mu_w - 3 (1 - mu_f mu_w) =", sp.expand(4 - 2 * muf * muw - 3 * (1 - muf * muw)))
moment = (muf * m * g / D) * (s + muw * c) - m * g * c / 2
tan_lim = (1 - muf * muw) / (2 * muf)
print("statics at the limit holds at tan(theta) = (1 - mu_f mu_w)/(2 mu_f):",
      sp.simplify((moment / c).subs(th, sp.atan(tan_lim))) == 0)

# Frictionless: theta'' = -3 g c/(2 ell), theta'^2 = 3 g (s0 - s)/ell, N_w = (3/4) m g c (3 s - 2 s0),
# separation at sin(theta) = (2/3) s0.
fr = {muf: 0, muw: 0}
thdd0 = sol[thdd].subs(fr)
print("frictionless theta'':", sp.simplify(thdd0))
u = 3 * g * (s0 - s) / l
print("energy theta'^2 consistent (d(theta'^2)/dtheta = 2 theta''):",
      sp.simplify(sp.diff(u, th) - 2 * thdd0) == 0)
Nw0 = sp.simplify(Nw_hand.subs(fr).subs(thdd, thdd0).subs(thd**2, u))
print("frictionless N_w =", sp.factor(Nw0))
print("N_w = (3/4) m g c (3 s - 2 s0):", sp.simplify(Nw0 - sp.Rational(3, 4) * m * g * c * (3 * s - 2 * s0)) == 0)
Nf0 = sp.simplify(Nf_hand.subs(fr).subs(thdd, thdd0).subs(thd**2, u))
print("frictionless N_f =", sp.factor(Nf0))

# Numbers used by the Rust tests (ell = 1, g = 9.81, a = 0.8): the frictionless separation.
mp.mp.dps = 30
gg, ll, aa = mp.mpf("9.81"), mp.mpf(1), mp.mpf("0.8")
t0 = mp.asin(aa / ll)
tsep = mp.asin(2 * aa / (3 * ll))
tt = mp.quad(lambda v: 2 * v / mp.sqrt(3 * gg / ll * (aa / ll - mp.sin(t0 - v**2))), [0, mp.sqrt(t0 - tsep)])
print("frictionless a = 0.8: theta_sep =", tsep, " t_sep =", tt)

# Friction cases (ell = 1, g = 9.81, a = 0.8, m = 1): theta'^2 = u(theta) from the linear ODE
# du/dtheta = 2 (G - B u)/A (mpmath's Taylor integrator, in psi = theta0 - theta), the separation
# where N_w = 0, the time by quadrature with theta = theta0 - v^2. No time integration.
fA = sp.lambdify((th, muf, muw), A.subs({l: 1}), "mpmath")
fG = sp.lambdify((th, muf, muw), G.subs({g: sp.Rational(981, 100)}), "mpmath")
fB = sp.lambdify((th, muf, muw), B.subs({l: 1}), "mpmath")
fNw = sp.lambdify((th, thd, thdd, muf, muw), Nw_hand.subs({m: 1, l: 1, g: sp.Rational(981, 100)}), "mpmath")
mp.mp.dps = 20
for mf, mw in [(mp.mpf("0.3"), mp.mpf(0)), (mp.mpf("0.3"), mp.mpf("0.2"))]:
    u_psi = mp.odefun(lambda psi, uu: -2 * (fG(t0 - psi, mf, mw) - fB(t0 - psi, mf, mw) * uu) / fA(t0 - psi, mf, mw), 0, 0)
    def nw(x):
        uu = u_psi(t0 - x)
        tdd = (fG(x, mf, mw) - fB(x, mf, mw) * uu) / fA(x, mf, mw)
        return fNw(x, -mp.sqrt(uu), tdd, mf, mw)
    xs = mp.findroot(nw, (mp.mpf("0.3"), mp.mpf("0.6")), solver="anderson")
    ts = mp.quad(lambda v: 2 * v / mp.sqrt(u_psi(v**2)), [0, mp.sqrt(t0 - xs)])
    print(f"mu_f = {mf}, mu_w = {mw}: theta_sep =", xs, " t_sep =", ts,
          " static limit tan =", (1 - mf * mw) / (2 * mf), "vs tan(theta0) =", mp.tan(t0))
