//! The pendulum's reference solutions: the closed form ([`super::exact`]) for a release from rest
//! with |θ0| < 180°, from its table of one period for long runs, and a converged fine-step
//! solution for every other start.

use super::PendulumParams;
use super::exact::ExactPendulum;
use super::exact::closed_form_text;
use super::periodic::PeriodicExact;

/// RK4 on the pendulum with the state kept as compensated (Kahan) sums: each step's increment
/// is added with the rounding of the previous additions carried along, so the round-off of
/// θ and ω stays near one ulp over millions of steps instead of growing with their number.
/// Without it the fine run's round-off, amplified by the motion (over the top, near the
/// separatrix), grows past its truncation error, which the comparison of two step sizes
/// does not see.
#[derive(Clone, Debug)]
struct CompensatedRk4 {
    g_over_l: f64,
    h: f64,
    theta: (f64, f64),
    omega: (f64, f64),
}

impl CompensatedRk4 {
    fn new(p: &PendulumParams, h: f64) -> Self {
        CompensatedRk4 {
            g_over_l: p.gravity / p.length,
            h,
            theta: (p.theta0, 0.0),
            omega: (p.omega0, 0.0),
        }
    }

    fn step(&mut self) {
        let (c, h) = (self.g_over_l, self.h);
        let (x, v) = (self.theta.0, self.omega.0);
        let a = |x: f64| -c * x.sin();
        let (k1x, k1v) = (v, a(x));
        let (k2x, k2v) = (v + 0.5 * h * k1v, a(x + 0.5 * h * k1x));
        let (k3x, k3v) = (v + 0.5 * h * k2v, a(x + 0.5 * h * k2x));
        let (k4x, k4v) = (v + h * k3v, a(x + h * k3x));
        let add = |(sum, carry): (f64, f64), increment: f64| {
            let y = increment - carry;
            let t = sum + y;
            (t, (t - sum) - y)
        };
        self.theta = add(self.theta, h / 6.0 * (k1x + 2.0 * (k2x + k3x) + k4x));
        self.omega = add(self.omega, h / 6.0 * (k1v + 2.0 * (k2v + k3v) + k4v));
    }

    /// (θ, ω), their carries folded in.
    fn state(&self) -> (f64, f64) {
        (self.theta.0 - self.theta.1, self.omega.0 - self.omega.1)
    }
}

/// A fine-step RK4 solution for starts the closed form does not cover, run at h and h/2: the
/// finer one is used, their difference estimates its error ([`FineStepReference::error_estimate`]),
/// and both keep compensated sums ([`CompensatedRk4`]) so that what is left of it is truncation.
#[derive(Clone, Debug)]
pub struct FineStepReference {
    fine: CompensatedRk4,
    coarse: CompensatedRk4,
    substeps: u64,
    max_difference: f64,
    /// Largest |θ| so far [rad] (over the top it grows without bound), which sets the state's
    /// own rounding.
    max_theta: f64,
    step: u64,
}

/// Fine steps are chosen so that (fastest rate) × h ≤ this; RK4's error then sits near 1e-10
/// over tens of periods, far below what the methods under test reach.
const FINE_STEP_RATE_TIMES_H: f64 = 2e-3;

impl FineStepReference {
    /// RK4 substeps per sample step `dt`: (fastest rate) × h ≤ [`FINE_STEP_RATE_TIMES_H`], the
    /// fastest rate being the small-angle frequency or the largest |ω| the energy allows. Each
    /// substep costs three RK4 steps (one at h, two at h/2).
    pub fn substeps(p: &PendulumParams, dt: f64) -> f64 {
        let rate = p
            .omega_n()
            .max((2.0 * p.initial_energy()).sqrt() / p.length);
        (rate * dt / FINE_STEP_RATE_TIMES_H).ceil().max(1.0)
    }

    /// A reference sampled every `dt`, stepped with RK4 at dt / substeps and dt / (2 substeps).
    pub fn new(p: &PendulumParams, dt: f64) -> Self {
        let substeps = (Self::substeps(p, dt) as u64).max(1);
        let h = dt / substeps as f64;
        FineStepReference {
            coarse: CompensatedRk4::new(p, h),
            fine: CompensatedRk4::new(p, 0.5 * h),
            substeps,
            max_difference: 0.0,
            max_theta: p.theta0.abs(),
            step: 0,
        }
    }

    /// Advances to the next sample time (one outer step dt) and returns (θ, ω) there. A stop
    /// request ([`crate::interrupt::requested`], looked at every 2¹⁶ substeps, well under a
    /// millisecond) ends it early; the caller then discards the sample.
    pub fn advance(&mut self) -> (f64, f64) {
        for k in 0..self.substeps {
            if k % 65_536 == 65_535 && crate::interrupt::requested() {
                break;
            }
            self.coarse.step();
            self.fine.step();
            self.fine.step();
        }
        self.step += 1;
        let (fine, coarse) = (self.fine.state(), self.coarse.state());
        self.max_difference = self.max_difference.max((fine.0 - coarse.0).abs());
        self.max_theta = self.max_theta.max(fine.0.abs());
        fine
    }

