//! The schedule a run follows: its ticks, how a tick maps to simulated time, which ticks are
//! plotted and which are drawn in 3D.

use super::series::SeriesPlan;
use crate::error::Error;
use crate::format::{shown, trim_number};
use crate::scene::m4::MAX_COLUMNS;

/// A run that samples at most this many ticks keeps every sampled row; a longer one keeps an M4
/// aggregate of its whole run and every row of its windows ([`super::LaneSeries`]).
pub const MAX_PLOT_POINTS: u64 = 10_000;

/// Rows a window keeps at most: the first and the last window are cut to this many.
pub const MAX_WINDOW_ROWS: u64 = MAX_PLOT_POINTS;

/// Rows the windows asked for (`--window`) keep at most per lane, together.
pub const MAX_ASKED_WINDOW_ROWS: u64 = 10 * MAX_PLOT_POINTS;

/// A stretch of simulated time whose every sampled step is kept (`--window FROM:TO`, seconds).
/// A negative end (`-0` too: the end itself) counts back from the end of the run; an empty one is
/// the run's start or end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    pub from: Option<f64>,
    pub to: Option<f64>,
}

impl std::str::FromStr for Window {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let rule = "must be FROM:TO in seconds (either may be empty: the run's start or end; \
                    negative counts back from the end), e.g. 0:20 or -20:";
        let (from, to) = text.split_once(':').ok_or(rule)?;
        let end = |e: &str| -> Result<Option<f64>, String> {
            match e.trim() {
                "" => Ok(None),
                e => match e.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(Some(v)),
                    _ => Err(rule.to_string()),
                },
            }
        };
        Ok(Window {
            from: end(from)?,
            to: end(to)?,
        })
    }
}

impl std::fmt::Display for Window {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let end = |e: Option<f64>| e.map_or(String::new(), shown);
        write!(f, "{}:{}", end(self.from), end(self.to))
    }
}

crate::integrate::serde_as_text!(Window, |w: &Window| w.to_string());

/// A run's windows: the first and the last `edge_seconds` (the last one before each lane
/// stops), and those asked for.
#[derive(Clone, Debug, PartialEq)]
pub struct Windows {
    pub edge_seconds: f64,
    pub asked: Vec<Window>,
}

impl Windows {
    /// The first and last ten seconds, and those asked for.
    pub fn with(asked: &[Window]) -> Self {
        Windows {
            edge_seconds: 10.0,
            asked: asked.to_vec(),
        }
    }
}

/// `ranges` (in order, apart) with `range` added: those it overlaps or touches merged into one,
/// so that a tick is in one range at most.
fn merged_ranges(ranges: Vec<(u64, u64)>, range: (u64, u64)) -> Vec<(u64, u64)> {
    let (mut from, mut to) = range;
    let mut out = Vec::with_capacity(ranges.len() + 1);
    for (a, b) in ranges {
        if b.saturating_add(1) < from || to.saturating_add(1) < a {
            out.push((a, b));
        } else {
            (from, to) = (from.min(a), to.max(b));
        }
    }
    let at = out.partition_point(|r: &(u64, u64)| r.0 < from);
    out.insert(at, (from, to));
    out
}

/// 3D frames a run draws at most. A longer run draws the first and the last half of this many
/// (the motion as it starts and as it ends, at the frame rate asked for) and none between, so
/// that its 3D part does not grow with its length; the plots and every check still cover every
/// step.
pub const MAX_FRAMES: u64 = 6000;

/// How a tick maps to simulated time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Clock {
    /// Each tick is one step of this many seconds: t = tick · dt.
    Step(f64),
    /// This many ticks per second: t = tick / rate.
    Rate(f64),
}

impl Clock {
    pub fn time(self, tick: u64) -> f64 {
        match self {
            Clock::Step(dt) => tick as f64 * dt,
            Clock::Rate(rate) => tick as f64 / rate,
        }
    }
}

