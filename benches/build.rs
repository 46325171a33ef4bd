//! Criterion: BVH build per strategy on generated tori of 10k / 100k / 1M triangles
//! (throughput in triangles per second; the SAH cost of each tree is printed once).
//! `cargo bench -p meshclash-bench --bench build`.
//!
//! With `BUILD_REPORT=1` (e.g. `BUILD_REPORT=1 cargo bench -p meshclash-bench --bench build`) criterion is skipped
//! and a short report is printed instead, per size: SAH build Mtris/s for one tree and for two
//! trees built side by side (median of several runs, as `meshclash check` builds), tree bytes per
//! triangle, the peak heap the build allocates beyond its input (counted by this binary's global
//! allocator, so exact and independent of other processes), and the SAH cost against a full
//! sweep (up to `BUILD_REPORT_SWEEP_MAX` triangles, default 300k).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use meshclash::bvh::{self, BuildOptions, Bvh, Strategy};
use meshclash::geom::Aabb;
use meshclash::testing::{gen, sweep};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The system allocator, counting live and peak bytes.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(n: usize) {
    let now = LIVE.fetch_add(n, Ordering::Relaxed) + n;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = System.alloc(l);
        if !p.is_null() {
            grew(l.size());
        }
        p
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(l);
        if !p.is_null() {
            grew(l.size());
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l);
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = System.realloc(p, l, new);
        if !q.is_null() {
            // Counted as old + new at the moment of the copy (the worst case of a moving realloc).
            grew(new);
            LIVE.fetch_sub(l.size(), Ordering::Relaxed);
        }
        q
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// CPU seconds used by this process so far (all threads; Linux `/proc/self/stat`, 10 ms ticks).
fn cpu_s() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = s.rsplit(") ").next().unwrap_or("");
    let f: Vec<f64> = rest.split(' ').map(|t| t.parse().unwrap_or(0.0)).collect();
    // After the command name: state is field 3, utime 14 and stime 15 (1-based).
    f.get(11).zip(f.get(12)).map_or(0.0, |(u, s)| (u + s) / 100.0)
}

/// CPU seconds used by the calling thread (`/proc/thread-self/schedstat`, nanoseconds).
fn thread_cpu_s() -> f64 {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    s.split(' ').next().and_then(|t| t.parse::<f64>().ok()).map_or(0.0, |ns| ns / 1e9)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn report() {
    let sweep_max: usize =
        std::env::var("BUILD_REPORT_SWEEP_MAX").ok().and_then(|s| s.parse().ok()).unwrap_or(300_000);
    let sizes: Vec<usize> = std::env::var("BUILD_REPORT_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|t| t.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![100_000, 1_000_000]);
    let opts = BuildOptions::default();
    println!("threads {}", rayon::current_num_threads());
    for n in sizes {
        let (a, b) = gen::crossing_tori(n);
        let tris = a.triangles.len();
        let reps = if tris <= 300_000 { 15 } else { 7 };
        // Warm up (thread pool, page faults of the allocator).
        black_box(Bvh::build(&a, opts));
        let cpu0 = cpu_s();
        let one: Vec<f64> = (0..reps)
            .map(|_| {
                let t = Instant::now();
                black_box(Bvh::build(&a, opts));
                t.elapsed().as_secs_f64()
            })
            .collect();
        let cpu_one = (cpu_s() - cpu0) / reps as f64;
        let cpu0 = cpu_s();
        let two: Vec<f64> = (0..reps)
            .map(|_| {
                let t = Instant::now();
                black_box(rayon::join(|| Bvh::build(&a, opts), || Bvh::build(&b, opts)));
                t.elapsed().as_secs_f64()
            })
            .collect();
        let cpu_two = (cpu_s() - cpu0) / reps as f64;
        // One thread: its own CPU time, unaffected by other processes sharing the cores.
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
        let single: Vec<f64> = (0..reps)
            .map(|_| {
                pool.install(|| {
                    let c = thread_cpu_s();
                    black_box(Bvh::build(&a, opts));
                    thread_cpu_s() - c
                })
            })
            .collect();
        let base = LIVE.load(Ordering::Relaxed);
        PEAK.store(base, Ordering::Relaxed);
        let tree = Bvh::build(&a, opts);
        let peak = PEAK.load(Ordering::Relaxed) - base;
        let boxes: Vec<Aabb> = (0..tris as u32).map(|t| Aabb::of_triangle(&bvh::triangle(&a, t))).collect();
        tree.validate(&boxes, opts.leaf_size).expect("valid tree");
        let st = tree.stats();
        let full =
            (tris <= sweep_max).then(|| sweep::build_full_sweep(&boxes, opts.leaf_size).stats().sah_cost);
        println!(
            "{tris} tris: one tree {:.1} ms (min {:.1}, CPU {:.1}) = {:.2} Mtris/s; \
             two trees {:.1} ms (min {:.1}, CPU {:.1}) = {:.2} Mtris/s; one thread: CPU {:.1} ms (min {:.1}) = {:.2} Mtris/CPU-s; tree {:.1} B/tri; peak build heap {:.1} B/tri; SAH {:.4}{}",
            median(one.clone()) * 1e3,
            one.iter().copied().fold(f64::INFINITY, f64::min) * 1e3,
            cpu_one * 1e3,
            tris as f64 / median(one) / 1e6,
            median(two.clone()) * 1e3,
            two.iter().copied().fold(f64::INFINITY, f64::min) * 1e3,
            cpu_two * 1e3,
            2.0 * tris as f64 / median(two) / 1e6,
            median(single.clone()) * 1e3,
            single.iter().copied().fold(f64::INFINITY, f64::min) * 1e3,
            tris as f64 / median(single) / 1e6,
            st.bytes as f64 / tris as f64,
            peak as f64 / tris as f64,
            st.sah_cost,
            full.map_or(String::new(), |f| format!(" vs full sweep {f:.4} (ratio {:.4})", st.sah_cost / f)),
        );
    }
}

fn build(c: &mut Criterion) {
    if std::env::var_os("BUILD_REPORT").is_some() {
        report();
        return;
    }
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
