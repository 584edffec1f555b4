//! Hair as a [`Scene`]: every method on its own copy of the head and strands, stepped frame by
//! frame (`substeps` steps per frame), with the invariants measured every frame. A tick of the
//! harness is one simulation frame.

use super::{Hair, HairMethod, HairParams, HairStats};
use crate::format;
use crate::scene::harness::{Checked, Clock, Sampler, Scene, Schedule, Window, Windows};
use crate::scene::params::{self, Invalid};

/// A method diverges when a position stops being finite or a segment is stretched by more than
/// this many rest lengths (|ℓ - ℓ0|/ℓ0 > 10: the segment is over 11 times its length), far past
/// any sound run and short of a wind the solver cannot hold. Position methods do not blow up the
/// way force-based ones do; this is where their strands stop being hair.
pub const STRETCH_BOUND: f64 = 10.0;

/// Everything a hair run needs; its serialised form is the scene file's `[hair]` table.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct HairConfig {
    #[serde(flatten)]
    pub params: HairParams,
    /// The springs' stiffness k/m as given [1/s²]; when not given, `params.stiffness` follows
    /// the scene (`HairParams::default_stiffness`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// Simulation frames per simulated second (60 Hz: a display's frame rate).
    pub rate: f64,
    /// Steps per simulation frame.
    pub substeps: u32,
    /// 3D logging rate [Hz]; plots get every simulation frame.
    pub fps: f64,
    /// Stretches kept whole when the plots are aggregated (`--window`).
    pub window: Vec<Window>,
    pub duration: f64,
    pub methods: Vec<HairMethod>,
    /// The step as given [s], which sets `substeps` to 1/(rate·dt).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    /// Strands drawn in 3D (what the recording draws, not what is simulated; sized to the run
    /// when not given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub log_strands: Option<usize>,
}

impl Default for HairConfig {
    fn default() -> Self {
        HairConfig {
            params: HairParams::default(),
            stiffness: None,
            rate: 60.0,
            substeps: 1,
            fps: 30.0,
            window: Vec::new(),
            duration: 8.0,
            methods: HairMethod::DEFAULT.to_vec(),
            dt: None,
            log_strands: None,
        }
    }
}

/// The stiffest springs allowed, k/m [1/s²].
pub const MAX_STIFFNESS: f64 = 1e12;

/// Node-steps × (iterations + 1) per method beyond which a hair run is refused.
pub const MAX_HAIR_WORK: f64 = 1e12;

impl params::SceneConfig for HairConfig {
    fn settle(&mut self, given: &dyn Fn(&str) -> bool) -> Result<(), Invalid> {
        let p = &mut self.params;
        p.stiffness = self.stiffness.unwrap_or_else(|| p.default_stiffness());
        if let Some(dt) = self.dt {
            let substeps = given("substeps").then_some(self.substeps);
            self.substeps = substeps_for_dt(self.rate, dt, substeps)?;
        }
        self.methods = params::dedup_methods(&self.methods);
        Ok(())
    }
    fn same_value(key: &str) -> &'static [&'static str] {
        match key {
            "dt" => &["substeps"],
            "substeps" => &["dt"],
            _ => &[],
        }
    }

    fn validate(&self) -> Result<(), Invalid> {
        let p = &self.params;
        let (strands, nodes, iterations, substeps) =
            (p.strands, p.nodes, p.iterations, self.substeps);
        params::some_methods(&self.methods, &HairMethod::ALL.map(HairMethod::name))?;
        params::count_within("--strands", strands as u64, 1, 1_000_000)?;
        params::count_within("--nodes", nodes as u64, 2, 10_000)?;
        // The same physical ranges as the pendulum's and the rope's magnitudes.
        let max = params::MAX_MAGNITUDE;
        params::within("--segment-length", p.segment_length, 1.0 / max, max, "m")?;
        params::within("--head-radius", p.head_radius, 1.0 / max, max, "m")?;
        for (option, v) in [("--gravity", p.gravity), ("--wind", p.wind)] {
            params::vector(option, v, " [m/s²]")?;
        }
        params::non_negative("--gust", p.gust, "fraction")?;
        let peak = p.wind.length() * (1.0 + p.gust);
        if peak > max {
            return Err(Invalid::Usage(format!(
                "--gust {} with --wind of {} m/s²: the gusts reach {} m/s²; at most {max:e} is allowed",
                format::shown(p.gust),
                format::shown(p.wind.length()),
                format::shown(peak)
            )));
        }
        params::within("--damping", p.damping, 0.0, max, "1/s")?;
        self.schedule().check_windows(&self.window)?;
        let margin_ok = p.margin.is_finite() && (0.0..0.5).contains(&p.margin);
        let rule = "must be in [0, 0.5) head radii";
        params::require(margin_ok, "--margin", p.margin, rule)?;
        params::at_least_one("--iterations", iterations.into())?;
        self.validate_stiffness()?;
        params::within("--spring-damping", p.spring_damping, 0.0, max, "1/s")?;
        params::at_least_one("--substeps", substeps.into())?;
        let rule = "must be at least 1 (--no-record draws nothing at all)";
        params::refuse_unless(self.log_strands != Some(0), "--log-strands", 0, rule)?;
        self.validate_frames()?;
        // Symplectic Euler's springs take their own inner steps.
        let inner = if self.methods.contains(&HairMethod::SemiImplicitEuler) {
            (self.step_dt() / p.spring_step_limit()).ceil().max(1.0)
        } else {
            1.0
        };
        let work = self.frames() as f64
            * substeps as f64
            * (strands * nodes) as f64
            * ((iterations + 1) as f64).max(inner);
        if work > MAX_HAIR_WORK {
            return Err(Invalid::Usage(format!(
                "--strands {strands} × --nodes {nodes} × --iterations {iterations} over {} frames × {substeps} substeps \
                 is {work:.2e} node-updates per method; at most {MAX_HAIR_WORK:.0e} are allowed (fewer strands or a \
                 shorter --duration)",
                self.frames()
            )));
        }
        params::memory(
            &format!(
                "--strands {strands} × --nodes {nodes} with {} methods",
                self.methods.len()
            ),
            self.memory_bytes(),
            "use fewer --strands or --nodes",
        )
    }
}

