//! The rope as a [`Scene`]: every chosen method stepping its own copy of the rope over the same
//! time grid, with energy and strain measured and checked after every step.

use super::implicit::Workspace;
use super::{Rope, RopeParams};
use crate::integrate::{Counts, Integrator, Method, MethodOptions};
use crate::scene::harness::{Checked, Sampler, Scene, Schedule, Window, Windows};
use crate::scene::params::{self, Invalid};

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

/// Where each method's rope is drawn (a presentation choice; it does not change the numbers).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RopeLayout {
    /// Each method in its own slot, rows of four.
    #[default]
    SideBySide,
    /// All methods at the same place, told apart by colour.
    Overlay,
}

impl RopeLayout {
    pub const ALL: [(&'static str, RopeLayout); 2] = [
        ("side-by-side", RopeLayout::SideBySide),
        ("overlay", RopeLayout::Overlay),
    ];
}

/// Everything a rope run needs; its serialised form is the scene file's `[rope]` table.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct RopeConfig {
    /// The known setup the other values start from, if one was named.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<RopePreset>,
    #[serde(flatten)]
    pub params: RopeParams,
    /// Step [s].
    pub dt: f64,
    /// Simulated time [s].
    pub duration: f64,
    /// 3D frames per simulated second.
    pub fps: f64,
    /// Plot every Nth step (thinned further beyond MAX_PLOT_POINTS).
    pub plot_every: u64,
    /// Stretches kept whole when the plots are aggregated (`--window`).
    pub window: Vec<Window>,
    /// How the recording lays the methods out.
    pub layout: RopeLayout,
    pub methods: Vec<Method>,
    #[serde(flatten)]
    pub options: MethodOptions,
}

impl Default for RopeConfig {
    fn default() -> Self {
        RopeConfig {
            preset: None,
            params: RopeParams::default(),
            dt: 1e-3,
            duration: 10.0,
            fps: 30.0,
            plot_every: 5,
            window: Vec::new(),
            layout: RopeLayout::default(),
            methods: Method::DEFAULT.to_vec(),
            options: MethodOptions::default(),
        }
    }
}

/// Refuses a method that needs forces of position alone (the Nyström methods) on a rope whose
/// spring damping or air drag makes its forces depend on the velocity.
pub fn refuse_position_only_methods(p: &RopeParams, methods: &[Method]) -> Result<(), Invalid> {
    let Some(m) = methods
        .iter()
        .find(|m| !m.info().accepts_velocity_dependent())
    else {
        return Ok(());
    };
    let causes = velocity_causes(p);
    let (make, fix) = match causes.len() {
        0 => return Ok(()),
        1 => ("makes", "set it to 0"),
        _ => ("make", "set both to 0"),
    };
    Err(Invalid::param(
        "--methods",
        m.name(),
        format!(
            "{m} needs forces of position alone; the rope's {} {make} them depend on velocity; \
             {fix} or pick another method",
            causes.join(" and ")
        ),
    ))
}

/// The rope's flags that make its forces depend on the velocity, as typed.
fn velocity_causes(p: &RopeParams) -> Vec<String> {
    [
        ("--spring-damping", p.spring_damping),
        ("--air-drag", p.air_drag),
    ]
    .into_iter()
    .filter(|&(_, v)| v != 0.0)
    .map(|(flag, v)| format!("{flag} {}", crate::format::shown(v)))
    .collect()
}

/// One line per method of `methods` whose order drops on this rope (registry
/// `order_drop`): the order to expect, what it pays for it, and why. Said before the run
/// starts, as the Nyström methods are refused.
pub fn order_drops(p: &RopeParams, methods: &[Method]) -> Vec<String> {
    let causes = velocity_causes(p);
    if causes.is_empty() {
        return Vec::new();
    }
    (methods.iter())
        .filter_map(|m| {
            let i = m.info();
            i.order_drop().map(|why| {
                format!(
                    "{m} is order {} on this rope, not {} ({} evaluations per step): the rope's \
                     {} make its forces depend on velocity, and {why}",
                    i.order_velocity_dependent,
                    i.order,
                    i.evals_per_step,
                    causes.join(" and ")
                )
            })
        })
        .collect()
}

/// Nodes beyond which a rope is refused (~1 kB per node per method including the implicit solver).
pub const MAX_NODES: usize = 10_000_000;

/// Parameter sets that reproduce a known setup; values given with a preset override it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RopePreset {
    /// GAMES101 assignment 8: 16 nodes from (0,0,200) to (-400,0,200), mass 1, ks 100, no
    /// spring damping or drag, gravity (0,0,-1) (the assignment's 2D x,y is x,z here), dt = 1/64
    /// with 64 steps per frame, node 0 pinned, Verlet damping 0.00005, 20 time units.
    Games101,
}

