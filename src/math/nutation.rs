//! The IAU 1980 theory of nutation [Seidelmann-1982] and the TEME frame of SGP4.
//!
//! TEME ("true equator, mean equinox", the output frame of SGP4 [Vallado-2006] Sec. 6) has the true equator of
//! date and, on it, the mean equinox of date in the sense of the 1982 equation of the equinoxes
//! Eq_eq = Δψ cos ε_A (the form without the terms in the Moon's node Ω that the IAU added in 1994, as
//! [Vallado-2006] defines TEME). From TEME to the mean equator and equinox of J2000:
//!
//! ```text
//! r_J2000 = Pᵀ Nᵀ R3(−Eq_eq) r_TEME
//! ```
//!
//! with P the IAU 1976 precession ([`time_scales::precession`]) and N = R1(−ε_A − Δε) R3(−Δψ) R1(ε_A) the
//! IAU 1980 nutation (mean → true equator and equinox of date; [Vallado-2013] Sec. 3.7). The result
//! has the axes of the J2000 mean equator and equinox, which differ from GCRF by the frame bias (23 mas).
//!
//! The series is complete: all 106 terms of the 1980 theory, in units of 0.1 mas with their rates per
//! Julian century, and the fundamental (Delaunay) arguments of the theory, as tabulated in
//! [Vallado-2013] (nut80.dat) and the IAU SOFA/ERFA routine `nut80`; the unit tests check the sum against a
//! worked example of [Meeus-1998] (Example 22.a) and the Orbit tests against astropy and ERFA.

use nalgebra::Matrix3;

use super::time_scales::{precession, rot1, rot3};

const ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);
/// 0.1 mas in radians: the unit of the coefficients.
const UNIT: f64 = ARCSEC * 1e-4;

/// One term: multiples of (l, l′, F, D, Ω); Δψ sine coefficient and its rate per century; Δε cosine
/// coefficient and its rate (0.1 mas, 0.1 mas per Julian century).
type Term = ([i8; 5], f64, f64, f64, f64);