/// When a run ticks, hands 3D frames to the observer and samples its series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schedule {
    /// Ticks in the run, at least 1.
    pub total: u64,
    /// 3D frames asked for per simulated second. Frame k is handed out at the tick nearest to
    /// k / fps s (within half a tick), so that frames come at `fps` on average whatever the step;
    /// when a tick is longer than 1 / fps, every tick is a frame ([`Schedule::frame_rate`]).
    pub fps: f64,
    /// Ticks between sampled series values (the final tick is always sampled), at least 1.
    pub plot_stride: u64,
    pub clock: Clock,
}

impl Schedule {
    /// A fixed-step schedule: round(duration / dt) steps, 3D frames at `fps`, series sampled
    /// every `plot_every` steps.
    pub fn fixed_step(dt: f64, duration: f64, fps: f64, plot_every: u64) -> Self {
        Schedule {
            total: ((duration / dt).round() as u64).max(1),
            fps,
            plot_stride: plot_every.max(1),
            clock: Clock::Step(dt),
        }
    }

    /// Simulated seconds per tick.
    pub fn tick_seconds(&self) -> f64 {
        match self.clock {
            Clock::Step(dt) => dt,
            Clock::Rate(rate) => 1.0 / rate,
        }
    }

    /// Ticks per 3D frame on average (at least 1): 1 / (fps · dt), or rate / fps.
    pub fn ticks_per_frame(&self) -> f64 {
        match self.clock {
            Clock::Step(dt) => 1.0 / (self.fps * dt),
            Clock::Rate(rate) => rate / self.fps,
        }
        .max(1.0)
    }

    /// The 3D frames' actual rate [Hz]: `fps`, or one per tick when ticks are longer than a frame.
    pub fn frame_rate(&self) -> f64 {
        1.0 / (self.ticks_per_frame() * self.tick_seconds())
    }

    /// The tick of 3D frame k: the one nearest to k / fps s.
    pub fn frame_tick(&self, k: u64) -> u64 {
        (k as f64 * self.ticks_per_frame()).round() as u64
    }

    /// The last 3D frame at or before `tick`.
    pub fn frame_at(&self, tick: u64) -> u64 {
        let k = self.uniform_frame_at(tick);
        match self.gap() {
            Some((a, b)) if (a..=b).contains(&k) => a - 1,
            _ => k,
        }
    }

    /// The frames a run of more than [`MAX_FRAMES`] does not draw, first and last: frame k comes
    /// at the same tick whether drawn or not, so that `frame` numbers one moment in every scene.
    pub fn gap(&self) -> Option<(u64, u64)> {
        let all = self.uniform_frame_at(self.total) + 1;
        (all > MAX_FRAMES).then(|| (MAX_FRAMES / 2, all - MAX_FRAMES / 2 - 1))
    }

    /// The first frame drawn from frame `k` on.
    pub fn drawn_from(&self, k: u64) -> u64 {
        match self.gap() {
            Some((a, b)) if (a..=b).contains(&k) => b + 1,
            _ => k,
        }
    }

    /// The last frame at or before `tick`, drawn or not.
    fn uniform_frame_at(&self, tick: u64) -> u64 {
        let mut k = (tick as f64 / self.ticks_per_frame()) as u64;
        while k > 0 && self.frame_tick(k) > tick {
            k -= 1;
        }
        while self.frame_tick(k + 1) <= tick {
            k += 1;
        }
        k
    }

    /// The first 3D frame drawn at or after `tick`.
    pub fn next_frame(&self, tick: u64) -> u64 {
        let k = self.uniform_frame_at(tick);
        self.drawn_from(if self.frame_tick(k) == tick { k } else { k + 1 })
    }

    /// When the 3D frames come, in words (the recordings' `about` panels).
    pub fn frames_text(&self) -> String {
        let all = self.uniform_text();
        match self.gap_text() {
            Some(gap) => format!("{all}; {gap}"),
            None => all,
        }
    }

