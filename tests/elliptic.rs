//! Jacobi elliptic functions and K(m) (`physlab::elliptic`, the pendulum's closed form) against
//! a 40-digit reference table.

use physlab::elliptic::*;
use std::f64::consts::FRAC_PI_2;

const EPS: f64 = f64::EPSILON;

/// (m, u, K(m), sn, cn, dn) from `tests/data/elliptic_reference.csv`: 40-digit mpmath at the
/// exact doubles m and u, confirmed by a second, independent algorithm (see
/// `tests/data/elliptic_reference.py`, which wrote the file).
fn reference() -> Vec<[f64; 6]> {
    let rows: Vec<[f64; 6]> = include_str!("data/elliptic_reference.csv")
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
