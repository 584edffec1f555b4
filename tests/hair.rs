//! The hair scene: its invariants after every step, its length at the defaults and extremes,
//! divergence and energy, and the command end to end.

#[cfg(feature = "rerun")]
mod common;

mod invariants {
    //! The hair scene's invariants, checked after every step, and determinism across thread
    //! counts.

    use std::f64::consts::PI;

    use glam::DVec3;
    use physlab::scene::hair::run::{HairConfig, HairScene};
    use physlab::scene::hair::{Hair, HairMethod, HairParams, HeadMotion, Solver};
    use physlab::scene::harness::{NoObserver, run};

    fn params(strands: usize) -> HairParams {
        HairParams {
            strands,
            ..HairParams::default()
        }
    }

    /// v rotated by `angle` about the unit `axis` (Rodrigues' formula).
    fn rotate(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
        let (s, c) = angle.sin_cos();
        v * c + axis.cross(v) * s + axis * axis.dot(v) * (1.0 - c)
    }

    /// Where the root with head-frame direction `dir` belongs at time t of the tour, written here
    /// from the motion's definition (`head.rs`), not with its code: every 8 s, a sway on [0, 2) s
    /// moves the centre along x by 2R·P, a turn on [2, 4) s rotates the head by 1.0·P rad about the
    /// vertical z, a nod on [4, 6) s by 0.5·P rad about the left-right x, then a rest; P = P(s) =
    /// sin(2πs) sin²(πs) with s the fraction of the 2 s pulse. The root sits at R·dir in the head
    /// frame. `inverse` applies the rotation the wrong way round (head from world), to show that
    /// the check tells the two apart.
    fn tour_root(r: f64, dir: DVec3, t: f64, inverse: bool) -> DVec3 {
        let p = |s: f64| (2.0 * PI * s).sin() * (PI * s).sin().powi(2);
        let cycle = t.rem_euclid(8.0);
        let s = (cycle % 2.0) / 2.0;
        let (sway, turn, nod) = match (cycle / 2.0) as u32 {
            0 => (p(s), 0.0, 0.0),
            1 => (0.0, p(s), 0.0),
            2 => (0.0, 0.0, p(s)),
            _ => (0.0, 0.0, 0.0),
        };
        let sign = if inverse { -1.0 } else { 1.0 };
        // Turn and nod never overlap in the tour, so their order cannot matter here.
        let rotated = rotate(
            rotate(r * dir, DVec3::X, sign * 0.5 * nod),
            DVec3::Z,
            sign * turn,
        );
        DVec3::new(2.0 * r * sway, 0.0, 0.0) + rotated
    }

    /// The largest distance of a root node from where `tour_root` puts it at time t.
    fn root_error(hair: &Hair, dirs: &[DVec3], t: f64) -> f64 {
        let r = hair.params.head_radius;
        dirs.iter()
            .enumerate()
            .map(|(s, d)| (hair.node(s, 0) - tour_root(r, *d, t, false)).length())
            .fold(0.0, f64::max)
    }

    /// Roots are placed from the head pose to within this [m]: positions are up to ~0.3 m, so this is
    /// ~20 ulp (measured 5.6e-17, one ulp, over every step of every tour here). A root placed at the
    /// step's start time instead of its end would be off by up to 1.0e-2 m at 60 Hz (5.2e-3 m at
    /// 120 Hz), and one rotated the wrong way (head from world) by up to 0.12 m.
    const ROOT_TOLERANCE: f64 = 1e-15;

    /// Steps one method through `seconds` of the default tour (head moving, wind with gusts) at
    /// 60 Hz × `substeps`, asserting after every step; returns the largest stretch seen.
    fn tour(method: HairMethod, p: HairParams, substeps: u32, seconds: f64) -> f64 {
        assert_eq!(p.motion, HeadMotion::Tour);
        let r = p.head_radius;
        let dirs = p.root_directions();
        let mut hair = Hair::new(p, method);
        let dt = 1.0 / (60.0 * substeps as f64);
        let mut worst: f64 = 0.0;
        // The scene's clock: the sum of the steps taken.
        let mut t = 0.0;
        let root = root_error(&hair, &dirs, t);
        assert!(
            root <= ROOT_TOLERANCE,
            "{} at start: root off by {root:e} m",
            method.name()
        );
        let (mut wrong_time, mut wrong_way) = (0.0f64, 0.0f64);
        for step in 0..(seconds / dt).round() as usize {
            hair.step(dt);
            t += dt;
            let pen = hair.max_penetration();
            assert!(
                pen <= 1e-6 * r,
                "{} step {step}: a node is {pen:e} m inside the head",
                method.name()
            );
            let root = root_error(&hair, &dirs, t);
            assert!(
                root <= ROOT_TOLERANCE,
                "{} step {step} (t = {t}): a root is {root:e} m from the head pose's anchor",
                method.name()
            );
            for d in &dirs {
                let right = tour_root(r, *d, t, false);
                wrong_time = wrong_time.max((tour_root(r, *d, t - dt, false) - right).length());
                wrong_way = wrong_way.max((tour_root(r, *d, t, true) - right).length());
            }
            let stretch = hair.max_stretch();
            if method == HairMethod::Ftl {
                assert!(
                    stretch <= 1e-6,
                    "ftl step {step}: a segment is off rest length by {stretch:e} (relative)"
                );
            }
            assert!(hair.positions().iter().all(|x| x.is_finite()));
            worst = worst.max(stretch);
        }
        // The check can fail: over a tour through the turn and the nod, the two likely mistakes move
        // roots by ten orders of magnitude more than the tolerance.
        if seconds >= 6.0 {
            assert!(wrong_time > 1e9 * ROOT_TOLERANCE && wrong_way > 1e9 * ROOT_TOLERANCE);
        }
        worst
    }

