//! The schedule a run follows: its ticks, how a tick maps to simulated time, which ticks are
//! plotted and which are drawn in 3D.

/// Series are thinned evenly so that no plot holds more than this many points per lane.
pub const MAX_PLOT_POINTS: u64 = 10_000;

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
    /// A fixed-step schedule: round(duration / dt) steps, 3D frames at `fps`, series every
    /// `plot_every` steps or more, so that no series holds more than [`MAX_PLOT_POINTS`] points.
    pub fn fixed_step(dt: f64, duration: f64, fps: f64, plot_every: u64) -> Self {
        let total = ((duration / dt).round() as u64).max(1);
        Schedule {
            total,
            fps,
            plot_stride: total.div_ceil(MAX_PLOT_POINTS).max(plot_every).max(1),
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
            crate::scene::params::shown(self.time(self.frame_tick(a - 1))),
            crate::scene::params::shown(self.time(self.frame_tick(b + 1))),
            self.frames()
        ))
    }

    /// Whether the series are sampled at `tick`.
    pub fn samples(&self, tick: u64) -> bool {
        tick.is_multiple_of(self.plot_stride) || tick == self.total
    }

    pub fn time(&self, tick: u64) -> f64 {
        self.clock.time(tick)
    }

    /// Simulated time at the end of the run [s].
    pub fn end_time(&self) -> f64 {
        self.time(self.total)
    }
}
