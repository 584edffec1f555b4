//! Turning flags, scene files, presets and defaults into validated configs. Every check names
//! the option, the value and what is allowed.

use glam::DVec3;

use super::UsageError;
use crate::cli::{HairArgs, PendulumArgs, RopeArgs, RopePreset};
use crate::config::{Vector, layered};
use crate::method::{Method, MethodOptions};
use crate::record::rope::Layout;
use crate::scene::hair::run::HairConfig;
use crate::scene::hair::{HairMethod, HairParams, HeadMotion};
use crate::scene::pendulum::PendulumParams;
use crate::scene::pendulum::run::PendulumConfig;
use crate::scene::rope::RopeParams;
use crate::scene::rope::run::RopeConfig;

/// Runs longer than this many steps per method are refused: a typo in --dt should not
/// start an hours-long run.
pub const MAX_STEPS: f64 = 1e9;

/// Every pendulum parameter at its default.
pub fn pendulum_defaults() -> PendulumArgs {
    PendulumArgs {
        gravity: Some(9.81),
        length: Some(3.521),
        theta0: Some(60.0),
        omega0: Some(0.0),
        dt: Some(0.01),
        duration: Some(20.0),
        fps: Some(30.0),
        plot_every: Some(1),
        methods: Some(Method::DEFAULT.to_vec()),
        verlet_damping: Some(0.0),
        rtol: Some(1e-6),
    }
}

/// Every rope parameter at its default.
pub fn rope_defaults() -> RopeArgs {
    let p = RopeParams::default();
    RopeArgs {
        preset: None,
        nodes: Some(p.nodes),
        start: Some(Vector(p.start)),
        end: Some(Vector(p.end)),
        mass: Some(p.mass),
        stiffness: Some(p.stiffness),
        spring_damping: Some(p.spring_damping),
        air_drag: Some(p.air_drag),
        gravity: Some(Vector(p.gravity)),
        pinned: Some(p.pinned),
        dt: Some(1e-3),
        duration: Some(10.0),
        fps: Some(30.0),
        plot_every: Some(5),
        methods: Some(Method::DEFAULT.to_vec()),
        verlet_damping: Some(0.0),
        newton_iterations: Some(p.newton_iterations),
        layout: Some(Layout::SideBySide),
        rtol: Some(1e-6),
    }
}

/// The GAMES101 assignment's parameters (a layer over the defaults).
pub fn games101_preset() -> RopeArgs {
    RopeArgs {
        nodes: Some(16),
        start: Some(Vector(DVec3::new(0.0, 200.0, 0.0))),
        end: Some(Vector(DVec3::new(-400.0, 200.0, 0.0))),
        mass: Some(1.0),
        stiffness: Some(100.0),
        spring_damping: Some(0.0),
        air_drag: Some(0.0),
        gravity: Some(Vector(DVec3::new(0.0, -1.0, 0.0))),
        pinned: Some(vec![0]),
        dt: Some(1.0 / 64.0),
        fps: Some(1.0), // one frame per time unit = 64 steps per frame
        duration: Some(20.0),
        plot_every: Some(1),
        verlet_damping: Some(0.00005),
        ..RopeArgs::default()
    }
}

/// Every hair parameter at its default.
pub fn hair_defaults() -> HairArgs {
    let p = HairParams::default();
    HairArgs {
        strands: Some(p.strands),
        nodes: Some(p.nodes),
        segment_length: Some(p.segment_length),
        head_radius: Some(p.head_radius),
        head_motion: Some(HeadMotion::Tour),
        wind: Some(Vector(p.wind)),
        gust: Some(p.gust),
        gravity: Some(Vector(p.gravity)),
        damping: Some(p.damping),
        iterations: Some(p.iterations),
        substeps: Some(1),
        rate: Some(60.0),
        fps: Some(15.0),
        duration: Some(8.0),
        margin: Some(p.margin),
        methods: Some(HairMethod::ALL.to_vec()),
    }
}

/// The pendulum's parameters over its defaults, every field given.
pub fn pendulum_effective(args: &PendulumArgs) -> PendulumArgs {
    layered(&[&pendulum_defaults(), args])
}

