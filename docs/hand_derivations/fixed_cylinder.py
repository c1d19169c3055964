# Rod on a frictionless floor leaning on a fixed frictionless cylinder (axis (0, R)): sympy checks
# of docs/hand_derivations.md, section B. Run: python3 fixed_cylinder.py
#
# sin(theta), cos(theta) are the symbols S, C; d/dtheta acts as S' = C, C' = -S, and an identity
# is proved by reducing its numerator modulo S^2 + C^2 - 1.
import sympy as sp
import mpmath as mpm  # ships with sympy (a required dependency)

m, l, g, R = sp.symbols("m ell g R", positive=True)
S, C, S0 = sp.symbols("S C S0", real=True)
thd, thdd = sp.symbols("thetadot thetaddot", real=True)
P, N = sp.symbols("P N", real=True)
x1, y1, x1d, y1d, x1dd, y1dd = sp.symbols("x1 y1 x1d y1d x1dd y1dd", real=True)
I = m * l**2 / 12


def dth(f):
    """d/dtheta of a function of S = sin(theta), C = cos(theta)."""
    return sp.diff(f, S) * C - sp.diff(f, C) * S


def zero(e):
    """e == 0 identically on S^2 + C^2 = 1."""
    num = sp.expand(sp.numer(sp.together(e)))
    return sp.reduced(num, [S**2 + C**2 - 1], S, C, x1, y1)[1] == 0


# Geometry. e = (C, S) along the rod, n = (-S, C) its upper normal; the cylinder lies below the
# rod, so the gap is -(Cyl - F).n - R with Cyl = (0, R), F = (x1, y1).
gap = -((0 - x1) * (-S) + (R - y1) * C) - R
dist = (0 - x1) * C + (R - y1) * S            # tangent point's distance from the foot
cot_half = (1 + C) / S                        # cot(theta/2)
th = sp.symbols("theta")
print("cot(theta/2) = (1 + cos)/sin:",
      sp.simplify(sp.expand_trig(((1 + sp.cos(2 * th)) / sp.sin(2 * th) - 1 / sp.tan(th)))) == 0)
x1_floor = sp.solve(gap.subs(y1, 0), x1)[0]
print("x1 on the floor =", x1_floor, "= -R cot(theta/2):", zero(x1_floor + R * cot_half))
print("tangent distance on the floor = R cot(theta/2):",
      zero(dist.subs({y1: 0, x1: x1_floor}) - R * cot_half))

# Both contacts: one coordinate theta. Centre G = F + (ell/2) e.
xG = x1_floor + l / 2 * C
yG = l / 2 * S
kap, lam = dth(xG), dth(yG)
print("kappa = dxG/dtheta = R/(1 - cos) - (ell/2) sin:", zero(kap - (R / (1 - C) - l / 2 * S)))
xGdd = dth(kap) * thd**2 + kap * thdd
yGdd = dth(lam) * thd**2 + lam * thdd
d = R * cot_half
ne = [
    m * xGdd + P * S,                               # m xG'' = -P sin
    m * yGdd - (P * C + N - m * g),                 # m yG'' = P cos + N - m g
    I * thdd - (P * (d - l / 2) - l / 2 * C * N),   # about G: P at d - ell/2, N at the foot
]
A, b = sp.linear_eq_to_matrix(ne, [thdd, P, N])
sol = dict(zip([thdd, P, N], A.LUsolve(b)))

# Check 1: Lagrange in theta (the contact forces do no work): the same theta''.
Q = kap**2 + lam**2 + l**2 / 12
Meff = m * Q
# d/dt(Meff thd) - (1/2) dMeff/dtheta thd^2 + dV/dtheta = 0, V = m g yG.
thdd_lag = (-(dth(Meff) / 2) * thd**2 - m * g * lam) / Meff
print("Lagrange theta'' = Newton-Euler theta'':", zero(thdd_lag - sol[thdd]))
# Check 2: energy integral theta'^2 = g ell (S0 - S)/Q is consistent with theta''.
u = g * l * (S0 - S) / Q
print("energy: d(theta'^2)/dtheta = 2 theta'':", zero(dth(u) - 2 * sol[thdd].subs(thd, sp.sqrt(u))))

