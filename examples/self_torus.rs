//! Write a generated torus as OBJ for timing `meshclash self` on a large surface:
//! `cargo run --release --example self_torus -- N FILE [--fold]` (N ≈ triangle count; with
//! `--fold`, one vertex is pulled through the tube so the surface crosses itself).

use meshclash::check::self_clash::gen::folded_torus;
use meshclash::testing::gen::{to_obj, torus};

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(n), Some(path)) = (args.first().and_then(|n| n.parse::<usize>().ok()), args.get(1)) else {
        eprintln!("usage: self_torus N FILE [--fold]");
        return std::process::ExitCode::from(2);
    };
    let m = if args.iter().any(|a| a == "--fold") { folded_torus(n) } else { torus(n) };
    if let Err(e) = std::fs::write(path, to_obj(&m)) {
        eprintln!("self_torus: {path}: {e}");
        return std::process::ExitCode::from(2);
    }
    std::process::ExitCode::SUCCESS
}
