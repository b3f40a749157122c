//! The publications the models come from, cited in descriptions and documentation by a bracketed key
//! (`[Navabi-2019] Eq. 37`). The FMU documentation and the generated docs expand every key they use
//! into the full reference, so a user never meets an internal paper number.

/// One publication.
#[derive(Clone, Copy, Debug)]
pub struct Reference {
    /// Citation key, written in text as `[key]`.
    pub key: &'static str,
    pub authors: &'static str,
    pub title: &'static str,
    /// Journal, year and language notes, as far as known ("" = not recorded; likewise `authors`).
    pub venue: &'static str,
    /// A description standing in for the title when the title is not recorded ("" otherwise).
    pub subject: &'static str,
    /// What this library takes from it.
    pub used_for: &'static str,
}

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
];

/// The references whose `[key]` occurs in any of `texts`, in the order of [`ALL`].
pub fn cited_in<'a>(texts: impl IntoIterator<Item = &'a str> + Clone) -> Vec<&'static Reference> {
    ALL.iter()
        .filter(|r| {
            let tag = format!("[{}]", r.key);
            texts.clone().into_iter().any(|t| t.contains(&tag))
        })
        .collect()
}

/// Every `[key]`-shaped tag in `text` (letters, digits and '-' only), for checking that each is known.
pub fn tags_in(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find('[') {
        let after = &rest[i + 1..];
        match after.find(']') {
            Some(j)
                if j > 0
                    && after[..j].chars().all(|c| c.is_ascii_alphanumeric() || c == '-')
                    && after[..j].chars().any(|c| c.is_ascii_alphabetic())
                    && after[..j].contains('-') =>
            {
                out.push(&after[..j]);
                rest = &after[j + 1..];
            }
            _ => rest = after,
        }
    }
    out
}

/// "authors, “title”, venue." in plain text; unknown authors or venue (empty) are said to be unknown.
pub fn citation(r: &Reference) -> String {
    let title = if r.title.is_empty() {
        format!("A work on {} (title not recorded)", r.subject)
    } else {
        format!("\u{201c}{}\u{201d}", r.title)
    };
    match (r.authors.is_empty(), r.venue.is_empty()) {
        (false, false) => format!("{}, {title}, {}.", r.authors, r.venue),
        (false, true) => format!("{}, {title} (venue not recorded).", r.authors),
        (true, false) => format!("{title}, {} (authors not recorded).", r.venue),
        (true, true) => format!("{title} (authors and venue not recorded)."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_unique_and_found() {
        for (i, a) in ALL.iter().enumerate() {
            assert!(ALL[i + 1..].iter().all(|b| b.key != a.key));
        }
        let t = "as in [Navabi-2019] Eq. 5 and [Moradi-FTC]; not a key: [0, 1] or [x]";
        let keys: Vec<_> = cited_in([t]).iter().map(|r| r.key).collect();
        assert_eq!(keys, ["Navabi-2019", "Moradi-FTC"]);
        assert_eq!(tags_in(t), ["Navabi-2019", "Moradi-FTC"]);
    }

    #[test]
    fn every_model_cites_only_known_references_and_at_least_one() {
        for e in spacecraft_fmus::registry::ALL {
            let texts = e.texts();
            let mut cited = 0;
            for t in &texts {
                for tag in tags_in(t) {
                    assert!(
                        ALL.iter().any(|r| r.key == tag),
                        "{}: unknown reference [{tag}]",
                        e.info.name
                    );
                    cited += 1;
                }
            }
            assert!(cited > 0, "{}: cites no reference", e.info.name);
        }
    }
}
