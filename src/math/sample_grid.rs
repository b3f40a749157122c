//! The sample grid of the sampled units (PID, PI^λD^μ, sample-and-hold, sensors): instants t_k = k T
//! (or start + k T) numbered by an integer k, and the rule that turns a master's communication point or
//! step into grid indices despite the master's floating-point rounding.
//!
//! Masters compute their time in floating point: many sum t += h (after n steps the sum is off by up
//! to about n/2 ulp of t: 1e5 steps of 1 ms, 10 ms or 100 ms end 1.1e-10 s, 7.6e-10 s and 1.9e-8 s away
//! from 100 s, 1000 s and 10 000 s, i.e. 1.1e-12, 7.6e-13 and 1.9e-12 of the time, 5 000 to 10 000 ulp)
//! and clip the last step to the stop time (that step then differs from a multiple of T by the whole
//! accumulated error); others take each step as a difference of grid times (k+1) h − k h (a few ulp).
//! So a time x is taken as the grid instant k T when |x − k T| ≤ `tolerance(scale, T)`:
//!
//! ```text
//! tolerance = min(REL_TOL · max(scale, T), MAX_FRACTION · T),   REL_TOL = 1e-10,  MAX_FRACTION = 1e-3
//! ```
//!
//! where `scale` is the magnitude of the times the master added or subtracted to get x (|t| for a
//! communication point, |t + h| for a step). 1e-10 of the time (about 450 000 ulp) covers the sum of up
//! to about 5e6 steps; near t = 0 it is 1e-10 T, far below any deliberate mismatch (a step of 1.5 T, or
//! T (1 + 1e-6), is still refused); the cap keeps every tolerance far below T/2, so the nearest grid
//! instant is never ambiguous. The schedule itself is an integer sample counter: a unit never sums
//! floating-point time, and instants are computed as k T from the integer k.

/// The paragraph of a sampled unit's documentation that states the grid tolerance (appended to the
/// model's equations with `concat!`).
#[macro_export]
macro_rules! sample_grid_note {
    () => {
        "<p>Sample timing: the schedule is an integer sample counter (instants k T computed from the integer k, \
never a sum of times). A master's rounding is tolerated: a communication point or step end within \
1e-10 of the time (at most 1e-3 T) of a sample instant is taken as that instant, so masters that sum \
t += h (1e5 steps drift by about 2e-12 of the time) or clip the last step to the stop time give the \
same samples as a master passing exact multiples.</p>"
    };
}

/// Relative tolerance of a time on the sample grid (of the time's magnitude).
pub const REL_TOL: f64 = 1e-10;
/// The tolerance never exceeds this fraction of the sample time.
pub const MAX_FRACTION: f64 = 1e-3;

/// Largest distance |x − k T| at which a time x of magnitude `scale` counts as the grid instant k T.
pub fn tolerance(scale: f64, period: f64) -> f64 {
    (REL_TOL * scale.abs().max(period)).min(MAX_FRACTION * period)
}

/// The grid index k with |x − k T| ≤ `tolerance(scale, T)`, if any.
pub fn on_grid(x: f64, period: f64, scale: f64) -> Option<i64> {
    let k = (x / period).round();
    ((x - k * period).abs() <= tolerance(scale, period)).then_some(k as i64)
}

/// Index k of the interval [k T, (k+1) T) holding t, where a t within the tolerance of a grid instant
/// counts as on it (so t = 0.3 − 1e-17 or a summed 0.30000000000000004 are both in interval 3 of T = 0.1).
pub fn index_at(t: f64, period: f64, scale: f64) -> i64 {
    on_grid(t, period, scale).unwrap_or_else(|| (t / period).floor() as i64)
}

/// Index of the last grid instant strictly before `t_end` (−1 if none), where an instant within the
/// tolerance of t_end counts as at t_end (not before it): the samples a step ending at t_end takes.
pub fn last_before(t_end: f64, period: f64, scale: f64) -> i64 {
    on_grid(t_end, period, scale).unwrap_or_else(|| (t_end / period).ceil() as i64) - 1
}

/// The number k ≥ 0 of sample times in a communication step h (|h − k T| within the tolerance of a
/// step ending at magnitude `scale`), or `None` when h is no whole multiple of T. A step within the
/// tolerance of 0 (a master's last step of rounding size) takes no sample.
pub fn samples_in(h: f64, period: f64, scale: f64) -> Option<i64> {
    on_grid(h, period, scale.abs().max(h.abs())).filter(|k| *k >= 0)
}

/// A sample counter on the grid start + n T: checks that a master's communication point is the
/// counter's instant (to the tolerance) and turns a step into its number of samples.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SampleCounter {
    pub start: f64,
    pub period: f64,
}

