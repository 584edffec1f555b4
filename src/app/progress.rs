//! A progress bar on stderr for runs longer than a second, when stderr is a terminal and the
//! user did not ask for quiet, and a notice when a scene will take long or write much.
//! [`WithProgress`] wraps any scene's observer and reports the simulated time of each 3D frame.

use std::io::IsTerminal as _;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

use crate::scene::harness::{Event, Frame, Observer, Run, Scene, SeriesBatch};

/// Shows after one second; silent when quiet or when stderr is not a terminal.
pub struct Progress {
    enabled: bool,
    quiet: bool,
    /// The recording's bytes written so far, when it is written to a file.
    written: Option<Arc<AtomicU64>>,
    /// Bytes written when the current stage started.
    stage_bytes: u64,
    /// Whether the current stage's notice was considered already.
    noticed: bool,
    started: Instant,
    bar: Option<ProgressBar>,
    label: String,
    end: f64,
    /// When the current stage started, for the remaining-time estimate.
    stage_started: Instant,
}

impl Progress {
    pub fn new(quiet: bool, written: Option<Arc<AtomicU64>>) -> Self {
        Progress {
            enabled: !quiet && std::io::stderr().is_terminal(),
            quiet,
            written,
            stage_bytes: 0,
            noticed: false,
            started: Instant::now(),
            bar: None,
            label: String::new(),
            end: 1.0,
            stage_started: Instant::now(),
        }
    }

    /// Starts a new stage: `label` runs to simulated time `end` [s].
    pub fn stage(&mut self, label: &str, end: f64) {
        self.label = label.to_string();
        self.end = end.max(1e-12);
        self.stage_started = Instant::now();
        self.stage_bytes = self.bytes();
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
        let elapsed = self.stage_started.elapsed();
        if !self.noticed && !self.quiet && elapsed >= NOTICE_AFTER {
            self.noticed = true;
            let written = self
                .written
                .as_ref()
                .map(|_| (self.bytes() - self.stage_bytes) as f64);
            let done = (t / self.end).clamp(0.0, 1.0);
            if let Some(notice) = long_run_notice(&self.label, elapsed, done, written) {
                match &self.bar {
                    Some(bar) => bar.println(notice),
                    None => eprintln!("{notice}"),
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
                // The estimate is ours: the stage's elapsed time scaled by what is left.
                ProgressStyle::with_template(
                    "{prefix:>9} [{bar:40}] {percent:>3}% {elapsed} (eta {msg})",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar.set_prefix(self.label.clone());
            self.bar = Some(bar);
        }
        if let Some(bar) = &self.bar {
            let done = (t / self.end).clamp(0.0, 1.0);
            bar.set_position((1000.0 * done) as u64);
            bar.set_message(eta_text(self.stage_started.elapsed(), done));
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

/// What a scene that `elapsed` took to `done` (0–1) of its simulated time, writing `written`
/// bytes meanwhile, will take in all at that pace, when that is long or large (the pace of a
/// scene's steps and recording is steady: every step costs the same and 3D frames come evenly).
fn long_run_notice(
    label: &str,
    elapsed: Duration,
    done: f64,
    written: Option<f64>,
) -> Option<String> {
    if done <= 0.0 || done >= 1.0 {
        return None;
    }
    let seconds = elapsed.as_secs_f64() / done;
    let bytes = written.map(|w| w / done);
    if seconds <= LONG_SECONDS && bytes.is_none_or(|b| b <= LARGE_BYTES) {
        return None;
    }
    let size = bytes.map_or(String::new(), |b| {
        format!(" and writes about {} to its recording", size_text(b))
    });
    Some(format!(
        "{label}: this scene takes about {}{size} in all (its pace over the first {:.1} s, {:.2} % of \
         its simulated time, extrapolated); Ctrl-C stops it and keeps what is recorded",
        duration_text(seconds),
        elapsed.as_secs_f64(),
        100.0 * done
    ))
}

/// A duration rounded for reading: "45 s", "3 min 05 s", "7 h 12 min".
fn duration_text(seconds: f64) -> String {
    let s = seconds.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

/// A size rounded for reading: "120 MB", "3.4 GB".
fn size_text(bytes: f64) -> String {
    if bytes < 1e9 {
        format!("{:.0} MB", bytes / 1e6)
    } else {
        format!("{:.1} GB", bytes / 1e9)
    }
}

/// The remaining time when `done` (0–1) took `elapsed`, rounded for reading: "12s", "3m 05s",
/// "?" before anything is done.
fn eta_text(elapsed: Duration, done: f64) -> String {
    if done <= 0.0 {
        return "?".into();
    }
    let left = (elapsed.as_secs_f64() * (1.0 - done) / done).round() as u64;
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
    fn finish(&mut self, scene: &S, run: &Run<S::Lane>) -> anyhow::Result<()> {
        self.inner.finish(scene, run)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_is_said_long_or_large_from_its_pace_extrapolated() {
        let second = Duration::from_secs(1);
        // 1 % in a second: 100 s in all.
        let long = long_run_notice("pendulum", second, 0.01, None).unwrap();
        assert!(long.contains("about 1 min 40 s in all"), "{long}");
        assert!(!long.contains("writes"), "{long}");
        // Half in a second: 2 s, 2 MB in all — neither long nor large.
        assert_eq!(long_run_notice("rope", second, 0.5, Some(1e6)), None);
        // Quick but large: 40 MB at 20 % is 200 MB.
        let large = long_run_notice("hair", second, 0.2, Some(40e6)).unwrap();
        assert!(
            large.contains("about 5 s and writes about 200 MB"),
            "{large}"
        );
        // 10^8 steps at the pace of 0.004 %: hours and gigabytes.
        let huge = long_run_notice("pendulum", second, 4e-5, Some(1.6e6)).unwrap();
        assert!(
            huge.contains("6 h 56 min") && huge.contains("40.0 GB"),
            "{huge}"
        );
        // Nothing to extrapolate from, or nothing left.
        assert_eq!(long_run_notice("x", second, 0.0, None), None);
        assert_eq!(long_run_notice("x", second, 1.0, None), None);
    }

    #[test]
    fn eta_scales_elapsed_by_what_is_left() {
        assert_eq!(eta_text(Duration::from_secs(10), 0.25), "30s");
        assert_eq!(eta_text(Duration::from_secs(100), 0.5), "1m 40s");
        assert_eq!(eta_text(Duration::from_secs(3), 0.0), "?");
        assert_eq!(eta_text(Duration::from_secs(3), 1.0), "0s");
    }
}
