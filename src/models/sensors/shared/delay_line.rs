//! Sampling schedule and delay line of the sampled units.
//!
//! Samples are taken at t_k = k T (k = 0, 1, …), each from the inputs the unit holds at t_k (inputs are
//! held over a communication step, so a sample strictly inside a step sees the inputs of the step's
//! start). Sample k is delivered at t_k + d (d = delay or latency ≥ 0): the output at t is the sample of
//! index k_d(t) = ⌊(t − d)/T⌋ (`math::sample_grid::index_at`: a time within the grid tolerance — 1e-10
//! of the time, at most 1e-3 T — of an instant k T counts as on it, so a master's summed or clipped time
//! gives the same samples as exact multiples), i.e. a zero-order hold of the samples shifted by d. Before the first delivery (t < d) and while
//! the delivered sample is not usable (a sensor's availability flag), the output is the last usable
//! delivered sample (`held`, initially the unit's initial output).
//!
//! `advance` latches every sample taken in [t, t + h) in a queue and drops the ones superseded at t + h,
//! so the queue holds at most ⌈d/T⌉ + 2 samples; `at` reads the delivered sample, computing it from the
//! current inputs when its instant is the current time and it is not latched yet (d = 0). Both are pure
//! functions of (last latched index, queue, held) and the inputs: an FMU state restores them exactly.

use serde::{Deserialize, Serialize};

use crate::math::sample_grid;
use crate::model::ModelResult;

/// At most this many samples per doStep (bounded work: a longer step is refused before any work).
pub const MAX_SAMPLES_PER_CALL: i64 = 1_000_000;

/// Index of the last sample instant k T strictly before `t_end` (−1 if none; an instant within the grid
/// tolerance of t_end is at t_end): samples latched by a step that ends at t_end.
pub fn last_sample_before(t_end: f64, period: f64) -> Result<i64, String> {
    sample_grid::last_before(t_end, period, t_end)
}

/// Index k of the sample interval [k T, (k+1) T) holding t (on the grid to its tolerance).
pub fn sample_index(t: f64, period: f64) -> Result<i64, String> {
    sample_grid::index_at(t, period, t)
}

/// Index of the sample delivered at t with delay d: the interval of t − d, on the grid to the
/// tolerance of the times t and d the difference is made of.
pub fn delivered_index(t: f64, delay: f64, period: f64) -> Result<i64, String> {
    sample_grid::index_at(t - delay, period, t.abs() + delay.abs())
}

/// Latched samples of type `T` awaiting delivery, and the last delivered usable one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DelayLine<T> {
    /// Index of the last latched sample (−1: none yet).
    pub last: i64,
    /// (index, sample) of the latched samples not yet superseded, ascending.
    pub queue: Vec<(i64, T)>,
    /// The last delivered usable sample (the initial output before any).
    pub held: T,
}

impl<T: Clone> DelayLine<T> {
    /// A line whose first sample has index `first` (the interval of the start time).
    pub fn new(initial: T, first: i64) -> Self {
        DelayLine {
            last: first - 1,
            queue: Vec::new(),
            held: initial,
        }
    }

    /// The output at t: (sample, usable). `fresh(k)` computes sample k from the current inputs (used
    /// when sample k is due now and not latched yet).
    pub fn at(
        &self,
        t: f64,
        period: f64,
        delay: f64,
        fresh: impl FnOnce(i64) -> T,
        usable: impl Fn(&T) -> bool,
    ) -> Result<(T, bool), String> {
        let kd = delivered_index(t, delay, period)?;
        if kd < 0 {
            return Ok((self.held.clone(), false));
        }
        let s = if kd > self.last {
            Some(fresh(kd))
        } else {
            self.queue.iter().find(|(k, _)| *k == kd).map(|(_, s)| s.clone())
        };
        Ok(match s {
            Some(s) if usable(&s) => (s, true),
            _ => (self.latest_usable_before(kd, &usable), false),
        })
    }

    /// The last usable sample delivered before index kd (queue entries below kd, else `held`).
    fn latest_usable_before(&self, kd: i64, usable: &impl Fn(&T) -> bool) -> T {
        self.queue
            .iter()
            .rev()
            .find(|(k, s)| *k < kd && usable(s))
            .map_or_else(|| self.held.clone(), |(_, s)| s.clone())
    }

    /// Latches the samples of [t, t + h) (`sample(k)` with the held inputs) and drops the ones superseded
    /// at t + h (updating `held`). Refuses more than `MAX_SAMPLES_PER_CALL` samples.
    pub fn advance(
        &mut self,
        t: f64,
        h: f64,
        period: f64,
        delay: f64,
        mut sample: impl FnMut(i64) -> T,
        usable: impl Fn(&T) -> bool,
    ) -> ModelResult {
        let k_end = last_sample_before(t + h, period)?;
        // checked: a restored `last` is bounded by `check`, but never wrap on the way to the loop
        let first = self
            .last
            .checked_add(1)
            .ok_or("delay line: last sample index overflows")?;
        let n = k_end.checked_sub(first).ok_or("delay line: sample count overflows")?;
        if n >= MAX_SAMPLES_PER_CALL {
            return Err(format!(
                "a step to t = {} takes {} samples of period {period} s (at most {MAX_SAMPLES_PER_CALL} per step)",
                t + h,
                n + 1
            ));
        }
        let kd = delivered_index(t + h, delay, period)?;
        // drop what is superseded at t + h: entries below kd (the last usable of them becomes `held`),
        // then latch the new samples (those already superseded only update `held`)
        let n_old = self.queue.iter().take_while(|(k, _)| *k < kd).count();
        if let Some((_, s)) = self.queue[..n_old].iter().rev().find(|(_, s)| usable(s)) {
            self.held = s.clone();
        }
        self.queue.drain(..n_old);
        for k in first..=k_end {
            let s = sample(k);
            if k >= kd {
                self.queue.push((k, s));
            } else if usable(&s) {
                self.held = s;
            }
        }
        self.last = self.last.max(k_end);
        Ok(())
    }

