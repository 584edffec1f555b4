//! The pendulum as a [`Scene`]: every chosen method and the reference stepped over the same time
//! grid, checked every step, with the period measured from each lane's motion.

use super::exact::{ExactPendulum, exact_period};
use super::period::PeriodMeter;
use super::reference::{FineStepReference, Reference};
use super::{Pendulum, PendulumParams, step_block};
use crate::format;
use crate::integrate::{Counts, Integrator, Method, MethodOptions};
use crate::scene::harness::{Checked, Sampler, Scene, Schedule, Window, Windows};
use crate::scene::params::{self, BLOCK_STEPS, Invalid};

/// A method diverges when θ or ω stops being finite or its energy exceeds this many times
/// max(E0, 2gL): far beyond anything a pendulum started with E0 can reach, so only an unstable
/// integrator gets there.
pub const DIVERGENCE_ENERGY_FACTOR: f64 = 10.0;

/// Everything a pendulum run needs; its serialised form is the scene file's `[pendulum]` table.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PendulumConfig {
    #[serde(flatten)]
    pub params: PendulumParams,
    /// θ0 as given [degrees], taken into (-180°, 180°] as `params.theta0` (in radians, with
    /// what the conversion rounds off) when the configuration settles.
    #[serde(rename = "theta0")]
    pub theta0_degrees: f64,
    /// Step [s].
    pub dt: f64,
    /// Simulated time [s]; the run takes round(duration / dt) steps.
    pub duration: f64,
    /// How often the 3D state is reported, in simulated Hz.
    pub fps: f64,
    /// Plot every Nth step (thinned further beyond MAX_PLOT_POINTS).
    pub plot_every: u64,
    /// Stretches kept whole when the plots are aggregated (`--window`).
    pub window: Vec<Window>,
    /// Methods in the order they are shown.
    pub methods: Vec<Method>,
    #[serde(flatten)]
    pub options: MethodOptions,
}

impl Default for PendulumConfig {
    fn default() -> Self {
        PendulumConfig {
            params: PendulumParams::default(),
            theta0_degrees: DEFAULT_THETA0_DEGREES,
            dt: 0.01,
            duration: 20.0,
            fps: 30.0,
            plot_every: 1,
            window: Vec::new(),
            methods: Method::DEFAULT.to_vec(),
            options: MethodOptions::default(),
        }
    }
}

/// θ0 by default [degrees]; the one place this default is written.
pub const DEFAULT_THETA0_DEGREES: f64 = 60.0;

impl params::SceneConfig for PendulumConfig {
    fn settle(&mut self, given: &dyn Fn(&str) -> bool) -> Result<(), Invalid> {
        if given("theta0") {
            (self.params.theta0, self.params.theta0_low) =
                super::theta0_from_degrees(self.theta0_degrees);
        }
        self.methods = params::dedup_methods(&self.methods);
        Ok(())
    }

    fn validate(&self) -> Result<(), Invalid> {
        let p = &self.params;
        let max = params::MAX_MAGNITUDE;
        params::some_methods(&self.methods, &Method::names().collect::<Vec<_>>())?;
        params::within("--gravity", p.gravity, 1.0 / max, max, "m/s²")?;
        params::within("--length", p.length, 1.0 / max, max, "m")?;
        let turns = super::MAX_THETA0_TURNS;
        if p.theta0.is_nan() || p.theta0.abs() > turns * std::f64::consts::TAU {
            // The value as typed: degrees → radians → degrees, rounded to 12 digits.
            let typed: f64 = format!("{:.11e}", p.theta0.to_degrees())
                .parse()
                .unwrap_or(f64::NAN);
            let degrees = turns * 360.0;
            let rule =
                format!("must be a finite angle within ±{turns} turns (±{degrees}°) [degrees]");
            return Err(Invalid::param("--theta0", format::shown(typed), rule));
        }
        params::within("--omega0", p.omega0, -max, max, "rad/s")?;
        params::time(self.dt, self.duration, self.fps, 1)?;
        params::own_step(self.options.step, self.dt, self.duration, 1)?;
        self.reference_guard()?;
        self.schedule().check_windows(&self.window)?;
        params::plot_and_options(self.plot_every, &self.options)
    }

