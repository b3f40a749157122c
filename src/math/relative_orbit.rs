//! Leader–follower relative orbital motion in the leader's LVLH frame ([NPPID-Formation],
//! paper 001 Eqs. 3–5 with the printed typos fixed): leader-orbit geometry θ̇(ν), θ̈(ν), R(ν), the
//! nonlinear term G(ρ, ρ̇) of ρ̈ + G = F/m + d, and Kepler's equation for tests and references.
//!
//! Frame: x radial (outward through the leader), y along-track, z along the orbital angular momentum.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Keplerian leader orbit: μ, a, e and the derived mean motion n and semi-latus rectum p.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LeaderOrbit {
    pub mu: f64,
    pub a: f64,
    pub e: f64,
    /// Mean motion n = sqrt(μ / a³).
    pub n: f64,
    /// Semi-latus rectum p = a (1 − e²).
    pub p: f64,
}

impl Default for LeaderOrbit {
    fn default() -> Self {
        LeaderOrbit::new(3.986004418e14, 6.0e6, 0.0).expect("default orbit is valid")
    }
}

impl LeaderOrbit {
    /// Checks μ > 0, a > 0, 0 ≤ e < 1; the message names the offending parameter.
    pub fn new(mu: f64, a: f64, e: f64) -> Result<Self, String> {
        if !(mu.is_finite() && mu > 0.0) {
            return Err(format!("parameter mu = {mu} must be > 0"));
        }
        if !(a.is_finite() && a > 0.0) {
            return Err(format!("parameter semi_major_axis = {a} must be > 0"));
        }
        if !(e.is_finite() && (0.0..1.0).contains(&e)) {
            return Err(format!("parameter eccentricity = {e} must lie in [0, 1)"));
        }
        Ok(LeaderOrbit {
            mu,
            a,
            e,
            n: (mu / (a * a * a)).sqrt(),
            p: a * (1.0 - e * e),
        })
    }

    /// Orbital rate θ̇ = n (1 + e cos ν)² / (1 − e²)^{3/2} (paper 001 Eq. 4); = ν̇ for Kepler motion.
    pub fn theta_dot(&self, nu: f64) -> f64 {
        let k = 1.0 + self.e * nu.cos();
        let s = 1.0 - self.e * self.e;
        self.n * k * k / (s * s.sqrt())
    }

    /// Orbital acceleration θ̈ = −2 n² e sin ν (1 + e cos ν)³ / (1 − e²)³ (derivative of θ̇).
    pub fn theta_ddot(&self, nu: f64) -> f64 {
        let k = 1.0 + self.e * nu.cos();
        let s = 1.0 - self.e * self.e;
        -2.0 * self.n * self.n * self.e * nu.sin() * k * k * k / (s * s * s)
    }

    /// Leader radius R = a (1 − e²) / (1 + e cos ν) (paper 001 Eq. 4 with its sign typo fixed).
    pub fn radius(&self, nu: f64) -> f64 {
        self.p / (1.0 + self.e * nu.cos())
    }

    /// Follower distance from the Earth's centre ρ_f = |(R + x, y, z)|.
    pub fn follower_radius(&self, nu: f64, rho: &Vector3<f64>) -> f64 {
        Vector3::new(self.radius(nu) + rho.x, rho.y, rho.z).norm()
    }

    /// Differential gravity μ/R² e_x − μ (R e_x + ρ)/ρ_f³ in LVLH, free of the cancellation between
    /// μ/R² and μ (R + x)/ρ_f³: with q = 2Rx + |ρ|², ρ_f² = R² + q and
    /// ρ_f³ − R²(R + x) = q (ρ_f² + ρ_f R + R²)/(ρ_f + R) − R² x. Exactly 0 at ρ = 0.
    pub fn differential_gravity(&self, nu: f64, rho: &Vector3<f64>) -> Result<Vector3<f64>, String> {
        let r = self.radius(nu);
        let q = 2.0 * r * rho.x + rho.norm_squared();
        let rf2 = r * r + q;
        if !(rf2.is_finite() && rf2 > 0.0) {
            return Err(format!(
                "follower at the Earth's centre or non-finite (rho = {:?})",
                rho.as_slice()
            ));
        }
        let rf = rf2.sqrt();
        let rf3 = rf2 * rf;
        let num_x = q * (rf2 + rf * r + r * r) / (rf + r) - r * r * rho.x;
        Ok(Vector3::new(
            self.mu * num_x / (r * r * rf3),
            -self.mu * rho.y / rf3,
            -self.mu * rho.z / rf3,
        ))
    }

