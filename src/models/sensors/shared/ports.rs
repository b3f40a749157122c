//! Port and parameter blocks the sensors embed. The truth inputs carry the plant's output names
//! (`q_*`, `w_*`), so a sensor placed beside `AttitudePlant` is fed by name; the orbit parameters keep the
//! plant's names and value references (160–164), so one set of orbit values serves plant and sensors.

use crate::declare_variables;

declare_variables! {
    /// The true attitude, from `AttitudePlant.q_*`.
    pub struct TrueAttitude {
        0 => q: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "True attitude quaternion of B relative to R (the plant's q)";
    }
}

declare_variables! {
    /// The plant's circular orbit and dipole field (same names, value references and defaults as
    /// `AttitudePlant`).
    pub struct OrbitParams {
        160 => mu: Real = 3.986004418e14, Parameter, "m3/s2", "Earth gravitational parameter (as the plant)", Positive;
        161 => orbit_radius: Real = 7078137.0, Parameter, "m", "Circular orbit radius (as the plant; 700 km altitude)", Positive;
        162 => orbit_inclination: Real = 1.7104226669544429, Parameter, "rad", "Orbit inclination (as the plant; 98 deg)";
        163 => orbit_arg_lat0: Real = 0.0, Parameter, "rad", "Argument of latitude at t = 0 (as the plant)";
        164 => earth_dipole: Real = 7.96e15, Parameter, "T.m3", "Earth dipole strength M_E (as the plant)";
    }
}

declare_variables! {
    /// The sun's apparent position.
    pub struct SunParams {
        165 => sun_ecliptic_longitude: Real = 0.0, Parameter, "rad", "Ecliptic longitude lambda_0 of the sun at t = 0 (0 = vernal equinox; project choice)";
    }
}

impl OrbitParams {
    pub fn orbit(&self) -> crate::math::environment::CircularOrbit {
        crate::math::environment::CircularOrbit {
            mu: self.mu,
            radius: self.orbit_radius,
            inclination: self.orbit_inclination,
            arg_lat0: self.orbit_arg_lat0,
            dipole: self.earth_dipole,
        }
    }
}
