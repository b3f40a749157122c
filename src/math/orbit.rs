//! Earth orbits in an Earth-centred inertial frame whose z-axis is the Earth's rotation (and symmetry)
//! axis: classical elements ↔ state vector, the zonal-harmonic accelerations J2–J4, atmospheric drag
//! against an atmosphere that turns with the Earth, and Kepler's equation. SI units throughout
//! (metres, seconds, radians). Formulas: [Vallado-2013] Secs. 2.2, 2.6 and 8.6, [Montenbruck-Gill-2000]
//! Secs. 2.2 and 3.2.

use nalgebra::Vector3;

/// Gravitational parameter of the Earth μ (m³/s², EGM-96 / WGS-84).
pub const MU_EARTH: f64 = 3.986_004_418e14;
/// Equatorial radius of the Earth R_E (m, WGS-84), the reference radius of the zonal harmonics.
pub const R_EARTH: f64 = 6_378_137.0;
/// Unnormalised zonal coefficients J2, J3, J4 of EGM-96 (from its normalised C̄_n0 as −√(2n+1) C̄_n0).
pub const J2: f64 = 1.082_626_683_553_15e-3;
pub const J3: f64 = -2.532_656_485_33e-6;
pub const J4: f64 = -1.619_621_591_37e-6;
/// Rotation rate of the Earth ω_E (rad/s, WGS-84).
pub const OMEGA_EARTH: f64 = 7.292_115e-5;

/// Classical (Keplerian) elements of an elliptic orbit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elements {
    /// Semi-major axis a (m).
    pub a: f64,
    /// Eccentricity e, 0 ≤ e < 1.
    pub e: f64,
    /// Inclination i (rad).
    pub i: f64,
    /// Right ascension of the ascending node Ω (rad).
    pub raan: f64,
    /// Argument of perigee ω (rad).
    pub argp: f64,
    /// True anomaly ν (rad).
    pub nu: f64,
}

/// Position and velocity from classical elements: the perifocal state r = p/(1 + e cos ν) (cos ν, sin ν),
/// v = √(μ/p) (−sin ν, e + cos ν), turned by R3(−Ω) R1(−i) R3(−ω). Refuses e outside [0, 1) and a ≤ 0.
pub fn rv_from_elements(mu: f64, el: &Elements) -> Result<(Vector3<f64>, Vector3<f64>), String> {
    if !(el.e >= 0.0 && el.e < 1.0) {
        return Err(format!(
            "eccentricity {} must lie in [0, 1) (elliptic orbits only)",
            el.e
        ));
    }
    if !(el.a > 0.0) {
        return Err(format!("semi-major axis {} m must be positive", el.a));
    }
    let p = el.a * (1.0 - el.e * el.e);
    let (sn, cn) = el.nu.sin_cos();
    let r = p / (1.0 + el.e * cn);
    let vs = (mu / p).sqrt();
    let (r_pf, v_pf) = (
        Vector3::new(r * cn, r * sn, 0.0),
        Vector3::new(-vs * sn, vs * (el.e + cn), 0.0),
    );
    let rot = perifocal_to_inertial(el.i, el.raan, el.argp);
    Ok((rot * r_pf, rot * v_pf))
}

/// The matrix that maps perifocal components (P towards perigee, Q 90° ahead in the orbit plane, W
/// along the angular momentum) into inertial ones; its columns are P, Q and W.
pub fn perifocal_to_inertial(i: f64, raan: f64, argp: f64) -> nalgebra::Matrix3<f64> {
    let (so, co) = raan.sin_cos();
    let (sw, cw) = argp.sin_cos();
    let (si, ci) = i.sin_cos();
    nalgebra::Matrix3::new(
        co * cw - so * sw * ci,
        -co * sw - so * cw * ci,
        so * si,
        so * cw + co * sw * ci,
        -so * sw + co * cw * ci,
        -co * si,
        sw * si,
        cw * si,
        ci,
    )
}

/// Osculating semi-major axis from the vis-viva energy, a = 1 / (2/r − v²/μ) (negative when the orbit
/// is hyperbolic, infinite when parabolic).
pub fn semi_major_axis(mu: f64, r: &Vector3<f64>, v: &Vector3<f64>) -> f64 {
    1.0 / (2.0 / r.norm() - v.norm_squared() / mu)
}

/// Osculating classical elements of a bound state (refuses an unbound one). The angles that are
/// undefined for circular or equatorial orbits are taken as 0 (Ω for i = 0, ω for e = 0) and the
/// anomaly is then measured from the node or from the x-axis.
pub fn elements_from_rv(mu: f64, r: &Vector3<f64>, v: &Vector3<f64>) -> Result<Elements, String> {
    let a = semi_major_axis(mu, r, v);
    if !(a > 0.0 && a.is_finite()) {
        return Err(format!("the state is not on an elliptic orbit (a = {a} m)"));
    }
    let h = r.cross(v);
    let node = Vector3::z().cross(&h);
    let ev = v.cross(&h) / mu - r / r.norm();
    let e = ev.norm();
    let i = (h.z / h.norm()).clamp(-1.0, 1.0).acos();
    let tiny = 1e-12;
    let angle = |from: &Vector3<f64>, to: &Vector3<f64>| {
        let c = (from.dot(to) / (from.norm() * to.norm())).clamp(-1.0, 1.0).acos();
        // measured in the direction of motion (about h)
        if from.cross(to).dot(&h) < 0.0 {
            2.0 * std::f64::consts::PI - c
        } else {
            c
        }
    };
    let raan = if node.norm() > tiny * h.norm() {
        node.y.atan2(node.x).rem_euclid(2.0 * std::f64::consts::PI)
    } else {
        0.0
    };
    let line = if node.norm() > tiny * h.norm() {
        node
    } else {
        Vector3::x()
    };
    let (argp, nu) = if e > tiny {
        (angle(&line, &ev), angle(&ev, r))
    } else {
        (0.0, angle(&line, r))
    };
    Ok(Elements {
        a,
        e,
        i,
        raan,
        argp,
        nu,
    })
}

