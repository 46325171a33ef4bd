//! Time the result cache's own costs on a real assembly, whole process:
//! `cargo run --release --example cache_store -- MESH DIR MODE`, MODE one of
//!
//! - `load`: load MESH and split it into parts (the floor every run pays);
//! - `keys`: that, plus the part key of every part (what a warm run adds before any lookup);
//! - `cold`: that, plus a fresh cache in DIR and one stored result per candidate part pair
//!   (parts whose boxes overlap);
//! - `warm`: that, but looking every pair up in DIR (filled by `cold`) instead.
//!
//! The stored value stands in for a part pair's result: a verdict, counts, 16 index pairs and
//! a closest pair of points.

use std::path::Path;
use std::process::ExitCode;

use meshclash::cache::{Fingerprint, PairKey, PartKey, Store, DEFAULT_MAX_BYTES};
use meshclash::check::assembly::parts_of;
use serde::{Deserialize, Serialize};

#[derive(Serialize, Deserialize, PartialEq, Debug)]
struct Stand {
    verdict: String,
    counts: [u64; 3],
    pairs: Vec<(u32, u32)>,
    closest: [[f64; 3]; 2],
}

fn stand(i: usize, j: usize) -> Stand {
    Stand {
        verdict: "clear".into(),
        counts: [i as u64, j as u64, 0],
        pairs: (0..16).map(|k| (i as u32 + k, j as u32 + k)).collect(),
        closest: [[i as f64 / 3.0, 0.1, -2.5e-7], [j as f64 / 7.0, 0.2, 1e300]],
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh, dir, mode] = &args[..] else {
        eprintln!("usage: cache_store MESH DIR load|keys|cold|warm");
        return ExitCode::from(2);
    };
    let (loaded, _) = match meshclash::load::load_path(Path::new(mesh)) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("cache_store: {e}");
            return ExitCode::from(2);
        }
    };
    let m = &loaded.mesh;
    let parts = parts_of(m, 0);
    if mode == "load" {
        println!("{} parts", parts.len());
        return ExitCode::SUCCESS;
    }
    let keys = PartKey::of_parts(m, &parts);
    if mode == "keys" {
        let triangles: usize = parts.iter().map(|p| p.triangles.len()).sum();
        println!("{} part keys over {triangles} triangles", keys.len());
        return ExitCode::SUCCESS;
    }
    let settings = Fingerprint::of([("mode", "clash".into()), ("tolerance", 0.0.into())]);
    let mut candidates = Vec::new();
    for i in 0..parts.len() {
        for j in i + 1..parts.len() {
            if parts[i].bounds.overlaps(&parts[j].bounds) {
                candidates.push((i, j));
            }
        }
    }
    if mode == "cold" {
        let _ = std::fs::remove_dir_all(dir);
    }
    let store = match Store::open(dir, DEFAULT_MAX_BYTES) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cache_store: {e}");
            return ExitCode::from(2);
        }
    };
    for &(i, j) in &candidates {
        let key = PairKey::new(&keys[i], &keys[j], &settings);
        match mode.as_str() {
            "cold" => store.put(&key, &stand(i, j)),
            _ => assert_eq!(store.get::<Stand>(&key), Some(stand(i, j))),
        }
    }
    let s = store.stats();
    println!(
        "{} candidate pairs: {} stored, {} hits, {} misses",
        candidates.len(),
        s.stored,
        s.hits,
        s.misses
    );
    for w in store.take_warnings() {
        eprintln!("{w}");
    }
    ExitCode::SUCCESS
}
