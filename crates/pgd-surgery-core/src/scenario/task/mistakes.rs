//! The mistakes a task notes as it runs, as a few numbers each: the haptic thread notes them
//! into room made before the attempt, and they are put into words (with the task's organ and
//! zone names) only when the attempt is scored, away from it.

use super::Task;
use super::countertraction::Lapse;
use crate::scenario::units::Newtons;

/// How many mistakes a task keeps in detail; past that they are counted, not listed.
pub const MISTAKES_LISTED: usize = 64;

/// One mistake, and when it was made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mistake {
    /// The tool's force went over the task's limit (every task watches it).
    OverLimit { time_s: f64, limit_n: f64 },
    /// A mistake of the task's type's own, numbered `code` by it, with an amount to say (a
    /// limit, a zone's number); its type puts it into words.
    Own { time_s: f64, code: u16, amount: f64 },
    /// The other hand's counter-traction lapsed (the task's `countertraction`).
    Countertraction { time_s: f64, lapse: Lapse },
    /// The hand came onto tissue with an instrument not among the task's `instruments`.
    OtherInstrument { time_s: f64, kind: &'static str },
}

impl Mistake {
    /// The mistake in words, for `task` (the one that noted it).
    pub fn describe(&self, task: &Task) -> String {
        match *self {
            Mistake::OverLimit { time_s, limit_n } => format!(
                "{time_s:.2} s: {} harder than {} N",
                task.force_verb(),
                Newtons(limit_n)
            ),
            Mistake::Own {
                time_s,
                code,
                amount,
            } => format!("{time_s:.2} s: {}", task.describe_mistake(code, amount)),
            Mistake::Countertraction { time_s, lapse } => {
                let countertraction = task.shared.countertraction.as_ref();
                let words = countertraction.map(|c| c.describe(task.hand(), lapse));
                format!("{time_s:.2} s: {}", words.unwrap_or_default())
            }
            Mistake::OtherInstrument { time_s, kind } => format!(
                "{time_s:.2} s: worked on tissue with the {kind}, not with the task's {}",
                task.shared.instruments.join(" or ")
            ),
        }
    }
}

/// A task's mistakes: the first [`MISTAKES_LISTED`] in detail, the others counted.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mistakes {
    listed: Vec<Mistake>,
    unlisted: usize,
}

impl Mistakes {
    /// Room for the mistakes listed, made before the task runs.
    pub fn reserved() -> Self {
        Self {
            listed: Vec::with_capacity(MISTAKES_LISTED),
            unlisted: 0,
        }
    }

    /// Notes `mistake`; never allocates once reserved.
    pub fn note(&mut self, mistake: Mistake) {
        match self.listed.len() < MISTAKES_LISTED.min(self.listed.capacity()) {
            true => self.listed.push(mistake),
            false => self.unlisted += 1,
        }
    }

    /// The mistakes listed, in words, and how many more were made.
    pub fn describe(&self, task: &Task) -> (Vec<String>, usize) {
        let words = self.listed.iter().map(|m| m.describe(task)).collect();
        (words, self.unlisted)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Past the room made, mistakes are counted, not listed, and noting them never grows it.
    #[test]
    fn mistakes_past_the_room_are_counted_without_growing_it() {
        let mut mistakes = Mistakes::reserved();
        let room = mistakes.listed.capacity();
        for k in 0..MISTAKES_LISTED + 6 {
            mistakes.note(Mistake::OverLimit {
                time_s: k as f64,
                limit_n: 1.0,
            });
        }
        assert_eq!(mistakes.listed.capacity(), room);
        assert_eq!(
            (mistakes.listed.len(), mistakes.unlisted),
            (MISTAKES_LISTED, 6)
        );
    }
}