impl RopePreset {
    pub const ALL: [(&'static str, RopePreset); 1] = [("games101", RopePreset::Games101)];

    /// The configuration the preset starts from.
    pub fn config(self) -> RopeConfig {
        match self {
            RopePreset::Games101 => RopeConfig {
                preset: Some(self),
                params: RopeParams {
                    nodes: 16,
                    mass: 1.0,
                    stiffness: 100.0,
                    spring_damping: 0.0,
                    air_drag: 0.0,
                    start: glam::DVec3::new(0.0, 0.0, 200.0),
                    end: glam::DVec3::new(-400.0, 0.0, 200.0),
                    gravity: glam::DVec3::new(0.0, 0.0, -1.0),
                    pinned: vec![0],
                    ..RopeParams::default()
                },
                dt: 1.0 / 64.0,
                fps: 1.0, // one frame per time unit = 64 steps per frame
                duration: 20.0,
                plot_every: 1,
                options: MethodOptions {
                    verlet_damping: 0.00005,
                    ..MethodOptions::default()
                },
                ..RopeConfig::default()
            },
        }
    }
}

impl params::SceneConfig for RopeConfig {
    fn preset_base(&self) -> Option<Self> {
        self.preset.map(RopePreset::config)
    }

    fn settle(&mut self, _given: &dyn Fn(&str) -> bool) -> Result<(), Invalid> {
        self.params.pinned.sort_unstable();
        self.params.pinned.dedup();
        self.methods = params::dedup_methods(&self.methods);
        Ok(())
    }

    fn validate(&self) -> Result<(), Invalid> {
        let p = &self.params;
        params::some_methods(&self.methods, &Method::names().collect::<Vec<_>>())?;
        refuse_position_only_methods(p, &self.methods)?;
        params::count_within("--nodes", p.nodes as u64, 2, MAX_NODES as u64)?;
        let rule = "must differ from --start (the spacing is the springs' rest length)";
        let end = crate::format::shown_vector(p.end);
        params::refuse_unless((p.end - p.start).length() != 0.0, "--end", end, rule)?;
        let max = params::MAX_MAGNITUDE;
        for (option, v) in [
            ("--start", p.start),
            ("--end", p.end),
            ("--gravity", p.gravity),
        ] {
            params::vector(option, v, "")?;
        }
        params::within("--mass", p.mass, 1.0 / max, max, "kg")?;
        // A rope without springs is no rope: every method would let it fall apart.
        params::within("--stiffness", p.stiffness, 1.0 / max, 1e12, "N/m")?;
        params::within("--spring-damping", p.spring_damping, 0.0, max, "N·s/m")?;
        params::within("--air-drag", p.air_drag, 0.0, max, "N·s/m")?;
        if let Some(&bad) = p.pinned.iter().find(|&&i| i >= p.nodes) {
            let last = p.nodes - 1;
            let rule = format!("node index out of range; the rope has nodes 0..={last}");
            return Err(Invalid::param("--pinned", bad, rule));
        }
        params::at_least_one("--newton-iterations", p.newton_iterations.into())?;
        params::time(self.dt, self.duration, self.fps, p.nodes)?;
        params::own_step(self.options.step, self.dt, self.duration, p.nodes)?;
        params::memory(
            &format!("--nodes {} with {} methods", p.nodes, self.methods.len()),
            self.memory_bytes(),
            "use fewer --nodes or --methods",
        )?;
        self.schedule().check_windows(&self.window)?;
        params::plot_and_options(self.plot_every, &self.options)
    }

    /// A step beyond 2/ω_max, the stiffest spring mode's scale, for the methods stable only
    /// below some ω dt (or never): they are expected to blow up.
    fn step_warning(&self) -> Option<String> {
        use crate::integrate::Stability;
        let (omega_max, _) = self.params.omega_max();
        let limit = 2.0 / omega_max;
        let bounded: Vec<&str> = (self.methods.iter())
            .filter(|m| matches!(m.info().stability, Stability::Below(_) | Stability::Never))
            .map(|m| m.name())
            .collect();
        let (flag, h) = params::fixed_step(self.dt, &self.options);
        let step = (h > limit && !bounded.is_empty()).then(|| {
            format!(
                "{flag} {} s exceeds 2/ω_max = {} s, the scale of the rope's stiffest spring mode \
                 (ω_max = {} rad/s): {} are stable only below about that step and are expected \
                 to diverge",
                crate::format::shown(h),
                crate::format::seconds(limit),
                crate::format::seconds(omega_max),
                bounded.join(", ")
            )
        });
        // Both said up front, one warning a line.
        let drops = order_drops(&self.params, &self.methods);
        let warnings: Vec<String> = step.into_iter().chain(drops).collect();
        (!warnings.is_empty()).then(|| warnings.join("\nwarning: "))
    }
}

impl RopeConfig {
    pub fn schedule(&self) -> Schedule {
        Schedule::fixed_step(self.dt, self.duration, self.fps, self.plot_every)
    }

    /// The memory the run's state takes [B]: per node, the start positions and pinned flags,
    /// each method's vectors, and the implicit solve's workspace when an implicit method runs.
    pub fn memory_bytes(&self) -> f64 {
        let coordinates = 3.0 * self.params.nodes as f64;
        let vectors: usize = self
            .methods
            .iter()
            .map(|&m| Integrator::vectors(m) + Integrator::option_vectors(m, &self.options))
            .sum();
        let workspace = if self.methods.iter().any(|m| m.info().implicit) {
            Workspace::BYTES_PER_NODE
        } else {
            0.0
        };
        self.params.nodes as f64 * (25.0 + workspace) + coordinates * 8.0 * vectors as f64
    }
}

/// Coordinates (m) and velocities (m/s) below this are set to zero at the start of every block.
/// A rope pinned at one end swings down and its swing decays exponentially about x = 0 for
/// ever; after about 5,000 s at the defaults its x components are below 1e-110 and their
/// products subnormal, which makes every later step 2–3 times dearer. 1e-90 keeps the products
/// of two or three coordinates normal, and is far below anything a run reports: the energy,
/// of order 10 J, is summed to a relative 1e-16.
pub const NEGLIGIBLE: f64 = 1e-90;

/// The plotted quantities, in order: the energy E, the dissipated work W, the balance error
/// (E + W − E0) / scale (the method's own energy error, DESIGN principle 7; E − E0 is E less a
/// constant, in the summary), the largest strain.
pub const QUANTITIES: [&str; 4] = ["energy", "work", "energy_balance", "max_strain"];

/// One method's rope and what has been measured on it.
pub struct RopeLane {
    pub method: Method,
    integrator: Integrator,
    /// Sampled rows of the current block: (step, the [`QUANTITIES`]).
    rows: Vec<(u64, [f64; 4])>,
    /// The failed check of the current block: its offset and why.
    failed: Option<(usize, String)>,
    /// The first step of the current block whose implicit solve missed its tolerance.
    first_miss: Option<usize>,
    /// Largest strain over every accepted step.
    pub max_strain: f64,
    /// Energy after the last accepted step [J].
    pub final_energy: f64,
    /// Work the damping and drag dissipated up to the last accepted step [J].
    pub final_work: f64,
    /// Largest |E + W − E0| over every accepted step [J].
    pub max_balance_error: f64,
}

impl RopeLane {
    /// The nodes' positions (flat, 3 per node).
    pub fn positions(&self) -> &[f64] {
        let x = self.integrator.position();
        &x[..x.len() / 3 * 3]
    }

    /// E + W − E0 after the last accepted step [J]: the method's error in the energy balance.
    pub fn balance_error(&self, initial_energy: f64) -> f64 {
        self.final_energy + self.final_work - initial_energy
    }
}

/// A rope run.
pub struct RopeScene {
    pub config: RopeConfig,
    pub rope: Rope,
    pub initial_positions: Vec<f64>,
    pub initial_energy: f64,
    /// See [`energy_scale`].
    pub energy_scale: f64,
    /// See [`strain_bound`].
    pub strain_bound: f64,
    /// Highest angular frequency of the linearised springs [rad/s], and whether it is exact
    /// ([`RopeParams::omega_max`]).
    pub omega_max: f64,
    pub omega_max_is_exact: bool,
    /// Largest damping rate of the linearised chain [1/s]: the damping matrix's Gershgorin bound
    /// (4 kd + ka)/m. Explicit steps also need it well below 2/dt, whatever the springs allow.
    pub damping_rate_max: f64,
}

impl RopeScene {
    pub fn new(config: RopeConfig) -> Self {
        let rope = Rope::balanced(config.params.clone());
        let x0 = config.params.initial_positions();
        let v0 = vec![0.0; x0.len()];
        RopeScene {
            initial_energy: rope.energy(&x0, &v0),
            energy_scale: energy_scale(&rope, &x0, &v0),
            strain_bound: strain_bound(&config.params),
            omega_max: config.params.omega_max().0,
            omega_max_is_exact: config.params.omega_max().1,
            damping_rate_max: (4.0 * config.params.spring_damping + config.params.air_drag)
                / config.params.mass,
            initial_positions: x0,
            rope,
            config,
        }
    }

    /// The failed check at this state, if any: not finite, overstretched, or too energetic.
    fn verdict(&self, x: &[f64], v: &[f64], energy: f64, strain: f64) -> Option<String> {
        let finite = energy.is_finite() && x.iter().chain(v).all(|c| c.is_finite());
        let gained = energy - self.initial_energy;
        if !finite {
            Some("the state is not finite".to_string())
        } else if strain > self.strain_bound {
            Some(format!(
                "a spring's strain reached {strain:.3e} (bound {:.3})",
                self.strain_bound
            ))
        } else if self.energy_scale > 0.0 && gained > ENERGY_GAIN_BOUND * self.energy_scale {
            Some(format!(
                "it gained {gained:.3e} J, over {ENERGY_GAIN_BOUND} × the energy scale {:.3e} J",
                self.energy_scale
            ))
        } else {
            None
        }
    }
}

impl Scene for RopeScene {
    type Lane = RopeLane;

    fn name(&self) -> &'static str {
        "rope"
    }

    fn schedule(&self) -> Schedule {
        self.config.schedule()
    }

    fn windows(&self) -> Windows {
        Windows::with(&self.config.window)
    }

    /// Blocks end at 3D frames, and also after [`params::BLOCK_STEPS`] steps: a block's rows
    /// are held until it is checked.
    fn max_block(&self) -> u64 {
        params::block_ticks(self.config.dt, &self.config.options)
    }

    fn lanes(&self) -> Vec<(&'static str, RopeLane)> {
        // Undamped, the scene's own start serves: no second copy of a large rope's positions.
        let with_work;
        let x0: &[f64] = if self.rope.tracks_work() {
            with_work = self.rope.start().0;
            &with_work
        } else {
            &self.initial_positions
        };
        let v0 = vec![0.0; x0.len()];
        let (dt, options) = (self.config.dt, self.config.options);
        self.config
            .methods
            .iter()
            .map(|&m| {
                let lane = RopeLane {
                    method: m,
                    integrator: Integrator::new(m, &self.rope, x0, &v0, dt, options),
                    rows: Vec::new(),
                    failed: None,
                    first_miss: None,
                    max_strain: self.rope.max_strain(x0),
                    final_energy: self.initial_energy,
                    final_work: 0.0,
                    max_balance_error: 0.0,
                };
                (m.name(), lane)
            })
            .collect()
    }

    fn quantities(&self, _lane: &RopeLane) -> &'static [&'static str] {
        &QUANTITIES
    }

