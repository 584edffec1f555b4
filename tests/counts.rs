//! Evaluation counts against what the methods compute: for every method,
//! `Integrator::evals()` is the number of force evaluations actually made, counted where they
//! happen, and `Integrator::jacobian_evals()` the number of Jacobian evaluations.

use std::cell::Cell;

use physlab::integrate::{
    EvalsPerStep, ImplicitSolve, Integrator, Method, MethodOptions, SecondOrderSystem,
    scalar_backward_euler,
};
use physlab::scene::pendulum::{NEWTON_MAX_ITERATIONS, NEWTON_TOL, Pendulum, PendulumParams};
use physlab::scene::rope::{Rope, RopeParams};

/// Any system, with its `acceleration` calls counted. Its implicit step is the inner system's,
/// which does not go through `acceleration`: implicit Euler is counted by the systems below.
struct Counting<S> {
    inner: S,
    calls: Cell<u64>,
}

impl<S: SecondOrderSystem> SecondOrderSystem for Counting<S> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn acceleration(&self, x: &[f64], v: &[f64], a: &mut [f64]) {
        self.calls.set(self.calls.get() + 1);
        self.inner.acceleration(x, v, a);
    }
    fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve {
        self.inner.implicit_euler_step(x, v, dt)
    }
}

/// The pendulum θ'' = -(g/L) sin θ with every sin and cos counted, in its acceleration and in its
/// implicit step, which is the pendulum's own Newton scheme (`scalar_backward_euler`, same
/// arithmetic, same tolerance). A force evaluation is one sin, a Jacobian evaluation one cos.
struct CountingPendulum {
    g_over_l: f64,
    sin: Cell<u64>,
    cos: Cell<u64>,
}

impl CountingPendulum {
    fn new(p: &PendulumParams) -> Self {
        CountingPendulum {
            g_over_l: p.gravity / p.length,
            sin: Cell::new(0),
            cos: Cell::new(0),
        }
    }
    fn sin(&self, t: f64) -> f64 {
        self.sin.set(self.sin.get() + 1);
        t.sin()
    }
    fn sin_cos(&self, t: f64) -> (f64, f64) {
        self.cos.set(self.cos.get() + 1);
        (self.sin(t), t.cos())
    }
}

impl SecondOrderSystem for CountingPendulum {
    fn dim(&self) -> usize {
        1
    }
    fn acceleration(&self, x: &[f64], _v: &[f64], a: &mut [f64]) {
        a[0] = -self.g_over_l * self.sin(x[0]);
    }
    fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve {
        let c = self.g_over_l;
        let (theta, omega, solve) = scalar_backward_euler(
            x[0],
            v[0],
            dt,
            NEWTON_TOL,
            NEWTON_MAX_ITERATIONS,
            |t| -(dt * c * self.sin(t)),
            |t| {
                let (s, co) = self.sin_cos(t);
                (-(dt * c * s), -(dt * dt * c * co))
            },
        );
        x[0] = theta;
        v[0] = omega;
        solve
    }
}

fn options() -> MethodOptions {
    MethodOptions::default()
}

/// The default rope, damped (forces depend on v), has every explicit method's evaluations
/// counted as `acceleration` calls, including Verlet's start and dopri5's rejected substeps.
#[test]
fn every_explicit_method_counts_its_acceleration_calls_on_the_rope() {
    let params = RopeParams::default();
    let x0 = params.initial_positions();
    let v0 = vec![0.0; x0.len()];
    for m in Method::ALL {
        if m == Method::ImplicitEuler {
            continue;
        }
        let sys = Counting {
            inner: Rope::new(params.clone()),
            calls: Cell::new(0),
        };
        // dopri5 at a coarse dt with a tight tolerance, so that it rejects substeps too.
        let (dt, opts) = if m == Method::Dopri5 {
            (
                0.01,
                MethodOptions {
                    rtol: 1e-9,
                    ..options()
                },
            )
        } else {
            (1e-4, options())
        };
        let mut it = Integrator::new(m, &sys, &x0, &v0, dt, opts);
        for _ in 0..300 {
            it.step(&sys);
        }
        assert_eq!(it.evals(), sys.calls.get(), "{m}");
        assert_eq!(it.jacobian_evals(), 0, "{m}");
        match m.info().evals_per_step {
            EvalsPerStep::Fixed(k) => {
                let start = u64::from(m == Method::Verlet);
                assert_eq!(it.evals(), 300 * u64::from(k) + start, "{m}");
            }
            // The registry's substep costs against the calls counted: exact without dense
            // output, and at most one dense build per accepted substep with it.
            EvalsPerStep::Adaptive(e) => {
                let (accepted, rejected) = (it.accepted_steps(), it.rejected_steps());
                let stepping = u64::from(e.first)
                    + accepted * u64::from(e.accepted)
                    + rejected * u64::from(e.rejected);
                let dense = it.evals() - stepping.min(it.evals());
                assert!(it.evals() >= stepping, "{m}: {} < {stepping}", it.evals());
                assert!(
                    dense <= accepted * u64::from(e.dense),
                    "{m}: {dense} dense evals"
                );
                assert_eq!(
                    dense % u64::from(e.dense.max(1)),
                    0,
                    "{m}: {dense} dense evals"
                );
                if m == Method::Dopri5 {
                    assert!(
                        rejected > 0,
                        "the tight tolerance makes dopri5 reject substeps"
                    );
                }
            }
            EvalsPerStep::NewtonIterations => {}
        }
    }
}

