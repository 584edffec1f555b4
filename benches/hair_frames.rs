//! Hair throughput at 10,000 strands × 32 nodes (verlet with its default direct solver, ftl),
//! 60 Hz frames (one step each):
//! `cargo bench --bench hair_frames`. Criterion's throughput is simulated frames per second;
//! real time is 60. "record" also logs the 3D state every second frame (30 fps) and the plots
//! every frame to a Rerun file sink writing to /dev/null, so encoding and compression are paid
//! but no disk fills up.

use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use physlab::scene::hair::run::{HairConfig, HairScene};
use physlab::scene::hair::{Hair, HairMethod, HairParams};
use physlab::scene::harness::{
    Frame, LaneSeries, Observer as _, Sampler, Scene as _, absent_when_zero,
};

fn config() -> HairConfig {
    HairConfig {
        params: HairParams {
            strands: 10_000,
            nodes: 32,
            ..HairParams::default()
        },
        ..HairConfig::default()
    }
}

fn hair_frames(c: &mut Criterion) {
    let config = config();
    let mut group = c.benchmark_group("hair_10k_x_32");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(6))
        .warm_up_time(Duration::from_secs(2));
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        // The spring methods take hundreds of inner steps a frame at this size: see the report.
        for method in [HairMethod::Verlet, HairMethod::Ftl] {
            // Two frames per iteration, so "record" logs 3D once per iteration (30 of 60 Hz).
            group.throughput(Throughput::Elements(2));
            let mut hair = Hair::new(config.params.clone(), method);
            group.bench_function(
                format!("{}/{threads}-thread/no-record", method.name()),
                |b| {
                    b.iter(|| {
                        pool.install(|| {
                            hair.step(1.0 / 60.0);
                            hair.step(1.0 / 60.0);
                        })
                    })
                },
            );
            if threads == 2 {
                let rec = rerun::RecordingStreamBuilder::new("physlab-bench")
                    .save("/dev/null")
                    .unwrap();
                rec.set_log_time_enabled(false);
                let mut recorder = physlab::record::hair::recorder(rec, true, None);
                let scene = HairScene::new(HairConfig {
                    methods: vec![method],
                    ..config.clone()
                });
                let schedule = scene.schedule();
                let (name, mut lane) = scene.lanes().pop().unwrap();
                recorder.start(&scene, &[(name, &lane)]).unwrap();
                let absent: Vec<bool> = scene
                    .quantities(&lane)
                    .iter()
                    .map(|q| absent_when_zero(q))
                    .collect();
                let mut series = LaneSeries::new(&schedule, &absent, None, true);
                let mut frame = 0u64;
                group.bench_function(
                    format!("{}/{threads}-thread/record-30fps", method.name()),
                    |b| {
                        b.iter(|| {
                            pool.install(|| {
                                for _ in 0..2 {
                                    frame += 1;
                                    scene.advance(&mut lane, frame, 1);
                                    series.batch.clear();
                                    let mut sampler = Sampler::new(&schedule, &mut series);
                                    scene.check(&mut lane, frame, 1, &mut sampler);
                                    recorder.series(&scene, 0, &series.batch).unwrap();
                                }
                                let view = Frame {
                                    tick: frame,
                                    time: schedule.time(frame),
                                    lanes: vec![Some((&lane, 0))],
                                    cost_ms: vec![0.0],
                                };
                                recorder.frame(&scene, &view).unwrap();
                            })
                        })
                    },
                );
            }
        }
    }
    group.finish();
}

criterion_group!(benches, hair_frames);
criterion_main!(benches);
