//! Each scene once, as the commands see it: its name, how its flags, scene-file table and
//! defaults resolve into a validated configuration, its 3D layout, how it runs and reports.
//! Everything that lists scenes iterates over [`SCENES`]; a new scene is one entry here.

use super::layers::{Given, table_of};
use super::progress::Progress;
use super::{Ran, SceneFile};
use crate::cli::{HairArgs, PendulumArgs, RopeArgs, RunArgs, StepFlags};
use crate::error::Error;
use crate::integrate::{Method, composition_weights};
use crate::record::{self, SceneViews, Staging};
use crate::report;
use crate::scene::hair::HairMethod;
use crate::scene::hair::run::{HairConfig, HairScene};
use crate::scene::params::SceneConfig;
use crate::scene::pendulum::run::{PendulumConfig, PendulumScene};
use crate::scene::rope::run::{RopeConfig, RopeScene};

/// Every scene, in the order `physlab all` runs them.
pub static SCENES: [&SceneKind; 3] = [&PENDULUM, &ROPE, &HAIR];

/// A scene as the commands know it before any parameter is given.
pub struct SceneKind {
    pub name: &'static str,
    /// The recording's application id when it runs alone (the viewer keys layouts by it).
    pub application_id: &'static str,
    pub views: &'static SceneViews,
    /// Its flags as `physlab all` sets them.
    flags: fn(&AllFlags) -> Box<dyn Flags>,
}

impl SceneKind {
    pub fn flags(&self, all: &AllFlags) -> Box<dyn Flags> {
        (self.flags)(all)
    }

    /// Its configuration as `file` (a recording's) sets it, no flag given.
    pub fn as_recorded(&self, file: &SceneFile) -> Resolution {
        self.flags(&AllFlags::default())
            .resolve(file, &RunArgs::default())
    }
}

pub fn scene_named(name: &str) -> Option<&'static SceneKind> {
    SCENES.iter().copied().find(|k| k.name == name)
}

/// Every scene's name: the tables a scene file may hold.
pub fn scene_names() -> Vec<&'static str> {
    SCENES.iter().map(|s| s.name).collect()
}

/// A recording's configuration as a scene file.
pub fn parse_scene_file(text: &str) -> Result<SceneFile, String> {
    SceneFile::parse(text, &scene_names())
}

static PENDULUM: SceneKind = SceneKind {
    name: "pendulum",
    application_id: "physlab-pendulum",
    views: &record::pendulum::VIEWS,
    flags: |all| {
        Box::new(PendulumArgs {
            step: all.step(),
            ..PendulumArgs::default()
        })
    },
};

static ROPE: SceneKind = SceneKind {
    name: "rope",
    application_id: "physlab-rope",
    views: &record::rope::VIEWS,
    flags: |all| {
        Box::new(RopeArgs {
            step: all.step(),
            ..RopeArgs::default()
        })
    },
};

static HAIR: SceneKind = SceneKind {
    name: "hair",
    application_id: "physlab-hair",
    views: &record::hair::VIEWS,
    flags: |all| {
        Box::new(HairArgs {
            dt: all.dt,
            duration: all.duration,
            fps: all.fps,
            methods: all.hair.clone(),
            ..HairArgs::default()
        })
    },
};

/// `physlab all`'s own flags, which override every scene's.
#[derive(Default)]
pub struct AllFlags {
    pub dt: Option<f64>,
    pub duration: Option<f64>,
    pub fps: Option<f64>,
    pub plot_every: Option<u64>,
    pub registry: Option<Vec<Method>>,
    pub hair: Option<Vec<HairMethod>>,
}

impl AllFlags {
    /// As the step flags of the scenes that take the registry's methods.
    fn step(&self) -> StepFlags {
        StepFlags {
            dt: self.dt,
            duration: self.duration,
            fps: self.fps,
            plot_every: self.plot_every,
            methods: self.registry.clone(),
            ..StepFlags::default()
        }
    }
}

pub type Resolution = Result<Box<dyn ReadyScene>, Error>;

pub trait Flags {
    fn kind(&self) -> &'static SceneKind;
    fn resolve(self: Box<Self>, file: &SceneFile, run: &RunArgs) -> Resolution;
}