    /// Estimated largest error of θ so far [rad]: the h/2 run's error is the difference
    /// between the runs / (2⁴ - 1) for a fourth-order method, taken twice (the largest
    /// difference and the largest error need not fall on the same sample, and the ratio is 2⁴
    /// only in the limit), plus 4 ulps of the largest |θ| for the state's own rounding. Measured
    /// against mpmath over whole runs with ω0 ≠ 0 (`tests/pendulum.rs`): 1.9 to 5.8 times
    /// the true error.
    pub fn error_estimate(&self) -> f64 {
        2.0 * self.max_difference / 15.0 + 4.0 * f64::EPSILON * self.max_theta
    }
}

/// Runs of more than this many steps evaluate the closed form from its verified table of one
/// period ([`PeriodicExact`]), shorter ones call it directly (so default runs keep its values bit
/// for bit): the table's build pays for itself within 10⁵ steps from 0.001° to 179.999°
/// (`periodic.rs` `cost_per_step`), so 10⁶ leaves it a tenth of such a run at most.
pub const TABULATE_ABOVE_STEPS: u64 = 1_000_000;

/// The reference a run compares against.
#[derive(Clone, Debug)]
pub enum Reference {
    Exact(ExactPendulum),
    /// The closed form evaluated from its table of one period.
    Tabulated(ExactPendulum, Box<PeriodicExact>),
    FineStep(Box<FineStepReference>),
}

impl Reference {
    /// The closed form where it applies (from its table for runs of more than
    /// [`TABULATE_ABOVE_STEPS`] steps), otherwise the fine-step solution sampled every `dt`.
    pub fn for_start(p: &PendulumParams, dt: f64, steps: u64) -> Self {
        match ExactPendulum::new(p) {
            Some(e) if steps > TABULATE_ABOVE_STEPS => PeriodicExact::new(p)
                .map_or(Reference::Exact(e), |t| {
                    Reference::Tabulated(e, Box::new(t))
                }),
            Some(e) => Reference::Exact(e),
            None => Reference::FineStep(Box::new(FineStepReference::new(p, dt))),
        }
    }

    /// Its lane name in tables and recordings: `exact` or `reference`.
    pub fn name(&self) -> &'static str {
        match self {
            Reference::Exact(_) | Reference::Tabulated(..) => "exact",
            Reference::FineStep(_) => "reference",
        }
    }

    /// (θ, ω) at the steps first, first + 1, ... (times n·dt), one per element of `theta` and
    /// `omega`; blocks must be asked for in order. The closed form and its table give each step
    /// on its own, so they are evaluated in chunks on the rayon pool (the values do not depend on
    /// the threads); the fine-step solution is stepped in order and stops at a stop request
    /// ([`crate::interrupt::requested`]), leaving the rest unset.
    pub fn fill(&mut self, first: u64, dt: f64, theta: &mut [f64], omega: &mut [f64]) {
        match self {
            Reference::Exact(e) => fill_each(first, theta, omega, |n| e.state(n as f64 * dt)),
            Reference::Tabulated(_, table) => {
                fill_each(first, theta, omega, |n| table.state_at_step(n, dt));
            }
            Reference::FineStep(f) => {
                debug_assert_eq!(first, f.step + 1, "fine-step reference is sampled in order");
                for (th, w) in theta.iter_mut().zip(omega) {
                    if crate::interrupt::requested() {
                        return;
                    }
                    (*th, *w) = f.advance();
                }
            }
        }
    }

    /// One sentence on what the reference is, for the recording and the summary.
    pub fn describe(&self) -> String {
        match self {
            Reference::Exact(e) => closed_form_text(e),
            Reference::Tabulated(e, table) => format!(
                "{}; evaluated from a table of one period ({} Hermite pieces of degree 7, used beyond \
                 {TABULATE_ABOVE_STEPS} steps), verified within {:.1e} rad in θ and {:.1e} rad/s in ω \
                 of the closed form",
                closed_form_text(e),
                table.intervals(),
                table.max_theta_error(),
                table.max_omega_error()
            ),
            Reference::FineStep(f) => format!(
                "reference: no closed form for this start (ω0 ≠ 0 or |θ0| ≥ 180°); RK4 at h = {:.3e} s, \
                 estimated max θ error {:.1e} rad (Richardson against a run at 2h)",
                f.fine.h,
                f.error_estimate()
            ),
        }
    }
}

/// Steps evaluated per task of the rayon pool: a block of 4096 is four tasks.
const FILL_CHUNK: usize = 1024;

/// `state(n)` for n = first, first + 1, ... into `theta` and `omega`, in chunks on the pool.
fn fill_each(
    first: u64,
    theta: &mut [f64],
    omega: &mut [f64],
    state: impl Fn(u64) -> (f64, f64) + Sync,
) {
    use rayon::prelude::*;
    (theta
        .par_chunks_mut(FILL_CHUNK)
        .zip(omega.par_chunks_mut(FILL_CHUNK)))
    .enumerate()
    .for_each(|(c, (theta, omega))| {
        let start = first + (c * FILL_CHUNK) as u64;
        for (j, (th, w)) in theta.iter_mut().zip(omega).enumerate() {
            (*th, *w) = state(start + j as u64);
        }
    });
}
