//! The one integration-test crate: one test binary links once instead of once per file. Every
//! `tests/*.rs` file is a module here; run one file's tests with `cargo test --test suite cli::`
//! (module path as the filter). `common` finds the test meshes (shipped, or the corpus).

#[path = "assembly.rs"]
mod assembly;
#[path = "bcf.rs"]
mod bcf;
#[path = "bcf_schema.rs"]
mod bcf_schema;
#[path = "bench_cmd.rs"]
mod bench_cmd;
#[path = "bodies_penetration.rs"]
mod bodies_penetration;
#[path = "brute_force.rs"]
mod brute_force;
#[path = "cache.rs"]
mod cache;
#[path = "clash_set.rs"]
mod clash_set;
#[path = "cli.rs"]
mod cli;
#[path = "cli_errors.rs"]
mod cli_errors;
#[path = "cli_messages.rs"]
mod cli_messages;
#[path = "cli_subcommands.rs"]
mod cli_subcommands;
#[path = "common.rs"]
mod common;
#[path = "contract.rs"]
mod contract;
#[path = "convex_penetration.rs"]
mod convex_penetration;
#[path = "docs_commands.rs"]
mod docs_commands;
#[path = "exactness.rs"]
mod exactness;
#[path = "extremes.rs"]
mod extremes;
#[path = "fcl_reference.rs"]
mod fcl_reference;
#[path = "gate.rs"]
mod gate;
#[path = "glb.rs"]
mod glb;
#[path = "gltf_ext.rs"]
mod gltf_ext;
#[path = "hostile.rs"]
mod hostile;
#[path = "html.rs"]
mod html;
#[path = "instanced_scene.rs"]
mod instanced_scene;
#[path = "layers.rs"]
mod layers;
#[path = "memory_bounds.rs"]
mod memory_bounds;
#[path = "never_lose.rs"]
mod never_lose;
#[path = "obj_vs_tobj.rs"]
mod obj_vs_tobj;
#[path = "outputs.rs"]
mod outputs;
#[path = "overlap.rs"]
mod overlap;
#[path = "parry_oracle.rs"]
mod parry_oracle;
#[path = "part_pairs.rs"]
mod part_pairs;
#[path = "safety.rs"]
mod safety;
#[path = "self_clash.rs"]
mod self_clash;
#[path = "self_scene.rs"]
mod self_scene;
#[path = "shard.rs"]
mod shard;
#[path = "shard_limits.rs"]
mod shard_limits;
#[path = "solids.rs"]
mod solids;
#[path = "tri_tri_oracle.rs"]
mod tri_tri_oracle;
#[path = "trust.rs"]
mod trust;
