//! The pendulum: its numbers against theory and independent references up to the separatrix,
//! and the command end to end.

#[cfg(feature = "rerun")]
mod common;

mod numerics {
    //! The pendulum's numbers against theory (each test states the formula it checks) and
    //! independent references: periods from `tests/data/pendulum_period.csv`, computed with
    //! 40-digit mpmath.

    use physlab::integrate::{Integrator, Method, MethodOptions};
    use physlab::scene::harness::{NoObserver, Run, run};
    use physlab::scene::pendulum::exact::{ExactPendulum, exact_period};
    use physlab::scene::pendulum::period::PeriodMeter;
    use physlab::scene::pendulum::run::{PendulumConfig, PendulumLane, PendulumScene};
    use physlab::scene::pendulum::{Pendulum, PendulumParams};

    fn params(theta0_deg: f64) -> PendulumParams {
        PendulumParams {
            theta0: theta0_deg.to_radians(),
            ..PendulumParams::default()
        }
    }

    /// A run without a recording.
    fn simulate(config: PendulumConfig) -> Run<PendulumLane> {
        run(&mut PendulumScene::new(config), &mut NoObserver).unwrap()
    }

    fn config(method: Method, theta0_deg: f64, dt: f64, duration: f64) -> PendulumConfig {
        PendulumConfig {
            params: params(theta0_deg),
            dt,
            duration,
            fps: 1.0,
            plot_every: 1,
            methods: vec![method],
            ..PendulumConfig::default()
        }
    }

    /// Steps one method by hand and returns (E_n - E0)/E0 after every step.
    fn energy_errors(method: Method, theta0_deg: f64, dt: f64, steps: usize) -> Vec<f64> {
        let p = params(theta0_deg);
        let sys = Pendulum::new(&p);
        let mut it = Integrator::new(
            method,
            &sys,
            &[p.theta0],
            &[0.0],
            dt,
            MethodOptions::default(),
        );
        let e0 = p.initial_energy();
        (0..steps)
            .map(|_| {
                it.step(&sys);
                (p.energy(it.position()[0], it.velocity()[0]) - e0) / e0
            })
            .collect()
    }

    /// (a) The order measured from the largest |θ - θ_exact| over a 10 s run (every step, so not
    /// only turning points, where the observed order would double) as dt halves, for every method.
    #[test]
    fn measured_convergence_order_matches_the_registry() {
        for &m in Method::DEFAULT {
            let order = m.info().order;
            // Asymptotic ranges: first-order methods need small dt for errors ≪ amplitude; RK4 must
            // stay above round-off (errors here run from 2e-5 down to 6e-9).
            let dts: [f64; 4] = if order == 4 {
                [0.08, 0.04, 0.02, 0.01]
            } else {
                [0.004, 0.002, 0.001, 0.0005]
            };
            let errors: Vec<f64> = dts
                .iter()
                .map(|&dt| {
                    let s = simulate(config(m, 60.0, dt, 10.0));
                    assert!(s.stats[1].divergence.is_none(), "{m} diverged at dt = {dt}");
                    s.lanes[1].max_theta_error
                })
                .collect();
            for (w, dt) in errors.windows(2).zip(dts) {
                let measured = (w[0] / w[1]).log2();
                assert!(
                    (measured - order as f64).abs() <= 0.15,
                    "{m}: order {measured:.3} from dt {dt} to {} (errors {:.3e}, {:.3e}), registry says {order}",
                    dt / 2.0,
                    w[0],
                    w[1]
                );
            }
        }
    }

    /// The scene with `--step` (`MethodOptions::step`): rkn4 stepping at h across samples every
    /// 0.1 s of the 60° swing, its largest |θ − θ_exact| over every sample of 20 s (the scene's
    /// exact lane, the elliptic closed form) below 1e-3 at h = 0.25 s and converging at order 4
    /// as h halves from 1/32 s, and
    /// its own steps and evaluations as the registry counts them: ⌈20/h⌉ steps of 3, plus a(x0).
    #[test]
    fn stepping_across_the_samples_keeps_the_methods_order_and_cost() {
        let errors: Vec<f64> = [0.25, 0.03125, 0.015625]
            .iter()
            .map(|&h| {
                let mut c = config(Method::Rkn4, 60.0, 0.1, 20.0);
                c.options.step = Some(h);
                let s = simulate(c);
                let steps = (20.0 / h) as u64;
                assert_eq!(s.stats[1].counts.own_steps, Some((steps, 0)), "h = {h}");
                assert_eq!(s.stats[1].counts.evals, 1 + 3 * steps, "h = {h}");
                assert_eq!(
                    s.stats[1].ticks_taken(),
                    200,
                    "h = {h}: one sample per 0.1 s"
                );
                s.lanes[1].max_theta_error
            })
            .collect();
        assert!(errors[0] < 1e-3, "h = 0.25: {:.2e}", errors[0]);
        // The order from h = 1/32 s (ω h = 0.05): on the 60° swing rkn4 itself, sampled at its
        // step ends, approaches 4 slowly (3.4 from 0.25 to 0.125 s, 3.85 from 1/16 to 1/32 s).
        let order = (errors[1] / errors[2]).log2();
        assert!(
            (order - 4.0).abs() <= 0.15,
            "order {order:.3} ({:.2e}, {:.2e})",
            errors[1],
            errors[2]
        );
    }

