//! The hair scene's invariants, checked after every step (issue 4, point 5), and determinism
//! across thread counts (point 6).

use physlab::scene::hair::run::{HairConfig, HairScene};
use physlab::scene::hair::{Hair, HairMethod, HairParams, HeadMotion};
use physlab::scene::harness::{NoObserver, run};

fn params(strands: usize) -> HairParams {
    HairParams {
        strands,
        ..HairParams::default()
    }
}

/// Steps one method through `seconds` of the default tour (head moving, wind with gusts) at
/// 60 Hz × `substeps`, asserting after every step; returns the largest stretch seen.
fn tour(method: HairMethod, p: HairParams, substeps: u32, seconds: f64) -> f64 {
    let r = p.head_radius;
    let mut hair = Hair::new(p, method);
    let dt = 1.0 / (60.0 * substeps as f64);
    let mut worst: f64 = 0.0;
    for step in 0..(seconds / dt).round() as usize {
        hair.step(dt);
        let pen = hair.max_penetration();
        assert!(
            pen <= 1e-6 * r,
            "{} step {step}: a node is {pen:e} m inside the head",
            method.name()
        );
        let root = hair.max_root_error();
        assert!(
            root <= 1e-12,
            "{} step {step}: a root is {root:e} m off its anchor",
            method.name()
        );
        let stretch = hair.max_stretch();
        if method == HairMethod::Ftl {
            assert!(
                stretch <= 1e-6,
                "ftl step {step}: a segment is off rest length by {stretch:e} (relative)"
            );
        }
        assert!(hair.pos.iter().all(|x| x.is_finite()));
        worst = worst.max(stretch);
    }
    worst
}

/// Every method keeps the head impenetrable (to 1e-6 R) and the roots exactly on their anchors
/// through a full 8 s tour with gusty wind; ftl keeps every segment at rest length to 1e-6.
/// Verlet and PBD, at the default 4 iterations and 16 nodes at 60 Hz, stay below a stretch of
/// 2.0 (the bound this project states; measured 1.70 and 1.67 at 200 strands: the first fall of
/// the straight-out strands is the worst moment).
#[test]
fn invariants_hold_after_every_step_of_a_tour() {
    for m in HairMethod::ALL {
        let stretch = tour(m, params(60), 1, 8.0);
        if m != HairMethod::Ftl {
            assert!(stretch < 2.0, "{}: max stretch {stretch:.3}", m.name());
        }
    }
}

/// More iterations, or more substeps, reduce Verlet's and PBD's stretch; and at equal cost
/// (iterations × substeps = 8) two substeps of 4 iterations beat one step of 8 iterations:
/// the "small steps" result (Macklin et al. 2019).
#[test]
fn substeps_beat_iterations() {
    for m in [HairMethod::Verlet, HairMethod::SemiImplicitEuler] {
        let with = |iterations: u32, substeps: u32| {
            tour(
                m,
                HairParams {
                    iterations,
                    ..params(30)
                },
                substeps,
                2.0,
            )
        };
        let base = with(4, 1);
        let more_iterations = with(8, 1);
        let more_substeps = with(4, 2);
        assert!(
            more_iterations < base,
            "{}: 8 iterations {more_iterations:.3} vs 4 {base:.3}",
            m.name()
        );
        assert!(
            more_substeps < base,
            "{}: 2 substeps {more_substeps:.3} vs 1 {base:.3}",
            m.name()
        );
        assert!(
            more_substeps < more_iterations,
            "{}: 2 substeps × 4 iterations {more_substeps:.3} should beat 1 × 8 {more_iterations:.3}",
            m.name()
        );
    }
}

/// A still head without wind: after 20 s every strand hangs at rest, its tip below its root.
#[test]
fn still_head_without_wind_settles_with_strands_hanging() {
    for m in HairMethod::ALL {
        let p = HairParams {
            motion: HeadMotion::Still,
            wind: glam::DVec3::ZERO,
            gust: 0.0,
            ..params(60)
        };
        let n = p.nodes;
        let mut hair = Hair::new(p, m);
        for _ in 0..1200 {
            hair.step(1.0 / 60.0);
        }
        let ke = hair.kinetic_energy();
        assert!(
            ke < 1e-9,
            "{}: kinetic energy {ke:e} J/kg after 20 s",
            m.name()
        );
        for (s, strand) in hair.pos.chunks(n).enumerate() {
            assert!(
                strand[n - 1].z < strand[0].z,
                "{} strand {s}: tip not below its root",
                m.name()
            );
        }
    }
}

/// The same run with 1 and with 2 worker threads gives bit-identical states and statistics.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let config = HairConfig {
        params: params(97),
        duration: 1.0,
        ..HairConfig::default()
    };
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let summary = run(&mut HairScene::new(config.clone()), &mut NoObserver).unwrap();
            let states: Vec<Vec<[u64; 3]>> = HairMethod::ALL
                .iter()
                .map(|&m| {
                    let mut h = Hair::new(config.params.clone(), m);
                    for _ in 0..60 {
                        h.step(1.0 / 60.0);
                    }
                    h.pos
                        .iter()
                        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                        .collect()
                })
                .collect();
            let stats: Vec<(u64, u64)> = summary
                .lanes
                .iter()
                .map(|l| {
                    (
                        l.worst.max_stretch.to_bits(),
                        l.worst.kinetic_energy.to_bits(),
                    )
                })
                .collect();
            (states, stats)
        })
    };
    assert_eq!(on(1), on(2));
}
