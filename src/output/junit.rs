//! JUnit XML for CI test-report viewers: one `<testsuite>` named `meshclash` with one
//! `<testcase>` per checked pair of inputs (today the one file pair A × B; [`render`] takes any
//! list so part pairs can be added), with a `<failure>` when that case fails the run, whose
//! message gives the counts and the first findings.

use crate::report::{Report, ReportPairKind, ReportVerdict};
use std::fmt::Write;

/// How many findings a failure lists.
pub const FIRST: usize = 10;

/// One test case: a checked pair of inputs (or, later, of parts).
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Test case name, e.g. `a.obj vs b.obj`.
    pub name: String,
    /// Its verdict (`clash`, `touching`, `clearance`, `clear`).
    pub verdict: String,
    /// One line of counts, e.g. `192 crossing, 0 touching, 0 clearance pairs`.
    pub counts: String,
    /// The first findings, one line each (the failure lists the first [`FIRST`]).
    pub findings: Vec<String>,
    /// Total number of findings (may exceed `findings.len()`).
    pub total: u64,
    /// Does this case fail the run?
    pub failed: bool,
    /// Seconds taken (0 when unknown).
    pub time_s: f64,
    /// Text for `<system-out>` (may be empty).
    pub output: String,
}

/// Escape text for XML content and attribute values. Characters XML 1.0 cannot carry at all
/// (control characters other than tab, newline and carriage return) become U+FFFD.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(ch),
            c if (c as u32) < 0x20 || c == '\u{fffe}' || c == '\u{ffff}' => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

/// Render the suite.
pub fn render(suite: &str, cases: &[Case]) -> String {
    let failures = cases.iter().filter(|c| c.failed).count();
    let time: f64 = cases.iter().map(|c| c.time_s).sum();
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        s,
        "<testsuites name=\"{n}\" tests=\"{t}\" failures=\"{failures}\" errors=\"0\" time=\"{time}\">",
        n = escape(suite),
        t = cases.len()
    );
    let _ = writeln!(
        s,
        "  <testsuite name=\"{n}\" tests=\"{t}\" failures=\"{failures}\" errors=\"0\" skipped=\"0\" time=\"{time}\">",
        n = escape(suite),
        t = cases.len()
    );
    for c in cases {
        let _ = writeln!(
            s,
            "    <testcase classname=\"{}\" name=\"{}\" time=\"{}\">",
            escape(suite),
            escape(&c.name),
            c.time_s
        );
        if c.failed {
            let first: Vec<&str> = c.findings.iter().take(FIRST).map(String::as_str).collect();
            let mut message = format!("{}: {}", c.verdict, c.counts);
            if !first.is_empty() {
                let _ = write!(message, "; first: {}", first[0]);
            }
            let mut body = first.join("\n");
            if c.total > first.len() as u64 {
                let _ = write!(body, "\n... and {} more", c.total - first.len() as u64);
            }
            let _ = writeln!(
                s,
                "      <failure message=\"{}\" type=\"{}\">{}</failure>",
                escape(&message),
                escape(&c.verdict),
                escape(&body)
            );
        }
        if !c.output.is_empty() {
            let _ = writeln!(s, "      <system-out>{}</system-out>", escape(&c.output));
        }
        s.push_str("    </testcase>\n");
    }
    s.push_str("  </testsuite>\n</testsuites>\n");
    s
}

/// The cases of a report: the whole run (the two inputs), then one per part pair with a finding.
pub fn cases(r: &Report) -> Vec<Case> {
    let m = &r.summary;
    let mut counts = format!(
        "{} crossing, {} touching, {} clearance pairs",
        m.crossing_pairs, m.touching_pairs, m.clearance_pairs
    );
    if let Some(c) = &m.contained {
        let _ = write!(counts, ", contained: {c}");
    }
    if let Some(b) = &r.baseline {
        let _ = write!(
            counts,
            "; baseline: {} new ({} new crossing), {} persistent, {} resolved",
            b.new, b.new_crossing, b.persistent, b.resolved
        );
    }
    let worst = super::text::worst(r);
    let mut cases = vec![Case {
        name: format!("{} vs {}", r.inputs.a.path, r.inputs.b.path),
        verdict: r.verdict.name().into(),
        counts,
        findings: worst.iter().take(FIRST).map(|p| super::text::pair_line(r, p)).collect(),
        total: m.crossing_pairs + m.touching_pairs + m.clearance_pairs,
        failed: r.failed,
        time_s: r.timings_ms.as_ref().map_or(0.0, |t| t.total / 1e3),
        output: super::text::render(r, false),
    }];
    // A partial merge never passes: say which shards are missing, as a failure of its own.
    if !r.missing_shards.is_empty() {
        let names = r.missing_shards.join(", ");
        cases.push(Case {
            name: "merge: every shard present".into(),
            verdict: "incomplete".into(),
            counts: format!("missing shard{} {names}", if r.missing_shards.len() > 1 { "s" } else { "" }),
            findings: vec![format!(
                "the missing shards were not checked: their part pairs may clash (merge shards {names} too)"
            )],
            total: r.missing_shards.len() as u64,
            failed: true,
            time_s: 0.0,
            output: String::new(),
        });
    }
    // Two single-part inputs: the part pair is the whole run; say it once.
    if r.assembly.mode == "parts" || r.parts.len() > 2 {
        cases.extend(part_pair_cases(r));
    }
    if let Some(x) = &r.self_check {
        cases.extend(scene_junit_cases(x));
    }
    cases
}

