//! The `meshclash-bench` binary: parse, run, print. Without a subcommand it runs the phase
//! tables of the library ([`meshclash_bench::run_command`], what `meshclash bench` used to be);
//! `gen DIR` writes the benchmark inputs and `cases DIR` times them.

use clap::Parser;
use meshclash_bench::cases::{self, CasesArgs, GenArgs};
use meshclash_bench::self_case::{self, SelfCaseArgs};
use meshclash_bench::BenchArgs;
use std::io::Write;
use std::process::ExitCode;

/// Time meshclash against parry3d (f32 and f64) on generated and given meshes, compare their
/// answers, and (--trade) tabulate every speed/accuracy option against the exact default.
#[derive(Debug, Parser)]
#[command(name = "meshclash-bench", version, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    phases: BenchArgs,
}

#[derive(Debug, clap::Subcommand)]
enum Command {
    /// Write the benchmark inputs (spheres, tori, engine grids) into a directory.
    Gen(GenArgs),
    /// Time the benchmark cases in a directory written by `gen`: meshclash against parry3d f64
    /// and f32, phase by phase, with same-run ratios.
    Cases(CasesArgs),
    /// Self-clash and mesh health on a generated folded torus (1M triangles) and on
    /// given files, phase by phase.
    #[command(name = "self")]
    SelfCase(SelfCaseArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) if e.use_stderr() => {
            let msg = e.to_string();
            let first = msg.lines().next().unwrap_or("bad arguments");
            eprintln!("meshclash-bench: {} (see --help)", first.trim_start_matches("error: ").trim());
            return ExitCode::from(2);
        }
        Err(e) => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
    };
    let out = match &cli.command {
        None => meshclash_bench::run_command(&cli.phases),
        Some(Command::Gen(g)) => cases::generate(g),
        Some(Command::Cases(c)) => cases::run_cases(c),
        Some(Command::SelfCase(c)) => self_case::run_self_case(c),
    };
    match out {
        Ok(text) => {
            let mut so = std::io::stdout().lock();
            let _ = so.write_all(text.as_bytes()).and_then(|_| so.flush());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("meshclash-bench: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
