//! Units used in modelDescription: name → SI base-unit exponents (FMI 2.0 `<BaseUnit>`).
//! A variable may only use a unit listed here; `description` tests check that.

/// Exponents of kg, m, s, A, K, mol, cd, rad, plus a factor to the SI unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaseUnit {
    pub kg: i32,
    pub m: i32,
    pub s: i32,
    pub a: i32,
    pub rad: i32,
    pub factor: f64,
}

const fn u(kg: i32, m: i32, s: i32, a: i32, rad: i32) -> BaseUnit {
    BaseUnit {
        kg,
        m,
        s,
        a,
        rad,
        factor: 1.0,
    }
}

const DEG: f64 = std::f64::consts::PI / 180.0;

/// One unit: (name, base unit, display units with their factor to the base unit).
pub type UnitRow = (&'static str, BaseUnit, &'static [(&'static str, f64)]);

pub const UNITS: &[UnitRow] = &[
    ("s", u(0, 0, 1, 0, 0), &[]),
    (
        "d",
        BaseUnit {
            factor: 86_400.0,
            ..u(0, 0, 1, 0, 0)
        },
        &[],
    ),
    ("1/s", u(0, 0, -1, 0, 0), &[]),
    ("1/s2", u(0, 0, -2, 0, 0), &[]),
    ("rad", u(0, 0, 0, 0, 1), &[("deg", 1.0 / DEG)]),
    ("rad/s", u(0, 0, -1, 0, 1), &[("deg/s", 1.0 / DEG)]),
    ("rad/s2", u(0, 0, -2, 0, 1), &[]),
    (
        "deg",
        BaseUnit {
            factor: DEG,
            ..u(0, 0, 0, 0, 1)
        },
        &[],
    ),
    (
        "deg/s",
        BaseUnit {
            factor: DEG,
            ..u(0, 0, -1, 0, 1)
        },
        &[],
    ),
    (
        "deg.s",
        BaseUnit {
            factor: DEG,
            ..u(0, 0, 1, 0, 1)
        },
        &[],
    ),
    ("rad2", u(0, 0, 0, 0, 2), &[]),
    ("rad2/s2", u(0, 0, -2, 0, 2), &[]),
    ("rad2.s", u(0, 0, 1, 0, 2), &[]),
    ("rad2/s", u(0, 0, -1, 0, 2), &[]),
    ("rad2/s3", u(0, 0, -3, 0, 2), &[]),
    ("1/m", u(0, -1, 0, 0, 0), &[]),
    ("m", u(0, 1, 0, 0, 0), &[]),
    ("m/s", u(0, 1, -1, 0, 0), &[]),
    ("m/s2", u(0, 1, -2, 0, 0), &[]),
    ("m.s", u(0, 1, 1, 0, 0), &[]),
    ("m2", u(0, 2, 0, 0, 0), &[]),
    ("W/m2", u(1, 0, -3, 0, 0), &[]),
    ("m3/s2", u(0, 3, -2, 0, 0), &[]),
    ("kg", u(1, 0, 0, 0, 0), &[]),
    ("kg/m2", u(1, -2, 0, 0, 0), &[]),
    ("kg/m3", u(1, -3, 0, 0, 0), &[]),
    ("kg.m2", u(1, 2, 0, 0, 0), &[]),
    ("kg.m2.s2", u(1, 2, 2, 0, 0), &[]),
    ("N", u(1, 1, -2, 0, 0), &[]),
    ("N.s", u(1, 1, -1, 0, 0), &[]),
    ("N2.s", u(2, 2, -3, 0, 0), &[]),
    ("N/m", u(1, 0, -2, 0, 0), &[]),
    ("N.s/m", u(1, 0, -1, 0, 0), &[]),
    ("N/(m.s)", u(1, 0, -3, 0, 0), &[]),
    ("N.m", u(1, 2, -2, 0, 0), &[]),
    ("N.m.s", u(1, 2, -1, 0, 0), &[]),
    ("N2.m2.s", u(2, 4, -3, 0, 0), &[]),
    ("N.m/rad", u(1, 2, -2, 0, -1), &[]),
    ("N.m.s/rad", u(1, 2, -1, 0, -1), &[]),
    ("A", u(0, 0, 0, 1, 0), &[]),
    ("A.m2", u(0, 2, 0, 1, 0), &[]),
    ("N.m/A", u(1, 2, -2, -1, 0), &[]),
    ("T", u(1, 0, -2, -1, 0), &[]),
    ("T.m3", u(1, 3, -2, -1, 0), &[]),
];

/// Whether `name` is "" (dimensionless) or a unit of the table; usable in constants (the declaration
/// macro checks every unit at compile time with it).
pub const fn is_defined(name: &str) -> bool {
    if name.is_empty() {
        return true;
    }
    let mut i = 0;
    while i < UNITS.len() {
        if crate::text::same_str(UNITS[i].0, name) {
            return true;
        }
        i += 1;
    }
    false
}

pub fn lookup(name: &str) -> Option<&'static UnitRow> {
    UNITS.iter().find(|(n, _, _)| *n == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique() {
        for (i, a) in UNITS.iter().enumerate() {
            for b in &UNITS[i + 1..] {
                assert_ne!(a.0, b.0);
            }
        }
    }

    #[test]
    fn newton_metre_is_kg_m2_per_s2() {
        let (_, nm, _) = lookup("N.m").unwrap();
        assert_eq!((nm.kg, nm.m, nm.s), (1, 2, -2));
    }
}
