//! Forces and torques of the flow of air and of sunlight on a spacecraft made of flat facets (a
//! "facet" or "panel" model, as in Wertz's and Vallado's textbooks):
//!
//! - **Aerodynamic drag**, free-molecular with a drag coefficient per facet: a facet whose outward normal
//!   n̂ faces the flow (n̂·v̂ > 0, v the velocity of the spacecraft relative to the air) receives
//!   F = −½ ρ |v|² C_d A (n̂·v̂) v̂ at its centre of pressure c, and the torque c × F about the centre of mass.
//! - **Solar-radiation pressure** with specular and diffuse reflection: a facet lit by the sun (n̂·ŝ > 0,
//!   ŝ the unit vector from the spacecraft to the sun) receives
//!   F = −P A (n̂·ŝ) [(1 − C_s) ŝ + 2 (C_s (n̂·ŝ) + C_d / 3) n̂],
//!   where C_s and C_d are the specular and diffuse reflection coefficients (the absorbed fraction is
//!   1 − C_s − C_d) and P the radiation pressure at the spacecraft (flux / c, times the visible fraction
//!   of the sun).
//!
//! Facets do not shadow one another (a convex body: every facet that faces the flow or the sun gets it).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Speed of light in vacuum c (m/s), exact.
pub const SPEED_OF_LIGHT: f64 = 299_792_458.0;
/// The astronomical unit (m), exact (IAU 2012).
pub const ASTRONOMICAL_UNIT: f64 = 149_597_870_700.0;

/// One flat facet, body axes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Facet {
    /// Area A (m²).
    pub area: f64,
    /// Outward unit normal n̂.
    pub normal: Vector3<f64>,
    /// Centre of pressure c relative to the centre of mass (m).
    pub centre: Vector3<f64>,
    /// Drag coefficient C_D.
    pub drag_coeff: f64,
    /// Specular reflection coefficient C_s.
    pub specular: f64,
    /// Diffuse reflection coefficient C_d.
    pub diffuse: f64,
}

impl Facet {
    /// A facet from its declared values: a unit normal from `normal` (refused when zero or not finite
    /// while the area is positive); coefficients checked (C_D ≥ 0; C_s, C_d ≥ 0 with C_s + C_d ≤ 1).
    pub fn new(
        name: &str,
        area: f64,
        normal: Vector3<f64>,
        centre: Vector3<f64>,
        coeffs: [f64; 3],
    ) -> Result<Self, String> {
        let [drag_coeff, specular, diffuse] = coeffs;
        if !(area.is_finite() && area >= 0.0) {
            return Err(format!("{name}_area = {area}: a finite area ≥ 0 m² is allowed"));
        }
        let n = normal.norm();
        if area > 0.0 && !(n.is_finite() && n > 0.0) {
            return Err(format!(
                "{name}_normal = {:?} has no direction: a non-zero finite vector is allowed",
                normal.as_slice()
            ));
        }
        if !(drag_coeff.is_finite() && drag_coeff >= 0.0) {
            return Err(format!(
                "{name}_drag_coeff = {drag_coeff}: a finite coefficient ≥ 0 is allowed"
            ));
        }
        if !(specular >= 0.0 && diffuse >= 0.0 && specular + diffuse <= 1.0) {
            return Err(format!(
                "{name}_specular = {specular}, {name}_diffuse = {diffuse}: coefficients ≥ 0 with a sum ≤ 1 are allowed (the rest is absorbed)"
            ));
        }
        let normal = if area > 0.0 { normal / n } else { Vector3::zeros() };
        Ok(Facet {
            area,
            normal,
            centre,
            drag_coeff,
            specular,
            diffuse,
        })
    }
}

/// Force and torque about the centre of mass (N, N·m), body axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wrench {
    pub force: Vector3<f64>,
    pub torque: Vector3<f64>,
}

impl Wrench {
    fn add(&mut self, f: Vector3<f64>, at: &Vector3<f64>) {
        self.force += f;
        self.torque += at.cross(&f);
    }
}

/// Drag on the facets for air density `rho` (kg/m³) and the velocity of the spacecraft relative to the
/// air `v` (m/s, body axes).
pub fn drag(facets: &[Facet], rho: f64, v: &Vector3<f64>) -> Wrench {
    let mut w = Wrench::default();
    let speed = v.norm();
    if rho == 0.0 || speed == 0.0 {
        return w;
    }
    let v_hat = v / speed;
    let q = 0.5 * rho * speed * speed;
    for f in facets {
        let cos = f.normal.dot(&v_hat);
        if f.area > 0.0 && cos > 0.0 {
            w.add(v_hat * (-q * f.drag_coeff * f.area * cos), &f.centre);
        }
    }
    w
}

/// Radiation pressure P (N/m²) at distance `distance` (m) from the sun for the flux `flux_1au` at one
/// astronomical unit (W/m²), times the visible fraction `visible` of the solar disk.
pub fn radiation_pressure(flux_1au: f64, distance: f64, visible: f64) -> f64 {
    let au = ASTRONOMICAL_UNIT / distance;
    flux_1au / SPEED_OF_LIGHT * au * au * visible
}

