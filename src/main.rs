//! The `meshclash` binary: parse, run, print, exit. All logic is in the library.

use clap::Parser;
use meshclash::cli::{self, Args};
use meshclash::error::ExitCode as Code;
use meshclash::output::progress::{self, Spinner};
use meshclash::output::{text, Format};
use std::io::{IsTerminal, Write};
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) if e.use_stderr() => {
            // Usage errors: clap's whole message (the missing argument, the allowed values, the
            // "did you mean" tip), under the one prefix every error has; exit 2.
            let msg = e.to_string();
            eprintln!("meshclash: error: {}", msg.trim_start_matches("error: ").trim_end());
            return Code::Error.into();
        }
        Err(e) => {
            let _ = e.print(); // --help, --version
            return ExitCode::SUCCESS;
        }
    };
    if let Some(cli::Command::ClashSet(set)) = args.command {
        return clash_set(set);
    }
    if let Some(cli::Command::SelfCheck(s)) = args.command {
        return self_check(s);
    }
    if let Some(cmd) = &args.command {
        // `schema`, `completions <shell>`, `man`: generated text on stdout; `bench`: its tables.
        let text = match cmd {
            cli::Command::Output(c) => c.render(),
            cli::Command::ClashSet(_) | cli::Command::SelfCheck(_) => unreachable!("handled above"),
            cli::Command::Bench(b) => match meshclash::bench::run_command(b) {
                Ok(t) => t,
                Err(e) => {
                    eprintln!("meshclash: error: {e}");
                    return e.exit_code().into();
                }
            },
        };
        let mut so = std::io::stdout().lock();
        let _ = so.write_all(text.as_bytes()).and_then(|_| so.flush());
        return ExitCode::SUCCESS;
    }
    let quiet = args.quiet;
    let format = args.outputs.format;
    let (stdout_tty, stderr_tty) = (std::io::stdout().is_terminal(), std::io::stderr().is_terminal());
    let color = std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty());
    // Progress and the human summary only for a person at a terminal, never in pipes or CI logs.
    let spinner = (stderr_tty && !quiet)
        .then(|| Spinner::start(indicatif::ProgressDrawTarget::stderr(), progress::DEFAULT_DELAY));
    let on_phase = |p| {
        if let Some(s) = &spinner {
            s.phase(p);
        }
    };
    let outcome = args.into_config().and_then(|cfg| cli::run_with_progress(&cfg, &on_phase));
    if let Some(s) = spinner {
        s.finish();
    }
    match outcome {
        Ok(mut out) => {
            if !quiet {
                for w in &out.warnings {
                    eprintln!("meshclash: warning: {w}");
                }
            }
            let text_on_tty = format == Some(Format::Text) && stdout_tty;
            if stderr_tty && !quiet && !text_on_tty {
                eprint!("{}", text::render(&out.report, color));
            }
            if text_on_tty && color {
                out.stdout = Some(text::render(&out.report, true));
            }
            if let Some(json) = out.stdout {
                let mut so = std::io::stdout().lock();
                if let Err(e) = so.write_all(json.as_bytes()).and_then(|_| so.flush()) {
                    if e.kind() != std::io::ErrorKind::BrokenPipe {
                        eprintln!("meshclash: error: cannot write to stdout: {e}");
                        return Code::Error.into();
                    }
                }
            }
            out.exit_code.into()
        }
        Err(e) => {
            eprintln!("meshclash: error: {e}");
            e.exit_code().into()
        }
    }
}

/// `meshclash clash-set FILE`: like the main job, with one document for all checks.
fn clash_set(set: meshclash::clash_set::ClashSetArgs) -> ExitCode {
    use meshclash::clash_set;
    if let Some(kind) = set.schema {
        return print_stdout(&clash_set::schema_json(kind));
    }
    let quiet = set.quiet;
    let (stdout_tty, stderr_tty) = (std::io::stdout().is_terminal(), std::io::stderr().is_terminal());
    let spinner = (stderr_tty && !quiet)
        .then(|| Spinner::start(indicatif::ProgressDrawTarget::stderr(), progress::DEFAULT_DELAY));
    let on_phase = |p| {
        if let Some(s) = &spinner {
            s.phase(p);
        }
    };
    let outcome = clash_set::run_with_progress(&set, &on_phase);
    if let Some(s) = spinner {
        s.finish();
    }
    match outcome {
        Ok(out) => {
            if !quiet {
                for w in &out.warnings {
                    eprintln!("meshclash: warning: {w}");
                }
            }
            let text_on_tty = set.format == Some(clash_set::SetFormat::Text) && stdout_tty;
            if stderr_tty && !quiet && !text_on_tty {
                eprint!("{}", clash_set::summary(&out.report));
            }
            if let Some(text) = out.stdout {
                let code = print_stdout(&text);
                if code != ExitCode::SUCCESS {
                    return code;
                }
            }
            ExitCode::from(out.exit_code)
        }
        Err(e) => {
            eprintln!("meshclash: error: {e}");
            e.exit_code().into()
        }
    }
}

/// Write `text` to stdout; a closed pipe is not an error, any other failure is exit 2.
fn print_stdout(text: &str) -> ExitCode {
    let mut so = std::io::stdout().lock();
    match so.write_all(text.as_bytes()).and_then(|_| so.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            eprintln!("meshclash: error: cannot write to stdout: {e}");
            Code::Error.into()
        }
        _ => ExitCode::SUCCESS,
    }
}

/// `meshclash self FILE`: the report on stdout (or -o), the summary on stderr at a terminal.
fn self_check(args: meshclash::self_cmd::SelfArgs) -> ExitCode {
    let quiet = args.quiet;
    match meshclash::self_cmd::run(&args) {
        Ok(out) => {
            if !quiet {
                for w in &out.warnings {
                    eprintln!("meshclash: warning: {w}");
                }
                let text_on_stdout = args.format == Some(meshclash::self_cmd::SelfFormat::Text);
                if std::io::stderr().is_terminal() && !text_on_stdout {
                    eprint!("{}", out.summary);
                }
            }
            match out.stdout.map(|s| print_stdout(&s)) {
                Some(code) if code != ExitCode::SUCCESS => code,
                _ => ExitCode::from(out.exit_code),
            }
        }
        Err(e) => {
            eprintln!("meshclash: error: {e}");
            e.exit_code().into()
        }
    }
}
