//! The human summary: what a person at a terminal (or reading a CI log) wants first. Verdict and
//! whether the run failed, the two inputs, counts, the closest points, containment, the worst
//! findings, the baseline comparison, timings and warnings. ANSI colours only when asked for.

use crate::report::{PairReport, Report, ReportContact, ReportContainment, ReportPairKind, ReportVerdict};
use std::fmt::Write;

/// How many findings the summary lists.
pub const WORST: usize = 5;

const RESET: &str = "\x1b[0m";
const BOLD: &str = "\x1b[1m";
const DIM: &str = "\x1b[2m";
const RED: &str = "\x1b[1;31m";
const ORANGE: &str = "\x1b[33m";
const YELLOW: &str = "\x1b[93m";
const GREEN: &str = "\x1b[1;32m";

struct Paint(bool);

impl Paint {
    fn p(&self, style: &str, s: &str) -> String {
        if self.0 {
            format!("{style}{s}{RESET}")
        } else {
            s.to_string()
        }
    }
}

/// A number with 6 significant digits, without trailing zeros (`%g` style).
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let e = x.abs().log10().floor() as i32;
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if !(-4..6).contains(&e) {
        let s = format!("{x:.5e}");
        let (m, exp) = s.split_once('e').expect("exponent");
        format!("{}e{exp}", trim(m.to_string()))
    } else {
        trim(format!("{:.*}", (5 - e).max(0) as usize, x))
    }
}

fn point(p: &[f64; 3]) -> String {
    format!("({}, {}, {})", num(p[0]), num(p[1]), num(p[2]))
}

fn severity(p: &PairReport) -> (u8, f64) {
    let rank = match (p.kind, p.contact) {
        (ReportPairKind::Crossing, _) => 0,
        (ReportPairKind::Touching, Some(ReportContact::WithinTolerance)) => 2,
        (ReportPairKind::Touching, _) => 1,
        (ReportPairKind::Clearance, _) => 3,
    };
    (rank, p.distance)
}

/// The listed pairs, worst first: crossing, exact touching, within tolerance, clearance, and
/// within one kind by distance, then (a, b).
pub fn worst(r: &Report) -> Vec<&PairReport> {
    let mut v: Vec<&PairReport> = r.pairs.iter().collect();
    v.sort_by(|x, y| {
        let (kx, dx) = severity(x);
        let (ky, dy) = severity(y);
        kx.cmp(&ky).then(dx.total_cmp(&dy)).then((x.a, x.b).cmp(&(y.a, y.b)))
    });
    v
}

fn object(r: &Report, side: char, i: u32) -> std::borrow::Cow<'_, str> {
    let objs = if side == 'a' { &r.inputs.a.objects } else { &r.inputs.b.objects };
    objs.get(i as usize).map_or("?".into(), |o| shown(&o.name))
}

/// A name or path as the summary prints it: control characters (escape sequences that could
/// move the cursor or rewrite the verdict line) and the invisible bidirectional controls
/// written as Rust escapes (`\u{1b}`), everything else as is.
pub fn shown(s: &str) -> std::borrow::Cow<'_, str> {
    let bad = |c: char| c.is_control() || matches!(c, '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}');
    if !s.chars().any(bad) {
        return s.into();
    }
    s.chars()
        .map(|c| if bad(c) { c.escape_unicode().to_string() } else { c.to_string() })
        .collect::<String>()
        .into()
}

/// One line describing a pair: kind, triangles with their objects, contact, where.
pub fn pair_line(r: &Report, p: &PairReport) -> String {
    let mut s = format!(
        "{} A#{} ({}) x B#{} ({})",
        p.kind,
        p.a,
        object(r, 'a', p.a_object),
        p.b,
        object(r, 'b', p.b_object)
    );
    if let Some(c) = &p.contact {
        let _ = write!(s, " {c}");
    }
    if p.distance > 0.0 {
        let _ = write!(s, " d={}", num(p.distance));
    }
    if let Some([x, y]) = &p.segment {
        if x == y {
            let _ = write!(s, " at {}", point(x));
        } else {
            let _ = write!(s, " {} - {}", point(x), point(y));
        }
    }
    if let Some(st) = &p.status {
        let _ = write!(s, " [{st}]");
    }
    s
}

/// A length with the report's unit (`12.5 mm`), or bare in model units.
fn with_units(r: &Report, x: f64) -> String {
    match r.settings.units.as_str() {
        "model" => num(x),
        u => format!("{} {u}", num(x)),
    }
}

/// `units: mm (A: m given, x1000; B: mm assumed)`, when units or a scale were given.
fn units_line(r: &Report) -> Option<String> {
    let (ua, ub) = (r.inputs.a.units.as_ref(), r.inputs.b.units.as_ref());
    if ua.is_none() && ub.is_none() {
        return None;
    }
    let side = |name: &str, u: Option<&crate::report::InputUnitsReport>| {
        let Some(u) = u else { return format!("{name}: as given") };
        let mut t = format!("{name}:");
        if let (Some(unit), Some(src)) = (&u.units, &u.source) {
            let _ = write!(t, " {unit} {src}");
        }
        if u.scale != 1.0 {
            let _ = write!(t, " scale {}", num(u.scale));
        }
        if u.multiplier != 1.0 {
            let _ = write!(t, ", x{}", num(u.multiplier));
        }
        if t.len() == name.len() + 1 {
            t.push_str(" as given");
        }
        t
    };
    Some(format!("units: {} ({}; {})", r.settings.units, side("A", ua), side("B", ub)))
}

