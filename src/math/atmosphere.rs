//! Static atmospheric density models, both functions of the height above the WGS-84 ellipsoid:
//!
//! - the piecewise exponential model of [Vallado-2013] Table 8-4 (CIRA-72 based, moderate solar
//!   activity, 0 km to above 1000 km): ρ = ρ0 exp(−(h − h0)/H) with (h0, ρ0, H) of the layer holding h;
//! - the modified Harris–Priester model of [Montenbruck-Gill-2000] Sec. 3.5.2 (Table 3.8, mean solar
//!   activity, 100 km to 1000 km): the antapex and apex densities ρ_m(h), ρ_M(h) interpolated
//!   exponentially between the tabulated heights and blended by the diurnal bulge,
//!   ρ = ρ_m + (ρ_M − ρ_m) cos^n(ψ/2), with ψ the angle between the position and the bulge apex (the
//!   sun direction turned by 30° in right ascension, towards the afternoon, declination unchanged).
//!
//! Above 1000 km both continue with the scale height of their top layer.

use nalgebra::Vector3;

/// [Vallado-2013] Table 8-4: base height h0 (km), nominal density ρ0 (kg/m³), scale height H (km).
#[rustfmt::skip]
pub const EXPONENTIAL: [(f64, f64, f64); 28] = [
    (0.0, 1.225, 7.249), (25.0, 3.899e-2, 6.349), (30.0, 1.774e-2, 6.682), (40.0, 3.972e-3, 7.554),
    (50.0, 1.057e-3, 8.382), (60.0, 3.206e-4, 7.714), (70.0, 8.770e-5, 6.549), (80.0, 1.905e-5, 5.799),
    (90.0, 3.396e-6, 5.382), (100.0, 5.297e-7, 5.877), (110.0, 9.661e-8, 7.263), (120.0, 2.438e-8, 9.473),
    (130.0, 8.484e-9, 12.636), (140.0, 3.845e-9, 16.149), (150.0, 2.070e-9, 22.523), (180.0, 5.464e-10, 29.740),
    (200.0, 2.789e-10, 37.105), (250.0, 7.248e-11, 45.546), (300.0, 2.418e-11, 53.628), (350.0, 9.518e-12, 53.298),
    (400.0, 3.725e-12, 58.515), (450.0, 1.585e-12, 60.828), (500.0, 6.967e-13, 63.822), (600.0, 1.454e-13, 71.835),
    (700.0, 3.614e-14, 88.667), (800.0, 1.170e-14, 124.64), (900.0, 5.245e-15, 181.05), (1000.0, 3.019e-15, 268.00),
];

/// [Montenbruck-Gill-2000] Table 3.8: height (km), antapex density ρ_m, apex density ρ_M (g/km³ = 1e-12 kg/m³).
#[rustfmt::skip]
pub const HARRIS_PRIESTER: [(f64, f64, f64); 50] = [
    (100.0, 497400.0, 497400.0), (120.0, 24900.0, 24900.0), (130.0, 8377.0, 8710.0), (140.0, 3899.0, 4059.0),
    (150.0, 2122.0, 2215.0), (160.0, 1263.0, 1344.0), (170.0, 800.8, 875.8), (180.0, 528.3, 601.0),
    (190.0, 361.7, 429.7), (200.0, 255.7, 316.2), (210.0, 183.9, 239.6), (220.0, 134.1, 185.3),
    (230.0, 99.49, 145.5), (240.0, 74.88, 115.7), (250.0, 57.09, 93.08), (260.0, 44.03, 75.55),
    (270.0, 34.30, 61.82), (280.0, 26.97, 50.95), (290.0, 21.39, 42.26), (300.0, 17.08, 35.26),
    (320.0, 10.99, 25.11), (340.0, 7.214, 18.19), (360.0, 4.824, 13.37), (380.0, 3.274, 9.955),
    (400.0, 2.249, 7.492), (420.0, 1.558, 5.684), (440.0, 1.091, 4.355), (460.0, 0.7701, 3.362),
    (480.0, 0.5474, 2.612), (500.0, 0.3916, 2.042), (520.0, 0.2819, 1.605), (540.0, 0.2042, 1.267),
    (560.0, 0.1488, 1.005), (580.0, 0.1092, 0.7997), (600.0, 0.08070, 0.6390), (620.0, 0.06012, 0.5123),
    (640.0, 0.04519, 0.4121), (660.0, 0.03430, 0.3325), (680.0, 0.02632, 0.2691), (700.0, 0.02043, 0.2185),
    (720.0, 0.01607, 0.1779), (740.0, 0.01281, 0.1452), (760.0, 0.01036, 0.1190), (780.0, 0.008496, 0.09776),
    (800.0, 0.007069, 0.08059), (840.0, 0.004680, 0.05741), (880.0, 0.003200, 0.04210), (920.0, 0.002210, 0.03130),
    (960.0, 0.001560, 0.02360), (1000.0, 0.001150, 0.01810),
];

