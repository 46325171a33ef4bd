//! A hand-written SVG scatter plot of the trade: time (log scale) against error (log scale, with
//! a separate "0 (exact)" row at the bottom), one colour per input, one marker shape per option
//! family.

use super::BenchReport;
use std::fmt::Write;

const W: f64 = 960.0;
const H: f64 = 560.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 300.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 70.0;
/// Errors below this are drawn on the log axis' floor; exactly 0 gets its own row.
const ERR_MIN: f64 = 1e-6;

const COLOURS: [&str; 10] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22",
];

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn family(mode: &str) -> usize {
    if mode.starts_with("exact") {
        0
    } else if mode.contains("fast") {
        1
    } else if mode.contains("first-hit") {
        2
    } else if mode.starts_with("distance") {
        3
    } else {
        4
    }
}

const FAMILIES: [&str; 5] =
    ["exact (default)", "--mode fast", "--first-hit", "approximate distance", "BVH strategy / leaf size"];

fn marker(out: &mut String, fam: usize, x: f64, y: f64, colour: &str, title: &str) {
    let t = format!("<title>{}</title>", esc(title));
    let _ = match fam {
        0 => writeln!(
            out,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="6" fill="none" stroke="{colour}" stroke-width="2">{t}</circle>"#
        ),
        1 => writeln!(
            out,
            r#"<rect x="{:.1}" y="{:.1}" width="9" height="9" fill="{colour}">{t}</rect>"#,
            x - 4.5,
            y - 4.5
        ),
        2 => writeln!(
            out,
            r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="{colour}">{t}</polygon>"#,
            x,
            y - 6.0,
            x - 5.5,
            y + 4.0,
            x + 5.5,
            y + 4.0
        ),
        3 => writeln!(
            out,
            r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="{colour}">{t}</polygon>"#,
            x,
            y - 6.0,
            x + 6.0,
            y,
            x,
            y + 6.0,
            x - 6.0,
            y
        ),
        _ => writeln!(
            out,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="3" fill="{colour}" opacity="0.7">{t}</circle>"#
        ),
    };
}

/// The SVG document.
pub fn plot_svg(rep: &BenchReport) -> String {
    let pts: Vec<(usize, usize, f64, f64, String)> = rep
        .trade
        .iter()
        .enumerate()
        .flat_map(|(k, t)| {
            t.rows.iter().map(move |r| {
                (
                    k,
                    family(&r.mode),
                    (r.build_ms + r.query_ms).max(1e-3),
                    r.error_fraction,
                    format!("{}: {}", t.input, r.mode),
                )
            })
        })
        .collect();
    let (mut tmin, mut tmax) = (f64::INFINITY, 0.0f64);
    for p in &pts {
        tmin = tmin.min(p.2);
        tmax = tmax.max(p.2);
    }
    if pts.is_empty() {
        (tmin, tmax) = (1.0, 10.0);
    }
    let (lx0, lx1) = (tmin.log10().floor(), tmax.log10().ceil().max(tmin.log10().floor() + 1.0));
    let emax = pts.iter().map(|p| p.3).fold(ERR_MIN * 10.0, f64::max);
    let (ly0, ly1) = (ERR_MIN.log10(), emax.log10().ceil().max(0.0));
    let pw = W - LEFT - RIGHT;
    let ph = H - TOP - BOTTOM;
    let zero_y = TOP + ph + 25.0; // the "0 (exact)" row below the log axis
    let x_of = |t: f64| LEFT + (t.log10() - lx0) / (lx1 - lx0) * pw;
    let y_of = |e: f64| {
        if e <= 0.0 {
            zero_y
        } else {
            TOP + (1.0 - (e.max(ERR_MIN).log10() - ly0) / (ly1 - ly0)) * ph
        }
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{}" viewBox="0 0 {W} {}" font-family="sans-serif" font-size="12">"#,
        H + 20.0,
        H + 20.0
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{LEFT}" y="22" font-size="15">meshclash speed/accuracy trade: time against error (each option vs the exact default)</text>"#
    );
    // Axes and grid.
    let _ =
        writeln!(s, r##"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="none" stroke="#333"/>"##);
    let mut e = lx0;
    while e <= lx1 + 1e-9 {
        let x = LEFT + (e - lx0) / (lx1 - lx0) * pw;
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            TOP + ph,
            zero_y + 22.0,
            fmt_ms(10f64.powf(e))
        );
        e += 1.0;
    }
    let mut e = ly0;
    while e <= ly1 + 1e-9 {
        let y = TOP + (1.0 - (e - ly0) / (ly1 - ly0)) * ph;
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">1e{}</text>"##,
            LEFT + pw,
            LEFT - 6.0,
            y + 4.0,
            e as i32
        );
        e += 1.0;
    }
    let _ = writeln!(
        s,
        r##"<line x1="{LEFT}" y1="{zero_y:.1}" x2="{:.1}" y2="{zero_y:.1}" stroke="#999" stroke-dasharray="4 3"/><text x="{:.1}" y="{:.1}" text-anchor="end">0 (exact)</text>"##,
        LEFT + pw,
        LEFT - 6.0,
        zero_y + 4.0
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">total time, ms (build + query, log scale)</text>"#,
        LEFT + pw / 2.0,
        zero_y + 42.0
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate(18 {:.1}) rotate(-90)" text-anchor="middle">error: fraction of exact pairs wrong, or relative distance error</text>"#,
        TOP + ph / 2.0
    );
    for (k, fam, t, err, title) in &pts {
        marker(&mut s, *fam, x_of(*t), y_of(*err), COLOURS[k % COLOURS.len()], title);
    }
    // Legend.
    let lx = LEFT + pw + 20.0;
    let mut y = TOP + 10.0;
    for (k, t) in rep.trade.iter().enumerate() {
        let _ = writeln!(
            s,
            r#"<rect x="{lx}" y="{:.1}" width="10" height="10" fill="{}"/><text x="{:.1}" y="{:.1}">{}</text>"#,
            y - 9.0,
            COLOURS[k % COLOURS.len()],
            lx + 16.0,
            y,
            esc(&t.input)
        );
        y += 18.0;
    }
    y += 10.0;
    for (fam, name) in FAMILIES.iter().enumerate() {
        marker(&mut s, fam, lx + 5.0, y - 4.0, "#333", name);
        let _ = writeln!(s, r#"<text x="{:.1}" y="{y:.1}">{}</text>"#, lx + 16.0, esc(name));
        y += 18.0;
    }
    s.push_str("</svg>\n");
    s
}

fn fmt_ms(v: f64) -> String {
    if v >= 1000.0 {
        format!("{} s", v / 1000.0)
    } else if v >= 1.0 {
        format!("{v:.0} ms")
    } else {
        format!("{v} ms")
    }
}
