//! `Orbit`: the spacecraft's position and velocity in an Earth-centred inertial frame, propagated
//! numerically (two-body, zonal harmonics J2–J4, drag against a co-rotating atmosphere of a density that
//! arrives as an input) or by SGP4 from the numbers of a two-line element set; with the LVLH frame the
//! pointing modes need.

mod tle;

use nalgebra::SVector;
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::integrate::{Method, Stepper};
use crate::math::nutation;
use crate::math::orbit::{self, Elements, Gravity};
use crate::math::time_scales::{CENTURY, DAY, JD_J2000, TT_MINUS_UTC};
use crate::model::{check_derived, check_finite_state, Experiment, Model, ModelInfo, ModelResult, ParamEnum, StateDecl};

pub use tle::{rev_per_day, Tle, WGS72_RADIUS};

crate::param_enum! {
    /// `propagator`: how the orbit is computed.
    pub enum Propagator {
        /// 0: numerical integration of two-body + zonal harmonics + drag.
        Numerical = 0,
        /// 1: SGP4 from the TLE parameters (Co-Simulation only).
        Sgp4 = 1,
    }
}

crate::param_enum! {
    /// `sgp4_frame`: the axes of r and v in the SGP4 mode.
    pub enum Sgp4Frame {
        /// 0: SGP4's own TEME (true equator, mean equinox of date), unconverted.
        Teme = 0,
        /// 1: the J2000 mean equator and equinox (GCRF to the frame bias), as in the numerical mode.
        J2000 = 1,
    }
}

crate::param_enum! {
    /// `initial_state`: where the numerical propagation starts.
    pub enum InitialState {
        /// 0: classical elements `semi_major_axis` … `true_anomaly`.
        Elements = 0,
        /// 1: the state vector `init_r`, `init_v`.
        StateVector = 1,
    }
}

crate::param_enum! {
    /// `zonal_degree`: the highest zonal harmonic of the gravity field.
    pub enum ZonalDegree {
        TwoBody = 0,
        J2 = 2,
        J3 = 3,
        J4 = 4,
    }
}