/// Solar-radiation pressure on the facets for the pressure `p` (N/m²) and the unit vector `s` from the
/// spacecraft to the sun (body axes).
pub fn solar_pressure(facets: &[Facet], p: f64, s: &Vector3<f64>) -> Wrench {
    let mut w = Wrench::default();
    if p == 0.0 {
        return w;
    }
    for f in facets {
        let cos = f.normal.dot(s);
        if f.area > 0.0 && cos > 0.0 {
            let dir = s * (1.0 - f.specular) + f.normal * (2.0 * (f.specular * cos + f.diffuse / 3.0));
            w.add(dir * (-p * f.area * cos), &f.centre);
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plate(normal: [f64; 3], centre: [f64; 3], cs: f64, cd: f64) -> Facet {
        Facet::new("f", 2.0, Vector3::from(normal), Vector3::from(centre), [2.2, cs, cd]).unwrap()
    }

    #[test]
    fn drag_on_a_plate_facing_the_flow_is_the_dynamic_pressure_times_cd_a() {
        let f = plate([1.0, 0.0, 0.0], [0.1, 0.2, 0.0], 0.0, 0.0);
        let (rho, v) = (1e-12, Vector3::new(7500.0, 0.0, 0.0));
        let w = drag(&[f], rho, &v);
        let fx = -0.5 * rho * 7500.0 * 7500.0 * 2.2 * 2.0;
        assert!((w.force - Vector3::new(fx, 0.0, 0.0)).norm() <= 1e-15 * fx.abs());
        // τ = c × F = (0.1, 0.2, 0) × (F, 0, 0) = (0, 0, −0.2 F)
        assert!((w.torque - Vector3::new(0.0, 0.0, -0.2 * fx)).norm() <= 1e-15 * fx.abs());
    }

    #[test]
    fn drag_scales_with_the_cosine_and_ignores_the_lee_side() {
        let f = plate([1.0, 1.0, 0.0], [0.0; 3], 0.0, 0.0); // normalised to 45°
        let v = Vector3::new(1000.0, 0.0, 0.0);
        let w = drag(&[f], 1.0, &v);
        let expect = -0.5 * 1e6 * 2.2 * 2.0 * std::f64::consts::FRAC_1_SQRT_2;
        assert!((w.force.x - expect).abs() <= 1e-12 * expect.abs() && w.force.y == 0.0);
        assert_eq!(drag(&[f], 1.0, &-v), Wrench::default()); // flow from behind: nothing
    }

    #[test]
    fn srp_of_an_absorber_pushes_along_the_light_and_a_mirror_along_the_normal() {
        let s = Vector3::new(0.6, 0.8, 0.0);
        let p = 4.5e-6;
        // black absorber: F = −P A cosθ ŝ
        let black = plate([0.0, 1.0, 0.0], [0.0; 3], 0.0, 0.0);
        let w = solar_pressure(&[black], p, &s);
        assert!((w.force - s * (-p * 2.0 * 0.8)).norm() <= 1e-20);
        // perfect mirror: F = −2 P A cos²θ n̂
        let mirror = plate([0.0, 1.0, 0.0], [0.0; 3], 1.0, 0.0);
        let w = solar_pressure(&[mirror], p, &s);
        assert!((w.force - Vector3::new(0.0, -2.0 * p * 2.0 * 0.64, 0.0)).norm() <= 1e-20);
        // Lambertian diffuser: F = −P A cosθ (ŝ + 2/3 n̂)
        let white = plate([0.0, 1.0, 0.0], [0.0; 3], 0.0, 1.0);
        let w = solar_pressure(&[white], p, &s);
        let f = (s + Vector3::new(0.0, 2.0 / 3.0, 0.0)) * (-p * 2.0 * 0.8);
        assert!((w.force - f).norm() <= 1e-20, "{:?}", w.force);
        // unlit side: nothing
        assert_eq!(solar_pressure(&[black], p, &-s), Wrench::default());
    }

    #[test]
    fn pressure_at_one_au_is_flux_over_c_and_falls_with_the_square_of_distance() {
        let p = radiation_pressure(1361.0, ASTRONOMICAL_UNIT, 1.0);
        assert!((p - 1361.0 / SPEED_OF_LIGHT).abs() < 1e-20);
        assert!((radiation_pressure(1361.0, 2.0 * ASTRONOMICAL_UNIT, 0.5) - p / 8.0).abs() < 1e-20);
    }

    #[test]
    fn facets_are_checked() {
        let z = Vector3::zeros();
        assert!(Facet::new("facet1", 1.0, z, z, [2.2, 0.0, 0.0])
            .unwrap_err()
            .contains("facet1_normal"));
        assert!(Facet::new("facet1", 0.0, z, z, [2.2, 0.0, 0.0]).is_ok()); // an unused facet
        assert!(Facet::new("facet2", 1.0, Vector3::x(), z, [2.2, 0.7, 0.5])
            .unwrap_err()
            .contains("sum"));
        assert!(Facet::new("facet2", -1.0, Vector3::x(), z, [2.2, 0.0, 0.0]).is_err());
    }
}
