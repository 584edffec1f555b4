#!/usr/bin/env python3
"""Reference values of the exact pendulum near the separatrix (release from rest at theta0 just
below 180 degrees), for tests/separatrix.rs.

Writes tests/data/separatrix_reference.csv next to this script:

    python3 tests/data/separatrix_reference.py     # needs mpmath (pip install mpmath)

The input is the release angle in degrees, as typed on the command line. physlab converts it
with Rust's f64::to_radians (one IEEE multiplication by the double nearest pi/180); Python's
float multiplication is the same IEEE operation, so `theta_rad` below is bit for bit the double
the Rust code receives. Every reference is computed at that exact binary value with 100
significant digits (mp.dps = 100; ellipk in m alone loses the digits of m1, hence the margin), with g = 9.81 and L = 3.521 and omega_n = the double
sqrt(9.81/3.521) (correctly rounded in both languages), so the only error left in a comparison
is the Rust code's own. The period for the decimal angle itself is written alongside, to show
what the input's rounding to radians alone costs.

Each value is computed by two routes that share no algorithm, and the script refuses to write
the file unless they agree to 1e-30 relative:

  K(m):   mpmath.ellipk(m) (AGM in m)  vs  the convergent series in k' = cos(theta/2) about m = 1
          (A&S 17.3.26 form): K = sum_n ((1/2)_n / n!)^2 k'^(2n) (ln(4/k') - 2 sum_{j<=n} 1/((2j-1)2j))
  theta:  2 asin(k sn(K - omega_n t | m)) with mpmath.ellipfun  vs  the time the energy integral
          gives back for that angle, omega_n t = K - F(asin(sin(theta/2)/k) | m) (mpmath.ellipf),
          (the inverse evaluated at 100 digits, asin near 1 being ill-conditioned), checked on the first quarter period (t <= T/4), the mismatch in time times omega
          (the mismatch it means in theta) below 1e-30.
"""

import math
import os

from mpmath import mp, mpf, ellipk, ellipf, ellipfun, sin, cos, asin, log, pi, rf, factorial

mp.dps = 100

G, L = 9.81, 3.521
OMEGA_N = math.sqrt(G / L)  # the double physlab uses

DEGREES = [
    "90", "170", "179", "179.9", "179.99", "179.999", "179.9999", "179.99999", "179.999999",
    "179.9999999", "179.99999999", "179.999999999", "179.9999999999", "179.99999999999",
    "-179.9999999",
]
# Sample times as fractions of the period and fixed times [s].
FRACTIONS = [mpf(0), mpf(1) / 8, mpf(1) / 4, mpf(3) / 8, mpf(1) / 2, mpf(7) / 10, mpf(1), mpf(5) / 2]
FIXED_T = [0.5, 3.0, 10.0, 20.0]


def k_series(k1):
    total, term_coef, harmonic = mpf(0), mpf(1), mpf(0)
    lg = log(4 / k1)
    n = 0
    while True:
        if n > 0:
            term_coef *= (mpf(2 * n - 1) / (2 * n)) ** 2
            harmonic += mpf(1) / ((2 * n - 1) * (2 * n))
        term = term_coef * k1 ** (2 * n) * (lg - 2 * harmonic)
        total += term
        if abs(term) < mpf(10) ** (-mp.dps - 5) * abs(total) or n > 2000:
            return total
        n += 1


def main():
    rows = []
    wn = mpf(OMEGA_N)
    for deg_text in DEGREES:
        deg = float(deg_text)
        theta_rad = deg * (math.pi / 180.0)  # == f64::to_radians
        assert abs(theta_rad) < math.pi
        th = mpf(theta_rad)
        k, k1 = sin(th / 2), cos(th / 2)
        m = k * k
        big_k = ellipk(m)
        if abs(k1) < mpf("0.1"):
            alt = k_series(abs(k1))
            assert abs(alt / big_k - 1) < mpf(10) ** -30, (deg_text, big_k, alt)
        period = 4 * big_k / wn
        th_dec = mpf(deg_text) * pi / 180
        period_decimal = 4 * ellipk(sin(th_dec / 2) ** 2) / wn
        times = [float(f * period) for f in FRACTIONS] + FIXED_T
        for t in times:
            tt = mpf(t)
            sn, cn = ellipfun("sn", big_k - wn * tt, m), ellipfun("cn", big_k - wn * tt, m)
            theta = 2 * asin(k * sn)
            omega = -2 * k * wn * cn
            if 0 < tt <= period / 4 and abs(theta) > mpf(10) ** -20:
                # asin near 1 is ill-conditioned: go back with twice the digits.
                with mp.workdps(2 * mp.dps):
                    phi = asin(sin(theta / 2) / k)
                    t_back = (big_k - ellipf(phi, m)) / wn
                # The mismatch in time, moved to the angle: theta' = omega.
                assert abs(omega * (t_back - tt)) < mpf(10) ** -30, (deg_text, t, t_back)
            rows.append((deg_text, repr(theta_rad), mp.nstr(k1, 40), mp.nstr(period, 40),
                         mp.nstr(period_decimal, 40), repr(t), mp.nstr(theta, 40), mp.nstr(omega, 40)))
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "separatrix_reference.csv")
    with open(out, "w") as f:
        f.write("# Exact pendulum near the separatrix: release from rest, g = 9.81, L = 3.521, omega_n = the double sqrt(g/L).\n")
        f.write("# Written by separatrix_reference.py (mpmath, 100 digits, two independent routes agreeing to 1e-30).\n")
        f.write("# theta0_rad is the exact double f64::to_radians(theta0_deg); period_s and theta, omega at t are for it;\n")
        f.write("# period_decimal_s is the period for the decimal angle theta0_deg itself.\n")
        f.write("theta0_deg,theta0_rad,k_complement,period_s,period_decimal_s,t,theta,omega\n")
        for r in rows:
            f.write(",".join(r) + "\n")
    print(f"wrote {len(rows)} rows to {out}")


if __name__ == "__main__":
    main()