declare_variables! {
    pub struct OrbitVars {
        0 => rho: Real = 0.0, Input, "kg/m3", "Atmospheric density at the spacecraft (e.g. the Environment unit's density); 0 = no drag";
        10 => r: Vec3 = [6_878_137.0, 0.0, 0.0], Output, "m", "Position, ECI (J2000/GCRF axes; SGP4's TEME in propagator 1 with sgp4_frame 0)";
        13 => v: Vec3 = [0.0, 0.0, 7612.6], Output, "m/s", "Velocity, ECI (same frame as r)";
        16 => t_utc: Real = 0.0, Output, "s", "Elapsed UTC seconds since the epoch epoch_jd_utc (the start time)";
        17 => jd_utc: Real = 2_451_545.0, Output, "d", "UTC Julian date, epoch_jd_utc + t_utc / 86400";
        18 => n_orb: Real = 0.0011, Output, "rad/s", "Osculating mean motion sqrt(mu / a^3), a from the vis-viva energy";
        19 => lvlh_x: Vec3 = [0.0, 0.0, 1.0], Output, "", "LVLH x axis in ECI: along-track (velocity side), x = y cross z";
        22 => lvlh_y: Vec3 = [0.0, 1.0, 0.0], Output, "", "LVLH y axis in ECI: negative orbit normal, -h/|h|";
        25 => lvlh_z: Vec3 = [-1.0, 0.0, 0.0], Output, "", "LVLH z axis in ECI: nadir, -r/|r|";
        30 => altitude: Real = 500e3, Output, "m", "Height above the equatorial radius, |r| - earth_radius (spherical, not geodetic)";
        31 => sma: Real = 6_878_137.0, Output, "m", "Osculating semi-major axis";
        100 => mu: Real = 3.986004418e14, Parameter, "m3/s2", "Gravitational parameter of the Earth (EGM-96)", Positive;
        101 => earth_radius: Real = 6_378_137.0, Parameter, "m", "Reference radius of the zonal harmonics (WGS-84 equatorial radius)", Positive;
        102 => j2: Real = 1.08262668355315e-3, Parameter, "", "Zonal coefficient J2 (EGM-96, unnormalised)";
        103 => j3: Real = -2.53265648533e-6, Parameter, "", "Zonal coefficient J3 (EGM-96, unnormalised)";
        104 => j4: Real = -1.61962159137e-6, Parameter, "", "Zonal coefficient J4 (EGM-96, unnormalised)";
        105 => earth_rate: Real = 7.292115e-5, Parameter, "rad/s", "Rotation rate of the Earth and of its atmosphere (about the frame's z axis)", NonNegative;
        106 => ballistic_coeff: Real = 50.0, Parameter, "kg/m2", "Ballistic coefficient B = m / (C_D A)", Positive;
        107 => tolerance: Real = 1e-12, Parameter, "", "Relative and absolute tolerance of the adaptive Dormand-Prince 5(4) on the state scaled by the initial radius and circular speed", Range(1e-14, 1e-3);
        108 => epoch_jd_utc: Real = 2_451_545.0, Parameter, "d", "Epoch: UTC Julian date of the start time (the instant of the initial state)", Range(2.0e6, 3.0e6);
        110 => semi_major_axis: Real = 6_878_137.0, Parameter, "m", "Initial osculating semi-major axis a (initial_state 0)", Positive;
        111 => eccentricity: Real = 0.0, Parameter, "", "Initial eccentricity e in [0, 1) (initial_state 0)", Range(0.0, 0.999999);
        112 => inclination: Real = 1.7000137, Parameter, "rad", "Initial inclination i (initial_state 0; default 97.4 deg, sun-synchronous at 500 km)";
        113 => raan: Real = 0.0, Parameter, "rad", "Initial right ascension of the ascending node (initial_state 0)";
        114 => arg_perigee: Real = 0.0, Parameter, "rad", "Initial argument of perigee (initial_state 0)";
        115 => true_anomaly: Real = 0.0, Parameter, "rad", "Initial true anomaly (initial_state 0)";
        116 => init_r: Vec3 = [6_878_137.0, 0.0, 0.0], Parameter, "m", "Initial position, ECI (initial_state 1)";
        119 => init_v: Vec3 = [0.0, -983.0, 7548.9], Parameter, "m/s", "Initial velocity, ECI (initial_state 1)";
        122 => tle_epoch_jd_utc: Real = 2_451_545.0, Parameter, "d", "TLE epoch as a UTC Julian date (propagator 1)", Range(2.0e6, 3.0e6);
        123 => tle_mean_motion: Real = 0.0011, Parameter, "rad/s", "TLE mean motion (rev/day times 2 pi / 86400; propagator 1)", Positive;
        124 => tle_eccentricity: Real = 0.001, Parameter, "", "TLE eccentricity (propagator 1)", Range(0.0, 0.999999);
        125 => tle_inclination: Real = 1.7, Parameter, "rad", "TLE inclination (propagator 1)";
        126 => tle_raan: Real = 0.0, Parameter, "rad", "TLE right ascension of the ascending node (propagator 1)";
        127 => tle_arg_perigee: Real = 0.0, Parameter, "rad", "TLE argument of perigee (propagator 1)";
        128 => tle_mean_anomaly: Real = 0.0, Parameter, "rad", "TLE mean anomaly (propagator 1)";
        129 => tle_bstar: Real = 0.0, Parameter, "1/m", "TLE drag term B* divided by the WGS-72 earth radius 6378135 m (propagator 1)";
        140 => propagator: Integer = 0, Parameter, "", "0 = numerical integration (two-body, J2-J4, drag), 1 = SGP4 from the tle_* parameters (axes: sgp4_frame; Co-Simulation only)", Choice(Propagator::CODES);
        141 => initial_state: Integer = 0, Parameter, "", "Initial state of propagator 0: 0 = classical elements, 1 = state vector init_r, init_v", Choice(InitialState::CODES);
        142 => zonal_degree: Integer = 2, Parameter, "", "Zonal harmonics of propagator 0: 0 = two-body only, 2 = J2, 3 = J2-J3, 4 = J2-J4", Choice(ZonalDegree::CODES);
        143 => corotating_atmosphere: Boolean = true, Parameter, "", "Drag relative to an atmosphere turning with the Earth (v - omega_E x r); false = still atmosphere";
        144 => sgp4_frame: Integer = 1, Parameter, "", "Axes of r and v in propagator 1: 1 = J2000 (as propagator 0 and the Environment unit; TEME turned by the IAU 1980 nutation, the 1982 equation of the equinoxes and the IAU 1976 precession), 0 = SGP4's TEME unconverted", Choice(Sgp4Frame::CODES);
    }
}

