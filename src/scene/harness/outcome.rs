//! What a run leaves: every lane's final state and bookkeeping (ticks accepted, time spent,
//! evaluations, where it diverged).

use std::time::Duration;

use super::{Event, Schedule};
use crate::integrate::Counts;

/// One lane's bookkeeping: what the summary needs besides the scene's own measurements.
#[derive(Clone, Debug, Default)]
pub struct LaneStats {
    pub name: &'static str,
    pub is_method: bool,
    /// Ticks accepted (up to divergence).
    pub ticks: u64,
    /// Wall time spent in `advance`.
    pub wall: Duration,
    /// Ticks stepped while timed (a diverged block may step past its divergence).
    pub timed_ticks: u64,
    pub counts: Counts,
    pub divergence: Option<Event>,
}

impl LaneStats {
    /// Ticks taken: the accepted ones and, if the lane diverged, the one that failed.
    pub fn ticks_taken(&self) -> u64 {
        self.ticks + u64::from(self.divergence.is_some())
    }

    /// Whether the lane failed its first check, so that it has no figures to show (a summary
    /// shows "—" rather than the zeros it started from).
    pub fn failed_at_once(&self) -> bool {
        self.ticks == 0 && self.divergence.is_some()
    }

    /// Wall time per tick [ns], for method lanes that stepped.
    pub fn ns_per_tick(&self) -> Option<f64> {
        (self.is_method && self.timed_ticks > 0)
            .then(|| self.wall.as_nanos() as f64 / self.timed_ticks as f64)
    }

    /// Ticks taken, and an adaptive method's own steps beside them: its steps do not end on
    /// the tick grid, so the ticks alone would not say what it did.
    pub fn steps_text(&self) -> String {
        match self.counts.own_steps {
            Some((accepted, rejected)) => format!(
                "{} (own: {accepted} + {rejected} rejected)",
                self.ticks_taken()
            ),
            None => self.ticks_taken().to_string(),
        }
    }

    /// Wall time per step of the method [ns]: per tick, or per own step (accepted or
    /// rejected) for an adaptive method.
    pub fn ns_per_step(&self) -> Option<f64> {
        match self.counts.own_steps {
            Some((accepted, rejected)) if accepted + rejected > 0 => self
                .ns_per_tick()
                .map(|_| self.wall.as_nanos() as f64 / (accepted + rejected) as f64),
            Some(_) => None,
            None => self.ns_per_tick(),
        }
    }
}

/// A finished (or interrupted) run: the lanes' final states and their bookkeeping.
pub struct Run<L> {
    pub lanes: Vec<L>,
    pub stats: Vec<LaneStats>,
    /// Whether the run stopped early on request (Ctrl-C).
    pub interrupted: bool,
    /// The last tick the run reached: the schedule's total, or where it was interrupted.
    pub last_tick: u64,
}

impl<L> Run<L> {
    /// Where the run ended, in words: complete, or interrupted at which time and tick; and the
    /// lanes that diverged, when.
    pub fn ending(&self, schedule: &Schedule) -> String {
        let mut text = if self.interrupted {
            format!(
                "ended early: interrupted (Ctrl-C) at t = {} s, tick {} of {} ({:.1}% of the run); \
                 the configuration's duration is what was asked, not what was run",
                schedule.time(self.last_tick),
                self.last_tick,
                schedule.total,
                100.0 * self.last_tick as f64 / schedule.total as f64
            )
        } else {
            format!(
                "complete: t = {} s, {} ticks",
                schedule.end_time(),
                schedule.total
            )
        };
        for s in &self.stats {
            if let Some(e) = &s.divergence {
                text.push_str(&format!(
                    "; {} stopped at t = {} s (tick {}): diverged",
                    s.name, e.time, e.tick
                ));
            }
        }
        text
    }

    /// `scene/lane` for every lane that diverged.
    pub fn diverged(&self, scene: &str) -> Vec<String> {
        self.stats
            .iter()
            .filter(|s| s.divergence.is_some())
            .map(|s| format!("{scene}/{}", s.name))
            .collect()
    }
}

/// The summaries' "diverged" cell: when the lane was stopped and how many implicit solves
/// missed their tolerance.
pub fn divergence_cell(stats: &LaneStats) -> String {
    let mut cell = match &stats.divergence {
        Some(ev) => format!("yes, t = {:.4} s", ev.time),
        None => "no".to_string(),
    };
    let failed = stats.counts.failed_solves;
    if failed > 0 {
        cell.push_str(&format!("; Newton missed tolerance on {failed} steps"));
    }
    cell
}
