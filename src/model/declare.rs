//! `declare_variables!`: the one declaration of a model's variables, and the const helpers it uses.
//!
//! ```
//! use spacecraft_fmus::export::*;
//!
//! declare_variables! {
//!     /// Variables of a controller.
//!     pub struct MyControllerVars {
//!         ports: AttitudeControllerPorts;          // a shared port block, embedded by name (optional)
//!         // vr  field    kind = start,              causality, unit,   description [, bound]
//!         103 => wn: Real = 1.0,                     Parameter, "rad/s", "Natural frequency", Positive;
//!         105 => kp: Vec3 = [1000.0, 500.0, 700.0],  Parameter, "N.m/rad", "Proportional gain";
//!         120 => mode: Integer = 0,                  Parameter, "", "0 = a, 1 = b", Choice(&[0, 1]);
//!     }
//! }
//!
//! // one row of a Vec3 is three FMI variables; the embedded block's variables come first
//! let names: Vec<&str> = MyControllerVars::DECLS.iter().map(|d| d.name).collect();
//! assert_eq!(&names[names.len() - 5..], ["wn", "kp_x", "kp_y", "kp_z", "mode"]);
//! assert_eq!(MyControllerVars::DECLS.iter().find(|d| d.name == "kp_y").unwrap().vr, 106);
//! assert_eq!(MyControllerVars::default().kp, Vector3::new(1000.0, 500.0, 700.0));
//! ```
//!
//! Kinds: `Real` (f64), `Integer` (i32), `Boolean` (bool), `Vec3` (`nalgebra::Vector3`, FMI names
//! `<field>_x/_y/_z` at vr, vr+1, vr+2), `Diag3` (a Vector3 named `<field>_xx/_yy/_zz`, for inertia
//! diagonals) and `Quat` (`nalgebra::Quaternion`, names `<field>_w/_x/_y/_z` at vr … vr+3, scalar first).
//! Variability follows from causality and kind ([`Variability::derived`](super::Variability::derived)).
//! Bounds ([`Bound`](super::Bound)) are checked before the model initializes and written as min/max.
//! A duplicated value reference or name anywhere in the block (embedded blocks included) is a compile
//! error.

use crate::catalogue::decl::{Bound, Causality, Start, VarDecl, VarKind};
use crate::text::same_str;

/// Sum of the lengths of slices (array length of their concatenation).
pub const fn total_len<T>(parts: &[&[T]]) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < parts.len() {
        n += parts[i].len();
        i += 1;
    }
    n
}

/// Concatenation of slices at compile time; `filler` only initialises the array.
pub const fn concat<T: Copy, const N: usize>(parts: &[&[T]], filler: T) -> [T; N] {
    let mut out = [filler; N];
    let mut k = 0;
    let mut i = 0;
    while i < parts.len() {
        let mut j = 0;
        while j < parts[i].len() {
            out[k] = parts[i][j];
            k += 1;
            j += 1;
        }
        i += 1;
    }
    assert!(k == N, "concatenation length mismatch");
    out
}