impl HairConfig {
    /// The springs' stiffness in range where a method reads it. The default follows the other
    /// parameters: it is refused only when a spring method would take it, and then by what it
    /// follows from.
    fn validate_stiffness(&self) -> Result<(), Invalid> {
        let (p, max) = (&self.params, params::MAX_MAGNITUDE);
        let defaulted = p.stiffness == p.default_stiffness();
        let springs = self.methods.iter().any(|m| m.is_spring());
        if springs && defaulted && p.stiffness > MAX_STIFFNESS {
            return Err(Invalid::Usage(format!(
                "the springs' default --stiffness here is k/m = {:.3e} 1/s² (a wave speed \
                 ℓ0·√(k/m) of {} × the strands' speed scale {:.3} m/s over --segment-length {} m), \
                 beyond the {MAX_STIFFNESS:e} allowed: give --stiffness (the 1e-2 stretch bound is \
                 then not stated) or a longer --segment-length",
                p.stiffness,
                super::SPRING_WAVE_SPEEDS,
                p.speed_scale(),
                format::shown(p.segment_length)
            )));
        }
        if springs || !defaulted {
            params::within("--stiffness", p.stiffness, 1.0 / max, MAX_STIFFNESS, "1/s²")?;
        }
        Ok(())
    }

    /// The frame rate and duration: at least one frame, at most [`params::MAX_STEPS`].
    fn validate_frames(&self) -> Result<(), Invalid> {
        params::positive("--rate", self.rate, "Hz")?;
        params::positive("--duration", self.duration, "s")?;
        let frames = self.duration * self.rate;
        if frames < 1.0 {
            return Err(Invalid::Usage(format!(
                "--rate {} Hz over --duration {} s is less than one frame: raise --rate or lengthen --duration",
                format::shown(self.rate),
                format::shown(self.duration)
            )));
        }
        if frames > params::MAX_STEPS {
            return Err(Invalid::Usage(format!(
                "--rate {} Hz over --duration {} s is {frames:.2e} frames; at most {:.0e} are allowed",
                format::shown(self.rate),
                format::shown(self.duration),
                params::MAX_STEPS
            )));
        }
        params::time(1.0 / self.rate, self.duration, self.fps, 1)
    }

    /// The memory the run's state takes [B]: per node and method, position, previous position
    /// and velocity (3 × 24 B).
    pub fn memory_bytes(&self) -> f64 {
        (self.params.strands * self.params.nodes) as f64 * self.methods.len() as f64 * 72.0
    }

    pub fn frames(&self) -> u64 {
        ((self.duration * self.rate).round() as u64).max(1)
    }
    pub fn step_dt(&self) -> f64 {
        1.0 / (self.rate * self.substeps as f64)
    }
    /// One tick per simulation frame; series every frame; 3D frames at `fps`.
    pub fn schedule(&self) -> Schedule {
        Schedule {
            total: self.frames(),
            fps: self.fps,
            plot_stride: 1,
            clock: Clock::Rate(self.rate),
        }
    }
}

