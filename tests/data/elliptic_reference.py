#!/usr/bin/env python3
"""Reference values of K(m) and the Jacobi elliptic functions sn, cn, dn for src/elliptic.rs.

Writes tests/data/elliptic_reference.csv next to this script. Run from anywhere:

    python3 tests/data/elliptic_reference.py     # needs mpmath (pip install mpmath)

Every input (m, u) is an IEEE double, written with Python's shortest round-trip repr, and the
reference is computed at that exact binary value with 40 significant digits, so the only error
left in a comparison is the Rust code's own. Each value is computed twice, by two different
algorithms, and the script refuses to write the file unless they agree to 1e-30:

  K(m):       mpmath.ellipk (AGM)               vs  the quadrature of 1/sqrt(1 - m sin^2 t)
  sn, cn, dn: mpmath.ellipfun (theta functions) vs  the amplitude am(u|m) found by solving
                                                    F(am|m) = u (incomplete integral, Newton)

The second route shares nothing with the first (nor with the Rust code's descending Landen /
AGM scheme).
"""

import os

from mpmath import mp, mpf, ellipk, ellipf, ellipfun, quad, sqrt, sin, cos, floor, pi

mp.dps = 40

# Parameters m = k^2 (A&S convention), from the circular limit to within 1e-12 of 1.
MS = [0.0, 1e-6, 0.1, 0.5, 0.9, 0.99, 0.999999, 1.0 - 1e-12]

# Arguments: fixed values (negative, small, several periods for small m) and fractions of the
# quarter period K(m) (rounded to doubles, so they are just further doubles).
FIXED_U = [-7.3, -1.0, 0.1, 0.7, 1.3, 2.0, 3.1, 5.0, 12.5, 40.0]
K_FRACTIONS = [mpf(1) / 2, mpf(1), mpf(3) / 2, mpf(3), mpf(11) / 4]


def k_quadrature(m):
    return quad(lambda t: 1 / sqrt(1 - m * sin(t) ** 2), [0, pi / 4, pi / 2])


def by_amplitude(u, m):
    """(sn, cn, dn) from phi = am(u|m), the root of F(phi|m) = u, found by Newton on
    F(phi) - u with F'(phi) = 1/sqrt(1 - m sin^2 phi). F(phi + n pi) = F(phi) + 2 n K, so the
    root is sought in the half-period containing u."""
    if m == 0:
        return sin(u), cos(u), mpf(1)
    k = ellipk(m)
    n = floor(u / (2 * k) + mpf(1) / 2)
    r = u - 2 * n * k  # in [-K, K): am(r) in [-pi/2, pi/2)
    phi = r if m < mpf("0.9") else mpf(2) * mp.atan(mp.tanh(r / 2))  # gd(r) is am at m = 1
    phi = max(min(phi, pi / 2), -pi / 2)
    for _ in range(200):
        step = (ellipf(phi, m) - r) * sqrt(1 - m * sin(phi) ** 2)
        phi -= step
        if abs(step) < mpf(10) ** (-mp.dps + 2):
            break
    else:
        raise RuntimeError(f"Newton did not converge at u={u} m={m}")
    phi += n * pi
    return sin(phi), cos(phi), sqrt(1 - m * sin(phi) ** 2)


def main():
    rows = []
    for m_f in MS:
        m = mpf(m_f)  # exactly the double
        k = ellipk(m)
        k2 = k_quadrature(m)
        assert abs(k - k2) < mpf(10) ** -30 * k, (m_f, k, k2)
        us = list(FIXED_U) + [float(f * k) for f in K_FRACTIONS]
        for u_f in us:
            u = mpf(u_f)
            if m == 0:
                sn, cn, dn = sin(u), cos(u), mpf(1)
            else:
                sn = ellipfun("sn", u, m=m)
                cn = ellipfun("cn", u, m=m)
                dn = ellipfun("dn", u, m=m)
            sn2, cn2, dn2 = by_amplitude(u, m)
            for name, a, b in (("sn", sn, sn2), ("cn", cn, cn2), ("dn", dn, dn2)):
                assert abs(a - b) < mpf(10) ** -30, (name, m_f, u_f, a, b)
            rows.append((m_f, u_f, k, sn, cn, dn))

    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "elliptic_reference.csv")
    with open(path, "w") as f:
        f.write("# K(m), sn(u|m), cn(u|m), dn(u|m) at the exact doubles m, u; 40-digit mpmath,\n")
        f.write("# two independent algorithms agreeing to 1e-30. Made by elliptic_reference.py.\n")
        f.write("m,u,K,sn,cn,dn\n")
        for m_f, u_f, k, sn, cn, dn in rows:
            vals = ",".join(mp.nstr(x, 25, min_fixed=1, max_fixed=0) for x in (k, sn, cn, dn))
            f.write(f"{m_f!r},{u_f!r},{vals}\n")
    print(f"wrote {len(rows)} rows to {path}")


if __name__ == "__main__":
    main()
