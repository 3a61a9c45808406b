//! The stress suite's accuracy targets, checked against the rows of a run, and the Markdown
//! tables of `docs/stability.md`.

use crate::precision::Precision;
use crate::record::{Growth, Row};
use std::fmt::Write as _;

/// Whether a target was met.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Every row it covers meets it.
    Met,
    /// Some row misses it.
    Missed,
    /// The run has no row for it.
    NotRun,
}

/// One target and its outcome.
#[derive(Clone, Debug)]
pub struct Target {
    /// What is required.
    pub name: String,
    /// The outcome.
    pub status: Status,
    /// The measured figure(s).
    pub detail: String,
    /// Kinds (see [`kind`]) of the rows it covers.
    pub covers: Vec<Kind>,
}

/// Every target of a run.
pub struct Summary {
    /// In the order.
    pub targets: Vec<Target>,
}

impl Summary {
    /// No target missed (those not run do not count).
    pub fn all_met(&self) -> bool {
        self.targets.iter().all(|t| t.status != Status::Missed)
    }

    /// One line per target.
    pub fn text(&self) -> String {
        let mut out = String::new();
        for t in &self.targets {
            let _ = writeln!(
                out,
                "  [{}] {}: {}",
                status_word(t.status),
                t.name,
                t.detail
            );
        }
        out
    }
}

fn status_word(s: Status) -> &'static str {
    match s {
        Status::Met => "met",
        Status::Missed => "MISSED",
        Status::NotRun => "not run",
    }
}

/// What a row is summarised under: its test, for the round trips (whose variants have
/// different targets and tolerances) the variant too, and its precision.
type Kind = (String, Precision);

fn kind(r: &Row) -> Kind {
    let name = if r.test == "roundtrip" {
        format!("roundtrip {}", r.variant)
    } else {
        r.test.clone()
    };
    (name, r.precision)
}

/// Distinct kinds of `rows`, in the order their names first appear, each name's `f64`
/// kind before its `f32` kind.
fn kinds_of(rows: &[&Row]) -> Vec<Kind> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        let (name, _) = kind(r);
        if !names.contains(&name) {
            names.push(name);
        }
    }
    let mut kinds = Vec::new();
    for name in names {
        for p in Precision::ALL {
            let k = (name.clone(), p);
            if rows.iter().any(|r| kind(r) == k) {
                kinds.push(k);
            }
        }
    }
    kinds
}

/// Worst value of `field` over `rows`, with the row it came from.
fn worst<'a>(rows: &[&'a Row], field: fn(&Row) -> f64) -> Option<(f64, &'a Row)> {
    rows.iter().fold(None, |acc: Option<(f64, &Row)>, r| {
        let v = field(r);
        match acc {
            Some((w, _)) if !(v > w || v.is_nan()) => acc,
            _ => Some((v, r)),
        }
    })
}

/// A bound on the worst `field` of the rows `select` picks.
fn bound(
    rows: &[Row],
    name: &str,
    select: impl Fn(&Row) -> bool,
    field: fn(&Row) -> f64,
    limit: f64,
) -> Target {
    let picked: Vec<&Row> = rows.iter().filter(|r| select(r)).collect();
    let (status, detail) = match worst(&picked, field) {
        None => (Status::NotRun, "no rows".to_string()),
        Some((v, r)) => {
            let bs: Vec<usize> = picked.iter().map(|r| r.b).collect();
            let range = format!(
                "B = {}..{}",
                bs.iter().min().unwrap(),
                bs.iter().max().unwrap()
            );
            let status = if v <= limit {
                Status::Met
            } else {
                Status::Missed
            };
            (
                status,
                format!(
                    "worst {v:.2e} ({} B = {}; {} rows, {range})",
                    r.variant,
                    r.b,
                    picked.len()
                ),
            )
        }
    };
    Target {
        name: name.into(),
        status,
        detail,
        covers: kinds_of(&picked),
    }
}

/// A condition on the notes of the rows `select` picks.
fn every_note(
    rows: &[Row],
    name: &str,
    select: impl Fn(&Row) -> bool,
    ok: impl Fn(&str) -> bool,
) -> Target {
    let picked: Vec<&Row> = rows.iter().filter(|r| select(r)).collect();
    let bad: Vec<String> = picked
        .iter()
        .filter(|r| !ok(&r.note))
        .map(|r| format!("{} {} B={}: {}", r.test, r.variant, r.b, r.note))
        .collect();
    let (status, detail) = if picked.is_empty() {
        (Status::NotRun, "no rows".to_string())
    } else if bad.is_empty() {
        (Status::Met, format!("all {} rows", picked.len()))
    } else {
        (Status::Missed, bad.join("; "))
    };
    Target {
        name: name.into(),
        status,
        detail,
        covers: kinds_of(&picked),
    }
}

fn rel(r: &Row) -> f64 {
    r.rel_l2
}

fn max_abs(r: &Row) -> f64 {
    r.max_abs
}

