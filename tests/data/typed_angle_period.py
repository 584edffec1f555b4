#!/usr/bin/env python3
"""The exact period of a release from rest at the very angle typed in degrees, for
tests/separatrix.rs: near 180 degrees the complement 180 - theta0 carries all the digits, so the
reference is computed from the typed double itself (mpf(float(text)), wrapped into (-180, 180]
exactly as physlab wraps it), not from its rounding to radians.

Writes tests/data/typed_angle_period.csv next to this script:

    python3 tests/data/typed_angle_period.py     # needs mpmath (pip install mpmath)

g = 9.81, L = 3.521 and omega_n = the double sqrt(g/L), as physlab's closed form uses; 60 digits
(K(m) at 120, as m near 1 loses the digits of 1 - m).
K is computed by two routes (mpmath.ellipk in m, and the series in k' = cos(theta/2) about m = 1,
A&S 17.3.26), which must agree to 1e-40 relative.
"""

import math
import os

from mpmath import mp, mpf, ellipk, sin, cos, pi

from separatrix_reference import k_series  # the series in k' about m = 1, beside this script

mp.dps = 60

G, L = 9.81, 3.521
OMEGA_N = math.sqrt(G / L)

TYPED = [
    "90", "135", "170", "179", "179.9", "179.99", "179.999", "179.9999", "179.99999",
    "179.999999", "179.9999999", "179.99999999", "179.999999999", "179.9999999999",
    "179.99999999999", "179.999999999999", "-179.9999999", "-179.99999999", "180.0000001",
    "180.00000001", "539.9999999", "-900.0000001", "359999.9999", "-179.99999999999",
]


def main():
    rows = []
    for text in TYPED:
        typed = mpf(float(text))  # the double the command line holds, exactly
        wrapped = typed % 360  # exact, like f64::rem_euclid on this double
        if wrapped > 180:
            wrapped -= 360
        th = wrapped * pi / 180
        k1 = cos(th / 2)
        with mp.workdps(2 * mp.dps):  # m near 1 loses the digits of 1 - m
            big_k = +ellipk(sin(wrapped * pi / 360) ** 2)
        if abs(k1) < mpf("0.1"):
            alt = k_series(abs(k1))
            assert abs(alt / big_k - 1) < mpf(10) ** -40, (text, big_k, alt)
        period = 4 * big_k / mpf(OMEGA_N)
        rows.append((text, mp.nstr(wrapped, 30), mp.nstr(period, 30)))
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "typed_angle_period.csv")
    with open(out, "w") as f:
        f.write("# Exact period of a release from rest at the typed angle (the double of theta0_typed, wrapped into (-180, 180]).\n")
        f.write("# g = 9.81, L = 3.521, omega_n = the double sqrt(g/L). Written by typed_angle_period.py (mpmath, 60 digits).\n")
        f.write("theta0_typed,theta0_wrapped_deg,period_s\n")
        for r in rows:
            f.write(",".join(r) + "\n")
    print(f"wrote {len(rows)} rows to {out}")


if __name__ == "__main__":
    main()