/// The rope's parameters over the preset (if any) over the defaults, every field given.
pub fn rope_effective(args: &RopeArgs) -> RopeArgs {
    match args.preset {
        Some(RopePreset::Games101) => layered(&[&rope_defaults(), &games101_preset(), args]),
        None => layered(&[&rope_defaults(), args]),
    }
}

/// The hair's parameters over its defaults, every field given.
pub fn hair_effective(args: &HairArgs) -> HairArgs {
    layered(&[&hair_defaults(), args])
}

/// Turns pendulum parameters (missing ones at their defaults) into a validated config.
pub fn pendulum_config(args: &PendulumArgs) -> Result<PendulumConfig, UsageError> {
    let a = pendulum_effective(args);
    let (gravity, length, theta0, omega0) = (
        a.gravity.unwrap(),
        a.length.unwrap(),
        a.theta0.unwrap(),
        a.omega0.unwrap(),
    );
    let (dt, duration, fps, d) = (
        a.dt.unwrap(),
        a.duration.unwrap(),
        a.fps.unwrap(),
        a.verlet_damping.unwrap(),
    );
    positive("--gravity", gravity, "m/s²")?;
    positive("--length", length, "m")?;
    finite("--theta0", theta0, "degrees")?;
    finite("--omega0", omega0, "rad/s")?;
    check_time(dt, duration, fps, 1)?;
    check_verlet_damping(d)?;
    let plot_every = check_plot_every(a.plot_every.unwrap())?;
    Ok(PendulumConfig {
        params: PendulumParams {
            gravity,
            length,
            theta0: theta0.to_radians(),
            omega0,
        },
        dt,
        duration,
        fps,
        plot_every,
        methods: resolve_methods(&a.methods.unwrap(), Method::DEFAULT),
        options: MethodOptions {
            verlet_damping: d,
            rtol: check_rtol(a.rtol.unwrap())?,
        },
    })
}

/// The memory this machine has available [bytes] (MemAvailable), if it can be read.
fn available_memory() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Refuses a run whose state would not fit in memory, naming the estimate and what to change.
fn check_memory(what: &str, bytes: f64, change: &str) -> Result<(), UsageError> {
    if let Some(available) = available_memory()
        && bytes > 0.8 * available
    {
        return Err(UsageError(format!(
            "{what} needs about {:.1} GB of memory, more than the {:.1} GB available; {change}",
            bytes / 1e9,
            available / 1e9
        )));
    }
    Ok(())
}

fn check_rtol(rtol: f64) -> Result<f64, UsageError> {
    if rtol.is_finite() && (1e-14..=0.1).contains(&rtol) {
        Ok(rtol)
    } else {
        Err(UsageError(format!(
            "--rtol {rtol}: must be between 1e-14 and 0.1"
        )))
    }
}

fn check_plot_every(n: u64) -> Result<u64, UsageError> {
    if n == 0 {
        Err(UsageError(
            "--plot-every 0: must be at least 1 (plot every Nth step)".into(),
        ))
    } else {
        Ok(n)
    }
}

pub(crate) fn finite(option: &str, value: f64, unit: &str) -> Result<(), UsageError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(UsageError(format!(
            "{option} {value}: must be a finite number [{unit}]"
        )))
    }
}

pub(crate) fn positive(option: &str, value: f64, unit: &str) -> Result<(), UsageError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(UsageError(format!(
            "{option} {value}: must be a finite number > 0 [{unit}]"
        )))
    }
}

