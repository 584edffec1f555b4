//! The commands: resolve and validate options into plain configs, run, record, report.

use std::fmt;

use glam::DVec3;

use crate::cli::{Cli, Command, HairArgs, PendulumArgs, RopeArgs, RopePreset};
use crate::method::{Method, MethodOptions, methods_table};
use crate::record::{FileRecording, send_provenance};
use crate::scene::hair::run::HairConfig;
use crate::scene::hair::{HairMethod, HairParams};
use crate::scene::pendulum::PendulumParams;
use crate::scene::pendulum::run::{PendulumConfig, run as run_pendulum};
use crate::scene::pendulum::summary::summary_text;
use crate::scene::rope::RopeParams;
use crate::scene::rope::run::RopeConfig;

/// Runs longer than this many steps per method are refused: a typo in --dt should not
/// start an hours-long run.
pub const MAX_STEPS: f64 = 1e9;

/// Bad input: the option, the value and what is allowed. Exit code 2.
#[derive(Debug, Clone, PartialEq)]
pub struct UsageError(pub String);

impl fmt::Display for UsageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Methods => {
            print!("{}", methods_table());
            Ok(())
        }
        Command::Pendulum(args) => pendulum(&args),
        Command::Rope(args) => rope(&args),
        Command::Hair(args) => hair(&args),
    }
}

fn pendulum(args: &PendulumArgs) -> anyhow::Result<()> {
    let config = pendulum_config(args)?;
    let recording = FileRecording::create(
        &args.output,
        "pendulum",
        crate::record::pendulum::blueprint(),
    )?;
    let methods: Vec<&str> = config.methods.iter().map(|m| m.name()).collect();
    send_provenance(
        recording.stream(),
        "pendulum",
        &pendulum_config_toml(&config, args),
        &methods,
    )?;
    let mut recorder = crate::record::pendulum::PendulumRecorder::new(recording.stream().clone());
    let summary = run_pendulum(&config, &mut recorder)?;
    drop(recorder);
    let bytes = recording.commit()?;
    print!("{}", summary_text(&summary));
    println!(
        "\nrecording: {} ({:.2} MB)",
        args.output.display(),
        bytes as f64 / 1e6
    );
    Ok(())
}

/// Turns the pendulum flags into a validated config.
pub fn pendulum_config(args: &PendulumArgs) -> Result<PendulumConfig, UsageError> {
    positive("--gravity", args.gravity, "m/s²")?;
    positive("--length", args.length, "m")?;
    finite("--theta0", args.theta0, "degrees")?;
    finite("--omega0", args.omega0, "rad/s")?;
    check_time(args.dt, args.duration, args.fps, 1)?;
    let d = args.verlet_damping;
    check_verlet_damping(d)?;
    let methods = resolve_methods(&args.methods);
    Ok(PendulumConfig {
        params: PendulumParams {
            gravity: args.gravity,
            length: args.length,
            theta0: args.theta0.to_radians(),
            omega0: args.omega0,
        },
        dt: args.dt,
        duration: args.duration,
        fps: args.fps,
        methods,
        options: MethodOptions { verlet_damping: d },
    })
}

/// The resolved configuration as TOML text, for the recording's provenance.
fn pendulum_config_toml(c: &PendulumConfig, args: &PendulumArgs) -> String {
    let methods: Vec<String> = c.methods.iter().map(|m| format!("\"{m}\"")).collect();
    format!(
        "[pendulum]\ngravity = {:?}\nlength = {:?}\ntheta0 = {:?}\nomega0 = {:?}\ndt = {:?}\nduration = {:?}\n\
         fps = {:?}\nmethods = [{}]\nverlet_damping = {:?}\noutput = {:?}\n",
        c.params.gravity,
        c.params.length,
        args.theta0,
        c.params.omega0,
        c.dt,
        c.duration,
        c.fps,
        methods.join(", "),
        c.options.verlet_damping,
        args.output.display().to_string(),
    )
}

fn finite(option: &str, value: f64, unit: &str) -> Result<(), UsageError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(UsageError(format!(
            "{option} {value}: must be a finite number [{unit}]"
        )))
    }
}

fn positive(option: &str, value: f64, unit: &str) -> Result<(), UsageError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(UsageError(format!(
            "{option} {value}: must be a finite number > 0 [{unit}]"
        )))
    }
}

