//! What the attitude controllers share — not FMUs themselves: the common port block (declared in the
//! public `crate::models::ports`, re-exported here), paper 000's error
//! laws and per-axis linear law, the model-reference adaptive (MRAC) core with its variable block,
//! paper 003's quaternion sliding-mode law with its variable block, and paper 004's
//! feedback-linearising law with the reference corrector's open-loop plant copy.
//! A new controller takes its ports from here; a law two controllers need goes here.

pub mod error_law;
pub mod feedback_linearization;
pub mod mrac;
pub mod mrac_exchange;
pub mod smc;

pub use crate::models::ports::{check_unit_quaternions, AttitudeControllerPorts};
pub use error_law::{linear_law, DcmError, ErrorLaw};
