//! Checks shared by every scene's `validate()`: each names the parameter (as its flag), the value
//! and what is allowed, so the same message serves a flag and a scene-file key.

pub use crate::error::Error as Invalid;
use crate::format;
use crate::format::{shown, shown_vector};

/// Runs longer than this many steps per method are refused: a typo in --dt should not
/// start an hours-long run.
pub const MAX_STEPS: f64 = 1e9;

/// Node-steps per method beyond which a run is refused (about an hour at
/// [`NODE_STEP_SECONDS`]).
pub const MAX_NODE_STEPS: f64 = 1e11;

/// What one node's step of one method takes, roughly [s]: the rate a run's length is judged by
/// before it starts.
pub const NODE_STEP_SECONDS: f64 = 30e-9;

/// `value` of `option` refused by `rule` unless `ok`: the one shape of every check here.
pub fn require(ok: bool, option: &str, value: f64, rule: impl Into<String>) -> Result<(), Invalid> {
    refuse_unless(ok, option, shown(value), rule)
}

/// [`require`] for a value already in words (a vector, a count).
pub fn refuse_unless(
    ok: bool,
    option: &str,
    value: impl std::fmt::Display,
    rule: impl Into<String>,
) -> Result<(), Invalid> {
    ok.then_some(())
        .ok_or_else(|| Invalid::param(option, value, rule))
}

pub fn positive(option: &str, value: f64, unit: &str) -> Result<(), Invalid> {
    let rule = format!("must be a finite number > 0 [{unit}]");
    require(value.is_finite() && value > 0.0, option, value, rule)
}