/// On the pendulum every method's evaluations are its sin calls, implicit Euler's included
/// (its explicit-Euler guess and one per Newton iteration), and its Jacobian evaluations are
/// its cos calls. The real `Pendulum` steps in lockstep with the counting one: bit-identical
/// states and the same reported counts, so the counts hold for the scene's pendulum too.
#[test]
fn every_method_counts_its_sin_and_cos_calls_on_the_pendulum() {
    let p = PendulumParams::default();
    let real = Pendulum::new(&p);
    // The scene's defaults: dt = 0.01 s for 20 s.
    let (dt, steps) = (0.01, 2000);
    for m in Method::ALL {
        let counted = CountingPendulum::new(&p);
        let mut a = Integrator::new(m, &counted, &[p.theta0], &[p.omega0], dt, options());
        let mut b = Integrator::new(m, &real, &[p.theta0], &[p.omega0], dt, options());
        let mut iterations = 0;
        for k in 0..steps {
            let solve = a.step(&counted);
            b.step(&real);
            if let Some(s) = solve {
                iterations += u64::from(s.jacobian_evals);
            }
            assert_eq!(a.position(), b.position(), "{m} at step {k}");
            assert_eq!(a.velocity(), b.velocity(), "{m} at step {k}");
        }
        assert_eq!(
            a.evals(),
            counted.sin.get(),
            "{m}: evaluations vs sin calls"
        );
        assert_eq!(
            a.jacobian_evals(),
            counted.cos.get(),
            "{m}: Jacobians vs cos calls"
        );
        assert_eq!(b.evals(), a.evals(), "{m}: the scene's pendulum");
        assert_eq!(b.jacobian_evals(), a.jacobian_evals(), "{m}");
        if m == Method::ImplicitEuler {
            // The guess and every iteration evaluate the force: 2000 steps of two Newton
            // iterations each make 6000 sin and 4000 cos calls.
            assert_eq!(a.evals(), steps + iterations);
            assert!(iterations >= 2 * steps, "{iterations} iterations");
        }
    }
}

/// `scalar_backward_euler` reports the closure calls it made, whatever the iteration count.
#[test]
fn scalar_newton_reports_the_calls_it_makes() {
    for max_iterations in [1, 2, 3, 50] {
        let (kicks, slopes) = (Cell::new(0u32), Cell::new(0u32));
        let (_, _, solve) = scalar_backward_euler(
            2.0,
            0.5,
            0.3,
            1e-15,
            max_iterations,
            |x| {
                kicks.set(kicks.get() + 1);
                -0.3 * 4.0 * x.sin()
            },
            |x| {
                slopes.set(slopes.get() + 1);
                (-0.3 * 4.0 * x.sin(), -0.09 * 4.0 * x.cos())
            },
        );
        assert_eq!(solve.evals, kicks.get() + slopes.get(), "{solve:?}");
        assert_eq!(solve.jacobian_evals, slopes.get(), "{solve:?}");
        assert!(solve.jacobian_evals <= max_iterations);
    }
}

/// The rope's implicit step reports as many force and Jacobian evaluations as Newton
/// iterations it ran, checked independently of its own counter: capped at the reported count
/// the step is reproduced to the bit, capped one lower it is not (so the count is neither too
/// high nor too low).
#[test]
fn rope_implicit_step_counts_its_newton_iterations() {
    let base = RopeParams::default();
    let x0 = base.initial_positions();
    let v0 = vec![0.0; x0.len()];
    let rope_with = |iterations: u32| {
        Rope::new(RopeParams {
            newton_iterations: iterations,
            ..base.clone()
        })
    };
    // A moving, stretched state: a few steps in.
    let mut it = Integrator::new(Method::Rk4, &rope_with(1), &x0, &v0, 1e-3, options());
    for _ in 0..50 {
        it.step(&rope_with(1));
    }
    let (x, v) = (it.position().to_vec(), it.velocity().to_vec());
    for h in [1e-3, 1e-2, 0.1] {
        let step = |iterations: u32| {
            let (mut x1, mut v1) = (x.clone(), v.clone());
            let solve = rope_with(iterations).implicit_euler_step(&mut x1, &mut v1, h);
            (x1, v1, solve)
        };
        let (x20, v20, solve) = step(20);
        let n = solve.evals;
        assert!(solve.converged && n >= 2, "dt {h}: {solve:?}");
        assert_eq!(solve.jacobian_evals, n, "dt {h}");
        let (xn, vn, _) = step(n);
        assert!(
            xn == x20 && vn == v20,
            "dt {h}: {n} iterations do not reproduce the step"
        );
        let (xl, vl, _) = step(n - 1);
        assert!(
            xl != x20 || vl != v20,
            "dt {h}: {} iterations already do",
            n - 1
        );
        // One iteration is the linearised step: one force and one Jacobian evaluation.
        let (_, _, one) = step(1);
        assert_eq!((one.evals, one.jacobian_evals), (1, 1), "dt {h}");
    }
    // Through the integrator, the counts add up over steps.
    let rope = rope_with(20);
    let mut it = Integrator::new(Method::ImplicitEuler, &rope, &x0, &v0, 1e-2, options());
    let (mut evals, mut jacobians) = (0, 0);
    for _ in 0..100 {
        let s = it.step(&rope).unwrap();
        evals += u64::from(s.evals);
        jacobians += u64::from(s.jacobian_evals);
    }
    assert_eq!((it.evals(), it.jacobian_evals()), (evals, jacobians));
    assert!(evals > 100, "Newton iterates more than once: {evals}");
}