    /// Rows (θ0 [deg], T/T0, T [s] for g = 9.81, L = 3.521) of the reference table.
    fn period_table() -> Vec<(f64, f64, f64)> {
        let text = include_str!("data/pendulum_period.csv");
        let rows: Vec<(f64, f64, f64)> = text
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("theta0"))
            .map(|l| {
                let f: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
                (f[0], f[1], f[2])
            })
            .collect();
        assert_eq!(rows.len(), 7, "the reference table has 7 amplitudes");
        rows
    }

    /// (b) The closed-form solution's period matches the table to 1e-9, both from K(m) and as
    /// measured from the zero crossings of the closed-form θ(t) itself.
    #[test]
    fn exact_solution_matches_reference_periods() {
        for (deg, ratio, period) in period_table() {
            let p = params(deg);
            let exact = ExactPendulum::new(&p).unwrap();
            let t0 = 2.0 * std::f64::consts::PI / p.omega_n();
            assert!(
                (exact.period() / period - 1.0).abs() < 1e-9,
                "{deg}°: T = {} vs {period}",
                exact.period()
            );
            assert!(
                (exact.period() / t0 / ratio - 1.0).abs() < 1e-9,
                "{deg}°: T/T0"
            );
            assert!((exact_period(&p).unwrap() / period - 1.0).abs() < 1e-9);

            let mut meter = PeriodMeter::new();
            let dt = 1e-3;
            let steps = (10.5 * period / dt) as usize;
            for n in 0..=steps {
                let t = n as f64 * dt;
                let (th, w) = exact.state(t);
                meter.push(t, th, w);
            }
            let measured = meter.period().unwrap();
            assert!(
                (measured / period - 1.0).abs() < 1e-9,
                "{deg}°: crossings give {measured} vs {period}"
            );
        }
    }

    /// The leading term c·h^q (h = ωn dt) of a method's relative period error on the linear
    /// oscillator, h/φ(h) - 1, where φ is the angle its one-step matrix turns per step:
    /// semi-implicit Euler and Verlet cos φ = 1 - h²/2, so -h²/24; midpoint and trapezoid (Heun)
    /// R = 1 - h²/2 + ih, so -h²/6; RK4 R = 1 - h²/2 + h⁴/24 + i(h - h³/6), so +h⁴/120; Yoshida-4
    /// cos φ = trace/2 of its composition, +0.0661430883936 h⁴ (`tests/data/yoshida4_stability.py`).
    ///
    /// Semi-implicit Euler is a first-order method, but its period is second-order accurate: it is
    /// Verlet conjugated by a half kick, which moves the start by O(dt) and the energy by O(dt²). No
    /// period bound tells it from Verlet. Explicit and implicit Euler have none: their energy, and so
    /// the amplitude and the period, drift at first order.
    fn period_theory(m: Method) -> Option<(i32, f64)> {
        match m {
            Method::SemiImplicitEuler | Method::Verlet => Some((2, -1.0 / 24.0)),
            Method::Midpoint | Method::Trapezoid => Some((2, -1.0 / 6.0)),
            Method::Rk4 => Some((4, 1.0 / 120.0)),
            Method::Yoshida4 => Some((4, 0.066_143_088_393_6)),
            _ => None,
        }
    }

    /// Relative error of the period measured from zero crossings over ten periods, against the
    /// closed form 4K(m)/ωn (K checked against 40-digit mpmath to 2 eps in `elliptic`, and the
    /// periods against the reference table above).
    fn period_error(m: Method, deg: f64, dt: f64) -> f64 {
        let exact = exact_period(&params(deg)).unwrap();
        let s = simulate(config(m, deg, dt, 10.5 * exact));
        let meter = &s.lanes[1].meter;
        assert!(
            meter.periods_seen() >= 9,
            "{m} {deg}°: {} periods",
            meter.periods_seen()
        );
        meter.period().unwrap() / exact - 1.0
    }

    /// (b) At 1° (the linear regime), each method's period error has the theory's order and its
    /// leading coefficient: the order from dt and 2 dt within 0.01 of q (measured 2.0000 for every
    /// second-order method, 3.9999 RK4, 4.0000 Yoshida-4) and c·h^q within 0.5% (measured 0.02%
    /// to 0.03%; the pendulum's own correction at 1° is ~1e-4). dt = 1 ms for q = 2, 4 ms for q = 4,
    /// where the errors (1e-7, 1e-11) stand far above the measurement's round-off.
    #[test]
    fn period_errors_have_the_linear_theorys_order_and_constant() {
        let deg = 1.0;
        let wn = params(deg).omega_n();
        for m in Method::ALL {
            let Some((q, c)) = period_theory(m) else {
                continue;
            };
            let dt = if q == 2 { 1e-3 } else { 4e-3 };
            let (e1, e2) = (period_error(m, deg, dt), period_error(m, deg, 2.0 * dt));
            let order = (e2 / e1).log2();
            let constant = e1 / (c * (wn * dt).powi(q));
            assert!(
                (order - q as f64).abs() <= 0.01,
                "{m}: period error order {order:.4} (errors {e1:.3e}, {e2:.3e}), theory {q}"
            );
            assert!(
                (constant - 1.0).abs() <= 5e-3,
                "{m}: period error {e1:.4e} is {constant:.4} × theory's {c:.6} h^{q}"
            );
        }
    }

    /// (b) At every amplitude of the reference table (10° to 170°), RK4 at dt = 1 ms and Verlet at
    /// 0.1 ms reproduce the period to within 1.5 × the linear theory's |c| h^q: 9.7e-14 for RK4
    /// (measured at most 6.4e-14), 1.7e-9 for Verlet (measured at most 1.2e-9; the coefficient
    /// shrinks and turns over with amplitude). A method of lower order fails by orders of magnitude:
    /// at 10° midpoint's error at 1 ms is 4.6e-7, explicit Euler's at 0.1 ms 1.1e-5 (both checked).
    /// Semi-implicit Euler would pass Verlet's bound (see `period_theory`).
    #[test]
    fn rk4_and_verlet_reproduce_reference_periods() {
        let wn = params(10.0).omega_n();
        let bound = |m: Method, dt: f64| {
            let (q, c) = period_theory(m).unwrap();
            1.5 * c.abs() * (wn * dt).powi(q)
        };
        let (rk4, verlet) = (bound(Method::Rk4, 1e-3), bound(Method::Verlet, 1e-4));
        for (deg, _, _) in period_table() {
            for (m, dt, bound) in [(Method::Rk4, 1e-3, rk4), (Method::Verlet, 1e-4, verlet)] {
                let e = period_error(m, deg, dt);
                assert!(
                    e.abs() <= bound,
                    "{m} at {deg}°: period error {e:+.2e}, bound {bound:.2e}"
                );
            }
        }
        let midpoint = period_error(Method::Midpoint, 10.0, 1e-3);
        assert!(midpoint.abs() > 1e6 * rk4, "midpoint {midpoint:e}");
        let euler = period_error(Method::ExplicitEuler, 10.0, 1e-4);
        assert!(euler.abs() > 1e3 * verlet, "explicit Euler {euler:e}");
    }

    /// (a) dopri5 with its error control off (rtol = 1e6 and `max_step` = dt: every step is
    /// accepted and spans one dt, checked by its 1 + 6 n force evaluations) is the fixed-step
    /// Dormand–Prince method, fifth order: the largest |θ - θ_exact| over 10 s at 60° as dt halves
    /// from 0.04 s to 0.01 s (errors 5.6e-9, 1.7e-10, 5.1e-12) gives orders 5.08 and 5.04, asserted
    /// within 0.15 of 5 as for the other methods. Larger steps are pre-asymptotic (5.78 from 0.32 to
    /// 0.16 s).
    ///
    /// With error control on (dt = 0.1 s is only the sampling: the steps are the controller's and
    /// the samples come from the dense output), the error is proportional to rtol (tolerance
    /// proportionality: the step is set by the embedded fourth-order estimate, the solution carried
    /// is fifth order): over rtol = 1e-8 to 1e-12 at 60°, error/rtol stays within 8.5 to 9.8
    /// (asserted: within 20% of each other, and the fitted slope 1 ± 0.05; measured 1.015).
    #[test]
    fn dopri5_is_fifth_order_and_its_error_follows_rtol() {
        let fixed = |dt: f64| {
            let mut c = config(Method::Dopri5, 60.0, dt, 10.0);
            c.options.rtol = 1e6;
            c.options.max_step = dt;
            let steps = (10.0 / dt).round() as u64;
            let s = simulate(c);
            assert!(s.stats[1].divergence.is_none());
            assert_eq!(
                s.stats[1].counts.evals,
                1 + 6 * steps,
                "dt {dt}: not one substep per step"
            );
            s.lanes[1].max_theta_error
        };
        let dts = [0.04, 0.02, 0.01];
        let errors: Vec<f64> = dts.iter().map(|&dt| fixed(dt)).collect();
        for (w, dt) in errors.windows(2).zip(dts) {
            let order = (w[0] / w[1]).log2();
            assert!(
                (order - 5.0).abs() <= 0.15,
                "dopri5 (fixed step): order {order:.3} from dt {dt} to {} (errors {:.3e}, {:.3e})",
                dt / 2.0,
                w[0],
                w[1]
            );
        }

        let rtols: Vec<f64> = (8..=12).map(|k| 10f64.powi(-k)).collect();
        let errors: Vec<f64> = rtols
            .iter()
            .map(|&rtol| {
                let mut c = config(Method::Dopri5, 60.0, 0.1, 10.0);
                c.options.rtol = rtol;
                simulate(c).lanes[1].max_theta_error
            })
            .collect();
        let ratios: Vec<f64> = errors.iter().zip(&rtols).map(|(e, r)| e / r).collect();
        let (lo, hi) = ratios.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
            (lo.min(r), hi.max(r))
        });
        assert!(
            hi <= 1.2 * lo,
            "dopri5: error/rtol from {lo:.2} to {hi:.2} ({ratios:?}, slope {:.3})",
            (errors[0] / errors[4]).log10() / (rtols[0] / rtols[4]).log10()
        );
        let slope = (errors[0] / errors[4]).log10() / (rtols[0] / rtols[4]).log10();
        println!("dopri5: errors {errors:?}; error/rtol {ratios:?}; slope {slope:.3}");
        assert!(
            (slope - 1.0).abs() <= 0.05,
            "dopri5: error ∝ rtol^{slope:.3}"
        );
    }

    /// (c) Explicit Euler multiplies the oscillator's energy by exactly 1 + h² per step (h = ωn dt)
    /// and implicit Euler by 1/(1 + h²). At θ0 = 1° the pendulum is that oscillator to ~1e-4, so
    /// the energy must change monotonically and land within 1e-3 (relative) of the theory after 2000 steps.
    #[test]
    fn euler_energy_grows_and_implicit_euler_energy_decays_as_theory_says() {
        let dt = 0.01;
        let n = 2000;
        let h = params(1.0).omega_n() * dt;
        for (m, per_step) in [
            (Method::ExplicitEuler, 1.0 + h * h),
            (Method::ImplicitEuler, 1.0 / (1.0 + h * h)),
        ] {
            let e = energy_errors(m, 1.0, dt, n);
            let growing = per_step > 1.0;
            for w in e.windows(2) {
                assert!(
                    if growing { w[1] > w[0] } else { w[1] < w[0] },
                    "{m}: energy not monotone"
                );
            }
            let theory = per_step.powi(n as i32) - 1.0;
            let last = e[n - 1];
            assert!(
                (last / theory - 1.0).abs() < 1e-3,
                "{m}: ΔE/E0 = {last:.6e}, theory {theory:.6e}"
            );
        }
    }

    /// Largest |x| of a slice.
    fn max_abs(s: &[f64]) -> f64 {
        s.iter().fold(0.0, |a, &b| a.max(b.abs()))
    }

    fn mean(s: &[f64]) -> f64 {
        s.iter().sum::<f64>() / s.len() as f64
    }

    /// (c) Semi-implicit Euler and Verlet keep the energy bounded with no drift over 1000 periods.
    ///
    /// Bounds, from the exactly conserved modified energy of each map on the linear oscillator
    /// (oscillator_theory.md; the pendulum's softening only lowers them): semi-implicit Euler
    /// conserves (v² + x² - h x v)/2, so |ΔE/E0| ≤ (h/2)/(1 - h/2); Verlet conserves
    /// (v² + (1 - h²/4) x²)/2, so |ΔE/E0| ≤ h²/4. At 5° the measured maximum must also reach 95% of
    /// the bound: the oscillation has the predicted size, not merely some bounded size.
    ///
    /// Drift: the mean of ΔE/E0 over the last ten periods may differ from that over the first ten
    /// by at most 1% of the oscillation's amplitude. The same measure flags midpoint, whose energy
    /// grows by h⁴/4 per step, at more than 10× the amplitude, so it does discriminate.
    #[test]
    fn symplectic_methods_keep_energy_bounded_without_drift_over_1000_periods() {
        let dt = 0.01;
        for deg in [5.0, 60.0] {
            let p = params(deg);
            let h = p.omega_n() * dt;
            let period = exact_period(&p).unwrap();
            let window = (10.0 * period / dt).round() as usize;
            let steps = (1000.0 * period / dt).round() as usize;
            let drift = |e: &[f64]| {
                (mean(&e[e.len() - window..]) - mean(&e[..window])).abs() / max_abs(&e[..window])
            };

            for (m, bound) in [
                (Method::SemiImplicitEuler, 0.5 * h / (1.0 - 0.5 * h)),
                (Method::Verlet, 0.25 * h * h),
            ] {
                let e = energy_errors(m, deg, dt, steps);
                let max = max_abs(&e);
                assert!(
                    max <= bound * (1.0 + 1e-9),
                    "{m} at {deg}°: max |ΔE/E0| {max:.4e} > bound {bound:.4e}"
                );
                if deg == 5.0 {
                    assert!(
                        max >= 0.95 * bound,
                        "{m} at {deg}°: max |ΔE/E0| {max:.4e} far below theory {bound:.4e}"
                    );
                }
                assert!(
                    drift(&e) < 0.01,
                    "{m} at {deg}°: energy drifts by {:.2}% of its oscillation",
                    100.0 * drift(&e)
                );
            }
            let e = energy_errors(Method::Midpoint, deg, dt, steps);
            assert!(
                drift(&e) > 10.0,
                "midpoint at {deg}°: drift measure {:.2} should flag it",
                drift(&e)
            );
        }
    }

    /// One run of `tests/data/whole_run_reference.csv`: its start and θ at t = j·every, j = 1..
    struct WholeRun {
        params: PendulumParams,
        degrees: f64,
        every: f64,
        theta: Vec<f64>,
    }

    fn whole_runs() -> Vec<WholeRun> {
        let mut runs: Vec<WholeRun> = Vec::new();
        for line in include_str!("data/whole_run_reference.csv")
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("gravity"))
        {
            let f: Vec<f64> = line.split(',').map(|x| x.trim().parse().unwrap()).collect();
            let params = PendulumParams {
                gravity: f[0],
                length: f[1],
                theta0: f[3],
                omega0: f[4],
                ..PendulumParams::default()
            };
            let (degrees, every, j, theta) = (f[2], f[5], f[6] as usize, f[7]);
            if j == 1 {
                runs.push(WholeRun {
                    params,
                    degrees,
                    every,
                    theta: Vec::new(),
                });
            }
            let run = runs.last_mut().unwrap();
            assert_eq!((run.params, run.theta.len() + 1), (params, j), "{line}");
            run.theta.push(theta);
        }
        runs
    }

    /// The closed form holds its stated accuracy at every sample of whole runs (30–100 s, 10° to
    /// 179.999999°, many periods), not only at a few times: the argument K - ωn t and its reduction
    /// by the period lose a little with every period, so the bound is stated per duration.
    #[test]
    fn closed_form_holds_its_stated_accuracy_over_whole_runs() {
        let runs: Vec<WholeRun> = whole_runs()
            .into_iter()
            .filter(|r| r.params.omega0 == 0.0)
            .collect();
        assert_eq!(runs.len(), 8);
        let mut failed = Vec::new();
        for r in runs {
            let exact = ExactPendulum::new(&r.params).unwrap();
            let duration = r.every * r.theta.len() as f64;
            let worst = r
                .theta
                .iter()
                .enumerate()
                .map(|(i, th)| (exact.state((i + 1) as f64 * r.every).0 - th).abs())
                .fold(0.0, f64::max);
            let stated = exact.theta_accuracy(duration);
            let line = format!(
                "{}° over {duration} s: {worst:.2e} rad (stated {stated:.1e})",
                r.degrees
            );
            println!("{line}");
            if worst > stated {
                failed.push(line);
            }
        }
        assert!(failed.is_empty(), "{failed:#?}");
    }

    /// The fine-step reference's printed error estimate is honest: over whole runs with ω0 ≠ 0
    /// (over the top both ways, near the separatrix, swinging), sampled at 0.1 s and at 0.01 s, the
    /// true largest error against 32-digit mpmath never exceeds the estimate, and the estimate is
    /// within 100× of it (or 1e-12 rad), so it still says how good the reference is.
    #[test]
    fn fine_step_reference_error_estimate_bounds_the_true_error() {
        use physlab::scene::pendulum::reference::FineStepReference;
        let runs: Vec<WholeRun> = whole_runs()
            .into_iter()
            .filter(|r| r.params.omega0 != 0.0)
            .collect();
        assert_eq!(runs.len(), 8);
        let mut failed = Vec::new();
        for r in runs {
            for per in [1usize, 10] {
                let mut reference = FineStepReference::new(&r.params, r.every / per as f64);
                let mut worst: f64 = 0.0;
                for th in &r.theta {
                    let mut got = 0.0;
                    for _ in 0..per {
                        got = reference.advance().0;
                    }
                    worst = worst.max((got - th).abs());
                }
                let estimate = reference.error_estimate();
                let line = format!(
                    "{}°, {} rad/s, dt {}: true {worst:.2e}, estimate {estimate:.2e}",
                    r.degrees,
                    r.params.omega0,
                    r.every / per as f64
                );
                println!("{line}");
                // Above the true error (honest), and within 100× of it (informative).
                if worst > estimate || estimate > 100.0 * worst.max(1e-14) {
                    failed.push(line);
                }
            }
        }
        assert!(failed.is_empty(), "{failed:#?}");
    }

    /// The convergence study's own reference for starts with ω0 ≠ 0 (the scene's fine-step
    /// reference): over the same whole runs, the error it states bounds its true error against
    /// 32-digit mpmath and is within 100× of it (or 1e-14 rad).
    #[test]
    fn the_studys_reference_states_its_error_honestly() {
        use physlab::study::{Problem, reference};
        let mut failed = Vec::new();
        for r in whole_runs().into_iter().filter(|r| r.params.omega0 != 0.0) {
            // Sampled every r.every, as a study with dt0 = r.every / 10 and 6 levels would be.
            let finest = r.every / 10.0 / 32.0;
            let (states, estimate) =
                reference(&Problem::Pendulum(r.params), r.every, r.theta.len(), finest).unwrap();
            let worst = states
                .iter()
                .zip(&r.theta)
                .map(|(s, th)| (s[0] - th).abs())
                .fold(0.0, f64::max);
            let line = format!(
                "{}°, {} rad/s: true {worst:.2e}, estimate {estimate:.2e}",
                r.degrees, r.params.omega0
            );
            println!("{line}");
            if worst > estimate || estimate > 100.0 * worst.max(1e-14) {
                failed.push(line);
            }
        }
        assert!(failed.is_empty(), "{failed:#?}");
    }
}