/// Whether a `scale-2^k` row's exponent keeps every value of its transforms in the normal
/// range of its precision (see docs/stability.md): the target covers these; the others are
/// reported only.
fn scale_in_range(r: &Row) -> bool {
    r.test
        .strip_prefix("scale-2^")
        .and_then(|k| k.parse::<i32>().ok())
        .is_some_and(|k| r.precision.scale_in_range(k))
}

/// The exponents a precision's scaling target covers, as the target names them.
fn scale_target_exponents(p: Precision) -> String {
    let ks = p.scale_exponents();
    let covered: Vec<i32> = ks.into_iter().filter(|&k| p.scale_in_range(k)).collect();
    let mut parts: Vec<String> = Vec::new();
    for &k in &covered {
        if k < 0 && covered.contains(&-k) {
            continue;
        }
        if k > 0 && covered.contains(&-k) {
            parts.push(format!("+-{k}"));
        } else {
            parts.push(k.to_string());
        }
    }
    parts.join(", ")
}

/// The f32 round trips' bound on the relative L2 error, up to B = 512.
pub const F32_ROUND_TRIP: f64 = 1e-5;

/// Checks the targets against the rows (`big`: the run included the f64 full-grid round
/// trip at B = 512; `big_f32`: the f32 ones).
pub fn evaluate(rows: &[Row], big: bool, big_f32: bool) -> Summary {
    let f64_rows = |r: &Row| r.precision == Precision::F64;
    let f32_rows = |r: &Row| r.precision == Precision::F32;
    let full = |r: &Row| r.test == "roundtrip" && (r.variant == "complex" || r.variant == "real");
    let so3 = |r: &Row| f64_rows(r) && full(r);
    let partial = |b: usize| {
        move |r: &Row| {
            f64_rows(r) && r.test == "roundtrip" && r.variant.starts_with("partial-m8") && r.b == b
        }
    };
    let s2 = |r: &Row| {
        f64_rows(r) && r.test == "roundtrip" && r.variant.starts_with("s2-") && r.b == 2048
    };
    let every = |test: &'static str| move |r: &Row| r.test == test;
    let mut targets = vec![
        bound(
            rows,
            "SO(3) round trip rel L2 <= 1e-14 (complex, real)",
            so3,
            rel,
            1e-14,
        ),
        bound(
            rows,
            "SO(3) round trip max abs <= 3e-13 at B = 512",
            |r: &Row| so3(r) && r.b == 512,
            max_abs,
            3e-13,
        ),
        bound(
            rows,
            "order-limited B = 1024 rel L2 <= 5e-14",
            partial(1024),
            rel,
            5e-14,
        ),
        bound(
            rows,
            "order-limited B = 2048 rel L2 <= 1e-13",
            partial(2048),
            rel,
            1e-13,
        ),
        bound(rows, "S^2 B = 2048 rel L2 <= 1e-12", s2, rel, 1e-12),
        bound(
            rows,
            "f32 round trip rel L2 <= 1e-5 up to B = 512 (SO(3) complex, real, order-limited; S^2)",
            |r: &Row| f32_rows(r) && r.test == "roundtrip" && r.b <= 512,
            rel,
            F32_ROUND_TRIP,
        ),
        bound(
            rows,
            "f32 SO(3) round trip rel L2 <= 1e-5 at B = 512 (complex, real)",
            |r: &Row| f32_rows(r) && full(r) && r.b == 512,
            rel,
            F32_ROUND_TRIP,
        ),
        every_note(
            rows,
            &format!(
                "scaling by 2^k bit-exact (f64: k = {}; f32: k = {})",
                scale_target_exponents(Precision::F64),
                scale_target_exponents(Precision::F32)
            ),
            scale_in_range,
            |n| n == "bit-exact",
        ),
        every_note(
            rows,
            "NaN / Inf inputs: a result, no hang, no error",
            every("nan-inf"),
            |n| !n.starts_with("HANG") && !n.starts_with("error"),
        ),
        every_note(
            rows,
            "subnormal inputs: finite results",
            every("subnormal"),
            |n| n.ends_with("; finite"),
        ),
        every_note(
            rows,
            "determinism: bit-identical on 1, 2, 4 threads and repeats",
            every("determinism"),
            |n| n.starts_with("bit-identical"),
        ),
        every_note(
            rows,
            "f32 matching: the grid peak is f64's, or a tie within f32 rounding",
            |r: &Row| f32_rows(r) && r.test == "matching" && r.variant != "match-refined",
            |n| n.contains("peak = f64's") || n.contains("peak: a tie"),
        ),
    ];
    if !big {
        targets[1].detail = "needs --big (B = 512 full grid, about 24 GB)".into();
    }
    if !big_f32 {
        targets[6].detail = "needs --big (B = 512 full grid in f32, about 12 GB)".into();
    }
    Summary { targets }
}

fn fmt_value(v: f64) -> String {
    if v.is_nan() {
        "-".into()
    } else {
        format!("{v:.2e}")
    }
}

