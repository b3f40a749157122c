//! What the attitude controllers share — not FMUs themselves: the common port block, paper 000's error
//! laws and per-axis linear law, the model-reference adaptive (MRAC) core with its variable block, and
//! paper 003's quaternion sliding-mode law with its variable block.
//! A new controller takes its ports from here; a law two controllers need goes here.

pub mod error_law;
pub mod mrac;
pub mod ports;
pub mod smc;

pub use error_law::{linear_law, ErrorLaw};
pub use ports::{check_unit_quaternions, AttitudeControllerPorts};
