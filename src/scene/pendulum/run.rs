//! One pendulum comparison run: every chosen method and the reference stepped over the same
//! time grid, with statistics, divergence detection and period measurement. What happens is
//! reported to a [`PendulumObserver`] (the recording, a test's collector), so this module never
//! touches Rerun.

use std::time::{Duration, Instant};

use super::period::PeriodMeter;
use super::reference::{Reference, exact_period};
use super::{Pendulum, PendulumParams, step_block};
use crate::method::{Integrator, Method, MethodOptions};
use crate::scene::schedule::Schedule;

/// A method diverges when θ or ω stops being finite or its energy exceeds this many times
/// max(E0, 2gL): far beyond anything a pendulum started with E0 can reach, so only an unstable
/// integrator gets there.
pub const DIVERGENCE_ENERGY_FACTOR: f64 = 10.0;

/// Steps taken per method between switches; large enough that the clock reads cost nothing.
const BLOCK_STEPS: usize = 4096;

/// Everything a pendulum run needs, resolved and validated.
#[derive(Clone, Debug, PartialEq)]
pub struct PendulumConfig {
    pub params: PendulumParams,
    /// Step [s].
    pub dt: f64,
    /// Simulated time [s]; the run takes round(duration / dt) steps.
    pub duration: f64,
    /// How often the 3D state is reported, in simulated Hz.
    pub fps: f64,
    /// Plot every Nth step (thinned further beyond MAX_PLOT_POINTS).
    pub plot_every: u64,
    /// Methods in the order they are shown.
    pub methods: Vec<Method>,
    pub options: MethodOptions,
}

impl Default for PendulumConfig {
    fn default() -> Self {
        PendulumConfig {
            params: PendulumParams::default(),
            dt: 0.01,
            duration: 20.0,
            fps: 30.0,
            plot_every: 1,
            methods: Method::DEFAULT.to_vec(),
            options: MethodOptions::default(),
        }
    }
}

impl PendulumConfig {
    pub fn schedule(&self) -> Schedule {
        Schedule::new(self.dt, self.duration, self.fps, self.plot_every)
    }
    pub fn total_steps(&self) -> u64 {
        self.schedule().total_steps
    }
    /// Steps between reported 3D frames.
    pub fn frame_stride(&self) -> u64 {
        self.schedule().frame_stride
    }
    /// Steps between plotted samples.
    pub fn plot_stride(&self) -> u64 {
        self.schedule().plot_stride
    }
}

/// A lane is one series of states: a method, or the reference.
#[derive(Clone, Debug)]
pub struct LaneInfo {
    pub name: &'static str,
    /// `None` for the reference lane.
    pub method: Option<Method>,
}

/// What an observer learns before the first step.
#[derive(Clone, Debug)]
pub struct RunSetup {
    pub config: PendulumConfig,
    /// Lane 0 is the reference, then the methods in the configured order.
    pub lanes: Vec<LaneInfo>,
    pub reference_description: String,
    pub initial_energy: f64,
    pub energy_scale: f64,
    pub energy_bound: f64,
    pub exact_period: Option<f64>,
}

/// Thinned samples of one lane over one block of steps. Plots never see a NaN or infinity:
/// a diverged lane stops before its bad step.
#[derive(Clone, Debug, Default)]
pub struct SeriesBlock {
    pub steps: Vec<u64>,
    pub times: Vec<f64>,
    pub theta: Vec<f64>,
    pub omega: Vec<f64>,
    pub energy: Vec<f64>,
    /// (E - E0) / energy_scale
    pub energy_error: Vec<f64>,
    /// |θ - θ_ref|; empty for the reference lane.
    pub theta_error: Vec<f64>,
}

impl SeriesBlock {
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        step: u64,
        t: f64,
        theta: f64,
        omega: f64,
        energy: f64,
        energy_error: f64,
        theta_error: Option<f64>,
    ) {
        self.steps.push(step);
        self.times.push(t);
        self.theta.push(theta);
        self.omega.push(omega);
        self.energy.push(energy);
        self.energy_error.push(energy_error);
        if let Some(err) = theta_error {
            self.theta_error.push(err);
        }
    }

    fn clear(&mut self) {
        self.steps.clear();
        self.times.clear();
        self.theta.clear();
        self.omega.clear();
        self.energy.clear();
        self.energy_error.clear();
        self.theta_error.clear();
    }
}

/// The state of every lane at one 3D frame; `None` for a lane that has diverged.
#[derive(Clone, Debug)]
pub struct FrameState {
    pub frame: u64,
    pub step: u64,
    pub time: f64,
    /// (θ, ω) per lane, lane order as in [`RunSetup::lanes`].
    pub states: Vec<Option<(f64, f64)>>,
}

pub use crate::scene::schedule::{Event, EventKind};