/// A scene's validated configuration, ready to run.
pub trait ReadyScene: Send {
    fn kind(&self) -> &'static SceneKind;
    fn staging(&self) -> Staging;
    fn fps(&self) -> f64;
    fn methods(&self) -> Vec<&'static str>;
    /// Every effective value, as the scene-file table that runs it again.
    fn table(&self) -> Result<toml::Table, Error>;
    /// The memory its state takes [B] (0 when small by construction).
    fn memory_bytes(&self) -> f64 {
        0.0
    }
    /// Why its step is too large for its shortest time scale, if it is.
    fn step_warning(&self) -> Option<String>;
    fn bulk(&self) -> Bulk;
    fn run(self: Box<Self>, ctx: &mut RunContext) -> anyhow::Result<Ran>;
}

/// What a run does, from its configuration alone (nothing built or stepped).
#[derive(Clone, Copy, Debug, Default)]
pub struct Bulk {
    /// Steps of one node of one method, over the run (a method's fine-step reference too).
    pub node_steps: f64,
    /// Nodes drawn in 3D over every frame drawn and every method.
    pub node_frames: f64,
}

impl Bulk {
    /// A floor on its wall time: blind to adaptive and inner steps and to each method's cost.
    pub fn seconds(&self) -> f64 {
        self.node_steps * crate::scene::params::NODE_STEP_SECONDS
    }

    /// Its recording, at hair's measured bytes per node drawn (the rope wrote 9–10 B).
    pub fn bytes(&self) -> f64 {
        self.node_frames * record::hair::BYTES_PER_NODE_FRAME
    }
}

/// A fixed-step scene's bulk: `nodes` nodes drawn and stepped by each of `methods`.
fn fixed_step_bulk(
    schedule: crate::scene::harness::Schedule,
    step: f64,
    duration: f64,
    nodes: f64,
    methods: usize,
) -> Bulk {
    let methods = methods as f64;
    Bulk {
        node_steps: methods * nodes * duration / step,
        node_frames: methods * nodes * schedule.frames() as f64,
    }
}

pub struct RunContext<'a> {
    pub stream: Option<rerun::RecordingStream>,
    /// Also record wall-clock costs.
    pub timings: bool,
    /// The highest fps of the scenes run.
    pub frame_rate: f64,
    pub quiet: bool,
    pub progress: &'a mut Progress,
    pub pool: &'a rayon::ThreadPool,
    /// A replayed interruption: stop at the first block boundary past this tick.
    pub stop_after: Option<u64>,
}

impl Flags for PendulumArgs {
    fn kind(&self) -> &'static SceneKind {
        &PENDULUM
    }
    fn resolve(self: Box<Self>, file: &SceneFile, run: &RunArgs) -> Resolution {
        refuse_drawing_flags(run, &self.step.drawing_flags())?;
        let config: PendulumConfig = given(&*self, "pendulum", file)?.resolve()?;
        let flags = self.step.method_flags();
        refuse_unread(&flags, &config.methods, &Method::ALL, Method::name)?;
        Ok(Box::new(config))
    }
}

impl Flags for RopeArgs {
    fn kind(&self) -> &'static SceneKind {
        &ROPE
    }
    fn resolve(self: Box<Self>, file: &SceneFile, run: &RunArgs) -> Resolution {
        refuse_drawing_flags(run, &self.step.drawing_flags())?;
        let config: RopeConfig = given(&*self, "rope", file)?.resolve()?;
        let mut flags = self.step.method_flags();
        flags.push(MethodFlag::new(
            "--newton-iterations",
            self.newton_iterations.is_some(),
            |m| m.info().implicit,
        ));
        refuse_unread(&flags, &config.methods, &Method::ALL, Method::name)?;
        Ok(Box::new(config))
    }
}

impl Flags for HairArgs {
    fn kind(&self) -> &'static SceneKind {
        &HAIR
    }
    fn resolve(self: Box<Self>, file: &SceneFile, run: &RunArgs) -> Resolution {
        let drawing = [
            ("--fps", self.fps.is_some()),
            ("--window", self.window.is_some()),
        ];
        refuse_drawing_flags(run, &drawing)?;
        let config: HairConfig = given(&*self, "hair", file)?.resolve()?;
        if run.no_record && config.log_strands.is_some() {
            return Err(Error::Usage(
                "--no-record with --log-strands: --no-record draws nothing".into(),
            ));
        }
        let flags = self.method_flags();
        refuse_unread(&flags, &config.methods, &HairMethod::ALL, HairMethod::name)?;
        Ok(Box::new(config))
    }
}

