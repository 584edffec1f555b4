//! A progress bar on stderr for runs longer than a second, when stderr is a terminal and the
//! user did not ask for quiet. [`WithProgress`] wraps any scene's observer and reports the
//! simulated time of each 3D frame.

use std::io::IsTerminal as _;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

use crate::scene::harness::{Event, Frame, Observer, Run, Scene, SeriesBatch};

/// Shows after one second; silent when quiet or when stderr is not a terminal.
pub struct Progress {
    enabled: bool,
    started: Instant,
    bar: Option<ProgressBar>,
    label: String,
    end: f64,
    /// When the current stage started, for the remaining-time estimate.
    stage_started: Instant,
}

impl Progress {
    pub fn new(quiet: bool) -> Self {
        Progress {
            enabled: !quiet && std::io::stderr().is_terminal(),
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
        if let Some(bar) = &self.bar {
            bar.set_prefix(self.label.clone());
            bar.set_position(0);
        }
    }

    /// Simulated time reached.
    pub fn at(&mut self, t: f64) {
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
    fn eta_scales_elapsed_by_what_is_left() {
        assert_eq!(eta_text(Duration::from_secs(10), 0.25), "30s");
        assert_eq!(eta_text(Duration::from_secs(100), 0.5), "1m 40s");
        assert_eq!(eta_text(Duration::from_secs(3), 0.0), "?");
        assert_eq!(eta_text(Duration::from_secs(3), 1.0), "0s");
    }
}
