//! Long-time behaviour on the pendulum: how each method's energy error and phase error grow
//! over many periods. For an integrable system, a symplectic method keeps its energy error
//! bounded and its phase error grows linearly in time (a constant error of the period); a
//! non-symplectic one lets the energy drift linearly, the period with it, and the phase error
//! grows quadratically (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, ch. IX–X).
//!
//! Every step is taken and looked at: the energy error of each step, and the time of every
//! upward zero crossing of θ, found between two steps on the cubic that matches θ and ω at
//! both (error O(dt⁴) of the crossing time, far below the phase errors measured). The exact
//! crossings are those of the closed form, a period T apart.

use super::orders::fit;
use crate::integrate::{Integrator, Method, MethodOptions};
use crate::scene::pendulum::exact::ExactPendulum;
use crate::scene::pendulum::{Pendulum, PendulumParams};
use crate::scene::rope::{Rope, RopeParams};

/// The step the study runs the pendulum at unless told otherwise [s].
pub const DEFAULT_DT: f64 = 0.01;

/// The rope's step and simulated time unless told otherwise [s]: 10⁷ steps of the study's
/// soft rope (ω_max·dt ≈ 0.06).
pub const ROPE_DT: f64 = 1e-3;
pub const ROPE_DURATION: f64 = 1e4;

/// The periods it runs for unless told otherwise: long enough that over the last two decades
/// the quadratic phase term of the non-symplectic methods has overtaken their linear one.
pub const DEFAULT_PERIODS: f64 = 1e5;

/// The methods it runs unless told otherwise: the fixed-step ones of order 4 or less (the
/// adaptive ones' growth depends on their tolerance, and the higher orders' energy error is
/// round-off at the default step; name them to see it), of those `problem` accepts.
pub fn default_methods(problem: &super::Problem) -> Vec<Method> {
    (problem.methods().into_iter())
        .filter(|m| !m.info().adaptive() && m.info().order <= 4)
        .collect()
}

/// How many checkpoints per decade of simulated time the growth is sampled at.
pub const PER_DECADE: usize = 10;

/// The exponents are fitted over the run's last stretch, from its end over this factor.
pub const FIT_SPAN: f64 = 100.0;

/// The errors over the stretch of the run that ends at `t`.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// Simulated time [s].
    pub t: f64,
    /// Largest |E − E0| / E0 over the steps since the previous checkpoint.
    pub energy: f64,
    /// |phase error| [rad] at the last upward crossing of θ = 0 before `t`, 2π times its
    /// time's offset from the exact crossing over the period; `None` before the first.
    pub phase: Option<f64>,
}

/// One method's long run.
#[derive(Clone, Debug, PartialEq)]
pub struct Drift {
    pub method: Method,
    pub dt: f64,
    /// The simulated time asked for [s].
    pub duration: f64,
    pub checkpoints: Vec<Checkpoint>,
    pub steps: u64,
    pub evals: u64,
    /// The time from which the run stopped being a libration (non-finite, over the top, or
    /// the crossings lost), if it did; the checkpoints end there.
    pub lost_at: Option<f64>,
    /// The rope's shortest spring over the run, over its rest length: where a spring folds
    /// through zero length its potential k(ℓ − ℓ0)²/2 is not smooth, and the theory of bounded
    /// energy error (backward error analysis) needs a smooth one.
    pub shortest_spring: Option<f64>,
    /// Whether dissipative forces act (the damped rope): its energy error is then the balance
    /// error |E + W − E0|, the dissipated work W integrated with the state.
    pub damped: bool,
}

/// What the theory says an error grows like, t^exponent, for a method on an integrable system;
/// `damped`: the balance error on a damped system, which every method that stays stable leaves
/// bounded (exponent 0): its local errors shrink with the motion, which decays to rest, after
/// which nothing is added to it.
pub fn theory(method: Method, damped: bool) -> (Option<f64>, Option<f64>) {
    match method {
        _ if damped => (Some(0.0), None),
        // Explicit Euler's energy grows geometrically, implicit Euler's decays to rest: no
        // power law.
        Method::ExplicitEuler | Method::ImplicitEuler => (None, None),
        _ if method.info().symplectic => (Some(0.0), Some(1.0)),
        _ => (Some(1.0), Some(2.0)),
    }
}

/// The least-squares exponent of error against time over the last two decades of the run
/// (`None` with fewer than three usable checkpoints): the early decades hold the transient
/// and, for non-symplectic methods, the linear phase term the quadratic one overtakes.
pub fn exponent(points: &[(f64, f64)]) -> Option<f64> {
    let end = points.last()?.0;
    let used: Vec<(f64, f64)> = points
        .iter()
        .filter(|(t, e)| *t >= end / FIT_SPAN && *e > 0.0 && e.is_finite())
        .map(|(t, e)| (t.ln(), e.ln()))
        .collect();
    if used.len() < 3 {
        return None;
    }
    fit(&used).0
}