# Release (theta' = 0): closed forms and the sign of P.
P0 = sol[P].subs(thd, 0)
N0 = sol[N].subs(thd, 0)
P0_hand = m * g * (l / 2) * C * kap / (S * Q)
N0_hand = m * g * (kap**2 + l**2 / 12 - (l / 2) * C**2 * kap / S) / Q
print("P0 = m g (ell/2) cos kappa/(sin Q):", zero(P0 - P0_hand))
print("N0 = m g (kappa^2 + ell^2/12 - (ell/2) cos^2 kappa/sin)/Q:", zero(N0 - N0_hand))
print("kappa (1 - cos) = R - (ell/2) sin (1 - cos):", zero(kap * (1 - C) - (R - l / 2 * S * (1 - C))))
print("=> P0 > 0 <=> kappa > 0 <=> R > (ell/2) sin(th0) (1 - cos(th0))  (Q, sin, cos, 1 - cos > 0)")

# After the foot lifts: coordinates (x1, y1, theta), the constraint gap = 0.
J = [sp.diff(gap, x1), sp.diff(gap, y1), dth(gap)]
print("gap Jacobian = (-sin, cos, d):", zero(J[0] + S) and zero(J[1] - C) and zero(J[2] - dist))


def ddt(f):
    """Time derivative of f(x1, y1, S, C, x1d, y1d, thd)."""
    return (sp.diff(f, x1) * x1d + sp.diff(f, y1) * y1d + dth(f) * thd
            + sp.diff(f, x1d) * x1dd + sp.diff(f, y1d) * y1dd + sp.diff(f, thd) * thdd)


gdot = J[0] * x1d + J[1] * y1d + J[2] * thd
gdd = ddt(gdot)
bias = -2 * C * thd * x1d + S * thd**2 * x1 + C * R * thd**2 - 2 * S * thd * y1d - C * thd**2 * y1
print("gap'' = -sin x1'' + cos y1'' + d theta'' + bias:",
      zero(gdd - (-S * x1dd + C * y1dd + dist * thdd + bias)))
# Lagrange with a multiplier: d/dt dT/dq' - dT/dq + dV/dq = J^T P, T of the free rod.
xGd = x1d - l / 2 * S * thd
yGd = y1d + l / 2 * C * thd
T = m * (xGd**2 + yGd**2) / 2 + I * thd**2 / 2
V = m * g * (y1 + l / 2 * S)
EL = [
    ddt(sp.diff(T, x1d)) - sp.diff(T, x1) + sp.diff(V, x1) - J[0] * P,
    ddt(sp.diff(T, y1d)) - sp.diff(T, y1) + sp.diff(V, y1) - J[1] * P,
    ddt(sp.diff(T, thd)) - dth(T) + dth(V) - J[2] * P,
]
# The references' Newton-Euler residuals (force P n at the tangent point, distance d from the foot).
r1 = m * (x1dd - l / 2 * (S * thdd + C * thd**2)) + P * S
r2 = m * (y1dd + l / 2 * (C * thdd - S * thd**2)) - P * C + m * g
r3 = I * thdd - P * (dist - l / 2)
print("Lagrange rows: x1 = r1, y1 = r2, theta = r3 + (ell/2)(-sin r1 + cos r2):",
      zero(EL[0] - r1) and zero(EL[1] - r2) and zero(EL[2] - (r3 + l / 2 * (-S * r1 + C * r2))))

# Numbers: R = 0.2, ell = 1, th0 = 1.0, g = 9.81, m = 1.
mpm.mp.dps = 30
vals = {R: mpm.mpf("0.2"), l: 1, g: mpm.mpf("9.81"), m: 1}
s0 = mpm.sin(1)
fu = sp.lambdify((S, C), u.subs(vals).subs(S0, s0), "mpmath")
fN = sp.lambdify((S, C, thd), sol[N].subs(vals), "mpmath")
fP = sp.lambdify((S, C, thd), sol[P].subs(vals), "mpmath")
fP0 = sp.lambdify((S, C), P0.subs(vals), "mpmath")
fN0 = sp.lambdify((S, C), N0.subs(vals), "mpmath")
print("release: P0 =", fP0(s0, mpm.cos(1)), " N0 =", fN0(s0, mpm.cos(1)))


def along(f, x):
    return f(mpm.sin(x), mpm.cos(x), -mpm.sqrt(fu(mpm.sin(x), mpm.cos(x))))


thl = mpm.re(mpm.findroot(lambda x: mpm.re(along(fN, x)), mpm.mpf("0.86")))
tl = mpm.quad(lambda v: 2 * v / mpm.sqrt(fu(mpm.sin(1 - v**2), mpm.cos(1 - v**2))), [0, mpm.sqrt(1 - thl)])
print("foot lifts at theta =", thl, " t =", mpm.re(tl), " P there =", mpm.re(along(fP, thl)))
print("edge angle 2 atan(R/ell) =", 2 * mpm.atan(mpm.mpf("0.2")))