mod separatrix {
    //! The exact pendulum up to the separatrix: the period and θ(t) of a release
    //! from rest just below 180° against `tests/data/separatrix_reference.csv` (100-digit mpmath at
    //! the exact radian doubles, two independent routes; `tests/data/separatrix_reference.py` wrote
    //! it), and no panic or hang for any finite release angle, on both reference paths.

    use physlab::integrate::Method;
    use physlab::scene::harness::{NoObserver, run};
    use physlab::scene::pendulum::PendulumParams;
    use physlab::scene::pendulum::exact::{ExactPendulum, exact_period};
    use physlab::scene::pendulum::run::{PendulumConfig, PendulumScene};

    struct Row {
        deg: f64,
        rad: f64,
        period: f64,
        period_decimal: f64,
        t: f64,
        theta: f64,
        omega: f64,
    }

    fn rows() -> Vec<Row> {
        include_str!("data/separatrix_reference.csv")
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("theta0_deg"))
            .map(|l| {
                let f: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
                Row {
                    deg: f[0],
                    rad: f[1],
                    period: f[3],
                    period_decimal: f[4],
                    t: f[5],
                    theta: f[6],
                    omega: f[7],
                }
            })
            .collect()
    }

    fn params(rad: f64) -> PendulumParams {
        PendulumParams {
            theta0: rad,
            ..PendulumParams::default()
        }
    }

    /// The radian double in the table is the one the CLI makes of the degrees (f64::to_radians).
    #[test]
    fn table_angles_are_what_the_cli_makes_of_the_degrees() {
        for r in rows() {
            assert_eq!(r.deg.to_radians(), r.rad, "{}", r.deg);
        }
    }

    /// T = 4K/ωn to 1e-12 relative for every angle in the table, 90° to 179.99999999999°
    /// (k' down to 8.7e-14); the worst measured is printed.
    #[test]
    fn period_holds_to_1e_12_up_to_the_separatrix() {
        let mut worst: f64 = 0.0;
        for r in rows().iter().filter(|r| r.t == 0.0) {
            let p = params(r.rad);
            let exact = ExactPendulum::new(&p).unwrap();
            for (what, got) in [
                ("ExactPendulum", exact.period()),
                ("exact_period", exact_period(&p).unwrap()),
            ] {
                let rel = (got / r.period - 1.0).abs();
                worst = worst.max(rel);
                assert!(
                    rel <= 1e-12,
                    "{what} at {}°: {got} vs {}: {rel:.1e}",
                    r.deg,
                    r.period
                );
            }
        }
        println!("worst relative period error: {worst:.2e}");
        // 179.9999° is 36.7559359 s (1 - m computed by subtraction would cancel to 36.7558266 s).
        let t = exact_period(&params(179.9999_f64.to_radians())).unwrap();
        assert!((t - 36.755_935_9).abs() < 1e-7, "{t}");
    }

    /// What the rounding of the decimal degrees to a radian double costs: at 179.9999999° the period
    /// of the radian double differs from the decimal angle's by about 2e-9 relative. The table's
    /// references are for the radian double; `theta0_from_degrees` keeps what the rounding lost
    /// (`typed_angles_get_the_period_of_the_angle_typed`).
    #[test]
    fn input_rounding_dominates_beyond_179_9999999() {
        let r = rows()
            .into_iter()
            .find(|r| r.deg == 179.999_999_9 && r.t == 0.0)
            .unwrap();
        let rounding = (r.period / r.period_decimal - 1.0).abs();
        assert!(rounding > 1e-10 && rounding < 1e-8, "{rounding:e}");
    }

    /// θ(t) and ω(t) at sample times over several periods: θ to 4e-12 rad (1.3e-12 of π), ω to
    /// 1e-12 of its largest value 2 ωn. Measured: 9.6e-15 rad and 1.6e-15.
    #[test]
    fn motion_holds_to_1e_12_up_to_the_separatrix() {
        let (mut worst_theta, mut worst_omega): (f64, f64) = (0.0, 0.0);
        for r in rows() {
            let p = params(r.rad);
            let (theta, omega) = ExactPendulum::new(&p).unwrap().state(r.t);
            let scale = 2.0 * p.omega_n();
            let (et, ew) = ((theta - r.theta).abs(), (omega - r.omega).abs() / scale);
            worst_theta = worst_theta.max(et);
            worst_omega = worst_omega.max(ew);
            assert!(
                et <= 4e-12,
                "θ({}) at {}°: {theta} vs {}: {et:.1e}",
                r.t,
                r.deg,
                r.theta
            );
            assert!(
                ew <= 1e-12,
                "ω({}) at {}°: {omega} vs {}: {ew:.1e}",
                r.t,
                r.deg,
                r.omega
            );
        }
        println!("worst |Δθ| {worst_theta:.2e} rad, worst |Δω|/(2ωn) {worst_omega:.2e}");
        // The accuracy the studies state for the exact solution.
        assert!(
            worst_theta <= physlab::scene::pendulum::exact::EXACT_THETA_ACCURACY,
            "{worst_theta:e}"
        );
    }

    /// Beyond the table: every double below π is finite, the period grows monotonically, θ(0) = θ0.
    #[test]
    fn finite_and_monotone_to_the_last_double_below_pi() {
        let mut theta0 = std::f64::consts::PI;
        let mut last = f64::INFINITY;
        for _ in 0..60 {
            theta0 = f64::from_bits(theta0.to_bits() - 1);
            let p = params(theta0);
            let e = ExactPendulum::new(&p).unwrap();
            let t = e.period();
            assert!(t.is_finite() && t < last, "{theta0}: {t}");
            assert_eq!(exact_period(&p).unwrap(), t);
            assert!(
                (e.state(0.0).0 - theta0).abs() <= 4.0 * f64::EPSILON,
                "{theta0}"
            );
            for s in [0.1, 1.0, 7.0, 100.0] {
                let (th, w) = e.state(s);
                assert!(
                    th.is_finite() && w.is_finite() && th.abs() <= theta0,
                    "{theta0} at {s}"
                );
            }
            last = t;
            theta0 = f64::from_bits(theta0.to_bits() - (1 << 20));
        }
    }

    /// A short run of the scene (both reference paths, the exact period, the summary's numbers) for
    /// release angles the CLI accepts, near and beyond the top: no panic, no hang, finite reference.
    #[test]
    fn scene_runs_at_any_release_angle() {
        for deg in [
            179.999_999,
            179.999_999_999_999_97,
            180.0,
            -180.0,
            360.0,
            -179.999_999_99,
            540.0,
            1e6,
            -1e6,
            1e300,
        ] {
            let config = PendulumConfig {
                params: params(f64::to_radians(deg)),
                dt: 0.01,
                duration: 2.0,
                fps: 1.0,
                plot_every: 1,
                methods: vec![Method::Rk4, Method::Dopri5],
                ..PendulumConfig::default()
            };
            let started = std::time::Instant::now();
            let mut scene = PendulumScene::new(config);
            let description = scene.reference_description();
            let out = run(&mut scene, &mut NoObserver).unwrap();
            assert!(
                started.elapsed().as_secs_f64() < 30.0,
                "{deg}° took too long"
            );
            assert!(!description.contains("NaN"), "{deg}°: {description}");
            if let Some(t) = scene.exact_period {
                assert!(t.is_finite() && t > 0.0, "{deg}°: {t}");
            }
            assert!(!out.lanes.is_empty(), "{deg}°");
        }
    }

    /// The period of a release from rest at an angle typed in degrees is that of the very double
    /// typed (`tests/data/typed_angle_period.csv`, 60-digit mpmath from the typed double, wrapped as
    /// physlab wraps it), 90° to 179.999999999999°, negative, past 180° and several turns out, to
    /// 1e-13 relative (measured 4.4e-16); the radian double alone is off by up to 1.4e-4 there.
    #[test]
    fn typed_angles_get_the_period_of_the_angle_typed() {
        use physlab::scene::pendulum::theta0_from_degrees;
        let rows: Vec<(String, f64)> = include_str!("data/typed_angle_period.csv")
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("theta0"))
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                (f[0].to_string(), f[2].parse().unwrap())
            })
            .collect();
        assert_eq!(rows.len(), 24);
        let (mut worst, mut worst_radians): (f64, f64) = (0.0, 0.0);
        for (typed, period) in rows {
            let (theta0, theta0_low) = theta0_from_degrees(typed.parse().unwrap());
            let p = PendulumParams {
                theta0,
                theta0_low,
                ..PendulumParams::default()
            };
            for (what, got) in [
                ("ExactPendulum", ExactPendulum::new(&p).unwrap().period()),
                ("exact_period", exact_period(&p).unwrap()),
            ] {
                let rel = (got / period - 1.0).abs();
                worst = worst.max(rel);
                assert!(
                    rel <= 1e-13,
                    "{what} at {typed}°: {got} vs {period}: {rel:.1e}"
                );
            }
            // Without the low part: what rounding to radians alone costs (the test can fail).
            let rounded = ExactPendulum::new(&PendulumParams {
                theta0_low: 0.0,
                ..p
            })
            .unwrap()
            .period();
            worst_radians = worst_radians.max((rounded / period - 1.0).abs());
        }
        println!("worst {worst:.1e}; from the radian double alone {worst_radians:.1e}");
        assert!(worst_radians > 1e-9, "{worst_radians:e}");
    }
}

