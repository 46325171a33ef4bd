//! Criterion: the dual walk with exact classification (all pairs) and the distance query on
//! generated tori (crossing and apart), 10k / 100k / 1M triangles each.
//! `cargo bench -p meshclash-bench --bench query`.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use meshclash::bvh::{BuildOptions, Bvh};
use meshclash::testing::gen;
use meshclash_bench::{exact_distance, exact_pairs};
use std::time::Duration;

fn query(c: &mut Criterion) {
    let mut g = c.benchmark_group("query");
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    for n in [10_000usize, 100_000, 1_000_000] {
        let (a, b) = gen::crossing_tori(n);
        let (ta, tb) = (Bvh::build(&a, BuildOptions::default()), Bvh::build(&b, BuildOptions::default()));
        g.bench_function(BenchmarkId::new("dual walk + exact pairs, crossing", n), |bch| {
            bch.iter(|| exact_pairs(black_box(&a), &ta, &b, &tb).len())
        });
        g.bench_function(BenchmarkId::new("distance, crossing (first contact)", n), |bch| {
            bch.iter(|| exact_distance(black_box(&a), &ta, &b, &tb))
        });
        let (a, b) = gen::separated_tori(n);
        let (ta, tb) = (Bvh::build(&a, BuildOptions::default()), Bvh::build(&b, BuildOptions::default()));
        g.bench_function(BenchmarkId::new("distance, apart (branch and bound)", n), |bch| {
            bch.iter(|| exact_distance(black_box(&a), &ta, &b, &tb))
        });
    }
    g.finish();
}

criterion_group!(benches, query);
criterion_main!(benches);
