//! Cost of one rope step per method at N = 16, 1,000 and 100,000 nodes:
//! `cargo bench --bench rope_step`. Criterion's throughput is node-steps per second, so a flat
//! figure across N means a cost per node that does not grow with N (O(N) per step).
//!
//! `<method>+work` is the same step with the dissipated work integrated as one more coordinate
//! ([`Rope::balanced`], what the rope scene runs on a damped rope): its cost over `<method>` in
//! the same run is the price of the energy balance. An undamped balanced rope is `Rope::new`'s.
//!
//! `ROPE_WORK_PAIRS=N cargo bench --bench rope_step` runs no Criterion group: it times each
//! method's steps without and with W alternately, N pairs at 16 nodes and N/10 at 100,000, and
//! prints the median ratio and its quartiles, a figure that load on a shared machine does not
//! skew (both halves of a pair run under the same load).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BatchSize, Criterion, Throughput, criterion_group};
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

/// W's cost per method as the median of `pairs` interleaved ratios (see the module docs).
fn work_cost(pairs: usize) {
    for nodes in [16usize, 100_000] {
        let rope = Rope::new(RopeParams {
            nodes,
            ..RopeParams::default()
        });
        let balanced = Rope::balanced(rope.params.clone());
        let (x0, v0) = rope.start();
        let (xb, vb) = balanced.start();
        let (steps, pairs) = if nodes > 10_000 {
            (4, (pairs / 10).max(1))
        } else {
            (64, pairs)
        };
        let time = |fresh: &Integrator, rope: &Rope| {
            let mut it = fresh.clone();
            let start = Instant::now();
            step_rope(&mut it, black_box(rope), steps);
            black_box(it.position()[3]);
            start.elapsed().as_secs_f64()
        };
        for m in Method::ALL
            .into_iter()
            .filter(|m| m.info().accepts_velocity_dependent())
        {
            let plain = Integrator::new(m, &rope, &x0, &v0, 1e-3, MethodOptions::default());
            let with = Integrator::new(m, &balanced, &xb, &vb, 1e-3, MethodOptions::default());
            let mut ratios: Vec<f64> = (0..pairs)
                .map(|k| {
                    // Which half goes first alternates.
                    if k % 2 == 0 {
                        let t = time(&plain, &rope);
                        time(&with, &balanced) / t
                    } else {
                        let t = time(&with, &balanced);
                        t / time(&plain, &rope)
                    }
                })
                .collect();
            ratios.sort_by(f64::total_cmp);
            let pct = |r: f64| 100.0 * (r - 1.0);
            println!(
                "n{nodes} {:<20} W costs {:+5.1} % (median of {pairs}; quartiles {:+.1} to {:+.1} %)",
                m.name(),
                pct(ratios[pairs / 2]),
                pct(ratios[pairs / 4]),
                pct(ratios[3 * pairs / 4]),
            );
        }
    }
}

criterion_group!(benches, rope_step);

fn main() {
    match std::env::var("ROPE_WORK_PAIRS").map(|n| n.parse()) {
        Ok(Ok(pairs)) => work_cost(pairs),
        _ => {
            benches();
            Criterion::default().configure_from_args().final_summary();
        }
    }
}
