//! Cost of one rope step per method at N = 16, 1,000 and 100,000 nodes:
//! `cargo bench --bench rope_step`. Criterion's throughput is node-steps per second, so a flat
//! figure across N means a cost per node that does not grow with N (O(N) per step).
//!
//! `<method>+work` is the same step with the dissipated work integrated as one more coordinate
//! ([`Rope::balanced`], what the rope scene runs on a damped rope): its cost over `<method>` in
//! the same run is the price of the energy balance. An undamped balanced rope is `Rope::new`'s.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use physlab::integrate::{Integrator, Method, MethodOptions};
use physlab::scene::rope::{Rope, RopeParams, step_rope};

fn rope_step(c: &mut Criterion) {
    for nodes in [16usize, 1_000, 100_000] {
        // The default rope (ks = 5000 N/m, 0.1 kg per node, dt = 1 ms) with N nodes over the same
        // 4 m; each sample starts from rest, so no method has blown up while it is timed.
        let rope = Rope::new(RopeParams {
            nodes,
            ..RopeParams::default()
        });
        let x0 = rope.params.initial_positions();
        let v0 = vec![0.0; x0.len()];
        let steps: u64 = if nodes > 10_000 { 4 } else { 64 };
        let mut group = c.benchmark_group(format!("rope_step/n{nodes}"));
        group.throughput(Throughput::Elements(nodes as u64 * steps));
        if nodes > 10_000 {
            group
                .sample_size(10)
                .measurement_time(Duration::from_secs(4));
        }
        let balanced = Rope::balanced(rope.params.clone());
        let (xb, vb) = balanced.start();
        for m in Method::ALL {
            let mut variants = vec![(m.name().to_string(), &rope, &x0, &v0)];
            if m.info().accepts_velocity_dependent() {
                variants.push((format!("{}+work", m.name()), &balanced, &xb, &vb));
            }
            for (name, rope, x0, v0) in variants {
                let fresh = Integrator::new(m, rope, x0, v0, 1e-3, MethodOptions::default());
                group.bench_function(name, |b| {
                    b.iter_batched(
                        || fresh.clone(),
                        |mut it| {
                            step_rope(&mut it, black_box(rope), steps);
                            black_box(it.position()[3])
                        },
                        BatchSize::LargeInput,
                    );
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, rope_step);
criterion_main!(benches);