    /// Every default method keeps the head impenetrable (to 1e-6 R) and the roots on the anchors of
    /// an independently computed head pose (to 1e-15 m) through a full 8 s tour with gusty wind; ftl
    /// keeps every segment at rest length to 1e-6, verlet with its direct solver to 1e-3 (measured
    /// 2e-15), semi-implicit-euler's springs to 2e-2 (measured 9.8e-3 at 200 strands).
    #[test]
    fn invariants_hold_after_every_step_of_a_tour() {
        for m in [
            HairMethod::Verlet,
            HairMethod::SemiImplicitEuler,
            HairMethod::Ftl,
        ] {
            let stretch = tour(m, params(60), 1, 8.0);
            let bound = match m {
                HairMethod::Verlet => 1e-3,
                HairMethod::Ftl => 1e-6,
                _ => 2e-2,
            };
            assert!(stretch <= bound, "{}: max stretch {stretch:.3e}", m.name());
        }
    }

    /// With the Gauss–Seidel solver, more sweeps, or more substeps, reduce Verlet's stretch; and at
    /// equal cost (sweeps × substeps = 8) two substeps of 4 sweeps beat one step of 8 sweeps: the
    /// "small steps" result (Macklin et al. 2019).
    #[test]
    fn substeps_beat_iterations() {
        {
            let m = HairMethod::Verlet;
            let with = |iterations: u32, substeps: u32| {
                tour(
                    m,
                    HairParams {
                        iterations,
                        solver: Solver::GaussSeidel,
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

    /// A still head without wind: after 20 s every strand hangs at rest, its tip below its root,
    /// with each solver and method at the default 60 Hz step.
    #[test]
    fn still_head_without_wind_settles_with_strands_hanging() {
        for (m, solver) in [
            (HairMethod::Verlet, Solver::Direct),
            (HairMethod::Verlet, Solver::GaussSeidel),
            (HairMethod::SemiImplicitEuler, Solver::Direct),
            (HairMethod::Ftl, Solver::Direct),
        ] {
            let p = HairParams {
                motion: HeadMotion::Still,
                wind: glam::DVec3::ZERO,
                gust: 0.0,
                solver,
                ..params(60)
            };
            let n = p.nodes;
            let mut hair = Hair::new(p, m);
            for _ in 0..1200 {
                hair.step(1.0 / 60.0);
            }
            let ke = hair.total_kinetic_energy();
            // The springs keep a little motion (measured 3.9e-7 J/kg): only c = 1/s damps them.
            let bound = if m.is_spring() { 1e-6 } else { 1e-9 };
            assert!(
                ke < bound,
                "{} ({}): kinetic energy {ke:e} J/kg after 20 s",
                m.name(),
                solver.name()
            );
            for (s, strand) in hair.positions().chunks(n).enumerate() {
                assert!(
                    strand[n - 1].z < strand[0].z,
                    "{} strand {s}: tip not below its root",
                    m.name()
                );
            }
        }
    }

    /// The direct solver's tension solve is what lets a still head settle at 60 Hz. The root
    /// segment of a hanging strand carries its weight, tension T = g (nodes - 1) per unit node mass,
    /// and the tension's transverse stiffness has ω ≈ 2 √(T/ℓ0): ω dt ≈ 3.3 at 16 nodes and 6.6 at
    /// 64 nodes at 60 Hz, beyond the explicit limit ω dt < 2. Newton steps alone correct along the
    /// segment directions of the prediction, an explicit step on that stiffness, and left the nodes
    /// near the root in a steady zig-zag (kinetic energy 0.18 J/kg after 20 s at 16 nodes; below
    /// 1e-6 only at 4 steps per frame). The tension solve puts the tensions on the end-of-step
    /// directions (backward Euler on the transverse stiffness), so at 64 nodes the energy decays at
    /// the damping's rate instead (measured 1.8e-7 J/kg after 20 s).
    #[test]
    fn verlet_direct_settles_at_64_nodes_beyond_the_explicit_tension_limit() {
        let p = HairParams {
            motion: HeadMotion::Still,
            wind: glam::DVec3::ZERO,
            gust: 0.0,
            nodes: 64,
            ..params(60)
        };
        let omega_dt = 2.0 * (9.81 * 63.0 / p.segment_length).sqrt() / 60.0;
        assert!(
            omega_dt > 6.0,
            "the step is beyond the explicit limit: {omega_dt}"
        );
        let mut hair = Hair::new(p, HairMethod::Verlet);
        for _ in 0..1200 {
            hair.step(1.0 / 60.0);
        }
        let (s, kinetic) = (hair.stats(), hair.total_kinetic_energy());
        assert!(kinetic < 1e-6, "kinetic energy {kinetic:e} J/kg");
        assert!(s.max_stretch < 1e-12 && s.max_penetration < 1e-12);
    }

    /// What damping each method adds, measured on a free chain (one 16-node strand from a
    /// pin-sized head, so nothing touches it) released horizontal with no velocity damping (c = 0)
    /// and no wind: the exact motion keeps its energy E = ½|v|² + g z per unit node mass. The loss
    /// after 0.5 s, as a fraction of the energy a hanging strand has released (g ℓ0 Σ k):
    ///
    /// | method (60 Hz) | 1 step | 2 | 4 | 8 | 32 steps per frame |
    /// |---|---|---|---|---|---|
    /// | verlet, direct | 0.62 | 0.43 | 0.29 | 0.19 | 0.07 |
    /// | verlet, 64 Gauss–Seidel sweeps | 0.62 | | | | |
    /// | ftl | 0.96 | | | 0.45 | |
    /// | implicit-euler (k/m 4e8) | 0.62 | | | 0.19 | |
    /// | semi-implicit-euler (k/m 4e8) | 0.03 | | | | |
    ///
    /// A position projection is an inelastic collision with the constraint: the velocity the
    /// prediction had against it is removed, an O(dt) loss per unit time that vanishes as dt → 0
    /// (verlet, and implicit-euler whose stiff springs are a projection in the limit); DFTL's
    /// velocity correction removes more; symplectic Euler on the springs keeps the energy up to the
    /// spring damping. Checked here: the loss falls with the step toward zero for the consistent
    /// methods, and ftl loses more than verlet at the same step.
    #[test]
    fn what_damping_each_method_adds() {
        let loss = |m: HairMethod, steps_per_frame: usize| {
            let p = HairParams {
                strands: 1,
                cap_angle: PI,
                head_radius: 1e-3,
                motion: HeadMotion::Still,
                wind: DVec3::ZERO,
                gust: 0.0,
                damping: 0.0,
                ..HairParams::default()
            };
            let g = -p.gravity.z;
            let released = g * p.segment_length * (0..p.nodes).sum::<usize>() as f64;
            let mut h = Hair::new(p, m);
            let energy = |h: &Hair| {
                h.positions().iter().map(|x| g * x.z).sum::<f64>() + h.total_kinetic_energy()
            };
            let e0 = energy(&h);
            for _ in 0..30 * steps_per_frame {
                h.step(1.0 / 60.0 / steps_per_frame as f64);
            }
            (e0 - energy(&h)) / released
        };
        let verlet: Vec<f64> = [1, 2, 4, 8, 32]
            .iter()
            .map(|&s| loss(HairMethod::Verlet, s))
            .collect();
        assert!(
            verlet.windows(2).all(|w| w[1] < 0.8 * w[0]) && verlet[4] < 0.1,
            "verlet's loss falls with the step toward zero: {verlet:?}"
        );
        let ftl = loss(HairMethod::Ftl, 1);
        assert!(ftl > verlet[0], "ftl {ftl} vs verlet {}", verlet[0]);
        let sie = loss(HairMethod::SemiImplicitEuler, 1);
        assert!(sie.abs() < 0.05, "semi-implicit-euler loses {sie}");
        let ie = [
            loss(HairMethod::ImplicitEuler, 1),
            loss(HairMethod::ImplicitEuler, 8),
        ];
        assert!(ie[1] < 0.5 * ie[0], "implicit-euler: {ie:?}");
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
                        h.positions()
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
}

mod length {
    //! Length at the defaults and at the extremes: with the default solver,
    //! the largest relative stretch over the whole run stays ≤ 1e-3 for verlet and ≤ 1e-6 for ftl
    //! at the default scene, 64 nodes, strong gusty wind and the shaking head; no non-root node is
    //! inside R(1 + margin) (to round-off) and every root sits exactly on its anchor.

    use glam::DVec3;
    use physlab::scene::hair::run::{HairConfig, HairScene};
    use physlab::scene::hair::{HairMethod, HairParams, HeadMotion};
    use physlab::scene::harness::{NoObserver, run};

    fn scenario(name: &str) -> HairConfig {
        let base = HairConfig {
            duration: 8.0,
            ..HairConfig::default()
        };
        match name {
            "default" => base,
            "nodes-64" => HairConfig {
                params: HairParams {
                    nodes: 64,
                    ..HairParams::default()
                },
                ..base
            },
            "wind" => HairConfig {
                params: HairParams {
                    wind: DVec3::new(0.0, 30.0, 0.0),
                    gust: 1.0,
                    ..HairParams::default()
                },
                ..base
            },
            "shake" => HairConfig {
                params: HairParams {
                    motion: HeadMotion::Shake,
                    ..HairParams::default()
                },
                duration: 4.0,
                ..base
            },
            _ => unreachable!(),
        }
    }

    /// The bounds, over every frame of each scenario, for the constraint methods.
    #[test]
    fn constraint_methods_keep_length_at_the_defaults_and_extremes() {
        for name in ["default", "nodes-64", "wind", "shake"] {
            let config = HairConfig {
                params: HairParams {
                    strands: 100,
                    ..scenario(name).params
                },
                methods: vec![HairMethod::Verlet, HairMethod::Ftl],
                ..scenario(name)
            };
            let r = run(&mut HairScene::new(config), &mut NoObserver).unwrap();
            for (lane, s) in r.lanes.iter().zip(&r.stats) {
                let w = &lane.worst;
                let bound = if lane.hair.method == HairMethod::Ftl {
                    1e-6
                } else {
                    1e-3
                };
                assert!(s.divergence.is_none(), "{name} {}", s.name);
                assert!(
                    w.max_stretch <= bound,
                    "{name} {}: stretch {:e}",
                    s.name,
                    w.max_stretch
                );
                assert!(
                    w.max_penetration <= 1e-12,
                    "{name} {}: penetration {:e} m",
                    s.name,
                    w.max_penetration
                );
                assert_eq!(w.max_root_error, 0.0, "{name} {}: roots exact", s.name);
            }
        }
    }

    /// The spring methods at their default stiffness ([`HairParams::default_stiffness`]) hold the
    /// stated bound (`SPRING_STRETCH_BOUND` = 1e-2) over the whole run, over a grid of every head
    /// motion × strand shapes from 8 long segments to 64 short ones × head radii 0.05–0.3 m, plus
    /// strong gusty wind; implicit-euler on the shake, the motion that stretches most.
    #[test]
    fn spring_methods_at_the_default_stiffness() {
        let bound = physlab::scene::hair::SPRING_STRETCH_BOUND;
        let mut cases = Vec::new();
        for (_, motion) in HeadMotion::ALL {
            for (nodes, segment_length) in [(16, 0.015), (32, 0.01), (8, 0.03), (64, 0.005)] {
                for head_radius in [0.05, 0.1, 0.3] {
                    let methods = if motion == HeadMotion::Shake {
                        vec![HairMethod::SemiImplicitEuler, HairMethod::ImplicitEuler]
                    } else {
                        vec![HairMethod::SemiImplicitEuler]
                    };
                    let params = HairParams {
                        motion,
                        nodes,
                        segment_length,
                        head_radius,
                        strands: 6,
                        ..HairParams::default()
                    };
                    cases.push((params, methods));
                }
            }
        }
        for motion in [HeadMotion::Tour, HeadMotion::Shake] {
            let params = HairParams {
                motion,
                nodes: 32,
                segment_length: 0.01,
                wind: DVec3::new(0.0, 30.0, 0.0),
                gust: 1.0,
                strands: 6,
                ..HairParams::default()
            };
            cases.push((params, vec![HairMethod::SemiImplicitEuler]));
        }
        let mut worst: f64 = 0.0;
        for (mut params, methods) in cases {
            params.stiffness = params.default_stiffness();
            let name = format!(
                "{:?}, {} nodes × {} m, head radius {} m, wind {}",
                params.motion, params.nodes, params.segment_length, params.head_radius, params.wind
            );
            // One period of the motion (the tour's is four pulses), and the fall at the start.
            let duration = if params.motion == HeadMotion::Tour {
                8.0
            } else {
                4.0
            };
            let config = HairConfig {
                params,
                methods,
                duration,
                ..HairConfig::default()
            };
            let r = run(&mut HairScene::new(config), &mut NoObserver).unwrap();
            for (lane, s) in r.lanes.iter().zip(&r.stats) {
                let w = &lane.worst;
                assert!(s.divergence.is_none(), "{name} {}", s.name);
                assert!(w.kinetic_energy.is_finite(), "{name} {}", s.name);
                assert!(
                    w.max_stretch <= bound,
                    "{name} {}: stretch {:e}",
                    s.name,
                    w.max_stretch
                );
                assert!(
                    w.max_penetration <= 1e-12,
                    "{name} {}: penetration {:e} m",
                    s.name,
                    w.max_penetration
                );
                worst = worst.max(w.max_stretch);
            }
        }
        eprintln!("largest stretch over the grid: {worst:.2e}");
    }

    /// The stretch follows the springs' wave speed: 60 strands of 32 short segments on the shake
    /// stretch past 1e-2 at k/m = 4e8 (wave speed 200 m/s, 28 × the speed scale), and stay within
    /// it at the default stiffness, as the summary says of each.
    #[test]
    fn softer_springs_than_the_default_stretch_past_the_bound() {
        let bound = physlab::scene::hair::SPRING_STRETCH_BOUND;
        let params = HairParams {
            motion: HeadMotion::Shake,
            nodes: 32,
            segment_length: 0.01,
            strands: 60,
            ..HairParams::default()
        };
        let stretch = |stiffness: f64| {
            let config = HairConfig {
                params: HairParams {
                    stiffness,
                    ..params.clone()
                },
                methods: vec![HairMethod::SemiImplicitEuler],
                duration: 4.0,
                ..HairConfig::default()
            };
            let r = run(&mut HairScene::new(config), &mut NoObserver).unwrap();
            r.lanes[0].worst.max_stretch
        };
        let soft = stretch(4e8);
        assert!(soft > bound, "k/m 4e8: stretch {soft:e}");
        let default = stretch(params.default_stiffness());
        assert!(default <= bound, "default: stretch {default:e}");
    }

    /// The hair swings under a nod: every method's nodes move (kinetic energy per unit mass above
    /// 1e-3 J/kg at some frame during the nod) with a still wind.
    #[test]
    fn hair_swings_under_a_nod() {
        let config = HairConfig {
            params: HairParams {
                strands: 20,
                motion: HeadMotion::Nod,
                wind: DVec3::ZERO,
                gust: 0.0,
                ..HairParams::default()
            },
            duration: 1.0,
            ..HairConfig::default()
        };
        for m in HairMethod::DEFAULT {
            let mut hair = physlab::scene::hair::Hair::new(config.params.clone(), m);
            // Let the strands fall and settle first under a still head? The nod starts at t = 0;
            // the fall is over by 0.5 s, and the nod's peak speed is at 0.5 s.
            let mut peak: f64 = 0.0;
            for _ in 0..60 {
                hair.step(1.0 / 60.0);
                peak = peak.max(hair.total_kinetic_energy());
            }
            assert!(peak > 1e-3, "{}: peak KE {peak:e}", m.name());
        }
    }

    #[test]
    #[ignore]
    fn print_implicit() {
        let env = |k: &str, d: u32| {
            std::env::var(k)
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(d)
        };
        for name in ["default", "nodes-64", "wind", "shake"] {
            let mut config = scenario(name);
            config.methods = vec![match std::env::var("M").as_deref() {
                Ok("sie") => HairMethod::SemiImplicitEuler,
                _ => HairMethod::ImplicitEuler,
            }];
            config.params.strands = env("STRANDS", 200) as usize;
            config.params.iterations = env("IT", 2);
            config.substeps = env("SUB", 1);
            config.params.stiffness = env("K", 100_000_000) as f64;
            config.params.spring_damping = env("KD", 2000) as f64;
            let r = run(&mut HairScene::new(config), &mut NoObserver).unwrap();
            for (lane, s) in r.lanes.iter().zip(&r.stats) {
                println!(
                    "{name:9} {:20} stretch {:.2e} pen {:.1e} ke {:.3e} div {:?} wall {:.0} ms",
                    s.name,
                    lane.worst.max_stretch,
                    lane.worst.max_penetration,
                    lane.worst.kinetic_energy,
                    s.divergence.as_ref().map(|e| e.time),
                    s.wall.as_secs_f64() * 1e3
                );
            }
        }
    }

    #[test]
    #[ignore]
    fn print_figures() {
        for name in ["default", "nodes-64", "wind", "shake"] {
            let config = scenario(name);
            let t = std::time::Instant::now();
            let r = run(&mut HairScene::new(config), &mut NoObserver).unwrap();
            for (lane, s) in r.lanes.iter().zip(&r.stats) {
                println!(
                    "{name:9} {:20} stretch {:.2e} pen {:.1e} root {:.1e} ke {:.3e} div {:?} wall {:.0} ms",
                    s.name,
                    lane.worst.max_stretch,
                    lane.worst.max_penetration,
                    lane.worst.max_root_error,
                    lane.worst.kinetic_energy,
                    s.divergence.as_ref().map(|e| e.message.clone()),
                    s.wall.as_secs_f64() * 1e3
                );
            }
            println!("  ({:.1} s)", t.elapsed().as_secs_f64());
        }
        let _ = HairMethod::ALL;
    }

    #[test]
    #[ignore]
    fn print_settle() {
        for it in [1u32, 2, 4, 8] {
            let p = HairParams {
                motion: HeadMotion::Still,
                wind: DVec3::ZERO,
                gust: 0.0,
                strands: 60,
                iterations: it,
                ..HairParams::default()
            };
            let mut hair = physlab::scene::hair::Hair::new(p, HairMethod::Verlet);
            let mut ke = vec![];
            for f in 0..1200 {
                hair.step(1.0 / 60.0);
                if f % 200 == 199 {
                    ke.push(hair.total_kinetic_energy());
                }
            }
            println!("it {it}: {ke:.2?}");
        }
    }
}

#[cfg(feature = "rerun")]
mod cli {
    //! The hair command end to end: exit code, summary, recording layout, `--dt` and substeps.

    use crate::common::{decode, physlab, scratch_dir};

    #[test]
    fn hair_run_writes_one_strip_entity_per_method() {
        let dir = scratch_dir("hair-e2e");
        let out = dir.join("h.rrd");
        let (code, stdout, stderr) = physlab(&[
            "hair",
            "--strands",
            "30",
            "--duration",
            "1",
            "--methods",
            "verlet,semi-implicit-euler,ftl",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stdout}\n{stderr}");
        let d = decode(&out);
        assert!(d.has_footer);
        for m in ["verlet", "semi-implicit-euler", "ftl"] {
            assert!(
                stdout.lines().any(|l| l.starts_with(&format!("| {m} "))),
                "row for {m}:\n{stdout}"
            );
            for part in ["strands", "head", "roots"] {
                assert!(
                    d.entities.contains(&format!("/hair/{m}/{part}")),
                    "missing /hair/{m}/{part}"
                );
            }
            // Wall-clock costs are only recorded with --timings.
            assert!(!d.scalars.contains_key(&format!("/hair/plots/frame_ms/{m}")));
            for q in ["max_penetration", "specific_kinetic_energy"] {
                let rows = &d.scalars[&format!("/hair/plots/{q}/{m}")];
                assert_eq!(rows.len(), 60, "{q}/{m}: one value per 60 Hz frame");
            }
            // The stretch is plotted as log10 (frames with exactly zero stretch left out): every
            // value below 10⁻¹ (the springs' bound is 10⁻², the constraints' round-off).
            let rows = &d.scalars[&format!("/hair/plots/log10_max_stretch/{m}")];
            assert!(
                (1..=60).contains(&rows.len())
                    && rows.iter().all(|r| r.1.is_finite() && r.1 < -1.0),
                "log10_max_stretch/{m}: {rows:?}"
            );
            // The head never swallows a node: every recorded penetration is below 1e-6 R.
            assert!(
                d.scalars[&format!("/hair/plots/max_penetration/{m}")]
                    .iter()
                    .all(|r| r.1 <= 1e-7)
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `--dt` is the simulation step, as in every scene: in hair 1/(rate·substeps).
    #[test]
    fn hair_dt_is_the_simulation_step_and_sets_the_substeps() {
        let substeps = |args: &[&str]| -> (i32, Option<i64>, String) {
            let mut all = vec!["hair"];
            all.extend_from_slice(args);
            all.push("--print-config");
            let (code, toml, stderr) = physlab(&all);
            let n = toml
                .parse::<toml::Table>()
                .ok()
                .and_then(|t| t.get("hair")?.get("substeps")?.as_integer());
            (code, n, stderr)
        };
        // 1/(60 · 1/240) = 4 exactly in reals; in f64 within round-off.
        assert_eq!(substeps(&["--dt", "0.004166666666666667"]).1, Some(4));
        assert_eq!(substeps(&["--dt", "0.0041666666666667"]).1, Some(4));
        assert_eq!(substeps(&["--rate", "100", "--dt", "0.002"]).1, Some(5));
        assert_eq!(
            substeps(&["--dt", "0.008333333333333333", "--substeps", "2"]).1,
            Some(2)
        );
        assert_eq!(substeps(&[]).1, Some(1));

        // Steps that are not a whole number of substeps, or disagree with --substeps, are refused
        // naming the nearest allowed steps (rows of `cli_input.rs`); a scene file follows the same
        // rule, and its error names the file's key.
        let dir = scratch_dir("hair-dt");
        let file = dir.join("h.toml");
        std::fs::write(&file, "[hair]\ndt = 0.01\n").unwrap();
        let (code, _, stderr) = substeps(&["--config", file.to_str().unwrap()]);
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains("[hair] dt = 0.01:"), "{stderr}");
        std::fs::write(&file, "[hair]\ndt = 0.008333333333333333\nsubsteps = 2\n").unwrap();
        assert_eq!(substeps(&["--config", file.to_str().unwrap()]).1, Some(2));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A flag overrides the scene file's value of the same thing however each spells it: `--dt`
    /// a file's `substeps` (every file physlab prints states them) and `--substeps` a file's
    /// `dt`. At 60 Hz, dt = 1/240 s is 4 substeps; 3 substeps are dt = 1/180 s.
    #[test]
    fn a_step_flag_overrides_the_scene_files_step_in_either_spelling() {
        let dir = scratch_dir("hair-dt-over-file");
        let printed = |args: &[&str]| -> toml::Table {
            let mut all = args.to_vec();
            all.push("--print-config");
            let (code, toml, stderr) = physlab(&all);
            assert_eq!(code, 0, "{all:?}: {stderr}");
            toml.parse().unwrap()
        };
        let file = dir.join("all.toml");
        let own = toml::to_string(&printed(&["all"])).unwrap();
        assert!(own.contains("substeps = 1"), "{own}");
        std::fs::write(&file, own).unwrap();
        let file = file.to_str().unwrap();
        let hair =
            printed(&["all", "--config", file, "--dt", "0.004166666666666667"])["hair"].clone();
        assert_eq!(hair["substeps"].as_integer(), Some(4), "{hair}");
        let stepped = dir.join("stepped.toml");
        std::fs::write(&stepped, "[hair]\ndt = 0.008333333333333333\n").unwrap();
        let stepped = stepped.to_str().unwrap();
        let hair = printed(&["hair", "--config", stepped, "--substeps", "3"])["hair"].clone();
        assert_eq!(hair["substeps"].as_integer(), Some(3), "{hair}");
        assert!(
            hair.get("dt").is_none(),
            "the file's dt is replaced: {hair}"
        );
        // Given together on one layer they still must agree (a row of `cli_input.rs`).
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[cfg(feature = "rerun")]
mod divergence {
    //! Hair reports divergence honestly, and its kinetic energy per unit mass.

    use crate::common::physlab;

    /// Hair states its divergence bound, stops a run whose strands the solver cannot hold
    /// (|ℓ - ℓ0|/ℓ0 > 10) across a class of winds and solvers while the constrained methods go on,
    /// shows "—" for a lane that failed its first frame, and reports its kinetic energy per unit
    /// mass of hair, which does not grow with the strand count.
    #[test]
    fn hair_reports_divergence_honestly_and_its_energy_per_unit_mass() {
        let summary = |args: &[&str]| {
            let mut all = vec!["hair", "--no-record", "-q", "--wide", "--duration", "1"];
            all.extend_from_slice(args);
            let (code, stdout, stderr) = physlab(&all);
            assert_eq!(code, 0, "{args:?}: {stderr}");
            stdout
        };
        let row = |text: &str, method: &str| -> Vec<String> {
            let line = text
                .lines()
                .find(|l| l.starts_with(&format!("| {method} ")))
                .unwrap_or_else(|| panic!("no {method} row:\n{text}"));
            line.split('|').map(|c| c.trim().to_string()).collect()
        };
        for wind in ["300,0,0", "1000,0,0", "0,3000,0", "1e5,0,0"] {
            let s = summary(&["--wind", wind, "--methods", "verlet,ftl"]);
            assert!(
                s.contains("divergence = a non-finite position or a stretch |ℓ - ℓ0|/ℓ0 > 10"),
                "{s}"
            );
            for m in ["verlet", "ftl"] {
                assert_eq!(row(&s, m).last().map(String::as_str), Some(""), "{wind}");
                assert!(
                    row(&s, m)[11] == "no",
                    "--wind {wind}: {m} {:?}",
                    row(&s, m)
                );
            }
            // Gauss–Seidel's sweeps cannot hold these winds: 27-fold at 100, 267-fold at 1000.
            let s = summary(&[
                "--wind",
                wind,
                "--methods",
                "verlet",
                "--solver",
                "gauss-seidel",
            ]);
            assert!(
                row(&s, "verlet")[11].starts_with("yes"),
                "--wind {wind}: {s}"
            );
        }
        // Failing the first frame: no figures, not zeros.
        for wind in ["0,0,1e6", "1e6,0,0"] {
            // Gauss–Seidel's sweeps stretch past the bound in the first frame.
            let s = summary(&[
                "--wind",
                wind,
                "--gust",
                "0",
                "--methods",
                "verlet",
                "--solver",
                "gauss-seidel",
            ]);
            let r = row(&s, "verlet");
            assert!(r[11].starts_with("yes"), "{r:?}");
            assert_eq!(&r[7..11], ["—", "—", "—", "—"], "{r:?}");
        }
        // Per unit mass: 1, 10 and 100 strands move alike, so their KE is alike (a sum over nodes
        // would grow 100-fold).
        let ke = |strands: &str| -> f64 {
            let s = summary(&["--strands", strands, "--methods", "verlet"]);
            assert!(
                s.contains("KE = kinetic energy per unit mass of hair"),
                "{s}"
            );
            row(&s, "verlet")[10].parse().unwrap()
        };
        let (one, ten, hundred) = (ke("1"), ke("10"), ke("100"));
        for (n, k) in [(10, ten), (100, hundred)] {
            assert!(
                (0.2..5.0).contains(&(k / one)),
                "{n} strands: {k} J/kg against {one} J/kg for one strand"
            );
        }
    }
}

/// The direct solver (`physlab::scene::hair::direct`).
mod direct_solver {
    use glam::DVec3;
    use physlab::scene::hair::direct::*;

    /// A zig-zag chain stretched to `factor` times its length, root at the origin.
    fn stretched(n: usize, l0: f64, factor: f64) -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let side = if k % 2 == 0 { 0.0 } else { 0.3 };
                DVec3::new(k as f64 * l0 * factor, side * l0 * factor, 0.0)
            })
            .collect()
    }

    /// On a short chain the Newton steps converge quadratically: 5.4e-2, 2.2e-2, 2.8e-3, 2.5e-5,
    /// 2.8e-9 of ℓ0 (the same figures as a dense numpy solve of the same system).
    #[test]
    fn newton_converges_quadratically_on_a_short_chain() {
        let (n, l0) = (8, 1.0);
        let mut x = stretched(n, l0, 1.01);
        for _ in 0..4 {
            newton_step(&mut x, l0);
        }
        let r = residual(&x, l0);
        assert!(r < 1e-8, "residual after 4 steps {r:e}");
        assert_eq!(x[0], DVec3::ZERO, "the root is held");
    }

    /// The known catch: on 32 nodes folded into the same zig-zag, plain Newton stalls at
    /// residuals of order 1e-2 ℓ0, which is why the solver ends every step with the exact
    /// root-to-tip finish.
    #[test]
    fn newton_alone_stalls_on_a_long_folded_chain() {
        let (n, l0) = (32, 0.015);
        let mut x = stretched(n, l0, 1.01);
        for _ in 0..4 {
            newton_step(&mut x, l0);
        }
        let r = residual(&x, l0);
        assert!(r > 1e-3 && r < 1e-1, "residual after 4 steps {r:e}");
    }
}

mod head {
    //! The head's scripted path: every motion starts and ends at rest, with bounded
    //! acceleration.

    use glam::{DQuat, DVec3};
    use physlab::scene::hair::HeadMotion;
    use physlab::scene::hair::head::{PULSE, head_pose};

    /// The sway's amplitude [head radii] (`head.rs`'s `SWAY`).
    const SWAY: f64 = 2.0;

    #[test]
    fn every_motion_starts_and_ends_at_home_at_rest() {
        for m in [
            HeadMotion::Sway,
            HeadMotion::Turn,
            HeadMotion::Nod,
            HeadMotion::Tour,
            HeadMotion::Shake,
        ] {
            let period = if m == HeadMotion::Tour {
                4.0 * PULSE
            } else {
                PULSE
            };
            for t in [0.0, period, 2.0 * period] {
                let (c, q) = head_pose(m, t, 0.1);
                assert!(
                    c.length() < 1e-12 && q.angle_between(DQuat::IDENTITY) < 1e-12,
                    "{m:?} at {t}"
                );
                // Velocity by central difference vanishes at the joints.
                let e = 1e-4;
                let (c1, _) = head_pose(m, t + e, 0.1);
                let (c0, _) = head_pose(m, (t - e).max(0.0), 0.1);
                assert!((c1 - c0).length() / (2.0 * e) < 1e-6, "{m:?} moving at {t}");
            }
        }
    }

    #[test]
    fn acceleration_stays_bounded() {
        // Second differences of the sway over a tour stay near the analytic bound
        // max |pulse''| · SWAY·R / PULSE² (pulse'' ≤ ~4π² · 1.2).
        let (r, h) = (0.1, 1e-3);
        let bound = 4.0 * std::f64::consts::PI.powi(2) * 1.5 * SWAY * r / (PULSE * PULSE);
        for k in 1..8000 {
            let t = k as f64 * h;
            let x = |t: f64| head_pose(HeadMotion::Tour, t, r).0.x;
            let acc = (x(t + h) - 2.0 * x(t) + x(t - h)) / (h * h);
            assert!(acc.abs() < bound, "acceleration {acc} at t = {t}");
        }
    }

    #[test]
    fn shake_accelerates_by_several_g() {
        // Peak acceleration of the centre and of a root at the side of the head (radius R).
        let (r, h) = (0.1, 1e-4);
        let point = |t: f64| {
            let (c, q) = head_pose(HeadMotion::Shake, t, r);
            c + q * DVec3::new(0.0, r, 0.0)
        };
        let mut peak: f64 = 0.0;
        for k in 1..20_000 {
            let t = k as f64 * h;
            let acc = (point(t + h) - 2.0 * point(t) + point(t - h)) / (h * h);
            peak = peak.max(acc.length());
        }
        assert!(peak > 3.0 * 9.81 && peak < 10.0 * 9.81, "peak {peak} m/s²");
    }
}

#[cfg(feature = "rerun")]
mod strands_drawn {
    //! How many strands the recording draws in 3D (`physlab::record::hair::strand_plan`).

    use physlab::record::hair::{DEFAULT_3D_BUDGET, spread, strand_plan};
    use physlab::scene::hair::run::HairConfig;

    #[test]
    fn the_default_keeps_any_strand_count_within_the_budget() {
        for strands in [1, 200, 2000, 10_000, 100_000] {
            for nodes in [2, 16, 32, 64] {
                let mut c = HairConfig::default();
                c.params.strands = strands;
                c.params.nodes = nodes;
                let plan = strand_plan(&c, None);
                assert!(plan.drawn >= 1 && plan.drawn <= strands);
                // Within budget unless a single strand alone exceeds it (it never does here).
                assert!(
                    plan.expected_bytes <= DEFAULT_3D_BUDGET,
                    "{strands}×{nodes}: {plan:?}"
                );
            }
        }
        // The default run (200 strands × 16 nodes, 2 methods, 241 logged frames) draws all of
        // them: 200 × 16 × 241 × 2 × 13 B = 20.1 MB.
        let plan = strand_plan(&HairConfig::default(), None);
        assert_eq!(plan.drawn, HairConfig::default().params.strands);
        // 10 000 strands × 16 nodes at the defaults: 180e6 / (13 × 16 × 241 × 2) = 1795 drawn.
        let mut c = HairConfig::default();
        c.params.strands = 10_000;
        assert_eq!(strand_plan(&c, None).drawn, 1795);
        assert_eq!(strand_plan(&c, Some(50)).drawn, 50);
        assert_eq!(strand_plan(&c, Some(50_000)).drawn, 10_000);
    }

    #[test]
    fn spread_takes_evenly_spaced_distinct_strands() {
        assert_eq!(spread(4, 10), vec![0, 2, 5, 7]);
        assert_eq!(spread(3, 3), vec![0, 1, 2]);
        assert_eq!(spread(5, 2), vec![0, 1]);
        let s = spread(1000, 10_000);
        assert!(s.windows(2).all(|w| w[1] - w[0] == 10));
    }
}
