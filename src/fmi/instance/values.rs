//! Value access of an instance with the causality/variability rules both standards share (which variable
//! may be set in which state): atomic sets, lazy outputs, and the Model Exchange variables the layer adds
//! (continuous states and their derivatives at reserved value references), which value access refuses
//! to set.

use super::{CallResult, Fail, Instance, LayerVar, Reason};
use crate::fmi::types::{FsmState, Status};
use crate::model::{
    Causality, SlotMut, Value, VarDecl, VarKind, Variability, DERIVATIVE_VR_BASE, RESERVED_VR_START, STATE_VR_BASE,
};

fn kind_name(k: VarKind) -> &'static str {
    match k {
        VarKind::Real => "Real",
        VarKind::Integer => "Integer",
        VarKind::Boolean => "Boolean",
    }
}

impl Instance {
    /// Declaration index and declaration of a value reference of the given kind.
    #[inline]
    pub(in crate::fmi) fn decl(&self, kind: VarKind, vr: u32) -> CallResult<(usize, &'static VarDecl)> {
        if let Some(i) = self.index.get(kind, vr) {
            return Ok((i, &self.entry.decls[i]));
        }
        self.unknown_vr(kind, vr)
    }

    #[cold]
    fn unknown_vr(&self, kind: VarKind, vr: u32) -> CallResult<(usize, &'static VarDecl)> {
        let other = [VarKind::Real, VarKind::Integer, VarKind::Boolean]
            .into_iter()
            .filter(|k| *k != kind)
            .find_map(|k| self.index.get(k, vr).map(|i| &self.entry.decls[i]));
        Err(match other {
            Some(d) => Fail::error(format!(
                "value reference {vr} is {} ({}), not {}",
                d.name,
                kind_name(d.kind),
                kind_name(kind)
            )),
            None => Fail::error(format!("unknown {} value reference {vr}", kind_name(kind))),
        })
    }

    /// Whether a variable may be set in the current state.
    fn check_settable(&self, d: &VarDecl) -> CallResult {
        let init = matches!(self.run.fsm, FsmState::Instantiated | FsmState::InitializationMode);
        let ok = match (d.causality, d.variability) {
            (_, Variability::Constant) => false,
            (Causality::Input, _) => true,
            (Causality::Parameter, Variability::Fixed) => init,
            (Causality::Parameter, Variability::Tunable) => true,
            (Causality::Parameter, _) => init,
            _ => false,
        };
        if ok {
            return Ok(());
        }
        Err(Fail::error(match d.causality {
            Causality::Parameter => Reason::FixedParameter {
                name: d.name,
                state: self.run.fsm,
            },
            Causality::Output => format!("{} is an output and cannot be set", d.name).into(),
            Causality::CalculatedParameter => format!("{} is a calculated parameter and cannot be set", d.name).into(),
            _ => format!("{} ({:?}, {:?}) cannot be set", d.name, d.causality, d.variability).into(),
        }))
    }

    /// Sets values of one kind atomically: every entry is checked before any is written, so a
    /// refused call leaves the instance unchanged. `value(i)` is the value for `vrs[i]`.
    pub fn set_values(&mut self, kind: VarKind, vrs: &[u32], value: impl Fn(usize) -> Value) -> CallResult {
        let mut sets_parameter = false;
        for (i, vr) in vrs.iter().enumerate() {
            if kind == VarKind::Real {
                if let Some(var) = self.layer_var(*vr) {
                    let (LayerVar::State(k) | LayerVar::Derivative(k)) = var;
                    let name = self.entry.state_decls()[k].name;
                    return Err(Fail::error(match var {
                        LayerVar::State(_) => Reason::StateByValue { name },
                        LayerVar::Derivative(_) => {
                            format!("der({name}) is a state derivative and cannot be set").into()
                        }
                    }));
                }
            }
            let (_, d) = self.decl(kind, *vr)?;
            self.check_settable(d)?;
            if let Value::Real(x) = value(i) {
                if !x.is_finite() {
                    return Err(Fail::error(format!(
                        "value {x} for {} is not finite (use 1e30 for \"no limit\")",
                        d.name
                    )));
                }
            }
            sets_parameter |= d.causality == Causality::Parameter;
        }
        // All checked: write (the value references are known to exist with this kind).
        for (i, vr) in vrs.iter().enumerate() {
            let index = self.index.get(kind, *vr).expect("checked above");
            match (self.model.slot(index), value(i)) {
                (Some(SlotMut::Real(s)), Value::Real(x)) => *s = x,
                (Some(SlotMut::Integer(s)), Value::Integer(x)) => *s = x,
                (Some(SlotMut::Boolean(s)), Value::Boolean(x)) => *s = x,
                _ => {
                    return Err(Fail::error(format!(
                        "internal: storage of value reference {vr} does not match its declaration"
                    )))
                }
            }
        }
        self.run.params_dirty |= sets_parameter;
        self.run.outputs_dirty = true;
        Ok(())
    }

    /// During initialization, (re)applies parameters set since the last initialization (what reads the
    /// state or the derivatives needs; the outputs are left to be computed when they are read).
    pub fn ensure_initialized(&mut self) -> CallResult {
        if self.run.fsm == FsmState::InitializationMode && self.run.params_dirty {
            self.model.initialize(&self.run.exp).map_err(Fail::error)?;
            self.run.params_dirty = false;
            self.run.outputs_dirty = true;
        }
        Ok(())
    }