/// The time of the root of the cubic through (0, a0) and (h, a1) with slopes s0 and s1, in
/// [0, h], where a0 < 0 ≤ a1: a few Newton steps from the secant's root, kept in the bracket.
fn crossing(a0: f64, s0: f64, a1: f64, s1: f64, h: f64) -> f64 {
    let value = |u: f64| {
        // Hermite basis on u ∈ [0, 1].
        let (u2, u3) = (u * u, u * u * u);
        let (h00, h10, h01, h11) = (
            2.0 * u3 - 3.0 * u2 + 1.0,
            u3 - 2.0 * u2 + u,
            -2.0 * u3 + 3.0 * u2,
            u3 - u2,
        );
        let slope = (6.0 * u2 - 6.0 * u) * a0
            + (3.0 * u2 - 4.0 * u + 1.0) * h * s0
            + (-6.0 * u2 + 6.0 * u) * a1
            + (3.0 * u2 - 2.0 * u) * h * s1;
        (h00 * a0 + h10 * h * s0 + h01 * a1 + h11 * h * s1, slope)
    };
    let mut u = a0 / (a0 - a1);
    for _ in 0..4 {
        let (f, df) = value(u);
        if df == 0.0 {
            break;
        }
        u = (u - f / df).clamp(0.0, 1.0);
    }
    u * h
}

/// Runs `method` on the pendulum released from rest at θ0 (|θ0| < 180°) for `duration` [s]
/// at step `dt`; `None` when the start has no closed form.
pub fn pendulum_drift(
    p: &PendulumParams,
    method: Method,
    dt: f64,
    duration: f64,
    options: MethodOptions,
) -> Option<Drift> {
    let exact = ExactPendulum::new(p)?;
    let period = exact.period();
    // Released at θ0 > 0 the pendulum first swings down through zero at T/4 and up at 3T/4;
    // released at θ0 < 0, up at T/4.
    let first_up = if p.theta0 > 0.0 { 0.75 } else { 0.25 } * period;
    let sys = Pendulum::new(p);
    let e0 = p.initial_energy();
    let mut it = Integrator::new(method, &sys, &[p.theta0], &[p.omega0], dt, options);
    let steps = (duration / dt).round() as u64;
    let mut points = Points::new(steps, dt, period);
    let (mut phase, mut crossings) = (None, 0u64);
    let (mut theta, mut omega) = (p.theta0, p.omega0);
    let mut lost_at = None;
    for n in 1..=steps {
        it.step(&sys);
        let (th, om) = (it.position()[0], it.velocity()[0]);
        let t = n as f64 * dt;
        let error = ((p.energy(th, om) - e0) / e0).abs();
        // Over the top (or not finite): the motion is no libration any more and its crossings
        // are not the exact ones'.
        if th.is_nan() || th.abs() >= std::f64::consts::PI || !error.is_finite() {
            lost_at = Some(t);
            break;
        }
        if theta < 0.0 && th >= 0.0 {
            let at = t - dt + crossing(theta, omega, th, om, dt);
            let expected = first_up + crossings as f64 * period;
            phase = Some(std::f64::consts::TAU * (at - expected).abs() / period);
            crossings += 1;
        }
        (theta, omega) = (th, om);
        points.note(n, error, phase);
        if n % 4096 == 0 && crate::interrupt::requested() {
            break;
        }
    }
    Some(Drift {
        method,
        dt,
        duration,
        checkpoints: points.done,
        steps: it.accepted_steps(),
        evals: it.evals(),
        lost_at,
        shortest_spring: None,
        damped: false,
    })
}

