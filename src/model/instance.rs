//! [`Fmu`]: a model's variables plus its internal state, the one generic wrapper the FMI layer drives
//! (through the object-safe [`DynModel`]) and the models' own unit tests use directly.

use serde::{Deserialize, Serialize};

use super::{Experiment, Model, ModelInfo, ModelResult, SlotMut, Value, VarDecl, Variables};

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
        Fmu { v: M::Vars::default(), state: None }
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
    fn clone_box(&self) -> Box<dyn DynModel>;
    fn to_bytes(&self) -> Result<Vec<u8>, String>;
    /// Replaces `self` by the decoded state; `self` is unchanged on error.
    fn load_bytes(&mut self, bytes: &[u8]) -> ModelResult;
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
    fn clone_box(&self) -> Box<dyn DynModel> {
        Box::new(self.clone())
    }
    fn to_bytes(&self) -> Result<Vec<u8>, String> {
        postcard::to_stdvec(self).map_err(|e| e.to_string())
    }
    fn load_bytes(&mut self, bytes: &[u8]) -> ModelResult {
        let decoded: Fmu<M> = postcard::from_bytes(bytes).map_err(|e| format!("model state does not decode: {e}"))?;
        *self = decoded;
        Ok(())
    }
}
