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
    // dn = cos φ0 / cos(φ1 - φ0) loses digits where cn → 0; sqrt(1 - m sn²) does not (dn ≥ √(1-m) > 0).
    let dn = if n == 0 {
        1.0
    } else if cn.abs() > 0.5 {
        cn / (phi_above - phi).cos()
    } else {
        (1.0 - m * sn * sn).sqrt()
    };
    Jacobi { sn, cn, dn }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn k_matches_known_values() {
        // K(0) = π/2; K(1/2) = Γ(1/4)² / (4 √π) = 1.854074677301372 (A&S table 17.1).
        assert_eq!(complete_k(0.0), FRAC_PI_2);
        assert!((complete_k(0.5) - 1.854_074_677_301_372).abs() < 1e-15);
        // K(0.99) = 3.695637362989875 (A&S table 17.1 / mpmath).
        assert!((complete_k(0.99) - 3.695_637_362_989_875).abs() < 1e-13);
    }

    #[test]
    fn jacobi_identities_and_special_points() {
        for &m in &[0.0, 1e-6, 0.25, 0.5, 0.9, 0.999, 1.0 - 1e-9] {
            let k = complete_k(m);
            // sn(K) = 1, cn(K) = 0, dn(K) = √(1-m).
            let j = jacobi(k, m);
            assert!((j.sn - 1.0).abs() < 1e-14, "m={m} sn(K)={}", j.sn);
            assert!(j.cn.abs() < 1e-7, "m={m} cn(K)={}", j.cn);
            for i in 0..50 {
                let u = -7.0 + 0.31 * i as f64;
                let j = jacobi(u, m);
                assert!((j.sn * j.sn + j.cn * j.cn - 1.0).abs() < 1e-14);
                assert!((j.dn * j.dn + m * j.sn * j.sn - 1.0).abs() < 1e-14);
                // d sn/du = cn dn, checked by a central difference.
                let e = 1e-5;
                let d = (jacobi(u + e, m).sn - jacobi(u - e, m).sn) / (2.0 * e);
                assert!(
                    (d - j.cn * j.dn).abs() < 1e-8,
                    "m={m} u={u}: {d} vs {}",
                    j.cn * j.dn
                );
            }
        }
    }

    #[test]
    fn sn_at_half_period_point_known_value() {
        // sn(K/2 | m) = 1 / sqrt(1 + sqrt(1 - m)) (A&S 16.5.2).
        for &m in &[0.1, 0.5, 0.9, 0.999_999] {
            let s = jacobi(0.5 * complete_k(m), m).sn;
            let expected = 1.0 / (1.0 + (1.0 - m).sqrt()).sqrt();
            assert!((s - expected).abs() < 1e-14, "m={m}: {s} vs {expected}");
        }
    }
}