    /// G(ρ, ρ̇) of ρ̈ + G = F/m + d (the relative-orbit equations of the formation family; third row μ z/ρ_f³):
    /// G = [−2θ̇ẏ − θ̈y − θ̇²x + μ(R+x)/ρ_f³ − μ/R² ; 2θ̇ẋ + θ̈x − θ̇²y + μy/ρ_f³ ; μz/ρ_f³].
    pub fn g_term(&self, nu: f64, rho: &Vector3<f64>, rho_dot: &Vector3<f64>) -> Result<Vector3<f64>, String> {
        let td = self.theta_dot(nu);
        let tdd = self.theta_ddot(nu);
        let dg = self.differential_gravity(nu, rho)?;
        let (x, y) = (rho.x, rho.y);
        let (vx, vy) = (rho_dot.x, rho_dot.y);
        Ok(Vector3::new(
            -2.0 * td * vy - tdd * y - td * td * x - dg.x,
            2.0 * td * vx + tdd * x - td * td * y - dg.y,
            -dg.z,
        ))
    }

    /// Relative acceleration ρ̈ = −G(ρ, ρ̇) + a_ext (a_ext = F/m + d).
    pub fn relative_acceleration(
        &self,
        nu: f64,
        rho: &Vector3<f64>,
        rho_dot: &Vector3<f64>,
        a_ext: &Vector3<f64>,
    ) -> Result<Vector3<f64>, String> {
        Ok(a_ext - self.g_term(nu, rho, rho_dot)?)
    }

    /// Orbital period 2π/n.
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.n
    }
}

/// Eccentric anomaly from mean anomaly: Newton iteration on E − e sin E = M (0 ≤ e < 1).
pub fn eccentric_anomaly(mean_anomaly: f64, e: f64) -> f64 {
    let mut ea = if e < 0.8 {
        mean_anomaly
    } else {
        std::f64::consts::PI.copysign(mean_anomaly)
    };
    for _ in 0..50 {
        let f = ea - e * ea.sin() - mean_anomaly;
        let d = f / (1.0 - e * ea.cos());
        ea -= d;
        if d.abs() <= 1e-15 * (1.0 + ea.abs()) {
            break;
        }
    }
    ea
}