/// The methods as given, first occurrence kept; all of them when none is given.
fn resolve_methods(given: &[Method]) -> Vec<Method> {
    let mut methods: Vec<Method> = Vec::new();
    for &m in given {
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    if methods.is_empty() {
        Method::ALL.to_vec()
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

/// "x,y" or "x,y,z" (z = 0 when omitted), finite.
fn parse_vector(option: &str, text: &str) -> Result<DVec3, UsageError> {
    let bad = || {
        UsageError(format!(
            "{option} {text}: expected x,y or x,y,z with finite numbers, e.g. 0,-9.81,0"
        ))
    };
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match parts[..] {
        [x, y] if x.is_finite() && y.is_finite() => Ok(DVec3::new(x, y, 0.0)),
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(DVec3::new(x, y, z)),
        _ => Err(bad()),
    }
}

fn rope(args: &RopeArgs) -> anyhow::Result<()> {
    let config = rope_config(args)?;
    let recording = FileRecording::create(&args.output, "rope", crate::record::rope::blueprint())?;
    let methods: Vec<&str> = config.methods.iter().map(|m| m.name()).collect();
    send_provenance(
        recording.stream(),
        "rope",
        &rope_config_toml(&config, args),
        &methods,
    )?;
    let mut recorder =
        crate::record::rope::RopeRecorder::new(recording.stream().clone(), args.layout);
    let summary = crate::scene::rope::run::run(&config, &mut recorder)?;
    drop(recorder);
    let bytes = recording.commit()?;
    print!("{}", crate::scene::rope::summary::summary_text(&summary));
    println!(
        "\nrecording: {} ({:.2} MB)",
        args.output.display(),
        bytes as f64 / 1e6
    );
    Ok(())
}

/// Turns the rope flags (over the preset, over the defaults) into a validated config.
pub fn rope_config(args: &RopeArgs) -> Result<RopeConfig, UsageError> {
    let mut p = RopeParams::default();
    let mut dt = 1e-3;
    let mut duration = 10.0;
    let mut fps = 30.0;
    let mut verlet_damping = 0.0;
    if args.preset == Some(RopePreset::Games101) {
        p = RopeParams {
            nodes: 16,
            start: DVec3::new(0.0, 200.0, 0.0),
            end: DVec3::new(-400.0, 200.0, 0.0),
            mass: 1.0,
            stiffness: 100.0,
            spring_damping: 0.0,
            air_drag: 0.0,
            gravity: DVec3::new(0.0, -1.0, 0.0),
            pinned: vec![0],
            newton_iterations: 1,
        };
        dt = 1.0 / 64.0;
        fps = 1.0; // one frame per time unit = 64 steps per frame
        duration = 20.0;
        verlet_damping = 0.00005;
    }
    if let Some(n) = args.nodes {
        p.nodes = n;
    }
    if let Some(s) = &args.start {
        p.start = parse_vector("--start", s)?;
    }
    if let Some(s) = &args.end {
        p.end = parse_vector("--end", s)?;
    }
    if let Some(g) = &args.gravity {
        p.gravity = parse_vector("--gravity", g)?;
    }
    p.mass = args.mass.unwrap_or(p.mass);
    p.stiffness = args.stiffness.unwrap_or(p.stiffness);
    p.spring_damping = args.spring_damping.unwrap_or(p.spring_damping);
    p.air_drag = args.air_drag.unwrap_or(p.air_drag);
    p.newton_iterations = args.newton_iterations.unwrap_or(p.newton_iterations);
    if let Some(pins) = &args.pinned {
        p.pinned = pins.clone();
    }
    let dt = args.dt.unwrap_or(dt);
    let duration = args.duration.unwrap_or(duration);
    let fps = args.fps.unwrap_or(fps);
    let verlet_damping = args.verlet_damping.unwrap_or(verlet_damping);

    if !(2..=MAX_NODES).contains(&p.nodes) {
        return Err(UsageError(format!(
            "--nodes {}: must be between 2 and {MAX_NODES}",
            p.nodes
        )));
    }
    if (p.end - p.start).length() == 0.0 {
        return Err(UsageError(format!(
            "--end {:?}: must differ from --start (the spacing is the springs' rest length)",
            p.end.to_array()
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
    check_verlet_damping(verlet_damping)?;
    Ok(RopeConfig {
        params: p,
        dt,
        duration,
        fps,
        methods: resolve_methods(&args.methods),
        options: MethodOptions { verlet_damping },
    })
}

fn rope_config_toml(c: &RopeConfig, args: &RopeArgs) -> String {
    let p = &c.params;
    let methods: Vec<String> = c.methods.iter().map(|m| format!("\"{m}\"")).collect();
    let v = |d: DVec3| format!("[{:?}, {:?}, {:?}]", d.x, d.y, d.z);
    format!(
        "[rope]\nnodes = {}\nstart = {}\nend = {}\nmass = {:?}\nstiffness = {:?}\nspring_damping = {:?}\n\
         air_drag = {:?}\ngravity = {}\npinned = {:?}\nnewton_iterations = {}\ndt = {:?}\nduration = {:?}\n\
         fps = {:?}\nmethods = [{}]\nverlet_damping = {:?}\nlayout = \"{:?}\"\noutput = {:?}\n",
        p.nodes,
        v(p.start),
        v(p.end),
        p.mass,
        p.stiffness,
        p.spring_damping,
        p.air_drag,
        v(p.gravity),
        p.pinned,
        p.newton_iterations,
        c.dt,
        c.duration,
        c.fps,
        methods.join(", "),
        c.options.verlet_damping,
        args.layout,
        args.output.display().to_string(),
    )
}

/// Node-steps × (iterations + 1) per method beyond which a hair run is refused.
pub const MAX_HAIR_WORK: f64 = 1e12;

/// Turns the hair flags into a validated config.
pub fn hair_config(args: &HairArgs) -> Result<HairConfig, UsageError> {
    if !(1..=1_000_000).contains(&args.strands) {
        return Err(UsageError(format!(
            "--strands {}: must be between 1 and 1000000",
            args.strands
        )));
    }
    if !(2..=10_000).contains(&args.nodes) {
        return Err(UsageError(format!(
            "--nodes {}: must be between 2 and 10000",
            args.nodes
        )));
    }
    positive("--segment-length", args.segment_length, "m")?;
    positive("--head-radius", args.head_radius, "m")?;
    non_negative("--gust", args.gust, "fraction")?;
    non_negative("--damping", args.damping, "1/s")?;
    if !(args.margin.is_finite() && (0.0..0.5).contains(&args.margin)) {
        return Err(UsageError(format!(
            "--margin {}: must be in [0, 0.5) head radii",
            args.margin
        )));
    }
    if args.iterations == 0 {
        return Err(UsageError("--iterations 0: must be at least 1".into()));
    }
    if args.substeps == 0 {
        return Err(UsageError("--substeps 0: must be at least 1".into()));
    }
    positive("--rate", args.rate, "Hz")?;
    check_time(1.0 / args.rate, args.duration, args.fps, 1)?;
    let config = HairConfig {
        params: HairParams {
            head_radius: args.head_radius,
            motion: args.head_motion,
            strands: args.strands,
            nodes: args.nodes,
            segment_length: args.segment_length,
            gravity: parse_vector("--gravity", &args.gravity)?,
            wind: parse_vector("--wind", &args.wind)?,
            gust: args.gust,
            damping: args.damping,
            iterations: args.iterations,
            margin: args.margin,
            ..HairParams::default()
        },
        rate: args.rate,
        substeps: args.substeps,
        fps: args.fps,
        duration: args.duration,
        methods: {
            let mut m: Vec<HairMethod> = Vec::new();
            for &x in &args.methods {
                if !m.contains(&x) {
                    m.push(x);
                }
            }
            if m.is_empty() {
                HairMethod::ALL.to_vec()
            } else {
                m
            }
        },
    };
    let work = config.frames() as f64
        * config.substeps as f64
        * (args.strands * args.nodes) as f64
        * (args.iterations + 1) as f64;
    if work > MAX_HAIR_WORK {
        return Err(UsageError(format!(
            "--strands {} × --nodes {} × --iterations {} over {} frames × {} substeps is {work:.2e} node-updates \
             per method; at most {MAX_HAIR_WORK:.0e} are allowed (fewer strands or a shorter --duration)",
            args.strands,
            args.nodes,
            args.iterations,
            config.frames(),
            config.substeps
        )));
    }
    if args.threads == Some(0) {
        return Err(UsageError("--threads 0: must be at least 1".into()));
    }
    Ok(config)
}

fn hair(args: &HairArgs) -> anyhow::Result<()> {
    let config = hair_config(args)?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        pool = pool.num_threads(n);
    }
    let pool = pool.build()?;
    let summary = if args.no_record {
        pool.install(|| {
            crate::scene::hair::run::run(&config, &mut crate::scene::hair::run::NoHairObserver)
        })?
    } else {
        let recording =
            FileRecording::create(&args.output, "hair", crate::record::hair::blueprint())?;
        let methods: Vec<&str> = config.methods.iter().map(|m| m.name()).collect();
        send_provenance(
            recording.stream(),
            "hair",
            &format!("[hair]\n{config:?}\n"),
            &methods,
        )?;
        let mut recorder = crate::record::hair::HairRecorder::new(recording.stream().clone());
        let summary = pool.install(|| crate::scene::hair::run::run(&config, &mut recorder))?;
        drop(recorder);
        let bytes = recording.commit()?;
        print!("{}", crate::scene::hair::summary::summary_text(&summary));
        println!(
            "\nrecording: {} ({:.2} MB)",
            args.output.display(),
            bytes as f64 / 1e6
        );
        return Ok(());
    };
    print!("{}", crate::scene::hair::summary::summary_text(&summary));
    Ok(())
}
