//! VTK results of a run (`output.directory`).

use super::{LogEvent, Slave};
use crate::model::category;

/// A file name made from a model name: characters other than letters, digits, `-`, `_` and `.`
/// become `_`.
pub(super) fn file_stem(name: &str) -> String {
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() || stem.chars().all(|c| c == '.') {
        "body".into()
    } else {
        stem
    }
}

impl Slave {
    /// Writes the current state to the results if they are on and a state is due. A file error
    /// is logged and switches the results off: it never fails the simulation.
    pub(super) fn write_results(&mut self) {
        let (Some(writer), Some(model), Some(dynamics)) = (
            self.results.as_mut(),
            self.model.as_ref(),
            self.dynamics.as_ref(),
        ) else {
            return;
        };
        let s = &dynamics.state;
        if !writer.is_due(s.time) {
            return;
        }
        if let Err(e) = writer.write(
            s.time,
            &self.mesh,
            &self.parameters.material,
            &model.body,
            &s.position,
            &s.velocity,
        ) {
            self.output_failed(&e);
        }
    }

    /// Logs a failure to write results (an error message; the call itself succeeds) and stops
    /// writing.
    pub(super) fn output_failed(&mut self, reason: &str) {
        self.results = None;
        self.events.push(LogEvent {
            category: category::ERROR,
            message: format!(
                "error: output.directory = '{}': {reason}; no further results are written (the simulation goes on)",
                self.parameters.output_directory
            ),
        });
    }
}