/// The Markdown of the targets, the growth exponents and a summary per test; the rows
/// themselves are in stability.csv.
pub fn markdown(rows: &[Row], growths: &[Growth], summary: &Summary) -> String {
    let mut out =
        String::from("### Accuracy targets\n\n| target | status | measured |\n|---|---|---|\n");
    for t in &summary.targets {
        let _ = writeln!(
            out,
            "| {} | {} | {} |",
            t.name,
            status_word(t.status),
            t.detail
        );
    }
    out.push_str("\n### Growth of the error with the bandwidth\n\n");
    out.push_str(
        "Least-squares slope of log(error) against log(B): error ~ C B^p; r^2 of the relative \
         error's fit (well below 1: no power law).\n\n",
    );
    out.push_str(
        "| test | variant | precision | p (rel L2) | r^2 | p (max abs) | bandwidths |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let show = |e: Option<f64>| e.map_or("-".to_string(), |v| format!("{v:.2}"));
    for g in growths {
        let bs: Vec<String> = g.bandwidths.iter().map(|b| b.to_string()).collect();
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} |",
            g.test,
            g.variant,
            g.precision,
            show(g.rel_exponent),
            show(g.rel_r2),
            show(g.max_exponent),
            bs.join(", ")
        );
    }
    out.push_str("\n### Summary per test\n\n");
    out.push_str(
        "Worst errors over each test's rows (round trips: each variant's) per precision, with \
         the variant and B where they occur (\"-\" where the rows carry no such error: bit checks, NaN \
         counts), and the accuracy targets that cover them. Every row (test, B, variant, \
         precision, errors, time, note) is in [stability.csv](stability.csv).\n\n",
    );
    out.push_str(
        "| test | precision | rows | variants | B | worst rel L2 | worst max abs | targets |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for k in kind_summaries(rows, summary) {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            k.kind.0,
            k.kind.1,
            k.rows,
            k.variants,
            k.bandwidths,
            k.worst_rel,
            k.worst_max,
            k.targets
        );
    }
    out
}

/// One line of the per-test summary, formatted.
struct KindSummary {
    kind: Kind,
    rows: usize,
    variants: usize,
    /// `lo..hi`, or the one bandwidth.
    bandwidths: String,
    worst_rel: String,
    worst_max: String,
    /// `met: name; MISSED: name`, or `-`.
    targets: String,
}

/// Per kind, in the order the kinds first appear.
fn kind_summaries(rows: &[Row], summary: &Summary) -> Vec<KindSummary> {
    let all: Vec<&Row> = rows.iter().collect();
    kinds_of(&all)
        .into_iter()
        .map(|kind_name| {
            let mine: Vec<&Row> = rows.iter().filter(|r| kind(r) == kind_name).collect();
            let mut variants: Vec<&str> = mine.iter().map(|r| r.variant.as_str()).collect();
            variants.sort_unstable();
            variants.dedup();
            let lo = mine.iter().map(|r| r.b).min().unwrap_or(0);
            let hi = mine.iter().map(|r| r.b).max().unwrap_or(0);
            let bandwidths = if lo == hi {
                lo.to_string()
            } else {
                format!("{lo}..{hi}")
            };
            let worst_of = |field: fn(&Row) -> f64| {
                let with_values: Vec<&Row> = mine
                    .iter()
                    .copied()
                    .filter(|r| !field(r).is_nan())
                    .collect();
                worst(&with_values, field).map_or("-".to_string(), |(v, r)| {
                    format!("{} ({} B = {})", fmt_value(v), r.variant, r.b)
                })
            };
            let targets: Vec<String> = summary
                .targets
                .iter()
                .filter(|t| t.covers.contains(&kind_name))
                .map(|t| format!("{}: {}", status_word(t.status), t.name))
                .collect();
            KindSummary {
                rows: mine.len(),
                variants: variants.len(),
                bandwidths,
                worst_rel: worst_of(rel),
                worst_max: worst_of(max_abs),
                targets: if targets.is_empty() {
                    "-".into()
                } else {
                    targets.join("; ")
                },
                kind: kind_name,
            }
        })
        .collect()
}

/// Marker lines of the generated part of docs/stability.md.
pub const BEGIN: &str = "<!-- stress-tables:begin (generated by so3fft-stress --docs docs) -->";
/// End marker.
pub const END: &str = "<!-- stress-tables:end -->";

/// `old` with the text between the markers replaced by `tables`.
pub fn splice(old: &str, tables: &str) -> Result<String, String> {
    let start = old
        .find(BEGIN)
        .ok_or("stability.md: begin marker missing")?;
    let end = old.find(END).ok_or("stability.md: end marker missing")?;
    if end < start {
        return Err("stability.md: markers out of order".into());
    }
    Ok(format!(
        "{}{BEGIN}\n\n{tables}\n{}",
        &old[..start],
        &old[end..]
    ))
}