/// The substeps a simulation step `--dt` means at `rate` frames per second: 1/(rate·dt), which
/// must be a whole number (within round-off), and must agree with `substeps` when that is given
/// too. A refusal names the nearest steps that are allowed.
pub fn substeps_for_dt(rate: f64, dt: f64, substeps: Option<u32>) -> Result<u32, Invalid> {
    params::positive("--dt", dt, "s")?;
    params::positive("--rate", rate, "Hz")?;
    let n = 1.0 / (rate * dt);
    let whole = n.round();
    let step = |k: f64| {
        let plural = if k == 1.0 { "" } else { "s" };
        format!("{} ({k} substep{plural})", format::shown(1.0 / (rate * k)))
    };
    if !(1.0..=1e6).contains(&whole) || (n - whole).abs() > 1e-9 * n {
        let below = n.floor().max(1.0);
        let nearest = if n < 1.0 {
            step(1.0)
        } else {
            format!("{} or {}", step(below), step(below + 1.0))
        };
        return Err(Invalid::param(
            "--dt",
            format::shown(dt),
            format!(
                "a hair step is 1/(rate·substeps), and at --rate {} this is {} substeps per frame, \
                 not a whole number; nearest allowed: --dt {nearest}",
                format::shown(rate),
                format::shown(n)
            ),
        ));
    }
    let whole = whole as u32;
    match substeps {
        Some(given) if given != whole => Err(Invalid::Usage(format!(
            "--dt {} and --substeps {given} disagree: at --rate {} that step is {whole} substeps \
             per frame, and --substeps {given} is --dt {}; give one of them",
            format::shown(dt),
            format::shown(rate),
            format::shown(1.0 / (rate * f64::from(given)))
        ))),
        _ => Ok(whole),
    }
}

/// The plotted quantities, in order.
pub const QUANTITIES: [&str; 3] = ["max_stretch", "max_penetration", "specific_kinetic_energy"];

/// One method's hair and the largest values measured on it.
pub struct HairLane {
    pub hair: Hair,
    /// Largest values over the accepted frames; the kinetic energy is the last frame's.
    pub worst: HairStats,
}

/// A hair run.
pub struct HairScene {
    pub config: HairConfig,
}

impl HairScene {
    pub fn new(config: HairConfig) -> Self {
        HairScene { config }
    }
}

impl Scene for HairScene {
    type Lane = HairLane;

    fn name(&self) -> &'static str {
        "hair"
    }

    fn schedule(&self) -> Schedule {
        self.config.schedule()
    }

    fn lanes(&self) -> Vec<(&'static str, HairLane)> {
        self.config
            .methods
            .iter()
            .map(|&m| {
                let lane = HairLane {
                    hair: Hair::new(self.config.params.clone(), m),
                    worst: HairStats::default(),
                };
                (m.name(), lane)
            })
            .collect()
    }

    fn quantities(&self, _lane: &HairLane) -> &'static [&'static str] {
        &QUANTITIES
    }

    /// The plots start at the first frame (nothing has moved at 0).
    fn initial(&self, _lane: &HairLane) -> Option<Vec<f64>> {
        None
    }

    /// One frame at a time: a frame is milliseconds of work, and measuring it outside the timed
    /// step needs its state.
    fn max_block(&self) -> u64 {
        1
    }

    fn windows(&self) -> Windows {
        Windows::with(&self.config.window)
    }

    fn advance(&self, lane: &mut HairLane, _first: u64, _len: usize) {
        let dt = self.config.step_dt();
        for _ in 0..self.config.substeps {
            lane.hair.step(dt);
        }
    }

    fn check(&self, lane: &mut HairLane, first: u64, _len: usize, out: &mut Sampler) -> Checked {
        let st = lane.hair.stats();
        if !st.finite || st.max_stretch > STRETCH_BOUND {
            let why = if st.finite {
                format!("stretch reached {:.3e}", st.max_stretch)
            } else {
                "state not finite".into()
            };
            return Checked {
                divergence: Some(why),
                ..Checked::default()
            };
        }
        let w = &mut lane.worst;
        w.max_stretch = w.max_stretch.max(st.max_stretch);
        w.max_penetration = w.max_penetration.max(st.max_penetration);
        w.max_root_error = w.max_root_error.max(st.max_root_error);
        w.kinetic_energy = st.kinetic_energy;
        let row = [st.max_stretch, st.max_penetration, st.kinetic_energy];
        out.push(first, &row);
        Checked::all(1)
    }
}
