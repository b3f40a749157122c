//! Integer parameters that select an option: one helper turns the code into an enum, and the same
//! list of codes is the parameter's declared [`Bound::Choice`](super::Bound::Choice).

/// An option selected by an Integer parameter.
pub trait ParamEnum: Sized + Copy {
    /// The admissible codes, for the declaration: `Choice(Kinematics::CODES)`.
    const CODES: &'static [i32];
    fn from_code(code: i32) -> Option<Self>;

    /// The option of a parameter value; the message names the parameter (normally unreachable,
    /// because the declared bound has already refused unknown codes).
    fn from_param(name: &str, code: i32) -> Result<Self, String> {
        Self::from_code(code).ok_or_else(|| format!("parameter {name} = {code} is not one of {:?}", Self::CODES))
    }
}

/// Declares an enum selected by an Integer parameter and its codes:
///
/// ```
/// use spacecraft_fmus::export::*;
///
/// param_enum! {
///     /// Kinematics option.
///     pub enum Kinematics { Quaternion = 0, Dcm = 1 }
/// }
///
/// declare_variables! {
///     pub struct Vars {
///         // the codes are the parameter's bound: any other value is refused before initialize
///         140 => kinematics: Integer = 0, Parameter, "", "0 = quaternion, 1 = DCM", Choice(Kinematics::CODES);
///     }
/// }
///
/// assert_eq!(Kinematics::from_param("kinematics", 1), Ok(Kinematics::Dcm));
/// assert_eq!(Kinematics::from_param("kinematics", 7).unwrap_err(), "parameter kinematics = 7 is not one of [0, 1]");
/// ```
#[macro_export]
macro_rules! param_enum {
    ($(#[$meta:meta])* $vis:vis enum $Name:ident { $( $(#[$vmeta:meta])* $variant:ident = $code:literal ),+ $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
        $vis enum $Name { $( $(#[$vmeta])* $variant ),+ }

        impl $crate::model::ParamEnum for $Name {
            const CODES: &'static [i32] = &[$($code),+];
            fn from_code(code: i32) -> Option<Self> {
                match code {
                    $( $code => Some($Name::$variant), )+
                    _ => None,
                }
            }
        }
    };
}