/// The 106 terms of the IAU 1980 nutation series (order of the SOFA/ERFA table).
#[rustfmt::skip]
const TERMS: [Term; 106] = [
    ([0, 0, 0, 0, 1], -171996.0, -174.2, 92025.0, 8.9),
    ([0, 0, 0, 0, 2], 2062.0, 0.2, -895.0, 0.5),
    ([-2, 0, 2, 0, 1], 46.0, 0.0, -24.0, 0.0),
    ([2, 0, -2, 0, 0], 11.0, 0.0, 0.0, 0.0),
    ([-2, 0, 2, 0, 2], -3.0, 0.0, 1.0, 0.0),
    ([1, -1, 0, -1, 0], -3.0, 0.0, 0.0, 0.0),
    ([0, -2, 2, -2, 1], -2.0, 0.0, 1.0, 0.0),
    ([2, 0, -2, 0, 1], 1.0, 0.0, 0.0, 0.0),
    ([0, 0, 2, -2, 2], -13187.0, -1.6, 5736.0, -3.1),
    ([0, 1, 0, 0, 0], 1426.0, -3.4, 54.0, -0.1),
    ([0, 1, 2, -2, 2], -517.0, 1.2, 224.0, -0.6),
    ([0, -1, 2, -2, 2], 217.0, -0.5, -95.0, 0.3),
    ([0, 0, 2, -2, 1], 129.0, 0.1, -70.0, 0.0),
    ([2, 0, 0, -2, 0], 48.0, 0.0, 1.0, 0.0),
    ([0, 0, 2, -2, 0], -22.0, 0.0, 0.0, 0.0),
    ([0, 2, 0, 0, 0], 17.0, -0.1, 0.0, 0.0),
    ([0, 1, 0, 0, 1], -15.0, 0.0, 9.0, 0.0),
    ([0, 2, 2, -2, 2], -16.0, 0.1, 7.0, 0.0),
    ([0, -1, 0, 0, 1], -12.0, 0.0, 6.0, 0.0),
    ([-2, 0, 0, 2, 1], -6.0, 0.0, 3.0, 0.0),
    ([0, -1, 2, -2, 1], -5.0, 0.0, 3.0, 0.0),
    ([2, 0, 0, -2, 1], 4.0, 0.0, -2.0, 0.0),
    ([0, 1, 2, -2, 1], 4.0, 0.0, -2.0, 0.0),
    ([1, 0, 0, -1, 0], -4.0, 0.0, 0.0, 0.0),
    ([2, 1, 0, -2, 0], 1.0, 0.0, 0.0, 0.0),
    ([0, 0, -2, 2, 1], 1.0, 0.0, 0.0, 0.0),
    ([0, 1, -2, 2, 0], -1.0, 0.0, 0.0, 0.0),
    ([0, 1, 0, 0, 2], 1.0, 0.0, 0.0, 0.0),
    ([-1, 0, 0, 1, 1], 1.0, 0.0, 0.0, 0.0),
    ([0, 1, 2, -2, 0], -1.0, 0.0, 0.0, 0.0),
    ([0, 0, 2, 0, 2], -2274.0, -0.2, 977.0, -0.5),
    ([1, 0, 0, 0, 0], 712.0, 0.1, -7.0, 0.0),
    ([0, 0, 2, 0, 1], -386.0, -0.4, 200.0, 0.0),
    ([1, 0, 2, 0, 2], -301.0, 0.0, 129.0, -0.1),
    ([1, 0, 0, -2, 0], -158.0, 0.0, -1.0, 0.0),
    ([-1, 0, 2, 0, 2], 123.0, 0.0, -53.0, 0.0),
    ([0, 0, 0, 2, 0], 63.0, 0.0, -2.0, 0.0),
    ([1, 0, 0, 0, 1], 63.0, 0.1, -33.0, 0.0),
    ([-1, 0, 0, 0, 1], -58.0, -0.1, 32.0, 0.0),
    ([-1, 0, 2, 2, 2], -59.0, 0.0, 26.0, 0.0),
    ([1, 0, 2, 0, 1], -51.0, 0.0, 27.0, 0.0),
    ([0, 0, 2, 2, 2], -38.0, 0.0, 16.0, 0.0),
    ([2, 0, 0, 0, 0], 29.0, 0.0, -1.0, 0.0),
    ([1, 0, 2, -2, 2], 29.0, 0.0, -12.0, 0.0),
    ([2, 0, 2, 0, 2], -31.0, 0.0, 13.0, 0.0),
    ([0, 0, 2, 0, 0], 26.0, 0.0, -1.0, 0.0),
    ([-1, 0, 2, 0, 1], 21.0, 0.0, -10.0, 0.0),
    ([-1, 0, 0, 2, 1], 16.0, 0.0, -8.0, 0.0),
    ([1, 0, 0, -2, 1], -13.0, 0.0, 7.0, 0.0),
    ([-1, 0, 2, 2, 1], -10.0, 0.0, 5.0, 0.0),
    ([1, 1, 0, -2, 0], -7.0, 0.0, 0.0, 0.0),
    ([0, 1, 2, 0, 2], 7.0, 0.0, -3.0, 0.0),
    ([0, -1, 2, 0, 2], -7.0, 0.0, 3.0, 0.0),
    ([1, 0, 2, 2, 2], -8.0, 0.0, 3.0, 0.0),
    ([1, 0, 0, 2, 0], 6.0, 0.0, 0.0, 0.0),
    ([2, 0, 2, -2, 2], 6.0, 0.0, -3.0, 0.0),
    ([0, 0, 0, 2, 1], -6.0, 0.0, 3.0, 0.0),
    ([0, 0, 2, 2, 1], -7.0, 0.0, 3.0, 0.0),
    ([1, 0, 2, -2, 1], 6.0, 0.0, -3.0, 0.0),
    ([0, 0, 0, -2, 1], -5.0, 0.0, 3.0, 0.0),
    ([1, -1, 0, 0, 0], 5.0, 0.0, 0.0, 0.0),
    ([2, 0, 2, 0, 1], -5.0, 0.0, 3.0, 0.0),
    ([0, 1, 0, -2, 0], -4.0, 0.0, 0.0, 0.0),
    ([1, 0, -2, 0, 0], 4.0, 0.0, 0.0, 0.0),
    ([0, 0, 0, 1, 0], -4.0, 0.0, 0.0, 0.0),
    ([1, 1, 0, 0, 0], -3.0, 0.0, 0.0, 0.0),
    ([1, 0, 2, 0, 0], 3.0, 0.0, 0.0, 0.0),
    ([1, -1, 2, 0, 2], -3.0, 0.0, 1.0, 0.0),
    ([-1, -1, 2, 2, 2], -3.0, 0.0, 1.0, 0.0),
    ([-2, 0, 0, 0, 1], -2.0, 0.0, 1.0, 0.0),
    ([3, 0, 2, 0, 2], -3.0, 0.0, 1.0, 0.0),
    ([0, -1, 2, 2, 2], -3.0, 0.0, 1.0, 0.0),
    ([1, 1, 2, 0, 2], 2.0, 0.0, -1.0, 0.0),
    ([-1, 0, 2, -2, 1], -2.0, 0.0, 1.0, 0.0),
    ([2, 0, 0, 0, 1], 2.0, 0.0, -1.0, 0.0),
    ([1, 0, 0, 0, 2], -2.0, 0.0, 1.0, 0.0),
    ([3, 0, 0, 0, 0], 2.0, 0.0, 0.0, 0.0),
    ([0, 0, 2, 1, 2], 2.0, 0.0, -1.0, 0.0),
    ([-1, 0, 0, 0, 2], 1.0, 0.0, -1.0, 0.0),
    ([1, 0, 0, -4, 0], -1.0, 0.0, 0.0, 0.0),
    ([-2, 0, 2, 2, 2], 1.0, 0.0, -1.0, 0.0),
    ([-1, 0, 2, 4, 2], -2.0, 0.0, 1.0, 0.0),
    ([2, 0, 0, -4, 0], -1.0, 0.0, 0.0, 0.0),
    ([1, 1, 2, -2, 2], 1.0, 0.0, -1.0, 0.0),
    ([1, 0, 2, 2, 1], -1.0, 0.0, 1.0, 0.0),
    ([-2, 0, 2, 4, 2], -1.0, 0.0, 1.0, 0.0),
    ([-1, 0, 4, 0, 2], 1.0, 0.0, 0.0, 0.0),
    ([1, -1, 0, -2, 0], 1.0, 0.0, 0.0, 0.0),
    ([2, 0, 2, -2, 1], 1.0, 0.0, -1.0, 0.0),
    ([2, 0, 2, 2, 2], -1.0, 0.0, 0.0, 0.0),
    ([1, 0, 0, 2, 1], -1.0, 0.0, 0.0, 0.0),
    ([0, 0, 4, -2, 2], 1.0, 0.0, 0.0, 0.0),
    ([3, 0, 2, -2, 2], 1.0, 0.0, 0.0, 0.0),
    ([1, 0, 2, -2, 0], -1.0, 0.0, 0.0, 0.0),
    ([0, 1, 2, 0, 1], 1.0, 0.0, 0.0, 0.0),
    ([-1, -1, 0, 2, 1], 1.0, 0.0, 0.0, 0.0),
    ([0, 0, -2, 0, 1], -1.0, 0.0, 0.0, 0.0),
    ([0, 0, 2, -1, 2], -1.0, 0.0, 0.0, 0.0),
    ([0, 1, 0, 2, 0], -1.0, 0.0, 0.0, 0.0),
    ([1, 0, -2, -2, 0], -1.0, 0.0, 0.0, 0.0),
    ([0, -1, 2, 0, 1], -1.0, 0.0, 0.0, 0.0),
    ([1, 1, 0, -2, 1], -1.0, 0.0, 0.0, 0.0),
    ([1, 0, -2, 2, 0], -1.0, 0.0, 0.0, 0.0),
    ([2, 0, 0, 2, 0], 1.0, 0.0, 0.0, 0.0),
    ([0, 0, 2, 4, 2], -1.0, 0.0, 0.0, 0.0),
    ([0, 1, 0, 1, 0], 1.0, 0.0, 0.0, 0.0),
];

