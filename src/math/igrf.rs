//! The International Geomagnetic Reference Field, 14th generation ([IGRF-14]; model and conventions as
//! in [Alken-2021]): the internal field as the gradient of a spherical-harmonic potential of degree 13,
//!
//!   V(r) = a Σ_{n=1..13} (a/r)^{n+1} Σ_{m=0..n} [g_n^m cos mλ + h_n^m sin mλ] P_n^m(cos θ),   B = −∇V,
//!
//! with a = 6371.2 km, Schmidt semi-normalised P_n^m, geocentric colatitude θ and longitude λ in the
//! Earth-fixed frame, and the coefficients interpolated linearly in the decimal year between the
//! five-yearly models (1900.0 … 2020.0 definitive or historical, 2025.0 with its secular variation to
//! 2030.0; `igrf14_coefficients.rs`).
//!
//! The sum is evaluated in Cartesian Earth-fixed coordinates by the recursions of the solid harmonics
//! V_nm = (a/r)^{n+1} P_nm cos mλ, W_nm = (a/r)^{n+1} P_nm sin mλ (unnormalised P_nm) and their
//! gradient formulas ([Montenbruck-Gill-2000] Sec. 3.2.4–3.2.5, written there for the gravity potential):
//! no trigonometric function and no singularity at the poles.

use nalgebra::Vector3;

use super::igrf14_coefficients::{COEFFS, EPOCHS};

/// Degree (and order) of the expansion.
pub const N_MAX: usize = 13;
/// Reference radius a of the expansion (m).
pub const REFERENCE_RADIUS: f64 = 6_371_200.0;
/// First and last decimal year the coefficients cover.
pub const FIRST_YEAR: f64 = 1900.0;
pub const LAST_YEAR: f64 = 2030.0;

const N: usize = N_MAX + 2; // solid harmonics to degree N_MAX + 1 for the gradient

/// Coefficients at one instant, unnormalised (the Schmidt factor sqrt(2 (n−m)!/(n+m)!) for m > 0 folded in),
/// in nT: `g[n][m]`, `h[n][m]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Coefficients {
    pub g: [[f64; N_MAX + 1]; N_MAX + 1],
    pub h: [[f64; N_MAX + 1]; N_MAX + 1],
}

/// The Schmidt semi-normalised coefficients (nT) at the decimal year `year`: `(g, h)` indexed `[n][m]`.
pub fn schmidt_coefficients(year: f64) -> Result<Coefficients, String> {
    if !(FIRST_YEAR..=LAST_YEAR).contains(&year) {
        return Err(format!(
            "IGRF-14 covers the years {FIRST_YEAR:.1} to {LAST_YEAR:.1}; the time requested is {year:.4}"
        ));
    }
    let k = (((year - FIRST_YEAR) / 5.0).floor() as usize).min(EPOCHS.len() - 2);
    let w = (year - EPOCHS[k]) / (EPOCHS[k + 1] - EPOCHS[k]);
    let mut c = Coefficients {
        g: [[0.0; N_MAX + 1]; N_MAX + 1],
        h: [[0.0; N_MAX + 1]; N_MAX + 1],
    };
    let mut row = COEFFS.iter().map(|r| r[k] + w * (r[k + 1] - r[k]));
    for n in 1..=N_MAX {
        for m in 0..=n {
            c.g[n][m] = row.next().unwrap_or(0.0);
            if m > 0 {
                c.h[n][m] = row.next().unwrap_or(0.0);
            }
        }
    }
    Ok(c)
}

/// The coefficients at the decimal year `year`, unnormalised for the solid-harmonic recursion.
pub fn coefficients(year: f64) -> Result<Coefficients, String> {
    let mut c = schmidt_coefficients(year)?;
    for n in 1..=N_MAX {
        let mut s = 1.0; // sqrt((n−m)!/(n+m)!)
        for m in 1..=n {
            s /= (((n - m + 1) * (n + m)) as f64).sqrt();
            let f = s * std::f64::consts::SQRT_2;
            c.g[n][m] *= f;
            c.h[n][m] *= f;
        }
    }
    Ok(c)
}

/// The field B (T) at the Earth-fixed position `r` (m, r ≠ 0), with `c` from [`coefficients`].
pub fn field_ecef(c: &Coefficients, r: &Vector3<f64>) -> Vector3<f64> {
    let a = REFERENCE_RADIUS;
    let r2 = r.norm_squared();
    let (x0, y0, z0, rho) = (a * r.x / r2, a * r.y / r2, a * r.z / r2, a * a / r2);
    let mut v = [[0.0; N]; N];
    let mut w = [[0.0; N]; N];
    v[0][0] = a / r2.sqrt();
    for m in 0..N {
        if m > 0 {
            let k = (2 * m - 1) as f64;
            v[m][m] = k * (x0 * v[m - 1][m - 1] - y0 * w[m - 1][m - 1]);
            w[m][m] = k * (x0 * w[m - 1][m - 1] + y0 * v[m - 1][m - 1]);
        }
        if m + 1 < N {
            let k = (2 * m + 1) as f64 * z0;
            v[m + 1][m] = k * v[m][m];
            w[m + 1][m] = k * w[m][m];
        }
        for n in m + 2..N {
            let (k1, k2, d) = ((2 * n - 1) as f64 * z0, (n + m - 1) as f64 * rho, (n - m) as f64);
            v[n][m] = (k1 * v[n - 1][m] - k2 * v[n - 2][m]) / d;
            w[n][m] = (k1 * w[n - 1][m] - k2 * w[n - 2][m]) / d;
        }
    }
    // ∇V from the degree-(n+1) harmonics; B = −∇V
    let mut grad = Vector3::zeros();
    for n in 1..=N_MAX {
        let (vn, wn) = (&v[n + 1], &w[n + 1]);
        grad.x -= c.g[n][0] * vn[1];
        grad.y -= c.g[n][0] * wn[1];
        grad.z -= (n + 1) as f64 * c.g[n][0] * vn[0];
        for m in 1..=n {
            let (g, h) = (c.g[n][m], c.h[n][m]);
            let f = ((n - m + 2) * (n - m + 1)) as f64;
            grad.x += 0.5 * (-g * vn[m + 1] - h * wn[m + 1] + f * (g * vn[m - 1] + h * wn[m - 1]));
            grad.y += 0.5 * (-g * wn[m + 1] + h * vn[m + 1] + f * (-g * wn[m - 1] + h * vn[m - 1]));
            grad.z += (n - m + 1) as f64 * (-g * vn[m] - h * wn[m]);
        }
    }
    -grad * 1e-9
}

#[cfg(test)]
#[path = "igrf_tests.rs"]
mod tests;
