//! Orbit environment of the attitude plant (project choice): circular
//! orbit with right ascension of the ascending node 0, non-tilted dipole geomagnetic field, gravity
//! gradient torque; for the sensors, the sun direction on the ecliptic and the Earth's cylindrical
//! shadow. R is the Earth-centred inertial frame (equatorial).

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Circular orbit and dipole constants.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CircularOrbit {
    /// Gravitational parameter μ (m³/s²).
    pub mu: f64,
    /// Orbit radius r_orb (m).
    pub radius: f64,
    /// Inclination i (rad).
    pub inclination: f64,
    /// Argument of latitude at t = 0, u0 (rad).
    pub arg_lat0: f64,
    /// Earth dipole strength M_E (T·m³).
    pub dipole: f64,
}

impl CircularOrbit {
    /// Orbital rate n = sqrt(μ / r³).
    pub fn rate(&self) -> f64 {
        (self.mu / self.radius.powi(3)).sqrt()
    }

    /// Unit position vector r̂(t) = [cos u, sin u cos i, sin u sin i], u = u0 + n t.
    pub fn r_hat(&self, t: f64) -> Vector3<f64> {
        let (su, cu) = (self.arg_lat0 + self.rate() * t).sin_cos();
        let (si, ci) = self.inclination.sin_cos();
        Vector3::new(cu, su * ci, su * si)
    }

    /// Dipole field in R: B = (M_E / r³) [ẑ − 3 (ẑ·r̂) r̂] (T); points north at the equator.
    pub fn field_ref(&self, t: f64) -> Vector3<f64> {
        dipole_field(&self.r_hat(t), self.radius, self.dipole)
    }
}

/// Field of a dipole M_E aligned with ẑ (pointing south, as the Earth's) at r r̂: B = (M_E / r³) [ẑ − 3 (ẑ·r̂) r̂] (T).
pub fn dipole_field(r_hat: &Vector3<f64>, radius: f64, dipole: f64) -> Vector3<f64> {
    (Vector3::z() - r_hat * (3.0 * r_hat.z)) * (dipole / radius.powi(3))
}

/// Obliquity of the ecliptic ε (rad), 23.439 281° (J2000).
pub const OBLIQUITY: f64 = 0.409_092_627_750_149;
/// Mean motion of the sun on the ecliptic (rad/s): 2π per sidereal year of 365.256 363 days.
pub const SUN_RATE: f64 = 2.0 * std::f64::consts::PI / (365.256_363 * 86_400.0);
/// Equatorial Earth radius R_E (m), the radius of the shadow cylinder.
pub const EARTH_RADIUS: f64 = 6_378_137.0;

/// Unit vector Earth → sun in R: ŝ = [cos λ, sin λ cos ε, sin λ sin ε], ecliptic longitude
/// λ = λ0 + n_sun t (circular apparent solar orbit, obliquity ε).
pub fn sun_ref(lambda0: f64, t: f64) -> Vector3<f64> {
    let (sl, cl) = (lambda0 + SUN_RATE * t).sin_cos();
    let (se, ce) = OBLIQUITY.sin_cos();
    Vector3::new(cl, sl * ce, sl * se)
}

/// Cylindrical Earth shadow: the spacecraft at r r̂ is in eclipse when it is behind the Earth
/// (r̂·ŝ < 0) and within the shadow cylinder (r |r̂ × ŝ| < R_E).
pub fn in_eclipse(r_hat: &Vector3<f64>, radius: f64, sun: &Vector3<f64>) -> bool {
    r_hat.dot(sun) < 0.0 && radius * r_hat.cross(sun).norm() < EARTH_RADIUS
}

