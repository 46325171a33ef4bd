//! Criterion: the same operations for meshclash and parry3d (f64 and f32) in one group, on
//! generated crossing tori (10k and 100k triangles each): build, all pairs, and the whole
//! pipeline (build + pairs). parry's distance on crossing meshes is left out (seconds per call
//! at 100k); `meshclash-bench` measures it once. `cargo bench -p meshclash-bench --bench vs_parry`.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use meshclash::bvh::{BuildOptions, Bvh};
use meshclash::check::cross_check::parry_f64;
use meshclash::check::query::{check, Settings};
use meshclash::testing::gen;
use meshclash_bench::exact_pairs;
use meshclash_bench::parry32::parry_f32;
use std::time::Duration;

fn vs_parry(c: &mut Criterion) {
    let mut g = c.benchmark_group("vs parry");
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(3));
    for n in [10_000usize, 100_000] {
        let (a, b) = gen::crossing_tori(n);
        g.bench_function(BenchmarkId::new("meshclash build", n), |bch| {
            bch.iter(|| {
                rayon::join(
                    || Bvh::build(black_box(&a), BuildOptions::default()),
                    || Bvh::build(&b, BuildOptions::default()),
                )
            })
        });
        let (ta, tb) = (Bvh::build(&a, BuildOptions::default()), Bvh::build(&b, BuildOptions::default()));
        g.bench_function(BenchmarkId::new("meshclash pairs", n), |bch| {
            bch.iter(|| exact_pairs(black_box(&a), &ta, &b, &tb).len())
        });
        g.bench_function(BenchmarkId::new("meshclash whole check", n), |bch| {
            bch.iter(|| check(black_box(&a), &b, &Settings::default()).pairs.len())
        });
        g.bench_function(BenchmarkId::new("parry f64 build + pairs", n), |bch| {
            bch.iter(|| parry_f64(black_box(&a), &b, false).unwrap().intersecting_pairs.len())
        });
        g.bench_function(BenchmarkId::new("parry f32 build + pairs", n), |bch| {
            bch.iter(|| parry_f32(black_box(&a), &b, false).unwrap().intersecting_pairs.len())
        });
    }
    g.finish();
}

criterion_group!(benches, vs_parry);
criterion_main!(benches);
