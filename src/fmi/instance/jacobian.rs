//! Directional derivatives (the body of both rooms' call): partial derivatives by central
//! differences on a copy of the model at the current time and inputs; the instance itself is not
//! touched. Outputs with respect to inputs on every instance; on a Model Exchange instance also the
//! state derivatives as unknowns and the continuous states as knowns (the Jacobian ∂ẋ/∂x an implicit
//! solver asks for).

use super::{CallResult, Fail, Instance, LayerVar};
use crate::model::{Causality, SlotMut, Value, VarKind};

/// A known: an input (declaration index) or a continuous state.
enum Known {
    Input(usize),
    State(usize),
}

/// An unknown: an output (declaration index) or a state derivative.
enum Unknown {
    Output(usize),
    Derivative(usize),
}

impl Instance {
    pub fn directional_derivative(&mut self, unknowns: &[u32], knowns: &[u32], seed: &[f64]) -> CallResult<Vec<f64>> {
        // states and derivatives take part only on a Model Exchange instance that names one of them
        let with_states = self.model_exchange && unknowns.iter().chain(knowns).any(|vr| self.layer_var(*vr).is_some());
        self.ensure_outputs()?;
        let ks = knowns
            .iter()
            .map(|vr| self.known(*vr, with_states))
            .collect::<CallResult<Vec<_>>>()?;
        let us = unknowns
            .iter()
            .map(|vr| self.unknown(*vr, with_states))
            .collect::<CallResult<Vec<_>>>()?;
        if let Some(x) = seed.iter().find(|x| !x.is_finite()) {
            return Err(Fail::error(format!("seed value {x} is not finite")));
        }
        let dmax = seed.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        if dmax == 0.0 {
            return Ok(vec![0.0; unknowns.len()]);
        }
        let n = if with_states { self.n_states() } else { 0 };
        let mut x0 = vec![0.0; n];
        if with_states {
            self.model.get_states(&mut x0).map_err(Fail::error)?;
        }
        let xmax = ks.iter().fold(0.0f64, |a, k| match k {
            Known::State(k) => a.max(x0[*k].abs()),
            Known::Input(i) => match self.model.value(*i) {
                Some(Value::Real(x)) => a.max(x.abs()),
                _ => a,
            },
        });
        let eps = 1e-6 * (1.0 + xmax) / dmax;
        let t = self.run.time;
        let eval = |sign: f64| -> CallResult<Vec<f64>> {
            let mut m = self.model.clone_box();
            let mut x = x0.clone();
            for (k, dv) in ks.iter().zip(seed) {
                match k {
                    Known::State(k) => x[*k] += sign * eps * dv,
                    Known::Input(i) => {
                        if let Some(SlotMut::Real(s)) = m.slot(*i) {
                            *s += sign * eps * dv;
                        }
                    }
                }
            }
            let mut dx = vec![0.0; n];
            if with_states {
                m.set_states(&x).map_err(Fail::error)?;
            }
            m.update_outputs(t).map_err(Fail::error)?;
            if with_states {
                m.derivatives(t, &mut dx)
                    .map_err(|e| Fail::error(format!("derivatives at t = {t}: {e}")))?;
            }
            Ok(us
                .iter()
                .map(|u| match u {
                    Unknown::Derivative(k) => dx[*k],
                    Unknown::Output(i) => {
                        if let Some(Value::Real(y)) = m.value(*i) {
                            y
                        } else {
                            f64::NAN
                        }
                    }
                })
                .collect())
        };
        let plus = eval(1.0)?;
        let minus = eval(-1.0)?;
        let d: Vec<f64> = plus.iter().zip(&minus).map(|(p, m)| (p - m) / (2.0 * eps)).collect();
        if let Some(v) = d.iter().find(|v| !v.is_finite()) {
            return Err(Fail::error(format!(
                "directional derivative {v} at t = {t} is not finite"
            )));
        }
        Ok(d)
    }

    fn known(&self, vr: u32, with_states: bool) -> CallResult<Known> {
        if with_states {
            return match (self.layer_var(vr), self.real_decl(vr)) {
                (Some(LayerVar::State(k)), _) => Ok(Known::State(k)),
                (None, Some(i)) if self.entry.decls[i].causality == Causality::Input => Ok(Known::Input(i)),
                _ => Err(Fail::error(format!(
                    "known {vr} is neither a Real input nor a continuous state"
                ))),
            };
        }
        let (i, d) = self.decl(VarKind::Real, vr)?;
        if d.causality != Causality::Input {
            return Err(Fail::error(format!("known {} is not an input", d.name)));
        }
        Ok(Known::Input(i))
    }

    fn unknown(&self, vr: u32, with_states: bool) -> CallResult<Unknown> {
        if with_states {
            return match (self.layer_var(vr), self.real_decl(vr)) {
                (Some(LayerVar::Derivative(k)), _) => Ok(Unknown::Derivative(k)),
                (None, Some(i)) if self.entry.decls[i].causality == Causality::Output => Ok(Unknown::Output(i)),
                _ => Err(Fail::error(format!(
                    "unknown {vr} is neither a Real output nor a state derivative"
                ))),
            };
        }
        let (i, d) = self.decl(VarKind::Real, vr)?;
        if d.causality != Causality::Output {
            return Err(Fail::error(format!("unknown {} is not an output", d.name)));
        }
        Ok(Unknown::Output(i))
    }

    /// Declaration index of a Real variable.
    fn real_decl(&self, vr: u32) -> Option<usize> {
        self.entry
            .decls
            .iter()
            .position(|d| d.vr == vr && d.kind == VarKind::Real)
    }
}