/// State [r, v] in SI units.
type State = SVector<f64, 6>;

/// The force model of the numerical propagator.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Forces {
    gravity: Gravity,
    ballistic: f64,
    /// Rotation rate of the atmosphere (0 when it is still).
    omega_atm: f64,
}

impl Forces {
    /// ẋ = (v, a_gravity(r) + a_drag(r, v)).
    fn derivative(&self, rho: f64, x: &State) -> State {
        let (r, v) = (x.fixed_rows::<3>(0).into_owned(), x.fixed_rows::<3>(3).into_owned());
        let mut a = self.gravity.acceleration(&r);
        if rho > 0.0 {
            a += orbit::drag_acceleration(rho, self.ballistic, self.omega_atm, &r, &v);
        }
        State::from_column_slice(&[v.x, v.y, v.z, a.x, a.y, a.z])
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct Orbit {
    /// Position and velocity (m, m/s) at the last communication point (or the importer's state).
    x: State,
    forces: Forces,
    /// Length and speed scales of the integrated state (initial radius and circular speed there).
    scale: (f64, f64),
    stepper: Stepper,
    /// SGP4 elements (propagator 1); the propagator itself is rebuilt from them.
    tle: Option<Tle>,
    #[serde(skip)]
    sgp4: Option<sgp4::Constants>,
    /// Seconds from the TLE epoch to the start time.
    tle_offset: f64,
    /// Days of UTC from J2000.0 to the start time when the SGP4 state is turned from TEME to J2000 axes
    /// (`sgp4_frame` 1); None: TEME.
    j2000_from: Option<f64>,
    /// Master time of the epoch (the start time of the experiment).
    t0: f64,
}

impl Orbit {
    fn sgp4_state(&self, t: f64) -> Result<State, String> {
        let c = self.sgp4.as_ref().ok_or("SGP4 propagator missing")?;
        let (mut r, mut v) = tle::propagate(c, self.tle_offset + (t - self.t0))?;
        if let Some(d0) = self.j2000_from {
            // the axes turn at most 1.1e-11 rad/s against each other (math::nutation tests): v is rotated
            // with r, the transport term (below 1e-4 m/s in low orbit) is left out
            let t_tt = (d0 + (t - self.t0) / DAY + TT_MINUS_UTC / DAY) / CENTURY;
            let m = nutation::teme_to_j2000(t_tt);
            (r, v) = (m * r, m * v);
        }
        Ok(State::from_column_slice(&[r.x, r.y, r.z, v.x, v.y, v.z]))
    }
}

fn tle_of(v: &OrbitVars) -> Tle {
    Tle {
        epoch_jd: v.tle_epoch_jd_utc,
        n: v.tle_mean_motion,
        e: v.tle_eccentricity,
        i: v.tle_inclination,
        raan: v.tle_raan,
        argp: v.tle_arg_perigee,
        m: v.tle_mean_anomaly,
        bstar: v.tle_bstar,
    }
}

/// Initial state of the numerical propagator from the elements or the state vector.
fn initial_state(v: &OrbitVars) -> Result<State, String> {
    let (r, vel) = match InitialState::from_param("initial_state", v.initial_state)? {
        InitialState::Elements => {
            let el = Elements {
                a: v.semi_major_axis,
                e: v.eccentricity,
                i: v.inclination,
                raan: v.raan,
                argp: v.arg_perigee,
                nu: v.true_anomaly,
            };
            let (r, vel) = orbit::rv_from_elements(v.mu, &el)?;
            if !(el.a * (1.0 - el.e) > v.earth_radius) {
                return Err(format!(
                    "perigee radius semi_major_axis (1 - eccentricity) = {} m lies inside the Earth (earth_radius {} m)",
                    el.a * (1.0 - el.e),
                    v.earth_radius
                ));
            }
            (r, vel)
        }
        InitialState::StateVector => {
            if !(v.init_r.norm() > v.earth_radius) {
                return Err(format!("init_r: |r| = {} m lies inside the Earth (earth_radius {} m)", v.init_r.norm(), v.earth_radius));
            }
            orbit::lvlh_axes(&v.init_r, &v.init_v).map_err(|e| format!("init_r, init_v: {e}"))?;
            (v.init_r, v.init_v)
        }
    };
    Ok(State::from_column_slice(&[r.x, r.y, r.z, vel.x, vel.y, vel.z]))
}

impl Model for Orbit {
    type Vars = OrbitVars;
    const EVOLVING: &'static [&'static str] = &["x", "stepper.h_adapt"];
    const INFO: ModelInfo = ModelInfo {
        name: "Orbit",
        description: "Earth orbit in an inertial frame: numerical (two-body, J2-J4, drag with a density input) or SGP4 from TLE numbers; position, velocity, time, orbit rate and the LVLH frame",
        source: "[Vallado-2013] Secs. 2.6, 8.6 (elements, zonal harmonics, drag); [Montenbruck-Gill-2000] Secs. 3.2, 3.5, 4.1; SGP4: [Hoots-Roehrich-1980], [Vallado-2006] via the sgp4 crate; TEME to J2000: [Seidelmann-1982], [Lieske-1977]",
        equations_html: EQUATIONS_HTML,
        default_stop_time: 6000.0,
        default_step: 1.0,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut OrbitVars, exp: &Experiment) -> Result<Self, String> {
        let propagator = Propagator::from_param("propagator", v.propagator)?;
        let degree = ZonalDegree::from_param("zonal_degree", v.zonal_degree)?;
        let degree = match degree {
            ZonalDegree::TwoBody => 0,
            ZonalDegree::J2 => 2,
            ZonalDegree::J3 => 3,
            ZonalDegree::J4 => 4,
        };
        let gravity = Gravity { mu: v.mu, radius: v.earth_radius, j: [v.j2, v.j3, v.j4], degree };
        let omega_atm = if v.corotating_atmosphere { v.earth_rate } else { 0.0 };
        let forces = Forces { gravity, ballistic: v.ballistic_coeff, omega_atm };
        let stepper = Stepper::new(Method::DormandPrince, 0.0, v.tolerance);
        let mut model = Orbit { x: State::zeros(), forces, scale: (1.0, 1.0), stepper, tle: None, sgp4: None, tle_offset: 0.0, j2000_from: None, t0: exp.start_time };
        match propagator {
            Propagator::Numerical => model.x = initial_state(v)?,
            Propagator::Sgp4 => {
                let t = tle_of(v);
                model.sgp4 = Some(tle::propagator(&t)?);
                model.tle = Some(t);
                model.tle_offset = (v.epoch_jd_utc - v.tle_epoch_jd_utc) * 86_400.0;
                if Sgp4Frame::from_param("sgp4_frame", v.sgp4_frame)? == Sgp4Frame::J2000 {
                    model.j2000_from = Some(v.epoch_jd_utc - JD_J2000);
                }
                model.x = model.sgp4_state(exp.start_time).map_err(|e| format!("at the epoch: {e}"))?;
            }
        }
        let r0 = model.x.fixed_rows::<3>(0).norm();
        model.scale = (r0, (v.mu / r0).sqrt());
        Ok(model)
    }

    fn outputs(&self, v: &mut OrbitVars, t: f64) -> ModelResult {
        let (r, vel) = (self.x.fixed_rows::<3>(0).into_owned(), self.x.fixed_rows::<3>(3).into_owned());
        let [lx, ly, lz] = orbit::lvlh_axes(&r, &vel).map_err(|e| format!("at t = {t}: {e}"))?;
        (v.r, v.v, v.lvlh_x, v.lvlh_y, v.lvlh_z) = (r, vel, lx, ly, lz);
        v.t_utc = t - self.t0;
        v.jd_utc = v.epoch_jd_utc + v.t_utc / 86_400.0;
        let a = orbit::semi_major_axis(v.mu, &r, &vel);
        if !(a > 0.0 && a.is_finite()) {
            return Err(format!("at t = {t}: the orbit is no longer elliptic (semi-major axis {a} m)"));
        }
        v.sma = a;
        v.n_orb = (v.mu / (a * a * a)).sqrt();
        v.altitude = r.norm() - v.earth_radius;
        Ok(())
    }

    fn step(&mut self, v: &OrbitVars, t: f64, h: f64) -> ModelResult {
        if self.sgp4.is_some() {
            self.x = self.sgp4_state(t + h)?;
            return Ok(());
        }
        let rho = v.rho;
        if !(rho >= 0.0 && rho.is_finite()) {
            return Err(format!("input rho = {rho} kg/m3 must be finite and non-negative"));
        }
        let (forces, (l, s)) = (self.forces, self.scale);
        // integrate y = (r / L, v / V): every component is of order 1, so one tolerance fits all
        let unscale = State::from_column_slice(&[l, l, l, s, s, s]);
        let mut y = self.x.component_div(&unscale);
        let mut stepper = self.stepper;
        stepper.advance(
            t,
            h,
            &[],
            &mut y,
            |_, _| move |_tt: f64, yy: &State| forces.derivative(rho, &yy.component_mul(&unscale)).component_div(&unscale),
            |yy, tt| {
                let rn = yy.fixed_rows::<3>(0).norm() * l;
                if rn < forces.gravity.radius {
                    return Err(format!("the orbit has decayed: |r| = {rn} m is below earth_radius at t = {tt}"));
                }
                Ok(())
            },
        )?;
        self.stepper = stepper;
        self.x = y.component_mul(&unscale);
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        self.stepper.check_against(&fresh.stepper)?;
        check_derived("force model", &self.forces, &fresh.forces)?;
        check_finite_state("state vector", self.x.iter())
    }

    fn restored(&mut self) -> ModelResult {
        self.sgp4 = self.tle.as_ref().map(tle::propagator).transpose()?;
        Ok(())
    }

    const STATES: Option<&'static [StateDecl]> = Some(&[
        StateDecl::new("state_r_x", "m", "Continuous state: position x, ECI").depends_on(&["state_v_x"]),
        StateDecl::new("state_r_y", "m", "Continuous state: position y, ECI").depends_on(&["state_v_y"]),
        StateDecl::new("state_r_z", "m", "Continuous state: position z, ECI").depends_on(&["state_v_z"]),
        StateDecl::new("state_v_x", "m/s", "Continuous state: velocity x, ECI (gravity and drag)"),
        StateDecl::new("state_v_y", "m/s", "Continuous state: velocity y, ECI (gravity and drag)"),
        StateDecl::new("state_v_z", "m/s", "Continuous state: velocity z, ECI (gravity and drag)"),
    ]);
    fn get_states(&self, _v: &Self::Vars, x: &mut [f64]) {
        x.copy_from_slice(self.x.as_slice());
    }
    fn set_states(&mut self, x: &[f64]) {
        self.x.copy_from_slice(x);
    }
    fn derivatives(&self, v: &OrbitVars, _t: f64, dx: &mut [f64]) -> ModelResult {
        if self.sgp4.is_some() {
            return Err("propagator = 1 (SGP4) is Co-Simulation only: in Model Exchange use propagator 0".into());
        }
        if !(v.rho >= 0.0) {
            return Err(format!("input rho = {} kg/m3 must be non-negative", v.rho));
        }
        if !(self.x.fixed_rows::<3>(0).norm() > 0.0) {
            return Err("the position is at the Earth's centre".into());
        }
        dx.copy_from_slice(self.forces.derivative(v.rho, &self.x).as_slice());
        Ok(())
    }
}

const EQUATIONS_HTML: &str = include_str!("docs.html");

#[cfg(test)]
mod tests;