/// Per-lane results for the summary table.
#[derive(Clone, Debug)]
pub struct LaneSummary {
    pub name: &'static str,
    pub method: Option<Method>,
    /// Steps accepted (up to divergence).
    pub steps: u64,
    /// Wall time spent stepping (methods only; the reference is not timed).
    pub wall: Duration,
    /// Steps actually executed while timed (a diverged block runs to its end).
    pub timed_steps: u64,
    pub evals: u64,
    pub max_theta_error: f64,
    pub max_energy_error: f64,
    pub period: Option<f64>,
    pub periods_seen: u64,
    pub divergence: Option<Event>,
    pub failed_solves: u64,
}

impl LaneSummary {
    pub fn ns_per_step(&self) -> Option<f64> {
        (self.timed_steps > 0).then(|| self.wall.as_nanos() as f64 / self.timed_steps as f64)
    }
}

#[derive(Clone, Debug)]
pub struct RunSummary {
    pub setup: RunSetup,
    pub lanes: Vec<LaneSummary>,
    pub frames: u64,
}

/// Receives a run as it happens. Errors stop the run.
pub trait PendulumObserver {
    fn start(&mut self, _setup: &RunSetup) -> anyhow::Result<()> {
        Ok(())
    }
    fn series(&mut self, _lane: usize, _block: &SeriesBlock) -> anyhow::Result<()> {
        Ok(())
    }
    fn frame(&mut self, _frame: &FrameState) -> anyhow::Result<()> {
        Ok(())
    }
    fn event(&mut self, _event: &Event) -> anyhow::Result<()> {
        Ok(())
    }
    fn finish(&mut self, _summary: &RunSummary) -> anyhow::Result<()> {
        Ok(())
    }
}

/// An observer that ignores everything (for measurements without a recording).
pub struct NoObserver;
impl PendulumObserver for NoObserver {}

/// Per-lane working state.
struct Lane {
    integrator: Option<Integrator>,
    summary: LaneSummary,
    meter: PeriodMeter,
    /// Raw (θ, ω) of the current block.
    theta: Vec<f64>,
    omega: Vec<f64>,
    /// Offsets in the current block of steps whose implicit solve missed its tolerance.
    unconverged: Vec<usize>,
    /// Accepted steps in the current block (all, or up to divergence).
    accepted: usize,
    alive: bool,
}

