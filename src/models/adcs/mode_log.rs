//! The log line of an ADCS mode transition (`ModeLogic::describe`), from the codes' names in
//! `mode_codes.rs` and the quantities the logic measured (`modes.rs`).

use super::mode_codes::{num, Mode, Reason};
use super::modes::{ModeLogic, Outcome};

impl ModeLogic {
    /// The log line of a transition: time, old -> new mode and the condition that fired it.
    pub fn describe(&self, o: &Outcome) -> Option<String> {
        let tr = o.transition?;
        let (p, q) = (&self.p, &o.q);
        let nis = q.nis_avg.map_or("none".to_string(), num);
        let why = match tr.reason {
            Reason::Fault => format!(
                "actuator_fault held {} s >= fault_confirm_time {} s",
                num(q.fault_held),
                num(p.fault_confirm_time)
            ),
            Reason::SafeRequest => "safe_request >= 0.5".to_string(),
            Reason::RateHigh => format!("rate {} rad/s > rate_safe {}", num(q.rate), num(p.rate_safe)),
            Reason::DivergedSigma => format!(
                "sigma_att {} rad > sigma_diverged {}",
                num(q.sigma),
                num(p.sigma_diverged)
            ),
            Reason::DivergedNis => format!("nis_avg {nis} > nis_diverged {}", num(p.nis_diverged)),
            Reason::Recover => format!(
                "{}, rate {} rad/s {} rate_tumbling {}",
                if q.recover_input {
                    "recover >= 0.5".to_string()
                } else {
                    format!("t >= recover_time {}", num(p.recover_time))
                },
                num(q.rate),
                if tr.to == Mode::Detumble { ">" } else { "<=" },
                num(p.rate_tumbling)
            ),
            Reason::Detumbled => format!("rate {} rad/s < rate_detumbled {}", num(q.rate), num(p.rate_detumbled)),
            Reason::Tumbling => format!("rate {} rad/s > rate_tumbling {}", num(q.rate), num(p.rate_tumbling)),
            Reason::SunAcquired => format!(
                "sun_angle {} rad < sun_angle_acquired {}, rate {} rad/s < rate_detumbled {}",
                num(q.sun_angle),
                num(p.sun_angle_acquired),
                num(q.rate),
                num(p.rate_detumbled)
            ),
            Reason::SunLost => format!(
                "sun_angle {} rad > sun_angle_lost {}",
                num(q.sun_angle),
                num(p.sun_angle_lost)
            ),
            Reason::Converged => format!(
                "sigma_att {} rad < sigma_converged {}, nis_avg {nis} < nis_max {}",
                num(q.sigma),
                num(p.sigma_converged),
                num(p.nis_max)
            ),
        };
        Some(format!(
            "t = {} s: {} -> {} ({why}; {})",
            o.t,
            tr.from.name(),
            tr.to.name(),
            tr.reason.name()
        ))
    }
}
