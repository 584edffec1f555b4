//! Each scene's flags. A scene's flag struct doubles as its table in a scene file
//! (`--config FILE.toml`): every field is optional, so a value comes from a flag, the file, a
//! preset or the scene's default, in that order ([`PendulumArgs::over`]). Defaults are read
//! from the scene's `Default` ([`PendulumArgs::defaults`]), never typed here.

use clap::Args;
use serde::{Deserialize, Serialize};

use super::{Magnitude, Vector};
use crate::integrate::{Method, MethodOptions};
use crate::scene::hair::run::HairConfig;
use crate::scene::hair::{HairMethod, HeadMotion, Solver};
use crate::scene::params::dedup_methods;
use crate::scene::pendulum::run::{DEFAULT_THETA0_DEGREES, PendulumConfig};
use crate::scene::rope::run::{RopeConfig, RopeLayout};

/// `a.over(b)`: a's given values, b's for the rest.
macro_rules! overlay {
    ($ty:ident { $($field:ident),* $(,)? } $(nested { $($inner:ident),* })?) => {
        impl $ty {
            /// These values where given, `below`'s elsewhere.
            pub fn over(self, below: Self) -> Self {
                $ty {
                    $($field: self.$field.or(below.$field),)*
                    $($($inner: self.$inner.over(below.$inner),)*)?
                }
            }
        }
    };
}

/// The pendulum's start: the flags `physlab pendulum` and `physlab study` share.
#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct PendulumStart {
    /// Initial angle θ0 from straight down [degrees], within ±1000 turns, taken into
    /// (-180°, 180°] (so 190° is -170°). A release from rest is compared with the exact elliptic
    /// solution; a start with ω0 ≠ 0, or at exactly 180°, with a fine-step RK4 one
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub theta0: Option<f64>,

    /// Initial angular velocity ω0 [rad/s]
    #[arg(long, value_name = "RAD/S", allow_negative_numbers = true)]
    pub omega0: Option<f64>,
}

/// The rope's size and material: the flags `physlab rope` and `physlab study` share.
#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct RopeBody {
    /// Number of point masses, ≥ 2
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub nodes: Option<usize>,

    /// Mass of each node [kg]
    #[arg(long, value_name = "KG", allow_negative_numbers = true)]
    pub mass: Option<f64>,

    /// Spring stiffness ks [N/m]
    #[arg(long, value_name = "N/M", allow_negative_numbers = true)]
    pub stiffness: Option<f64>,

    /// Spring damping kd on the relative velocity along each spring [N·s/m]
    #[arg(long, value_name = "N·S/M", allow_negative_numbers = true)]
    pub spring_damping: Option<f64>,

    /// Air drag ka, force -ka·v on every node [N·s/m]
    #[arg(long, value_name = "N·S/M", allow_negative_numbers = true)]
    pub air_drag: Option<f64>,
}

/// How the pendulum and the rope are stepped, sampled and drawn: the flags both take.
#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct StepFlags {
    /// Time step dt [s], the same for every method
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Simulated time [s]; the run takes round(duration / dt) steps
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// How often the 3D state is logged [Hz of simulated time]
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// Plot every Nth step (thinned further to at most 10,000 points per series)
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub plot_every: Option<u64>,

    /// Methods to run, comma-separated (the names are listed from the registry by `cli::command`)
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<Method>>,

    /// Verlet's damping factor d in x1 = x0 + (1-d)(x0 - x_-1) + a dt², 0 ≤ d < 1
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub verlet_damping: Option<f64>,

    /// dopri5's relative tolerance per substep (the absolute one equals it)
    #[arg(long, value_name = "TOL", allow_negative_numbers = true)]
    pub rtol: Option<f64>,
}

// No `deny_unknown_fields` here or in the flattened structs (serde does not support it with
// `flatten`): scene files are checked for unknown keys in `app::file` instead.
#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct PendulumArgs {
    /// Gravitational acceleration g [m/s²], or the z-up vector x,y,z the rope and hair take
    /// (e.g. 0,0,-9.81), of which the pendulum uses the length |g| (it swings in the plane of
    /// gravity; θ is measured from the direction gravity points)
    #[arg(long, value_name = "G|X,Y,Z", allow_hyphen_values = true)]
    pub gravity: Option<Magnitude>,

    /// Rod length L, pivot to bob [m]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub length: Option<f64>,

    #[command(flatten)]
    #[serde(flatten)]
    pub initial: PendulumStart,

    #[command(flatten)]
    #[serde(flatten)]
    pub step: StepFlags,
}

