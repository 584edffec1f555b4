//! Complete elliptic integral K(m) and the Jacobi elliptic functions sn, cn, dn, by the
//! arithmetic-geometric mean (Abramowitz & Stegun 17.6 and 16.4; Bulirsch's descending Gauss
//! transformation for sn, cn, dn).
//!
//! The parameter is m = k² (A&S convention), 0 ≤ m < 1. Both converge quadratically, so a
//! handful of AGM steps reach machine precision for any m. Near m = 1 the complement m1 = 1 - m
//! carries all the information (K ≈ ln(4/√m1)), so [`complete_k_m1`] and [`jacobi_m1`] take it
//! separately: a caller that knows m1 without cancellation (the pendulum: m1 = cos²(θ0/2)) gets
//! full relative precision up to the separatrix; [`complete_k`] and [`jacobi`] form 1 - m.

use std::f64::consts::FRAC_PI_2;

/// Enough for m up to 1 - 1e-300; the AGM at least doubles its correct digits each step.
const MAX_AGM_STEPS: usize = 40;

/// Complete elliptic integral of the first kind, K(m) = ∫₀^{π/2} dφ / sqrt(1 - m sin²φ).
///
/// Panics if m is outside [0, 1): K diverges at m = 1. Near m = 1 the complementary parameter
/// 1 - m is formed here by cancellation; callers that know it better use [`complete_k_m1`].
pub fn complete_k(m: f64) -> f64 {
    assert!((0.0..1.0).contains(&m), "K(m) needs 0 <= m < 1, got {m}");
    complete_k_m1(m, 1.0 - m)
}