    /// Brings outputs up to date with the inputs most recently set. During initialization the
    /// parameters are (re)applied first so that initial outputs reflect them.
    pub fn ensure_outputs(&mut self) -> CallResult {
        self.ensure_initialized()?;
        if self.run.fsm == FsmState::EventMode && self.clocks.active.contains(&true) {
            // a clocked output read before the discrete states are updated: the partitions run now
            self.run_active_partitions()?;
        }
        if self.run.outputs_dirty && self.run.fsm != FsmState::Instantiated {
            self.model.update_outputs(self.run.time).map_err(Fail::error)?;
            self.apply_held();
            self.run.outputs_dirty = false;
        }
        Ok(())
    }

    /// [`Self::ensure_outputs`], except in Initialization Mode: there the inputs a master has set so far
    /// need not be consistent yet (a master hands an unconnected input its default before the unit that
    /// feeds it is initialized: OMSimulator gives a quaternion `[0, 0, 0, 0]`). Outputs the model refuses
    /// to compute from them keep their previous values (the start values) and the call reports a warning
    /// with the model's reason; they are computed again at the next read, and outside Initialization Mode
    /// the same inputs are refused with an error (a step never runs on them).
    pub fn ensure_outputs_or_keep(&mut self) -> CallResult {
        if self.run.fsm != FsmState::InitializationMode {
            return self.ensure_outputs();
        }
        self.ensure_initialized()?;
        if !self.run.outputs_dirty {
            return Ok(());
        }
        let computed: Vec<usize> = (self.entry.decls.iter().enumerate())
            .filter(|(_, d)| matches!(d.causality, Causality::Output | Causality::Local))
            .map(|(i, _)| i)
            .collect();
        let kept: Vec<(usize, Value)> = computed
            .iter()
            .filter_map(|&i| self.model.value(i).map(|v| (i, v)))
            .collect();
        match self.model.update_outputs(self.run.time) {
            Ok(()) => {
                self.apply_held();
                self.run.outputs_dirty = false;
                Ok(())
            }
            Err(reason) => {
                for (i, v) in kept {
                    match (self.model.slot(i), v) {
                        (Some(SlotMut::Real(s)), Value::Real(x)) => *s = x,
                        (Some(SlotMut::Integer(s)), Value::Integer(x)) => *s = x,
                        (Some(SlotMut::Boolean(s)), Value::Boolean(x)) => *s = x,
                        _ => {}
                    }
                }
                Err(Fail::warning(format!(
                    "outputs not computed in Initialization Mode from the inputs set so far ({reason}); \
                     they keep their previous values until the inputs are consistent, and a step with these \
                     inputs is refused"
                )))
            }
        }
    }

    /// Reads values of one kind; `write(i, v)` receives the value of `vrs[i]`. Outputs are computed
    /// lazily here; a non-finite output puts the instance into the error state. In Initialization Mode,
    /// outputs that inconsistent inputs do not yet allow are read as kept, with a warning
    /// ([`Self::ensure_outputs_or_keep`]).
    pub fn get_values(&mut self, kind: VarKind, vrs: &[u32], mut write: impl FnMut(usize, Value)) -> CallResult {
        let mut warning = match self.ensure_outputs_or_keep() {
            Err(f) if f.status == Status::Warning => Some(f),
            other => {
                other?;
                None
            }
        };
        for (i, vr) in vrs.iter().enumerate() {
            if kind == VarKind::Real && *vr >= RESERVED_VR_START {
                if let Some(var) = self.layer_var(*vr) {
                    let x = match self.layer_value(var) {
                        Ok(x) => x,
                        // a master that reads every variable before it has set the inputs (libcosim's
                        // initialization reads, then transfers, then reads again): the same tolerance as
                        // for the outputs, a derivative the inputs do not yet allow reads as 0
                        Err(f) if self.run.fsm == FsmState::InitializationMode => {
                            warning.get_or_insert(Fail::warning(Reason::Then(
                                Box::new(f.reason),
                                "; read as 0 until the inputs are consistent in Initialization Mode",
                            )));
                            0.0
                        }
                        Err(f) => return Err(f),
                    };
                    write(i, Value::Real(x));
                    continue;
                }
            }
            let (index, d) = self.decl(kind, *vr)?;
            let v = self
                .model
                .value(index)
                .ok_or_else(|| Fail::error(format!("internal: no storage for {}", d.name)))?;
            if let Value::Real(x) = v {
                if !x.is_finite() && d.causality == Causality::Output {
                    self.run.fsm = FsmState::Error;
                    return Err(Fail::error(format!(
                        "output {} is {x} at t = {}",
                        d.name, self.run.time
                    )));
                }
            }
            write(i, v);
        }
        warning.map_or(Ok(()), Err)
    }
}

/// The Model Exchange variables the layer adds to a model's own (continuous states and their
/// derivatives, at reserved value references).
impl Instance {
    pub fn n_states(&self) -> usize {
        self.entry.state_decls().len()
    }

    /// The continuous state or derivative behind a value reference, if it is one.
    pub fn layer_var(&self, vr: u32) -> Option<LayerVar> {
        let n = self.n_states();
        let k = |base: u32| vr.checked_sub(base).map(|k| k as usize).filter(|k| *k < n);
        k(STATE_VR_BASE)
            .map(LayerVar::State)
            .or_else(|| k(DERIVATIVE_VR_BASE).map(LayerVar::Derivative))
    }
}
