//! Parse + lowering throughput (MB/s) on generated particle files held in memory.
//! The million-particle figures with peak memory come from `gtsphere bench parse`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gtsphere::bench::scenes::{write_particles, Layout};
use gtsphere::vrml::{load_bytes, LoadOptions};

fn parse(c: &mut Criterion) {
    let n = 100_000;
    let mut g = c.benchmark_group("parse");
    g.sample_size(10);
    for layout in [Layout::Flat, Layout::Group] {
        let mut text = Vec::new();
        write_particles(&mut text, n, layout).expect("generate");
        g.throughput(Throughput::Bytes(text.len() as u64));
        g.bench_function(format!("{layout:?}-{n}"), |b| {
            b.iter(|| {
                let (s, _) =
                    load_bytes("bench.wrl", text.clone(), &LoadOptions::default()).expect("parse");
                assert_eq!(s.spheres.len(), n);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, parse);
criterion_main!(benches);
