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

/// Largest sample index |k| a unit counts: 2^53. Every integer up to it is an exact f64, so the index
/// of a time (t/T rounded) converts to an integer without loss and back (k T) without a second rounding
/// of k, and every index difference or ±1 stays far inside i64. Beyond it consecutive indices are no
/// longer distinct doubles and a saturating conversion followed by `k − 1` would wrap (a sample loop
/// of 2^64 turns): such times are refused. (The grid tolerance of at most 1e-3 T exceeds the spacing
/// of doubles only below about 2^42 T; between 2^42 and 2^53 periods a master's times may be refused
/// as off the grid, with a message, but never loop.)
pub const MAX_INDEX: i64 = 1 << 53;

/// The integer of an already rounded quotient q = x/T, if |q| ≤ [`MAX_INDEX`] (exact conversion).
pub fn exact_index(q: f64) -> Option<i64> {
    (q.is_finite() && q.abs() <= MAX_INDEX as f64).then_some(q as i64)
}

/// Why a time x has no sample index on the grid of period T (for messages naming the bound).
pub fn beyond(what: &str, x: f64, period: f64) -> String {
    format!(
        "{what} {x} s is {:e} sample periods of {period} s from t = 0: at most 2^53 = {:e} periods (|t| <= {:e} s) can be counted exactly",
        x / period,
        MAX_INDEX as f64,
        MAX_INDEX as f64 * period
    )
}

/// Checks that a time x lies within [`MAX_INDEX`] periods of 0 (`what` names it in the message).
pub fn check_time(what: &str, x: f64, period: f64) -> Result<(), String> {
    match exact_index((x / period).round()) {
        Some(_) => Ok(()),
        None => Err(beyond(what, x, period)),
    }
}

fn index_of(q: f64, x: f64, period: f64) -> Result<i64, String> {
    exact_index(q).ok_or_else(|| beyond("time", x, period))
}

/// The grid index k with |x − k T| ≤ `tolerance(scale, T)`, if any; an error when x/T is beyond
/// [`MAX_INDEX`].
pub fn on_grid(x: f64, period: f64, scale: f64) -> Result<Option<i64>, String> {
    let k = index_of((x / period).round(), x, period)?;
    Ok(((x - k as f64 * period).abs() <= tolerance(scale, period)).then_some(k))
}

/// Index k of the interval [k T, (k+1) T) holding t, where a t within the tolerance of a grid instant
/// counts as on it (so t = 0.3 − 1e-17 or a summed 0.30000000000000004 are both in interval 3 of T = 0.1).
pub fn index_at(t: f64, period: f64, scale: f64) -> Result<i64, String> {
    match on_grid(t, period, scale)? {
        Some(k) => Ok(k),
        None => index_of((t / period).floor(), t, period),
    }
}

/// Index of the last grid instant strictly before `t_end` (−1 if none), where an instant within the
/// tolerance of t_end counts as at t_end (not before it): the samples a step ending at t_end takes.
pub fn last_before(t_end: f64, period: f64, scale: f64) -> Result<i64, String> {
    let k = match on_grid(t_end, period, scale)? {
        Some(k) => k,
        None => index_of((t_end / period).ceil(), t_end, period)?,
    };
    Ok(k - 1) // |k| <= 2^53: no overflow
}

/// The number k ≥ 0 of sample times in a communication step h (|h − k T| within the tolerance of a
/// step ending at magnitude `scale`), or `None` when h is no whole multiple of T (or more than
/// [`MAX_INDEX`] periods long). A step within the tolerance of 0 (a master's last step of rounding
/// size) takes no sample.
pub fn samples_in(h: f64, period: f64, scale: f64) -> Option<i64> {
    on_grid(h, period, scale.abs().max(h.abs()))
        .ok()
        .flatten()
        .filter(|k| *k >= 0)
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
        check_time("communication point", t, per)?;
        check_time("step end", t + h, per)?;
        check_time("communication step", h, per)?;
        let due = t0 + n as f64 * per;
        let tol = tolerance(t.abs().max(t0.abs()), per);
        if (t - due).abs() > tol {
            return Err(format!(
                "communication point {t} s is not the next sample instant start + {n} step = {due} s (step = {per} s; a point within {tol:e} s of it is taken as it)"
            ));
        }
        u64::try_from(k).map_err(|_| format!("communication step {h} s takes a negative number of samples"))
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
        assert_eq!(index_at(0.3, 0.1, 0.3), Ok(3)); // 0.3 / 0.1 = 2.9999999999999996
        assert_eq!(index_at(0.29, 0.1, 0.29), Ok(2));
        assert_eq!(index_at(0.0, 0.1, 0.0), Ok(0));
        assert_eq!(index_at(-0.05, 0.1, 0.05), Ok(-1));
        assert_eq!(last_before(0.0, 0.1, 0.0), Ok(-1));
        assert_eq!(last_before(0.3, 0.1, 0.3), Ok(2));
        assert_eq!(last_before(0.35, 0.1, 0.35), Ok(3));
        assert_eq!(last_before(0.01, 0.1, 0.01), Ok(0));
        // the summed clock of 3 steps of 0.1 (0.30000000000000004) is the instant 0.3
        assert_eq!(index_at(summed(0.1, 3), 0.1, 0.3), Ok(3));
        assert_eq!(last_before(summed(0.1, 3), 0.1, 0.3), Ok(2));
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
                assert_eq!(
                    on_grid(t, per, t),
                    Ok(Some(k as i64 * ratio)),
                    "h = {h}, step {k}, t = {t}"
                );
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

    /// Times beyond 2^53 periods are refused with the bound named; up to it the indices are exact and
    /// their neighbours (k - 1) do not wrap (before: `(-1e20 / 0.1).ceil() as i64` saturated at
    /// i64::MIN and `- 1` wrapped to i64::MAX, a sample loop of 2^64 turns).
    #[test]
    fn times_beyond_the_exact_index_range_are_refused() {
        let lim = 9_007_199_254_740_992.0; // 2^53, written out independently of MAX_INDEX
        assert_eq!(last_before(lim * 0.5, 0.5, lim * 0.5), Ok((1i64 << 53) - 1));
        assert_eq!(index_at(-lim, 1.0, lim), Ok(-(1i64 << 53)));
        for t in [-1e20, 1e20, -1e18, 1e18, 1e100, -1e300, 1e300, f64::MAX, -f64::MAX] {
            for f in [index_at, last_before] {
                let e = f(t, 0.1, t.abs()).unwrap_err();
                assert!(e.contains(&format!("{t} s")) && e.contains("2^53"), "{e}");
            }
            assert_eq!(on_grid(t, 0.1, t.abs()).map_err(|_| ()), Err(()));
            assert_eq!(samples_in(t.abs(), 0.1, t.abs()), None);
        }
        // f64 infinities and NaN are refused the same way, never cast
        assert!(index_at(f64::INFINITY, 0.1, 1.0).is_err() && last_before(f64::NAN, 0.1, 1.0).is_err());
        let c = SampleCounter {
            start: -1e20,
            period: 0.1,
        };
        let e = c.step(0, -1e20, 0.1, "x").unwrap_err();
        assert!(
            e.contains("communication point -100000000000000000000 s") && e.contains("2^53"),
            "{e}"
        );
        assert!(check_time("startTime", 1e14, 0.1).is_ok() && check_time("startTime", 1e14, 0.01).is_err());
    }
}
