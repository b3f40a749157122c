//! SGP4 through the `sgp4` crate (a pure-Rust port of the reference implementation of [Vallado-2006]):
//! the two-line element set arrives as numbers, the propagator is set up with the WGS-72 constants and
//! the IAU sidereal-time expression, the combination of the reference implementation's improved mode
//! ("i", the default of the Python `sgp4` package), and its TEME output is converted to SI units.

use nalgebra::Vector3;
use std::f64::consts::PI;

/// Earth radius of WGS-72 (m): the length unit of SGP4 and of B*.
pub const WGS72_RADIUS: f64 = 6_378_135.0;
/// Julian date of J2000.0 (2000-01-01 12:00).
const JD_J2000: f64 = 2_451_545.0;

/// The numbers of a two-line element set, in SI units.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tle {
    /// Epoch, Julian date (UTC).
    pub epoch_jd: f64,
    /// Mean motion n (rad/s; the TLE's rev/day times 2π/86 400).
    pub n: f64,
    pub e: f64,
    pub i: f64,
    pub raan: f64,
    pub argp: f64,
    /// Mean anomaly M (rad).
    pub m: f64,
    /// Drag term B* (1/m; the TLE's value in 1/earth radii divided by [`WGS72_RADIUS`]).
    pub bstar: f64,
}

/// Builds the SGP4 propagator; refuses elements SGP4 cannot take, naming the parameter.
pub fn propagator(t: &Tle) -> Result<sgp4::Constants, String> {
    if !(t.e >= 0.0 && t.e < 1.0) {
        return Err(format!("tle_eccentricity = {} must lie in [0, 1)", t.e));
    }
    let orbit = sgp4::Orbit::from_kozai_elements(&sgp4::WGS72, t.i, t.raan, t.e, t.argp, t.m, t.n * 60.0)
        .map_err(|e| format!("tle_mean_motion = {} rad/s is not usable by SGP4 ({e:?})", t.n))?;
    let years = (t.epoch_jd - JD_J2000) / 365.25;
    sgp4::Constants::new(sgp4::WGS72, sgp4::iau_epoch_to_sidereal_time, years, t.bstar * WGS72_RADIUS, orbit)
        .map_err(|e| format!("SGP4 cannot start from these elements (eccentricity {})", e.0))
}

/// Position (m) and velocity (m/s) in TEME `dt` seconds after the TLE epoch (negative: before it);
/// refused where SGP4 fails or the satellite is below the WGS-72 equatorial radius (decayed).
pub fn propagate(c: &sgp4::Constants, dt: f64) -> Result<(Vector3<f64>, Vector3<f64>), String> {
    let p = c
        .propagate(sgp4::MinutesSinceEpoch(dt / 60.0))
        .map_err(|e| format!("SGP4 fails {dt} s after the TLE epoch: {e}"))?;
    let r = Vector3::from(p.position) * 1e3;
    let v = Vector3::from(p.velocity) * 1e3;
    // the reference implementation's error 6: the satellite is under the surface
    if r.norm() < WGS72_RADIUS {
        return Err(format!("the satellite has decayed {dt} s after the TLE epoch (|r| = {} m)", r.norm()));
    }
    Ok((r, v))
}

/// Mean motion of a TLE in rev/day as rad/s (for readers who copy numbers from a TLE).
pub fn rev_per_day(n: f64) -> f64 {
    n * 2.0 * PI / 86_400.0
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEG: f64 = PI / 180.0;

    /// Satellite 00005 of the SGP4 verification set (TEME example of [Vallado-2006]):
    /// 1 00005U 58002B   00179.78495062  .00000023  00000-0  28098-4 0  4753
    /// 2 00005  34.2682 348.7242 1859667 331.7664  19.3264 10.82419157413667
    fn sat5() -> Tle {
        // epoch 2000 day 179.78495062: JD of 2000-01-00 0h is 2451543.5
        Tle {
            epoch_jd: 2_451_543.5 + 179.784_950_62,
            n: rev_per_day(10.824_191_57),
            e: 0.185_966_7,
            i: 34.2682 * DEG,
            raan: 348.7242 * DEG,
            argp: 331.7664 * DEG,
            m: 19.3264 * DEG,
            bstar: 0.28098e-4 / WGS72_RADIUS,
        }
    }

    #[test]
    fn verification_satellite_matches_the_published_table() {
        // [Vallado-2006] tcppver.out for 00005 (km, km/s), to the table's last digit (10 µm, 1 µm/s
        // after rounding)
        let c = propagator(&sat5()).unwrap();
        let table = [
            (0.0, [7022.46529266, -1400.08296755, 0.03995155], [1.893841015, 6.405893759, 4.534807250]),
            (360.0, [-7154.03120202, -3783.17682504, -3536.19412294], [4.741887409, -4.151817765, -2.093935425]),
            (1440.0, [-938.55923943, -6268.18748831, -4294.02924751], [7.536105209, -0.427127707, 0.989878080]),
        ];
        for (minutes, r_km, v_kms) in table {
            let (r, v) = propagate(&c, minutes * 60.0).unwrap();
            let dr = (r - Vector3::from(r_km) * 1e3).norm();
            let dv = (v - Vector3::from(v_kms) * 1e3).norm();
            assert!(dr < 2e-5 && dv < 2e-6, "t = {minutes} min: |dr| = {dr} m, |dv| = {dv} m/s");
        }
    }

    #[test]
    fn bad_elements_are_refused_by_name() {
        let t = Tle { e: 1.2, ..sat5() };
        assert!(propagator(&t).unwrap_err().contains("tle_eccentricity"));
        let t = Tle { n: -1e-3, ..sat5() };
        assert!(propagator(&t).unwrap_err().contains("tle_mean_motion"));
    }
}
