//! `documentation/index.html` of a model, and the texts the Markdown model pages ([`crate::docs`])
//! share with it: the interfaces sentence, the variable sections, admissible values and the expansion
//! of cited `[key]`s into full references from the catalogue's bibliography.

use std::fmt::Write as _;

use spacecraft_fmus::catalogue::{
    BoundDescription, Catalogue, Causality, LayerInfo, ModelDescription, ReferenceDescription, VariableDescription,
};

use crate::clocks::clock_vr;

use crate::xml::{start_str, variability_str, GENERATION_TOOL};

/// The variable tables of a model's documentation (HTML page and Markdown model pages), in order.
pub(crate) const VARIABLE_SECTIONS: [(&str, Causality); 5] = [
    ("Parameters", Causality::Parameter),
    ("Inputs", Causality::Input),
    ("Outputs", Causality::Output),
    ("Calculated parameters", Causality::CalculatedParameter),
    ("Local variables", Causality::Local),
];

pub(crate) fn bound_text(b: &BoundDescription) -> String {
    match b {
        BoundDescription::Any => String::new(),
        BoundDescription::Positive => "> 0".into(),
        BoundDescription::NonNegative => ">= 0".into(),
        BoundDescription::Limit => ">= 0 (1e30 = no limit)".into(),
        BoundDescription::Range(lo, hi) => format!("[{lo}, {hi}]"),
        BoundDescription::Choice(codes) => format!("one of {codes:?}"),
    }
}

pub(crate) fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The start value as the tables show it (none where the description writes none).
/// The cells of a variable's row in the documentation tables (the HTML page and the Markdown model pages):
/// name, value reference, type, variability, start, unit, admissible values and meaning, the last three
/// passed through the table's `escape`.
pub(crate) fn variable_cells(d: &VariableDescription, escape: fn(&str) -> String) -> [String; 8] {
    [
        d.name.clone(),
        d.vr.to_string(),
        format!("{:?}", d.kind),
        variability_str(d.variability).to_string(),
        start_text(d),
        escape(&d.unit),
        escape(&bound_text(&d.bound)),
        escape(&d.description),
    ]
}

pub(crate) fn start_text(d: &VariableDescription) -> String {
    if d.has_start() {
        start_str(d.start)
    } else {
        String::new()
    }
}

/// The references of the catalogue whose `[key]` occurs in any of `texts`, in bibliography order.
pub fn cited_in<'c>(cat: &'c Catalogue, texts: &[&str]) -> Vec<&'c ReferenceDescription> {
    cat.references
        .iter()
        .filter(|r| {
            let tag = format!("[{}]", r.key);
            texts.iter().any(|t| t.contains(&tag))
        })
        .collect()
}

/// "authors, “title”, venue." in plain text; unknown authors or venue (empty) are said to be unknown.
pub fn citation(r: &ReferenceDescription) -> String {
    let title = if r.title.is_empty() {
        format!("A work on {} (title not recorded)", r.subject)
    } else {
        format!("\u{201c}{}\u{201d}", r.title)
    };
    match (r.authors.is_empty(), r.venue.is_empty()) {
        (false, false) => format!("{}, {title}, {}.", r.authors, r.venue),
        (false, true) => format!("{}, {title} (venue not recorded).", r.authors),
        (true, false) => format!("{title}, {} (authors not recorded).", r.venue),
        (true, true) => format!("{title} (authors and venue not recorded)."),
    }
}

/// Which FMI interfaces a model offers, in one sentence (model pages and documentation/index.html), and
/// for a model with clocks a second one on its clocked FMI 3.0 interfaces.
pub fn interfaces_text(m: &ModelDescription) -> String {
    let text = interfaces_sentence(m);
    if m.clocks.is_empty() {
        return text;
    }
    format!(
        "{text} In FMI 3.0 it also offers clocked Co-Simulation (Event Mode) and Scheduled Execution, with {} (see Clocks).",
        match m.clocks.len() {
            1 => "one input clock".to_string(),
            n => format!("{n} input clocks"),
        }
    )
}

