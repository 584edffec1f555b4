//! The hair trade: largest stretch over a run against the cost of a frame,
//! over the constraint solvers (Gauss–Seidel sweeps × substeps, direct Newton steps), the
//! spring methods over stiffness and substeps, and DFTL. Each configuration runs alone on the
//! hair scene (its own lane, 200 strands by default), so its wall time per frame is its own;
//! wall times are measured, not deterministic.

use crate::scene::hair::run::{HairConfig, HairScene};
use crate::scene::hair::{HairMethod, Solver};
use crate::scene::harness::{NoObserver, run};

/// Simulated time of each run of the hair study by default [s]: one tour's sway and turn.
pub const DEFAULT_DURATION: f64 = 4.0;

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct HairRow {
    pub method: HairMethod,
    /// verlet's solver (None for the other methods).
    pub solver: Option<Solver>,
    /// Newton steps or sweeps per step.
    pub iterations: u32,
    pub substeps: u32,
    /// Spring stiffness k/m [1/s²] (spring methods only).
    pub stiffness: Option<f64>,
    /// Largest relative stretch over the run (None when the run diverged).
    pub stretch: Option<f64>,
    /// Wall time per simulation frame [ms].
    pub ms_per_frame: f64,
}

impl HairRow {
    /// The configuration as `physlab hair` flags.
    pub fn flags(&self) -> String {
        let method = format!("--methods {}", self.method.name());
        let solver = (self.solver).map_or(String::new(), |s| format!("--solver {}", s.name()));
        let words: Vec<String> = ([method, solver, self.settings()].into_iter())
            .filter(|w| !w.is_empty())
            .collect();
        words.join(" ")
    }

    /// The flags beyond the method and verlet's solver: "--iterations 2 --substeps 4".
    pub fn settings(&self) -> String {
        let mut f = Vec::new();
        if self.solver.is_some() || self.method == HairMethod::ImplicitEuler {
            f.push(format!("--iterations {}", self.iterations));
        }
        if let Some(k) = self.stiffness {
            f.push(format!("--stiffness {k:e}"));
        }
        if self.substeps > 1 {
            f.push(format!("--substeps {}", self.substeps));
        }
        f.join(" ")
    }
}

/// The configurations the study measures, on `base` (its scene, strands and duration).
pub fn configurations(base: &HairConfig) -> Vec<HairConfig> {
    let with = |(method, solver): (HairMethod, Solver), iterations: u32, substeps: u32, k: f64| {
        let mut c = base.clone();
        c.methods = vec![method];
        c.params.solver = solver;
        c.params.iterations = iterations;
        c.params.stiffness = k;
        c.substeps = substeps;
        c
    };
    let k0 = base.params.stiffness;
    let gauss_seidel = (HairMethod::Verlet, Solver::GaussSeidel);
    let springs = (HairMethod::SemiImplicitEuler, Solver::Direct);
    let implicit = (HairMethod::ImplicitEuler, Solver::Direct);
    let mut out = Vec::new();
    for substeps in [1, 2, 4, 8] {
        for sweeps in [1, 2, 4, 8, 16, 32, 64] {
            out.push(with(gauss_seidel, sweeps, substeps, k0));
        }
    }
    for newton in 1..=4 {
        out.push(with((HairMethod::Verlet, Solver::Direct), newton, 1, k0));
    }
    for k in [1e8, 2e8, 4e8, 8e8] {
        out.push(with(springs, 1, 1, k));
    }
    for substeps in [1, 4, 16] {
        for k in [1e8, 4e8] {
            out.push(with(implicit, 2, substeps, k));
        }
    }
    out.push(with((HairMethod::Ftl, Solver::Direct), 1, 1, k0));
    out
}

/// Runs every configuration and measures it, calling `done(i)` after configuration i. After a
/// stop request ([`crate::interrupt::requested`]) the rows of the configurations that ran to the
/// end: one cut short has no stretch or cost to show, and the rest never ran.
pub fn hair_trade(configs: &[HairConfig], mut done: impl FnMut(usize)) -> Vec<HairRow> {
    (configs.iter().enumerate())
        .map_while(|(i, c)| {
            if crate::interrupt::requested() {
                return None;
            }
            let method = c.methods[0];
            let r = run(&mut HairScene::new(c.clone()), &mut NoObserver)
                .expect("a configuration from `configurations` is valid");
            if r.interrupted {
                return None;
            }
            let (lane, stats) = (&r.lanes[0], &r.stats[0]);
            done(i);
            Some(HairRow {
                method,
                solver: (method == HairMethod::Verlet).then_some(c.params.solver),
                iterations: c.params.iterations,
                substeps: c.substeps,
                stiffness: method.is_spring().then_some(c.params.stiffness),
                stretch: stats.divergence.is_none().then_some(lane.worst.max_stretch),
                ms_per_frame: stats.wall.as_secs_f64() * 1e3 / stats.timed_ticks.max(1) as f64,
            })
        })
        .collect()
}

/// A configuration's expected cost, in units of one Gauss–Seidel sweep of one substep: what the
/// study's progress goes by. A model whose weights are ratios this study measures (a frame of
/// the direct solver or FTL costs about two sweeps, an inner spring step about four, an
/// implicit Newton iteration about 1400), not a measurement; it only has to rank the
/// configurations' costs within a factor of about two.
pub fn expected_cost(c: &HairConfig) -> f64 {
    let iterations = f64::from(c.params.iterations);
    let per_substep = match (c.methods[0], c.params.solver) {
        (HairMethod::Verlet, Solver::GaussSeidel) => iterations + 1.0,
        (HairMethod::Verlet, Solver::Direct) | (HairMethod::Ftl, _) => 2.0,
        (HairMethod::SemiImplicitEuler, _) => {
            let h = 1.0 / (c.rate * f64::from(c.substeps));
            4.0 * (h / c.params.spring_step_limit()).ceil().max(1.0)
        }
        (HairMethod::ImplicitEuler, _) => 1400.0 * iterations,
    };
    c.duration * c.rate * f64::from(c.substeps) * per_substep
}

/// The cheapest row (by wall time per frame) whose stretch is within `target`.
pub fn cheapest_within<'a>(
    rows: impl IntoIterator<Item = &'a HairRow>,
    target: f64,
) -> Option<&'a HairRow> {
    rows.into_iter()
        .filter(|r| r.stretch.is_some_and(|s| s <= target))
        .min_by(|a, b| a.ms_per_frame.total_cmp(&b.ms_per_frame))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(stretch: Option<f64>, ms: f64) -> HairRow {
        HairRow {
            method: HairMethod::Verlet,
            solver: Some(Solver::GaussSeidel),
            iterations: 1,
            substeps: 1,
            stiffness: None,
            stretch,
            ms_per_frame: ms,
        }
    }

    #[test]
    fn cheapest_takes_the_fastest_row_within_the_target() {
        let rows = [
            row(Some(5e-3), 3.0),
            row(Some(2e-2), 1.0),
            row(None, 0.5),
            row(Some(1e-4), 4.0),
        ];
        assert_eq!(cheapest_within(&rows, 1e-2).unwrap().ms_per_frame, 3.0);
        assert_eq!(cheapest_within(&rows, 1e-3).unwrap().ms_per_frame, 4.0);
        assert!(cheapest_within(&rows, 1e-5).is_none());
    }
}