    /// A step beyond a tenth of the period (the exact one for the start given; the small-angle
    /// 2π/ωn at rest) follows a swing with fewer than ten steps.
    fn step_warning(&self) -> Option<String> {
        let small_angle = std::f64::consts::TAU / self.params.omega_n();
        let (period, what) = match exact_period(&self.params) {
            Some(t) => (t, "period"),
            None => (small_angle, "small-angle period"),
        };
        let (flag, h) = params::fixed_step(self.dt, &self.options);
        (h > period / 10.0).then(|| {
            format!(
                "{flag} {} s exceeds a tenth of the pendulum's {what} {} s: fewer than ten steps \
                 a swing, so every method's error is of the order of the motion (milliseconds \
                 are {flag} 0.001)",
                format::shown(h),
                format::seconds(period)
            )
        })
    }
}

impl PendulumConfig {
    pub fn schedule(&self) -> Schedule {
        Schedule::fixed_step(self.dt, self.duration, self.fps, self.plot_every)
    }

    /// RK4 steps the fine-step reference takes over the run (0 when the closed form applies).
    pub fn reference_steps(&self) -> f64 {
        if ExactPendulum::new(&self.params).is_some() {
            return 0.0;
        }
        let steps = self.schedule().total as f64;
        3.0 * steps * FineStepReference::substeps(&self.params, self.dt)
    }

    /// The fine-step reference (ω0 ≠ 0 or |θ0| ≥ 180°) counts against the same step limit as
    /// a method: its substeps follow the fastest rate, which ω0 sets, so a large ω0 is refused
    /// up front rather than left to run for hours.
    fn reference_guard(&self) -> Result<(), Invalid> {
        let steps = self.reference_steps();
        if steps > params::MAX_STEPS {
            let degrees = format!("{:.6}", self.params.theta0.to_degrees());
            return Err(Invalid::Usage(format!(
                "--omega0 {} (θ0 {}°, --length {} m, --gravity {} m/s²) over --duration {} s: the fine-step \
                 reference needs {steps:.2e} RK4 steps (its step follows the fastest rate, here {:.3e} rad/s); \
                 at most {:.0e} are allowed (lower --omega0 or shorten --duration)",
                format::shown(self.params.omega0),
                degrees.trim_end_matches('0').trim_end_matches('.'),
                format::shown(self.params.length),
                format::shown(self.params.gravity),
                format::shown(self.duration),
                self.params
                    .omega_n()
                    .max((2.0 * self.params.initial_energy()).sqrt() / self.params.length),
                params::MAX_STEPS
            )));
        }
        Ok(())
    }
}

/// The quantities every lane plots, in order; method lanes add `theta_error` and `step_size`
/// (the size of the method's last accepted step: an adaptive method's own steps, which do not
/// end at the sample times, so a user sees the step size the error control chose).
pub const QUANTITIES: [&str; 6] = [
    "theta",
    "omega",
    "energy",
    "energy_error",
    "theta_error",
    "step_size",
];

/// One lane: a method, or the reference (`method` is `None`).
pub struct PendulumLane {
    pub method: Option<Method>,
    integrator: Option<Integrator>,
    /// (θ, ω) after every step of the current block (the initial state before the first).
    theta: Vec<f64>,
    omega: Vec<f64>,
    /// Evaluations spent after every step of the current block (so that a lane that diverged
    /// inside a block counts only up to its failing step).
    evals: Vec<u64>,
    /// The method's last accepted step size after every step of the current block.
    step_size: Vec<f64>,
    /// Offsets in the current block of steps whose implicit solve missed its tolerance.
    unconverged: Vec<usize>,
    pub meter: PeriodMeter,
    pub max_theta_error: f64,
    pub max_energy_error: f64,
}