/// What containment means, for a person.
fn containment_text(c: ReportContainment) -> &'static str {
    match c {
        ReportContainment::AInB => "A lies inside B",
        ReportContainment::BInA => "B lies inside A",
        ReportContainment::APartlyInB => "part of A lies inside B",
        ReportContainment::BPartlyInA => "part of B lies inside A",
        ReportContainment::VolumesOverlap => {
            "the closed parts' volumes overlap (faces in contact enclose shared volume)"
        }
        ReportContainment::Undecided => "undecided",
    }
}

/// Why there is no closest pair.
fn closest_none(r: &Report) -> &'static str {
    if r.settings.first_hit {
        "  closest: not computed (--first-hit)\n"
    } else if r.assembly.mode == "parts" && r.assembly.candidate_part_pairs == 0 {
        "  closest: none (no candidate part pairs: no two selected parts come within the search margin)\n"
    } else {
        "  closest: none (an input has no triangles)\n"
    }
}

/// How many clashing part pairs the summary names.
pub const WORST_PART_PAIRS: usize = 5;

/// The part pairs with a clash (crossing or containment), when the inputs have more than one
/// part on a side: their count and the worst few by name (most crossing pairs first, then
/// containment, then by index).
fn part_pairs(s: &mut String, c: &Paint, r: &Report) {
    let multi = r.inputs.a.objects.len() > 1 || r.inputs.b.objects.len() > 1 || r.assembly.mode == "parts";
    let mut clashing: Vec<&crate::report::PartPairReport> =
        r.part_pairs.iter().filter(|p| p.verdict == ReportVerdict::Clash).collect();
    if !multi {
        // One part each: the exact overlap box on its own line.
        if let Some(o) = clashing.first().and_then(|p| p.overlap.as_ref()) {
            let _ = writeln!(s, "  {}, from {} to {}", overlap_text(&o.extent), point(&o.min), point(&o.max));
        }
        return;
    }
    if clashing.is_empty() {
        return;
    }
    clashing.sort_by(|x, y| y.crossing_pairs.cmp(&x.crossing_pairs).then((x.a, x.b).cmp(&(y.a, y.b))));
    let _ = writeln!(
        s,
        "  {} clashing part pair{}{}:",
        c.p(RED, &clashing.len().to_string()),
        if clashing.len() == 1 { "" } else { "s" },
        if clashing.len() > WORST_PART_PAIRS {
            format!(" (worst {WORST_PART_PAIRS})")
        } else {
            String::new()
        }
    );
    for p in clashing.iter().take(WORST_PART_PAIRS) {
        let mut what = format!("{} crossing", p.crossing_pairs);
        if let Some(ct) = p.contained {
            let _ = write!(what, ", {}", ct.name());
        }
        if let Some(o) = &p.overlap {
            let _ = write!(what, ", {}", overlap_text(&o.extent));
        }
        let _ = writeln!(s, "    {} x {}  ({what})", shown(&p.a_name), shown(&p.b_name));
    }
}

/// "overlap 1.5 × 0.6 × 0.6": the extent of an exact overlap box.
pub fn overlap_text(extent: &[f64; 3]) -> String {
    format!("overlap {} \u{d7} {} \u{d7} {}", num(extent[0]), num(extent[1]), num(extent[2]))
}

