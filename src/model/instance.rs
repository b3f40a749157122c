//! [`Fmu`]: a model's variables plus its internal state, the one generic wrapper the FMI layer drives
//! (through the object-safe [`DynModel`]) and the models' own unit tests use directly.

use serde::{Deserialize, Serialize};

use super::contract::{Experiment, Model, ModelResult, SlotMut, Value, Variables};
use super::leaves;
use crate::catalogue::decl::{Causality, ModelInfo, VarDecl};

/// Variables + internal state of one model. The state exists once the parameters have been applied
/// (`initialize`); before that, outputs and steps are refused with a message.
#[derive(Clone, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct Fmu<M: Model> {
    pub v: M::Vars,
    pub state: Option<M>,
}

impl<M: Model> Default for Fmu<M> {
    fn default() -> Self {
        Fmu {
            v: M::Vars::default(),
            state: None,
        }
    }
}

impl<M: Model> Fmu<M> {
    /// Checks the declared bounds, builds the state from the parameters and checks that every
    /// calculated parameter is finite. On error the previous state is kept.
    pub fn initialize(&mut self, exp: &Experiment) -> ModelResult {
        self.v.check_bounds()?;
        let mut v = self.v.clone();
        let state = M::initialize(&mut v, exp)?;
        v.check_calculated()?;
        self.v = v;
        self.state = Some(state);
        Ok(())
    }

    /// Computes every output from the inputs and the state.
    pub fn outputs(&mut self, t: f64) -> ModelResult {
        let state = self.state.as_ref().ok_or(NOT_INITIALIZED)?;
        state.outputs(&mut self.v, t)
    }

    /// Advances the state from t to t + h with the inputs held.
    pub fn step(&mut self, t: f64, h: f64) -> ModelResult {
        let state = self.state.as_mut().ok_or(NOT_INITIALIZED)?;
        state.step(&self.v, t, h)
    }

    /// Checks a state restored from bytes as strictly as parameters at initialization: declared
    /// bounds, finite variables, parameter relations (a trial `initialize`), finite calculated
    /// parameters equal to the ones the parameters give; then the internal state: every serialized
    /// field outside [`Model::EVOLVING`] equal to a fresh `initialize`, every evolving number finite,
    /// and the model's own invariants ([`Model::validate`]). Last, the model rebuilds what it does
    /// not serialize ([`Model::restored`]).
    pub fn validate(&mut self, exp: &Experiment) -> ModelResult {
        self.v.check_bounds()?;
        self.v.check_finite()?;
        // every float anywhere (declared or not, evolving or derived): no dormant NaN or infinity
        leaves::check_all_finite(&self.v, "variable block field ")?;
        if let Some(state) = &mut self.state {
            leaves::check_all_finite(&*state, "")?;
            let mut v = self.v.clone();
            let fresh = M::initialize(&mut v, exp)?;
            v.check_calculated()?;
            for (i, d) in M::Vars::DECLS.iter().enumerate() {
                if d.causality != Causality::CalculatedParameter {
                    continue;
                }
                let (a, b) = (self.v.value(i), v.value(i));
                let same = match (a, b) {
                    (Some(Value::Real(x)), Some(Value::Real(y))) => x.to_bits() == y.to_bits(),
                    _ => a == b,
                };
                if !same {
                    return Err(format!(
                        "restored state: calculated parameter {} = {:?} does not match the parameters (they give {:?})",
                        d.name, a, b
                    ));
                }
            }
            leaves::check_restored(&*state, &fresh, M::EVOLVING)?;
            state.validate(&fresh)?;
            state.restored()?;
        }
        Ok(())
    }

    /// Model Exchange: the continuous states into `x`.
    pub fn get_states(&self, x: &mut [f64]) -> ModelResult {
        self.state.as_ref().ok_or(NOT_INITIALIZED)?.get_states(&self.v, x);
        Ok(())
    }

    /// Model Exchange: replaces the continuous states.
    pub fn set_states(&mut self, x: &[f64]) -> ModelResult {
        self.state.as_mut().ok_or(NOT_INITIALIZED)?.set_states(x);
        Ok(())
    }