    /// Invariants of a restored line: ascending indices not above `last`, at most `max_len` entries.
    pub fn check(&self, max_len: usize, first: i64) -> ModelResult {
        if self.last < first - 1 || self.last >= sample_grid::MAX_INDEX || self.queue.len() > max_len {
            return Err(format!(
                "restored state: delay line with last index {} and {} entries (at most {max_len})",
                self.last,
                self.queue.len()
            ));
        }
        if self.queue.windows(2).any(|w| w[0].0 >= w[1].0) || self.queue.last().is_some_and(|(k, _)| *k > self.last) {
            return Err("restored state: delay line indices are not ascending up to the last latched sample".into());
        }
        Ok(())
    }
}

/// Longest queue of a line with this period and delay (for `check`).
pub fn max_queue(period: f64, delay: f64) -> usize {
    (delay / period).ceil() as usize + 3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_instants_before_a_step_end() {
        assert_eq!(last_sample_before(0.0, 0.1), Ok(-1));
        assert_eq!(last_sample_before(0.3, 0.1), Ok(2)); // 0.3 = 3·0.1 is not exact in binary
        assert_eq!(last_sample_before(0.35, 0.1), Ok(3));
        assert_eq!(last_sample_before(0.01, 0.1), Ok(0));
    }

    /// Samples of u(t) = t² at k T, delivered at k T + d: the output at t is u(⌊(t − d)/T⌋ T).
    #[test]
    fn shifted_staircase_with_whole_and_fractional_delays() {
        let (period, h) = (0.1, 0.025);
        for delay in [0.0, 0.1, 0.2, 0.05, 0.125, 0.37] {
            let mut line = DelayLine::new(-1.0, 0);
            for n in 0..200 {
                let t = n as f64 * h;
                let u = |k: i64| (k as f64 * period).powi(2);
                let (y, ok) = line.at(t, period, delay, &u, |_| true).unwrap();
                let kd = ((t - delay) / period + 1e-9).floor() as i64;
                let want = if kd < 0 { -1.0 } else { u(kd) };
                assert_eq!(y, want, "delay {delay}, t = {t}");
                assert_eq!(ok, kd >= 0);
                // the sample taken inside the step sees the input held at the step's start: here u
                // is evaluated at the sample instant, as for an input that changes only at k T
                line.advance(t, h, period, delay, u, |_| true).unwrap();
                assert!(line.queue.len() <= max_queue(period, delay), "{}", line.queue.len());
                line.check(max_queue(period, delay), 0).unwrap();
            }
        }
    }

    #[test]
    fn unusable_samples_keep_the_last_usable_one() {
        let (period, h) = (1.0, 0.5);
        let mut line = DelayLine::new(0.0, 0);
        let mut out = vec![];
        for n in 0..12 {
            let t = n as f64 * h;
            // samples 2 and 3 are unusable (negative)
            let u = |k: i64| {
                if (2..=3).contains(&k) {
                    -(k as f64)
                } else {
                    k as f64 + 10.0
                }
            };
            out.push(line.at(t, period, 0.0, &u, |s| *s >= 0.0).unwrap());
            line.advance(t, h, period, 0.0, u, |s| *s >= 0.0).unwrap();
        }
        let ys: Vec<f64> = out.iter().map(|(y, _)| *y).collect();
        let oks: Vec<bool> = out.iter().map(|(_, ok)| *ok).collect();
        assert_eq!(
            ys,
            [10.0, 10.0, 11.0, 11.0, 11.0, 11.0, 11.0, 11.0, 14.0, 14.0, 15.0, 15.0]
        );
        assert_eq!(
            oks,
            [true, true, true, true, false, false, false, false, true, true, true, true]
        );
    }

    #[test]
    fn too_many_samples_in_one_step_are_refused() {
        let mut line = DelayLine::new(0.0, 0);
        let e = line.advance(0.0, 10.0, 1e-6, 0.0, |_| 1.0, |_| true).unwrap_err();
        assert!(e.contains("samples of period"), "{e}");
        assert_eq!(line, DelayLine::new(0.0, 0));
    }

    /// A start 1e20 s before t = 0 at T = 0.1 s (the case): refused at once, never a loop.
    #[test]
    fn a_time_beyond_the_index_range_is_refused_not_looped() {
        assert!(sample_index(-1e20, 0.1).unwrap_err().contains("2^53"));
        let mut line = DelayLine::new(0.0, 0);
        let e = line.advance(-1e20, 0.1, 0.1, 0.0, |_| 1.0, |_| true).unwrap_err();
        assert!(
            e.contains("-100000000000000000000 s") || e.contains("-99999999999999990000 s"),
            "{e}"
        );
        // a restored line whose last index is at the end of i64 is refused by `check`
        line.last = i64::MAX;
        assert!(line.check(4, 0).is_err());
        assert!(line.advance(0.0, 0.1, 0.1, 0.0, |_| 1.0, |_| true).is_err());
    }
}
