//! Complete elliptic integral K(m) and the Jacobi elliptic functions sn, cn, dn, by the
//! arithmetic-geometric mean (Abramowitz & Stegun 17.6 and 16.4, descending Landen).
//!
//! The parameter is m = k² (A&S convention), 0 ≤ m < 1. Both converge quadratically, so a
//! handful of AGM steps reach machine precision even for m within 1e-12 of 1.

use std::f64::consts::FRAC_PI_2;

/// Enough for m up to 1 - 1e-300; the AGM at least doubles its correct digits each step.
const MAX_AGM_STEPS: usize = 40;

/// Complete elliptic integral of the first kind, K(m) = ∫₀^{π/2} dφ / sqrt(1 - m sin²φ).
///
/// Panics if m is outside [0, 1): K diverges at m = 1.
pub fn complete_k(m: f64) -> f64 {
    assert!((0.0..1.0).contains(&m), "K(m) needs 0 <= m < 1, got {m}");
    let (mut a, mut b) = (1.0_f64, (1.0 - m).sqrt());
    for _ in 0..MAX_AGM_STEPS {
        if (a - b).abs() <= f64::EPSILON * a {
            break;
        }
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    FRAC_PI_2 / a
}

/// The Jacobi elliptic functions at one argument.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jacobi {
    pub sn: f64,
    pub cn: f64,
    pub dn: f64,
}

