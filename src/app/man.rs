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

/// The man page (roff), generated from the clap definition, with the sections clap does not
/// know: EXIT STATUS and ENVIRONMENT.
pub fn man_page() -> String {
    let mut out = Vec::new();
    clap_mangen::Man::new(super::args::Args::command()).render(&mut out).expect("writing to a Vec");
    let mut page = String::from_utf8_lossy(&out).into_owned();
    page.push_str(EXTRA_SECTIONS);
    page
}

/// EXIT STATUS and ENVIRONMENT (roff).
const EXTRA_SECTIONS: &str = r#".SH "EXIT STATUS"
.TP
\fB0\fR
Nothing at or above \fB\-\-fail\-on\fR (with \fB\-\-fail\-on new\fR: nothing new against the baseline).
.TP
\fB1\fR
Findings at or above \fB\-\-fail\-on\fR; a failing \fB\-\-self\fR block; any failing check of a clash set; a merge with shards missing (\fB\-\-allow\-partial\fR).
.TP
\fB2\fR
Bad input (a missing, unreadable, malformed or hostile file), a usage error, a combination that cannot be answered exactly (refused), or an output that cannot be written. Nothing is written then.
.SH ENVIRONMENT
.TP
\fBNO_COLOR\fR
When set and not empty, no colour (as \fB\-\-color never\fR, unless \fB\-\-color always\fR).
.TP
\fBTERM\fR
\fBdumb\fR means no colour.
.TP
\fBJOB_COMPLETION_INDEX\fR, \fBAWS_BATCH_JOB_ARRAY_INDEX\fR, \fBCLOUD_RUN_TASK_INDEX\fR, \fBSLURM_ARRAY_TASK_ID\fR
The shard index of \fBmeshclash run\fR when \fB\-\-shard\fR is not given (0\-based; Slurm's counts from \fBSLURM_ARRAY_TASK_MIN\fR).
.TP
\fBAWS_BATCH_JOB_ARRAY_SIZE\fR, \fBCLOUD_RUN_TASK_COUNT\fR, \fBSLURM_ARRAY_TASK_COUNT\fR
The shard count of \fBmeshclash run\fR when neither \fB\-\-shard\fR nor \fB\-\-shards\fR is given.
"#;

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// Every subcommand clap knows is in `--help`, the man page and every completion script,
    /// with its own `meshclash help <cmd>` page (the list comes from the definition itself).
    #[test]
    fn every_subcommand_is_in_help_man_and_completions() {
        let mut cmd = super::super::args::Args::command();
        let names: Vec<String> =
            cmd.get_subcommands().map(|c| c.get_name().to_string()).filter(|n| n != "help").collect();
        for expected in ["scene", "clash-set", "self", "plan", "run", "merge"] {
            assert!(names.iter().any(|n| n == expected), "{expected} is not a subcommand: {names:?}");
        }
        let help = cmd.render_long_help().to_string();
        let man = super::man_page();
        assert!(man.contains(".SH \"EXIT STATUS\"") && man.contains(".SH ENVIRONMENT"));
        let scripts: Vec<String> =
            [clap_complete::Shell::Bash, clap_complete::Shell::Zsh, clap_complete::Shell::Fish]
                .into_iter()
                .map(super::completions)
                .collect();
        for n in &names {
            assert!(help.lines().any(|l| l.trim_start().starts_with(n.as_str())), "{n} missing from --help");
            assert!(
                man.contains(&format!("meshclash\\-{}(1)", n.replace('-', "\\-"))),
                "{n} missing from man"
            );
            for s in &scripts {
                assert!(s.contains(n.as_str()), "{n} missing from a completion script");
            }
            let sub = cmd.find_subcommand_mut(n).unwrap();
            assert!(!sub.render_long_help().to_string().is_empty());
        }
    }
}
