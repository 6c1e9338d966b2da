//! What is wrong with a scenario, as the trainee's educator reads it: the file, the line and
//! column, the field, the problem and a hint; and a problem found after parsing, located in
//! the text by the field it is about.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where every reference of the scenario format is explained.
pub(super) const REFERENCE: &str = "docs/scenarios.md";

#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioError {
    pub file: PathBuf,
    /// 1-based, as editors count.
    pub line: usize,
    pub column: usize,
    /// The field path, e.g. `tasks[1].max_force_n` (empty for the file as a whole).
    pub field: String,
    pub message: String,
    pub hint: String,
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}: ", self.file.display(), self.line, self.column)?;
        if !self.field.is_empty() {
            write!(f, "{}: ", self.field)?;
        }
        write!(f, "{}\n  hint: {}", self.message, self.hint)
    }
}

impl std::error::Error for ScenarioError {}

impl ScenarioError {
    /// `file` could not be read as text, for the reason `why`.
    pub fn unreadable(file: &Path, why: impl fmt::Display) -> Self {
        Self {
            file: file.to_owned(),
            line: 1,
            column: 1,
            field: String::new(),
            message: format!("cannot read it: {why}"),
            hint: "check the path; shipped scenarios are in scenarios/".into(),
        }
    }
}

/// A problem found after parsing: the field path, and what to look for in the text to put
/// the cursor on it (each key or quoted value in turn, from the start of the file; the same
/// anchor twice in a row, the next occurrence).
pub(in crate::scenario) struct Problem {
    pub field: String,
    pub anchors: Vec<String>,
    pub message: String,
    pub hint: String,
}

impl Problem {
    pub fn locate(self, file: &Path, text: &str) -> ScenarioError {
        let mut at = 0;
        let mut previous: Option<&String> = None;
        for anchor in &self.anchors {
            // An anchor repeated finds the next occurrence (the k-th item of a list).
            let from = at + previous.filter(|p| *p == anchor).map_or(0, |p| p.len());
            if let Some(found) = text.get(from..).and_then(|rest| rest.find(anchor.as_str())) {
                at = from + found;
            }
            previous = Some(anchor);
        }
        let line = text[..at].matches('\n').count() + 1;
        let column = at - text[..at].rfind('\n').map_or(0, |n| n + 1) + 1;
        ScenarioError {
            file: file.to_owned(),
            line,
            column,
            field: self.field,
            message: self.message,
            hint: self.hint,
        }
    }
}