/// Parameter sets that reproduce a known setup; flags given with a preset override it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RopePreset {
    /// GAMES101 assignment 8 (seed 003): 16 nodes from (0,0,200) to (-400,0,200), mass 1, ks
    /// 100, no spring damping or drag, gravity (0,0,-1) (the assignment's 2D x,y is x,z here),
    /// dt = 1/64 with 64 steps per frame, node 0 pinned, Verlet damping 0.00005, 20 time units
    Games101,
}

#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct RopeArgs {
    /// Start from a known parameter set; flags given as well override it
    #[arg(long, value_enum)]
    pub preset: Option<RopePreset>,

    #[command(flatten)]
    #[serde(flatten)]
    pub body: RopeBody,

    /// First node's position x,y,z [m], z up
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub start: Option<Vector>,

    /// Last node's position x,y,z [m], z up; nodes are spaced evenly, and that spacing is every
    /// spring's rest length
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub end: Option<Vector>,

    /// Gravitational acceleration x,y,z [m/s²], z up like every scene
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub gravity: Option<Vector>,

    /// Indices of pinned nodes, comma-separated, e.g. 0,15 for both ends
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "LIST",
        allow_hyphen_values = true
    )]
    pub pinned: Option<Vec<usize>>,

    #[command(flatten)]
    #[serde(flatten)]
    pub step: StepFlags,

    /// Newton iterations per implicit-Euler step: 1 = linearised backward Euler
    /// (Baraff–Witkin), which is not unconditionally stable (it diverges on the default rope at
    /// dt = 0.3 s); more refine towards exact backward Euler, stopping at tolerance
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub newton_iterations: Option<u32>,

    /// Where each method's rope is drawn: side-by-side or overlay
    #[arg(long, value_name = "LAYOUT")]
    pub layout: Option<RopeLayout>,
}

#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HairArgs {
    /// Number of strands, rooted by a golden-angle spiral over the upper head
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub strands: Option<usize>,

    /// Nodes per strand, the root included
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub nodes: Option<usize>,

    /// Rest length of every segment [m]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub segment_length: Option<f64>,

    /// Head (sphere) radius [m]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub head_radius: Option<f64>,

    /// Scripted head path: smooth pulses that start and end at rest
    #[arg(long, value_name = "MOTION")]
    pub head_motion: Option<HeadMotion>,

    /// Wind as an acceleration x,y,z on every node [m/s²], z up
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub wind: Option<Vector>,

    /// Gust strength as a fraction of the wind: the wind varies by ±this, smoothly and
    /// deterministically
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub gust: Option<f64>,

    /// Gravitational acceleration x,y,z [m/s²], z up
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub gravity: Option<Vector>,

    /// Velocity damping rate c [1/s]: velocities decay as exp(-c t)
    #[arg(long, value_name = "1/S", allow_negative_numbers = true)]
    pub damping: Option<f64>,

    /// How verlet solves its length constraints: direct (each strand's constraints together,
    /// Newton on the multipliers, tridiagonal, O(nodes), the tensions applied along the end-of-step
    /// segments, then an exact root-to-tip finish; holds
    /// length to round-off) or gauss-seidel (relaxation sweeps from root to tip, today's PBD, kept
    /// to measure the trade: 4 sweeps leave stretches of ~1.7 at 60 Hz)
    #[arg(long, value_name = "SOLVER")]
    pub solver: Option<Solver>,

    /// Newton steps (verlet with --solver direct) or Gauss–Seidel sweeps (verlet with --solver
    /// gauss-seidel) per step; ftl needs one pass, implicit-euler iterates to tolerance (≤ 40).
    /// Default 2: two Newton steps measure the tensions better than one, so the exact finish
    /// moves nodes less; with gauss-seidel, 2 sweeps (raise it: see `physlab study hair`)
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub iterations: Option<u32>,

    /// Spring methods (semi-implicit-euler, implicit-euler): segment stiffness per unit node mass
    /// k/m [1/s²]. semi-implicit-euler takes inner steps h with h²·4k/m + 2h·4kd/m < 4 [default:
    /// the springs' wave speed ℓ0·√(k/m) at 100 × the speed the head and the pull of gravity and
    /// wind give a strand (the summary says it), at least 4e8: the stated 1e-2 stretch bound]
    #[arg(long, value_name = "1/S²", allow_negative_numbers = true)]
    pub stiffness: Option<f64>,

    /// Spring methods: damping per unit node mass kd/m [1/s] on the relative velocity along each
    /// segment (semi-implicit-euler; implicit-euler damps the stiff modes by itself)
    #[arg(long, value_name = "1/S", allow_negative_numbers = true)]
    pub spring_damping: Option<f64>,

    /// Steps per simulation frame
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub substeps: Option<u32>,

    /// Time step dt [s] of the simulation, as in every scene: sets --substeps to 1/(rate·dt),
    /// which must be a whole number [default: 1/(rate·substeps)]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Simulation frames per simulated second [Hz]
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub rate: Option<f64>,

    /// How often the 3D state is logged [Hz of simulated time]; plots get every frame
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// Simulated time [s] (one tour of the head takes 8 s)
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// Collision margin as a fraction of the head radius
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub margin: Option<f64>,

    /// Methods to run, comma-separated: verlet, semi-implicit-euler, implicit-euler, ftl
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<HairMethod>>,

    /// Strands drawn in 3D, spread evenly over the head; every strand is still simulated and
    /// measured [default: as many as keep the 3D part of the recording under 180 MB]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub log_strands: Option<usize>,
}