impl PendulumLane {
    /// (θ, ω) at `offset` in the last block.
    pub fn state(&self, offset: usize) -> (f64, f64) {
        (self.theta[offset], self.omega[offset])
    }
}

/// A pendulum run: the scene, its reference, and the bounds its lanes are checked against.
pub struct PendulumScene {
    pub config: PendulumConfig,
    system: Pendulum,
    reference: Reference,
    /// The reference's (θ, ω) over the current block.
    ref_theta: Vec<f64>,
    ref_omega: Vec<f64>,
    pub initial_energy: f64,
    /// The scale relative energy errors are taken against.
    pub energy_scale: f64,
    /// Energy beyond which a lane has diverged.
    pub energy_bound: f64,
    pub exact_period: Option<f64>,
}

impl PendulumScene {
    pub fn new(config: PendulumConfig) -> Self {
        let p = config.params;
        let e0 = p.initial_energy();
        PendulumScene {
            system: Pendulum::new(&p),
            reference: Reference::for_start(&p, config.dt, config.schedule().total),
            ref_theta: vec![0.0; BLOCK_STEPS],
            ref_omega: vec![0.0; BLOCK_STEPS],
            initial_energy: e0,
            energy_scale: p.energy_scale(),
            energy_bound: DIVERGENCE_ENERGY_FACTOR * e0.max(p.over_the_top_energy()),
            exact_period: exact_period(&p),
            config,
        }
    }

    /// One sentence on the reference (a fine-step one's error estimate grows during the run).
    pub fn reference_description(&self) -> String {
        self.reference.describe()
    }

    fn lane(&self, method: Option<Method>) -> PendulumLane {
        let (p, dt, options) = (self.config.params, self.config.dt, self.config.options);
        let (x0, v0) = ([p.theta0], [p.omega0]);
        let integrator = method.map(|m| Integrator::new(m, &self.system, &x0, &v0, dt, options));
        let mut meter = PeriodMeter::new();
        meter.push(0.0, p.theta0, p.omega0);
        let mut theta = vec![0.0; BLOCK_STEPS];
        let mut omega = vec![0.0; BLOCK_STEPS];
        (theta[0], omega[0]) = (p.theta0, p.omega0);
        PendulumLane {
            method,
            integrator,
            theta,
            omega,
            evals: vec![0; BLOCK_STEPS],
            step_size: vec![0.0; BLOCK_STEPS],
            unconverged: Vec::new(),
            meter,
            max_theta_error: 0.0,
            max_energy_error: 0.0,
        }
    }
}

impl Scene for PendulumScene {
    type Lane = PendulumLane;