/// Runs `method` on the rope from its start for `duration` [s] at step `dt`: the energy error
/// over the run's energy scale, |E − E0| undamped and the balance error |E + W − E0| damped (W
/// the dissipated work integrated with the state: [`Rope::balanced`]), no phase (no closed form
/// gives the rope's). The rope is not integrable, but backward error analysis bounds a
/// symplectic method's energy error on any Hamiltonian system all the same.
pub fn rope_drift(
    p: &RopeParams,
    method: Method,
    dt: f64,
    duration: f64,
    options: MethodOptions,
) -> Drift {
    let rope = Rope::balanced(p.clone());
    let (x0, v0) = rope.start();
    let scale = crate::scene::rope::run::energy_scale(&rope, &x0, &v0);
    let e0 = rope.energy(&x0, &v0);
    let mut it = Integrator::new(method, &rope, &x0, &v0, dt, options);
    let steps = (duration / dt).round() as u64;
    // Checkpoints from one second on: the rope's slowest swing takes a few.
    let mut points = Points::new(steps, dt, 1.0);
    let mut lost_at = None;
    let mut shortest = f64::INFINITY;
    let every = (4096 / p.nodes).max(1) as u64;
    for n in 1..=steps {
        it.step(&rope);
        if n % 4096 == 0 {
            it.zero_below(crate::scene::rope::run::NEGLIGIBLE);
        }
        let (x, v) = (it.position(), it.velocity());
        let error = (rope.energy(x, v) + rope.work(v) - e0).abs() / scale;
        // Diverged: the energy error beyond the scene's own bound.
        if !error.is_finite() || error > crate::scene::rope::run::ENERGY_GAIN_BOUND {
            lost_at = Some(n as f64 * dt);
            break;
        }
        for i in 0..p.nodes - 1 {
            let d = crate::scene::rope::node(x, i + 1) - crate::scene::rope::node(x, i);
            shortest = shortest.min(d.length() / rope.rest());
        }
        points.note(n, error, None);
        if n % every == 0 && crate::interrupt::requested() {
            break;
        }
    }
    Drift {
        method,
        dt,
        duration,
        checkpoints: points.done,
        steps: it.accepted_steps(),
        evals: it.evals(),
        lost_at,
        shortest_spring: Some(shortest),
        damped: rope.tracks_work(),
    }
}

/// A run's checkpoints as its steps come: the largest energy error since the last one, and
/// the phase error last measured.
struct Points {
    dt: f64,
    /// The steps they fall on ([`checkpoint_steps`]), and the next one's index.
    marks: Vec<u64>,
    next: usize,
    energy_max: f64,
    done: Vec<Checkpoint>,
}

impl Points {
    fn new(steps: u64, dt: f64, first: f64) -> Self {
        let marks = checkpoint_steps(steps, dt, first);
        Points {
            dt,
            done: Vec::with_capacity(marks.len()),
            marks,
            next: 0,
            energy_max: 0.0,
        }
    }

    /// Step `n` had this energy error; the phase error is the last measured.
    fn note(&mut self, n: u64, energy: f64, phase: Option<f64>) {
        self.energy_max = self.energy_max.max(energy);
        if self.marks.get(self.next) == Some(&n) {
            self.done.push(Checkpoint {
                t: n as f64 * self.dt,
                energy: self.energy_max,
                phase,
            });
            self.energy_max = 0.0;
            self.next += 1;
        }
    }
}

/// The steps the checkpoints fall on: [`PER_DECADE`] a decade of simulated time, log-spaced
/// from `first` [s] (one period) to the end, and the last step.
fn checkpoint_steps(steps: u64, dt: f64, first: f64) -> Vec<u64> {
    let end = steps as f64 * dt;
    let mut marks: Vec<u64> = Vec::new();
    let mut k = 0;
    loop {
        let t = first * 10f64.powf(k as f64 / PER_DECADE as f64);
        if t >= end {
            break;
        }
        let n = (t / dt).round() as u64;
        if marks.last() != Some(&n) && n > 0 {
            marks.push(n);
        }
        k += 1;
    }
    marks.push(steps);
    marks
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crossing of a cubic is found to round-off: the cubic through two points of
    /// sin(t − 0.3) with its slopes, on a step of 0.05, against 0.3 less the cubic's own
    /// interpolation error (below 1e-8 at this step).
    #[test]
    fn a_crossing_is_found_between_two_steps() {
        let (t0, h) = (0.28, 0.05);
        let f = |t: f64| (t - 0.3).sin();
        let g = |t: f64| (t - 0.3).cos();
        let at = t0 + crossing(f(t0), g(t0), f(t0 + h), g(t0 + h), h);
        assert!((at - 0.3).abs() < 1e-8, "{at}");
    }

    /// A power law's exponent is recovered from checkpoints; so is a bounded error's 0.
    #[test]
    fn exponents_of_power_laws() {
        let points = |p: f64| -> Vec<(f64, f64)> {
            (0..40)
                .map(|k| {
                    let t = 10f64.powf(k as f64 / 10.0);
                    (t, 3e-7 * t.powf(p))
                })
                .collect()
        };
        for p in [0.0, 0.5, 1.0, 2.0] {
            let e = exponent(&points(p)).unwrap();
            assert!((e - p).abs() < 1e-9, "{p}: {e}");
        }
    }
}