/// The methods as given, first occurrence kept; `defaults` when none is given.
fn resolve_methods<M: Copy + PartialEq>(given: &[M], defaults: &[M]) -> Vec<M> {
    let mut methods: Vec<M> = Vec::new();
    for &m in given {
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    if methods.is_empty() {
        defaults.to_vec()
    } else {
        methods
    }
}

/// dt, duration and fps, and a refusal of runs whose work (steps × `work_per_step`, e.g. nodes)
/// would take hours.
fn check_time(dt: f64, duration: f64, fps: f64, work_per_step: usize) -> Result<(), UsageError> {
    positive("--dt", dt, "s")?;
    positive("--duration", duration, "s")?;
    positive("--fps", fps, "Hz")?;
    if dt > duration {
        return Err(UsageError(format!(
            "--dt {dt}: must not exceed --duration {duration} s"
        )));
    }
    let steps = duration / dt;
    if steps > MAX_STEPS {
        return Err(UsageError(format!(
            "--dt {dt} with --duration {duration} is {steps:.2e} steps per method; at most {MAX_STEPS:.0e} \
             are allowed (raise --dt or shorten --duration)"
        )));
    }
    let work = steps * work_per_step as f64;
    if work > MAX_NODE_STEPS {
        return Err(UsageError(format!(
            "--duration {duration} / --dt {dt} × {work_per_step} nodes is {work:.2e} node-steps per method; \
             at most {MAX_NODE_STEPS:.0e} are allowed (raise --dt, shorten --duration or use fewer --nodes)"
        )));
    }
    Ok(())
}

/// Node-steps per method beyond which a run is refused (about an hour at ~30 ns per node-step).
pub const MAX_NODE_STEPS: f64 = 1e11;

/// Nodes beyond which a rope is refused (~1 kB per node per method including the implicit solver).
pub const MAX_NODES: usize = 10_000_000;

fn check_verlet_damping(d: f64) -> Result<(), UsageError> {
    if d.is_finite() && (0.0..1.0).contains(&d) {
        Ok(())
    } else {
        Err(UsageError(format!(
            "--verlet-damping {d}: must be in [0, 1)"
        )))
    }
}

fn non_negative(option: &str, value: f64, unit: &str) -> Result<(), UsageError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(UsageError(format!(
            "{option} {value}: must be a finite number ≥ 0 [{unit}]"
        )))
    }
}

/// Turns rope parameters (over the preset, over the defaults) into a validated config.
pub fn rope_config(args: &RopeArgs) -> Result<RopeConfig, UsageError> {
    let a = rope_effective(args);
    let mut p = RopeParams {
        nodes: a.nodes.unwrap(),
        start: a.start.unwrap().0,
        end: a.end.unwrap().0,
        mass: a.mass.unwrap(),
        stiffness: a.stiffness.unwrap(),
        spring_damping: a.spring_damping.unwrap(),
        air_drag: a.air_drag.unwrap(),
        gravity: a.gravity.unwrap().0,
        pinned: a.pinned.unwrap(),
        newton_iterations: a.newton_iterations.unwrap(),
    };
    let (dt, duration, fps, verlet_damping) = (
        a.dt.unwrap(),
        a.duration.unwrap(),
        a.fps.unwrap(),
        a.verlet_damping.unwrap(),
    );
    if !(2..=MAX_NODES).contains(&p.nodes) {
        return Err(UsageError(format!(
            "--nodes {}: must be between 2 and {MAX_NODES}",
            p.nodes
        )));
    }
    if (p.end - p.start).length() == 0.0 {
        return Err(UsageError(format!(
            "--end {}: must differ from --start (the spacing is the springs' rest length)",
            Vector(p.end)
        )));
    }
    positive("--mass", p.mass, "kg")?;
    non_negative("--stiffness", p.stiffness, "N/m")?;
    non_negative("--spring-damping", p.spring_damping, "N·s/m")?;
    non_negative("--air-drag", p.air_drag, "N·s/m")?;
    if let Some(&bad) = p.pinned.iter().find(|&&i| i >= p.nodes) {
        return Err(UsageError(format!(
            "--pinned {bad}: node index out of range; the rope has nodes 0..={}",
            p.nodes - 1
        )));
    }
    p.pinned.sort_unstable();
    p.pinned.dedup();
    if p.newton_iterations == 0 {
        return Err(UsageError(
            "--newton-iterations 0: must be at least 1".into(),
        ));
    }
    check_time(dt, duration, fps, p.nodes)?;
    let methods = resolve_methods(&a.methods.unwrap(), Method::DEFAULT);
    // Per node and method: state, scratch and Verlet's history (~10 × 24 B) and the implicit
    // solver's 3×3 blocks (~6 × 72 B): about 1 kB.
    check_memory(
        &format!("--nodes {} with {} methods", p.nodes, methods.len()),
        p.nodes as f64 * methods.len() as f64 * 1000.0,
        "use fewer --nodes or --methods",
    )?;
    check_verlet_damping(verlet_damping)?;
    let plot_every = check_plot_every(a.plot_every.unwrap())?;
    Ok(RopeConfig {
        params: p,
        dt,
        duration,
        fps,
        plot_every,
        layout: a.layout.unwrap(),
        methods,
        options: MethodOptions {
            verlet_damping,
            rtol: check_rtol(a.rtol.unwrap())?,
        },
    })
}

