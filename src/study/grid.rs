//! The steps a convergence sweep gives each fixed-step method. The default grid (dt0 halved
//! `--levels` times) suits orders up to 4; a higher order reaches the floor within a level or
//! two of dt0, and its fit would have fewer than 2 rows. Such a method gets its own grid, chosen
//! from its order and the floor.

use super::{Problem, SAMPLE_EVERY, Sweep};
use crate::integrate::{Method, Stability, whole_steps};

/// One run of a fixed-step method: its step, its steps between compared samples, and how many
/// samples apart the comparisons are (1: at every sample).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    pub dt: f64,
    pub per: u64,
    pub every: usize,
}

impl Level {
    /// The level of step about `dt` that lands on the samples `sample_dt` apart: a whole number
    /// of steps per sample, or of samples per step.
    fn near(dt: f64, sample_dt: f64) -> Level {
        if dt <= sample_dt {
            let per = (sample_dt / dt).round() as u64;
            let dt = sample_dt / per as f64;
            Level { dt, per, every: 1 }
        } else {
            let every = (dt / sample_dt).round() as usize;
            let dt = sample_dt * every as f64;
            Level { dt, per: 1, every }
        }
    }
}

/// The default grid: dt0, dt0/2, ... over `--levels`, compared at every sample.
pub fn halving(s: &Sweep) -> Vec<Level> {
    // Steps of dt0 per sample (validated whole).
    let per = whole_steps(s.sample_dt, s.dt0).unwrap_or(SAMPLE_EVERY);
    (0..s.levels)
        .map(|k| Level {
            dt: s.dt0 / 2f64.powi(k as i32),
            per: per << k,
            every: 1,
        })
        .collect()
}

/// Errors within this factor of the floor are left to round-off and the reference.
const ABOVE_FLOOR: f64 = 10.0;
/// Errors above this [rad or m] are before the compositions' asymptotic range: on the default
/// pendulum yoshida6's neighbours give order 5.7 at 2e-6 and 5.95 at 3e-8.
const ASYMPTOTIC_BELOW: f64 = 1e-7;
/// Levels above `ABOVE_FLOOR` × the floor the default grid must give to be kept.
const USABLE: f64 = 3.0;
/// The largest step tried, as a fraction of the method's stability limit.
const STABLE_FRACTION: f64 = 0.9;

/// The levels of `method` in a convergence sweep of `problem` whose error floor is `floor`; `error`
/// measures one level (`None`: diverged or stopped). The default grid is kept when its coarsest
/// error leaves [`USABLE`] levels above ten times the floor (each halving divides the error by 2^p
/// at order p). Otherwise the step is doubled from dt0 (within the stability limit) until the error
/// stands that far above the floor; from there e(h) = e·(h/dt)^p places the coarsest level where it
/// predicts [`ASYMPTOTIC_BELOW`] and the finest where it predicts ten times the floor, the levels
/// between evenly spaced in log h. Steps are whole fractions of a common interval of `every`
/// samples, compared at its ends, so that every level of a method is measured at the same times.
pub fn by_order(
    method: Method,
    problem: &Problem,
    s: &Sweep,
    floor: f64,
    mut error: impl FnMut(Level) -> Option<f64>,
) -> Vec<Level> {
    let default = halving(s);
    let p = f64::from(method.info().order_for(problem.velocity_dependent()));
    let low = ABOVE_FLOOR * floor;
    let Some(mut e) = error(default[0]).filter(|&e| e < low * 2f64.powf(p * (USABLE - 1.0))) else {
        return default;
    };
    let sample_dt = s.sample_dt;
    let samples = (s.duration / sample_dt).round().max(1.0);
    let cap = match method.info().stability {
        Stability::Below(h) => STABLE_FRACTION * h / problem.omega(),
        _ => f64::INFINITY,
    }
    .min(s.duration / 2.0);
    let mut dt = s.dt0;
    while e < low && 2.0 * dt <= cap {
        let coarser = Level::near(2.0 * dt, sample_dt);
        let Some(next) = error(coarser) else {
            break;
        };
        (dt, e) = (coarser.dt, next);
    }
    let at = |target: f64| dt * (target / e).powf(1.0 / p);
    let top = at(ASYMPTOTIC_BELOW).min(cap);
    let bottom = at(low).min(top / 2.0);
    let levels = s.levels.max(2) as i32;
    let ratio = (top / bottom).powf(1.0 / f64::from(levels - 1));
    // Steps per interval at the coarsest level: enough that the next level is a whole step more.
    let n0 = (1.0 / (ratio - 1.0)).ceil().max(1.0);
    let every = (n0 * top / sample_dt)
        .ceil()
        .clamp(1.0, (samples / 2.0).floor().max(1.0));
    let interval = every * sample_dt;
    let mut grid: Vec<Level> = Vec::new();
    for k in 0..levels {
        let mut per = (interval * ratio.powi(k) / top).round().max(1.0) as u64;
        if let Some(last) = grid.last() {
            per = per.max(last.per + 1);
        }
        let (dt, every) = (interval / per as f64, every as usize);
        grid.push(Level { dt, per, every });
    }
    grid
}
