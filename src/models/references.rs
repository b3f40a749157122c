//! The publications the project's models come from, cited in descriptions and documentation by a
//! bracketed key (`[Navabi-2019] Eq. 37`). The list goes into the catalogue the library exports; the
//! packaging tool expands every key a page uses into the full reference (so a user never meets an
//! internal paper number) and refuses a key that is not listed here.

use crate::catalogue::Reference;

/// The project's bibliography, in the order `docs/references.md` lists it (`src/cdylib` passes it to
/// `export_fmus!`). A new publication: one entry here, cited as `[key]` in a model's texts.
pub const ALL: &[Reference] = &[
    Reference {
        key: "Navabi-2019",
        authors: "M. Navabi, S. Hosseini",
        title: "Design of an adaptive-fuzzy controller based on the EULERINT criterion for a satellite",
        venue: "Modares Mechanical Engineering 19(12), 2019 (in Persian; English title translated)",
        subject: "",
        used_for: "rigid-body attitude with quaternion, DCM and Euler-angle kinematics; PD, LQR, pole placement, \
                   MRAC, fuzzy PD and adaptive-fuzzy controllers; the EULERINT criterion",
    },
    Reference {
        key: "NPPID-Formation",
        authors: "",
        title: "A Nonlinear Predictive PID Controller Design for Spacecraft Formation Flying Control",
        venue: "",
        subject: "",
        used_for: "nonlinear relative orbit of a follower about an elliptic leader orbit; predictive PID with a \
                   disturbance observer",
    },
    Reference {
        key: "Khatoonabadi-FO",
        authors: "E. Khatoonabadi, V. Bohlouri, A. R. Kosari",
        title: "Improving Satellite Attitude Control Performance Using Fractional-Order Controller in the \
                Presence of Environmental Disturbances",
        venue: "",
        subject: "",
        used_for: "single-axis plant with reaction-wheel lag and saturation; PID and fractional PI^lambda D^mu \
                   (Grunwald-Letnikov); PSO tuning",
    },
    Reference {
        key: "T2FSMC-LEO",
        authors: "",
        title: "",
        // the original title is not recorded; `subject` says what the work is about
        subject: "LEO satellite attitude control with reaction wheels and magnetorquers: GA-tuned sliding \
                  mode versus sliding mode with an interval type-2 fuzzy switching gain",
        venue: "",
        used_for: "reaction wheels with magnetorquer momentum dumping, gravity gradient and disturbance \
                   scenarios; sliding-mode and type-2 fuzzy sliding-mode controllers; ISE/ISF criteria",
    },
    Reference {
        key: "Moradi-FTC",
        authors: "R. Moradi",
        title: "Design of an active fault-tolerant controller for a spacecraft under actuator fault",
        venue: "in Persian; title translated",
        subject: "",
        used_for: "loss-of-effectiveness actuator faults; feedback-linearising quaternion law; reference \
                   correction from an optimised open-loop spline torque",
    },
    Reference {
        key: "Markley-Crassidis-2014",
        authors: "F. L. Markley, J. L. Crassidis",
        title: "Fundamentals of Spacecraft Attitude Determination and Control",
        venue: "Springer, 2014",
        subject: "",
        used_for: "sensor error models: gyro angle and rate random walk, star-tracker error rotation, sun-sensor \
                   and magnetometer measurements",
    },
    Reference {
        key: "Wie-Weiss-Arapostathis-1989",
        authors: "B. Wie, H. Weiss, A. Arapostathis",
        title: "Quaternion feedback regulator for spacecraft eigenaxis rotations",
        venue: "Journal of Guidance, Control, and Dynamics 12(3), 375-380, 1989",
        subject: "",
        used_for: "quaternion feedback u = -K q_e - C w: the sun-acquisition (safe-mode) law on the shortest \
                   rotation to the sun",
    },
    Reference {
        key: "Avanzini-Giulietti-2012",
        authors: "G. Avanzini, F. Giulietti",
        title: "Magnetic Detumbling of a Rigid Spacecraft",
        venue: "Journal of Guidance, Control, and Dynamics 35(4), 2012",
        subject: "",
        used_for: "B-dot detumbling on the normalised field direction and its gain rule from the orbit rate, the \
                   orbit's inclination to the geomagnetic equator and the smallest moment of inertia",
    },
    Reference {
        key: "IEEE-952",
        authors: "IEEE Aerospace and Electronic Systems Society",
        title: "IEEE Standard Specification Format Guide and Test Procedure for Single-Axis Interferometric \
                Fiber Optic Gyros",
        venue: "IEEE Std 952-1997 (R2008), Annex C: Allan variance",
        subject: "",
        used_for: "gyro noise terms by their Allan deviation: angle random walk N, bias instability B, rate \
                   random walk K",
    },
    Reference {
        key: "Franklin-Powell-Workman-1998",
        authors: "G. F. Franklin, J. D. Powell, M. Workman",
        title: "Digital Control of Dynamic Systems",
        venue: "3rd ed., Addison-Wesley, 1998",
        subject: "",
        used_for: "sampled-data timing: zero-order hold and computation delay",
    },
    Reference {
        key: "Lefferts-Markley-Shuster-1982",
        authors: "E. J. Lefferts, F. L. Markley, M. D. Shuster",
        title: "Kalman Filtering for Spacecraft Attitude Estimation",
        venue: "Journal of Guidance, Control, and Dynamics 5(5), 1982",
        subject: "",
        used_for: "the multiplicative extended Kalman filter of attitude and gyro bias (error state of small-angle \
                   attitude errors and biases, multiplicative reset)",
    },
    Reference {
        key: "IGRF-14",
        authors: "IAGA Division V, Working Group V-MOD",
        title: "International Geomagnetic Reference Field, 14th generation (IGRF-14): coefficients 1900-2030",
        venue: "IAGA release, Zenodo, doi:10.5281/zenodo.14012302, 2024",
        subject: "",
        used_for: "the Gauss coefficients of the geomagnetic main field to degree 13 and their secular variation",
    },
    Reference {
        key: "Alken-2021",
        authors: "P. Alken, E. Thebault, C. D. Beggan, et al.",
        title: "International Geomagnetic Reference Field: the thirteenth generation",
        venue: "Earth, Planets and Space 73, 49, 2021",
        subject: "",
        used_for: "the IGRF potential, reference radius, Schmidt normalisation and time interpolation rule",
    },
    Reference {
        key: "Montenbruck-Gill-2000",
        authors: "O. Montenbruck, E. Gill",
        title: "Satellite Orbits: Models, Methods and Applications",
        venue: "Springer, 2000",
        subject: "",
        used_for: "solid-harmonic recursions and gradient of a spherical-harmonic potential (Sec. 3.2); conical \
                   Earth shadow by the overlap of the apparent disks (Sec. 3.4.2); modified Harris-Priester \
                   density (Sec. 3.5.2, Table 3.8); numerical orbit propagation: force model (geopotential, drag \
                   relative to a co-rotating atmosphere), adaptive Runge-Kutta integration and its tolerances",
    },
    Reference {
        key: "Vallado-2013",
        authors: "D. A. Vallado",
        title: "Fundamentals of Astrodynamics and Applications",
        venue: "4th ed., Microcosm Press, 2013",
        subject: "",
        used_for: "Greenwich mean sidereal time (IAU 1982, Eq. 3-45), IAU 1976 precession; the exponential \
                   atmosphere (Table 8-4); classical orbital elements and the state vector, Kepler's equation, \
                   the zonal-harmonic accelerations J2-J4 and atmospheric drag of the Orbit unit",
    },
    Reference {
        key: "AA-2024",
        authors: "U.S. Naval Observatory, H.M. Nautical Almanac Office",
        title: "The Astronomical Almanac",
        venue: "Section C, low-precision formulas for the Sun (the same in every recent edition)",
        subject: "",
        used_for: "the sun's apparent ecliptic longitude, distance and the obliquity, accurate to 0.01 deg \
                   from 1950 to 2050; the mean longitude of the on-board mean sun of the Ephemeris",
    },
    Reference {
        key: "Lieske-1977",
        authors: "J. H. Lieske, T. Lederle, W. Fricke, B. Morando",
        title: "Expressions for the precession quantities based upon the IAU (1976) system of astronomical \
                constants",
        venue: "Astronomy and Astrophysics 58, 1-16, 1977",
        subject: "",
        used_for: "the precession angles zeta, z, theta from J2000 to the mean equator and equinox of date",
    },
    Reference {
        key: "Meeus-1998",
        authors: "J. Meeus",
        title: "Astronomical Algorithms",
        venue: "2nd ed., Willmann-Bell, 1998",
        subject: "",
        used_for: "Julian date of a calendar date and back (Ch. 7); a worked example of the IAU 1980 nutation \
                   (Example 22.a)",
    },
    Reference {
        key: "Hoots-Roehrich-1980",
        authors: "F. R. Hoots, R. L. Roehrich",
        title: "Spacetrack Report No. 3: Models for Propagation of NORAD Element Sets",
        venue: "Aerospace Defense Command, 1980",
        subject: "",
        used_for: "the SGP4 analytical propagator of two-line element sets",
    },
    Reference {
        key: "Vallado-2006",
        authors: "D. A. Vallado, P. Crawford, R. Hujsak, T. S. Kelso",
        title: "Revisiting Spacetrack Report #3",
        venue: "AIAA/AAS Astrodynamics Specialist Conference, AIAA 2006-6753, 2006",
        subject: "",
        used_for: "the reference SGP4 implementation, its verification element sets (SGP4-VER.TLE) and the TEME \
                   frame of its output",
    },
    Reference {
        key: "Seidelmann-1982",
        authors: "P. K. Seidelmann",
        title: "1980 IAU Theory of Nutation: The Final Report of the IAU Working Group on Nutation",
        venue: "Celestial Mechanics 27, 79-106, 1982",
        subject: "",
        used_for: "the IAU 1980 nutation series (106 terms) that turns SGP4's TEME output to J2000 axes",
    },
    Reference {
        key: "ECSS-E-ST-60-30C",
        authors: "European Cooperation for Space Standardization",
        title: "Space engineering: Satellite attitude and orbit control system (AOCS) requirements",
        venue: "ECSS-E-ST-60-30C, ESA Requirements and Standards Division, 2013",
        subject: "",
        used_for: "AOCS modes (safe mode, acquisition, nominal pointing), mode transitions and the selection of \
                   the control laws by mode",
    },
    Reference {
        key: "Bar-Shalom-2001",
        authors: "Y. Bar-Shalom, X. R. Li, T. Kirubarajan",
        title: "Estimation with Applications to Tracking and Navigation",
        venue: "Wiley, 2001",
        subject: "",
        used_for: "filter consistency by the normalized innovation squared (NIS) and its average over time",
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalogue::cited_keys;

    #[test]
    fn keys_are_unique_and_well_formed() {
        for (i, a) in ALL.iter().enumerate() {
            assert!(ALL[i + 1..].iter().all(|b| b.key != a.key));
            assert_eq!(cited_keys(&format!("[{}]", a.key)), [a.key]);
        }
    }

    #[test]
    fn every_model_cites_only_known_references_and_at_least_one() {
        for e in crate::registry::ALL {
            let keys: Vec<&str> = e.texts().iter().flat_map(|t| cited_keys(t)).collect();
            for k in &keys {
                assert!(
                    ALL.iter().any(|r| r.key == *k),
                    "{}: unknown reference [{k}]",
                    e.info.name
                );
            }
            assert!(!keys.is_empty(), "{}: cites no reference", e.info.name);
        }
    }
}
