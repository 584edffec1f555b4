//! `study convergence` at its defaults fits every method's order: each fixed-step method on a
//! grid of its own (`study/grid.rs`), in its asymptotic range above the reference's floor; and
//! where an order drops (the compositions on velocity-dependent forces), the run says so first.

#![cfg(feature = "rerun")]

mod common;

use physlab::integrate::Method;
use physlab::study::{Problem, Sweep, damped_companion, error_floor, orders, sweep_with};

/// Within this of theory every fitted order at the defaults (measured: 0.05 from theory at
/// most, sofroniou10 on the rope 0.23 with its neighbours 10.02 – 10.82).
const TOLERANCE: f64 = 0.25;

/// The theory orders, stated here as the literature gives them (the registry's are derived from
/// the same sources and checked against the tableaus in `tests/order_conditions`): for
/// forces of position alone, and for velocity-dependent ones (the compositions fall to 2: their
/// kicks take a predicted mid-kick velocity).
fn theory(m: Method, velocity_dependent: bool) -> f64 {
    let order = match m {
        Method::ExplicitEuler | Method::SemiImplicitEuler | Method::ImplicitEuler => 1,
        Method::Midpoint | Method::Trapezoid | Method::Verlet => 2,
        Method::Rk4 | Method::Rkn4 => 4,
        Method::Yoshida4 => 4,
        Method::Yoshida6 => 6,
        Method::KahanLi8 => 8,
        Method::Sofroniou10 => 10,
        _ => unreachable!("{m} is adaptive"),
    };
    let composition = matches!(
        m,
        Method::Yoshida4 | Method::Yoshida6 | Method::KahanLi8 | Method::Sofroniou10
    );
    if velocity_dependent && composition {
        2.0
    } else {
        f64::from(order)
    }
}

/// Every fixed-step method of the default convergence study of the pendulum, the study's rope
/// and its damped companion gets a fitted order, within [`TOLERANCE`] of theory, the registry
/// agreeing. On main yoshida6, kahan-li8 and sofroniou10 had "fewer than 2 usable rows" on both
/// scenes. The one exception, stated: sofroniou10 on the 60° pendulum, whose leading error terms
/// nearly cancel (`high_order_compositions_converge_at_their_order_on_the_pendulum` measures
/// order 10 at 10°): above the floor its errors fall faster than order 10 (measured 14.6, its
/// neighbours 10.0 – 17.4), so it is held to at least its order, its slowest neighbours at it.
#[test]
fn every_method_gets_its_order_at_the_default_convergence_study() {
    let pendulum = Problem::Pendulum(Default::default());
    let rope = Problem::Rope(physlab::study::study_rope(false));
    let damped = damped_companion(&rope).unwrap();
    for problem in [pendulum, rope, damped] {
        let v = problem.velocity_dependent();
        let sweep = Sweep {
            repeats: 1,
            ..Sweep::defaults(&problem)
        };
        let (rows, reference_error) = sweep_with(&problem, &sweep, true, &mut |_| {});
        let fitted = orders(&rows, error_floor(reference_error));
        let fixed = sweep.methods.iter().filter(|m| !m.info().adaptive());
        assert_eq!(fitted.len(), fixed.count(), "{}", problem.name());
        for o in fitted {
            let (m, name) = (o.method, problem.name());
            let order = theory(m, v);
            assert_eq!(f64::from(m.info().order_for(v)), order, "{m}: the registry");
            let f = o
                .fitted
                .unwrap_or_else(|| panic!("{name} {m}: no fitted order"));
            let (lo, _) = o.range.unwrap();
            if m == Method::Sofroniou10 && name == "pendulum" {
                assert!(
                    (order..order + 6.0).contains(&f) && lo < order + 0.5,
                    "{f} {lo}"
                );
            } else {
                assert!(
                    (f - order).abs() <= TOLERANCE,
                    "{name} {m}: {f:.3}, theory {order}"
                );
            }
        }
    }
}

/// The command at its defaults prints a fitted order for every method, for both scenes.
#[test]
fn the_default_convergence_study_fits_every_method() {
    let dir = common::scratch_dir("convergence-defaults");
    for scene in ["pendulum", "rope"] {
        let out = dir.join(scene);
        let args = ["study", "convergence", "--scene", scene, "--repeats", "1"];
        let (code, stdout, stderr) =
            common::physlab(&[&args[..], &["-o", common::s(&out)]].concat());
        assert_eq!(code, 0, "{stderr}");
        assert!(!stdout.contains("fewer than 2 usable rows"), "{stdout}");
        assert!(stdout.contains("| sofroniou10 "), "{stdout}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A rope whose forces depend on the velocity says, before it runs, which methods fall to which
/// order and why (as the Nyström methods are refused); an undamped rope says nothing;
/// `physlab methods` says it too; the convergence study warns for its damped companion.
#[test]
fn a_method_whose_order_drops_is_named_before_the_run() {
    let dir = common::scratch_dir("order-drops");
    let out = dir.join("r.rrd");
    let o = common::s(&out);
    let run = [
        "rope",
        "--methods",
        "verlet,kahan-li8",
        "--duration",
        "0.05",
    ];
    let (code, stdout, stderr) = common::physlab(&[&run[..], &["-o", o]].concat());
    assert_eq!(code, 0, "{stderr}");
    let said = "kahan-li8 is order 2 on this rope, not 8 (17 evaluations per step): the rope's \
                --spring-damping 0.05 and --air-drag 0.01 make its forces depend on velocity";
    // Warnings and the summary wrap their prose to 100 columns: their words, joined.
    let words = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        words(&stderr).starts_with(&format!("warning: rope: {said}")),
        "{stderr}"
    );
    assert!(
        words(&stdout).contains(said),
        "the summary keeps it: {stdout}"
    );
    assert!(!stderr.contains("verlet is order"), "{stderr}");
    let undamped = ["--spring-damping", "0", "--air-drag", "0", "-o", o];
    let (code, _, stderr) = common::physlab(&[&run[..], &undamped].concat());
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("is order"), "{stderr}");
    let (_, page, _) = common::physlab(&["methods", "kahan-li8"]);
    assert!(
        page.contains("- order drops: to 2 from 8 with a(x,v): its kicks take"),
        "{page}"
    );
    let (_, page, _) = common::physlab(&["methods", "rk4"]);
    assert!(!page.contains("order drops"), "{page}");
    let study = [
        "study",
        "convergence",
        "--scene",
        "rope",
        "--methods",
        "rk4,yoshida6",
    ];
    let o = common::s(&dir.join("s.rrd")).to_string();
    let (code, _, stderr) = common::physlab(&[&study[..], &["--levels", "2", "-o", &o]].concat());
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.starts_with("warning: the damped rope: yoshida6 is order 2 on this rope, not 6"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
