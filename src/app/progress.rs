//! A progress bar on stderr for runs longer than a second (a terminal, not quiet), and a notice
//! when a run will take long or write much. [`WithProgress`] wraps any scene's observer.

use std::io::IsTerminal as _;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

use crate::format;
use crate::scene::harness::{Event, Frame, Observer, Run, Scene, SeriesBatch, WantedRows};

/// Shows after one second; silent when quiet or when stderr is not a terminal.
pub struct Progress {
    enabled: bool,
    quiet: bool,
    /// The recording's bytes written so far, when it is written to a file.
    written: Option<Arc<AtomicU64>>,
    started: Instant,
    bar: Option<ProgressBar>,
    label: String,
    /// When the bar was last moved.
    shown: Instant,
    /// Whether the current stage's estimate was said already.
    noticed: bool,
    pace: Pace,
    /// What a stage may take (`reproduce`).
    pub budget: Option<Budget>,
    /// Wall time of the stages before this one [s].
    before: f64,
    /// The estimate of a stage beyond its budget, in words: the run stops at its next block.
    over: Option<String>,
}

/// What a run may take before it is stopped and refused (`reproduce` without `--allow-long`),
/// judged by the notice's estimate: the run's own pace, so that adaptive steps, inner steps and
/// each method's cost are all in it.
#[derive(Clone, Copy)]
pub struct Budget {
    /// The whole run's wall time [s], earlier stages included.
    pub seconds: f64,
    /// Each stage's recording.
    pub bytes: f64,
    /// State the estimate whatever it is (what a re-run will take is said before its verdict).
    pub say: bool,
}

/// A stage stopped because its estimate is beyond its [`Budget`]: the estimate, in words.
#[derive(Debug)]
pub struct OverBudget(pub String);

impl std::fmt::Display for OverBudget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for OverBudget {}

/// How a stage's wall time and recording grow: ticks and 3D frames each cost the same
/// throughout, counted apart because a long run draws frames at its two ends only
/// ([`crate::scene::harness::Schedule::gap`]). The recording grows by frame (its plots are
/// bounded, or come with the frames).
struct Pace {
    started: Instant,
    /// When its stepping started: its setup (lanes built) is counted once, not extrapolated.
    stepping: Option<Instant>,
    bytes0: u64,
    /// Progress at the end (ticks; any unit for a stage without frames).
    end: f64,
    frames: Option<u64>,
    /// Frames drawn so far, and the recorder's time on them.
    drawn: u64,
    drawing: Duration,
}

impl Pace {
    fn new(end: f64, frames: Option<u64>, bytes0: u64) -> Self {
        Pace {
            started: Instant::now(),
            stepping: None,
            bytes0,
            end: end.max(1e-12),
            frames,
            drawn: 0,
            drawing: Duration::ZERO,
        }
    }

    /// The whole stage's wall time [s] and bytes, from progress `at` reached with `bytes`
    /// written so far; none before there is a pace to go by.
    fn estimate(&self, at: f64, bytes: u64) -> Option<(f64, Option<f64>)> {
        let done = at / self.end;
        if done <= 0.0 {
            return None;
        }
        let setup = (self.stepping).map_or(0.0, |s| (s - self.started).as_secs_f64());
        let elapsed = self.started.elapsed().as_secs_f64() - setup;
        let bytes = bytes.saturating_sub(self.bytes0) as f64;
        match self.frames.filter(|_| self.drawn > 0) {
            Some(frames) => {
                let per_frame = frames as f64 / self.drawn as f64;
                let drawing = self.drawing.as_secs_f64();
                let seconds = (elapsed - drawing).max(0.0) / done + drawing * per_frame;
                Some((setup + seconds, Some(bytes * per_frame)))
            }
            None => Some((setup + elapsed / done, Some(bytes / done))),
        }
    }
}

impl Progress {
    pub fn new(quiet: bool, written: Option<Arc<AtomicU64>>) -> Self {
        Progress {
            enabled: !quiet && std::io::stderr().is_terminal(),
            quiet,
            written,
            started: Instant::now(),
            bar: None,
            label: String::new(),
            shown: Instant::now(),
            noticed: false,
            pace: Pace::new(1.0, None, 0),
            budget: None,
            before: 0.0,
            over: None,
        }
    }