/// Gravity-gradient torque 3 n² r̂_b × (I r̂_b) with n² = μ / r³ and r̂_b the orbit radius direction
/// in body axes.
pub fn gravity_gradient(n2: f64, r_hat_b: &Vector3<f64>, inertia: &Matrix3<f64>) -> Vector3<f64> {
    r_hat_b.cross(&(inertia * r_hat_b)) * (3.0 * n2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leo() -> CircularOrbit {
        CircularOrbit {
            mu: 3.986004418e14,
            radius: 7078137.0,
            inclination: 98f64.to_radians(),
            arg_lat0: 0.0,
            dipole: 7.96e15,
        }
    }

    #[test]
    fn orbit_rate_and_period() {
        // 700 km circular orbit: period 2π sqrt(r³/μ) = 5926.0 s
        let p = 2.0 * std::f64::consts::PI / leo().rate();
        assert!((p - 5926.0).abs() < 1.0, "{p}");
        let o = leo();
        assert!((o.r_hat(p) - o.r_hat(0.0)).norm() < 1e-12);
        assert!((o.r_hat(123.0).norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn dipole_field_shape() {
        let mut o = leo();
        // at the equator (u = 0): B = M_E/r³ ẑ, points north; |B| at the surface ≈ 3.1e-5 T
        let b = o.field_ref(0.0);
        assert!(b.x.abs() < 1e-20 && b.y.abs() < 1e-20 && b.z > 0.0);
        o.radius = 6.378137e6;
        assert!((o.field_ref(0.0).norm() - 3.07e-5).abs() < 0.01e-5);
        // over the pole (u = 90°, i = 90°): B = −2 M_E/r³ ẑ, twice the equatorial strength
        o.inclination = std::f64::consts::FRAC_PI_2;
        o.arg_lat0 = std::f64::consts::FRAC_PI_2;
        let bp = o.field_ref(0.0);
        assert!((bp.z + 2.0 * o.dipole / o.radius.powi(3)).abs() < 1e-18);
    }

    #[test]
    fn sun_direction_and_shadow() {
        // λ = 0: vernal equinox direction x; λ = 90°: summer solstice, declination = ε
        assert!((sun_ref(0.0, 0.0) - Vector3::x()).norm() < 1e-15);
        let s = sun_ref(std::f64::consts::FRAC_PI_2, 0.0);
        assert!((s.z.asin() - 23.439281f64.to_radians()).abs() < 1e-12 && s.x.abs() < 1e-15);
        // one sidereal year later the sun is back; a quarter year moves it by 90°
        let year = 365.256363 * 86400.0;
        assert!((sun_ref(0.3, year) - sun_ref(0.3, 0.0)).norm() < 1e-12);
        assert!((sun_ref(0.0, year / 4.0).dot(&Vector3::x())).abs() < 1e-12);
        // 700 km orbit: behind the Earth on the sun line in shadow, beside it not; shadow half-angle
        // asin(R_E / r) = 64.3° about the anti-sun direction
        let r = 7078137.0;
        let sun = Vector3::x();
        assert!(in_eclipse(&-Vector3::x(), r, &sun));
        assert!(!in_eclipse(&Vector3::x(), r, &sun));
        let half = (EARTH_RADIUS / r).asin();
        for (off, inside) in [(half - 1e-6, true), (half + 1e-6, false)] {
            let rh = Vector3::new(-off.cos(), off.sin(), 0.0);
            assert_eq!(in_eclipse(&rh, r, &sun), inside, "{off}");
        }
    }

    #[test]
    fn gravity_gradient_vanishes_on_principal_axes() {
        let i = Matrix3::new(4.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 3.5);
        for r in [Vector3::x(), Vector3::y(), -Vector3::z()] {
            assert_eq!(gravity_gradient(1.0, &r, &i), Vector3::zeros());
        }
        // off-axis: τ = 3 n² r × I r, e.g. r = (1, 0, 1)/√2 → τ_y = 3 n² (I_xx − I_zz)/2 · (−1)… checked by hand:
        let r = Vector3::new(1.0, 0.0, 1.0) / 2f64.sqrt();
        let t = gravity_gradient(2.0, &r, &i);
        // r × I r = (0, r_z I_xx r_x − r_x I_zz r_z, 0) = (0, (4 − 3.5)/2, 0)
        assert!((t - Vector3::new(0.0, 3.0 * 2.0 * 0.25, 0.0)).norm() < 1e-15, "{t}");
    }
}
