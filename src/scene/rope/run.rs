//! One rope comparison run: every chosen method stepping its own copy of the rope over the same
//! time grid, with energy, strain, cost and divergence reported to a [`RopeObserver`].

use std::time::{Duration, Instant};

use super::{Rope, RopeParams, step_rope};
use crate::method::{Integrator, Method, MethodOptions};
use crate::scene::schedule::{Event, EventKind, Schedule};

/// A method diverges when its state stops being finite, a spring's strain passes
/// [`strain_bound`], or it gains more than [`ENERGY_GAIN_BOUND`] times the rope's energy scale:
/// a passive rope never gains energy, so only an unstable method does.
pub const STRAIN_BOUND: f64 = 10.0;

/// The strain beyond which a rope has blown up: 10, plus four times the strain of the top spring
/// of the chain hanging at rest, (N-1) m |g| / (ks ℓ0), so that a very soft rope stretching under
/// its own weight (a real, stable motion) is not mistaken for a blow-up.
pub fn strain_bound(p: &RopeParams) -> f64 {
    let hanging =
        (p.nodes - 1) as f64 * p.mass * p.gravity.length() / (p.stiffness * p.rest_length());
    if hanging.is_finite() {
        STRAIN_BOUND + 4.0 * hanging
    } else {
        f64::INFINITY
    }
}

/// See [`STRAIN_BOUND`]. Generous, because stable methods near their limit oscillate strongly.
pub const ENERGY_GAIN_BOUND: f64 = 100.0;

/// The rope's energy scale [J]: what a straight rope hanging from its first node has released,
/// m |g| ℓ0 N(N-1)/2, plus the start's kinetic and elastic energy, plus the elastic energy of
/// every spring stretched by 1% (so that a weightless rope at rest still has a scale, and
/// round-off energy of 1e-31 J is not mistaken for a blow-up).
pub fn energy_scale(rope: &Rope, x0: &[f64], v0: &[f64]) -> f64 {
    let p = &rope.params;
    let n = p.nodes as f64;
    let one_percent = 0.5 * p.stiffness * (0.01 * rope.rest()).powi(2) * (n - 1.0);
    p.mass * p.gravity.length() * rope.rest() * n * (n - 1.0) / 2.0
        + rope.kinetic_and_elastic_energy(x0, v0)
        + one_percent
}

/// Plot samples collected per lane before they are handed to the observer.
const SERIES_BATCH: usize = 2048;

/// Everything a rope run needs, resolved and validated.
#[derive(Clone, Debug, PartialEq)]
pub struct RopeConfig {
    pub params: RopeParams,
    /// Step [s].
    pub dt: f64,
    /// Simulated time [s].
    pub duration: f64,
    /// 3D frames per simulated second.
    pub fps: f64,
    /// Plot every Nth step (thinned further beyond MAX_PLOT_POINTS).
    pub plot_every: u64,
    /// How the recording lays the methods out (it does not change the numbers).
    pub layout: crate::record::rope::Layout,
    pub methods: Vec<Method>,
    pub options: MethodOptions,
}

impl Default for RopeConfig {
    fn default() -> Self {
        RopeConfig {
            params: RopeParams::default(),
            dt: 1e-3,
            duration: 10.0,
            fps: 30.0,
            plot_every: 5,
            layout: Default::default(),
            methods: Method::DEFAULT.to_vec(),
            options: MethodOptions::default(),
        }
    }
}

impl RopeConfig {
    pub fn schedule(&self) -> Schedule {
        Schedule::new(self.dt, self.duration, self.fps, self.plot_every)
    }
}

/// What an observer learns before the first step.
#[derive(Clone, Debug)]
pub struct RopeSetup {
    pub config: RopeConfig,
    pub initial_positions: Vec<f64>,
    pub initial_energy: f64,
    /// See [`energy_scale`].
    pub energy_scale: f64,
    /// See [`strain_bound`].
    pub strain_bound: f64,
    pub rest_length: f64,
    /// Highest linear mode of the chain pinned at node 0 with the rest free [rad/s].
    pub omega_max: f64,
}

/// Plot samples of one lane (thinned per [`Schedule::plot_stride`]); never NaN or infinite.
#[derive(Clone, Debug, Default)]
pub struct RopeSeries {
    pub steps: Vec<u64>,
    pub times: Vec<f64>,
    /// Kinetic + spring + gravity [J].
    pub energy: Vec<f64>,
    /// E - E0 [J].
    pub energy_change: Vec<f64>,
    /// max |ℓ - ℓ0| / ℓ0.
    pub max_strain: Vec<f64>,
}