/// The summary, several lines ending in a newline; coloured with ANSI escapes if `color`.
pub fn render(r: &Report, color: bool) -> String {
    let c = Paint(color);
    let mut s = String::new();
    let verdict_style = match r.verdict {
        ReportVerdict::Clash => RED,
        ReportVerdict::Touching => ORANGE,
        ReportVerdict::Clearance => YELLOW,
        ReportVerdict::Clear => GREEN,
    };
    let outcome = if r.failed {
        c.p(RED, &format!("FAILED (--fail-on {})", r.settings.fail_on))
    } else {
        c.p(GREEN, &format!("passed (--fail-on {})", r.settings.fail_on))
    };
    let _ = writeln!(s, "meshclash: {}  {}", c.p(verdict_style, &r.verdict.name().to_uppercase()), outcome);
    for (name, i) in [("A", &r.inputs.a), ("B", &r.inputs.b)] {
        let _ = writeln!(
            s,
            "  {} {}  {}, {} triangles, {} object{}{}",
            c.p(BOLD, name),
            shown(&i.path),
            i.format,
            i.triangles,
            i.objects.len(),
            if i.objects.len() == 1 { "" } else { "s" },
            match i.closed {
                Some(true) => ", closed",
                Some(false) => ", open",
                None => "",
            }
        );
    }
    if let Some(line) = units_line(r) {
        let _ = writeln!(s, "  {line}");
    }
    let m = &r.summary;
    let _ = writeln!(
        s,
        "  {}{} crossing, {} touching ({} within tolerance), {} clearance pairs{}",
        if r.settings.first_hit { "at least " } else { "" },
        c.p(if m.crossing_pairs > 0 { RED } else { BOLD }, &m.crossing_pairs.to_string()),
        c.p(if m.touching_pairs > 0 { ORANGE } else { BOLD }, &m.touching_pairs.to_string()),
        m.within_tolerance_pairs,
        c.p(if m.clearance_pairs > 0 { YELLOW } else { BOLD }, &m.clearance_pairs.to_string()),
        if r.settings.first_hit {
            " (--first-hit: counts are lower bounds, the search stopped at the first crossing pair)"
                .to_string()
        } else if r.pairs_truncated {
            format!(" ({} listed)", r.pairs.len())
        } else {
            String::new()
        }
    );
    match &r.closest {
        Some(cl) => {
            let _ = writeln!(
                s,
                "  closest: {} between A#{} ({}) at {} and B#{} ({}) at {}",
                c.p(BOLD, &with_units(r, cl.distance)),
                cl.a.triangle,
                object(r, 'a', cl.a.object),
                point(&cl.a.point),
                cl.b.triangle,
                object(r, 'b', cl.b.object),
                point(&cl.b.point)
            );
        }
        None => s.push_str(closest_none(r)),
    }
    if let Some(ct) = m.contained {
        let why = m.contained_reason.as_deref().map(|w| format!(": {w}")).unwrap_or_default();
        let style = if ct.is_clash() { RED } else { YELLOW };
        let _ = writeln!(s, "  containment: {}{why}", c.p(style, containment_text(ct)));
    }
    part_pairs(&mut s, &c, r);
    let worst = worst(r);
    if !worst.is_empty() {
        let total = m.crossing_pairs + m.touching_pairs + m.clearance_pairs;
        let _ = writeln!(s, "  worst findings ({} of {total}):", worst.len().min(WORST));
        for p in worst.iter().take(WORST) {
            let style = match p.kind {
                ReportPairKind::Crossing => RED,
                ReportPairKind::Touching => ORANGE,
                ReportPairKind::Clearance => YELLOW,
            };
            let line = pair_line(r, p);
            let (kind, rest) = line.split_at(p.kind.name().len());
            let _ = writeln!(s, "    {}{rest}", c.p(style, kind));
        }
    }
    if let Some(x) = &r.self_check {
        s.push_str(&crate::report::self_report::scene_text(x));
    }
    if let Some(b) = &r.baseline {
        let _ = writeln!(
            s,
            "  baseline {}: {} new ({} new crossing{}), {} persistent, {} resolved{}",
            b.path,
            c.p(if b.new > 0 { RED } else { BOLD }, &b.new.to_string()),
            b.new_crossing,
            if b.new_containment { ", new containment" } else { "" },
            b.persistent,
            c.p(GREEN, &b.resolved.to_string()),
            if b.complete { "" } else { " (baseline list truncated)" }
        );
    }
    if let Some(x) = &r.cross_check {
        let _ = writeln!(
            s,
            "  cross-check {}: verdict {}, {} pairs only meshclash, {} only parry",
            x.tool,
            if x.verdict_agrees { "agrees" } else { "DISAGREES" },
            x.only_meshclash_count,
            x.only_parry_count
        );
    }
    if let Some(t) = &r.timings_ms {
        let _ = writeln!(
            s,
            "  {}",
            c.p(
                DIM,
                &format!(
                    "timings: load {} ms, build {} ms, query {} ms, total {} ms",
                    num(t.load),
                    num(t.build),
                    num(t.query),
                    num(t.total)
                )
            )
        );
    }
    if !r.warnings.is_empty() {
        let _ = writeln!(s, "  {} warning{}", r.warnings.len(), if r.warnings.len() == 1 { "" } else { "s" });
    }
    s
}

#[cfg(test)]
mod tests {
    use super::{num, shown};

    #[test]
    fn names_with_control_characters_are_escaped() {
        assert_eq!(shown("bolt M8 / ü"), "bolt M8 / ü");
        assert_eq!(shown("a\u{1b}[1A\rCLEAR\u{7}"), "a\\u{1b}[1A\\u{d}CLEAR\\u{7}");
        assert_eq!(shown("x\u{202E}y\n"), "x\\u{202e}y\\u{a}");
        let all: String = (0u32..0x3000).filter_map(char::from_u32).collect();
        assert!(!shown(&all).chars().any(|c| c.is_control()));
    }

    #[test]
    fn numbers_have_six_significant_digits() {
        assert_eq!(num(0.0), "0");
        assert_eq!(num(1.0), "1");
        assert_eq!(num(0.1 + 0.2), "0.3");
        assert_eq!(num(1750.9), "1750.9");
        assert_eq!(num(-123456.7), "-123457");
        assert_eq!(num(1234567.0), "1.23457e6");
        assert_eq!(num(0.0000123), "1.23e-5");
        assert_eq!(num(0.054326312), "0.0543263");
    }
}