    fn uniform_text(&self) -> String {
        let (unit, per) = match self.clock {
            Clock::Step(_) => ("step", "steps"),
            Clock::Rate(_) => ("simulation frame", "simulation frames"),
        };
        let tpf = self.ticks_per_frame();
        if tpf == 1.0 && self.frame_rate() < self.fps {
            format!(
                "every {unit}: {:.6} Hz, below the {} Hz asked for ({} frames)",
                self.frame_rate(),
                self.fps,
                self.frames()
            )
        } else if tpf.fract() == 0.0 {
            format!(
                "{} Hz, every {tpf} {per} ({} frames)",
                self.fps,
                self.frames()
            )
        } else {
            format!(
                "{} Hz: frame k at the {unit} nearest k/{} s, {tpf:.4} {per} apart on average ({} frames)",
                self.fps,
                self.fps,
                self.frames()
            )
        }
    }

    /// 3D frames drawn in the run, frame 0 (tick 0) included.
    pub fn frames(&self) -> u64 {
        let all = self.uniform_frame_at(self.total) + 1;
        all - self.gap().map_or(0, |(a, b)| b - a + 1)
    }

    /// Which 3D frames a run beyond [`MAX_FRAMES`] draws, in words (none when it draws all).
    pub fn gap_text(&self) -> Option<String> {
        let (a, b) = self.gap()?;
        let all = self.uniform_frame_at(self.total) + 1;
        Some(format!(
            "3D drawn over t ≤ {} s and t ≥ {} s only: {} of the {all} frames at the rate asked \
             for (at most {MAX_FRAMES} are drawn); the 3D view holds still between, while the \
             plots and every check cover every step",
            trim_number(self.time(self.frame_tick(a - 1)), 3),
            trim_number(self.time(self.frame_tick(b + 1)), 3),
            self.frames()
        ))
    }

    /// Whether the run samples more ticks than a plot keeps whole, so that its series are
    /// aggregated (M4) outside its windows.
    pub fn aggregates(&self) -> bool {
        self.total.div_ceil(MAX_PLOT_POINTS) > self.plot_stride
    }

    /// A window's sampled ticks (an inclusive range), or `None` when it holds none.
    fn window_ticks(&self, w: &Window) -> Option<(u64, u64)> {
        let end = self.end_time();
        let at = |e: f64| if e.is_sign_negative() { end + e } else { e };
        let (from, to) = (w.from.map_or(0.0, at), w.to.map_or(end, at));
        let per_tick = self.tick_seconds();
        let first = ((from / per_tick).ceil().max(0.0) as u64).next_multiple_of(self.plot_stride);
        let last = ((to / per_tick).floor().max(0.0) as u64).min(self.total);
        (from <= to && first <= last).then_some((first, last))
    }

    /// Sampled rows in a range of ticks.
    fn rows_in(&self, (first, last): (u64, u64)) -> u64 {
        last / self.plot_stride - first.div_ceil(self.plot_stride) + 1
    }

    /// The windows asked for as inclusive ranges of ticks, overlapping ones merged, in order; an
    /// error (the window and why) for a window that holds no sampled step, or once together they
    /// keep more than [`MAX_ASKED_WINDOW_ROWS`] rows.
    pub fn asked_windows(&self, asked: &[Window]) -> Result<Vec<(u64, u64)>, (Window, String)> {
        let mut ticks = Vec::new();
        for &w in asked {
            let Some(t) = self.window_ticks(&w) else {
                let end = shown(self.end_time());
                let why = format!(
                    "holds no plotted step of the run, which spans 0 to {end} s (FROM must not be \
                     after TO; negative ends count back from the end)"
                );
                return Err((w, why));
            };
            ticks = merged_ranges(ticks, t);
            let rows: u64 = ticks.iter().map(|&t| self.rows_in(t)).sum();
            if rows > MAX_ASKED_WINDOW_ROWS {
                let why = format!(
                    "the windows keep {rows} plotted steps per lane whole so far; at most \
                     {MAX_ASKED_WINDOW_ROWS} are kept (shorten the windows, or thin them with \
                     --plot-every)"
                );
                return Err((w, why));
            }
        }
        Ok(ticks)
    }