    /// Model Exchange: ẋ at time t for the current inputs and states.
    pub fn derivatives(&self, t: f64, dx: &mut [f64]) -> ModelResult {
        self.state.as_ref().ok_or(NOT_INITIALIZED)?.derivatives(&self.v, t, dx)
    }

    /// Model Exchange: the next time event after t.
    pub fn next_time_event(&self, t: f64) -> Option<f64> {
        self.state.as_ref().and_then(|s| s.next_time_event(&self.v, t))
    }

    /// Model Exchange: event update at t; whether the continuous states changed.
    pub fn event_update(&mut self, t: f64) -> Result<bool, String> {
        let v = &self.v;
        self.state.as_mut().ok_or(NOT_INITIALIZED)?.event_update(v, t)
    }

    /// Model Exchange: after an accepted integrator step; whether the model asks for an event.
    pub fn completed_integrator_step(&mut self, t: f64) -> bool {
        let v = &self.v;
        self.state.as_mut().is_some_and(|s| s.completed_integrator_step(v, t))
    }

    /// The event lines the last step produced ([`Model::take_log`]), emptied.
    pub fn take_log(&mut self) -> Vec<String> {
        self.state.as_mut().map(|s| s.take_log()).unwrap_or_default()
    }

    /// Whether the parameters have been applied (there is an internal state).
    pub fn is_initialized(&self) -> bool {
        self.state.is_some()
    }

    /// The internal state (for tests); panics before initialization.
    pub fn model(&self) -> &M {
        self.state.as_ref().expect("model is initialized")
    }

    /// The internal state, mutable (for tests); panics before initialization.
    pub fn model_mut(&mut self) -> &mut M {
        self.state.as_mut().expect("model is initialized")
    }
}

const NOT_INITIALIZED: &str = "the model is not initialized (parameters not applied yet)";

/// Object-safe view of an [`Fmu`], used by the FMI layer. Variables are addressed by declaration index.
pub trait DynModel: Send {
    fn info(&self) -> &'static ModelInfo;
    fn decls(&self) -> &'static [VarDecl];
    fn slot(&mut self, index: usize) -> Option<SlotMut<'_>>;
    fn value(&self, index: usize) -> Option<Value>;
    fn initialize(&mut self, exp: &Experiment) -> ModelResult;
    fn update_outputs(&mut self, t: f64) -> ModelResult;
    fn do_step(&mut self, t: f64, h: f64) -> ModelResult;
    /// The event lines of the last step, emptied ([`Model::take_log`]).
    fn take_log(&mut self) -> Vec<String>;
    fn clone_box(&self) -> Box<dyn DynModel>;
    fn to_bytes(&self) -> Result<Vec<u8>, String>;
    /// Replaces `self` by the decoded state; `self` is unchanged on error.
    fn load_bytes(&mut self, bytes: &[u8]) -> ModelResult;
    /// Checks a restored state and rebuilds its unserialized parts (see [`Fmu::validate`]).
    fn validate(&mut self, exp: &Experiment) -> ModelResult;
    fn is_initialized(&self) -> bool;
    /// The period of the model's integer time grid for the current parameters ([`Model::time_grid`]).
    fn time_grid(&self) -> Option<f64>;
    /// Model Exchange (see [`Model::STATES`]); the layer checks lengths and finiteness.
    fn get_states(&self, x: &mut [f64]) -> ModelResult;
    fn set_states(&mut self, x: &[f64]) -> ModelResult;
    fn derivatives(&self, t: f64, dx: &mut [f64]) -> ModelResult;
    fn next_time_event(&self, t: f64) -> Option<f64>;
    fn event_update(&mut self, t: f64) -> Result<bool, String>;
    fn completed_integrator_step(&mut self, t: f64) -> bool;
    /// Test support: the internal state as JSON, a replacement decoded from JSON, the evolving paths.
    #[cfg(test)]
    fn state_json(&self) -> serde_json::Value;
    #[cfg(test)]
    fn set_state_json(&mut self, state: serde_json::Value) -> ModelResult;
    #[cfg(test)]
    fn evolving(&self) -> &'static [&'static str];
    /// Test support: (path, byte offset in `to_bytes`) of every f64 of the serialized model.
    #[cfg(test)]
    fn float_leaves(&self) -> Vec<(String, usize, u64)>;
}

