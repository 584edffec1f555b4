//! Cost of one pendulum step per method: `cargo bench --bench pendulum_step`.
//! Criterion reports time per 1000 steps and throughput in steps/s.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use physlab::method::{Integrator, Method, MethodOptions};
use physlab::scene::pendulum::{Pendulum, PendulumParams};

const STEPS: u64 = 1000;

fn pendulum_step(c: &mut Criterion) {
    let p = PendulumParams::default();
    let sys = Pendulum::new(&p);
    let mut group = c.benchmark_group("pendulum_step");
    group.throughput(Throughput::Elements(STEPS));
    for m in Method::ALL {
        group.bench_function(m.name(), |b| {
            let mut it = Integrator::new(
                m,
                &sys,
                &[p.theta0],
                &[p.omega0],
                0.01,
                MethodOptions::default(),
            );
            b.iter(|| {
                for _ in 0..STEPS {
                    it.step(black_box(&sys));
                }
                black_box(it.position()[0])
            });
        });
    }
    group.finish();
}

criterion_group!(benches, pendulum_step);
criterion_main!(benches);