#[cfg(feature = "rerun")]
mod cli {
    //! The binary end to end: exit code, summary, and the recording read back
    //! with Rerun's own decoder.

    use std::collections::BTreeMap;

    use clap::Parser as _;
    use physlab::app::config_from_flags;
    use physlab::cli::{Cli, Command as Sub};
    use physlab::scene::harness::{Observer, SeriesBatch, run};
    use physlab::scene::pendulum::run::PendulumScene;

    use crate::common::{decode, physlab, scratch_dir};

    /// The exact period at 60° (g = 9.81, L = 3.521) from the mpmath table.
    const PERIOD_60: f64 = 4.039724609;

    /// A step beyond a tenth of the period (a unit mistake: `--dt 10` meant 10 ms) runs (exit 0)
    /// but is said up front on stderr with the period, and the summary marks the run; a step
    /// just under a tenth is not warned about.
    #[test]
    fn a_step_beyond_a_tenth_of_the_period_is_warned_with_the_period() {
        let base = [
            "pendulum",
            "--theta0",
            "60",
            "--gravity",
            "9.81",
            "--length",
            "3.521",
            "-q",
            "--no-record",
            "--duration",
            "20",
        ];
        let run = |dt: String| {
            let mut args = base.to_vec();
            args.extend(["--dt", dt.as_str()]);
            physlab(&args)
        };
        let (code, stdout, stderr) = run("10".into());
        assert_eq!(code, 0, "{stderr}");
        let warning = stderr
            .lines()
            .find(|l| l.starts_with("warning: pendulum: --dt 10 s exceeds a tenth"))
            .unwrap_or_else(|| panic!("no warning:\n{stderr}"));
        let said: f64 = warning
            .split("period ")
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .and_then(|t| t.parse().ok())
            .unwrap_or_else(|| panic!("no period in {warning}"));
        assert!((said - PERIOD_60).abs() < 0.005, "{said} vs {PERIOD_60}");
        assert!(stdout.contains("warning: --dt 10 s exceeds"), "{stdout}");
        // Just above and just below a tenth of the period.
        let (_, _, stderr) = run(format!("{}", PERIOD_60 / 10.0 * 1.001));
        assert!(stderr.contains("exceeds a tenth"), "{stderr}");
        let (code, stdout, stderr) = run(format!("{}", PERIOD_60 / 10.0 * 0.999));
        assert_eq!(code, 0, "{stderr}");
        assert!(!stderr.contains("warning"), "{stderr}");
        assert!(!stdout.contains("warning"), "{stdout}");
    }

