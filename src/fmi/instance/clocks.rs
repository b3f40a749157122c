//! The clocks of a clocked model ([`ClockDecl`]): the bookkeeping an instance keeps for them and the
//! partition a clock runs at its tick, for the two ways a master drives them: clocked stepping (the
//! master activates due clocks in Event Mode and the partitions run when the discrete states are
//! updated) and scheduled activation (the master activates one partition at a time in the Activation
//! state). A model's clocks are periodic: clock i ticks at t_start + shift_i + k·T_i (k = 0, 1, …),
//! interval and shift read from the parameters named by the declaration; the tick index is an integer
//! and a master's time counts as the tick within the sample-grid tolerance.
//!
//! At an instant, the first partition to run computes every output from the inputs and the state
//! before the instant (one `update_outputs`); every partition of that instant takes its clocked
//! outputs from that computation and holds them until its next tick, then a stepping partition advances
//! the state over one interval. So two clocks ticking together (a sample and a delivery with a delay of
//! whole periods) give what a sampled run gives: outputs read before the step.

use super::clock_book::{ClockMode, Clocks};
use super::{CallResult, Fail, Instance};
use crate::math::sample_grid;
use crate::model::{clocked_outputs, ClockDecl, SlotMut, Value, VarKind};

fn number(v: Value) -> f64 {
    match v {
        Value::Real(x) => x,
        Value::Integer(i) => i as f64,
        Value::Boolean(b) => b as u8 as f64,
    }
}