/// Nutation angles and the mean obliquity of date (rad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nutation {
    /// Nutation in longitude Δψ.
    pub dpsi: f64,
    /// Nutation in obliquity Δε.
    pub deps: f64,
    /// Mean obliquity of the ecliptic ε_A (IAU 1980).
    pub eps_mean: f64,
}

/// A fundamental argument: a cubic in arcseconds plus whole revolutions per century (the fractional part of
/// `rev` t, so that the large linear term keeps its precision).
fn fundamental(c: [f64; 4], rev: f64, t: f64) -> f64 {
    (c[0] + (c[1] + (c[2] + c[3] * t) * t) * t) * ARCSEC + (rev * t % 1.0) * std::f64::consts::TAU
}

/// Mean obliquity of the ecliptic, IAU 1980 (rad), at `t_tt` Julian centuries of TT from J2000.0
/// ([Vallado-2013] Sec. 3.7).
pub fn mean_obliquity_1980(t_tt: f64) -> f64 {
    let t = t_tt;
    (84_381.448 + (-46.8150 + (-0.00059 + 0.001_813 * t) * t) * t) * ARCSEC
}

/// The IAU 1980 nutation (all 106 terms) at `t_tt` Julian centuries of TT from J2000.0.
pub fn nutation_1980(t_tt: f64) -> Nutation {
    let t = t_tt;
    // Delaunay arguments of the 1980 theory: l (Moon's mean anomaly), l′ (Sun's), F = L − Ω, D (elongation),
    // Ω (longitude of the Moon's ascending node)
    let args = [
        fundamental([485_866.733, 715_922.633, 31.310, 0.064], 1325.0, t),
        fundamental([1_287_099.804, 1_292_581.224, -0.577, -0.012], 99.0, t),
        fundamental([335_778.877, 295_263.137, -13.257, 0.011], 1342.0, t),
        fundamental([1_072_261.307, 1_105_601.328, -6.891, 0.019], 1236.0, t),
        fundamental([450_160.280, -482_890.539, 7.455, 0.008], -5.0, t),
    ];
    let (mut dp, mut de) = (0.0, 0.0);
    // smallest terms first
    for (m, sp, spt, ce, cet) in TERMS.iter().rev() {
        let arg: f64 = m.iter().zip(&args).map(|(&k, a)| f64::from(k) * a).sum();
        let (s, c) = arg.sin_cos();
        dp += (sp + spt * t) * s;
        de += (ce + cet * t) * c;
    }
    Nutation {
        dpsi: dp * UNIT,
        deps: de * UNIT,
        eps_mean: mean_obliquity_1980(t),
    }
}

impl Nutation {
    /// N: mean equator and equinox of date → true equator and equinox of date,
    /// R1(−ε_A − Δε) R3(−Δψ) R1(ε_A).
    pub fn matrix(&self) -> Matrix3<f64> {
        rot1(-(self.eps_mean + self.deps)) * rot3(-self.dpsi) * rot1(self.eps_mean)
    }

    /// The equation of the equinoxes in its 1982 form Δψ cos ε_A (rad), without the 1994 terms in Ω: the
    /// angle from the mean to the true equinox along the true equator, as SGP4's TEME takes it.
    pub fn equation_of_equinoxes_1982(&self) -> f64 {
        self.dpsi * self.eps_mean.cos()
    }
}

/// The rotation TEME → J2000 (mean equator and equinox of J2000) at `t_tt` Julian centuries of TT from
/// J2000.0: Pᵀ Nᵀ R3(−Eq_eq).
pub fn teme_to_j2000(t_tt: f64) -> Matrix3<f64> {
    let n = nutation_1980(t_tt);
    precession(t_tt).transpose() * n.matrix().transpose() * rot3(-n.equation_of_equinoxes_1982())
}

#[cfg(test)]
#[path = "nutation_tests.rs"]
mod tests;
