//! Load a glTF scene without expanding its instances and place its parts one at a time, or
//! (with `--expand`) load it expanded as a check does, for comparing the memory and time of the
//! two: `cargo run --release --example instanced_scene -- FILE [--expand]`. Prints the part,
//! vertex and triangle counts and the world box (the same either way).

use meshclash::geom::Aabb;

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first().map(std::path::PathBuf::from) else {
        eprintln!("usage: instanced_scene FILE [--expand]");
        return std::process::ExitCode::from(2);
    };
    let fail = |e: &dyn std::fmt::Display| {
        eprintln!("instanced_scene: {e}");
        std::process::ExitCode::from(2)
    };
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) => return fail(&format!("{}: {e}", path.display())),
    };
    let (parts, vertices, triangles, bounds) = if args.iter().any(|a| a == "--expand") {
        let format = match meshclash::load::detect_format(&path, &bytes) {
            Ok(f) => f,
            Err(e) => return fail(&e),
        };
        let m = match meshclash::load::load_bytes(&path, &bytes, format) {
            Ok(l) => l.mesh,
            Err(e) => return fail(&e),
        };
        (m.objects.len(), m.positions.len(), m.triangles.len(), Aabb::of_points(&m.positions))
    } else {
        let scene = match meshclash::load::load_gltf_instanced(&path, &bytes) {
            Ok(s) => s,
            Err(e) => return fail(&e),
        };
        let (mut v, mut t, mut b) = (0, 0, Aabb::EMPTY);
        for k in 0..scene.parts.len() {
            let (pos, tris) = match scene.place(k) {
                Ok(p) => p,
                Err(e) => return fail(&e),
            };
            (v, t, b) = (v + pos.len(), t + tris.len(), b.union(Aabb::of_points(&pos)));
        }
        (scene.parts.len(), v, t, b)
    };
    println!(
        "{parts} parts, {vertices} vertices, {triangles} triangles, box {:?} {:?}",
        bounds.min, bounds.max
    );
    std::process::ExitCode::SUCCESS
}
