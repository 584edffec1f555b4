#!/usr/bin/env python3
"""The pendulum's exact motion over whole runs, for tests/pendulum_numerics.rs: the closed form's
stated accuracy (releases from rest) and the fine-step reference's error estimate (starts with
omega0 != 0, where physlab has no closed form), both measured at every sample of a run rather
than at a few times.

Writes tests/data/whole_run_reference.csv next to this script:

    python3 tests/data/whole_run_reference.py     # needs mpmath (pip install mpmath)

Every start is the exact pair of doubles physlab steps from: theta0 = f64::to_radians(degrees)
(one IEEE multiplication by the double nearest pi/180, the same in Python), omega0 as typed, and
the equation physlab's integrators step, theta'' = -c sin theta with c = the double g/L (so
omega_n = sqrt(c) exactly here; physlab's closed form rounds it, which is part of its error).
The motion is computed by two routes (the closed form at 32 digits plus those 1 - k^2 takes
near the separatrix, the Taylor solve at 32) that
share no algorithm, and the script refuses to write the file unless they agree to 1e-25 rad:

  closed form:  energy k^2 = sin^2(theta0/2) + omega0^2 / (4 c). Libration (k < 1):
                sin(theta/2) = k sn(u0 + omega_n t | k^2), with sn(u0) = sin(theta0/2)/k and
                cn(u0) of the sign of omega0 (u0 = F(asin(sin(theta0/2)/k) | k^2), or 2K minus it).
                Revolution (k > 1): theta/2 = sign(omega0) am(k omega_n t + F(sign(omega0) theta0/2
                | 1/k^2) | 1/k^2), am continued through its branches.
  Taylor ODE:   mpmath.odefun (a high-order Taylor series integrator) on theta'' = -c sin theta,
                at t = 2.5, 5 and 10 s of each run (enough to check the phase and the branch of
                every formula, over the top several times; the closed form is the one route
                that reaches the end of a long run in reasonable time).
"""

import math
import os

from mpmath import mp, mpf, ellipk, ellipf, ellipfun, sin, cos, asin, atan2, pi, sqrt, nint, odefun

mp.dps = 32

# (g, L, theta0 degrees, omega0 rad/s, duration s, sample every s)
CASES = [
    # Releases from rest: the closed form physlab uses, over whole runs.
    (9.81, 3.521, 10.0, 0.0, 30.0, 0.05),
    (9.81, 3.521, 60.0, 0.0, 30.0, 0.05),
    (9.81, 3.521, 120.0, 0.0, 30.0, 0.05),
    (9.81, 3.521, 172.93, 0.0, 30.0, 0.05),
    (9.81, 3.521, 179.9, 0.0, 60.0, 0.1),
    (9.81, 3.521, 179.9999, 0.0, 60.0, 0.1),
    (9.81, 3.521, 179.999999, 0.0, 60.0, 0.1),
    (9.81, 1.0, -150.0, 0.0, 100.0, 0.1),
    # Starts with omega0 != 0: the fine-step reference's domain.
    (9.81, 1.0, 10.0, 7.0, 20.0, 0.1),
    (9.81, 1.0, -45.0, -9.0, 20.0, 0.1),
    (9.81, 1.0, 120.0, -3.1, 20.0, 0.1),
    (9.81, 1.0, 0.0, 6.2641, 20.0, 0.1),
    (9.81, 1.0, 0.0, -6.2645, 20.0, 0.1),
    (9.81, 3.521, 30.0, 1.0, 20.0, 0.1),
    (9.81, 3.521, 170.0, 0.3, 20.0, 0.1),
    (9.81, 3.521, 0.0, 3.3383, 20.0, 0.1),
]


CHECK_AT = [2.5, 5.0, 10.0]


def am(u, m, big_k):
    """Jacobi amplitude, continuous in u (big_k = K(m))."""
    sn, cn = ellipfun("sn", u, m), ellipfun("cn", u, m)
    a = atan2(sn, cn)
    linear = pi * u / (2 * big_k)
    return a + 2 * pi * nint((linear - a) / (2 * pi))


def closed_form(g, length, theta0, omega0):
    c = mpf(g / length)  # the double physlab's Pendulum holds
    wn = sqrt(c)
    th0, w0 = mpf(theta0), mpf(omega0)
    k2 = sin(th0 / 2) ** 2 + w0 ** 2 / (4 * c)
    if k2 < 1:
        k = sqrt(k2)
        m = k2
        big_k = ellipk(m)
        f = ellipf(asin(sin(th0 / 2) / k), m)
        u0 = f if w0 >= 0 else 2 * big_k - f
        return lambda t: 2 * atan2(k * ellipfun("sn", u0 + wn * t, m), ellipfun("dn", u0 + wn * t, m))
    k = sqrt(k2)
    m = 1 / k2
    s = 1 if w0 > 0 else -1
    v0 = ellipf(s * th0 / 2, m)
    big_k = ellipk(m)
    return lambda t: s * 2 * am(k * wn * t + v0, m, big_k)


def main():
    rows = []
    for g, length, deg, omega0, duration, every in CASES:
        theta0 = deg * (math.pi / 180.0)  # == f64::to_radians
        # Near the separatrix m = k^2 loses the digits of 1 - m: the closed form gets them back.
        with mp.workdps(40):
            gap = abs(1 - sin(mpf(theta0) / 2) ** 2 - mpf(omega0) ** 2 / (4 * mpf(g / length)))
        mp.dps = 32 + max(0, int(-mp.log10(gap)))
        exact = closed_form(g, length, theta0, omega0)
        c = mpf(g / length)
        ode = odefun(lambda t, y: [y[1], -c * sin(y[0])], 0, [mpf(theta0), mpf(omega0)])
        n = int(round(duration / every))
        for j in range(1, n + 1):
            t = mpf(j * every)  # the double j·every, as the test computes it
            theta = exact(t)
            if any(abs(j * every - c) < 1e-9 for c in CHECK_AT):
                with mp.workdps(32):
                    other = ode(t)[0]
                assert abs(other - theta) < mpf(10) ** -25, (deg, omega0, j, theta, other)
            rows.append((repr(g), repr(length), repr(deg), repr(theta0), repr(omega0), repr(every), str(j), mp.nstr(theta, 30)))
        print(f"{deg}°, {omega0} rad/s: {n} samples")
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "whole_run_reference.csv")
    with open(out, "w") as f:
        f.write("# The pendulum's exact motion over whole runs (mpmath: closed form at 32+ digits, checked against a Taylor ODE solve to 1e-25).\n")
        f.write("# Written by whole_run_reference.py. theta0_rad is the double f64::to_radians(theta0_deg); theta at t = the double j * every.\n")
        f.write("gravity,length,theta0_deg,theta0_rad,omega0,every,j,theta\n")
        for r in rows:
            f.write(",".join(r) + "\n")
    print(f"wrote {len(rows)} rows to {out}")


if __name__ == "__main__":
    main()