impl RopeSeries {
    fn clear(&mut self) {
        self.steps.clear();
        self.times.clear();
        self.energy.clear();
        self.energy_change.clear();
        self.max_strain.clear();
    }
}

/// Every lane's positions at one 3D frame, and what the frame cost to simulate.
#[derive(Debug)]
pub struct RopeFrame<'a> {
    pub frame: u64,
    pub step: u64,
    pub time: f64,
    /// Flat positions per lane; `None` once the lane has diverged.
    pub positions: Vec<Option<&'a [f64]>>,
    /// Wall-clock milliseconds each lane spent stepping since the previous frame.
    pub cost_ms: Vec<f64>,
}

#[derive(Clone, Debug)]
pub struct RopeLaneSummary {
    pub method: Method,
    pub steps: u64,
    pub wall: Duration,
    pub evals: u64,
    pub final_energy: Option<f64>,
    pub max_strain: f64,
    pub divergence: Option<Event>,
    pub failed_solves: u64,
}

impl RopeLaneSummary {
    pub fn ns_per_step(&self) -> Option<f64> {
        (self.steps > 0).then(|| self.wall.as_nanos() as f64 / self.steps as f64)
    }
}

#[derive(Clone, Debug)]
pub struct RopeSummary {
    pub setup: RopeSetup,
    pub lanes: Vec<RopeLaneSummary>,
}

/// Receives a rope run as it happens. Errors stop the run.
pub trait RopeObserver {
    fn start(&mut self, _setup: &RopeSetup) -> anyhow::Result<()> {
        Ok(())
    }
    fn series(&mut self, _lane: usize, _series: &RopeSeries) -> anyhow::Result<()> {
        Ok(())
    }
    fn frame(&mut self, _frame: &RopeFrame) -> anyhow::Result<()> {
        Ok(())
    }
    fn event(&mut self, _event: &Event) -> anyhow::Result<()> {
        Ok(())
    }
    fn finish(&mut self, _summary: &RopeSummary) -> anyhow::Result<()> {
        Ok(())
    }
}

pub struct NoRopeObserver;
impl RopeObserver for NoRopeObserver {}

struct Lane {
    integrator: Integrator,
    summary: RopeLaneSummary,
    series: RopeSeries,
    frame_cost: Duration,
    alive: bool,
}