/// The clocks section of the documentation: what the clocks are, before their table.
pub(crate) const CLOCKS_TEXT: &str = concat!(
    "FMI 3.0 only (FMI 2.0 runs the unit sampled inside its step). Each clock is a time-based periodic ",
    "input clock (intervalVariability fixed): it ticks at the start time plus the shift, then once per ",
    "interval, both read from the named parameters (fmi3GetIntervalDecimal and fmi3GetShiftDecimal in ",
    "Initialization Mode; no shift: 0). At a tick, with the inputs the unit holds then, the clock's ",
    "partition computes its outputs from the state before the tick and holds them until the clock's next ",
    "tick; then, where the table says so, the state advances over one interval. A lower clock index runs ",
    "first when two clocks tick together (its priority in Scheduled Execution). In the FMI 3.0 ",
    "description the outputs a clock computes are discrete clocked variables (the variable tables give ",
    "their FMI 2.0 variability).",
);

/// The header of the clock table, and [`clock_cells`] of each row.
pub(crate) const CLOCK_HEADER: [&str; 6] = ["name", "vr", "interval", "shift", "partition", "meaning"];

/// The cells of clock `i`'s row: name, value reference, interval and shift parameters, what its partition
/// does, and meaning (the last two passed through the table's `escape`).
pub(crate) fn clock_cells(
    m: &ModelDescription,
    layer: &LayerInfo,
    i: usize,
    escape: fn(&str) -> String,
) -> [String; 6] {
    let c = &m.clocks[i];
    let outputs = match c.outputs.len() {
        0 => None,
        _ => Some(format!("computes {}", c.outputs.join(", "))),
    };
    let step = c.steps.then(|| "advances the state one interval".to_string());
    let partition = [outputs, step]
        .into_iter()
        .flatten()
        .collect::<Vec<_>>()
        .join("; then ");
    [
        c.name.clone(),
        clock_vr(layer, i).to_string(),
        c.interval.clone(),
        if c.shift.is_empty() {
            "none".into()
        } else {
            c.shift.clone()
        },
        escape(&partition),
        escape(&c.description),
    ]
}

fn interfaces_sentence(m: &ModelDescription) -> String {
    match &m.states {
        Some(states) if states.is_empty() => {
            "FMI 2.0 and FMI 3.0 Model Exchange (a static law: no continuous state) and Co-Simulation.".into()
        }
        Some(states) => format!(
            "FMI 2.0 and FMI 3.0 Model Exchange ({} continuous states: {}) and Co-Simulation.",
            states.len(),
            states.iter().map(|x| x.name.as_str()).collect::<Vec<_>>().join(", ")
        ),
        None if !m.variable_step => "FMI 2.0 and FMI 3.0 Co-Simulation only: a sampled law (its behaviour is defined at its sample times, not as a continuous right-hand side).".into(),
        None => "FMI 2.0 and FMI 3.0 Co-Simulation only: its internal state evolves in discrete steps (not as a continuous right-hand side).".into(),
    }
}

const STYLE: &str = "<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.4}table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:left;vertical-align:top}pre{background:#f4f4f4;padding:0.5em;overflow-x:auto}code{background:#f4f4f4}</style>\n";

const CONVENTIONS: &str = concat!(
    "\n<h2>Conventions</h2>\n<ul><li>SI units on every port; degrees only where the name ends in <code>_deg</code>.</li>",
    "<li>Quaternions are scalar-first Hamilton quaternions (q_w, q_x, q_y, q_z) of the body frame relative to the reference frame; A(q) maps reference components into body components.</li>",
    "<li>Parameters are read at fmi2ExitInitializationMode; invalid values give fmi2Error with a log message.</li>",
    "<li>\"No limit\" is encoded as 1e30.</li></ul>\n",
);