overlay!(PendulumStart { theta0, omega0 });

overlay!(StepFlags {
    dt,
    duration,
    fps,
    plot_every,
    methods,
    verlet_damping,
    rtol
});

overlay!(PendulumArgs { gravity, length } nested { initial, step });

impl PendulumArgs {
    /// Every value at the scene's default.
    pub fn defaults() -> Self {
        let c = PendulumConfig::default();
        PendulumArgs {
            gravity: Some(Magnitude(c.params.gravity)),
            length: Some(c.params.length),
            initial: PendulumStart {
                theta0: Some(DEFAULT_THETA0_DEGREES),
                omega0: Some(c.params.omega0),
            },
            step: StepFlags::given(c.dt, c.duration, c.fps, c.plot_every, c.methods, c.options),
        }
    }

    /// The config with these values where given, the defaults elsewhere (not yet validated).
    pub fn config(&self) -> PendulumConfig {
        let mut c = PendulumConfig::default();
        let p = &mut c.params;
        set(&mut p.gravity, self.gravity.map(|g| g.0));
        set(&mut p.length, self.length);
        if let Some(d) = self.initial.theta0 {
            (p.theta0, p.theta0_low) = crate::scene::pendulum::theta0_from_degrees(d);
        }
        set(&mut p.omega0, self.initial.omega0);
        self.step.set(
            (&mut c.dt, &mut c.duration, &mut c.fps, &mut c.plot_every),
            &mut c.methods,
            &mut c.options,
        );
        c
    }
}

overlay!(RopeBody {
    nodes,
    mass,
    stiffness,
    spring_damping,
    air_drag
});

overlay!(RopeArgs {
    preset, start, end, gravity, pinned, newton_iterations, layout
} nested { body, step });

impl RopeArgs {
    /// Every value at the scene's default.
    pub fn defaults() -> Self {
        let c = RopeConfig::default();
        let p = c.params;
        RopeArgs {
            preset: None,
            body: RopeBody {
                nodes: Some(p.nodes),
                mass: Some(p.mass),
                stiffness: Some(p.stiffness),
                spring_damping: Some(p.spring_damping),
                air_drag: Some(p.air_drag),
            },
            start: Some(Vector(p.start)),
            end: Some(Vector(p.end)),
            gravity: Some(Vector(p.gravity)),
            pinned: Some(p.pinned),
            newton_iterations: Some(p.newton_iterations),
            layout: Some(c.layout),
            step: StepFlags::given(c.dt, c.duration, c.fps, c.plot_every, c.methods, c.options),
        }
    }

    /// These values over the preset they name (if any) over the defaults, every field given.
    pub fn effective(self) -> Self {
        let below = match self.preset {
            Some(RopePreset::Games101) => games101_preset().over(RopeArgs::defaults()),
            None => RopeArgs::defaults(),
        };
        self.over(below)
    }

    /// The config with these values where given, the defaults elsewhere (not yet validated).
    pub fn config(&self) -> RopeConfig {
        let mut c = RopeConfig::default();
        let p = &mut c.params;
        let b = &self.body;
        set(&mut p.nodes, b.nodes);
        set(&mut p.start, self.start.map(|v| v.0));
        set(&mut p.end, self.end.map(|v| v.0));
        set(&mut p.mass, b.mass);
        set(&mut p.stiffness, b.stiffness);
        set(&mut p.spring_damping, b.spring_damping);
        set(&mut p.air_drag, b.air_drag);
        set(&mut p.gravity, self.gravity.map(|v| v.0));
        if let Some(pinned) = &self.pinned {
            p.pinned = pinned.clone();
            p.pinned.sort_unstable();
            p.pinned.dedup();
        }
        set(&mut p.newton_iterations, self.newton_iterations);
        set(&mut c.layout, self.layout);
        self.step.set(
            (&mut c.dt, &mut c.duration, &mut c.fps, &mut c.plot_every),
            &mut c.methods,
            &mut c.options,
        );
        c
    }
}

