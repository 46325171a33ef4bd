//! Property: over random part layouts (cubes that cross, touch, nest and keep apart; glTF-like
//! instances of one mesh, so trees are shared), plan → every shard → merge gives exactly the
//! outcome of the single check, for 1 to 5 shards.

use super::*;
use crate::check::assembly::{self, Hook, Selection};
use crate::check::query::Settings;
use crate::geom::predicates::Tolerances;
use crate::geom::DVec3;
use crate::scene::mesh::Object;
use glam::DMat4;
use std::sync::Arc;

/// A small deterministic generator (splitmix64).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// A multiple of 1/4 in [0, n) (exact coordinates: touching happens).
    fn quarter(&mut self, n: u64) -> f64 {
        (self.next() % (4 * n)) as f64 / 4.0
    }
}

const CUBE: [[u32; 3]; 12] = [
    [0, 2, 1],
    [0, 3, 2],
    [4, 5, 6],
    [4, 6, 7],
    [0, 1, 5],
    [0, 5, 4],
    [1, 2, 6],
    [1, 6, 5],
    [2, 3, 7],
    [2, 7, 6],
    [3, 0, 4],
    [3, 4, 7],
];

fn layout(rng: &mut Rng, n: usize) -> Mesh {
    let mut m =
        Mesh { positions: Vec::new(), triangles: Vec::new(), tri_object: Vec::new(), objects: Vec::new() };
    for o in 0..n {
        let size = 0.5 + rng.quarter(3);
        let at = DVec3::new(rng.quarter(6), rng.quarter(6), rng.quarter(3));
        let world = DMat4::from_translation(at) * DMat4::from_scale(DVec3::splat(size));
        let base = m.positions.len() as u32;
        for c in 0..8u32 {
            let unit = DVec3::new(((c & 1) ^ ((c >> 1) & 1)) as f64, ((c >> 1) & 1) as f64, (c >> 2) as f64);
            m.positions.push(world.transform_point3(unit));
        }
        for t in CUBE {
            m.triangles.push(t.map(|v| v + base));
            m.tri_object.push(o as u32);
        }
        // Most are instances of one mesh; every fourth is a mesh of its own.
        let instance = o % 4 != 3;
        m.objects.push(Object {
            name: format!("site/p{o}"),
            gltf_mesh: instance.then_some(0),
            world: instance.then_some(world),
        });
    }
    m
}

fn hooked(sel: &Selection, hook: Arc<dyn assembly::PartsHook>) -> Selection {
    Selection { hook: Some(Hook(hook)), ..sel.clone() }
}

fn untimed(mut o: Outcome) -> Outcome {
    o.result.timings = Timings::default();
    o
}

#[test]
fn plan_shards_merge_equals_the_single_check_on_random_layouts() {
    let mut rng = Rng(14);
    let (mut shared, mut clashes, mut clear_pairs) = (0, 0, 0);
    for case in 0..12 {
        let mesh = layout(&mut rng, 6 + case * 2);
        let settings = Settings {
            tolerances: Tolerances { touch: 0.0, clearance: [0.0, 0.25, 1.0][case % 3] },
            ..Settings::default()
        };
        let sel = Selection {
            scene: true,
            select_a: Vec::new(),
            select_b: Vec::new(),
            exclude: Vec::new(),
            hook: None,
        };
        let sel = if case % 4 == 3 {
            // Overlapping selections: self pairs and mirrors are not work.
            Selection { select_a: vec!["site/p1*".into(), "site/p2".into()], ..sel }
        } else {
            sel
        };
        let single = untimed(assembly::run(&mesh, &mesh, &sel, &settings).unwrap());
        shared += single.info.sharing.map_or(0, |s| s.mapped_instances);
        clashes += single.part_pairs.iter().filter(|p| p.verdict == Verdict::Clash).count();
        clear_pairs += single.info.candidate_part_pairs - single.part_pairs.len();
        let plan_hook = Arc::new(PlanHook::default());
        assembly::run(&mesh, &mesh, &hooked(&sel, plan_hook.clone()), &settings).unwrap();
        let plan = plan_hook.plan(Vec::new(), Vec::new(), 0.0);
        assert_eq!(plan.candidate_part_pairs, single.info.candidate_part_pairs, "case {case}");
        for n in 1..=5 {
            let shard_of = plan::partition(&plan.pairs, n);
            let owners = tree_owners(&plan, &shard_of);
            let needed = needed_parts(plan.pairs.iter().map(|p| (p.a, p.b)), &plan.extra_needed);
            let mut reports = Vec::new();
            for i in 0..n {
                let mine: Vec<&PlanPair> =
                    plan.pairs.iter().zip(&shard_of).filter(|(_, &s)| s == i).map(|(p, _)| p).collect();
                let hook = Arc::new(ShardHook {
                    files: false,
                    has_files_unit: false,
                    pairs: mine.iter().map(|p| (p.a.unwrap(), p.b.unwrap())).collect(),
                    needed: needed.clone(),
                    owned: owners.iter().filter(|(_, &s)| s == i).map(|(&p, _)| p).collect(),
                    bvh: settings.bvh,
                    parts: plan.parts,
                    captured: Mutex::new(None),
                });
                assembly::run(&mesh, &mesh, &hooked(&sel, hook.clone()), &settings).unwrap();
                let (outcome, trees) = hook.captured.lock().unwrap().take().unwrap();
                reports.push(ShardReport {
                    schema: SHARD_SCHEMA.into(),
                    plan_hash: String::new(),
                    shard: i + 1,
                    shards: n,
                    plan: plan.head(),
                    pairs: mine.iter().map(|p| Covered { id: p.id.clone(), a: p.a, b: p.b }).collect(),
                    error: None,
                    outcome: Some(outcome),
                    trees,
                });
            }
            reports.reverse();
            let merge = Arc::new(MergeHook { plan: plan.head(), shards: reports, partial: false });
            let merged = untimed(assembly::run(&mesh, &mesh, &hooked(&sel, merge), &settings).unwrap());
            assert_eq!(merged, single, "case {case}, {n} shards");
        }
    }
    // The layouts did exercise shared trees, clashes and candidates without findings.
    assert!(shared > 10 && clashes > 10 && clear_pairs > 10, "{shared} {clashes} {clear_pairs}");
}