    /// The windows asked for (`--window`) each hold a plotted step, and not too many together.
    pub fn check_windows(&self, asked: &[Window]) -> Result<(), Error> {
        self.asked_windows(asked)
            .map(|_| ())
            .map_err(|(w, rule)| Error::param("--window", w, rule))
    }

    /// The first window's ticks and the rows of the last one: `edge_seconds`, cut to
    /// [`MAX_WINDOW_ROWS`] rows.
    fn edge_rows(&self, edge_seconds: f64) -> u64 {
        let ticks = (edge_seconds / self.tick_seconds()).ceil() as u64;
        (ticks / self.plot_stride + 1).min(MAX_WINDOW_ROWS)
    }

    /// Sampled rows kept whole: every one, or those of the windows.
    pub fn whole_rows(&self, windows: &Windows) -> u64 {
        match self.series_plan(windows) {
            None => self.total / self.plot_stride + 1,
            Some(plan) => {
                plan.last_rows as u64 + plan.windows.iter().map(|&w| self.rows_in(w)).sum::<u64>()
            }
        }
    }

    /// How a run longer than [`MAX_PLOT_POINTS`] sampled ticks keeps its rows (`None`: every
    /// sampled row). Windows that cannot be kept were refused when the configuration was
    /// validated ([`Schedule::asked_windows`]).
    pub fn series_plan(&self, windows: &Windows) -> Option<SeriesPlan> {
        if !self.aggregates() {
            return None;
        }
        let edge = self.edge_rows(windows.edge_seconds);
        let asked = self.asked_windows(&windows.asked).unwrap_or_default();
        let ticks = asked
            .into_iter()
            .fold(vec![(0, (edge - 1) * self.plot_stride)], merged_ranges);
        Some(SeriesPlan {
            windows: ticks,
            last_rows: edge as usize,
        })
    }

    /// Which steps the plots hold, in words (summaries and the recordings' `about` panels).
    pub fn series_text(&self, windows: &Windows) -> String {
        let every = if self.plot_stride == 1 {
            "every step".to_string()
        } else {
            format!("every {} steps", self.plot_stride)
        };
        let Some(plan) = self.series_plan(windows) else {
            return format!("{every} of the run");
        };
        let edge = trim_number(self.time((plan.last_rows as u64 - 1) * self.plot_stride), 3);
        let asked = (windows.asked)
            .iter()
            .map(|w| format!(" and {w} s"))
            .collect::<String>();
        format!(
            "the run's {} sampled steps aggregated (M4) over {MAX_COLUMNS} columns: per \
             column the first, last, least and greatest value of every quantity, so that a plot up \
             to {MAX_COLUMNS} px wide (or {}, {}, ... px) draws what every step would; {every} \
             kept whole over t ≤ {edge} s, the last {edge} s before each lane stops (at the end, \
             a divergence or Ctrl-C){asked}; every check still runs on every step",
            self.total / self.plot_stride + 1,
            MAX_COLUMNS / 2,
            MAX_COLUMNS / 4,
        )
    }

    /// Whether the series are sampled at `tick`.
    pub fn samples(&self, tick: u64) -> bool {
        // (A division per step and lane costs more than the rest of the test.)
        self.plot_stride == 1 || tick.is_multiple_of(self.plot_stride) || tick == self.total
    }

    pub fn time(&self, tick: u64) -> f64 {
        self.clock.time(tick)
    }

    /// Simulated time at the end of the run [s].
    pub fn end_time(&self) -> f64 {
        self.time(self.total)
    }
}
