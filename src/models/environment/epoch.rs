//! The epoch block of the environment family: the UTC calendar date and time at simulation time 0
//! (value references 100–105, the same in every model of the family that needs the date).

use crate::declare_variables;
use crate::math::time_scales::{julian_date, DAY, JD_J2000};

declare_variables! {
    /// UTC date and time at simulation time t = 0.
    pub struct EpochParams {
        100 => epoch_year: Integer = 2026, Parameter, "", "Epoch (t = 0): UTC calendar year";
        101 => epoch_month: Integer = 1, Parameter, "", "Epoch: month (1-12)", Range(1.0, 12.0);
        102 => epoch_day: Integer = 1, Parameter, "", "Epoch: day of the month (1-31)", Range(1.0, 31.0);
        103 => epoch_hour: Integer = 0, Parameter, "", "Epoch: hour of the day, UTC (0-23)", Range(0.0, 23.0);
        104 => epoch_minute: Integer = 0, Parameter, "", "Epoch: minute (0-59)", Range(0.0, 59.0);
        105 => epoch_second: Real = 0.0, Parameter, "s", "Epoch: second of the minute, UTC (0 <= s < 60)", Range(0.0, 60.0);
    }
}

impl EpochParams {
    /// Days of UTC from J2000.0 at t = 0; refuses a day the month does not have.
    pub fn days_from_j2000(&self) -> Result<f64, String> {
        let (y, m, d) = (self.epoch_year, self.epoch_month as u32, self.epoch_day as u32);
        let jd0 = julian_date(y, m, 1, 0.0);
        let next = if m == 12 {
            julian_date(y + 1, 1, 1, 0.0)
        } else {
            julian_date(y, m + 1, 1, 0.0)
        };
        if f64::from(d) > next - jd0 {
            return Err(format!(
                "epoch: {y}-{m:02}-{d:02} is not a calendar date (epoch_year/epoch_month/epoch_day)"
            ));
        }
        let sod = f64::from(self.epoch_hour * 3600 + self.epoch_minute * 60) + self.epoch_second;
        Ok(julian_date(y, m, d, sod) - JD_J2000)
    }
}

/// Julian date (UTC) of `days` from J2000.0.
pub fn julian(days: f64) -> f64 {
    JD_J2000 + days
}

/// Days from J2000.0 at simulation time `t` (s) from an epoch `days0` days from J2000.0.
pub fn days_at(days0: f64, t: f64) -> f64 {
    days0 + t / DAY
}
