"""A 40-digit reference for the separation of `rod_cube_spring` with the rod lying almost flat.

README's "Adding a model" quotes it: at a/ell = 1e-8 and k = 5000 the spring's stretch is 3e-17
of the cube's place, so the integrated general model (which carries the place in f64) loses the
spring's force to rounding, and its separation is 3.9e-8 off this reference, which keeps it.
Independent of rodcube: the Lagrangian of the rod (foot sliding on the floor at x1, angle theta)
pushing the cube (x2 = x1 + ell cos theta) against the spring, written out by hand below and
integrated by mpmath's Taylor-series ODE solver; the separation is where the push on the cube,
m2 x2'' + k (x2 - x2(0)), reaches zero.

    pip install mpmath
    python3 docs/references/flat_spring_separation.py 1e-8 5000
    # t_sep 2.128502939755632e-5 theta_sep 6.666666404483539e-9
    rodcube run SCENE   # rod_cube_spring, a: 1.0e-8, k: 5000.0: 6.666666666666631e-9, 2.128502856047013e-5
"""
import sys

from mpmath import asin, cos, findroot, lu_solve, matrix, mp, mpf, nstr, odefun, sin

mp.dps = 40
m1, m2, L, g = mpf(1), mpf(3), mpf(1), mpf("9.81")
a, k = mpf(sys.argv[1]), mpf(sys.argv[2])
thi = asin(a / L)
ci = cos(thi)
A = m1 / 2 + m2


def accelerations(x1, th, w):
    """(x1'', theta'', stretch) from the Euler-Lagrange equations of
    T = (m1 + m2) x1'^2 / 2 - A L s x1' th' + (m1 L^2 / 3 + m2 L^2 s^2) th'^2 / 2,
    V = m1 g L s / 2 + k d^2 / 2 with d = x1 + L (cos theta - cos theta_i)."""
    s, c = sin(th), cos(th)
    d = x1 + L * (c - ci)
    inertia = m1 * L**2 / 3 + m2 * L**2 * s**2
    mass = matrix([[m1 + m2, -A * L * s], [-A * L * s, inertia]])
    force = matrix([A * L * c * w**2 - k * d, -m2 * L**2 * s * c * w**2 - m1 * g * L / 2 * c + k * d * L * s])
    q = lu_solve(mass, force)
    return q[0], q[1], d


def rhs(_t, y):
    _x1, _th, v1, w = y
    a1, a2, _ = accelerations(y[0], y[1], w)
    return [v1, w, a1, a2]


solution = odefun(rhs, 0, [mpf(0), thi, mpf(0), mpf(0)])


def push(t):
    """The rod's push on the cube: m2 x2'' + k d."""
    x1, th, _v1, w = solution(t)
    a1, a2, d = accelerations(x1, th, w)
    return m2 * (a1 - L * (cos(th) * w**2 + sin(th) * a2)) + k * d


# Newton from a start near the root: the optional third argument, else 2.1285e-5 s (a/ell = 1e-8).
t = findroot(push, mpf(sys.argv[3]) if len(sys.argv) > 3 else mpf("2.1285e-5"))
print("t_sep", nstr(t, 16), "theta_sep", nstr(solution(t)[1], 16))
