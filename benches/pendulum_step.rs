//! Cost of one pendulum step per method: `cargo bench --bench pendulum_step`.
//! Criterion reports time per 1000 steps and throughput in steps/s. It times
//! `step_block`, the same compiled loop whose cost the lab's ns/step column reports.

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use physlab::integrate::{Integrator, Method, MethodOptions};
use physlab::scene::pendulum::{Pendulum, PendulumParams, step_block};

const STEPS: usize = 1000;

fn pendulum_step(c: &mut Criterion) {
    let p = PendulumParams::default();
    let sys = Pendulum::new(&p);
    let mut group = c.benchmark_group("pendulum_step");
    group.throughput(Throughput::Elements(STEPS as u64));
    let (mut theta, mut omega) = (vec![0.0; STEPS], vec![0.0; STEPS]);
    let mut evals = vec![0u64; STEPS];
    let mut step_size = vec![0.0f64; STEPS];
    let mut unconverged: Vec<usize> = Vec::new();
    for m in Method::ALL {
        // Every sample starts afresh from the default start (θ0 = 60°, dt = 0.01 s), so each
        // method is timed on the states a default run visits (1000 steps ≈ 2.5 periods), not on
        // wherever a long benchmark would drift (explicit Euler's growth, implicit Euler's decay).
        let fresh = || {
            Integrator::new(
                m,
                &sys,
                &[p.theta0],
                &[p.omega0],
                0.01,
                MethodOptions::default(),
            )
        };
        group.bench_function(m.name(), |b| {
            b.iter_batched(
                fresh,
                |mut it| {
                    step_block(
                        &mut it,
                        black_box(&sys),
                        &mut theta,
                        &mut omega,
                        &mut evals,
                        &mut step_size,
                        &mut unconverged,
                    );
                    black_box(theta[STEPS - 1])
                },
                BatchSize::SmallInput,
            );
        });
    }
    group.finish();
}

criterion_group!(benches, pendulum_step);
criterion_main!(benches);
