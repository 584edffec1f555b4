//! Round-off over long runs: how a method's energy error grows with the number of steps where
//! its truncation error is below round-off, with and without compensated summation.

use super::{fit, steps};
use crate::integrate::{Integrator, Method, MethodOptions};
use crate::scene::pendulum::{Pendulum, PendulumParams};

/// The RMS over `starts` pendulums released from rest at θ0 + k·`spread` (k = 0, 1, …) of the
/// relative energy error |E - E0|/E0 after each of `checkpoints` steps (ascending). After a stop
/// request, the checkpoints every start completed.
pub fn energy_error_rms(
    params: &PendulumParams,
    method: Method,
    dt: f64,
    options: MethodOptions,
    starts: u32,
    spread: f64,
    checkpoints: &[u64],
) -> Vec<f64> {
    let runs: Vec<(PendulumParams, Pendulum)> = (0..starts)
        .map(|k| {
            let p = PendulumParams {
                theta0: params.theta0 + f64::from(k) * spread,
                omega0: 0.0,
                ..*params
            };
            (p, Pendulum::new(&p))
        })
        .collect();
    let mut its: Vec<Integrator> = runs
        .iter()
        .map(|(p, sys)| Integrator::new(method, sys, &[p.theta0], &[0.0], dt, options))
        .collect();
    let mut rms = Vec::new();
    let mut done = 0;
    for &n in checkpoints {
        let mut sum = 0.0;
        for ((p, sys), it) in runs.iter().zip(&mut its) {
            if !steps(it, sys, n - done) {
                return rms;
            }
            let e0 = p.initial_energy();
            let e = p.energy(it.position()[0], it.velocity()[0]);
            sum += ((e - e0) / e0).powi(2);
        }
        done = n;
        rms.push((sum / f64::from(starts)).sqrt());
    }
    rms
}

/// The least-squares exponent of `values` against `ns` (log-log): how they grow with n.
pub fn growth_exponent(ns: &[u64], values: &[f64]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = ns
        .iter()
        .zip(values)
        .map(|(&n, &v)| ((n as f64).ln(), v.ln()))
        .collect();
    fit(&pts).0
}
