//! What every scene's run shares: the step/frame/plot schedule and the events it reports.

/// Series are thinned evenly so that no plot holds more than this many points per method.
pub const MAX_PLOT_POINTS: u64 = 10_000;

/// When a run steps, logs 3D frames and samples its plots, in steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Schedule {
    /// round(duration / dt), at least 1.
    pub total_steps: u64,
    /// Steps between 3D frames: round(1 / (fps dt)), at least 1.
    pub frame_stride: u64,
    /// Steps between plotted samples: the requested stride, or more so that no series holds
    /// more than MAX_PLOT_POINTS points.
    pub plot_stride: u64,
}

impl Schedule {
    pub fn new(dt: f64, duration: f64, fps: f64, plot_every: u64) -> Self {
        let total_steps = ((duration / dt).round() as u64).max(1);
        Schedule {
            total_steps,
            frame_stride: ((1.0 / (fps * dt)).round() as u64).max(1),
            plot_stride: total_steps.div_ceil(MAX_PLOT_POINTS).max(plot_every).max(1),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum EventKind {
    /// The method stopped: its state is not finite or past the scene's stated bound.
    Divergence,
    /// An implicit step's Newton solve missed its tolerance (the step is kept).
    SolverNotConverged,
}

/// Something that happened to one lane at one moment, for the recording's event log.
#[derive(Clone, Debug)]
pub struct Event {
    pub lane: usize,
    pub time: f64,
    pub step: u64,
    pub kind: EventKind,
    pub message: String,
}

/// The summaries' "diverged" cell: when the method was stopped (`at` says how precisely: "t" at
/// the step, "by t" at the first check after it) and how many implicit solves missed their
/// tolerance.
pub fn divergence_cell(divergence: Option<&Event>, at: &str, failed_solves: u64) -> String {
    let mut cell = match divergence {
        Some(ev) => format!("yes, {at} = {:.4} s", ev.time),
        None => "no".to_string(),
    };
    if failed_solves > 0 {
        cell.push_str(&format!(
            "; Newton missed tolerance on {failed_solves} steps"
        ));
    }
    cell
}
