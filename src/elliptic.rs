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