impl Instance {
    /// The model's clocks (empty: not clocked).
    pub fn clock_decls(&self) -> &'static [ClockDecl] {
        self.entry.clocks
    }

    /// Clock index of a value reference, or an error naming it.
    pub fn clock_index(&self, vr: u32) -> CallResult<usize> {
        let base = crate::model::CLOCK_VR_BASE;
        match vr.checked_sub(base) {
            Some(i) if (i as usize) < self.clock_decls().len() => Ok(i as usize),
            _ if self.clock_decls().is_empty() => Err(Fail::error(format!(
                "value reference {vr} is not a clock: {} has no clocks",
                self.entry.info.name
            ))),
            _ => Err(Fail::error(format!(
                "value reference {vr} is not a clock of {} (clocks: {}..{})",
                self.entry.info.name,
                base,
                base as usize + self.clock_decls().len() - 1
            ))),
        }
    }

    fn real_parameter(&self, name: &str) -> CallResult<f64> {
        let i = self
            .entry
            .decls
            .iter()
            .position(|d| d.name == name && d.kind == VarKind::Real);
        match i.and_then(|i| self.model.value(i)) {
            Some(Value::Real(x)) => Ok(x),
            _ => Err(Fail::error(format!("clock parameter {name} is not a Real variable"))),
        }
    }

    /// (interval, shift) of clock i in seconds, from the current parameters.
    pub fn clock_timing(&self, i: usize) -> CallResult<(f64, f64)> {
        let c = &self.clock_decls()[i];
        let interval = self.real_parameter(c.interval)?;
        let shift = if c.shift.is_empty() {
            0.0
        } else {
            self.real_parameter(c.shift)?
        };
        Ok((interval, shift))
    }

    /// The time of tick k of clock i: t_start + shift + k·T.
    pub fn tick_time(&self, i: usize, k: i64) -> CallResult<f64> {
        let (interval, shift) = self.clock_timing(i)?;
        Ok(self.run.exp.start_time + shift + k as f64 * interval)
    }

    /// Whether time t is the tick `tick` of clock i (within the sample-grid tolerance).
    fn is_at(&self, i: usize, tick: f64, t: f64) -> CallResult<bool> {
        let (interval, _) = self.clock_timing(i)?;
        Ok((t - tick).abs() <= sample_grid::tolerance(t.abs().max(tick.abs()), interval))
    }

    /// The declaration indices of the outputs clock i holds.
    fn clocked_indices(&self, i: usize) -> Vec<usize> {
        let names = clocked_outputs(self.entry, &self.clock_decls()[i]);
        names
            .iter()
            .filter_map(|n| self.entry.decls.iter().position(|d| d.name == n))
            .collect()
    }

    fn read(&self, indices: &[usize]) -> Vec<(usize, f64)> {
        indices
            .iter()
            .filter_map(|&j| self.model.value(j).map(|v| (j, number(v))))
            .collect()
    }

    /// Refuses a clocked run whose start time is off a clock's grid k·T from t = 0: the units count
    /// their samples at k·T (most from t = 0), so a periodic clock from an off-grid start would tick
    /// between the samples of the sampled run and could not repeat it.
    pub fn check_clock_start(&self) -> CallResult {
        let t0 = self.run.exp.start_time;
        for (i, c) in self.clock_decls().iter().enumerate() {
            let (interval, _) = self.clock_timing(i)?;
            if sample_grid::on_grid(t0, interval, t0).map_err(Fail::error)?.is_none() {
                return Err(Fail::error(format!(
                    "clock {} of {}: the start time {t0} s is not a multiple of {} = {interval} s; a clocked run \
                     needs a start time on the sample grid k·{} from t = 0 (where the unit counts its samples); \
                     start there, or run the unit without event mode (it then samples inside the step)",
                    c.name, self.entry.info.name, c.interval, c.interval
                )));
            }
        }
        Ok(())
    }

    /// At the end of initialization: every clock's next tick is its first, nothing is active, and the
    /// held outputs are those of the start time (already computed).
    pub fn start_clocks(&mut self, mode: ClockMode) {
        let n = self.clock_decls().len();
        let all: Vec<usize> = (0..n).flat_map(|i| self.clocked_indices(i)).collect();
        let held = self.read(&all);
        self.clocks = Clocks {
            mode,
            active: vec![false; n],
            next: vec![0; n],
            reported: std::mem::take(&mut self.clocks.reported),
            held,
            snap: None,
        };
        self.clocks.reported.resize(n, false);
    }

    /// Writes the held values over the clocked outputs just computed (clocked modes only).
    pub fn apply_held(&mut self) {
        if self.clocks.mode == ClockMode::Off {
            return;
        }
        for &(j, x) in &self.clocks.held {
            match self.model.slot(j) {
                Some(SlotMut::Real(s)) => *s = x,
                Some(SlotMut::Integer(s)) => *s = x as i32,
                Some(SlotMut::Boolean(s)) => *s = x != 0.0,
                None => {}
            }
        }
    }

    /// Refuses clock i unless its next tick is at time t (names the clock, the time and the tick).
    pub fn check_due(&self, i: usize, t: f64) -> CallResult {
        let tick = self.tick_time(i, self.clocks.next[i])?;
        if self.is_at(i, tick, t)? {
            return Ok(());
        }
        Err(Fail::error(format!(
            "clock {} is not due at t = {t}: its next tick is at t = {tick} (tick {})",
            self.clock_decls()[i].name,
            self.clocks.next[i]
        )))
    }

    /// Runs the partition of clock i at its due tick t: the clocked outputs of the instant (computed
    /// once per instant, before any state advanced), then one interval of the model's step if the clock
    /// steps; the clock's next tick follows.
    pub fn run_partition(&mut self, i: usize, t: f64) -> CallResult {
        self.check_due(i, t)?;
        let tick = self.tick_time(i, self.clocks.next[i])?;
        let (interval, _) = self.clock_timing(i)?;
        // the same instant for two clocks may differ in the last bits (0.2 + 5·0.2 and 6·0.2)
        let snap_here = match &self.clocks.snap {
            Some((s, _)) => self.is_at(i, *s, tick)?,
            None => false,
        };
        if !snap_here {
            self.model.update_outputs(tick).map_err(|e| {
                Fail::error(format!(
                    "outputs at the tick t = {tick} of clock {}: {e}",
                    self.clock_decls()[i].name
                ))
            })?;
            let n = self.clock_decls().len();
            let all: Vec<usize> = (0..n).flat_map(|c| self.clocked_indices(c)).collect();
            self.clocks.snap = Some((tick, self.read(&all)));
        }
        let mine = self.clocked_indices(i);
        if let Some((_, snap)) = &self.clocks.snap {
            for (j, x) in snap.iter().filter(|(j, _)| mine.contains(j)) {
                if let Some(h) = self.clocks.held.iter_mut().find(|(k, _)| k == j) {
                    h.1 = *x;
                }
            }
        }
        if self.clock_decls()[i].steps {
            self.model.do_step(tick, interval).map_err(|e| {
                Fail::error(format!(
                    "partition of clock {} at t = {tick}: {e}",
                    self.clock_decls()[i].name
                ))
            })?;
        }
        self.clocks.next[i] += 1;
        self.clocks.active[i] = false;
        self.run.outputs_dirty = true;
        Ok(())
    }

    /// Runs the partitions of the activated clocks, in clock order (at the update of the discrete
    /// states, or when a clocked output is read before it).
    pub fn run_active_partitions(&mut self) -> CallResult {
        for i in 0..self.clock_decls().len() {
            if self.clocks.active[i] {
                self.run_partition(i, self.run.time)?;
            }
        }
        Ok(())
    }

    /// The earliest next tick of any clock.
    pub fn next_tick(&self) -> CallResult<f64> {
        let mut t = f64::INFINITY;
        for i in 0..self.clock_decls().len() {
            t = t.min(self.tick_time(i, self.clocks.next[i])?);
        }
        Ok(t)
    }

    /// A step from t to t + h in clocked stepping: refused when it would pass a tick that was not
    /// activated (a tick at t + h is the next event, not passed).
    pub fn check_no_tick_passed(&self, t: f64, h: f64) -> CallResult {
        for i in 0..self.clock_decls().len() {
            let tick = self.tick_time(i, self.clocks.next[i])?;
            if tick < t + h && !self.is_at(i, tick, t + h)? {
                return Err(Fail::error(format!(
                    "the step from t = {t} to {} passes the tick t = {tick} of clock {}, which was not activated (enter Event Mode at it and activate the clock)",
                    t + h,
                    self.clock_decls()[i].name
                )));
            }
        }
        Ok(())
    }

    /// Checks restored clock bookkeeping against this instance (its mode and its model's clocks).
    pub fn check_clocks(&self, c: &Clocks) -> CallResult {
        let n = self.clock_decls().len();
        let bad = |why: &str| Err(Fail::error(format!("FMU state: clock bookkeeping {why}")));
        if c.mode != self.clocks.mode {
            return bad(&format!(
                "was taken in clock mode {:?}, this instance runs {:?}",
                c.mode, self.clocks.mode
            ));
        }
        if c.mode == ClockMode::Off {
            return Ok(());
        }
        let held_len: usize = (0..n).map(|i| self.clocked_indices(i).len()).sum();
        if c.active.len() != n || c.next.len() != n || c.reported.len() != n || c.held.len() != held_len {
            return bad("does not match the model's clocks");
        }
        if c.next.iter().any(|k| !(0..sample_grid::MAX_INDEX).contains(k)) {
            return bad("has a tick index out of range");
        }
        let finite = |v: &[(usize, f64)]| v.iter().all(|(j, x)| *j < self.entry.decls.len() && x.is_finite());
        if !finite(&c.held) || c.snap.as_ref().is_some_and(|(t, v)| !t.is_finite() || !finite(v)) {
            return bad("holds a value that is not finite or not an output");
        }
        Ok(())
    }
}
