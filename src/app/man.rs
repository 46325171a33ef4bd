//! The text subcommands generated from definitions: `schema` (the report's JSON Schema),
//! `completions <shell>` and `man` (from the clap definition).

use super::args::TextCommand;
use clap::CommandFactory;

/// What a text subcommand prints.
pub fn render(c: &TextCommand) -> String {
    match c {
        TextCommand::Schema => meshclash::output::schema_json(),
        TextCommand::Completions { shell } => completions(*shell),
        TextCommand::Man => man_page(),
    }
}

/// A completion script for `shell`, generated from the clap definition.
pub fn completions(shell: clap_complete::Shell) -> String {
    let mut cmd = super::args::Args::command();
    let mut out = Vec::new();
    clap_complete::generate(shell, &mut cmd, "meshclash", &mut out);
    String::from_utf8_lossy(&out).into_owned()
}

/// The man page (roff), generated from the clap definition.
pub fn man_page() -> String {
    let mut out = Vec::new();
    clap_mangen::Man::new(super::args::Args::command()).render(&mut out).expect("writing to a Vec");
    String::from_utf8_lossy(&out).into_owned()
}