impl SampleCounter {
    /// The samples a doStep(t, h) takes when `n` samples were taken before: `Err(reason)` when t is not
    /// the instant start + n T or h no whole multiple of T (to the tolerance).
    pub fn step(&self, n: u64, t: f64, h: f64, what: &str) -> Result<u64, String> {
        let (t0, per) = (self.start, self.period);
        let scale = t.abs().max(t0.abs()) + h.abs();
        let Some(k) = samples_in(h, per, scale) else {
            return Err(format!(
                "communication step {h} s is not an integer multiple of the sample time parameter step = {per} s ({what}; a step within {:e} s of a multiple is taken as that multiple)",
                tolerance(scale, per)
            ));
        };
        let due = t0 + n as f64 * per;
        let tol = tolerance(t.abs().max(t0.abs()), per);
        if (t - due).abs() > tol {
            return Err(format!(
                "communication point {t} s is not the next sample instant start + {n} step = {due} s (step = {per} s; a point within {tol:e} s of it is taken as it)"
            ));
        }
        Ok(k as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The time of a master that sums t += h, n times.
    fn summed(h: f64, n: usize) -> f64 {
        let mut t = 0.0;
        for _ in 0..n {
            t += h;
        }
        t
    }

    #[test]
    fn grid_instants_and_intervals() {
        assert_eq!(index_at(0.3, 0.1, 0.3), 3); // 0.3 / 0.1 = 2.9999999999999996
        assert_eq!(index_at(0.29, 0.1, 0.29), 2);
        assert_eq!(index_at(0.0, 0.1, 0.0), 0);
        assert_eq!(index_at(-0.05, 0.1, 0.05), -1);
        assert_eq!(last_before(0.0, 0.1, 0.0), -1);
        assert_eq!(last_before(0.3, 0.1, 0.3), 2);
        assert_eq!(last_before(0.35, 0.1, 0.35), 3);
        assert_eq!(last_before(0.01, 0.1, 0.01), 0);
        // the summed clock of 3 steps of 0.1 (0.30000000000000004) is the instant 0.3
        assert_eq!(index_at(summed(0.1, 3), 0.1, 0.3), 3);
        assert_eq!(last_before(summed(0.1, 3), 0.1, 0.3), 2);
    }

    /// Summed clocks over 1e5 steps (the error grows to 1.9e-8 s at 10 000 s) stay on the grid; their
    /// last clipped step (stop − t) is the whole multiple; a deliberate mismatch is not.
    #[test]
    fn summed_clocks_and_clipped_steps_stay_on_the_grid() {
        for (h, per) in [(1e-3f64, 1e-3f64), (1e-2, 1e-2), (0.1, 0.1), (0.1, 0.01)] {
            let n = 100_000;
            let ratio = (h / per).round() as i64;
            let (mut t, mut worst) = (0.0f64, 0.0f64);
            for k in 0..n {
                let exact = k as f64 * h;
                worst = worst.max((t - exact).abs());
                assert_eq!(on_grid(t, per, t), Some(k as i64 * ratio), "h = {h}, step {k}, t = {t}");
                t += h;
            }
            assert!(
                worst > 1e-11,
                "the sum drifts ({worst}): the test exercises the tolerance"
            );
            let stop = n as f64 * h;
            // the last step clipped to the stop time, from the sum before it
            let t_last = summed(h, n - 1);
            assert_eq!(
                samples_in(stop - t_last, per, stop),
                Some(ratio),
                "h = {h}: last step {}",
                stop - t_last
            );
            // a step of rounding size after a sum that fell short of the stop time takes no sample
            if t < stop {
                assert_eq!(samples_in(stop - t, per, stop), Some(0));
            }
            // steps as differences of grid times
            for k in [0usize, 1, 999, 99_999] {
                let hk = (k + 1) as f64 * h - k as f64 * h;
                assert_eq!(samples_in(hk, per, (k + 1) as f64 * h), Some(ratio));
            }
        }
    }

    #[test]
    fn a_step_that_is_no_multiple_is_not_taken() {
        assert_eq!(samples_in(0.0015, 0.001, 0.0015), None);
        assert_eq!(samples_in(0.001 * (1.0 + 1e-6), 0.001, 0.001), None);
        assert_eq!(samples_in(0.002, 0.001, 0.002), Some(2));
        assert_eq!(samples_in(0.0015, 0.001, 1e9), None); // the cap: 1e-3 T however late
        assert!(tolerance(1e12, 0.001) <= 1e-6);
        assert_eq!(tolerance(0.0, 0.001), 1e-13);
    }

    #[test]
    fn counter_checks_point_and_step() {
        let c = SampleCounter {
            start: 0.0,
            period: 0.001,
        };
        assert_eq!(c.step(0, 0.0, 0.001, "x"), Ok(1));
        assert_eq!(c.step(3, 0.003, 0.002, "x"), Ok(2));
        // the OMSimulator step: t = 19.99900000000146, h = 0.0009999999985410568
        assert_eq!(c.step(19_999, 19.99900000000146, 0.0009999999985410568, "x"), Ok(1));
        let e = c.step(3, 0.003, 0.0015, "the history is sampled at step").unwrap_err();
        assert!(
            e.contains("not an integer multiple of the sample time parameter step = 0.001 s"),
            "{e}"
        );
        let e = c.step(3, 0.0035, 0.001, "x").unwrap_err();
        assert!(
            e.contains("communication point 0.0035 s is not the next sample instant"),
            "{e}"
        );
        let c = SampleCounter {
            start: 2.5,
            period: 0.1,
        };
        assert_eq!(c.step(10, 3.5000000000000004, 0.1, "x"), Ok(1));
    }
}
