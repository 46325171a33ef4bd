//! The `meshclash clash-set` output document (`meshclash.clash-set/1`): one report per named
//! check, each exactly the report of the equivalent command line.

use super::{Report, Tool};
use serde::{Deserialize, Serialize};

/// The schema identifier of the clash-set output document.
pub const SCHEMA: &str = "meshclash.clash-set/1";

/// The output document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ClashSetReport {
    /// Always [`SCHEMA`].
    pub schema: String,
    /// Who wrote it.
    pub tool: Tool,
    /// The clash-set file as given.
    pub file: String,
    /// True if any check failed its `fail_on` (the process exits 1).
    pub failed: bool,
    /// One entry per check, in file order.
    pub checks: Vec<CheckReport>,
}

/// One check's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CheckReport {
    /// The check's name.
    pub name: String,
    /// Its report, exactly as the equivalent `meshclash` command line writes it.
    pub report: Report,
}