/// Lag of the bulge apex behind the sun in right ascension (rad): 30°.
pub const BULGE_LAG: f64 = std::f64::consts::PI / 6.0;

/// Density (kg/m³) of the exponential model at the height `h` (m, ≥ 0) above the ellipsoid.
pub fn exponential_density(h: f64) -> f64 {
    let km = h / 1000.0;
    let i = EXPONENTIAL.iter().rposition(|row| row.0 <= km).unwrap_or(0);
    let (h0, rho0, scale) = EXPONENTIAL[i];
    rho0 * (-(km - h0) / scale).exp()
}

/// Density (kg/m³) of the Harris–Priester model at the height `h` (m) above the ellipsoid, with
/// `cos_psi` the cosine of the angle between the position and the bulge apex and `n` the exponent of the
/// bulge (2 for low, 6 for polar inclinations). Heights below 100 km are refused.
pub fn harris_priester_density(h: f64, cos_psi: f64, n: f64) -> Result<f64, String> {
    let km = h / 1000.0;
    if km < HARRIS_PRIESTER[0].0 {
        return Err(format!(
            "the Harris-Priester table starts at 100 km; the height above the ellipsoid is {km:.1} km \
             (density_model = 0, the exponential model, covers 0-1000 km)"
        ));
    }
    let last = HARRIS_PRIESTER.len() - 1;
    let i = HARRIS_PRIESTER
        .iter()
        .rposition(|row| row.0 <= km)
        .unwrap_or(0)
        .min(last - 1);
    let (lo, hi) = (HARRIS_PRIESTER[i], HARRIS_PRIESTER[i + 1]);
    // exponential interpolation between the tabulated heights (continued above the top one)
    let f = (km - lo.0) / (hi.0 - lo.0);
    let rho_min = lo.1 * (hi.1 / lo.1).powf(f);
    let rho_max = lo.2 * (hi.2 / lo.2).powf(f);
    let bulge = (0.5 * (1.0 + cos_psi)).max(0.0).powf(0.5 * n);
    Ok((rho_min + (rho_max - rho_min) * bulge) * 1e-12)
}

/// Unit vector of the bulge apex from the unit sun direction (inertial): turned by [`BULGE_LAG`] about z.
pub fn bulge_apex(sun: &Vector3<f64>) -> Vector3<f64> {
    let (s, c) = BULGE_LAG.sin_cos();
    Vector3::new(c * sun.x - s * sun.y, s * sun.x + c * sun.y, sun.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_model_reproduces_its_table_and_is_continuous() {
        // the tabulated nominal densities at the base heights, e.g. 400 km: 3.725e-12 kg/m³
        assert!((exponential_density(400e3) - 3.725e-12).abs() < 1e-18);
        assert!((exponential_density(0.0) - 1.225).abs() < 1e-15);
        // [Vallado-2013] Example 8-4 style: 747.2 km = 700 km layer, ρ = 3.614e-14 exp(−47.2/88.667)
        let rho = exponential_density(747.2e3);
        assert!(
            (rho / (3.614e-14 * (-47.2f64 / 88.667).exp()) - 1.0).abs() < 1e-12,
            "{rho}"
        );
        // the scale heights were chosen so that each layer ends at the next one's base density
        // (within the table's four digits, 0.2 %)
        for w in EXPONENTIAL.windows(2) {
            let top = w[0].1 * (-(w[1].0 - w[0].0) / w[0].2).exp();
            assert!((top / w[1].1 - 1.0).abs() < 2e-3, "{:?} -> {:?}: {top}", w[0], w[1]);
        }
        // above 1000 km: the top layer's scale height, 268 km
        assert!((exponential_density(1268e3) / (3.019e-15 / std::f64::consts::E) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn harris_priester_at_nodes_between_them_and_across_the_bulge() {
        // at a tabulated height the antapex value (ψ = π) and the apex value (ψ = 0): 400 km
        let at = |h: f64, c: f64| harris_priester_density(h, c, 4.0).unwrap();
        assert!((at(400e3, -1.0) / 2.249e-12 - 1.0).abs() < 1e-12);
        assert!((at(400e3, 1.0) / 7.492e-12 - 1.0).abs() < 1e-12);
        // halfway between 400 and 420 km the geometric mean of the two antapex values
        assert!((at(410e3, -1.0) / (2.249e-12f64 * 1.558e-12).sqrt() - 1.0).abs() < 1e-12);
        // ψ = 90°: cos^n(45°) = 2^(−n/2) of the way from ρ_m to ρ_M
        let mid = 2.249e-12 + (7.492e-12 - 2.249e-12) * 0.25;
        assert!((at(400e3, 0.0) / mid - 1.0).abs() < 1e-12);
        let e = harris_priester_density(99e3, 0.0, 4.0).unwrap_err();
        assert!(e.contains("100 km") && e.contains("99.0"), "{e}");
        // the apex is 30° east of the sun in right ascension
        let apex = bulge_apex(&Vector3::x());
        assert!((apex.y.atan2(apex.x).to_degrees() - 30.0).abs() < 1e-12);
    }
}
