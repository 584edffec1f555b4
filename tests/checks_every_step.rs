//! Invariants and divergence are checked after every step, and only logging is thinned: a run's
//! summary does not depend on how often it plots (--plot-every) or logs 3D frames (--fps).

use physlab::scene::hair::run::{HairConfig, HairScene};
use physlab::scene::hair::{HairMethod, HairParams, HeadMotion};
use physlab::scene::harness::{NoObserver, Run, run};
use physlab::scene::pendulum::run::{PendulumConfig, PendulumLane, PendulumScene};
use physlab::scene::rope::run::{RopeConfig, RopeLane, RopeScene};

/// What a summary reports per lane, as bits: accepted ticks, evaluations, divergence tick, and
/// the scene's own figures.
fn stats<L>(
    r: &Run<L>,
    figures: impl Fn(&L) -> Vec<f64>,
) -> Vec<(u64, u64, Option<u64>, Vec<u64>)> {
    r.lanes
        .iter()
        .zip(&r.stats)
        .map(|(l, s)| {
            (
                s.ticks,
                s.counts.evals,
                s.divergence.as_ref().map(|e| e.tick),
                figures(l).into_iter().map(f64::to_bits).collect(),
            )
        })
        .collect()
}

fn rope(plot_every: u64, fps: f64) -> Vec<(u64, u64, Option<u64>, Vec<u64>)> {
    let config = RopeConfig {
        duration: 8.0,
        plot_every,
        fps,
        ..RopeConfig::default()
    };
    let r = run(&mut RopeScene::new(config), &mut NoObserver).unwrap();
    stats(&r, |l: &RopeLane| vec![l.max_strain, l.final_energy])
}

#[test]
fn rope_summary_is_the_same_for_any_plot_and_frame_rate() {
    let reference = rope(1, 30.0);
    // The default rope has methods that diverge (explicit Euler early, midpoint and trapezoid
    // late): their divergence step must not move with the logging either.
    assert!(reference.iter().filter(|l| l.2.is_some()).count() >= 2);
    for (plot_every, fps) in [(5, 30.0), (50, 30.0), (7, 1.0), (1, 997.0), (333, 0.5)] {
        assert_eq!(
            rope(plot_every, fps),
            reference,
            "--plot-every {plot_every} --fps {fps}"
        );
    }
}

fn pendulum(plot_every: u64, fps: f64, dt: f64) -> Vec<(u64, u64, Option<u64>, Vec<u64>)> {
    let config = PendulumConfig {
        dt,
        duration: 20.0,
        plot_every,
        fps,
        ..PendulumConfig::default()
    };
    let r = run(&mut PendulumScene::new(config), &mut NoObserver).unwrap();
    stats(&r, |l: &PendulumLane| {
        vec![
            l.max_theta_error,
            l.max_energy_error,
            l.meter.period().unwrap_or(f64::NAN),
        ]
    })
}

#[test]
fn pendulum_summary_is_the_same_for_any_plot_and_frame_rate() {
    // dt = 1 s: explicit Euler and midpoint diverge within the run.
    for dt in [0.01, 1.0] {
        let reference = pendulum(1, 30.0, dt);
        assert_eq!(reference.iter().any(|l| l.2.is_some()), dt > 0.1);
        for (plot_every, fps) in [(5, 30.0), (50, 3.0), (7, 1000.0), (4096, 0.05)] {
            assert_eq!(
                pendulum(plot_every, fps, dt),
                reference,
                "dt {dt} --plot-every {plot_every} --fps {fps}"
            );
        }
    }
}

fn hair(fps: f64, wind: f64) -> Vec<(u64, u64, Option<u64>, Vec<u64>)> {
    let config = HairConfig {
        params: HairParams {
            strands: 24,
            motion: HeadMotion::Tour,
            wind: glam::DVec3::new(wind, 0.0, 0.0),
            ..HairParams::default()
        },
        duration: 3.0,
        fps,
        methods: HairMethod::ALL.to_vec(),
        ..HairConfig::default()
    };
    let r = run(&mut HairScene::new(config), &mut NoObserver).unwrap();
    stats(&r, |l| {
        let w = &l.worst;
        vec![
            w.max_stretch,
            w.max_penetration,
            w.max_root_error,
            w.kinetic_energy,
        ]
    })
}

#[test]
fn hair_summary_is_the_same_for_any_frame_rate() {
    for wind in [1.0, 1e6] {
        let reference = hair(60.0, wind);
        for fps in [15.0, 7.0, 1.0] {
            assert_eq!(hair(fps, wind), reference, "--fps {fps} --wind {wind}");
        }
    }
}