/// Runs the comparison, reporting to `observer`; returns the summary.
pub fn run(config: &RopeConfig, observer: &mut dyn RopeObserver) -> anyhow::Result<RopeSummary> {
    let rope = Rope::new(config.params.clone());
    let x0 = config.params.initial_positions();
    let v0 = vec![0.0; x0.len()];
    let e0 = rope.energy(&x0, &v0);
    let e_scale = energy_scale(&rope, &x0, &v0);
    let dt = config.dt;
    let schedule = config.schedule();

    let mut lanes: Vec<Lane> = config
        .methods
        .iter()
        .map(|&m| Lane {
            integrator: Integrator::new(m, &rope, &x0, &v0, dt, config.options),
            summary: RopeLaneSummary {
                method: m,
                steps: 0,
                wall: Duration::ZERO,
                evals: 0,
                final_energy: None,
                max_strain: 0.0,
                divergence: None,
                failed_solves: 0,
            },
            series: RopeSeries::default(),
            frame_cost: Duration::ZERO,
            alive: true,
        })
        .collect();

    let setup = RopeSetup {
        config: config.clone(),
        initial_positions: x0.clone(),
        initial_energy: e0,
        energy_scale: e_scale,
        strain_bound: strain_bound(&config.params),
        rest_length: rope.rest(),
        omega_max: config.params.omega_max_pinned_free(),
    };
    observer.start(&setup)?;

    let mut frames = 0u64;
    let mut step = 0u64;
    loop {
        // Sample (and check) every lane at plot steps and at the end.
        let at_sample = step.is_multiple_of(schedule.plot_stride) || step == schedule.total_steps;
        let at_frame = step.is_multiple_of(schedule.frame_stride);
        if at_sample || at_frame {
            for (i, l) in lanes.iter_mut().enumerate() {
                if l.alive {
                    sample(&rope, l, i, step, dt, e0, e_scale, observer)?;
                }
            }
        }
        if at_frame {
            let frame = RopeFrame {
                frame: frames,
                step,
                time: step as f64 * dt,
                positions: lanes
                    .iter()
                    .map(|l| l.alive.then(|| l.integrator.position()))
                    .collect(),
                cost_ms: lanes
                    .iter()
                    .map(|l| l.frame_cost.as_secs_f64() * 1e3)
                    .collect(),
            };
            observer.frame(&frame)?;
            frames += 1;
            for (i, l) in lanes.iter_mut().enumerate() {
                l.frame_cost = Duration::ZERO;
                // Plots go out in large batches: every batch becomes a chunk in the recording,
                // and small chunks cost more than their data.
                if l.series.steps.len() >= SERIES_BATCH || (!l.alive && !l.series.steps.is_empty())
                {
                    observer.series(i, &l.series)?;
                    l.series.clear();
                }
            }
        }
        // A stop request (Ctrl-C) ends the run at a frame; what was done so far stands.
        if step == schedule.total_steps || crate::interrupt::requested() {
            break;
        }

        // Step every live lane to the next sample or frame, timing only the stepping.
        let next = [
            step.next_multiple_of(schedule.plot_stride).max(step + 1),
            (step + 1).next_multiple_of(schedule.frame_stride),
            schedule.total_steps,
        ]
        .into_iter()
        .filter(|&s| s > step)
        .min()
        .unwrap_or(schedule.total_steps);
        let len = next - step;
        for (i, l) in lanes.iter_mut().enumerate() {
            if !l.alive {
                continue;
            }
            let failed_before = l.integrator.failed_solves();
            let start = Instant::now();
            step_rope(&mut l.integrator, &rope, len);
            let elapsed = start.elapsed();
            l.summary.wall += elapsed;
            l.frame_cost += elapsed;
            l.summary.steps += len;
            l.summary.evals = l.integrator.evals();
            l.summary.failed_solves = l.integrator.failed_solves();
            if failed_before == 0 && l.summary.failed_solves > 0 {
                // Reported once per lane (the summary has the count), so the log stays readable.
                let time = next as f64 * dt;
                observer.event(&Event {
                    lane: i,
                    time,
                    step: next,
                    kind: EventKind::SolverNotConverged,
                    message: format!(
                        "{}: an implicit step before t = {time:.4} s missed the Newton tolerance \
                         (max |δv| ≤ {:e}·(1 + max |v|)); the summary counts all such steps",
                        l.summary.method,
                        super::implicit::NEWTON_TOL
                    ),
                })?;
            }
        }
        step = next;
    }
    for (i, l) in lanes.iter_mut().enumerate() {
        if !l.series.steps.is_empty() {
            observer.series(i, &l.series)?;
            l.series.clear();
        }
    }
    let summary = RopeSummary {
        setup,
        lanes: lanes.into_iter().map(|l| l.summary).collect(),
    };
    observer.finish(&summary)?;
    Ok(summary)
}

#[allow(clippy::too_many_arguments)]
/// Measures one lane at `step`; marks it diverged (and reports it) if its state is bad.
fn sample(
    rope: &Rope,
    l: &mut Lane,
    lane: usize,
    step: u64,
    dt: f64,
    e0: f64,
    e_scale: f64,
    observer: &mut dyn RopeObserver,
) -> anyhow::Result<()> {
    let x = l.integrator.position();
    let v = l.integrator.velocity();
    let energy = rope.energy(x, v);
    let strain = rope.max_strain(x);
    let finite = energy.is_finite() && x.iter().chain(v).all(|c| c.is_finite());
    let time = step as f64 * dt;
    let gained = energy - e0;
    let too_energetic = e_scale > 0.0 && gained > ENERGY_GAIN_BOUND * e_scale;
    let bound = strain_bound(&rope.params);
    if !finite || strain > bound || too_energetic {
        let why = if !finite {
            "the state is not finite".to_string()
        } else if strain > bound {
            format!("a spring's strain reached {strain:.3e} (bound {bound:.3})")
        } else {
            format!(
                "it gained {gained:.3e} J, over {ENERGY_GAIN_BOUND} × the energy scale {e_scale:.3e} J"
            )
        };
        let event = Event {
            lane,
            time,
            step,
            kind: EventKind::Divergence,
            message: format!(
                "{} diverged by t = {time:.4} s (step {step}): {why}",
                l.summary.method
            ),
        };
        observer.event(&event)?;
        l.summary.divergence = Some(event);
        l.alive = false;
        // The reported steps are those that passed the last check.
        return Ok(());
    }
    l.summary.max_strain = l.summary.max_strain.max(strain);
    l.summary.final_energy = Some(energy);
    l.series.steps.push(step);
    l.series.times.push(time);
    l.series.energy.push(energy);
    l.series.energy_change.push(energy - e0);
    l.series.max_strain.push(strain);
    Ok(())
}
