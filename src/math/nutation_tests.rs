use super::*;
use crate::math::time_scales::{CENTURY, JD_J2000};
use nalgebra::Vector3;

/// Julian centuries of TT from J2000.0 of a Julian date (TT).
fn centuries(jd_tt: f64) -> f64 {
    (jd_tt - JD_J2000) / CENTURY
}

#[test]
fn meeus_example_22a() {
    // [Meeus-1998] Example 22.a, 1987 April 10 0h TD (JDE 2446895.5): Δψ = −3.788″, Δε = +9.443″,
    // ε0 = 23°26′27.407″, ε = ε0 + Δε = 23°26′36.850″ (Meeus sums the terms above 0.0003″, to 0.001″)
    let n = nutation_1980(centuries(2_446_895.5));
    let (dpsi, deps) = (n.dpsi / ARCSEC, n.deps / ARCSEC);
    let eps0 = n.eps_mean / ARCSEC - 23.0 * 3600.0 - 26.0 * 60.0;
    let eps = eps0 + deps;
    println!("Meeus 22.a: dpsi {dpsi:.4}\", deps {deps:.4}\", eps0 23d26'{eps0:.4}\", eps 23d26'{eps:.4}\"");
    assert!((dpsi + 3.788).abs() < 1e-3, "{dpsi}");
    assert!((deps - 9.443).abs() < 1e-3, "{deps}");
    assert!((eps0 - 27.407).abs() < 1e-3, "{eps0}");
    assert!((eps - 36.850).abs() < 1e-3, "{eps}");
}

#[test]
fn full_series_matches_erfa_nut80() {
    // ERFA 2.0.1 (pyerfa) eraNut80 and eraObl80, an independent implementation of the same theory (rad)
    // (2025 May 10 and 1995 Mar 24: away from perihelion and aphelion, where the annual terms in sin l′ vanish)
    let cases = [
        (
            2_460_805.25,
            1.428_864_354_424_918_8e-6,
            4.403_022_367_447_581_6e-5,
            0.409_035_261_197_420_45,
        ),
        (
            2_449_800.7,
            5.222_021_499_280_739_6e-5,
            -3.313_440_916_675_422e-5,
            0.409_103_643_255_639_97,
        ),
    ];
    for (jd, dpsi, deps, eps) in cases {
        let n = nutation_1980(centuries(jd));
        // 1e-12 rad = 0.2 µas
        assert!((n.dpsi - dpsi).abs() < 1e-12, "{jd}: {} vs {dpsi}", n.dpsi);
        assert!((n.deps - deps).abs() < 1e-12, "{jd}: {} vs {deps}", n.deps);
        assert!((n.eps_mean - eps).abs() < 1e-12, "{jd}: {} vs {eps}", n.eps_mean);
    }
}

#[test]
fn nutation_matrix_tilts_the_pole_and_moves_the_equinox_by_the_angles() {
    let n = nutation_1980(0.25);
    let m = n.matrix();
    assert!((m * m.transpose() - Matrix3::identity()).norm() < 1e-15);
    // the true pole, in mean-of-date axes, to first order: Δψ sin ε towards the equinox and Δε away from the
    // ecliptic pole (which lies towards −y): (Δψ sin ε, Δε, 1)
    let pole = m.transpose() * Vector3::z();
    let (s, c) = n.eps_mean.sin_cos();
    assert!((pole.x - n.dpsi * s).abs() < 1e-9, "{} vs {}", pole.x, n.dpsi * s);
    assert!((pole.y - n.deps).abs() < 1e-9, "{} vs {}", pole.y, n.deps);
    // the true equinox lies west of the mean one (longitudes grow by Δψ): at right ascension −Δψ cos ε of the
    // mean equator, the equation of the equinoxes with its sign (GAST = GMST + Eq_eq)
    let eq = m.transpose() * Vector3::x();
    assert!((eq.y.atan2(eq.x) + n.dpsi * c).abs() < 1e-9);
    assert_eq!(n.equation_of_equinoxes_1982(), n.dpsi * c);
}

#[test]
fn teme_axes_turn_slowly_against_j2000() {
    // the rotation rate of TEME against J2000, from a central difference of the matrix over an hour,
    // sampled every 3.7 days over 2020-2030: 1.1e-11 rad/s at most (8e-5 m/s at 7000 km, 5e-4 m/s at GEO),
    // so v is turned with r and the transport term ω × r is left out
    let h = 3600.0 / 86_400.0 / CENTURY;
    let mut worst = 0.0f64;
    for k in 0..1000 {
        let t = 0.2 + 0.1 * f64::from(k) / 1000.0;
        let d = (teme_to_j2000(t + h) - teme_to_j2000(t - h)) / (2.0 * 3600.0);
        let w = d * teme_to_j2000(t).transpose();
        worst = worst.max(Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]).norm());
    }
    println!("TEME against J2000, 2020-2030: at most {worst:.3e} rad/s");
    assert!(worst < 2e-11 && worst > 1e-12, "{worst}");
    // at J2000.0 itself only the nutation and the equation of the equinoxes remain (P = I)
    let n = nutation_1980(0.0);
    let m0 = n.matrix().transpose() * rot3(-n.equation_of_equinoxes_1982());
    assert!((teme_to_j2000(0.0) - m0).norm() < 1e-15);
}