/// True anomaly from mean anomaly via Kepler's equation; continuous (not wrapped) in M.
pub fn true_anomaly_from_mean(mean_anomaly: f64, e: f64) -> f64 {
    let ea = eccentric_anomaly(mean_anomaly, e);
    // ν = 2 atan(sqrt((1+e)/(1−e)) tan(E/2)), unwrapped onto the revolution of E
    let half = ea / 2.0;
    let k = (half / std::f64::consts::PI).round();
    let h = half - k * std::f64::consts::PI;
    2.0 * (((1.0 + e).sqrt() * h.sin()).atan2((1.0 - e).sqrt() * h.cos()) + k * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn orbit(e: f64) -> LeaderOrbit {
        LeaderOrbit::new(3.986004418e14, 6.0e6, e).unwrap()
    }

    #[test]
    fn circular_orbit_geometry() {
        let o = orbit(0.0);
        assert!((o.n - 1.35844e-3).abs() < 1e-8, "n = {}", o.n);
        for nu in [0.0, 1.0, 4.0] {
            assert_eq!(o.theta_dot(nu), o.n);
            assert_eq!(o.theta_ddot(nu), 0.0);
            assert_eq!(o.radius(nu), 6.0e6);
        }
    }

    #[test]
    fn theta_ddot_is_derivative_of_theta_dot() {
        // dθ̇/dt = dθ̇/dν · ν̇, central difference in ν
        let o = orbit(0.3);
        for nu in [0.0, 0.7, 2.0, 3.5, 5.9] {
            let h = 1e-5;
            let d = (o.theta_dot(nu + h) - o.theta_dot(nu - h)) / (2.0 * h) * o.theta_dot(nu);
            assert!(
                (d - o.theta_ddot(nu)).abs() < 1e-9 * o.n * o.n,
                "nu {nu}: {d} vs {}",
                o.theta_ddot(nu)
            );
        }
    }

    #[test]
    fn angular_momentum_is_constant() {
        // R² θ̇ = sqrt(μ p) for any ν
        let o = orbit(0.1);
        let h = (o.mu * o.p).sqrt();
        for nu in [0.0, 1.0, 2.0, 3.0] {
            let r = o.radius(nu);
            assert!((r * r * o.theta_dot(nu) - h).abs() < 1e-12 * h);
        }
    }

    #[test]
    fn g_is_zero_at_origin_and_matches_direct_formula() {
        for e in [0.0, 0.1, 0.5] {
            let o = orbit(e);
            for nu in [0.0, 1.3, 4.0] {
                assert_eq!(
                    o.g_term(nu, &Vector3::zeros(), &Vector3::zeros()).unwrap(),
                    Vector3::zeros()
                );
                // against the printed (cancelling) form, for a large offset where cancellation is mild
                let rho = Vector3::new(3.0e4, -2.0e4, 1.0e4);
                let v = Vector3::new(1.0, -2.0, 0.5);
                let g = o.g_term(nu, &rho, &v).unwrap();
                let (td, tdd, r) = (o.theta_dot(nu), o.theta_ddot(nu), o.radius(nu));
                let rf = ((r + rho.x).powi(2) + rho.y * rho.y + rho.z * rho.z).sqrt();
                let rf3 = rf.powi(3);
                let direct = Vector3::new(
                    -2.0 * td * v.y - tdd * rho.y - td * td * rho.x + o.mu * (r + rho.x) / rf3 - o.mu / (r * r),
                    2.0 * td * v.x + tdd * rho.x - td * td * rho.y + o.mu * rho.y / rf3,
                    o.mu * rho.z / rf3,
                );
                assert!(
                    (g - direct).norm() < 1e-9 * direct.norm(),
                    "e {e} nu {nu}: {g:?} vs {direct:?}"
                );
            }
        }
    }

    #[test]
    fn g_linearises_to_clohessy_wiltshire() {
        // e = 0, small ρ: G ≈ (−2nẏ − 3n²x, 2nẋ, n²z)
        let o = orbit(0.0);
        let n = o.n;
        let rho = Vector3::new(1.0, 2.0, -1.5);
        let v = Vector3::new(0.01, -0.02, 0.03);
        let g = o.g_term(0.0, &rho, &v).unwrap();
        let cw = Vector3::new(-2.0 * n * v.y - 3.0 * n * n * rho.x, 2.0 * n * v.x, n * n * rho.z);
        // second-order terms ~ n² |ρ|²/R
        assert!(
            (g - cw).norm() < 10.0 * n * n * rho.norm_squared() / o.a,
            "{g:?} vs {cw:?}"
        );
    }

    #[test]
    fn kepler_equation_solution() {
        for e in [0.0, 0.1, 0.7] {
            for m in [-2.0, 0.0, 0.5, 3.0, 7.5, 20.0] {
                let ea = eccentric_anomaly(m, e);
                assert!((ea - e * ea.sin() - m).abs() < 1e-13 * (1.0 + m.abs()));
                let nu = true_anomaly_from_mean(m, e);
                // cos ν = (cos E − e)/(1 − e cos E), and ν is continuous and within π of E
                assert!((nu.cos() - (ea.cos() - e) / (1.0 - e * ea.cos())).abs() < 1e-12);
                assert!((nu - ea).abs() < std::f64::consts::PI);
            }
        }
        assert!((true_anomaly_from_mean(1.234, 0.0) - 1.234).abs() < 1e-15);
    }

    #[test]
    fn invalid_orbits_are_rejected() {
        assert!(LeaderOrbit::new(-1.0, 6e6, 0.0).unwrap_err().contains("mu"));
        assert!(LeaderOrbit::new(1.0, 0.0, 0.0).unwrap_err().contains("semi_major_axis"));
        assert!(LeaderOrbit::new(1.0, 6e6, 1.0).unwrap_err().contains("eccentricity"));
    }
}
