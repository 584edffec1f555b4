#!/usr/bin/env python3
"""The stability limit of Yoshida's fourth-order composition on x'' = -x, to 30 digits.

One position-Verlet (drift-kick-drift) step of size t maps (x, v) by

    M(t) = [[1 - t^2/2, t - t^3/4],
            [-t,        1 - t^2/2]]      (det M = 1),

and Yoshida's step of size h is M(w1 h) M(w0 h) M(w1 h) with w1 = 1/(2 - 2^(1/3)),
w0 = 1 - 2 w1. The product is stable while |trace| < 2: the trace starts at 2 at h = 0, dips to
about 1.12 near h = 1.2 and crosses 2 once, at the limit printed here (the kick-drift-kick form
has the same trace). The value is quoted in src/study/mod.rs and tests/study.rs.

It also prints the leading coefficient c of the composition's relative period error on the
oscillator, h/phi(h) - 1 = c h^4 + O(h^6) with cos phi = trace/2 (quoted in
tests/pendulum_numerics.rs).

    python3 tests/data/yoshida4_stability.py     # needs mpmath
"""

from mpmath import mp, mpf, cbrt, findroot, matrix

mp.dps = 80  # the period coefficient needs digits beyond h^4 phi^2
w1 = 1 / (2 - cbrt(2))
w0 = 1 - 2 * w1


def m(t):
    return matrix([[1 - t**2 / 2, t - t**3 / 4], [-t, 1 - t**2 / 2]])


def trace(h):
    p = m(w1 * h) * m(w0 * h) * m(w1 * h)
    return p[0, 0] + p[1, 1]


# The only crossing of |trace| = 2 for 0 < h < 3 (the trace is below 2 on (0, limit) and rises
# monotonically past it).
assert all(abs(trace(mpf(k) / 100)) < 2 for k in range(1, 157))
assert all(trace(mpf(k) / 100) > 2 for k in range(158, 300))
limit = findroot(lambda h: trace(h) - 2, mpf("1.57"))
print("stability limit h* =", mp.nstr(limit, 30))

h = mpf("1e-6")  # c h^4 + O(h^6): the O(h^6) term is 1e-12 relative here
phi = mp.acos(trace(h) / 2)
print("period error coefficient c =", mp.nstr((h / phi - 1) / h**4, 15))