/// What a scene's flags, the scene file and the scene's defaults give.
pub fn given<'a, A: clap::Args + serde::Serialize>(
    flags: &A,
    scene: &'static str,
    file: &'a SceneFile,
) -> Result<Given<'a>, Error> {
    Ok(Given {
        scene,
        defaults: toml::Table::new(),
        file,
        flags: table_of(flags)?,
        keys: A::augment_args(clap::Command::new(scene))
            .get_arguments()
            .map(|a| a.get_id().to_string())
            .collect(),
    })
}

/// A flag that only some methods read.
pub(super) struct MethodFlag<M> {
    flag: &'static str,
    /// Given on the command line. A scene file's key is not refused: a file written by
    /// `--config-out` or a recording states every parameter, whichever methods it names.
    given: bool,
    reads: fn(M) -> bool,
}

impl<M> MethodFlag<M> {
    fn new(flag: &'static str, given: bool, reads: fn(M) -> bool) -> Self {
        MethodFlag { flag, given, reads }
    }
}

impl MethodFlag<Method> {
    /// `--rtol`, which only the adaptive methods read (the scenes' and the studies').
    pub(super) fn rtol(given: bool) -> Self {
        MethodFlag::new("--rtol", given, |m| m.info().adaptive())
    }
}

/// Refuses a flag given on the command line that none of the methods run would read.
pub(super) fn refuse_unread<M: Copy>(
    flags: &[MethodFlag<M>],
    methods: &[M],
    all: &[M],
    name: fn(M) -> &'static str,
) -> Result<(), Error> {
    let names = |ms: &mut dyn Iterator<Item = M>| ms.map(name).collect::<Vec<_>>().join(",");
    for f in flags {
        if f.given && !methods.iter().any(|&m| (f.reads)(m)) {
            let readers: Vec<M> = all.iter().copied().filter(|&m| (f.reads)(m)).collect();
            let (reads, add) = match readers.len() {
                1 => ("reads", "add it"),
                _ => ("read", "add one of them"),
            };
            return Err(Error::Usage(format!(
                "{}: only {} {reads} it, and --methods is {}; {add} to --methods or drop {}",
                f.flag,
                names(&mut readers.into_iter()),
                names(&mut methods.iter().copied()),
                f.flag
            )));
        }
    }
    Ok(())
}

/// Refuses a flag that sets only what is drawn or plotted when --no-record records nothing.
fn refuse_drawing_flags(run: &RunArgs, flags: &[(&str, bool)]) -> Result<(), Error> {
    match flags.iter().find(|(_, given)| *given) {
        Some((flag, _)) if run.no_record => Err(Error::Usage(format!(
            "--no-record with {flag}: {flag} sets what the recording draws, and --no-record records nothing; drop one"
        ))),
        _ => Ok(()),
    }
}

impl StepFlags {
    fn drawing_flags(&self) -> [(&'static str, bool); 3] {
        [
            ("--fps", self.fps.is_some()),
            ("--plot-every", self.plot_every.is_some()),
            ("--window", self.window.is_some()),
        ]
    }

    fn method_flags(&self) -> Vec<MethodFlag<Method>> {
        vec![
            MethodFlag::new("--verlet-damping", self.verlet_damping.is_some(), |m| {
                m == Method::Verlet
            }),
            MethodFlag::rtol(self.rtol.is_some()),
            MethodFlag::new("--compensated", self.compensated, |m| {
                composition_weights(m).is_some()
            }),
            MethodFlag::new("--step", self.step.is_some(), |m| !m.info().adaptive()),
        ]
    }
}

impl HairArgs {
    fn method_flags(&self) -> Vec<MethodFlag<HairMethod>> {
        let verlet = |m| m == HairMethod::Verlet;
        vec![
            MethodFlag::new("--solver", self.solver.is_some(), verlet),
            MethodFlag::new("--iterations", self.iterations.is_some(), verlet),
            MethodFlag::new(
                "--stiffness",
                self.stiffness.is_some(),
                HairMethod::is_spring,
            ),
            MethodFlag::new(
                "--spring-damping",
                self.spring_damping.is_some(),
                HairMethod::is_spring,
            ),
        ]
    }
}

/// What every scene's configuration says alike, its staging from `record::$record`.
macro_rules! said_alike {
    ($kind:ident, $record:ident) => {
        fn kind(&self) -> &'static SceneKind {
            &$kind
        }
        fn table(&self) -> Result<toml::Table, Error> {
            table_of(self)
        }
        fn step_warning(&self) -> Option<String> {
            SceneConfig::step_warning(self)
        }
        fn staging(&self) -> Staging {
            record::$record::staging(self)
        }
        fn fps(&self) -> f64 {
            self.fps
        }
        fn methods(&self) -> Vec<&'static str> {
            self.methods.iter().map(|m| m.name()).collect()
        }
    };
}

