//! The FMI 3.0 clocks of a sampled model, as the packager writes and checks them (FMI 2.0 has none: its
//! description of a clocked model is the same as without clocks).
//!
//! Each [`ClockDescription`] of the catalogue is one time-based periodic input clock: a `<Clock>`
//! variable at value reference `clock_vr_base + i` with `causality="input"`, `variability="discrete"`
//! (the only variability a clock may have), `intervalVariability="fixed"` and `priority="i"` (Scheduled
//! Execution runs a lower index first when two clocks tick together). It has no `intervalDecimal`: the
//! interval and the shift are parameters of the model, so the importer reads them with
//! `fmi3GetIntervalDecimal` / `fmi3GetShiftDecimal` in Initialization Mode, as the standard prescribes for a
//! fixed clock without `intervalDecimal`.
//!
//! The outputs a clock computes at its ticks are its clocked variables: `clocks="<vr>"`,
//! `variability="discrete"` (a clocked variable is discrete or tunable), and in `<ModelStructure>` their
//! `<Output>` dependencies include the clock (the standard asks for a clocked variable's dependency on its
//! clock to be listed). They are not `<InitialUnknown>`s: the standard lists there the outputs that are
//! not clocked and only those clocked variables an FMU chooses to initialize in Initialization Mode, and
//! these take their values at their clock's ticks (as the Reference FMUs' clocked outputs; fmpy's
//! validation also expects it).

use spacecraft_fmus::catalogue::{Causality, LayerInfo, ModelDescription, VarKind, Variability};

use crate::xml::{empty, W};

/// Value reference of clock `i` of a model.
pub fn clock_vr(layer: &LayerInfo, i: usize) -> u32 {
    layer.clock_vr_base + i as u32
}

/// Index of the clock whose partition computes output `name` (`None`: not clocked).
pub fn clock_of(m: &ModelDescription, name: &str) -> Option<usize> {
    m.clocks.iter().position(|c| c.outputs.iter().any(|o| o == name))
}

/// The `<Clock>` elements of a model, in clock order (none for a model without clocks).
pub(crate) fn write_clocks(w: &mut W, m: &ModelDescription, layer: &LayerInfo) {
    for (i, c) in m.clocks.iter().enumerate() {
        let attrs = [
            ("name", c.name.clone()),
            ("valueReference", clock_vr(layer, i).to_string()),
            ("description", c.description.clone()),
            ("causality", "input".into()),
            ("variability", "discrete".into()),
            ("priority", i.to_string()),
            ("intervalVariability", "fixed".into()),
        ];
        empty(w, "Clock", &attrs);
    }
}

/// A Real parameter with `variability="fixed"` of `m` named `p` (an interval or a shift).
fn fixed_real_parameter(m: &ModelDescription, clock: &str, role: &str, p: &str) -> Result<(), String> {
    match m.decl(p) {
        Some(d)
            if d.causality == Causality::Parameter
                && d.kind == VarKind::Real
                && d.variability == Variability::Fixed =>
        {
            Ok(())
        }
        Some(_) => Err(format!(
            "{}: the {role} of clock {clock} is {p}, which is not a fixed Real parameter",
            m.name
        )),
        None => Err(format!(
            "{}: the {role} of clock {clock} is {p}, which the model does not declare",
            m.name
        )),
    }
}

/// The clocks of a model: unique names that clash with no variable, a description, an interval (and a
/// shift, when given) that are fixed Real parameters, a partition that does something, outputs that
/// are declared outputs, each clocked by one clock only, and value references clear of the other
/// variables of the layer.
pub fn check_clocks(m: &ModelDescription, layer: &LayerInfo) -> Result<(), String> {
    let name = &m.name;
    // half-open ranges of value references: the clocks', the states', the derivatives', time's
    let n = m.clocks.len() as u64;
    let ns = m.state_decls().len() as u64;
    let clocks = (layer.clock_vr_base as u64, layer.clock_vr_base as u64 + n);
    let from = |vr: u32, len: u64| (vr as u64, vr as u64 + len);
    let meets = |(a, b): (u64, u64), (c, d): (u64, u64)| a < d && c < b;
    if n > 0
        && (clocks.1 > u32::MAX as u64 + 1
            || clocks.0 < layer.reserved_vr_start as u64
            || meets(clocks, from(layer.state_vr_base, ns))
            || meets(clocks, from(layer.derivative_vr_base, ns))
            || meets(clocks, from(layer.time_vr, 1)))
    {
        return Err(format!(
            "{name}: the value references of its {n} clocks from {} on clash with the layer's other variables",
            clocks.0
        ));
    }
    for (i, c) in m.clocks.iter().enumerate() {
        let clock = &c.name;
        let states = m.state_decls();
        if c.name.is_empty()
            || m.decl(clock).is_some()
            || states
                .iter()
                .any(|x| x.name == *clock || format!("der({})", x.name) == *clock)
            || m.clocks[i + 1..].iter().any(|o| o.name == *clock)
            || clock == "time"
        {
            return Err(format!("{name}: clock {clock:?} clashes with another variable name"));
        }
        if c.description.is_empty() {
            return Err(format!("{name}: clock {clock} has no description"));
        }
        fixed_real_parameter(m, clock, "interval", &c.interval)?;
        if !c.shift.is_empty() {
            fixed_real_parameter(m, clock, "shift", &c.shift)?;
        }
        if !c.steps && c.outputs.is_empty() {
            return Err(format!(
                "{name}: clock {clock} neither advances the state nor computes an output"
            ));
        }
        for o in &c.outputs {
            match m.decl(o) {
                Some(d) if d.causality == Causality::Output => {}
                _ => return Err(format!("{name}: clock {clock} clocks {o}, which is not an output")),
            }
            if clock_of(m, o) != Some(i) || c.outputs.iter().filter(|x| *x == o).count() > 1 {
                return Err(format!("{name}: output {o} is clocked twice"));
            }
        }
    }
    Ok(())
}