    fn name(&self) -> &'static str {
        "pendulum"
    }

    fn schedule(&self) -> Schedule {
        self.config.schedule()
    }

    fn lanes(&self) -> Vec<(&'static str, PendulumLane)> {
        let methods = (self.config.methods.iter()).map(|&m| (m.name(), self.lane(Some(m))));
        std::iter::once((self.reference.name(), self.lane(None)))
            .chain(methods)
            .collect()
    }

    fn is_method(&self, lane: &PendulumLane) -> bool {
        lane.method.is_some()
    }

    fn quantities(&self, lane: &PendulumLane) -> &'static [&'static str] {
        if lane.method.is_some() {
            &QUANTITIES
        } else {
            &QUANTITIES[..4]
        }
    }

    fn initial(&self, lane: &PendulumLane) -> Option<Vec<f64>> {
        let p = self.config.params;
        let mut values = vec![p.theta0, p.omega0, self.initial_energy, 0.0];
        if lane.method.is_some() {
            values.extend([0.0, 0.0]);
        }
        Some(values)
    }

    fn max_block(&self) -> u64 {
        params::block_ticks(self.config.dt, &self.config.options)
    }

    /// The first and the last five periods (small-angle periods when there is no exact one).
    fn windows(&self) -> Windows {
        let p = &self.config.params;
        let period = self
            .exact_period
            .unwrap_or(std::f64::consts::TAU / p.omega_n());
        Windows {
            edge_seconds: 5.0 * period,
            asked: self.config.window.clone(),
        }
    }

    fn traced(&self) -> bool {
        true
    }

    fn side_by_side(&self) -> bool {
        true
    }

    /// The reference over the block (not timed).
    fn prepare(&mut self, first: u64, len: usize) {
        let (theta, omega) = (&mut self.ref_theta[..len], &mut self.ref_omega[..len]);
        self.reference.fill(first, self.config.dt, theta, omega);
    }

    /// The timed loop does nothing but step and store.
    fn advance(&self, lane: &mut PendulumLane, _first: u64, len: usize) {
        lane.unconverged.clear();
        match &mut lane.integrator {
            Some(it) => step_block(
                it,
                &self.system,
                &mut lane.theta[..len],
                &mut lane.omega[..len],
                &mut lane.evals[..len],
                &mut lane.step_size[..len],
                &mut lane.unconverged,
            ),
            None => {
                lane.theta[..len].copy_from_slice(&self.ref_theta[..len]);
                lane.omega[..len].copy_from_slice(&self.ref_omega[..len]);
            }
        }
    }

    /// Each step is checked, then measured and (thinned) sampled; a diverged lane stops before
    /// its bad step, so no NaN reaches a plot.
    fn check(&self, lane: &mut PendulumLane, first: u64, len: usize, out: &mut Sampler) -> Checked {
        let p = &self.config.params;
        let (e0, e_scale, e_bound) = (self.initial_energy, self.energy_scale, self.energy_bound);
        let is_method = lane.method.is_some();
        let mut checked = Checked::all(len);
        for j in 0..len {
            let step = first + j as u64;
            let t = step as f64 * self.config.dt;
            let (th, w) = (lane.theta[j], lane.omega[j]);
            let e = p.energy(th, w);
            let bad = if !th.is_finite() || !w.is_finite() {
                Some(format!("θ = {th}, ω = {w} is not finite"))
            } else if e > e_bound {
                Some(format!(
                    "energy {e:.4e} J/kg exceeds the bound {e_bound:.4e} J/kg"
                ))
            } else {
                None
            };
            if bad.is_some() {
                checked.accepted = j;
                checked.divergence = bad;
                if let Some(it) = &lane.integrator {
                    // Count up to and including the failing step, not the rest of the block.
                    let later_misses = lane.unconverged.iter().filter(|&&o| o > j).count();
                    checked.counts = Some(Counts {
                        evals: lane.evals[j],
                        failed_solves: it.failed_solves() - later_misses as u64,
                        // The rest of the block's own steps cannot be told apart: not shown.
                        own_steps: None,
                    });
                }
                break;
            }
            lane.meter.push(t, th, w);
            let energy_error = (e - e0) / e_scale;
            lane.max_energy_error = lane.max_energy_error.max(energy_error.abs());
            let theta_error = (th - self.ref_theta[j]).abs();
            if is_method {
                lane.max_theta_error = lane.max_theta_error.max(theta_error);
            }
            if out.wants(step) {
                let row = [th, w, e, energy_error, theta_error, lane.step_size[j]];
                out.push(step, &row[..if is_method { 6 } else { 4 }]);
            }
        }
        // Misses are counted up to and including the failing step; so is the event.
        if let Some(&offset) = lane.unconverged.first()
            && offset <= checked.accepted
            && offset < len
        {
            let (tol, most) = (super::NEWTON_TOL, super::NEWTON_MAX_ITERATIONS);
            let asked = format!("|Δω| ≤ {tol:e}·(1+|ω|) within {most} iterations");
            checked.solver_miss = Some((offset, asked));
        }
        checked
    }

    fn counts(&self, lane: &PendulumLane) -> Counts {
        lane.integrator
            .as_ref()
            .map_or(Counts::default(), Integrator::counts)
    }
}
