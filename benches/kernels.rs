//! Criterion benchmarks of the kernels and phases: exact triangle–triangle classification,
//! closed-form distance, BVH build per strategy, and the whole check on real meshes.
//! `cargo bench -p meshclash-bench --bench kernels` (needs ../shared/meshes beside the repo for the mesh cases).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use glam::{DMat4, DVec3};
use meshclash::bvh::{BuildOptions, Bvh, Strategy};
use meshclash::check::query::{check, load_input, InputSpec, Settings};
use meshclash::geom::Aabb;
use meshclash::narrow::distance::triangle_distance;
use meshclash::narrow::tri_tri::{classify, classify_unfiltered, Hit};
use meshclash::scene::mesh::Mesh;
use meshclash::testing::gen;

/// Deterministic pseudo-random triangle pairs near each other (a mix of crossing and apart).
fn pairs(n: usize) -> Vec<([DVec3; 3], [DVec3; 3])> {
    let mut s = 0x9e3779b97f4a7c15u64;
    let mut r = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    (0..n)
        .map(|_| {
            let mut t = || [0; 3].map(|_| DVec3::new(r(), r(), r()));
            (t(), t())
        })
        .collect()
}

fn kernels(c: &mut Criterion) {
    let ps = pairs(4096);
    c.bench_function("tri_tri::classify x4096", |b| {
        b.iter(|| ps.iter().filter(|(x, y)| classify(black_box(x), black_box(y)).is_some()).count())
    });
    c.bench_function("tri_tri::classify_unfiltered x4096", |b| {
        b.iter(|| {
            ps.iter().filter(|(x, y)| classify_unfiltered(black_box(x), black_box(y)).is_some()).count()
        })
    });
    c.bench_function("distance::triangle_distance x4096", |b| {
        b.iter(|| ps.iter().map(|(x, y)| triangle_distance(black_box(x), black_box(y)).distance).sum::<f64>())
    });
}

fn shared(name: &str) -> Option<meshclash::scene::mesh::Mesh> {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes").join(name);
    load_input(&InputSpec { path, transform: DMat4::IDENTITY }).ok().map(|i| i.mesh)
}

fn phases(c: &mut Criterion) {
    let Some(bunny) = shared("stanford-bunny.obj") else { return };
    let mut g = c.benchmark_group("bunny 69k");
    g.sample_size(10);
    for s in [Strategy::Sah, Strategy::Median, Strategy::Equal] {
        let opts = BuildOptions { strategy: s, leaf_size: 4 };
        g.bench_function(format!("build {}", s.name()), |b| b.iter(|| Bvh::build(black_box(&bunny), opts)));
    }
    let mut moved = bunny.clone();
    let m = DMat4::from_cols_array(&[
        0.8, 0.6, 0.0, 0.0, -0.6, 0.8, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.01, 0.005, 0.002, 1.0,
    ]);
    meshclash::check::query::place(&mut moved, &m, std::path::Path::new("bunny")).unwrap();
    g.bench_function("check vs rotated copy", |b| b.iter(|| check(&bunny, &moved, &Settings::default())));
    g.finish();
}

/// A candidate pair: triangle indices into A and B.
type Pair = (u32, u32);

/// The candidate pairs (triangle boxes overlap) of a BVH walk of `a` against `b`, in walk order,
/// split into those that share no point and those that meet: what the pair walk classifies.
fn candidates(a: &Mesh, b: &Mesh) -> (Vec<Pair>, Vec<Pair>) {
    let opts = BuildOptions::default();
    let (ta, tb) = (Bvh::build(a, opts), Bvh::build(b, opts));
    let all: Vec<Pair> = meshclash::bvh::traverse::collect_pairs(
        &ta,
        &tb,
        |x, y| x.overlaps(y),
        |la, lb, out| {
            for &i in la {
                let bi = Aabb::of_triangle(&meshclash::bvh::triangle(a, i));
                for &j in lb {
                    if bi.overlaps(&Aabb::of_triangle(&meshclash::bvh::triangle(b, j))) {
                        out.push((i, j));
                    }
                }
            }
        },
    );
    all.into_iter().partition(|&(i, j)| {
        classify(&meshclash::bvh::triangle(a, i), &meshclash::bvh::triangle(b, j)).is_none()
    })
}

/// Replay the candidate pairs of real mesh pairs through the classifier, one thread; the
/// throughput is candidates per second (ns per candidate = 1e9 / throughput).
fn replay(c: &mut Criterion) {
    let mut cases: Vec<(String, Mesh, Mesh)> = Vec::new();
    let (a, b) = gen::crossing_tori(1_000_000);
    cases.push(("tori crossing 1M".into(), a, b));
    let (a, b) = gen::coplanar_grids(20_000);
    cases.push(("coplanar grids at 1e8 20k".into(), a, b));
    if let Some(bunny) = shared("stanford-bunny.obj") {
        cases.push(("bunny vs rotated copy".into(), gen::rotated_copy(&bunny), bunny));
    }
    for (name, a, b) in &cases {
        let (apart, meet) = candidates(a, b);
        let mut all = apart.clone();
        all.extend_from_slice(&meet);
        let mut g = c.benchmark_group(format!("tri_tri candidates {name}"));
        g.sample_size(10);
        for (what, list) in [("all", &all), ("apart", &apart), ("meet", &meet)] {
            if list.is_empty() {
                continue;
            }
            g.throughput(Throughput::Elements(list.len() as u64));
            type Classify = fn(&[DVec3; 3], &[DVec3; 3]) -> Option<Hit>;
            let fs: [(&str, Classify); 2] = [("filtered", classify), ("unfiltered", classify_unfiltered)];
            for (how, f) in fs {
                g.bench_function(format!("{what} ({}) {how}", list.len()), |bn| {
                    bn.iter(|| {
                        list.iter()
                            .filter(|&&(i, j)| {
                                f(
                                    black_box(&meshclash::bvh::triangle(a, i)),
                                    black_box(&meshclash::bvh::triangle(b, j)),
                                )
                                .is_some()
                            })
                            .count()
                    })
                });
            }
        }
        g.finish();
    }
}

criterion_group!(benches, kernels, phases, replay);
criterion_main!(benches);