pub const fn no_duplicate_vrs(d: &[VarDecl]) -> bool {
    let mut i = 0;
    while i < d.len() {
        let mut j = i + 1;
        while j < d.len() {
            if d[i].vr == d[j].vr {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// What is wrong with the declarations of one field (the `width` variables from value reference `vr`:
/// 1 for scalars, 3 for `Vec3`/`Diag3`, 4 for `Quat`) within the whole table `d`, as a code for the
/// compile-time assertions `declare_variables!` generates (each names the field):
/// 0 nothing; 1 a value reference used by another variable; 2 a name used by another variable;
/// 3 a unit not in `crate::units`; 4 a unit on a non-Real; 5 a parameter start value outside its bound;
/// 6 a bound on a variable that is not a parameter; 7 an empty description; 8 a non-finite start value.
pub const fn field_problem(d: &[VarDecl], vr: u32, width: u32) -> u8 {
    let mut i = 0;
    while i < d.len() {
        let a = &d[i];
        if a.vr >= vr && a.vr < vr + width {
            let mut j = 0;
            while j < d.len() {
                if j != i && d[j].vr == a.vr {
                    return 1;
                }
                if j != i && same_str(d[j].name, a.name) {
                    return 2;
                }
                j += 1;
            }
            if !crate::units::is_defined(a.unit) {
                return 3;
            }
            if !a.unit.is_empty() && !matches!(a.kind, VarKind::Real) {
                return 4;
            }
            if let Start::Real(x) = a.start {
                if !x.is_finite() {
                    return 8;
                }
            }
            if matches!(a.causality, Causality::Parameter) {
                if !a.bound.admits(a.start) {
                    return 5;
                }
            } else if !matches!(a.bound, Bound::Any) {
                return 6;
            }
            if a.description.is_empty() {
                return 7;
            }
        }
        i += 1;
    }
    0
}

pub const fn no_duplicate_names(d: &[VarDecl]) -> bool {
    let mut i = 0;
    while i < d.len() {
        let mut j = i + 1;
        while j < d.len() {
            if same_str(d[i].name, d[j].name) {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

#[macro_export]
macro_rules! declare_variables {
    (
        $(#[$meta:meta])*
        $vis:vis struct $Name:ident {
            $( $block:ident : $Block:ty ; )*
            $( $vr:literal => $field:ident : $kind:ident = $start:expr, $caus:ident, $unit:literal, $desc:literal
               $(, $bound:ident $( ( $($barg:expr),* ) )? )? ; )*
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
        $vis struct $Name {
            $( pub $block: $Block, )*
            $( #[doc = $desc] pub $field: $crate::__declare_field!(@type $kind), )*
        }

        impl Default for $Name {
            fn default() -> Self {
                Self {
                    $( $block: Default::default(), )*
                    $( $field: $crate::__declare_field!(@default $kind $start), )*
                }
            }
        }

        impl $Name {
            const PARTS: &'static [&'static [$crate::model::VarDecl]] = &[
                $( <$Block as $crate::model::Variables>::DECLS, )*
                $( &$crate::__declare_row!(@decls $kind $vr, $field, $start, $caus, $unit, $desc,
                       $crate::__declare_field!(@bound $( $bound $( ( $($barg),* ) )? )? )), )*
            ];
            const ALL_DECLS: [$crate::model::VarDecl; $crate::model::total_len($Name::PARTS)] =
                $crate::model::concat($Name::PARTS, $crate::model::VarDecl::PLACEHOLDER);
        }

        $( $crate::__declare_field!(@check $Name, $vr, $field, $kind, $unit); )*
        const _: () = assert!($crate::model::no_duplicate_vrs(&$Name::ALL_DECLS), concat!("duplicate value reference in ", stringify!($Name), " (between its embedded blocks)"));
        const _: () = assert!($crate::model::no_duplicate_names(&$Name::ALL_DECLS), concat!("duplicate variable name in ", stringify!($Name), " (between its embedded blocks)"));

        impl $crate::model::Variables for $Name {
            const DECLS: &'static [$crate::model::VarDecl] = &$Name::ALL_DECLS;

            fn slot(&mut self, index: usize) -> Option<$crate::model::SlotMut<'_>> {
                const PARTS: &[&[$crate::model::SlotFn<$Name>]] = &[ $( &$crate::__declare_row!(@slots $kind $field), )* ];
                const SLOTS: [$crate::model::SlotFn<$Name>; $crate::model::total_len(PARTS)] = $crate::model::concat(PARTS, |_| unreachable!());
                #[allow(unused_mut)]
                let mut i = index;
                $(
                    let n = <$Block as $crate::model::Variables>::DECLS.len();
                    if i < n {
                        return $crate::model::Variables::slot(&mut self.$block, i);
                    }
                    i -= n;
                )*
                SLOTS.get(i).map(|f| f(self))
            }

            fn value(&self, index: usize) -> Option<$crate::model::Value> {
                const PARTS: &[&[$crate::model::ValueFn<$Name>]] = &[ $( &$crate::__declare_row!(@values $kind $field), )* ];
                const VALUES: [$crate::model::ValueFn<$Name>; $crate::model::total_len(PARTS)] = $crate::model::concat(PARTS, |_| unreachable!());
                #[allow(unused_mut)]
                let mut i = index;
                $(
                    let n = <$Block as $crate::model::Variables>::DECLS.len();
                    if i < n {
                        return $crate::model::Variables::value(&self.$block, i);
                    }
                    i -= n;
                )*
                VALUES.get(i).map(|f| f(self))
            }
        }
    };
}

/// The per-field parts of [`declare_variables!`]: compile-time checks, width, Rust type, default and
/// bound of one field of each kind. Used by `declare_variables!` only.
#[doc(hidden)]
#[macro_export]
macro_rules! __declare_field {
    // compile-time checks of one field, each message naming the field (see `field_problem`)
    (@check $Name:ident, $vr:literal, $field:ident, $kind:ident, $unit:literal) => {
        const _: () = {
            const P: u8 = $crate::model::field_problem(&$Name::ALL_DECLS, $vr, $crate::__declare_field!(@width $kind));
            assert!(P != 1, concat!("declare_variables! ", stringify!($Name), ".", stringify!($field), " (vr ", stringify!($vr), "): its value reference is used by another variable"));
            assert!(P != 2, concat!("declare_variables! ", stringify!($Name), ".", stringify!($field), " (vr ", stringify!($vr), "): its name is used by another variable"));
            assert!(P != 3, concat!("declare_variables! ", stringify!($Name), ".", stringify!($field), " (vr ", stringify!($vr), "): unit \"", $unit, "\" is not in spacecraft_fmus::units (\"\" = dimensionless)"));
            assert!(P != 4, concat!("declare_variables! ", stringify!($Name), ".", stringify!($field), " (vr ", stringify!($vr), "): only Real variables carry a unit"));
            assert!(P != 5, concat!("declare_variables! ", stringify!($Name), ".", stringify!($field), " (vr ", stringify!($vr), "): the start value lies outside the declared bound"));
            assert!(P != 6, concat!("declare_variables! ", stringify!($Name), ".", stringify!($field), " (vr ", stringify!($vr), "): only parameters have bounds"));
            assert!(P != 7, concat!("declare_variables! ", stringify!($Name), ".", stringify!($field), " (vr ", stringify!($vr), "): the description is empty"));
            assert!(P != 8, concat!("declare_variables! ", stringify!($Name), ".", stringify!($field), " (vr ", stringify!($vr), "): the start value is not finite"));
        };
    };
    (@width Real) => { 1 };
    (@width Integer) => { 1 };
    (@width Boolean) => { 1 };
    (@width Vec3) => { 3 };
    (@width Diag3) => { 3 };
    (@width Quat) => { 4 };

    (@type Real) => { f64 };
    (@type Integer) => { i32 };
    (@type Boolean) => { bool };
    (@type Vec3) => { $crate::nalgebra::Vector3<f64> };
    (@type Diag3) => { $crate::nalgebra::Vector3<f64> };
    (@type Quat) => { $crate::nalgebra::Quaternion<f64> };

    (@default Real $s:expr) => { $s };
    (@default Integer $s:expr) => { $s };
    (@default Boolean $s:expr) => { $s };
    (@default Vec3 $s:expr) => { $crate::nalgebra::Vector3::from($s) };
    (@default Diag3 $s:expr) => { $crate::nalgebra::Vector3::from($s) };
    (@default Quat $s:expr) => {{
        let s: [f64; 4] = $s;
        $crate::nalgebra::Quaternion::new(s[0], s[1], s[2], s[3])
    }};

    (@bound) => { $crate::model::Bound::Any };
    (@bound $b:ident) => { $crate::model::Bound::$b };
    (@bound $b:ident ( $($a:expr),* )) => { $crate::model::Bound::$b($($a),*) };
}

/// The rows of [`declare_variables!`] for each kind: the `VarDecl`s of one field (three for `Vec3` and
/// `Diag3`, four for `Quat`), and its slot and value accessors. Used by `declare_variables!` only.
#[doc(hidden)]
#[macro_export]
macro_rules! __declare_row {
    (@one $vr:expr, $name:expr, $kind:ident, $start:expr, $caus:ident, $unit:literal, $desc:expr, $bound:expr) => {
        $crate::model::VarDecl {
            vr: $vr,
            name: $name,
            kind: $crate::model::VarKind::$kind,
            causality: $crate::model::Causality::$caus,
            variability: $crate::model::Variability::derived($crate::model::Causality::$caus, $crate::model::VarKind::$kind),
            unit: $unit,
            description: $desc,
            start: $crate::model::Start::$kind($start),
            bound: $bound,
        }
    };
    (@decls Real $vr:literal, $f:ident, $s:expr, $c:ident, $u:literal, $d:literal, $b:expr) => {
        [$crate::__declare_row!(@one $vr, stringify!($f), Real, $s, $c, $u, $d, $b)]
    };
    (@decls Integer $vr:literal, $f:ident, $s:expr, $c:ident, $u:literal, $d:literal, $b:expr) => {
        [$crate::__declare_row!(@one $vr, stringify!($f), Integer, $s, $c, $u, $d, $b)]
    };
    (@decls Boolean $vr:literal, $f:ident, $s:expr, $c:ident, $u:literal, $d:literal, $b:expr) => {
        [$crate::__declare_row!(@one $vr, stringify!($f), Boolean, $s, $c, $u, $d, $b)]
    };
    (@decls Vec3 $vr:literal, $f:ident, $s:expr, $c:ident, $u:literal, $d:literal, $b:expr) => {[
        $crate::__declare_row!(@one $vr, concat!(stringify!($f), "_x"), Real, $s[0], $c, $u, concat!($d, ", x"), $b),
        $crate::__declare_row!(@one $vr + 1, concat!(stringify!($f), "_y"), Real, $s[1], $c, $u, concat!($d, ", y"), $b),
        $crate::__declare_row!(@one $vr + 2, concat!(stringify!($f), "_z"), Real, $s[2], $c, $u, concat!($d, ", z"), $b),
    ]};
    (@decls Diag3 $vr:literal, $f:ident, $s:expr, $c:ident, $u:literal, $d:literal, $b:expr) => {[
        $crate::__declare_row!(@one $vr, concat!(stringify!($f), "_xx"), Real, $s[0], $c, $u, concat!($d, ", xx"), $b),
        $crate::__declare_row!(@one $vr + 1, concat!(stringify!($f), "_yy"), Real, $s[1], $c, $u, concat!($d, ", yy"), $b),
        $crate::__declare_row!(@one $vr + 2, concat!(stringify!($f), "_zz"), Real, $s[2], $c, $u, concat!($d, ", zz"), $b),
    ]};
    (@decls Quat $vr:literal, $f:ident, $s:expr, $c:ident, $u:literal, $d:literal, $b:expr) => {[
        $crate::__declare_row!(@one $vr, concat!(stringify!($f), "_w"), Real, $s[0], $c, $u, concat!($d, ", scalar part"), $b),
        $crate::__declare_row!(@one $vr + 1, concat!(stringify!($f), "_x"), Real, $s[1], $c, $u, concat!($d, ", x component"), $b),
        $crate::__declare_row!(@one $vr + 2, concat!(stringify!($f), "_y"), Real, $s[2], $c, $u, concat!($d, ", y component"), $b),
        $crate::__declare_row!(@one $vr + 3, concat!(stringify!($f), "_z"), Real, $s[3], $c, $u, concat!($d, ", z component"), $b),
    ]};

    (@slots Real $f:ident) => { [|s| $crate::model::SlotMut::Real(&mut s.$f)] };
    (@slots Integer $f:ident) => { [|s| $crate::model::SlotMut::Integer(&mut s.$f)] };
    (@slots Boolean $f:ident) => { [|s| $crate::model::SlotMut::Boolean(&mut s.$f)] };
    (@slots Vec3 $f:ident) => {[
        |s| $crate::model::SlotMut::Real(&mut s.$f.x),
        |s| $crate::model::SlotMut::Real(&mut s.$f.y),
        |s| $crate::model::SlotMut::Real(&mut s.$f.z),
    ]};
    (@slots Diag3 $f:ident) => { $crate::__declare_row!(@slots Vec3 $f) };
    (@slots Quat $f:ident) => {[
        |s| $crate::model::SlotMut::Real(&mut s.$f.w),
        |s| $crate::model::SlotMut::Real(&mut s.$f.i),
        |s| $crate::model::SlotMut::Real(&mut s.$f.j),
        |s| $crate::model::SlotMut::Real(&mut s.$f.k),
    ]};

    (@values Real $f:ident) => { [|s| $crate::model::Value::Real(s.$f)] };
    (@values Integer $f:ident) => { [|s| $crate::model::Value::Integer(s.$f)] };
    (@values Boolean $f:ident) => { [|s| $crate::model::Value::Boolean(s.$f)] };
    (@values Vec3 $f:ident) => {[
        |s| $crate::model::Value::Real(s.$f.x),
        |s| $crate::model::Value::Real(s.$f.y),
        |s| $crate::model::Value::Real(s.$f.z),
    ]};
    (@values Diag3 $f:ident) => { $crate::__declare_row!(@values Vec3 $f) };
    (@values Quat $f:ident) => {[
        |s| $crate::model::Value::Real(s.$f.w),
        |s| $crate::model::Value::Real(s.$f.i),
        |s| $crate::model::Value::Real(s.$f.j),
        |s| $crate::model::Value::Real(s.$f.k),
    ]};
}
