//! A progress bar on stderr for runs longer than a second, when stderr is a terminal and the
//! user did not ask for quiet, and a notice when a scene will take long or write much.
//! [`WithProgress`] wraps any scene's observer and reports the simulated time of each 3D frame.

use std::io::IsTerminal as _;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

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
    /// Whether the current stage's notice was considered already.
    noticed: bool,
    pace: Pace,
}

/// How a stage's wall time and recording grow, measured as it goes. A stage that draws every 3D
/// frame grows evenly with its simulated time. A long one draws its frames at its two ends only
/// ([`crate::scene::harness::Schedule::gap`]): its first window (dense frames, short blocks of
/// steps) costs more per simulated second than its gap, and its last window costs what its first
/// did, so its pace is taken from each part. Its size is twice what its first window wrote, read a
/// second into the gap (before then, the bytes written lag what was logged by the time Rerun
/// holds chunks back).
struct Pace {
    started: Instant,
    /// Bytes written when the stage started.
    bytes0: u64,
    /// Simulated time at the end.
    end: f64,
    /// The simulated times the gap starts and ends at, if there is one.
    gap: Option<(f64, f64)>,
    /// Wall time of the first window, once it is over [s].
    window: Option<f64>,
}

impl Pace {
    /// The whole stage's wall time [s] and, for an even stage, its bytes, from `t` reached with
    /// `bytes` written so far; none before there is a pace to go by.
    fn estimate(&mut self, t: f64, bytes: u64) -> Option<(f64, Option<f64>)> {
        let elapsed = self.started.elapsed().as_secs_f64();
        let done = t / self.end;
        let Some((t1, t2)) = self.gap else {
            let bytes = bytes.saturating_sub(self.bytes0) as f64;
            return (done > 0.0).then(|| (elapsed / done, Some(bytes / done)));
        };
        if t <= t1 {
            return None;
        }
        let window = *self.window.get_or_insert(elapsed);
        if t <= t2 {
            // A second into the gap: its first blocks also wait for the window's chunks, which
            // Rerun has written by then. The last window writes what the first did, and the
            // gap's plots are bounded and small beside them.
            if elapsed - window < 1.0 {
                return None;
            }
            // The gap's pace so far, over all of it: steps cost the same throughout (the rope
            // zeroes the negligible coordinates that made its late steps dearer), and the
            // whole gap's pace is the one least shaken by other work on the machine.
            let gap = (elapsed - window) * (t2 - t1) / (t - t1);
            let bytes = 2.0 * bytes.saturating_sub(self.bytes0) as f64;
            Some((2.0 * window + gap, Some(bytes)))
        } else {
            Some((elapsed + window * (self.end - t) / (self.end - t2), None))
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
            pace: Pace {
                started: Instant::now(),
                bytes0: 0,
                end: 1.0,
                gap: None,
                window: None,
            },
        }
    }

    /// Starts a new stage: `label` runs to simulated time `end` [s], drawing no 3D frame between
    /// the simulated times `gap` gives.
    pub fn stage(&mut self, label: &str, end: f64, gap: Option<(f64, f64)>) {
        self.label = label.to_string();
        self.pace = Pace {
            started: Instant::now(),
            bytes0: self.bytes(),
            end: end.max(1e-12),
            gap,
            window: None,
        };
        self.noticed = false;
        if let Some(bar) = &self.bar {
            bar.set_prefix(self.label.clone());
            bar.set_position(0);
        }
    }

    fn bytes(&self) -> u64 {
        self.written
            .as_ref()
            .map_or(0, |w| w.load(Ordering::Relaxed))
    }

