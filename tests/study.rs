//! `physlab study` against theory (issue 6, point 5).

mod common;

use physlab::integrate::{Method, MethodOptions, Stability};
use physlab::scene::pendulum::PendulumParams;
use physlab::scene::rope::RopeParams;
use physlab::study::{Problem, Sweep, cheapest, error_floor, orders, stability, sweep};

use common::{decode, physlab, scratch_dir};

fn pendulum() -> Problem {
    Problem::Pendulum(PendulumParams::default())
}

/// The study's rope for convergence: the scene's rope, softer (ks = 100 N/m) and undamped.
fn soft_rope() -> Problem {
    Problem::Rope(RopeParams {
        stiffness: 100.0,
        spring_damping: 0.0,
        air_drag: 0.0,
        ..RopeParams::default()
    })
}

fn fixed_step() -> Vec<Method> {
    Method::ALL
        .into_iter()
        .filter(|m| m.info().stability != Stability::Adaptive)
        .collect()
}

#[test]
fn fitted_orders_match_theory_on_both_scenes() {
    for (problem, dt0, duration) in [(pendulum(), 0.02, 10.0), (soft_rope(), 0.002, 1.0)] {
        let s = Sweep {
            dt0,
            levels: 6,
            duration,
            methods: fixed_step(),
            options: MethodOptions::default(),
            repeats: 1,
            rtols: vec![],
        };
        let (rows, reference_error) = sweep(&problem, &s);
        assert!(
            reference_error < 1e-11,
            "{}: reference error {reference_error:e}",
            problem.name()
        );
        for o in orders(&rows, error_floor(reference_error)) {
            let theory = o.method.info().order as f64;
            let fitted = o.fitted.unwrap();
            assert!(
                o.diverged_at.is_empty(),
                "{} {}: diverged at {:?}",
                problem.name(),
                o.method,
                o.diverged_at
            );
            assert!(
                (fitted - theory).abs() <= 0.15,
                "{} {}: fitted order {fitted:.3}, theory {theory}",
                problem.name(),
                o.method
            );
        }
    }
}

#[test]
fn stability_limits_are_within_two_percent_of_theory() {
    let rope = Problem::Rope(RopeParams::default());
    for problem in [pendulum(), rope] {
        let limits = stability(&problem, &Method::ALL, 2000);
        for l in limits {
            match l.method.info().stability {
                Stability::Below(_) => {
                    let ratio = l.measured_dt.unwrap() / l.theory_dt.unwrap();
                    assert!(
                        (ratio - 1.0).abs() <= 0.02,
                        "{} {}: measured/theory {ratio:.4}",
                        problem.name(),
                        l.method
                    );
                }
                Stability::Always => {
                    assert!(
                        l.measured_dt.is_some(),
                        "{} {}: unconditionally stable in theory",
                        problem.name(),
                        l.method
                    )
                }
                Stability::Never => {
                    // Growth is slow, so a finite run tolerates small steps; but nowhere near the
                    // conditionally stable methods' limits.
                    let measured = l.measured_dt.unwrap();
                    assert!(
                        measured * problem.omega() < 0.5,
                        "{} {}: 'stable' up to h = {}",
                        problem.name(),
                        l.method,
                        measured * problem.omega()
                    );
                }
                Stability::Adaptive => assert!(l.measured_dt.is_none()),
            }
        }
    }
}

#[test]
fn cheapest_method_answers_agree_with_the_measured_rows() {
    let s = Sweep {
        dt0: 0.02,
        levels: 6,
        duration: 10.0,
        methods: Method::ALL.to_vec(),
        options: MethodOptions::default(),
        repeats: 3,
        rtols: (3..=12).map(|k| 10f64.powi(-k)).collect(),
    };
    let (rows, _) = sweep(&pendulum(), &s);
    for target in [1e-3, 1e-6, 1e-9] {
        let (by_wall, by_evals) = cheapest(&rows, target);
        let (w, e) = (by_wall.unwrap(), by_evals.unwrap());
        assert!(w.error.unwrap() <= target && e.error.unwrap() <= target);
        for r in rows.iter().filter(|r| r.error.is_some_and(|x| x <= target)) {
            assert!(
                r.wall_seconds >= w.wall_seconds && r.evals >= e.evals,
                "{r:?} is cheaper than the answer"
            );
        }
    }
    // And a target nobody reaches has no answer.
    assert_eq!(cheapest(&rows, 1e-30), (None, None));
}

#[test]
fn study_writes_csv_and_a_recording() {
    let dir = scratch_dir("study");
    let csv = dir.join("s.csv");
    let (code, out, err) = physlab(&[
        "study",
        "stability",
        "--scene",
        "rope",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("| verlet ") && out.contains("1.0000"), "{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(
        text.starts_with("scene,method,measured_dt,theory_dt\n") && text.lines().count() == 10,
        "{text}"
    );

    let rrd = dir.join("s.rrd");
    let (code, out, err) = physlab(&[
        "study",
        "work-precision",
        "--scene",
        "pendulum",
        "--repeats",
        "1",
        "--csv",
        csv.to_str().unwrap(),
        "-o",
        rrd.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("cheapest run reaching each error"), "{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(
        text.starts_with("scene,method,dt,rtol,error,evals,wall_seconds,stable\n"),
        "{text}"
    );
    let d = decode(&rrd);
    assert!(
        d.has_footer
            && d.entities.contains("/study/wall/rk4")
            && d.entities.contains("/study/tables")
    );
    let (code, _, err) = physlab(&["study", "convergence", "--levels", "1"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--levels 1: must be between 2 and 20"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