/// Eccentric anomaly E of Kepler's equation M = E − e sin E (Newton's method from E = M + e sin M,
/// converged to a few ulp for e < 1).
pub fn eccentric_anomaly(m: f64, e: f64) -> f64 {
    let mut ea = m + e * m.sin();
    for _ in 0..50 {
        let d = (ea - e * ea.sin() - m) / (1.0 - e * ea.cos());
        ea -= d;
        if d.abs() < 1e-15 * ea.abs().max(1.0) {
            break;
        }
    }
    ea
}

/// True anomaly from the eccentric anomaly: tan(ν/2) = √((1 + e)/(1 − e)) tan(E/2).
pub fn true_from_eccentric(ea: f64, e: f64) -> f64 {
    2.0 * ((1.0 + e).sqrt() * (ea / 2.0).sin()).atan2((1.0 - e).sqrt() * (ea / 2.0).cos())
}

/// Mean anomaly of a true anomaly: E from tan(E/2) = √((1 − e)/(1 + e)) tan(ν/2), M = E − e sin E.
pub fn mean_from_true(nu: f64, e: f64) -> f64 {
    let ea = 2.0 * ((1.0 - e).sqrt() * (nu / 2.0).sin()).atan2((1.0 + e).sqrt() * (nu / 2.0).cos());
    ea - e * ea.sin()
}

/// Gravity field: μ and the zonal coefficients J2 … J_degree (degree 0 or 1 = point mass).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Gravity {
    pub mu: f64,
    /// Reference radius of the harmonics R (m).
    pub radius: f64,
    /// J2, J3, J4.
    pub j: [f64; 3],
    /// Highest zonal degree used: 0 (two-body), 2, 3 or 4.
    pub degree: u8,
}

impl Gravity {
    /// Acceleration a = −μ r / |r|³ plus the zonal terms up to `degree`. With s = z/r:
    ///
    /// J2: −(3/2) J2 μ R²/r⁴ [(1 − 5s²) x/r, (1 − 5s²) y/r, (3 − 5s²) z/r]
    /// J3: −(5/2) J3 μ R³/r⁵ [(3s − 7s³) x/r, (3s − 7s³) y/r, 6s² − 7s⁴ − 3/5]
    /// J4: (15/8) J4 μ R⁴/r⁶ [(1 − 14s² + 21s⁴) x/r, (1 − 14s² + 21s⁴) y/r, (5 − 70s²/3 + 21s⁴) z/r]
    ///
    /// ([Vallado-2013] Eq. 8-30 and the J3, J4 terms that follow it; the gradient of the zonal potential).
    pub fn acceleration(&self, r: &Vector3<f64>) -> Vector3<f64> {
        let rn = r.norm();
        let mut a = -self.mu / (rn * rn * rn) * r;
        if self.degree < 2 {
            return a;
        }
        let (ux, uy, s) = (r.x / rn, r.y / rn, r.z / rn);
        let s2 = s * s;
        let q = self.mu / (rn * rn) * (self.radius / rn).powi(2);
        let c2 = -1.5 * self.j[0] * q;
        a += Vector3::new(
            c2 * (1.0 - 5.0 * s2) * ux,
            c2 * (1.0 - 5.0 * s2) * uy,
            c2 * (3.0 - 5.0 * s2) * s,
        );
        if self.degree >= 3 {
            let c3 = -2.5 * self.j[1] * q * (self.radius / rn);
            let h = 3.0 * s - 7.0 * s * s2;
            a += Vector3::new(c3 * h * ux, c3 * h * uy, c3 * (6.0 * s2 - 7.0 * s2 * s2 - 0.6));
        }
        if self.degree >= 4 {
            let c4 = 1.875 * self.j[2] * q * (self.radius / rn).powi(2);
            let h = 1.0 - 14.0 * s2 + 21.0 * s2 * s2;
            a += Vector3::new(
                c4 * h * ux,
                c4 * h * uy,
                c4 * (5.0 - 70.0 / 3.0 * s2 + 21.0 * s2 * s2) * s,
            );
        }
        a
    }
}

/// Drag acceleration −½ (ρ / B) |v_rel| v_rel with v_rel = v − ω × r, the velocity relative to an
/// atmosphere turning with the Earth at ω (rad/s, about z; 0 = a still atmosphere), B = m / (C_D A).
pub fn drag_acceleration(rho: f64, ballistic: f64, omega: f64, r: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let v_rel = v - Vector3::new(-omega * r.y, omega * r.x, 0.0);
    v_rel * (-0.5 * rho / ballistic * v_rel.norm())
}

/// Unit vectors of the local-vertical local-horizontal frame in inertial components: z towards the
/// Earth's centre (nadir, −r̂), y against the orbit's angular momentum (−ĥ), x = y × z (along-track, the
/// velocity direction on a circular orbit). Refuses a state with r ∥ v.
pub fn lvlh_axes(r: &Vector3<f64>, v: &Vector3<f64>) -> Result<[Vector3<f64>; 3], String> {
    let h = r.cross(v);
    if !(h.norm() > 1e-12 * r.norm() * v.norm()) {
        return Err("the LVLH frame is undefined: position and velocity are parallel".into());
    }
    let z = -r.normalize();
    let y = -h.normalize();
    Ok([y.cross(&z), y, z])
}

#[cfg(test)]
#[path = "orbit_tests.rs"]
mod tests;
