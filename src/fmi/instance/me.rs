//! Model Exchange on an [`Instance`], the same in both standards: time, continuous states, derivatives, the
//! event iteration and the mode switches. The importer's solver integrates; the model gives ẋ, its
//! time events and, where it keeps an invariant (a unit quaternion), a projection at events.

use super::{CallResult, Fail, Instance, LayerVar, Reason};
use crate::fmi::types::{Arg, FsmState};

/// What one pass of the event iteration reports (each room copies it into its own arguments).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EventInfo {
    pub new_discrete_states_needed: bool,
    pub terminate_simulation: bool,
    pub nominals_changed: bool,
    pub values_changed: bool,
    pub next_event_time: Option<f64>,
}

impl Instance {
    /// Value of a state or derivative variable (derivatives at the current time and inputs).
    pub fn layer_value(&mut self, var: LayerVar) -> CallResult<f64> {
        let mut buf = vec![0.0; self.n_states()];
        match var {
            LayerVar::State(k) => {
                self.model.get_states(&mut buf).map_err(Fail::error)?;
                Ok(buf[k])
            }
            LayerVar::Derivative(k) => {
                self.derivatives_into(&mut buf)?;
                Ok(buf[k])
            }
        }
    }

    fn check_len(&self, arg: Arg, n: usize) -> CallResult {
        let states = self.n_states();
        if n != states {
            return Err(Fail::error(Reason::Length {
                arg,
                n,
                model: self.entry.info.name,
                states,
            }));
        }
        Ok(())
    }

    pub fn set_time(&mut self, t: f64) -> CallResult {
        if !t.is_finite() {
            return Err(Fail::error(format!("time {t} is not finite")));
        }
        if let Some(period) = self.model.time_grid() {
            crate::math::sample_grid::check_time("time", t, period).map_err(Fail::error)?;
        }
        // A solver may evaluate behind an accepted point, but never before the last event (event
        // instants increase): checked against the event itself (up to round-off),
        // in event mode too, so that no sequence of small steps back walks past it.
        if t < self.run.event_time - 1e-9 * self.run.event_time.abs().max(1.0) {
            return Err(Fail::error(format!(
                "time {t} lies before the last event at t = {}",
                self.run.event_time
            )));
        }
        self.run.time = t;
        self.run.outputs_dirty = true;
        Ok(())
    }

    pub fn set_continuous_states(&mut self, x: &[f64]) -> CallResult {
        self.check_len(Arg::States, x.len())?;
        if let Some((k, value)) = first_non_finite(x) {
            let name = self.entry.state_decls()[k].name;
            return Err(Fail::error(Reason::NonFiniteState { k, name, value }));
        }
        self.model.set_states(x).map_err(Fail::error)?;
        self.run.outputs_dirty = true;
        Ok(())
    }

    pub fn get_continuous_states(&mut self, x: &mut [f64]) -> CallResult {
        self.check_len(Arg::States, x.len())?;
        self.ensure_initialized()?;
        self.model.get_states(x).map_err(Fail::error)
    }

    pub fn get_nominals(&mut self, x: &mut [f64]) -> CallResult {
        self.check_len(Arg::Nominals, x.len())?;
        x.fill(1.0);
        Ok(())
    }

    /// ẋ at the current time, inputs and states. The outputs are not computed here: a model's
    /// right-hand side reads only its inputs, parameters and state (`Model::derivatives` gets the
    /// variables read-only), and a solver evaluates ẋ several times per step where the outputs are read
    /// once per communication point (computing them at every evaluation doubled a plant's cost).
    fn derivatives_into(&mut self, dx: &mut [f64]) -> CallResult {
        self.ensure_initialized()?;
        self.model
            .derivatives(self.run.time, dx)
            .map_err(|e| Fail::error(format!("derivatives at t = {}: {e}", self.run.time)))?;
        if let Some((k, v)) = first_non_finite(dx) {
            return Err(Fail::error(format!(
                "der({}) = {v} at t = {}",
                self.entry.state_decls()[k].name,
                self.run.time
            )));
        }
        Ok(())
    }

    pub fn get_derivatives(&mut self, dx: &mut [f64]) -> CallResult {
        self.check_len(Arg::Derivatives, dx.len())?;
        self.derivatives_into(dx)
    }

    pub fn get_event_indicators(&mut self, z: &[f64]) -> CallResult {
        if !z.is_empty() {
            return Err(Fail::error(format!(
                "eventIndicators[] has {} elements, but numberOfEventIndicators = 0",
                z.len()
            )));
        }
        Ok(())
    }

    pub fn enter_event_mode(&mut self) -> CallResult {
        self.run.fsm = FsmState::EventMode;
        Ok(())
    }

    /// One pass of the event iteration: the model's event update at the current time (projection,
    /// switching at a time event), then the next time event.
    pub fn new_discrete_states(&mut self) -> CallResult<EventInfo> {
        self.ensure_outputs()?;
        let t = self.run.time;
        let changed = self
            .model
            .event_update(t)
            .map_err(|e| Fail::error(format!("event at t = {t}: {e}")))?;
        self.run.event_time = t;
        self.run.outputs_dirty = true;
        let next = self.model.next_time_event(t).filter(|te| te.is_finite() && *te > t);
        Ok(EventInfo {
            values_changed: changed,
            next_event_time: next,
            ..EventInfo::default()
        })
    }

    pub fn enter_continuous_time_mode(&mut self) -> CallResult {
        self.run.fsm = FsmState::ContinuousTimeMode;
        Ok(())
    }

    /// After an accepted solver step: whether the model asks for an event (projection).
    pub fn completed_integrator_step(&mut self) -> CallResult<bool> {
        let t = self.run.time;
        Ok(self.model.completed_integrator_step(t))
    }
}

/// The first element that is not finite (index, value): a solver calls the functions that check this
/// several times per step, so the usual all-finite case is one pass without a branch per element
/// (vectorised); only a vector with a bad element is searched for its index.
fn first_non_finite(v: &[f64]) -> Option<(usize, f64)> {
    if v.iter().fold(true, |ok, x| ok & x.is_finite()) {
        return None;
    }
    v.iter().copied().enumerate().find(|(_, x)| !x.is_finite())
}