/// The GAMES101 assignment's parameters (a layer over the defaults).
pub fn games101_preset() -> RopeArgs {
    RopeArgs {
        body: RopeBody {
            nodes: Some(16),
            mass: Some(1.0),
            stiffness: Some(100.0),
            spring_damping: Some(0.0),
            air_drag: Some(0.0),
        },
        start: Some(Vector(glam::DVec3::new(0.0, 0.0, 200.0))),
        end: Some(Vector(glam::DVec3::new(-400.0, 0.0, 200.0))),
        gravity: Some(Vector(glam::DVec3::new(0.0, 0.0, -1.0))),
        pinned: Some(vec![0]),
        step: StepFlags {
            dt: Some(1.0 / 64.0),
            fps: Some(1.0), // one frame per time unit = 64 steps per frame
            duration: Some(20.0),
            plot_every: Some(1),
            verlet_damping: Some(0.00005),
            ..StepFlags::default()
        },
        ..RopeArgs::default()
    }
}

overlay!(HairArgs {
    strands,
    nodes,
    segment_length,
    head_radius,
    head_motion,
    wind,
    gust,
    gravity,
    damping,
    solver,
    iterations,
    stiffness,
    spring_damping,
    substeps,
    dt,
    rate,
    fps,
    duration,
    margin,
    methods,
    log_strands
});

impl HairArgs {
    /// Every value at the scene's default.
    pub fn defaults() -> Self {
        let c = HairConfig::default();
        let p = c.params;
        HairArgs {
            strands: Some(p.strands),
            nodes: Some(p.nodes),
            segment_length: Some(p.segment_length),
            head_radius: Some(p.head_radius),
            head_motion: Some(p.motion),
            wind: Some(Vector(p.wind)),
            gust: Some(p.gust),
            gravity: Some(Vector(p.gravity)),
            damping: Some(p.damping),
            solver: Some(p.solver),
            iterations: Some(p.iterations),
            // Follows the other parameters (HairParams::default_stiffness).
            stiffness: None,
            spring_damping: Some(p.spring_damping),
            substeps: Some(c.substeps),
            // Said by --substeps and --rate; a default here would contradict a given --substeps.
            dt: None,
            rate: Some(c.rate),
            fps: Some(c.fps),
            duration: Some(c.duration),
            margin: Some(p.margin),
            methods: Some(c.methods),
            // What the recording draws, not what is simulated: sized to the run when not given.
            log_strands: None,
        }
    }

    /// The config with these values where given, the defaults elsewhere (not yet validated).
    pub fn config(&self) -> HairConfig {
        let mut c = HairConfig::default();
        let p = &mut c.params;
        set(&mut p.strands, self.strands);
        set(&mut p.nodes, self.nodes);
        set(&mut p.segment_length, self.segment_length);
        set(&mut p.head_radius, self.head_radius);
        set(&mut p.motion, self.head_motion);
        set(&mut p.wind, self.wind.map(|v| v.0));
        set(&mut p.gust, self.gust);
        set(&mut p.gravity, self.gravity.map(|v| v.0));
        set(&mut p.damping, self.damping);
        set(&mut p.solver, self.solver);
        set(&mut p.iterations, self.iterations);
        set(&mut p.spring_damping, self.spring_damping);
        set(&mut p.margin, self.margin);
        p.stiffness = self.stiffness.unwrap_or_else(|| p.default_stiffness());
        set(&mut c.substeps, self.substeps);
        set(&mut c.rate, self.rate);
        set(&mut c.fps, self.fps);
        set(&mut c.duration, self.duration);
        if let Some(m) = &self.methods {
            c.methods = dedup_methods(m);
        }
        c
    }
}

/// `*slot = value` when a value was given.
fn set<T>(slot: &mut T, value: Option<T>) {
    if let Some(v) = value {
        *slot = v;
    }
}

impl StepFlags {
    /// Every value given: a scene's defaults.
    fn given(
        dt: f64,
        duration: f64,
        fps: f64,
        plot_every: u64,
        methods: Vec<Method>,
        options: MethodOptions,
    ) -> Self {
        StepFlags {
            dt: Some(dt),
            duration: Some(duration),
            fps: Some(fps),
            plot_every: Some(plot_every),
            methods: Some(methods),
            verlet_damping: Some(options.verlet_damping),
            rtol: Some(options.rtol),
        }
    }

    /// Sets a config's (dt, duration, fps, plot_every), methods and options where given.
    fn set(
        &self,
        (dt, duration, fps, plot_every): (&mut f64, &mut f64, &mut f64, &mut u64),
        methods: &mut Vec<Method>,
        options: &mut MethodOptions,
    ) {
        set(dt, self.dt);
        set(duration, self.duration);
        set(fps, self.fps);
        set(plot_every, self.plot_every);
        if let Some(m) = &self.methods {
            *methods = dedup_methods(m);
        }
        set(&mut options.verlet_damping, self.verlet_damping);
        set(&mut options.rtol, self.rtol);
    }
}
