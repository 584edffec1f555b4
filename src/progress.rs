//! A progress bar on stderr for runs longer than a second, when stderr is a terminal and the
//! user did not ask for quiet. Observers wrap a scene's observer and report simulated time.

use std::io::IsTerminal as _;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

use crate::scene::hair::Hair;
use crate::scene::hair::run::{HairConfig, HairFrame, HairObserver};
use crate::scene::pendulum::run::{
    FrameState, PendulumObserver, RunSetup, RunSummary, SeriesBlock,
};
use crate::scene::rope::run::{RopeFrame, RopeObserver, RopeSeries, RopeSetup, RopeSummary};
use crate::scene::schedule::Event;

/// Shows after one second; silent when quiet or when stderr is not a terminal.
pub struct Progress {
    enabled: bool,
    started: Instant,
    bar: Option<ProgressBar>,
    label: String,
    end: f64,
}

impl Progress {
    pub fn new(quiet: bool) -> Self {
        Progress {
            enabled: !quiet && std::io::stderr().is_terminal(),
            started: Instant::now(),
            bar: None,
            label: String::new(),
            end: 1.0,
        }
    }

    /// Starts a new stage: `label` runs to simulated time `end` [s].
    pub fn stage(&mut self, label: &str, end: f64) {
        self.label = label.to_string();
        self.end = end.max(1e-12);
        if let Some(bar) = &self.bar {
            bar.set_message(self.label.clone());
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
                ProgressStyle::with_template(
                    "{msg:>9} [{bar:40}] {percent:>3}% {elapsed} (eta {eta})",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar.set_message(self.label.clone());
            self.bar = Some(bar);
        }
        if let Some(bar) = &self.bar {
            bar.set_position((1000.0 * (t / self.end).clamp(0.0, 1.0)) as u64);
        }
    }

    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// A scene observer that also moves the progress bar.
pub struct WithProgress<'a, O: ?Sized> {
    pub inner: &'a mut O,
    pub progress: &'a mut Progress,
}

impl<O: PendulumObserver + ?Sized> PendulumObserver for WithProgress<'_, O> {
    fn start(&mut self, setup: &RunSetup) -> anyhow::Result<()> {
        self.inner.start(setup)
    }
    fn series(&mut self, lane: usize, block: &SeriesBlock) -> anyhow::Result<()> {
        self.inner.series(lane, block)
    }
    fn frame(&mut self, frame: &FrameState) -> anyhow::Result<()> {
        self.progress.at(frame.time);
        self.inner.frame(frame)
    }
    fn event(&mut self, event: &Event) -> anyhow::Result<()> {
        self.inner.event(event)
    }
    fn finish(&mut self, summary: &RunSummary) -> anyhow::Result<()> {
        self.inner.finish(summary)
    }
}

impl<O: RopeObserver + ?Sized> RopeObserver for WithProgress<'_, O> {
    fn start(&mut self, setup: &RopeSetup) -> anyhow::Result<()> {
        self.inner.start(setup)
    }
    fn series(&mut self, lane: usize, series: &RopeSeries) -> anyhow::Result<()> {
        self.inner.series(lane, series)
    }
    fn frame(&mut self, frame: &RopeFrame) -> anyhow::Result<()> {
        self.progress.at(frame.time);
        self.inner.frame(frame)
    }
    fn event(&mut self, event: &Event) -> anyhow::Result<()> {
        self.inner.event(event)
    }
    fn finish(&mut self, summary: &RopeSummary) -> anyhow::Result<()> {
        self.inner.finish(summary)
    }
}

impl<O: HairObserver + ?Sized> HairObserver for WithProgress<'_, O> {
    fn start(&mut self, config: &HairConfig, lanes: &[Hair]) -> anyhow::Result<()> {
        self.inner.start(config, lanes)
    }
    fn frame(&mut self, frame: &HairFrame) -> anyhow::Result<()> {
        self.progress.at(frame.time);
        self.inner.frame(frame)
    }
    fn event(&mut self, event: &Event) -> anyhow::Result<()> {
        self.inner.event(event)
    }
}
