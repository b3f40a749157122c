//! One file per FMU model. Each declares its variables, its init/step code and its documentation;
//! `crate::registry` lists them.

pub mod adaptive_fuzzy_controller;
pub mod attitude_command;
pub mod attitude_controller;
pub mod attitude_metrics;
pub mod attitude_plant;
pub mod fopid_controller;
pub mod fuzzy_pd_controller;
pub mod lqr_controller;
pub mod mrac_controller;
pub mod pd_controller;
pub mod pid_controller;
pub mod pole_placement_controller;
pub mod predictive_pid_controller;
pub mod relative_orbit_plant;
pub mod relative_position_command;
pub mod single_axis_plant;
