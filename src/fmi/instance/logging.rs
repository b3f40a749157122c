//! Logging of an instance: messages to the master's callback (either shape of [`Logger`]), filtered by
//! the debug-logging switch and the categories enabled by the room's debug-logging call; failures are
//! worded by the instance's dialect.

use std::ffi::{c_int, CString};

use super::{CallResult, Fail, Instance, Logger};
use crate::fmi::types::{Status, LOG_CATEGORIES};

impl Instance {
    /// Sends a message to the logger callback. Warnings and errors always go out; other messages
    /// only with debug logging on and their category enabled.
    pub fn log(&self, status: Status, category: &str, message: &str) {
        if matches!(self.logger, Logger::None) {
            return;
        }
        if status < Status::Warning
            && !(self.debug_logging && (self.categories.contains(category) || self.categories.contains("logAll")))
        {
            return;
        }
        let cat = CString::new(category).unwrap_or_default();
        match self.logger {
            Logger::None => {}
            Logger::Printf(logger) => {
                // The message is a printf format for C loggers: escape '%'; interior NULs cannot pass.
                let text = CString::new(message.replace('%', "%%").replace('\0', "")).unwrap_or_default();
                // SAFETY: the logger is the master's callback with the `PrintfLogFn` signature; all
                // strings are valid NUL-terminated for the duration of the call.
                unsafe {
                    logger(
                        self.env,
                        self.name.as_ptr(),
                        status as c_int,
                        cat.as_ptr(),
                        text.as_ptr(),
                    )
                };
            }
            Logger::Text(logger) => {
                // plain text (no printf format) that carries no instance name: prefix it
                let text = CString::new(format!("{}: {}", self.name.to_string_lossy(), message).replace('\0', ""))
                    .unwrap_or_default();
                // SAFETY: the master's `TextLogFn` callback; strings valid for the duration of the call.
                unsafe { logger(self.env, status as c_int, cat.as_ptr(), text.as_ptr()) };
            }
        }
    }

    pub fn log_fail(&self, func: &str, fail: &Fail) {
        let category = match fail.status {
            Status::Fatal => "logStatusFatal",
            Status::Error => "logStatusError",
            _ => "logStatusWarning",
        };
        self.log(
            fail.status,
            category,
            &format!("{func}: {}", fail.reason.render(self.dialect)),
        );
    }

    pub fn trace(&self, message: impl FnOnce() -> String) {
        if self.debug_logging && (self.categories.contains("logCalls") || self.categories.contains("logAll")) {
            self.log(Status::Ok, "logCalls", &message());
        }
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> CallResult {
        let known: Vec<&'static str> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
        if let Some(bad) = categories.iter().find(|c| !known.contains(&c.as_str())) {
            return Err(Fail::error(format!(
                "unknown log category '{bad}' (declared: {})",
                known.join(", ")
            )));
        }
        self.debug_logging = on;
        if categories.is_empty() {
            self.categories = known.into_iter().collect();
        } else {
            for c in categories {
                let c = known
                    .iter()
                    .find(|k| **k == c.as_str())
                    .copied()
                    .expect("checked above");
                if on {
                    self.categories.insert(c);
                } else {
                    self.categories.remove(c);
                }
            }
        }
        Ok(())
    }
}