/// K(m) given the parameter m and its complement m1 = 1 - m separately, so that K keeps full
/// relative precision up to the logarithmic singularity: K = π / (2 AGM(1, √m1)) depends on m1
/// only. m is not read (it is part of the signature so that the pair is passed consistently).
/// Returns +∞ for m1 = 0 (the separatrix); panics if m1 is not in [0, 1] or NaN.
pub fn complete_k_m1(_m: f64, m1: f64) -> f64 {
    assert!(
        (0.0..=1.0).contains(&m1),
        "K needs 0 <= 1 - m <= 1, got 1 - m = {m1}"
    );
    if m1 == 0.0 {
        return f64::INFINITY;
    }
    let (mut a, mut b) = (1.0_f64, m1.sqrt());
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
/// keep full precision in the back-substitution. Near m = 1 use [`jacobi_m1`], which takes the
/// complement 1 - m without cancellation.
pub fn jacobi(u: f64, m: f64) -> Jacobi {
    assert!(
        (0.0..1.0).contains(&m),
        "Jacobi functions need 0 <= m < 1, got {m}"
    );
    jacobi_m1(u, m, 1.0 - m)
}

/// sn(u|m), cn(u|m), dn(u|m) given m and m1 = 1 - m separately (A&S 16.4.3 with the AGM started
/// at (1, √m1, √m)), for 0 ≤ m ≤ 1. At m1 = 0 (m = 1) the limits sn = tanh u, cn = dn = sech u.
/// Panics unless both are in [0, 1].
pub fn jacobi_m1(u: f64, m: f64, m1: f64) -> Jacobi {
    assert!(
        (0.0..=1.0).contains(&m) && (0.0..=1.0).contains(&m1),
        "Jacobi functions need 0 <= m, 1 - m <= 1, got m = {m}, 1 - m = {m1}"
    );
    if m == 0.0 {
        return Jacobi {
            sn: u.sin(),
            cn: u.cos(),
            dn: 1.0,
        };
    }
    if m1 == 0.0 {
        let sech = 1.0 / u.cosh();
        return Jacobi {
            sn: u.tanh(),
            cn: sech,
            dn: sech,
        };
    }
    // Reduce to u in [-K, K] (sn and cn change sign over half a period 2K, dn does not), then
    // fold |u| > K/2 onto v = K - |u| ∈ [0, K/2] with sn(K - v) = cd(v), cn(K - v) = k' sd(v),
    // dn(K - v) = k' nd(v) (A&S 16.8): the Landen back-substitution below loses digits when
    // sn → 1 (its asin arguments approach 1), and near m = 1 that costs ~1e-12 absolute in cn
    // and dn at u ≈ K, where both are O(k') and the pendulum near the top needs them relative.
    let quarter = complete_k_m1(m, m1);
    let half = 2.0 * quarter;
    let turns = (u / half).round();
    let mut u = u - half * turns;
    let sign = if turns.rem_euclid(2.0) == 1.0 {
        -1.0
    } else {
        1.0
    };
    if !u.is_finite() {
        // |u| beyond 2^53 K: no digit of the phase is left.
        u = 0.0;
    }
    if u.abs() > 0.5 * quarter {
        let v = quarter - u.abs();
        let j = landen(v, m, m1);
        let k1 = m1.sqrt();
        return Jacobi {
            sn: sign * u.signum() * j.cn / j.dn,
            cn: sign * k1 * j.sn / j.dn,
            dn: k1 / j.dn,
        };
    }
    let j = landen(u, m, m1);
    Jacobi {
        sn: sign * j.sn,
        cn: sign * j.cn,
        dn: j.dn,
    }
}

/// Bulirsch's form of the Gauss / descending Landen transformation (Bulirsch 1965, Numer. Math.
/// 7, 78-90; as `sncndn` in Numerical Recipes §6.11), driven by the complement m1 directly, for
/// 0 < m1 ≤ 1 and |u| ≤ K/2 (the caller folds the rest). It carries the ratio cn/sn through the
/// transformations multiplicatively instead of the amplitude through asin, so it has no
/// asin-near-1 loss where sn → 1, which near m = 1 happens already well inside |u| < K/2.
fn landen(u: f64, _m: f64, m1: f64) -> Jacobi {
    /// Stop when the AGM's two means agree to this; the last mean is then good to its square.
    const CA: f64 = 1e-9;
    let mut em = [0.0_f64; MAX_AGM_STEPS + 1];
    let mut en = [0.0_f64; MAX_AGM_STEPS + 1];
    let (mut a, mut emc, mut c) = (1.0_f64, m1, 1.0_f64);
    let mut l = 0;
    for i in 0..MAX_AGM_STEPS {
        l = i;
        em[i] = a;
        emc = emc.sqrt();
        en[i] = emc;
        c = 0.5 * (a + emc);
        if (a - emc).abs() <= CA * a {
            break;
        }
        emc *= a;
        a = c;
    }
    let u = u * c;
    let (mut sn, cn) = u.sin_cos();
    let mut dn = 1.0_f64;
    if sn == 0.0 {
        return Jacobi { sn, cn, dn };
    }
    let mut a = cn / sn;
    let mut c = c * a;
    for ii in (0..=l).rev() {
        let b = em[ii];
        a *= c;
        c *= dn;
        dn = (en[ii] + a) / (b + a);
        a = c / b;
    }
    let r = 1.0 / c.hypot(1.0);
    sn = if sn >= 0.0 { r } else { -r };
    Jacobi { sn, cn: c * sn, dn }
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

    /// The error allowed in sn, cn and dn at argument u, 2 eps (1 + |u|): the argument is
    /// reduced modulo 2K, which alone costs about eps |u| in u. Measured (max over the table):
    /// sn 0.61, cn 1.00, dn 0.50 for every m up to 1 - 1e-12 (Bulirsch's scheme with the fold
    /// at K/2).
    fn allowed(u: f64) -> f64 {
        2.0 * EPS * (1.0 + u.abs())
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
            let tol = allowed(u);
            for (i, (name, got, want)) in [("sn", j.sn, sn), ("cn", j.cn, cn), ("dn", j.dn, dn)]
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

    /// The separatrix limits: K(m1 = 0) = ∞, sn = tanh, cn = dn = sech at m = 1; and at m1 =
    /// 1e-300 (far beyond where 1 - m could be formed) K = ln(4/k') to eps and the functions are
    /// finite and obey sn² + cn² = 1, dn² = m1 + m cn².
    #[test]
    fn separatrix_limits() {
        assert_eq!(complete_k_m1(1.0, 0.0), f64::INFINITY);
        let j = jacobi_m1(0.7, 1.0, 0.0);
        assert_eq!(
            (j.sn, j.cn, j.dn),
            (0.7f64.tanh(), 1.0 / 0.7f64.cosh(), 1.0 / 0.7f64.cosh())
        );
        let m1 = 1e-300;
        let k = complete_k_m1(1.0, m1);
        assert!((k / (4.0 / m1.sqrt()).ln() - 1.0).abs() <= 4.0 * EPS, "{k}");
        for u in [0.1, 1.0, 30.0, 0.5 * k, k, 3.3 * k] {
            let j = jacobi_m1(u, 1.0, m1);
            assert!(
                j.sn.is_finite() && j.cn.is_finite() && j.dn.is_finite(),
                "u {u}"
            );
            assert!(
                (j.sn * j.sn + j.cn * j.cn - 1.0).abs() <= 4.0 * EPS,
                "u {u}: {j:?}"
            );
            let dn2 = m1 + j.cn * j.cn;
            assert!((j.dn * j.dn / dn2 - 1.0).abs() <= 1e-14, "u {u}: {j:?}");
        }
    }
}