/// Runs the comparison, reporting to `observer`; returns the summary.
pub fn run(
    config: &PendulumConfig,
    observer: &mut dyn PendulumObserver,
) -> anyhow::Result<RunSummary> {
    let p = config.params;
    let dt = config.dt;
    let system = Pendulum::new(&p);
    let mut reference = Reference::for_start(&p, dt);
    let e0 = p.initial_energy();
    let e_scale = p.energy_scale();
    let e_bound = DIVERGENCE_ENERGY_FACTOR * e0.max(p.over_the_top_energy());

    let mut lanes: Vec<Lane> = Vec::with_capacity(config.methods.len() + 1);
    let lane = |name: &'static str, method: Option<Method>, integrator: Option<Integrator>| Lane {
        integrator,
        summary: LaneSummary {
            name,
            method,
            steps: 0,
            wall: Duration::ZERO,
            timed_steps: 0,
            evals: 0,
            max_theta_error: 0.0,
            max_energy_error: 0.0,
            period: None,
            periods_seen: 0,
            divergence: None,
            failed_solves: 0,
        },
        meter: PeriodMeter::new(),
        theta: vec![0.0; BLOCK_STEPS],
        omega: vec![0.0; BLOCK_STEPS],
        unconverged: Vec::new(),
        accepted: 0,
        alive: true,
    };
    lanes.push(lane(reference.name(), None, None));
    for &m in &config.methods {
        let it = Integrator::new(m, &system, &[p.theta0], &[p.omega0], dt, config.options);
        lanes.push(lane(m.name(), Some(m), Some(it)));
    }

    let setup = RunSetup {
        config: config.clone(),
        lanes: lanes
            .iter()
            .map(|l| LaneInfo {
                name: l.summary.name,
                method: l.summary.method,
            })
            .collect(),
        reference_description: reference.describe(),
        initial_energy: e0,
        energy_scale: e_scale,
        energy_bound: e_bound,
        exact_period: exact_period(&p),
    };
    observer.start(&setup)?;

    let total = config.total_steps();
    let frame_stride = config.frame_stride();
    let plot_stride = config.plot_stride();
    let mut frames = 0u64;
    let mut block = SeriesBlock::default();
    let mut ref_theta = vec![0.0; BLOCK_STEPS];

    // Step 0: the initial state is every lane's first sample and frame 0.
    for (i, l) in lanes.iter_mut().enumerate() {
        l.meter.push(0.0, p.theta0, p.omega0);
        block.clear();
        block.push(0, 0.0, p.theta0, p.omega0, e0, 0.0, (i > 0).then_some(0.0));
        observer.series(i, &block)?;
    }
    observer.frame(&FrameState {
        frame: 0,
        step: 0,
        time: 0.0,
        states: vec![Some((p.theta0, p.omega0)); lanes.len()],
    })?;
    frames += 1;

    let mut first = 1u64;
    // A stop request (Ctrl-C) ends the run at a block boundary; what was done so far stands.
    while first <= total && !crate::interrupt::requested() {
        let len = ((total - first + 1) as usize).min(BLOCK_STEPS);

        // Reference over the block (not timed).
        for (j, slot) in ref_theta[..len].iter_mut().enumerate() {
            let (th, w) = reference.state_at_step(first + j as u64, dt);
            lanes[0].theta[j] = th;
            lanes[0].omega[j] = w;
            *slot = th;
        }
        lanes[0].accepted = len;

        // Methods: the timed loop does nothing but step and store.
        for l in lanes.iter_mut().skip(1) {
            l.accepted = 0;
            if !l.alive {
                continue;
            }
            let it = l
                .integrator
                .as_mut()
                .expect("method lanes have an integrator");
            l.unconverged.clear();
            let start = Instant::now();
            step_block(
                it,
                &system,
                &mut l.theta[..len],
                &mut l.omega[..len],
                &mut l.unconverged,
            );
            l.summary.wall += start.elapsed();
            l.summary.timed_steps += len as u64;
            l.summary.evals = it.evals();
            l.summary.failed_solves = it.failed_solves();
        }

        // Check, measure and report each lane's block.
        for (i, l) in lanes.iter_mut().enumerate() {
            if !l.alive {
                continue;
            }
            // One pass: each step is checked, then measured and (thinned) sampled; a diverged
            // lane stops before its bad step, so no NaN reaches a plot.
            let mut accepted = len;
            block.clear();
            for (j, &theta_ref) in ref_theta[..len].iter().enumerate() {
                let step = first + j as u64;
                let t = step as f64 * dt;
                let (th, w) = (l.theta[j], l.omega[j]);
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
                if let Some(why) = bad {
                    let event = Event {
                        lane: i,
                        time: t,
                        step,
                        kind: EventKind::Divergence,
                        message: format!(
                            "{} diverged at t = {t:.6} s (step {step}): {why}",
                            l.summary.name
                        ),
                    };
                    observer.event(&event)?;
                    l.summary.divergence = Some(event);
                    l.alive = false;
                    accepted = j;
                    break;
                }
                l.meter.push(t, th, w);
                let energy_error = (e - e0) / e_scale;
                l.summary.max_energy_error = l.summary.max_energy_error.max(energy_error.abs());
                let theta_error = (i > 0).then(|| (th - theta_ref).abs());
                if let Some(err) = theta_error {
                    l.summary.max_theta_error = l.summary.max_theta_error.max(err);
                }
                if step.is_multiple_of(plot_stride) {
                    block.push(step, t, th, w, e, energy_error, theta_error);
                }
            }
            l.accepted = accepted;
            l.summary.steps += accepted as u64;
            observer.series(i, &block)?;

            if let Some(&offset) = l.unconverged.first() {
                let count = l.unconverged.iter().filter(|&&j| j < accepted).count();
                if count > 0 {
                    let step = first + offset as u64;
                    let time = step as f64 * dt;
                    observer.event(&Event {
                        lane: i,
                        time,
                        step,
                        kind: EventKind::SolverNotConverged,
                        message: format!(
                            "{}: Newton missed |Δω| ≤ {:e}·(1+|ω|) within {} iterations at t = {time:.6} s \
                             ({count} such steps in this block of {len})",
                            l.summary.name,
                            super::NEWTON_TOL,
                            super::NEWTON_MAX_ITERATIONS
                        ),
                    })?;
                }
            }
        }

        // 3D frames that fall in this block.
        let last = first + len as u64 - 1;
        let mut step = first.next_multiple_of(frame_stride);
        while step <= last {
            let j = (step - first) as usize;
            let states = lanes
                .iter()
                .map(|l| (j < l.accepted).then(|| (l.theta[j], l.omega[j])))
                .collect();
            observer.frame(&FrameState {
                frame: frames,
                step,
                time: step as f64 * dt,
                states,
            })?;
            frames += 1;
            step += frame_stride;
        }
        first += len as u64;
    }

    let mut summaries: Vec<LaneSummary> = Vec::with_capacity(lanes.len());
    for l in lanes {
        let mut s = l.summary;
        s.period = l.meter.period();
        s.periods_seen = l.meter.periods_seen();
        summaries.push(s);
    }
    let mut setup = setup;
    // The fine-step reference's error estimate is only known at the end.
    setup.reference_description = reference.describe();
    let summary = RunSummary {
        setup,
        lanes: summaries,
        frames,
    };
    observer.finish(&summary)?;
    Ok(summary)
}