impl ReadyScene for PendulumConfig {
    said_alike!(PENDULUM, pendulum);
    fn bulk(&self) -> Bulk {
        let (_, h) = crate::scene::params::fixed_step(self.dt, &self.options);
        let mut bulk = fixed_step_bulk(self.schedule(), h, self.duration, 1.0, self.methods.len());
        bulk.node_steps += self.reference_steps();
        bulk
    }
    fn run(self: Box<Self>, ctx: &mut RunContext) -> anyhow::Result<Ran> {
        let reference_steps = self.reference_steps();
        if reference_steps > 3e7 && !ctx.quiet {
            // Allowed, but not instant: say what the time goes to (~0.1 µs per RK4 step).
            eprintln!(
                "pendulum: the fine-step reference takes {reference_steps:.1e} RK4 steps (about {:.0} s); Ctrl-C stops it",
                reference_steps * 1e-7
            );
        }
        ctx.run(
            PendulumScene::new(*self),
            record::pendulum::recorder,
            report::pendulum::summary_text,
        )
    }
}

impl ReadyScene for RopeConfig {
    said_alike!(ROPE, rope);
    fn memory_bytes(&self) -> f64 {
        RopeConfig::memory_bytes(self)
    }
    fn bulk(&self) -> Bulk {
        let (_, h) = crate::scene::params::fixed_step(self.dt, &self.options);
        let nodes = self.params.nodes as f64;
        fixed_step_bulk(self.schedule(), h, self.duration, nodes, self.methods.len())
    }
    fn run(self: Box<Self>, ctx: &mut RunContext) -> anyhow::Result<Ran> {
        ctx.run(
            RopeScene::new(*self),
            record::rope::recorder,
            report::rope::summary_text,
        )
    }
}

impl ReadyScene for HairConfig {
    said_alike!(HAIR, hair);
    fn memory_bytes(&self) -> f64 {
        HairConfig::memory_bytes(self)
    }
    fn bulk(&self) -> Bulk {
        let nodes = (self.params.strands * self.params.nodes) as f64;
        let steps = self.frames() as f64 * self.substeps as f64;
        let plan = record::hair::strand_plan(self, self.log_strands);
        Bulk {
            node_steps: self.methods.len() as f64 * nodes * steps,
            node_frames: plan.expected_bytes / record::hair::BYTES_PER_NODE_FRAME,
        }
    }
    fn run(self: Box<Self>, ctx: &mut RunContext) -> anyhow::Result<Ran> {
        let plan = record::hair::strand_plan(&self, self.log_strands);
        let recording = ctx.stream.is_some();
        if recording && !ctx.quiet {
            eprintln!(
                "hair: drawing {} of {} strands in 3D; expected recording ≈ {:.0} MB",
                plan.drawn,
                plan.strands,
                plan.expected_bytes / 1e6
            );
        }
        let strands = self.log_strands;
        let recorder = |s, timings| record::hair::recorder(s, timings, strands);
        // Hair spreads its strands over the pool (--threads); the results do not depend on it.
        let pool = ctx.pool;
        let mut ran =
            pool.install(|| ctx.run(HairScene::new(*self), recorder, report::hair::summary_text))?;
        if recording {
            ran.append(&format!(
                "\n3D: {} of {} strands drawn per head (--log-strands); every strand is simulated and measured above\n",
                plan.drawn, plan.strands
            ));
        }
        ran.printed_only = format!(
            "threads: {} (the results do not depend on it)\n",
            ctx.pool.current_num_threads()
        );
        Ok(ran)
    }
}
