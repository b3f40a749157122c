//! Checks of a catalogue that the type system cannot make, run before anything is written: unique
//! names and value references (clear of the ones the FMI layer reserves, as the catalogue's
//! [`LayerInfo`] states them), known units, descriptions, start values inside their bounds, continuous
//! states and clocks that clash with nothing, feed-through names that are outputs and inputs, and
//! citations of publications the library declares.

use spacecraft_fmus::catalogue::{
    cited_keys, BoundDescription, Catalogue, Causality, FeedthroughDescription, LayerInfo, ModelDescription, Start,
    VarKind, VariableDescription,
};
use spacecraft_fmus::units;

use crate::names;
use crate::structure::input_index;

/// Every model of the catalogue passes [`check_model`], and cites only declared references.
pub fn check_catalogue(cat: &Catalogue) -> Result<(), String> {
    for m in &cat.models {
        check_model(m, &cat.layer)?;
        for text in m.texts() {
            for key in cited_keys(text) {
                if !cat.references.iter().any(|r| r.key == key) {
                    let known: Vec<&str> = cat.references.iter().map(|r| r.key.as_str()).collect();
                    return Err(format!(
                        "{}: cites [{key}], which the library does not declare (declared: {known:?}; pass your references to export_fmus!)",
                        m.name
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The declarations of one model.
pub fn check_model(m: &ModelDescription, layer: &LayerInfo) -> Result<(), String> {
    let name = &m.name;
    for (i, a) in m.variables.iter().enumerate() {
        for b in &m.variables[i + 1..] {
            if a.name == b.name {
                return Err(format!("{name}: duplicate variable name {}", a.name));
            }
            // Unique across kinds too: the generated slot/value dispatch matches on the number only.
            if a.vr == b.vr {
                return Err(format!(
                    "{name}: {} and {} share value reference {}",
                    a.name, b.name, a.vr
                ));
            }
        }
        check_variable(name, a, layer)?;
    }
    check_states(m, layer)?;
    crate::clocks::check_clocks(m, layer)?;
    check_feedthrough(m)
}

fn check_variable(name: &str, a: &VariableDescription, layer: &LayerInfo) -> Result<(), String> {
    if a.vr == layer.time_vr {
        return Err(format!(
            "{name}: {} uses value reference {}, reserved for time in FMI 3.0",
            a.name, a.vr
        ));
    }
    if a.vr >= layer.reserved_vr_start {
        return Err(format!(
            "{name}: {} uses value reference {}, reserved for the layer's Model Exchange variables (>= {})",
            a.name, a.vr, layer.reserved_vr_start
        ));
    }
    if !a.unit.is_empty() && units::lookup(&a.unit).is_none() {
        return Err(format!("{name}: variable {} uses undefined unit {}", a.name, a.unit));
    }
    if !a.unit.is_empty() && a.kind != VarKind::Real {
        return Err(format!("{name}: only Real variables carry units ({})", a.name));
    }
    if a.description.is_empty() {
        return Err(format!("{name}: variable {} has no description", a.name));
    }
    if let Start::Real(v) = a.start {
        if !v.is_finite() {
            return Err(format!("{name}: start of {} is not finite", a.name));
        }
    }
    if a.causality == Causality::Parameter {
        let ok = match a.start {
            Start::Real(v) => a.bound.check_real(&a.name, v),
            Start::Integer(v) => a.bound.check_integer(&a.name, v),
            Start::Boolean(_) => Ok(()),
        };
        ok.map_err(|e| format!("{name}: start value outside the declared bound: {e}"))?;
    } else if a.bound != BoundDescription::Any {
        return Err(format!("{name}: {} has a bound but is not a parameter", a.name));
    }
    Ok(())
}

fn check_states(m: &ModelDescription, layer: &LayerInfo) -> Result<(), String> {
    let name = &m.name;
    let states = m.state_decls();
    for (i, x) in states.iter().enumerate() {
        let der = format!("der({})", x.name);
        if m.decl(&x.name).is_some() || m.decl(&der).is_some() || states[i + 1..].iter().any(|y| y.name == x.name) {
            return Err(format!(
                "{name}: continuous state {} clashes with another variable name",
                x.name
            ));
        }
        if !x.unit.is_empty() && units::lookup(&x.unit).is_none() {
            return Err(format!(
                "{name}: continuous state {} uses undefined unit {}",
                x.name, x.unit
            ));
        }
        if x.description.is_empty() {
            return Err(format!("{name}: continuous state {} has no description", x.name));
        }
        for d in &x.starts_from {
            if input_index(m, d).is_none() {
                return Err(format!(
                    "{name}: the start of continuous state {} is taken from {d}, which is not an input (inputs: {})",
                    x.name,
                    names::of_causality(m, Causality::Input)
                ));
            }
        }
        for d in x.depends.as_deref().unwrap_or(&[]) {
            let input = m.decl(d).is_some_and(|v| v.causality == Causality::Input);
            if !input && !states.iter().any(|y| y.name == *d) {
                return Err(format!(
                    "{name}: the derivative of continuous state {} depends on {d}, which is neither an input nor a continuous state (valid: {})",
                    x.name,
                    names::inputs_and_states(m)
                ));
            }
        }
    }
    if states.len() > (layer.derivative_vr_base - layer.state_vr_base) as usize {
        return Err(format!(
            "{name}: {} continuous states are more than the layer can number",
            states.len()
        ));
    }
    Ok(())
}

/// Feed-through names must be outputs and inputs; a refusal lists the valid names.
fn check_feedthrough(m: &ModelDescription) -> Result<(), String> {
    let FeedthroughDescription::Some(list) = &m.feedthrough else {
        return Ok(());
    };
    for (o, ins) in list {
        if !m.decl(o).is_some_and(|d| d.causality == Causality::Output) {
            return Err(format!(
                "{}: feedthrough output {o} is not an output (outputs: {})",
                m.name,
                names::of_causality(m, Causality::Output)
            ));
        }
        for i in ins {
            if !m.decl(i).is_some_and(|d| d.causality == Causality::Input) {
                return Err(format!(
                    "{}: feedthrough input {i} is not an input (inputs: {})",
                    m.name,
                    names::of_causality(m, Causality::Input)
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_project_model_passes_and_cites_declared_references() {
        check_catalogue(&crate::tests_support::project()).unwrap();
    }

    #[test]
    fn the_fmi3_time_value_reference_is_reserved() {
        let mut cat = crate::tests_support::project();
        let time = cat.layer.time_vr;
        let m = cat.models.iter_mut().find(|m| m.name == "PdController").unwrap();
        m.variables[0].vr = time;
        assert!(check_catalogue(&cat)
            .unwrap_err()
            .contains("reserved for time in FMI 3.0"));
    }

    #[test]
    fn an_undeclared_citation_and_a_wrong_feedthrough_name_are_refused_with_the_valid_names() {
        let mut cat = crate::tests_support::project();
        cat.models[0].source.push_str(" [Nobody-1999]");
        let e = check_catalogue(&cat).unwrap_err();
        assert!(e.contains("cites [Nobody-1999]") && e.contains("Navabi-2019"), "{e}");
        let mut cat = crate::tests_support::project();
        let m = cat.models.iter_mut().find(|m| m.name == "PdController").unwrap();
        m.feedthrough = FeedthroughDescription::Some(vec![("torque_cmd".into(), vec!["q_w".into()])]);
        let e = check_model(m, &cat.layer).unwrap_err();
        assert!(
            e.contains("torque_cmd is not an output (outputs: torque_cmd_x, torque_cmd_y"),
            "{e}"
        );
    }
}