    /// Starts a new stage: `label` runs to progress `end` (ticks, or any unit), drawing
    /// `frames` 3D frames.
    pub fn stage(&mut self, label: &str, end: f64, frames: Option<u64>) {
        self.label = label.to_string();
        self.pace = Pace::new(end, frames, self.bytes());
        self.noticed = false;
        self.before = self.started.elapsed().as_secs_f64();
        if let Some(bar) = &self.bar {
            bar.set_prefix(self.label.clone());
            bar.set_position(0);
        }
    }

    fn bytes(&self) -> u64 {
        (self.written.as_ref()).map_or(0, |w| w.load(Ordering::Relaxed))
    }

    /// Progress reached (ticks, or the stage's unit).
    pub fn at(&mut self, t: f64) {
        let elapsed = self.pace.started.elapsed();
        let estimate = self.pace.estimate(t, self.bytes());
        let done = t / self.pace.end;
        if let Some((seconds, bytes)) = estimate
            && elapsed >= PROBE_AFTER
            && done < 0.5
        {
            let basis = format!(
                "from the cost of its steps and 3D frames so far, at {:.2} % of its way",
                100.0 * done
            );
            self.judge(seconds, bytes.filter(|_| self.written.is_some()), &basis);
        }
        if !self.enabled {
            return;
        }
        if self.bar.is_none() && self.started.elapsed() > Duration::from_secs(1) {
            let bar = ProgressBar::new(1000);
            bar.set_style(
                // indicatif's own {eta} reads 0 s here: the bar appears after a second with
                // its position already far along, so its rate estimate starts out infinite.
                // The estimate is ours (`Pace`).
                ProgressStyle::with_template(
                    "{prefix:>9} [{bar:40}] {percent:>3}% {elapsed} (eta {msg})",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar.set_prefix(self.label.clone());
            self.bar = Some(bar);
        }
        // At most 20 updates a second: `at` comes after every block of steps.
        if self.shown.elapsed() < Duration::from_millis(50) {
            return;
        }
        self.shown = Instant::now();
        let left = estimate.map(|(seconds, _)| seconds - elapsed.as_secs_f64());
        if let Some(bar) = &self.bar {
            bar.set_position((1000.0 * done.clamp(0.0, 1.0)) as u64);
            bar.set_message(left.map_or("?".into(), format::eta));
        }
    }

    /// The stage's estimate of `seconds` (and `bytes`) from `basis`: beyond the budget it stops
    /// the run; said once, when long or large or when the budget asks.
    pub fn judge(&mut self, seconds: f64, bytes: Option<f64>, basis: &str) {
        let text = estimate_text(&self.label, seconds, bytes, basis);
        let say = match self.budget {
            Some(b) => {
                let over = self.before + seconds > b.seconds || bytes.is_some_and(|x| x > b.bytes);
                if over {
                    self.over = Some(text.clone());
                }
                b.say && !over
            }
            None => {
                !self.quiet && (seconds > LONG_SECONDS || bytes.is_some_and(|b| b > LARGE_BYTES))
            }
        };
        if self.noticed || !say {
            return;
        }
        self.noticed = true;
        let notice = match self.budget {
            Some(_) => text,
            None => format!("{text}; Ctrl-C stops it and keeps what is done"),
        };
        let notice = crate::report::table::fit_lines(&notice);
        match &self.bar {
            Some(bar) => bar.println(notice),
            None => eprintln!("{notice}"),
        }
    }

    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// How long a scene runs before its pace is extrapolated: its first blocks are short (a block
/// is at most as many ticks as came before it), so its pace is measured by then.
pub const PROBE_AFTER: Duration = Duration::from_millis(500);

/// A scene said to take long: its extrapolated wall time beyond this [s]...
pub const LONG_SECONDS: f64 = 10.0;
/// ...or its recording beyond this many bytes.
pub const LARGE_BYTES: f64 = 100e6;

fn estimate_text(label: &str, seconds: f64, bytes: Option<f64>, basis: &str) -> String {
    let size = bytes.map_or(String::new(), |b| {
        format!(" and writes about {} to its recording", format::size(b))
    });
    format!(
        "{label}: this takes about {}{size} in all ({basis})",
        format::duration(seconds),
    )
}

/// A scene observer that also moves the progress bar.
pub struct WithProgress<'a, O: ?Sized> {
    pub inner: &'a mut O,
    pub progress: &'a mut Progress,
}

impl<S: Scene, O: Observer<S> + ?Sized> Observer<S> for WithProgress<'_, O> {
    fn start(&mut self, scene: &S, lanes: &[(&'static str, &S::Lane)]) -> anyhow::Result<()> {
        self.progress.pace.stepping = Some(Instant::now());
        self.inner.start(scene, lanes)
    }
    fn rows(&self) -> WantedRows {
        self.inner.rows()
    }
    fn series(&mut self, scene: &S, lane: usize, batch: &SeriesBatch) -> anyhow::Result<()> {
        self.inner.series(scene, lane, batch)
    }
    fn frame(&mut self, scene: &S, frame: &Frame<S::Lane>) -> anyhow::Result<()> {
        let started = Instant::now();
        let drawn = self.inner.frame(scene, frame);
        // Its progress is the block's, said by `reached` (a frame inside a block is older).
        self.progress.pace.drawn += 1;
        self.progress.pace.drawing += started.elapsed();
        drawn
    }
    fn event(&mut self, scene: &S, event: &Event) -> anyhow::Result<()> {
        self.inner.event(scene, event)
    }
    fn reached(&mut self, scene: &S, tick: u64) -> anyhow::Result<()> {
        self.progress.at(tick as f64);
        if let Some(over) = self.progress.over.take() {
            return Err(OverBudget(over).into());
        }
        self.inner.reached(scene, tick)
    }
    fn finish(&mut self, scene: &S, run: &Run<S::Lane>) -> anyhow::Result<()> {
        self.inner.finish(scene, run)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_is_said_long_or_large_and_refused_beyond_its_budget() {
        let long = estimate_text("pendulum", 100.0, None, "from");
        assert!(long.contains("about 1 min 40 s in all (from"), "{long}");
        assert!(!long.contains("writes"), "{long}");
        let huge = estimate_text("pendulum", 25000.0, Some(4e10), "");
        assert!(
            huge.contains("6 h 56 min") && huge.contains("40.0 GB"),
            "{huge}"
        );
        let mut p = Progress::new(true, None);
        p.budget = Some(Budget {
            seconds: 600.0,
            bytes: 1e9,
            say: false,
        });
        p.judge(599.0, Some(9e8), "");
        assert!(p.over.is_none());
        p.before = 2.0;
        p.judge(599.0, None, "");
        assert!(p.over.take().is_some(), "the stages before count");
        p.before = 0.0;
        p.judge(1.0, Some(2e9), "");
        assert!(p.over.is_some(), "too large");
    }

    /// A run of 10,000 ticks drawing 100 frames, 10 of them drawn by tick 50 in 2 s of which
    /// the recorder took 1.5 s and 4 MB: its ticks cost 0.5 s per 50, 100 s in all, its frames
    /// 0.15 s and 0.4 MB each, 15 s and 40 MB in all, though the simulated time done says 400 s.
    #[test]
    fn the_pace_of_a_run_is_its_ticks_and_its_frames_apart() {
        let mut pace = Pace::new(10_000.0, Some(100), 1_000_000);
        pace.started = Instant::now() - Duration::from_secs(2);
        assert_eq!(pace.estimate(0.0, 1_000_000), None, "nothing done yet");
        pace.drawn = 10;
        pace.drawing = Duration::from_millis(1500);
        let (seconds, bytes) = pace.estimate(50.0, 5_000_000).unwrap();
        assert!((seconds - 115.0).abs() < 0.5, "{seconds}");
        assert_eq!(bytes, Some(40e6));
        let mut even = Pace::new(1_000.0, None, 0);
        even.started = Instant::now() - Duration::from_secs(2);
        let (seconds, bytes) = even.estimate(100.0, 1_000_000).unwrap();
        assert!((seconds - 20.0).abs() < 0.02 && bytes == Some(1e7));
    }
}
