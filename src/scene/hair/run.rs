//! One hair comparison run: every method on its own copy of the head and strands, stepped frame
//! by frame (`substeps` steps per frame), with the invariants measured every frame.

use std::time::{Duration, Instant};

use super::{Hair, HairMethod, HairParams};
use crate::scene::schedule::{Event, EventKind};

/// A method diverges when a position stops being finite or a segment is stretched past this many
/// rest lengths. Position-based methods do not blow up the way force-based ones do, but with one
/// sweep and millimetre segments they can stretch tenfold and stay stable, hence the wide bound.
pub const STRETCH_BOUND: f64 = 1000.0;

#[derive(Clone, Debug, PartialEq)]
pub struct HairConfig {
    pub params: HairParams,
    /// Simulation frames per simulated second (the seeds' 60 Hz).
    pub rate: f64,
    /// Steps per simulation frame.
    pub substeps: u32,
    /// 3D logging rate [Hz]; plots get every simulation frame.
    pub fps: f64,
    pub duration: f64,
    pub methods: Vec<HairMethod>,
}

impl Default for HairConfig {
    fn default() -> Self {
        HairConfig {
            params: HairParams::default(),
            rate: 60.0,
            substeps: 1,
            fps: 15.0,
            duration: 8.0,
            methods: HairMethod::ALL.to_vec(),
        }
    }
}

impl HairConfig {
    pub fn frames(&self) -> u64 {
        ((self.duration * self.rate).round() as u64).max(1)
    }
    /// Simulation frames between logged 3D frames.
    pub fn log_stride(&self) -> u64 {
        ((self.rate / self.fps).round() as u64).max(1)
    }
    pub fn step_dt(&self) -> f64 {
        1.0 / (self.rate * self.substeps as f64)
    }
}

/// What was measured on one lane after one simulation frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HairStats {
    pub max_stretch: f64,
    pub max_penetration: f64,
    pub max_root_error: f64,
    pub kinetic_energy: f64,
    /// Wall-clock milliseconds the frame's steps took.
    pub cost_ms: f64,
}

/// Every lane after one simulation frame.
pub struct HairFrame<'a> {
    pub frame: u64,
    pub time: f64,
    /// Whether the 3D state should be logged at this frame (every `log_stride` frames).
    pub log_3d: bool,
    /// Per lane: its state and stats, `None` once it has diverged.
    pub lanes: Vec<Option<(&'a Hair, HairStats)>>,
}

#[derive(Clone, Debug)]
pub struct HairLaneSummary {
    pub method: HairMethod,
    pub frames: u64,
    pub wall: Duration,
    pub max_stretch: f64,
    pub max_penetration: f64,
    pub max_root_error: f64,
    pub final_kinetic_energy: f64,
    pub divergence: Option<Event>,
}

impl HairLaneSummary {
    /// Simulated frames per wall-clock second.
    pub fn frames_per_second(&self) -> f64 {
        self.frames as f64 / self.wall.as_secs_f64().max(1e-12)
    }
}

#[derive(Clone, Debug)]
pub struct HairSummary {
    pub config: HairConfig,
    pub lanes: Vec<HairLaneSummary>,
    pub threads: usize,
}

pub trait HairObserver {
    fn start(&mut self, _config: &HairConfig, _lanes: &[Hair]) -> anyhow::Result<()> {
        Ok(())
    }
    fn frame(&mut self, _frame: &HairFrame) -> anyhow::Result<()> {
        Ok(())
    }
    fn event(&mut self, _event: &Event) -> anyhow::Result<()> {
        Ok(())
    }
}

pub struct NoHairObserver;
impl HairObserver for NoHairObserver {}

/// Measures a lane's invariants.
pub fn measure(hair: &Hair) -> HairStats {
    HairStats {
        max_stretch: hair.max_stretch(),
        max_penetration: hair.max_penetration(),
        max_root_error: hair.max_root_error(),
        kinetic_energy: hair.kinetic_energy(),
        cost_ms: 0.0,
    }
}

/// Runs the comparison on the current rayon pool.
pub fn run(config: &HairConfig, observer: &mut dyn HairObserver) -> anyhow::Result<HairSummary> {
    let mut lanes: Vec<Hair> = config
        .methods
        .iter()
        .map(|&m| Hair::new(config.params.clone(), m))
        .collect();
    let mut alive = vec![true; lanes.len()];
    let mut summaries: Vec<HairLaneSummary> = config
        .methods
        .iter()
        .map(|&method| HairLaneSummary {
            method,
            frames: 0,
            wall: Duration::ZERO,
            max_stretch: 0.0,
            max_penetration: 0.0,
            max_root_error: 0.0,
            final_kinetic_energy: 0.0,
            divergence: None,
        })
        .collect();
    observer.start(config, &lanes)?;
    let dt = config.step_dt();
    let log_stride = config.log_stride();
    let mut stats = vec![HairStats::default(); lanes.len()];

    for frame in 1..=config.frames() {
        // A stop request (Ctrl-C) ends the run between frames; what was done so far stands.
        if crate::interrupt::requested() {
            break;
        }
        for (i, hair) in lanes.iter_mut().enumerate() {
            if !alive[i] {
                continue;
            }
            let start = Instant::now();
            for _ in 0..config.substeps {
                hair.step(dt);
            }
            let elapsed = start.elapsed();
            let s = &mut summaries[i];
            s.wall += elapsed;
            s.frames += 1;
            stats[i] = HairStats {
                cost_ms: elapsed.as_secs_f64() * 1e3,
                ..measure(hair)
            };
            let st = stats[i];
            // The kinetic energy sums |Δx/dt|² over every node, so it is finite exactly when
            // every position is (no second pass over the state needed).
            let finite = st.kinetic_energy.is_finite();
            if !finite || st.max_stretch > STRETCH_BOUND {
                let time = hair.time;
                let why = if finite {
                    format!("stretch reached {:.3e}", st.max_stretch)
                } else {
                    "state not finite".into()
                };
                let event = Event {
                    lane: i,
                    time,
                    step: frame,
                    kind: EventKind::Divergence,
                    message: format!(
                        "{} diverged at t = {time:.4} s (frame {frame}): {why}",
                        hair.method.name()
                    ),
                };
                observer.event(&event)?;
                s.divergence = Some(event);
                alive[i] = false;
                continue;
            }
            s.max_stretch = s.max_stretch.max(st.max_stretch);
            s.max_penetration = s.max_penetration.max(st.max_penetration);
            s.max_root_error = s.max_root_error.max(st.max_root_error);
            s.final_kinetic_energy = st.kinetic_energy;
        }
        let view = HairFrame {
            frame,
            time: frame as f64 / config.rate,
            log_3d: frame.is_multiple_of(log_stride),
            lanes: lanes
                .iter()
                .zip(&stats)
                .zip(&alive)
                .map(|((h, s), &a)| a.then_some((h, *s)))
                .collect(),
        };
        observer.frame(&view)?;
    }
    Ok(HairSummary {
        config: config.clone(),
        lanes: summaries,
        threads: rayon::current_num_threads(),
    })
}