    /// Simulated time reached.
    pub fn at(&mut self, t: f64) {
        let elapsed = self.pace.started.elapsed();
        if !self.noticed && !self.quiet && elapsed >= NOTICE_AFTER {
            let done = t / self.pace.end;
            if let Some((seconds, bytes)) = self.pace.estimate(t, self.bytes()) {
                self.noticed = true;
                let bytes = bytes.filter(|_| self.written.is_some());
                let how = match self.pace.gap {
                    None => "its pace so far, extrapolated",
                    Some(_) => {
                        "the pace of its first 3D window and of its gap so far, extrapolated, \
                         its last window like its first; its recording twice what its first \
                         window wrote, the 3D frame budget's two ends"
                    }
                };
                if let Some(notice) = long_run_notice(&self.label, done, seconds, bytes, how) {
                    match &self.bar {
                        Some(bar) => bar.println(notice),
                        None => eprintln!("{notice}"),
                    }
                }
            }
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
        let left = self
            .pace
            .estimate(t, self.bytes())
            .map(|(seconds, _)| seconds - elapsed.as_secs_f64());
        if let Some(bar) = &self.bar {
            bar.set_position((1000.0 * (t / self.pace.end).clamp(0.0, 1.0)) as u64);
            bar.set_message(left.map_or("?".into(), eta_text));
        }
    }

    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// How long a scene runs before its pace is extrapolated to the whole run.
const NOTICE_AFTER: Duration = Duration::from_secs(1);

/// A scene said to take long: its extrapolated wall time beyond this [s]...
pub const LONG_SECONDS: f64 = 10.0;
/// ...or its recording beyond this many bytes.
pub const LARGE_BYTES: f64 = 100e6;

/// The notice of a scene at `done` (0–1) of its simulated time that will take `seconds` in all
/// and write `bytes` (estimated `how`), when that is long or large.
fn long_run_notice(
    label: &str,
    done: f64,
    seconds: f64,
    bytes: Option<f64>,
    how: &str,
) -> Option<String> {
    if !(0.0..1.0).contains(&done) {
        return None;
    }
    if seconds <= LONG_SECONDS && bytes.is_none_or(|b| b <= LARGE_BYTES) {
        return None;
    }
    let size = bytes.map_or(String::new(), |b| {
        format!(" and writes about {} to its recording", size_text(b))
    });
    Some(format!(
        "{label}: this takes about {}{size} in all ({how}, at {:.2} % of its way); Ctrl-C \
         stops it and keeps what is done",
        duration_text(seconds),
        100.0 * done
    ))
}

/// A duration rounded for reading: "45 s", "3 min 05 s", "7 h 12 min".
pub(super) fn duration_text(seconds: f64) -> String {
    let s = seconds.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

/// A size rounded for reading: "120 MB", "3.4 GB".
pub(super) fn size_text(bytes: f64) -> String {
    if bytes < 1e9 {
        format!("{:.0} MB", bytes / 1e6)
    } else {
        format!("{:.1} GB", bytes / 1e9)
    }
}

/// The remaining time [s] rounded for reading: "12s", "3m 05s".
fn eta_text(left: f64) -> String {
    let left = left.max(0.0).round() as u64;
    if left < 60 {
        format!("{left}s")
    } else {
        format!("{}m {:02}s", left / 60, left % 60)
    }
}

/// A scene observer that also moves the progress bar.
pub struct WithProgress<'a, O: ?Sized> {
    pub inner: &'a mut O,
    pub progress: &'a mut Progress,
}

impl<S: Scene, O: Observer<S> + ?Sized> Observer<S> for WithProgress<'_, O> {
    fn start(&mut self, scene: &S, lanes: &[(&'static str, &S::Lane)]) -> anyhow::Result<()> {
        self.inner.start(scene, lanes)
    }
    fn rows(&self) -> WantedRows {
        self.inner.rows()
    }
    fn series(&mut self, scene: &S, lane: usize, batch: &SeriesBatch) -> anyhow::Result<()> {
        self.inner.series(scene, lane, batch)
    }
    fn frame(&mut self, scene: &S, frame: &Frame<S::Lane>) -> anyhow::Result<()> {
        self.progress.at(frame.time);
        self.inner.frame(scene, frame)
    }
    fn event(&mut self, scene: &S, event: &Event) -> anyhow::Result<()> {
        self.inner.event(scene, event)
    }
    fn reached(&mut self, scene: &S, tick: u64) {
        self.progress.at(scene.schedule().time(tick));
        self.inner.reached(scene, tick);
    }
    fn finish(&mut self, scene: &S, run: &Run<S::Lane>) -> anyhow::Result<()> {
        self.inner.finish(scene, run)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_is_said_long_or_large_from_its_pace_extrapolated() {
        let how = "its pace so far";
        let long = long_run_notice("pendulum", 0.01, 100.0, None, how).unwrap();
        assert!(
            long.contains("about 1 min 40 s in all (its pace so far"),
            "{long}"
        );
        assert!(!long.contains("writes"), "{long}");
        assert_eq!(long_run_notice("rope", 0.5, 2.0, Some(2e6), how), None);
        let large = long_run_notice("hair", 0.2, 5.0, Some(200e6), how).unwrap();
        assert!(
            large.contains("about 5 s and writes about 200 MB"),
            "{large}"
        );
        let huge = long_run_notice("pendulum", 4e-5, 25000.0, Some(4e10), how).unwrap();
        assert!(
            huge.contains("6 h 56 min") && huge.contains("40.0 GB"),
            "{huge}"
        );
        assert_eq!(long_run_notice("x", 1.0, 1e9, None, how), None);
    }

    /// A run with a gap: 1 s for its first window (to t = 100 of 10,000), then 1.5 s more for
    /// 1,000 simulated seconds of gap, is 1 + 14.7 + 1 s in all, and writes twice what it has
    /// written a second into the gap (its two 3D windows); even pace otherwise.
    #[test]
    fn the_pace_of_a_long_run_is_taken_from_its_window_and_its_gap() {
        let at = |ago: f64| Instant::now() - Duration::from_secs_f64(ago);
        let mut pace = Pace {
            started: at(1.0),
            bytes0: 0,
            end: 10_000.0,
            gap: Some((100.0, 9_900.0)),
            window: None,
        };
        assert_eq!(pace.estimate(50.0, 5_000_000), None, "in the first window");
        assert_eq!(pace.estimate(100.5, 8_000_000), None, "just out of it");
        pace.started = at(2.5);
        let (seconds, bytes) = pace.estimate(1_100.0, 9_000_000).unwrap();
        assert!((seconds - (2.0 + 14.7)).abs() < 0.02, "{seconds}");
        assert_eq!(bytes, Some(18e6), "both windows");
        let mut even = Pace { gap: None, ..pace };
        even.started = at(2.0);
        let (seconds, bytes) = even.estimate(1_000.0, 1_000_000).unwrap();
        assert!((seconds - 20.0).abs() < 0.02 && bytes == Some(1e7));
    }

    #[test]
    fn eta_is_rounded_for_reading() {
        assert_eq!(eta_text(30.4), "30s");
        assert_eq!(eta_text(100.0), "1m 40s");
        assert_eq!(eta_text(-1.0), "0s");
    }
}