    /// Collects each lane's θ series, and its |θ − θref| where it has one, as the library reports
    /// them.
    #[derive(Default)]
    struct ThetaCollector(
        BTreeMap<usize, Vec<(u64, f64)>>,
        BTreeMap<usize, Vec<(u64, f64)>>,
    );

    impl Observer<PendulumScene> for ThetaCollector {
        fn series(
            &mut self,
            _: &PendulumScene,
            lane: usize,
            b: &SeriesBatch,
        ) -> anyhow::Result<()> {
            let rows = self.0.entry(lane).or_default();
            rows.extend(b.ticks.iter().copied().zip(b.columns[0].iter().copied()));
            let theta_error = physlab::scene::pendulum::run::QUANTITIES
                .iter()
                .position(|q| *q == "theta_error")
                .unwrap();
            if let Some(errors) = b.columns.get(theta_error) {
                let rows = self.1.entry(lane).or_default();
                rows.extend(b.ticks.iter().copied().zip(errors.iter().copied()));
            }
            Ok(())
        }
    }

    #[test]
    fn pendulum_run_writes_a_complete_recording_whose_theta_equals_the_simulation() {
        let dir = scratch_dir("e2e");
        let out = dir.join("sub/p.rrd");
        let args = [
            "pendulum",
            "--duration",
            "3",
            "--theta0",
            "75",
            "-o",
            out.to_str().unwrap(),
        ];
        // `physlab` also asserts that nothing panicked.
        let (code, stdout, stderr) = physlab(&args);
        assert_eq!(code, 0, "stdout:\n{stdout}\nstderr:\n{stderr}");

        let methods = [
            "explicit-euler",
            "semi-implicit-euler",
            "implicit-euler",
            "midpoint",
            "trapezoid",
            "rk4",
            "verlet",
        ];
        for lane in std::iter::once("exact").chain(methods) {
            assert!(
                stdout.lines().any(|l| l.starts_with(&format!("| {lane} "))),
                "summary row for {lane}:\n{stdout}"
            );
        }
        assert!(
            stdout.contains("T = 4.212040767") && stdout.contains("recording: "),
            "{stdout}"
        );
        // No temporary file is left beside the recording.
        let leftovers: Vec<_> = std::fs::read_dir(out.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(leftovers, vec![std::ffi::OsString::from("p.rrd")]);

        let d = decode(&out);
        assert!(d.has_footer, "the recording is finalised with a footer");
        for lane in std::iter::once("exact").chain(methods) {
            for part in ["pivot", "rod", "bob"] {
                assert!(
                    d.entities.contains(&format!("/pendulum/{lane}/{part}")),
                    "missing /pendulum/{lane}/{part}"
                );
            }
            for q in ["theta", "omega", "energy", "log10_energy_error"] {
                assert!(
                    d.scalars
                        .contains_key(&format!("/pendulum/plots/{q}/{lane}")),
                    "missing plot {q}/{lane}"
                );
            }
            assert!(d.entities.contains(&format!("/pendulum/phase/{lane}/path")));
        }
        for m in methods {
            assert!(
                d.scalars
                    .contains_key(&format!("/pendulum/plots/log10_theta_error/{m}"))
            );
            assert!(d.entities.contains(&format!("/pendulum/{m}/exact_ghost")));
        }
        assert!(d.entities.contains("/pendulum/events") && d.entities.contains("/pendulum/about"));

        // The θ series in the file equals the library's, value for value, at the same times.
        let Sub::Pendulum(parsed) = Cli::parse_from(std::iter::once("physlab").chain(args)).command
        else {
            unreachable!()
        };
        let config: physlab::scene::pendulum::run::PendulumConfig =
            config_from_flags(&parsed.scene, "pendulum").unwrap();
        let mut collected = ThetaCollector::default();
        let dt = config.dt;
        let summary = run(&mut PendulumScene::new(config), &mut collected).unwrap();
        for (lane, rows) in &collected.0 {
            let name = summary.stats[*lane].name;
            let recorded = &d.scalars[&format!("/pendulum/plots/theta/{name}")];
            assert_eq!(recorded.len(), rows.len(), "{name}: row count");
            for (&(t_ns, v), &(step, theta)) in recorded.iter().zip(rows) {
                let expected_ns = (step as f64 * dt * 1e9).round() as i64;
                assert!(
                    (t_ns - expected_ns).abs() <= 1,
                    "{name}: time {t_ns} ns vs step {step}"
                );
                assert_eq!(
                    v.to_bits(),
                    theta.to_bits(),
                    "{name} at step {step}: {v} vs {theta}"
                );
            }
        }
        // The error is plotted as log10 |θ − θref|, zeros (the start) left out: value for value.
        assert_eq!(collected.1.len(), methods.len());
        for (lane, rows) in &collected.1 {
            let name = summary.stats[*lane].name;
            let recorded = &d.scalars[&format!("/pendulum/plots/log10_theta_error/{name}")];
            let expected: Vec<(u64, f64)> = rows
                .iter()
                .filter(|r| r.1 != 0.0)
                .map(|&(s, e)| (s, e.abs().log10()))
                .collect();
            assert!(expected.len() + 1 >= rows.len() && expected.len() > 100);
            assert_eq!(recorded.len(), expected.len(), "{name}: log10 row count");
            for (&(t_ns, v), &(step, log_e)) in recorded.iter().zip(&expected) {
                assert!((t_ns - (step as f64 * dt * 1e9).round() as i64).abs() <= 1);
                assert_eq!(v.to_bits(), log_e.to_bits(), "{name} at step {step}");
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn dash_output_streams_the_recording_to_stdout_and_the_summary_to_stderr() {
        let dir = scratch_dir("stdout");
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(["pendulum", "--duration", "2", "-q", "-o", "-"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{stderr}");
        assert!(
            stderr.contains("| rk4 ") && stderr.contains("recording written to standard output"),
            "{stderr}"
        );
        // Standard output is the recording itself, footer included, and no file named `-` appears.
        let rrd = dir.join("piped.rrd");
        std::fs::write(&rrd, &out.stdout).unwrap();
        let d = decode(&rrd);
        assert!(d.has_footer && d.scalars.contains_key("/pendulum/plots/theta/rk4"));
        assert!(!std::path::Path::new("-").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn no_record_is_a_run_flag_of_every_scene() {
        for scene in ["pendulum", "rope"] {
            let (code, stdout, stderr) =
                physlab(&[scene, "--duration", "0.5", "-q", "--no-record"]);
            assert_eq!(code, 0, "{stderr}");
            assert!(stdout.contains("no recording (--no-record)"), "{stdout}");
        }
    }

    /// An adaptive method's own steps are shown beside the dt grid it is sampled on, and they are
    /// the steps it paid for: Dormand–Prince 5(4) is FSAL, so every step tried (accepted or
    /// rejected) costs 6 evaluations after the first step's extra one, and its dense output none.
    #[test]
    fn adaptive_methods_show_their_own_steps_and_pay_six_evaluations_each() {
        for rtol in ["1e-4", "1e-8", "1e-11"] {
            let (code, stdout, stderr) = physlab(&[
                "pendulum",
                "--methods",
                "dopri5",
                "--rtol",
                rtol,
                "--no-record",
                "-q",
                "--wide",
            ]);
            assert_eq!(code, 0, "{stderr}");
            let row = stdout
                .lines()
                .find(|l| l.starts_with("| dopri5 "))
                .unwrap_or_else(|| panic!("no dopri5 row:\n{stdout}"));
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            // "2000 (own: A + R rejected)"
            let own = cells[2]
                .split("own: ")
                .nth(1)
                .unwrap_or_else(|| panic!("no own steps in '{}'", cells[2]));
            let numbers: Vec<u64> = own
                .split(|c: char| !c.is_ascii_digit())
                .filter(|s| !s.is_empty())
                .map(|s| s.parse().unwrap())
                .collect();
            let (accepted, rejected) = (numbers[0], numbers[1]);
            let evals: u64 = cells[3].parse().unwrap();
            assert!(cells[2].starts_with("2000 "), "{row}");
            assert!(accepted < 2000, "its steps are not the dt grid: {row}");
            assert_eq!(evals, 6 * (accepted + rejected) + 1, "rtol {rtol}: {row}");
            assert!(stdout.contains("ns/step is per own step"), "{stdout}");
        }
    }

    /// `--gravity` takes the rope's and hair's vector form too; the pendulum uses its length.
    #[test]
    fn pendulum_gravity_takes_a_number_or_the_vector_and_uses_its_length() {
        let gravity = |args: &[&str]| -> (i32, Option<f64>, String) {
            let mut all = vec!["pendulum"];
            all.extend_from_slice(args);
            all.push("--print-config");
            let (code, toml, stderr) = physlab(&all);
            let g = toml
                .parse::<toml::Table>()
                .ok()
                .and_then(|t| t.get("pendulum")?.get("gravity")?.as_float());
            (code, g, stderr)
        };
        assert_eq!(gravity(&[]).1, Some(9.81));
        assert_eq!(gravity(&["--gravity", "1.62"]).1, Some(1.62));
        assert_eq!(gravity(&["--gravity", "0,0,-9.81"]).1, Some(9.81));
        assert_eq!(gravity(&["--gravity", "3,0,-4"]).1, Some(5.0));
        let dir = scratch_dir("pendulum-gravity");
        let file = dir.join("p.toml");
        std::fs::write(&file, "[pendulum]\ngravity = [0.0, -3.0, -4.0]\n").unwrap();
        assert_eq!(gravity(&["--config", file.to_str().unwrap()]).1, Some(5.0));
        // Bad forms are refused naming the flag and what it takes: rows of `cli_input.rs`.
    }
}

#[cfg(feature = "rerun")]
mod angles {
    //! Any release angle is the pendulum it names: modulo a turn, and down to tiny amplitudes.

    use crate::common::{physlab, scratch_dir};

    #[test]
    fn any_angle_is_the_same_pendulum_modulo_a_turn() {
        // 181° is the release from -179°, which the closed form covers; so is 541° and -539°.
        for theta0 in ["181", "541", "-539", "359999.5"] {
            let (code, stdout, stderr) = physlab(&[
                "pendulum",
                "--theta0",
                theta0,
                "--duration",
                "1",
                "--print-config",
            ]);
            assert_eq!(code, 0, "{theta0}: {stderr}");
            assert!(stdout.contains("theta0"), "{stdout}");
        }
        let dir = scratch_dir("edges-wrap");
        let out = dir.join("p.rrd");
        let (code, stdout, stderr) = physlab(&[
            "pendulum",
            "--theta0",
            "541",
            "--duration",
            "1",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
        assert!(stdout.contains("θ0 = -179°"), "{stdout}");
        assert!(stdout.contains("exact: closed form"), "{stdout}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tiny_amplitudes_are_the_small_oscillations_they_are() {
        use physlab::scene::harness::{NoObserver, run};
        use physlab::scene::pendulum::run::{PendulumConfig, PendulumScene};
        for degrees in [1e-3, 1e-6, 1e-9, -1e-12] {
            let mut config = PendulumConfig::default();
            config.params.theta0 = f64::to_radians(degrees);
            let mut scene = PendulumScene::new(config);
            assert!(scene.initial_energy > 0.0, "{degrees}°: E0 > 0");
            let period = scene.exact_period.expect("a swing has a period");
            let small = 2.0 * std::f64::consts::PI / scene.config.params.omega_n();
            assert!(
                (period / small - 1.0).abs() < 1e-9,
                "{degrees}°: {period} vs {small}"
            );
            let r = run(&mut scene, &mut NoObserver).unwrap();
            // The exact solution's own energy error is round-off, not 1 - cos θ's cancellation; RK4's
            // real error (~6e-10 at dt = 0.01 s) stands well above it.
            let error = |name: &str| {
                let i = r.stats.iter().position(|s| s.name == name).unwrap();
                r.lanes[i].max_energy_error
            };
            assert!(
                error("exact") < 1e-13,
                "{degrees}°: exact {:e}",
                error("exact")
            );
            assert!(
                error("rk4") > 1e3 * error("exact") && error("rk4") < 1e-8,
                "{degrees}°: rk4 {:e}",
                error("rk4")
            );
        }
    }
}

/// The pendulum's physics (`physlab::scene::pendulum`).
mod physics {
    use physlab::integrate::SecondOrderSystem;
    use physlab::scene::pendulum::*;

    #[test]
    fn implicit_step_satisfies_backward_euler_equations() {
        let p = PendulumParams::default();
        let sys = Pendulum::new(&p);
        let (theta0, omega0) = (1.0, 0.3);
        let (mut x, mut v) = ([theta0], [omega0]);
        let dt = 0.05;
        let r = sys.implicit_euler_step(&mut x, &mut v, dt);
        assert!(r.converged && r.jacobian_evals <= 6, "{r:?}");
        // The guess's force evaluation and one force + one Jacobian per Newton iteration.
        assert_eq!(r.evals, r.jacobian_evals + 1, "{r:?}");
        // The backward-Euler equations from scratch. Eliminating ω1 leaves one equation in θ1
        // alone, R(θ1) = θ1 - θ0 - dt ω0 + dt² (g/L) sin θ1 = 0 (the solver iterates on ω1, so
        // this is not true by construction); then ω1 = ω0 - dt (g/L) sin θ1.
        let c = p.gravity / p.length;
        let (theta1, omega1) = (x[0], v[0]);
        let residual = theta1 - theta0 - dt * omega0 + dt * dt * c * theta1.sin();
        assert!(residual.abs() < 1e-14, "R(θ1) = {residual:e}");
        assert!((omega1 - (omega0 - dt * c * theta1.sin())).abs() < 1e-12);
        // R is that small only at the root: at the explicit-Euler guess it is not.
        let guess = theta0 + dt * (omega0 - dt * c * theta0.sin());
        let miss = guess - theta0 - dt * omega0 + dt * dt * c * guess.sin();
        assert!(miss.abs() > 1e-6, "R(guess) = {miss:e}");
    }

    /// The incremental potential, written out here: Φ(θ) = ½ (θ - b)² + a (1 - cos θ).
    fn phi(theta: f64, b: f64, a: f64) -> f64 {
        0.5 * (theta - b).powi(2) + 2.0 * a * (0.5 * theta).sin().powi(2)
    }

    /// For a ≥ 1 the step returns a root of R(θ) = θ - b + a sin θ (|R| ≤ 1e-12 (1 + |b|)), and
    /// no point of a fine grid over the whole region where the minimiser can be
    /// (|θ - b| ≤ 2√a, since Φ ≥ ½ (θ - b)² and Φ(b) ≤ 2a) has a lower Φ: it is the global
    /// minimiser, found by brute force independently of the solver's interval argument.
    #[test]
    fn the_large_step_root_is_the_global_minimiser_of_the_incremental_potential() {
        let mut tried = 0;
        for a in [1.0, 1.003, 2.79, 10.0, 69.7, 697.0, 7000.0, 1e6] {
            for b in [
                0.0,
                1e-9,
                0.3,
                1.047,
                2.5,
                3.1,
                3.2,
                -4.0,
                7.0,
                20.5,
                -100.3,
                1e4 + 0.7,
            ] {
                let (theta, s, solve) =
                    minimising_root(b, a, 1.0, 0.0, NEWTON_TOL, NEWTON_MAX_ITERATIONS);
                tried += 1;
                assert!(solve.converged, "a {a}, b {b}: {solve:?}");
                assert!(
                    (s - theta.sin()).abs() <= 1e-12 * (1.0 + theta.abs()),
                    "a {a}, b {b}"
                );
                let r = theta - b + a * theta.sin();
                assert!(r.abs() <= 1e-9 * (1.0 + a), "a {a}, b {b}: R(θ1) = {r:e}");
                let mine = phi(theta, b, a);
                let reach = 2.0 * a.sqrt() + 1.0;
                let n = 400_000;
                let grid_min = (0..=n)
                    .map(|i| phi(b - reach + 2.0 * reach * i as f64 / n as f64, b, a))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    mine <= grid_min + 1e-9 * (1.0 + grid_min),
                    "a {a}, b {b}: Φ(θ1 = {theta}) = {mine}, the grid reaches {grid_min}"
                );
            }
        }
        assert_eq!(tried, 96);
    }

    /// Implicit Euler released from rest never gains energy at any dt: at every step of 200,
    /// E ≤ E0 (1 + 1e-12), for dt from 0.1 s (dt² g/L = 0.03) to 50 s (7000) and releases from
    /// 1° to 179°. Newton from the explicit-Euler guess gained ×58 in one step at dt = 5.
    #[test]
    fn implicit_euler_from_rest_never_gains_energy_at_any_step_size() {
        for theta0 in [1.0f64, 30.0, 60.0, 120.0, 170.0, 179.0] {
            let p = PendulumParams {
                theta0: theta0.to_radians(),
                ..PendulumParams::default()
            };
            let sys = Pendulum::new(&p);
            let e0 = p.initial_energy();
            for dt in [0.1, 0.5, 0.6, 1.0, 2.0, 5.0, 13.0, 50.0] {
                let (mut x, mut v) = ([p.theta0], [0.0]);
                let mut worst = 0.0f64;
                for _ in 0..200 {
                    let solve = sys.implicit_euler_step(&mut x, &mut v, dt);
                    assert!(solve.converged, "θ0 {theta0}, dt {dt}: {solve:?}");
                    worst = worst.max(p.energy(x[0], v[0]) / e0 - 1.0);
                }
                assert!(
                    worst <= 1e-12,
                    "θ0 {theta0}°, dt {dt}: E/E0 - 1 reached {worst:e}"
                );
            }
        }
    }

    #[test]
    fn energy_zero_at_bottom_and_2gl_at_top() {
        let p = PendulumParams::default();
        assert_eq!(p.energy(0.0, 0.0), 0.0);
        let top = p.energy(std::f64::consts::PI, 0.0);
        assert!((top - p.over_the_top_energy()).abs() < 1e-12);
    }
}

mod periodic_table {
    //! The closed form tabulated over one period (`scene/pendulum/periodic.rs`): its phase
    //! reduction, its verified error and its agreement with the closed form over many periods.

    use physlab::scene::pendulum::exact::ExactPendulum;
    use physlab::scene::pendulum::periodic::{PeriodicExact, TARGET_THETA_ERROR, reduce};
    use physlab::scene::pendulum::{PendulumParams, theta0_from_degrees};

    fn start(degrees: f64) -> PendulumParams {
        let (theta0, theta0_low) = theta0_from_degrees(degrees);
        PendulumParams {
            theta0,
            theta0_low,
            ..PendulumParams::default()
        }
    }

    /// The exact n·dt mod T for doubles dt and T, by integer arithmetic on their mantissas
    /// (exponents within 30 of each other, n < 2⁴⁰), rounded once to a double.
    fn reduce_exactly(n: u64, dt: f64, period: f64) -> f64 {
        let split = |x: f64| {
            let bits = x.to_bits();
            let exp = ((bits >> 52) & 0x7ff) as i32;
            let mantissa = (bits & ((1 << 52) - 1)) | (1 << 52);
            (u128::from(mantissa), exp - 1075)
        };
        let ((md, ed), (mt, et)) = (split(dt), split(period));
        let e = ed.min(et);
        let a = (u128::from(n) * md) << (ed - e);
        let b = mt << (et - e);
        (a % b) as f64 * 2f64.powi(e)
    }

    /// The closed form at phase τ ∈ [0, T] mirrored into the first quarter period, as the
    /// table's nodes are (θ(T/2 ∓ s) = -θ(s), θ(T - s) = θ(s), ω following).
    fn closed_form_at_phase(exact: &ExactPendulum, tau: f64) -> (f64, f64) {
        let period = exact.period();
        let (half, quarter) = (0.5 * period, 0.25 * period);
        let (s, theta_sign, omega_sign) = if tau <= quarter {
            (tau, 1.0, 1.0)
        } else if tau <= half {
            (half - tau, -1.0, 1.0)
        } else if tau <= half + quarter {
            (tau - half, -1.0, -1.0)
        } else {
            (period - tau, 1.0, -1.0)
        };
        let (theta, omega) = exact.state(s);
        (theta_sign * theta, omega_sign * omega)
    }

    /// The phase is within 2 ulp(T) of the exact n·dt mod T, from the first steps to 10⁹ and
    /// beyond (measured: at most 1 ulp).
    #[test]
    fn reduction_is_exact_to_an_ulp_of_the_period() {
        let mut worst = 0.0f64;
        for (dt, period) in [
            (0.01, 4.012_345_678_9),
            (1e-3, 2.0),
            (0.03, 0.7),
            (0.25, 100.3),
        ] {
            let ulp = period * f64::EPSILON;
            for n in (0..40)
                .map(|k| 3u64.pow(k / 2) * (k as u64 % 7 + 1))
                .chain([1, 99_999_999, 100_000_000, 1 << 39])
            {
                let got = reduce(n, dt, period);
                let want = reduce_exactly(n, dt, period);
                let err = (got - want).abs() / ulp;
                worst = worst.max(err);
                assert!(err <= 2.0, "n {n} dt {dt} T {period}: {got} vs {want}");
            }
        }
        println!("reduction: worst {worst:.2} ulp(T)");
    }

    const DEGREES: [f64; 8] = [1e-3, 10.0, 60.0, 120.0, 170.0, 179.0, 179.9, 179.999];

    /// The table reaches 1e-14 rad from 0.001° to 179.999° (checked between the nodes at 10
    /// points per interval, i.e. 11 times the node density).
    #[test]
    fn verified_to_the_target_up_to_the_separatrix() {
        for d in DEGREES {
            let table = PeriodicExact::new(&start(d)).unwrap();
            println!(
                "{d:>8}°: T = {:.6} s, {} intervals, θ error {:.1e} rad, ω error {:.1e} rad/s",
                table.period(),
                table.intervals(),
                table.max_theta_error(),
                table.max_omega_error()
            );
            assert!(table.max_theta_error() <= TARGET_THETA_ERROR, "{d}°");
        }
    }

    /// Over many periods, against the closed form at the exactly reduced phase (independent of
    /// the table's own reduction; mirrored into the first quarter period as the table's nodes): within the verified error plus ω × 2 ulp(T); and against the
    /// closed form at the rounded time n·dt, within the closed form's own accuracy there.
    #[test]
    fn agrees_with_the_closed_form_over_many_periods() {
        let dt = 0.01;
        for d in DEGREES {
            let p = start(d);
            let (table, exact) = (
                PeriodicExact::new(&p).unwrap(),
                ExactPendulum::new(&p).unwrap(),
            );
            let omega_max = 2.0 * p.omega_n() * p.half_angle().0;
            let at_phase = table.max_theta_error() * 2.0
                + omega_max * 2.0 * f64::EPSILON * table.period()
                + f64::EPSILON;
            for n in (0..2000u64).map(|k| k * k * 251 + k) {
                let (th, w) = table.state_at_step(n, dt);
                let tau = reduce_exactly(n, dt, table.period());
                let (eth, ew) = closed_form_at_phase(&exact, tau);
                assert!((th - eth).abs() <= at_phase, "{d}° step {n}: {th} vs {eth}");
                assert!(
                    (w - ew).abs() <= 1e-3 * omega_max,
                    "{d}° step {n}: {w} vs {ew}"
                );
                let t = n as f64 * dt;
                let (cth, _) = exact.state(t);
                let tol = exact.theta_accuracy(t) + table.max_theta_error();
                assert!((th - cth).abs() <= tol, "{d}° t {t}: {th} vs {cth}");
            }
        }
    }

    /// Cost per evaluation: the table, the closed form, and one rk4 step of the pendulum, on
    /// 10⁷ steps of the default pendulum (`cargo test --release --test pendulum periodic_table -- --ignored
    /// --nocapture`).
    #[test]
    #[ignore = "timing, prints numbers"]
    fn cost_per_step() {
        use physlab::integrate::{Integrator, Method, MethodOptions};
        use physlab::scene::pendulum::Pendulum;
        use std::hint::black_box;
        use std::time::Instant;
        let (p, dt, steps) = (PendulumParams::default(), 0.01, 10_000_000u64);
        let per_step = |start: Instant| start.elapsed().as_secs_f64() * 1e9 / steps as f64;
        let build = Instant::now();
        let table = PeriodicExact::new(&p).unwrap();
        println!(
            "build: {:.2} ms ({} intervals)",
            build.elapsed().as_secs_f64() * 1e3,
            table.intervals()
        );
        let exact = ExactPendulum::new(&p).unwrap();
        let mut sum = 0.0;
        let t0 = Instant::now();
        for n in 0..steps {
            sum += table.state_at_step(black_box(n), dt).0;
        }
        let table_ns = per_step(t0);
        let t0 = Instant::now();
        for n in 0..steps {
            sum += reduce(black_box(n), dt, table.period());
        }
        println!("reduce only {:.1}", per_step(t0));
        let t0 = Instant::now();
        for n in 0..steps {
            sum += table.at_phase(black_box(n as f64 * 1e-7)).0;
        }
        println!("at_phase only {:.1}", per_step(t0));
        let t0 = Instant::now();
        for n in 0..steps {
            sum += exact.state(black_box(n) as f64 * dt).0;
        }
        let exact_ns = per_step(t0);
        let sys = Pendulum::new(&p);
        let mut it = Integrator::new(
            Method::Rk4,
            &sys,
            &[p.theta0],
            &[0.0],
            dt,
            MethodOptions::default(),
        );
        let t0 = Instant::now();
        for _ in 0..steps {
            it.step(black_box(&sys));
        }
        let rk4_ns = per_step(t0);
        black_box((sum, it.position()[0]));
        println!("ns per step: table {table_ns:.1}, closed form {exact_ns:.1}, rk4 {rk4_ns:.1}");
        // The build against the steps it takes to pay for itself, over the angles tested.
        let probe = 1_000_000u64;
        for d in DEGREES {
            let p = start(d);
            let build = Instant::now();
            let table = PeriodicExact::new(&p).unwrap();
            let build_ns = build.elapsed().as_secs_f64() * 1e9;
            let exact = ExactPendulum::new(&p).unwrap();
            let t0 = Instant::now();
            for n in 0..probe {
                sum += exact.state(black_box(n) as f64 * dt).0;
            }
            let exact_ns = t0.elapsed().as_secs_f64() * 1e9 / probe as f64;
            let t0 = Instant::now();
            for n in 0..probe {
                sum += table.state_at_step(black_box(n), dt).0;
            }
            let table_ns = t0.elapsed().as_secs_f64() * 1e9 / probe as f64;
            println!(
                "{d:>8}°: build {:.1} ms ({} intervals), table {table_ns:.1} ns, closed form \
                 {exact_ns:.1} ns, break-even {:.0} steps",
                build_ns * 1e-6,
                table.intervals(),
                build_ns / (exact_ns - table_ns)
            );
        }
        black_box(sum);
    }
}

mod long_run {
    //! A run past `TABULATE_ABOVE_STEPS` takes its exact lane from the table.

    use physlab::integrate::Method;
    use physlab::scene::harness::Scene;
    use physlab::scene::pendulum::exact::ExactPendulum;
    use physlab::scene::pendulum::periodic::PeriodicExact;
    use physlab::scene::pendulum::reference::TABULATE_ABOVE_STEPS;
    use physlab::scene::pendulum::run::{PendulumConfig, PendulumScene};
    use physlab::scene::pendulum::theta0_from_degrees;

    /// A run past the threshold takes the exact lane from the table: at every step of a stretch
    /// at its start and one at its end, θ and ω agree with the closed form
    /// ([`ExactPendulum::state`] at n·dt) within the table's verified error plus the closed
    /// form's own stated accuracy at that time; up to the threshold the lane is the closed form
    /// itself, bit for bit.
    #[test]
    fn a_long_run_takes_the_exact_lane_from_the_table_within_its_bound() {
        let dt = 0.01;
        for degrees in [60.0, 170.0, 179.9, -179.999] {
            let mut config = PendulumConfig {
                duration: 1e6,
                methods: vec![Method::Verlet],
                ..PendulumConfig::default()
            };
            (config.params.theta0, config.params.theta0_low) = theta0_from_degrees(degrees);
            let p = config.params;
            let exact = ExactPendulum::new(&p).unwrap();
            let table = PeriodicExact::new(&p).unwrap();
            // A phase error that moves θ by δ moves ω by at most ωn cos(θ0/2) δ (|θ''|max over
            // |ω|max); twice ωn covers that and the rest of the closed form's rounding.
            let omega_per_theta = 2.0 * p.omega_n();
            let mut worst = (0.0f64, 0.0f64);
            for (duration, tabulated) in [(1e6, true), (TABULATE_ABOVE_STEPS as f64 * dt, false)] {
                config.duration = duration;
                let mut scene = PendulumScene::new(config.clone());
                let total = scene.schedule().total;
                assert_eq!(total > TABULATE_ABOVE_STEPS, tabulated);
                assert_eq!(
                    scene
                        .reference_description()
                        .contains("table of one period"),
                    tabulated,
                    "{}",
                    scene.reference_description()
                );
                let (_, mut lane) = scene.lanes().swap_remove(0);
                assert!(lane.method.is_none());
                for first in [1, 200_001, total - 200_000 + 1] {
                    if first > total {
                        continue;
                    }
                    let mut block = first;
                    while block < first + 200_000 {
                        let len =
                            (scene.max_block() as usize).min((first + 200_000 - block) as usize);
                        scene.prepare(block, len);
                        scene.advance(&mut lane, block, len);
                        for j in 0..len {
                            let n = block + j as u64;
                            let t = n as f64 * dt;
                            let (th, w) = lane.state(j);
                            let (eth, ew) = exact.state(t);
                            if !tabulated {
                                assert_eq!(
                                    (th.to_bits(), w.to_bits()),
                                    (eth.to_bits(), ew.to_bits())
                                );
                                continue;
                            }
                            let theta_bound = table.max_theta_error() + exact.theta_accuracy(t);
                            let omega_bound =
                                table.max_omega_error() + omega_per_theta * exact.theta_accuracy(t);
                            worst.0 = worst.0.max((th - eth).abs() / theta_bound);
                            worst.1 = worst.1.max((w - ew).abs() / omega_bound);
                            assert!(
                                (th - eth).abs() <= theta_bound && (w - ew).abs() <= omega_bound,
                                "{degrees}° step {n}: ({th}, {w}) against ({eth}, {ew})"
                            );
                        }
                        block += len as u64;
                    }
                }
            }
            println!(
                "{degrees}°: worst θ at {:.2} of its bound, ω at {:.2}",
                worst.0, worst.1
            );
        }
    }
}

mod period_meter {
    //! The period meter on motions of known period.

    use physlab::scene::pendulum::period::PeriodMeter;

    #[test]
    fn harmonic_motion_period_is_recovered() {
        // θ = 0.5 sin(2π t / T) sampled coarsely (20 samples per period).
        let period = 3.7;
        let w = 2.0 * std::f64::consts::PI / period;
        let mut meter = PeriodMeter::new();
        let dt = period / 20.0 * 1.013;
        for n in 0..400 {
            let t = n as f64 * dt;
            meter.push(t, 0.5 * (w * t).sin(), 0.5 * w * (w * t).cos());
        }
        let measured = meter.period().unwrap();
        assert!((measured / period - 1.0).abs() < 1e-4, "{measured}");
    }

    #[test]
    fn rotation_counts_one_crossing_per_revolution() {
        // Uniform rotation θ = ω t, ω < 0: period 2π/|ω|.
        let w = -2.5;
        let mut meter = PeriodMeter::new();
        for n in 0..10_000 {
            let t = n as f64 * 1e-3;
            meter.push(t, w * t, w);
        }
        let expected = 2.0 * std::f64::consts::PI / w.abs();
        assert!((meter.period().unwrap() / expected - 1.0).abs() < 1e-12);
    }
}