/// The FMI 3.0 terminals of a model, as a table (nothing for a model without terminals).
fn terminals_table(h: &mut String, m: &ModelDescription) {
    if !m.terminals.is_empty() {
        h.push_str("<h2>Terminals (FMI 3.0)</h2>\n<p>In <code>terminalsAndIcons/terminalsAndIcons.xml</code> of the FMI 3.0 archive; every member is a signal.</p>\n<table>\n<tr><th>terminal</th><th>kind</th><th>matching</th><th>members (member = variable)</th><th>meaning</th></tr>\n");
        for t in &m.terminals {
            let members: Vec<String> = t
                .members
                .iter()
                .map(|(a, b)| {
                    if a == b {
                        format!("<code>{a}</code>")
                    } else {
                        format!("<code>{a}</code> = <code>{b}</code>")
                    }
                })
                .collect();
            let _ = writeln!(
                *h,
                "<tr><td><code>{}</code></td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td></tr>",
                t.name,
                t.kind,
                t.matching_rule,
                members.join(", "),
                html_escape(&t.description)
            );
        }
        h.push_str("</table>\n");
    }
}

/// The FMI 3.0 clocks of a sampled model, as a table (nothing for a model without clocks).
fn clocks_table(h: &mut String, cat: &Catalogue, m: &ModelDescription) {
    if !m.clocks.is_empty() {
        let _ = writeln!(*h, "<h2>Clocks</h2>\n<p>{}</p>\n<table>", html_escape(CLOCKS_TEXT));
        let _ = writeln!(*h, "<tr><th>{}</th></tr>", CLOCK_HEADER.join("</th><th>"));
        for i in 0..m.clocks.len() {
            let [name, rest @ ..] = clock_cells(m, &cat.layer, i, html_escape);
            let _ = writeln!(
                *h,
                "<tr><td><code>{name}</code></td><td>{}</td></tr>",
                rest.join("</td><td>")
            );
        }
        h.push_str("</table>\n");
    }
}

/// documentation/index.html: purpose, source, equations, conventions, variable tables, references.
pub fn documentation_html(cat: &Catalogue, m: &ModelDescription) -> String {
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    let _ = writeln!(h, "<title>{}</title>", m.name);
    h.push_str(STYLE);
    h.push_str("</head>\n<body>\n");
    let _ = writeln!(h, "<h1>{}</h1>\n<p>{}</p>", m.name, html_escape(&m.description));
    let _ = writeln!(h, "<p><b>Source:</b> {}</p>", html_escape(&m.source));
    let _ = writeln!(
        h,
        "<p><b>GUID:</b> <code>{}</code> &middot; <b>Generated by:</b> {}</p>",
        m.guid, GENERATION_TOOL
    );
    let _ = writeln!(h, "<p><b>Interfaces:</b> {}</p>", html_escape(&interfaces_text(m)));
    h.push_str("<h2>Equations</h2>\n");
    h.push_str(&m.equations_html);
    h.push_str(CONVENTIONS);
    for (title, caus) in VARIABLE_SECTIONS {
        let rows: Vec<&VariableDescription> = m.variables.iter().filter(|d| d.causality == caus).collect();
        if rows.is_empty() {
            continue;
        }
        let _ = writeln!(h, "<h2>{title}</h2>\n<table>\n<tr><th>name</th><th>vr</th><th>type</th><th>variability</th><th>start</th><th>unit</th><th>admissible</th><th>meaning</th></tr>");
        for d in rows {
            let [name, rest @ ..] = variable_cells(d, html_escape);
            let _ = writeln!(
                h,
                "<tr><td><code>{name}</code></td><td>{}</td></tr>",
                rest.join("</td><td>")
            );
        }
        h.push_str("</table>\n");
    }
    terminals_table(&mut h, m);
    clocks_table(&mut h, cat, m);
    let cited = cited_in(cat, &m.texts());
    if !cited.is_empty() {
        h.push_str("<h2>References</h2>\n<ul>\n");
        for r in cited {
            let _ = writeln!(h, "<li><b>[{}]</b> {}</li>", r.key, html_escape(&citation(r)));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("</body>\n</html>\n");
    h
}
