//! Registry-wide check of restored states: for every FMU, after some steps, every serialized field
//! outside the model's `EVOLVING` paths and every calculated parameter is changed in turn, and the
//! restored-state check must refuse each change (a changed derived field is never accepted); the
//! unchanged state is accepted; every `EVOLVING` path names a field that exists.

use serde_json::Value as J;

use super::{Causality, DynModel, Experiment, SlotMut, Value};
use crate::model::leaves::under;
use crate::registry;

/// (dotted path, JSON pointer) of every scalar of the state and of every array (for a length change);
/// arrays contribute their first and last element only.
fn targets(v: &J, path: &str, ptr: &str, out: &mut Vec<(String, String, bool)>) {
    match v {
        J::Object(m) => {
            for (k, x) in m {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                targets(x, &p, &format!("{ptr}/{k}"), out);
            }
        }
        J::Array(a) => {
            if !a.is_empty() {
                out.push((path.to_string(), ptr.to_string(), true));
                let mut idx = vec![0];
                if a.len() > 1 {
                    idx.push(a.len() - 1);
                }
                for i in idx {
                    targets(&a[i], path, &format!("{ptr}/{i}"), out);
                }
            }
        }
        _ => out.push((path.to_string(), ptr.to_string(), false)),
    }
}

fn mutate(v: &mut J, array: bool) -> bool {
    if array {
        let a = v.as_array_mut().expect("array");
        let last = a.last().cloned().expect("non-empty");
        a.push(last);
        return true;
    }
    *v = match v {
        J::Bool(b) => J::Bool(!*b),
        J::Number(n) if n.is_u64() => J::from(n.as_u64().unwrap().wrapping_add(1)),
        J::Number(n) if n.is_i64() => J::from(n.as_i64().unwrap() + 1),
        J::Number(n) => J::from(n.as_f64().unwrap() * 1.5 + 0.37),
        _ => return false, // unit enum variants by name: covered by the unit test of `leaves`
    };
    true
}

fn stepped(entry: &'static crate::model::ModelEntry, exp: &Experiment) -> Box<dyn DynModel> {
    let mut m = (entry.create)();
    m.initialize(exp).unwrap_or_else(|e| panic!("{}: {e}", entry.info.name));
    let h = entry.info.default_step;
    for k in 0..20 {
        m.update_outputs(k as f64 * h).unwrap();
        m.do_step(k as f64 * h, h)
            .unwrap_or_else(|e| panic!("{}: {e}", entry.info.name));
    }
    m
}

#[test]
fn every_changed_derived_field_of_every_model_is_refused() {
    let exp = Experiment::default();
    let mut total = 0;
    for entry in registry::ALL {
        let name = entry.info.name;
        let m = stepped(entry, &exp);
        let mut same = m.clone_box();
        same.validate(&exp)
            .unwrap_or_else(|e| panic!("{name}: an unchanged state is refused: {e}"));
        let json = m.state_json();
        let mut t = vec![];
        targets(&json, "", "", &mut t);
        let paths: Vec<&str> = t.iter().map(|(p, _, _)| p.as_str()).collect();
        for ev in m.evolving() {
            assert!(
                paths.iter().any(|p| under(p, &[ev])),
                "{name}: EVOLVING path {ev} names no field of the state ({paths:?})"
            );
        }
        let mut checked = 0;
        for (path, ptr, array) in &t {
            if under(path, m.evolving()) {
                continue;
            }
            let mut j = json.clone();
            if !mutate(j.pointer_mut(ptr).expect("pointer"), *array) {
                continue;
            }
            let mut r = m.clone_box();
            if r.set_state_json(j).is_err() {
                checked += 1; // refused by the decoder itself
                continue;
            }
            assert!(
                r.validate(&exp).is_err(),
                "{name}: a restored state with {path} changed{} is accepted",
                if *array { " (length)" } else { "" }
            );
            checked += 1;
        }
        // calculated parameters
        for (i, d) in entry.decls.iter().enumerate() {
            if d.causality != Causality::CalculatedParameter {
                continue;
            }
            let mut r = m.clone_box();
            match r.slot(i) {
                Some(SlotMut::Real(x)) => *x = *x * 1.5 + 0.37,
                Some(SlotMut::Integer(x)) => *x += 1,
                Some(SlotMut::Boolean(x)) => *x = !*x,
                None => unreachable!(),
            }
            let e = r
                .validate(&exp)
                .expect_err(&format!("{name}: calculated parameter {} changed is accepted", d.name));
            assert!(e.contains(d.name), "{e}");
            assert!(matches!(
                m.value(i),
                Some(Value::Real(_) | Value::Integer(_) | Value::Boolean(_))
            ));
            checked += 1;
        }
        println!("{name}: {checked} changed derived fields refused");
        total += checked;
    }
    println!(
        "{} models, {total} changed derived fields, all refused",
        registry::COUNT
    );
}