/// A finite value within [lo, hi], the range the physics and f64 are trusted in.
pub fn within(option: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<(), Invalid> {
    let rule = format!(
        "must be between {} and {} [{unit}]",
        format::bound(lo),
        format::bound(hi)
    );
    require(
        value.is_finite() && (lo..=hi).contains(&value),
        option,
        value,
        rule,
    )
}

/// A vector whose every component is finite and within ±[`MAX_MAGNITUDE`]; `unit` follows the
/// rule (" [m/s²]", or "").
pub fn vector(option: &str, v: glam::DVec3, unit: &str) -> Result<(), Invalid> {
    let rule = format!("every component must be a finite number within ±{MAX_MAGNITUDE:e}{unit}");
    let ok = v.is_finite() && v.abs().max_element() <= MAX_MAGNITUDE;
    refuse_unless(ok, option, shown_vector(v), rule)
}

/// The largest magnitude accepted for a coordinate or a physical parameter: far beyond any lab
/// setup, yet small enough that energies, squares and sums of squares stay finite in f64.
pub const MAX_MAGNITUDE: f64 = 1e6;

pub fn non_negative(option: &str, value: f64, unit: &str) -> Result<(), Invalid> {
    let rule = format!("must be a finite number ≥ 0 [{unit}]");
    require(value.is_finite() && value >= 0.0, option, value, rule)
}

pub fn at_least_one(option: &str, value: u64) -> Result<(), Invalid> {
    refuse_unless(value != 0, option, value, "must be at least 1")
}

/// A count within [lo, hi].
pub fn count_within(option: &str, value: u64, lo: u64, hi: u64) -> Result<(), Invalid> {
    let rule = format!("must be between {lo} and {hi}");
    refuse_unless((lo..=hi).contains(&value), option, value, rule)
}

pub fn rtol(rtol: f64) -> Result<(), Invalid> {
    let ok = rtol.is_finite() && (1e-14..=0.1).contains(&rtol);
    require(ok, "--rtol", rtol, "must be between 1e-14 and 0.1")
}

/// The plotting stride and the methods' options of a scene on a fixed step grid.
pub fn plot_and_options(
    plot_every: u64,
    options: &crate::integrate::MethodOptions,
) -> Result<(), Invalid> {
    verlet_damping(options.verlet_damping)?;
    let rule = "must be at least 1 (plot every Nth step)";
    refuse_unless(plot_every != 0, "--plot-every", plot_every, rule)?;
    rtol(options.rtol)
}

pub fn verlet_damping(d: f64) -> Result<(), Invalid> {
    let ok = d.is_finite() && (0.0..1.0).contains(&d);
    require(ok, "--verlet-damping", d, "must be in [0, 1)")
}

/// dt, duration and fps, and a refusal of runs whose work (steps × `work_per_step`, e.g. nodes)
/// would take hours.
pub fn time(dt: f64, duration: f64, fps: f64, work_per_step: usize) -> Result<(), Invalid> {
    positive("--dt", dt, "s")?;
    positive("--duration", duration, "s")?;
    positive("--fps", fps, "Hz")?;
    let rule = format!("must not exceed --duration {} s", shown(duration));
    require(dt <= duration, "--dt", dt, rule)?;
    step_count("--dt", dt, duration, work_per_step)
}

/// The fixed-step methods' step and the flag that set it: `--step` when given, else `--dt`.
pub fn fixed_step(dt: f64, options: &crate::integrate::MethodOptions) -> (&'static str, f64) {
    options.step.map_or(("--dt", dt), |h| ("--step", h))
}

/// What a summary's header adds after dt when the fixed-step methods step at their own step.
pub fn own_step_text(options: &crate::integrate::MethodOptions) -> String {
    options.step.map_or(String::new(), |h| {
        format!(" (fixed-step methods step at --step {} s)", shown(h))
    })
}

/// The most steps of its own a fixed-step method takes between two samples (`--step` below
/// dt): the run looks at Ctrl-C between samples, so a sample's steps must stay a short wait.
pub const MAX_STEPS_PER_SAMPLE: f64 = 4096.0;

/// The fixed-step methods' own step (`--step`), when given: positive, at most the run, at
/// least dt / `MAX_STEPS_PER_SAMPLE`, and no more steps than --dt may take.
pub fn own_step(
    step: Option<f64>,
    dt: f64,
    duration: f64,
    work_per_step: usize,
) -> Result<(), Invalid> {
    let Some(h) = step else {
        return Ok(());
    };
    positive("--step", h, "s")?;
    let rule = format!("must not exceed --duration {} s", shown(duration));
    require(h <= duration, "--step", h, rule)?;
    let least = dt / MAX_STEPS_PER_SAMPLE;
    let rule = format!(
        "must be at least --dt / {MAX_STEPS_PER_SAMPLE} = {} s (steps between two samples); for \
         finer steps lower --dt and plot every Nth with --plot-every",
        shown(least)
    );
    require(h >= least, "--step", h, rule)?;
    step_count("--step", h, duration, work_per_step)
}

/// Steps a fixed-step scene takes per method between checks; large enough that the clock reads
/// cost nothing.
pub const BLOCK_STEPS: usize = 4096;

/// The longest block of ticks of a fixed-step scene: [`BLOCK_STEPS`] over the most own steps a
/// method takes in a tick (`--step` below dt), so that a block holds about as many steps either
/// way and Ctrl-C is looked at as often.
pub fn block_ticks(dt: f64, options: &crate::integrate::MethodOptions) -> u64 {
    let per_tick = options.step.map_or(1, |h| (dt / h).ceil().max(1.0) as u64);
    (BLOCK_STEPS as u64 / per_tick).max(1)
}

/// A refusal of runs of more than `MAX_STEPS` steps of `step` (the flag `option` sets), or
/// whose work (steps × `work_per_step`, e.g. nodes) would take hours.
fn step_count(option: &str, step: f64, duration: f64, work_per_step: usize) -> Result<(), Invalid> {
    let steps = duration / step;
    if steps > MAX_STEPS {
        return Err(Invalid::Usage(format!(
            "{option} {} with --duration {} is {steps:.2e} steps per method; at most {MAX_STEPS:.0e} \
             are allowed (raise {option} or shorten --duration)",
            shown(step),
            shown(duration)
        )));
    }
    let work = steps * work_per_step as f64;
    if work > MAX_NODE_STEPS {
        return Err(Invalid::Usage(format!(
            "--duration {} / {option} {} × {work_per_step} nodes is {work:.2e} node-steps per method; \
             at most {MAX_NODE_STEPS:.0e} are allowed (raise {option}, shorten --duration or use fewer --nodes)",
            shown(duration),
            shown(step)
        )));
    }
    Ok(())
}

/// The memory a run may still take [bytes]: this machine's MemAvailable, or what is left under
/// the process's address-space limit (`ulimit -v`) when that is less, with which of the two it is.
pub fn memory_room() -> Option<(f64, &'static str)> {
    let field = |file: &str, key: &str| -> Option<f64> {
        let text = std::fs::read_to_string(file).ok()?;
        let line = text.lines().find(|l| l.starts_with(key))?;
        Some(line.split_whitespace().nth(1)?.parse::<f64>().ok()? * 1024.0)
    };
    let available = field("/proc/meminfo", "MemAvailable:").map(|a| (a, "available"));
    let under_limit = crate::interrupt::limit(libc::RLIMIT_AS).map(|limit| {
        let used = field("/proc/self/status", "VmSize:").unwrap_or(0.0);
        let left = (limit as f64 - used).max(0.0);
        (left, "left under the address-space limit (`ulimit -v`)")
    });
    [available, under_limit]
        .into_iter()
        .flatten()
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// Refuses a run whose state would not fit in memory, naming the estimate and what to change.
pub fn memory(what: &str, bytes: f64, change: &str) -> Result<(), Invalid> {
    if let Some((room, which)) = memory_room()
        && bytes > 0.8 * room
    {
        return Err(Invalid::Usage(format!(
            "{what} needs about {:.1} GB of memory, more than the {:.1} GB {which}; {change}",
            bytes / 1e9,
            room / 1e9
        )));
    }
    Ok(())
}

/// The methods as given, first occurrence kept (an empty list stays empty, for `validate()` to
/// refuse: `methods = []` in a scene file is no more a request for the defaults than
/// `--methods ""` is).
pub fn dedup_methods<M: Copy + PartialEq>(given: &[M]) -> Vec<M> {
    let mut methods: Vec<M> = Vec::new();
    for &m in given {
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    methods
}

/// Worker threads allowed per core: a few more threads than cores can hide a stall, while
/// thousands only add switching (and each must see a stop request).
pub const MAX_THREADS_PER_CORE: usize = 4;

/// The cores this process may run on (1 when unknown).
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// A worker thread count between 1 and [`MAX_THREADS_PER_CORE`] × the cores.
pub fn threads(n: usize) -> Result<(), Invalid> {
    let max = MAX_THREADS_PER_CORE * cores();
    if (1..=max).contains(&n) {
        Ok(())
    } else {
        Err(Invalid::Usage(format!(
            "--threads {n}: must be between 1 and {max} ({MAX_THREADS_PER_CORE} × the {} cores here)",
            cores()
        )))
    }
}

/// At least one method to run; `names` are those allowed.
pub fn some_methods<M>(methods: &[M], names: &[&str]) -> Result<(), Invalid> {
    let rule = format!(
        "must name at least one method (any of: {})",
        names.join(", ")
    );
    refuse_unless(!methods.is_empty(), "--methods", "[]", rule)
}

/// How a configuration reads and writes its settings (the scene file's schema is the
/// configuration itself): a vector is `[x, y, z]` of finite numbers.
pub mod vec3 {
    use glam::DVec3;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &DVec3, s: S) -> Result<S::Ok, S::Error> {
        v.to_array().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<DVec3, D::Error> {
        match Vec::<f64>::deserialize(d)?[..] {
            [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(DVec3::new(x, y, z)),
            _ => Err(serde::de::Error::custom(
                "expected [x, y, z] with finite numbers, z up",
            )),
        }
    }
}

/// A magnitude written as a number or as a vector `[x, y, z]`, of which it is the length (the
/// pendulum's gravity, which the other scenes take as a vector).
pub fn magnitude<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    #[derive(serde::Deserialize)]
    #[serde(untagged)]
    enum Written {
        Number(f64),
        Vector(#[serde(with = "vec3")] glam::DVec3),
    }
    serde::Deserialize::deserialize(d)
        .map(|g| match g {
            Written::Number(x) => x,
            Written::Vector(v) => v.length(),
        })
        .map_err(|_| serde::de::Error::custom("expected g or [x, y, z] with finite numbers"))
}

/// A scene's configuration as the scene file and the flags give it: its serialised form is its
/// table in a scene file (every key a parameter, named as its flag), so values are layered as
/// tables (defaults < preset < file < flags) and no list of fields is written anywhere else.
pub trait SceneConfig: Clone + Default + serde::Serialize + serde::de::DeserializeOwned {
    /// The configuration a preset it names starts from (the file and flags then override it).
    fn preset_base(&self) -> Option<Self> {
        None
    }
    /// Sets what follows from other values once every layer is read; `given` says whether a key
    /// was given (by a preset, the file or a flag) rather than defaulted.
    fn settle(&mut self, _given: &dyn Fn(&str) -> bool) -> Result<(), Invalid> {
        Ok(())
    }
    /// The keys that set one value with `key` (hair's `dt` and `substeps`): a layer that gives
    /// `key` replaces what the layers below it give of these, as it replaces `key`.
    fn same_value(_key: &str) -> &'static [&'static str] {
        &[]
    }
    /// Every value in range, or the first that is not, named by its flag.
    fn validate(&self) -> Result<(), Invalid>;
    /// Why the step is too large for the scene's shortest time scale, naming the scale: allowed
    /// (a study of instability wants it), but most often a unit mistake (`--dt 10` for 10 ms).
    fn step_warning(&self) -> Option<String> {
        None
    }
}
