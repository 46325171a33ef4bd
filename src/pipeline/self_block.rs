//! The `self` block of `scene --self`: every selected part of the scene's file checked against
//! itself ([`crate::check::self_clash`]), projected into [`SceneSelfReport`].

use crate::report::self_report::*;

/// Check every selected part of `mesh` (the scene's one file, parts in
/// [`crate::check::assembly::parts_of`] order, which is the report's `parts` order) against
/// itself and build the `self` block. `keep` selects parts by name. Instances are checked once
/// per distinct placed geometry ([`crate::check::self_clash::check_part_list`]).
fn scene_self(
    mesh: &crate::scene::mesh::Mesh,
    keep: &dyn Fn(&str) -> bool,
    opts: crate::bvh::BuildOptions,
    fail_on: &[SelfFailOn],
    max_pairs: usize,
    deterministic: bool,
) -> SceneSelfReport {
    let t = std::time::Instant::now();
    let all = crate::check::assembly::parts_of(mesh, 0);
    let chosen: Vec<usize> = (0..all.len()).filter(|&i| keep(&all[i].name)).collect();
    let specs = chosen
        .iter()
        .map(|&i| (Some(all[i].object), all[i].name.clone(), all[i].triangles.clone()))
        .collect();
    let (results, _, _) =
        crate::check::self_clash::check_part_list(mesh, specs, opts, SCENE_FIRST_N, max_pairs, true);
    let (pairs, pairs_truncated) = pairs_of(mesh, &results, max_pairs);
    let summary = summary_of(&results);
    let failed_on: Vec<SelfFailOn> =
        fail_on.iter().copied().filter(|f| results.iter().any(|p| f.hit(p))).collect();
    let names = |v: &[SelfFailOn]| v.iter().map(|f| f.name().to_string()).collect::<Vec<_>>();
    SceneSelfReport {
        fail_on: names(fail_on),
        verdict: verdict_of(&summary),
        failed: !failed_on.is_empty(),
        failed_on: names(&failed_on),
        checks: results.iter().filter(|p| p.same_as.is_none()).count(),
        summary,
        pairs,
        pairs_truncated,
        parts: results
            .iter()
            .zip(&chosen)
            .map(|(p, &i)| SceneSelfPart {
                part: i,
                object: all[i].object,
                name: p.name.clone(),
                triangles: p.triangles,
                crossing_pairs: p.crossing,
                touching_pairs: p.count - p.crossing,
                same_as: p.same_as.map(|l| chosen[l]),
                health: health_report(&p.health),
            })
            .collect(),
        time_ms: (!deterministic).then(|| t.elapsed().as_secs_f64() * 1e3),
    }
}

/// The `self` block of `scene --self`: every selected part of `mesh` checked against itself
/// (a part is selected when a scene selection would keep it on either side).
pub fn scene_self_block(
    mesh: &crate::scene::mesh::Mesh,
    sel: &crate::check::assembly::Selection,
    opts: crate::bvh::BuildOptions,
    fail_on: &[SelfFailOn],
    max_pairs: usize,
    deterministic: bool,
) -> SceneSelfReport {
    use crate::check::assembly::glob_match;
    let keep = |name: &str| {
        let any = |g: &[String]| g.iter().any(|p| glob_match(p, name));
        !any(&sel.exclude) && (sel.select_a.is_empty() || any(&sel.select_a) || any(&sel.select_b))
    };
    scene_self(mesh, &keep, opts, fail_on, max_pairs, deterministic)
}