/// sn(u|m), cn(u|m), dn(u|m) for 0 ≤ m < 1 by the descending Landen / AGM scheme (A&S 16.4.3).
///
/// The argument is reduced modulo the real period 4K(m) first so that long runs (many periods)
/// keep full precision in the back-substitution.
pub fn jacobi(u: f64, m: f64) -> Jacobi {
    assert!(
        (0.0..1.0).contains(&m),
        "Jacobi functions need 0 <= m < 1, got {m}"
    );
    if m == 0.0 {
        return Jacobi {
            sn: u.sin(),
            cn: u.cos(),
            dn: 1.0,
        };
    }
    let period = 4.0 * complete_k(m);
    let u = u - period * (u / period).round();

    let mut a = [0.0_f64; MAX_AGM_STEPS + 1];
    let mut c = [0.0_f64; MAX_AGM_STEPS + 1];
    a[0] = 1.0;
    c[0] = m.sqrt();
    let mut b = (1.0 - m).sqrt();
    let mut n = 0;
    while c[n].abs() > f64::EPSILON * a[n] && n < MAX_AGM_STEPS {
        a[n + 1] = 0.5 * (a[n] + b);
        c[n + 1] = 0.5 * (a[n] - b);
        b = (a[n] * b).sqrt();
        n += 1;
    }
    // φ_n = 2ⁿ a_n u, then φ_{i-1} = (φ_i + asin(c_i/a_i sin φ_i)) / 2 down to φ_0.
    let mut phi = 2.0_f64.powi(n as i32) * a[n] * u;
    let mut phi_above = phi;
    for i in (1..=n).rev() {
        phi_above = phi;
        phi = 0.5 * (phi + (c[i] / a[i] * phi.sin()).asin());
    }
    let (sn, cn) = phi.sin_cos();
    // dn = cos φ0 / cos(φ1 - φ0) loses digits where cn → 0. There dn² = 1 - m sn² is written
    // (1 - m) + m cn²: the same number, but 1 - m sn² cancels when m sn² → 1 (m near 1), which
    // cost up to 4e-12 absolute (5e-7 relative) at m = 1 - 1e-12; this form is as accurate as cn.
    let dn = if n == 0 {
        1.0
    } else if cn.abs() > 0.5 {
        cn / (phi_above - phi).cos()
    } else {
        ((1.0 - m) + m * cn * cn).sqrt()
    };
    Jacobi { sn, cn, dn }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EPS: f64 = f64::EPSILON;

    /// (m, u, K(m), sn, cn, dn) from `tests/data/elliptic_reference.csv`: 40-digit mpmath at the
    /// exact doubles m and u, confirmed by a second, independent algorithm (see
    /// `tests/data/elliptic_reference.py`, which wrote the file).
    fn reference() -> Vec<[f64; 6]> {
        let rows: Vec<[f64; 6]> = include_str!("../tests/data/elliptic_reference.csv")
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("m,"))
            .map(|l| {
                let f: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
                [f[0], f[1], f[2], f[3], f[4], f[5]]
            })
            .collect();
        assert_eq!(rows.len(), 120, "8 parameters × 15 arguments");
        rows
    }

    /// The error allowed in sn, cn, dn at argument u, in units of eps (1 + |u|): the argument is
    /// reduced modulo 4K, which alone costs about eps |u| in u. Measured (max over the table):
    /// sn 0.56; cn and dn 0.85 for m ≤ 0.999999, but 16.2 at m = 1 - 1e-12, where the Landen
    /// back-substitution leaves ~1e-14 in φ and cn = cos φ (φ near π/2) shows it in full.
    fn allowed(m: f64, u: f64) -> (f64, f64) {
        let cn_dn = if m > 1.0 - 1e-9 { 32.0 } else { 2.0 };
        (2.0 * EPS * (1.0 + u.abs()), cn_dn * EPS * (1.0 + u.abs()))
    }

    /// K(m) to 2 eps relative (measured ≤ 1 eps) for m from 0 to 1 - 1e-12.
    #[test]
    fn k_matches_the_reference_table() {
        for [m, _, k, ..] in reference() {
            let got = complete_k(m);
            let rel = (got / k - 1.0).abs();
            assert!(
                rel <= 2.0 * EPS,
                "K({m}) = {got:e}, reference {k:e}: {rel:.1e} relative"
            );
        }
        // Literature: K(1/2) = Γ(1/4)² / (4 √π) = 1.854074677301372 (A&S table 17.1).
        assert_eq!(complete_k(0.0), FRAC_PI_2);
        assert!((complete_k(0.5) / 1.854_074_677_301_372 - 1.0).abs() <= 2.0 * EPS);
    }

    /// sn, cn, dn against the table, 8 parameters (0 to 1 - 1e-12) × 15 arguments (negative,
    /// small, up to 40, and multiples of K), to the bounds of `allowed`.
    #[test]
    fn jacobi_matches_the_reference_table() {
        let mut worst = [0.0f64; 3];
        for [m, u, _, sn, cn, dn] in reference() {
            let j = jacobi(u, m);
            let (tol_sn, tol_cn_dn) = allowed(m, u);
            for (i, (name, got, want, tol)) in [
                ("sn", j.sn, sn, tol_sn),
                ("cn", j.cn, cn, tol_cn_dn),
                ("dn", j.dn, dn, tol_cn_dn),
            ]
            .into_iter()
            .enumerate()
            {
                let err = (got - want).abs();
                worst[i] = worst[i].max(err / (EPS * (1.0 + u.abs())));
                assert!(
                    err <= tol,
                    "{name}({u}|{m}) = {got:e}, reference {want:e}: error {err:.1e} > {tol:.1e}"
                );
            }
        }
        println!(
            "worst error / eps(1 + |u|): sn {:.2}, cn {:.2}, dn {:.2}",
            worst[0], worst[1], worst[2]
        );
    }

    /// At the quarter period (the code's own K, a double within eps K of the true one): sn = 1
    /// and dn = √(1-m) to 2 eps (measured: exact), and cn, whose true value there is below
    /// √(1-m)·eps·K + eps ≈ 1e-15, to 4 eps = 8.9e-16 (measured 6.1e-17, cos of the double
    /// nearest π/2, for every m). Then sn(K/2) against A&S 16.5.2 to 2 eps (measured: exact).
    #[test]
    fn special_points() {
        for &m in &[0.0, 1e-6, 0.25, 0.5, 0.9, 0.999, 1.0 - 1e-9, 1.0 - 1e-12] {
            let k = complete_k(m);
            let j = jacobi(k, m);
            assert!((j.sn - 1.0).abs() <= 2.0 * EPS, "m={m} sn(K)={}", j.sn);
            assert!(j.cn.abs() <= 4.0 * EPS, "m={m} cn(K)={:e}", j.cn);
            assert!(
                (j.dn / (1.0 - m).sqrt() - 1.0).abs() <= 2.0 * EPS,
                "m={m} dn(K)={}",
                j.dn
            );
        }
        // sn(K/2 | m) = 1 / sqrt(1 + sqrt(1 - m)) (A&S 16.5.2).
        for &m in &[0.1, 0.5, 0.9, 0.999_999, 1.0 - 1e-12] {
            let s = jacobi(0.5 * complete_k(m), m).sn;
            let expected = 1.0 / (1.0 + (1.0 - m).sqrt()).sqrt();
            assert!(
                (s - expected).abs() <= 2.0 * EPS,
                "m={m}: {s} vs {expected}"
            );
        }
    }
}
