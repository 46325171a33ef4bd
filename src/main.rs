//! The `meshclash` binary: parse, run, print, exit. All logic is in the library.

use clap::Parser;
use meshclash::cli::{self, Args};
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) if e.use_stderr() => {
            // Usage errors: one line, exit 2, like every other error.
            let msg = e.to_string();
            let first = msg.lines().next().unwrap_or("bad arguments");
            eprintln!("meshclash: {} (see --help)", first.trim_start_matches("error: ").trim());
            return ExitCode::from(2);
        }
        Err(e) => {
            let _ = e.print(); // --help, --version
            return ExitCode::SUCCESS;
        }
    };
    let quiet = args.quiet;
    let outcome = args.into_config().and_then(|cfg| cli::run(&cfg));
    match outcome {
        Ok(out) => {
            if !quiet {
                for w in &out.warnings {
                    eprintln!("meshclash: warning: {w}");
                }
            }
            if let Some(json) = out.stdout {
                let mut so = std::io::stdout().lock();
                if let Err(e) = so.write_all(json.as_bytes()).and_then(|_| so.flush()) {
                    if e.kind() != std::io::ErrorKind::BrokenPipe {
                        eprintln!("meshclash: error: cannot write to stdout: {e}");
                        return ExitCode::from(2);
                    }
                }
            }
            ExitCode::from(out.exit_code)
        }
        Err(e) => {
            eprintln!("meshclash: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