impl<M: Model> DynModel for Fmu<M> {
    fn info(&self) -> &'static ModelInfo {
        &M::INFO
    }
    fn decls(&self) -> &'static [VarDecl] {
        M::Vars::DECLS
    }
    fn slot(&mut self, index: usize) -> Option<SlotMut<'_>> {
        self.v.slot(index)
    }
    fn value(&self, index: usize) -> Option<Value> {
        self.v.value(index)
    }
    fn initialize(&mut self, exp: &Experiment) -> ModelResult {
        Fmu::initialize(self, exp)
    }
    fn update_outputs(&mut self, t: f64) -> ModelResult {
        self.outputs(t)
    }
    fn do_step(&mut self, t: f64, h: f64) -> ModelResult {
        self.step(t, h)
    }
    fn take_log(&mut self) -> Vec<String> {
        Fmu::take_log(self)
    }
    fn time_grid(&self) -> Option<f64> {
        M::time_grid(&self.v).filter(|p| p.is_finite() && *p > 0.0)
    }
    fn clone_box(&self) -> Box<dyn DynModel> {
        Box::new(self.clone())
    }
    fn to_bytes(&self) -> Result<Vec<u8>, String> {
        postcard::to_stdvec(self).map_err(|e| e.to_string())
    }
    fn load_bytes(&mut self, bytes: &[u8]) -> ModelResult {
        let (decoded, rest): (Fmu<M>, &[u8]) =
            postcard::take_from_bytes(bytes).map_err(|e| format!("model state does not decode: {e}"))?;
        if !rest.is_empty() {
            return Err(format!("model state has {} trailing bytes after its end", rest.len()));
        }
        *self = decoded;
        Ok(())
    }
    fn validate(&mut self, exp: &Experiment) -> ModelResult {
        Fmu::validate(self, exp)
    }
    fn is_initialized(&self) -> bool {
        Fmu::is_initialized(self)
    }
    fn get_states(&self, x: &mut [f64]) -> ModelResult {
        Fmu::get_states(self, x)
    }
    fn set_states(&mut self, x: &[f64]) -> ModelResult {
        Fmu::set_states(self, x)
    }
    fn derivatives(&self, t: f64, dx: &mut [f64]) -> ModelResult {
        Fmu::derivatives(self, t, dx)
    }
    fn next_time_event(&self, t: f64) -> Option<f64> {
        Fmu::next_time_event(self, t)
    }
    fn event_update(&mut self, t: f64) -> Result<bool, String> {
        Fmu::event_update(self, t)
    }
    fn completed_integrator_step(&mut self, t: f64) -> bool {
        Fmu::completed_integrator_step(self, t)
    }
    #[cfg(test)]
    fn state_json(&self) -> serde_json::Value {
        serde_json::to_value(&self.state).expect("state encodes as JSON")
    }
    #[cfg(test)]
    fn set_state_json(&mut self, state: serde_json::Value) -> ModelResult {
        self.state = serde_json::from_value(state).map_err(|e| e.to_string())?;
        Ok(())
    }
    #[cfg(test)]
    fn evolving(&self) -> &'static [&'static str] {
        M::EVOLVING
    }
    #[cfg(test)]
    fn float_leaves(&self) -> Vec<(String, usize, u64)> {
        let l = leaves::Leaves::of(self).expect("serializable");
        l.leaves
            .iter()
            .zip(&l.offsets)
            .filter_map(|((p, leaf), o)| match leaf {
                leaves::Leaf::F64(bits) => Some((l.path(*p).to_string(), *o, *bits)),
                _ => None,
            })
            .collect()
    }
}
