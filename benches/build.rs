//! Criterion: BVH build per strategy on generated tori of 10k / 100k / 1M triangles
//! (throughput in triangles per second; the SAH cost of each tree is printed once).
//! `cargo bench --bench build`.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use meshclash::bench::gen;
use meshclash::bvh::{BuildOptions, Bvh, Strategy};
use std::time::Duration;

fn build(c: &mut Criterion) {
    let mut g = c.benchmark_group("bvh build");
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    for n in [10_000usize, 100_000, 1_000_000] {
        let m = gen::torus(n);
        g.throughput(Throughput::Elements(m.triangles.len() as u64));
        for s in [Strategy::Sah, Strategy::Median, Strategy::Equal] {
            let opts = BuildOptions { strategy: s, leaf_size: 4 };
            let st = Bvh::build(&m, opts).stats();
            eprintln!(
                "{} {} triangles: SAH cost {:.3}, {} nodes, {} bytes",
                s.name(),
                m.triangles.len(),
                st.sah_cost,
                st.nodes,
                st.bytes
            );
            g.bench_with_input(BenchmarkId::new(s.name(), m.triangles.len()), &m, |b, m| {
                b.iter(|| Bvh::build(black_box(m), opts))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, build);
criterion_main!(benches);