/// Node-steps × (iterations + 1) per method beyond which a hair run is refused.
pub const MAX_HAIR_WORK: f64 = 1e12;

/// Turns hair parameters (missing ones at their defaults) into a validated config.
pub fn hair_config(args: &HairArgs) -> Result<HairConfig, UsageError> {
    let a = hair_effective(args);
    let (strands, nodes, iterations, substeps) = (
        a.strands.unwrap(),
        a.nodes.unwrap(),
        a.iterations.unwrap(),
        a.substeps.unwrap(),
    );
    if !(1..=1_000_000).contains(&strands) {
        return Err(UsageError(format!(
            "--strands {strands}: must be between 1 and 1000000"
        )));
    }
    if !(2..=10_000).contains(&nodes) {
        return Err(UsageError(format!(
            "--nodes {nodes}: must be between 2 and 10000"
        )));
    }
    positive("--segment-length", a.segment_length.unwrap(), "m")?;
    positive("--head-radius", a.head_radius.unwrap(), "m")?;
    non_negative("--gust", a.gust.unwrap(), "fraction")?;
    non_negative("--damping", a.damping.unwrap(), "1/s")?;
    let margin = a.margin.unwrap();
    if !(margin.is_finite() && (0.0..0.5).contains(&margin)) {
        return Err(UsageError(format!(
            "--margin {margin}: must be in [0, 0.5) head radii"
        )));
    }
    if iterations == 0 {
        return Err(UsageError("--iterations 0: must be at least 1".into()));
    }
    if substeps == 0 {
        return Err(UsageError("--substeps 0: must be at least 1".into()));
    }
    let rate = a.rate.unwrap();
    positive("--rate", rate, "Hz")?;
    check_time(1.0 / rate, a.duration.unwrap(), a.fps.unwrap(), 1)?;
    let config = HairConfig {
        params: HairParams {
            head_radius: a.head_radius.unwrap(),
            motion: a.head_motion.unwrap(),
            strands,
            nodes,
            segment_length: a.segment_length.unwrap(),
            gravity: a.gravity.unwrap().0,
            wind: a.wind.unwrap().0,
            gust: a.gust.unwrap(),
            damping: a.damping.unwrap(),
            iterations,
            margin,
            ..HairParams::default()
        },
        rate,
        substeps,
        fps: a.fps.unwrap(),
        duration: a.duration.unwrap(),
        methods: resolve_methods(&a.methods.unwrap(), &HairMethod::ALL),
    };
    let work = config.frames() as f64
        * substeps as f64
        * (strands * nodes) as f64
        * (iterations + 1) as f64;
    if work > MAX_HAIR_WORK {
        return Err(UsageError(format!(
            "--strands {strands} × --nodes {nodes} × --iterations {iterations} over {} frames × {substeps} substeps \
             is {work:.2e} node-updates per method; at most {MAX_HAIR_WORK:.0e} are allowed (fewer strands or a \
             shorter --duration)",
            config.frames()
        )));
    }
    // Per node and method: position, previous position and velocity, 3 × 24 B.
    check_memory(
        &format!(
            "--strands {strands} × --nodes {nodes} with {} methods",
            config.methods.len()
        ),
        (strands * nodes) as f64 * config.methods.len() as f64 * 72.0,
        "use fewer --strands or --nodes",
    )?;
    Ok(config)
}