    fn initial(&self, _lane: &RopeLane) -> Option<Vec<f64>> {
        let strain = self.rope.max_strain(&self.initial_positions);
        Some(vec![self.initial_energy, 0.0, 0.0, strain])
    }

    /// Steps and checks every step: a rope cannot keep every step's state, so the O(N) energy
    /// and strain check runs inside the timed loop (ns/step includes it).
    fn advance(&self, lane: &mut RopeLane, first: u64, len: usize) {
        lane.rows.clear();
        lane.failed = None;
        lane.first_miss = None;
        let schedule = self.config.schedule();
        lane.integrator.zero_below(NEGLIGIBLE);
        for k in 0..len {
            let failed_before = lane.integrator.failed_solves();
            lane.integrator.step(&self.rope);
            let (x, v) = (lane.integrator.position(), lane.integrator.velocity());
            let (energy, strain) = self.rope.energy_and_strain(x, v);
            // A miss on the failing step is counted too, so the event log and the summary's
            // count agree.
            if lane.first_miss.is_none() && lane.integrator.failed_solves() > failed_before {
                lane.first_miss = Some(k);
            }
            if let Some(why) = self.verdict(x, v, energy, strain) {
                lane.failed = Some((k, why));
                return;
            }
            lane.max_strain = lane.max_strain.max(strain);
            lane.final_energy = energy;
            lane.final_work = self.rope.work(v);
            let balance = lane.balance_error(self.initial_energy);
            lane.max_balance_error = lane.max_balance_error.max(balance.abs());
            let step = first + k as u64;
            if schedule.samples(step) {
                let relative = balance / self.energy_scale;
                (lane.rows).push((step, [energy, lane.final_work, relative, strain]));
            }
        }
    }

    fn check(&self, lane: &mut RopeLane, _first: u64, len: usize, out: &mut Sampler) -> Checked {
        for (step, row) in &lane.rows {
            out.push(*step, row);
        }
        let (accepted, divergence) = match lane.failed.take() {
            Some((k, why)) => (k, Some(why)),
            None => (len, None),
        };
        let tol = super::implicit::NEWTON_TOL;
        Checked {
            accepted,
            divergence,
            solver_miss: (lane.first_miss)
                .map(|k| (k, format!("max |δv| ≤ {tol:e}·(1 + max |v|)"))),
            // The rope stops stepping at its failing step: its integrator's counts are exact.
            counts: None,
        }
    }

    fn counts(&self, lane: &RopeLane) -> Counts {
        lane.integrator.counts()
    }
}