/// One case per part pair with a finding (assemblies), after the whole-run case, so CI
/// dashboards show which parts clash with which.
fn part_pair_cases(r: &Report) -> Vec<Case> {
    let fails = |verdict: ReportVerdict, new_crossing: bool| -> bool {
        match r.settings.fail_on.as_str() {
            "never" => false,
            "new" => new_crossing,
            level => crate::report::verdict_from_name(level).is_some_and(|l| verdict.verdict() >= l),
        }
    };
    r.part_pairs
        .iter()
        .map(|pp| {
            let (pa, pb) = (&r.parts[pp.a], &r.parts[pp.b]);
            let mine: Vec<&crate::report::PairReport> = r
                .pairs
                .iter()
                .filter(|p| {
                    let objs = (p.a_object, p.b_object);
                    objs == (pa.object, pb.object) || objs == (pb.object, pa.object)
                })
                .collect();
            let new_crossing =
                mine.iter().any(|p| p.kind == ReportPairKind::Crossing && p.status.as_deref() == Some("new"));
            let mut counts = format!(
                "{} crossing, {} touching, {} clearance pairs",
                pp.crossing_pairs, pp.touching_pairs, pp.clearance_pairs
            );
            if let Some(c) = &pp.contained {
                let _ = write!(counts, ", contained: {c}");
            }
            Case {
                name: format!("{} vs {}", pp.a_name, pp.b_name),
                verdict: pp.verdict.name().into(),
                counts,
                findings: mine.iter().take(FIRST).map(|p| super::text::pair_line(r, p)).collect(),
                total: pp.crossing_pairs + pp.touching_pairs + pp.clearance_pairs,
                failed: fails(pp.verdict, new_crossing),
                time_s: 0.0,
                output: String::new(),
            }
        })
        .collect()
}

/// The JUnit XML of a report.
pub fn from_report(r: &Report) -> String {
    render("meshclash", &cases(r))
}

/// JUnit cases of the `self` block: one per part with a finding (a self-clash pair or any
/// health finding), named `<part> (self)`, failed when the part meets a `fail_on` condition.
pub fn scene_junit_cases(x: &crate::report::self_report::SceneSelfReport) -> Vec<Case> {
    use crate::report::self_report::{part_problems, SelfFailOn};
    use crate::report::ReportContact;
    let fail_on: Vec<SelfFailOn> = x.fail_on.iter().filter_map(|n| SelfFailOn::from_name(n)).collect();
    x.parts
        .iter()
        .filter_map(|p| {
            let problems = part_problems(p.crossing_pairs, p.touching_pairs, &p.health);
            if problems.is_empty() {
                return None;
            }
            let mut findings: Vec<String> = x
                .pairs
                .iter()
                .filter(|q| q.a_object == p.object)
                .take(FIRST)
                .map(|q| {
                    format!(
                        "triangles {} × {}: {} ({})",
                        q.a,
                        q.b,
                        q.kind,
                        q.contact.map_or("-", ReportContact::name)
                    )
                })
                .collect();
            let h = &p.health;
            let mut health_kinds = 0; // one line per kind of health finding
            for (what, f) in [
                ("boundary edges", &h.boundary_edges),
                ("non-manifold edges", &h.non_manifold_edges),
                ("non-manifold vertices", &h.non_manifold_vertices),
                ("duplicate faces", &h.duplicate_faces),
                ("zero-area triangles", &h.zero_area_triangles),
                ("inconsistent winding edges", &h.inconsistent_winding_edges),
            ] {
                if f.count > 0 {
                    health_kinds += 1;
                    findings.push(format!("{} {what}, first triangles {:?}", f.count, f.triangles));
                }
            }
            let verdict = if p.crossing_pairs > 0 {
                "clash"
            } else if p.touching_pairs > 0 {
                "touching"
            } else {
                "clear"
            };
            Some(Case {
                name: format!("{} (self)", p.name),
                verdict: verdict.into(),
                counts: format!(
                    "{} crossing, {} touching self-clash pairs; {}",
                    p.crossing_pairs,
                    p.touching_pairs,
                    if h.closed { "closed" } else { "open" }
                ),
                total: p.crossing_pairs + p.touching_pairs + health_kinds,
                findings,
                failed: fail_on.iter().any(|f| f.met(p.crossing_pairs, p.touching_pairs, &p.health)),
                time_s: 0.0,
                output: String::new(),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_covers_markup_quotes_and_control_characters() {
        assert_eq!(escape("a<b>&\"c'\u{1}\td"), "a&lt;b&gt;&amp;&quot;c&apos;\u{fffd}\td");
    }

    #[test]
    fn failures_are_counted_and_listed() {
        let case = |name: &str, failed| Case {
            name: name.into(),
            verdict: if failed { "clash" } else { "clear" }.into(),
            counts: "1 crossing".into(),
            findings: vec!["crossing A#1 x B#2".into()],
            total: 3,
            failed,
            time_s: 0.5,
            output: String::new(),
        };
        let x = render("s<1>", &[case("p1", true), case("p2 & p3", false)]);
        assert!(x.contains("tests=\"2\" failures=\"1\""), "{x}");
        assert_eq!(x.matches("<failure").count(), 1);
        assert!(x.contains("... and 2 more"));
        assert!(x.contains("name=\"p2 &amp; p3\""));
        assert!(x.contains("name=\"s&lt;1&gt;\""));
    }
}
