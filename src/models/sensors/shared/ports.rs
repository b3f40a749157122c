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

// The environment inputs (issue 43), read with `environment_inputs = 1` only: named as the outputs of
// `Environment` (`b_eci`, `sun_eci`, `eclipse`) and `Orbit` (`r`, `jd_utc`), so they connect by name, with
// one value reference each across the family.

declare_variables! {
    /// The true geomagnetic field, from `Environment.b_eci_*`.
    pub struct FieldInput {
        7 => b_eci: Vec3 = [0.0; 3], Input, "T", "Geomagnetic field at the spacecraft, inertial (ECI, J2000) axes, from Environment (environment_inputs = 1; the start value 0 is refused)";
    }
}

declare_variables! {
    /// The true sun and shadow, from `Environment.sun_eci_*` and `Environment.eclipse`.
    pub struct SunInputs {
        10 => sun_eci: Vec3 = [0.0; 3], Input, "", "Direction Earth to sun, inertial (ECI, J2000) axes, from Environment; normalised here (environment_inputs = 1; the start value 0 is refused)";
        13 => eclipse: Real = 1.0, Input, "", "Visible fraction of the solar disk, 0 (umbra) to 1 (full sun), from Environment (environment_inputs = 1; unwired: always full sun)";
    }
}

declare_variables! {
    /// The position and date the flight computer knows, from `Orbit.r_*` and `Orbit.jd_utc`.
    pub struct PositionInputs {
        14 => r: Vec3 = [0.0; 3], Input, "m", "Spacecraft position, inertial (ECI, J2000) axes, e.g. from GPS = Orbit's r (environment_inputs = 1; the start value 0 is refused)";
        17 => jd_utc: Real = 0.0, Input, "d", "UTC Julian date, from Orbit (environment_inputs = 1; the start value 0 is refused)";
    }
}
