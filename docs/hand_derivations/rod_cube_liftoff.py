# The floor's push on the rod's foot in the paper's rod-and-cube contact phase: sympy checks of
# docs/hand_derivations.md, section D. Run: python3 rod_cube_liftoff.py
import sympy as sp
import mpmath as mpm  # ships with sympy (a required dependency)

m1, m2, l, g = sp.symbols("m1 m2 ell g", positive=True)
n, r, M = sp.symbols("n r M", positive=True)  # n = m2/m1, r = a/ell, M = 1 + n
S, C = sp.symbols("S C", real=True)
thd, thdd, x1dd, P, N = sp.symbols("thetadot thetaddot x1dd P N", real=True)
I1 = m1 * l**2 / 12


def dth(f):
    return sp.diff(f, S) * C - sp.diff(f, C) * S


def zero(e):
    num = sp.expand(sp.numer(sp.together(e)))
    return sp.reduced(num, [S**2 + C**2 - 1], S, C)[1] == 0


# Newton-Euler for rod and cube while in contact (the foot on the floor, y1 = 0).
xGdd = x1dd - l / 2 * (S * thdd + C * thd**2)
yGdd = l / 2 * (C * thdd - S * thd**2)
x2dd = x1dd - l * (S * thdd + C * thd**2)
ne = [m1 * xGdd + P, m1 * yGdd - (N - m1 * g), I1 * thdd - l / 2 * (S * P - C * N), m2 * x2dd - P]
A, b = sp.linear_eq_to_matrix(ne, [x1dd, thdd, P, N])
sol = dict(zip([x1dd, thdd, P, N], A.LUsolve(b)))
# On the path from rest (momentum and energy give theta'^2, see rod_block_tipping.py).
u = 4 * g / l * (r - S) / (sp.Rational(4, 3) - S**2 / (1 + n))
subs = {thd: sp.sqrt(u)}
N_path = sp.simplify((sol[N].subs(subs) / (m1 * g)).subs(m2, n * m1).subs(n, M - 1))
P_path = sp.simplify((sol[P].subs(subs) / (m2 * g)).subs(m2, n * m1).subs(n, M - 1))
K = M * (12 * S - 8 * r) - 3 * S**3
print("P/(m2 g) = 3 C K/(4M - 3S^2)^2:", zero(P_path - 3 * C * K / (4 * M - 3 * S**2)**2))
N_hand = sp.Rational(1, 4) + 3 * S * (4 * M - 3) * K / (4 * (4 * M - 3 * S**2)**2)
print("N/(m1 g) = 1/4 + 3 S (4M - 3) K / (4 (4M - 3 S^2)^2):", zero(N_path - N_hand))
# Equivalently N = m1 g/4 + (1 + 4n) tan(theta) P/(4n): K > 0 in contact, so N > m1 g/4 there,
# and N = m1 g/4 exactly at separation (K = 0), whatever n and r.
print("N = m1 g/4 + (1 + 4n) tan P/(4n):",
      zero((N_path - sp.Rational(1, 4)) - (4 * M - 3) * S / (4 * (M - 1) * C) * (M - 1) * P_path))
# At release (S = r): N/(m1 g) = 1 - C^2/(4/3 - r^2/M).
print("release: N/(m1 g) = 1 - C^2/(4/3 - r^2/M):",
      sp.simplify((N_hand.subs(S, r) - (1 - C**2 / (sp.Rational(4, 3) - r**2 / M))).subs(C, sp.sqrt(1 - r**2))) == 0)
# Independent of the factorization: at separation P = 0, so the rod is free for an instant. With
# x2'' = 0 and the rod's x-balance xG'' = 0, both x1'' = 0 and S theta'' = -C theta'^2; then
# I theta'' = -(ell/2) C N and m1 yG'' = N - m1 g give N = m1 g/4.
Nsym = sp.symbols("Nsym")
t2 = -6 * C * Nsym / (m1 * l)                  # theta'' from the moment balance
ygdd = l / 2 * (C * t2 + S**2 * t2 / C)        # yG'' with theta'^2 = -S theta''/C
print("at separation N = m1 g/4:", zero(sp.solve(m1 * ygdd - (Nsym - m1 * g), Nsym)[0] - m1 * g / 4))

# Scan (n, r): the minimum of N/(m1 g) over the contact phase.
mpm.mp.dps = 20
def s_sep(nv, rv):
    Mv = 1 + nv
    return mpm.findroot(lambda x: Mv * (12 * x - 8 * rv) - 3 * x**3, (2 * rv / 3, rv), solver="bisect")
fN = sp.lambdify((M, r, S), N_hand, "mpmath")
worst, best = None, None
for nv in ["1e-9", "0.01", "0.1", "1", "3", "10", "1e3", "1e9"]:
    for rv in ["1e-6", "0.01", "0.25", "0.5", "0.9", "0.999999"]:
        nv_, rv_ = mpm.mpf(nv), mpm.mpf(rv)
        ss = s_sep(nv_, rv_)
        vals = [fN(1 + nv_, rv_, ss + (rv_ - ss) * k / 200) for k in range(201)]
        lo, hi = min(vals), max(vals)
        k_lo, k_hi = vals.index(lo), vals.index(hi)
        if worst is None or lo < worst[0]:
            worst = (lo, nv, rv, "at separation" if k_lo == 0 else k_lo)
        if best is None or hi > best[0]:
            best = (hi, nv, rv, "at release" if k_hi == 200 else k_hi)
print("smallest N/(m1 g) over the scan:", worst, "(1/4 at separation)")
print("largest N/(m1 g) over the scan:", best)
print("paper's case n = 3, r = 1/4 at release:",
      sp.N((1 - C**2 / (sp.Rational(4, 3) - r**2 / M)).subs({M: 4, r: sp.Rational(1, 4), C: sp.sqrt(15) / 4})))
