//! The `meshclash` binary: parse, run, print, exit. The app layer (clap definitions, validation
//! into a `Config`, running it, the `clash-set` and `self` runners, the spinner) is [`app`]; the
//! checks, reports and outputs are in the library.

mod app;

use app::args as cli;
use app::{clash_set, progress, run, self_cmd};
use meshclash::error::ExitCode as Code;
use meshclash::output::text;
use meshclash::output::write;
use progress::Spinner;
use std::io::IsTerminal;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Help wraps to the terminal's width, or to 100 columns when stdout is not a terminal.
    let width = (!std::io::stdout().is_terminal()).then_some(100);
    let args = match cli::parse(width) {
        Ok(a) => a,
        Err(e) if e.use_stderr() => {
            // Usage errors: clap's whole message (the missing argument, the allowed values, the
            // "did you mean" tip), under the one prefix every error has; exit 2.
            let msg = e.to_string();
            eprintln!("meshclash: error: {}", msg.trim_start_matches("error: ").trim_end());
            return Code::Error.into();
        }
        Err(e) => {
            // --help, --version: to stdout, and a stdout that cannot take them is an error.
            let text = if std::io::stdout().is_terminal() {
                e.render().ansi().to_string()
            } else {
                e.render().to_string()
            };
            return print_stdout(&text);
        }
    };
    if let Some(cli::Command::ClashSet(set)) = args.command {
        return run_clash_set(set);
    }
    if let Some(cli::Command::SelfCheck(s)) = args.command {
        return self_check(s);
    }
    if let Some(cmd @ (cli::Command::Plan(_) | cli::Command::Run(_) | cli::Command::Merge(_))) = args.command
    {
        return ExitCode::from(app::shard::dispatch(cmd));
    }
    if let Some(cmd) = args.command.as_ref().filter(|c| !matches!(c, cli::Command::Scene(_))) {
        // `schema`, `completions <shell>`, `man`: generated text on stdout; `bench`: forwarded.
        let text = match cmd {
            cli::Command::Output(c) => app::man::render(c),
            cli::Command::ClashSet(_)
            | cli::Command::SelfCheck(_)
            | cli::Command::Scene(_)
            | cli::Command::Plan(_)
            | cli::Command::Run(_)
            | cli::Command::Merge(_) => {
                unreachable!("handled above")
            }
            cli::Command::Bench(b) => return bench_forward(&b.args),
        };
        return print_stdout(&text);
    }
    let flags = match &args.command {
        Some(cli::Command::Scene(s)) => &s.check,
        _ => &args.check,
    };
    let (quiet, color) = (flags.quiet, flags.color);
    let (stdout_tty, stderr_tty) = (std::io::stdout().is_terminal(), std::io::stderr().is_terminal());
    // A person at a terminal with no -o and no --format gets the text summary; a program (a
    // pipe, a file) gets the JSON report.
    let config = args.into_config().map(|mut cfg| {
        if stdout_tty && cfg.outputs.format.is_none() && cfg.output.is_none() {
            cfg.outputs.format = Some(meshclash::output::Format::Text);
        }
        cfg
    });
    let text_out = config.as_ref().is_ok_and(|c| c.outputs.format == Some(meshclash::output::Format::Text));
    // Progress and the human summary only for a person at a terminal, never in pipes or CI logs.
    let spinner = (stderr_tty && !quiet)
        .then(|| Spinner::start(indicatif::ProgressDrawTarget::stderr(), progress::DEFAULT_DELAY));
    let on_phase = |p| {
        if let Some(s) = &spinner {
            s.phase(p);
        }
    };
    let outcome = config.and_then(|cfg| run::run_with_progress(&cfg, &on_phase));
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
            let text_on_tty = text_out && stdout_tty;
            if stderr_tty && !quiet && !text_on_tty {
                eprint!("{}", text::render(&out.report, color.enabled(true)));
            }
            if text_out && color.enabled(stdout_tty) {
                out.stdout = Some(text::render(&out.report, true));
            }
            if let Err(e) = out.write_stdout() {
                // All or nothing: the staged files are dropped unwritten.
                eprintln!("meshclash: error: cannot write to stdout: {e}");
                return Code::Error.into();
            }
            if let Err(e) = out.staged.commit() {
                eprintln!("meshclash: error: {e}");
                return e.exit_code().into();
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
fn run_clash_set(set: clash_set::ClashSetArgs) -> ExitCode {
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
    match write::to_stdout(|w| w.write_all(text.as_bytes())) {
        Err(e) => {
            eprintln!("meshclash: error: cannot write to stdout: {e}");
            Code::Error.into()
        }
        Ok(_) => ExitCode::SUCCESS,
    }
}

/// `meshclash self FILE`: the report on stdout (or -o), the summary on stderr at a terminal.
fn self_check(args: self_cmd::SelfArgs) -> ExitCode {
    let quiet = args.quiet;
    match self_cmd::run(&args) {
        Ok(out) => {
            if !quiet {
                for w in &out.warnings {
                    eprintln!("meshclash: warning: {w}");
                }
                let text_on_stdout = args.format == Some(self_cmd::SelfFormat::Text);
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

/// `meshclash bench ARGS`: the harness is the `meshclash-bench` binary of the workspace member
/// `bench/` (so a default build does not compile parry3d f32). Run it with ARGS when it sits
/// next to this executable, else say how to run it (exit 2).
fn bench_forward(args: &[std::ffi::OsString]) -> ExitCode {
    let name = format!("meshclash-bench{}", std::env::consts::EXE_SUFFIX);
    let sibling = std::env::current_exe().ok().and_then(|p| Some(p.parent()?.join(&name)));
    let Some(exe) = sibling.filter(|p| p.is_file()) else {
        eprintln!(
            "meshclash: error: `meshclash bench` is now the meshclash-bench binary: run \
             `cargo run --release -p meshclash-bench -- ARGS` in the source tree"
        );
        return ExitCode::from(2);
    };
    match std::process::Command::new(&exe).args(args).status() {
        Ok(s) => ExitCode::from(s.code().map_or(2, |c| u8::try_from(c).unwrap_or(2))),
        Err(e) => {
            eprintln!("meshclash: error: cannot run {}: {e}", exe.display());
            ExitCode::from(2)
        }
    }
}
