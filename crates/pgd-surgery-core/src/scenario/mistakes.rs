//! The mistakes a task notes as it runs, as a few numbers each: the haptic thread notes them
//! into room made before the attempt, and they are put into words (with the task's organ and
//! zone names) only when the attempt is scored, away from it.

use super::format::{Task, TaskKind, spot_name};
use super::units::Newtons;

/// How many mistakes a task keeps in detail; past that they are counted, not listed.
pub const MISTAKES_LISTED: usize = 64;

/// One mistake, and when it was made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mistake {
    /// The tool's force went over the task's limit.
    OverLimit { time_s: f64, limit_n: f64 },
    /// The load on the organs around the retracted one went over its limit.
    OverSurrounding { time_s: f64, limit_n: f64 },
    /// The cut strayed farther off the line than allowed.
    OffTheLine { time_s: f64, limit_mm: f64 },
    /// The grasper tore the task's organ.
    Tore { time_s: f64 },
    /// The tip entered the task's forbidden zone number `zone`.
    Forbidden { time_s: f64, zone: usize },
}

impl Mistake {
    /// The mistake in words, for `task` (the one that noted it).
    pub fn describe(&self, task: &Task) -> String {
        let organ = task_organ(task);
        match *self {
            Mistake::OverLimit { time_s, limit_n } => {
                let verb = match task.kind() {
                    TaskKind::Grasp => "pulled",
                    _ => "pressed",
                };
                format!("{time_s:.2} s: {verb} harder than {} N", Newtons(limit_n))
            }
            Mistake::OverSurrounding { time_s, limit_n } => format!(
                "{time_s:.2} s: loaded the organs around harder than {} N",
                Newtons(limit_n)
            ),
            Mistake::OffTheLine { time_s, limit_mm } => {
                format!("{time_s:.2} s: cut the {organ} more than {limit_mm:.0} mm off the line")
            }
            Mistake::Tore { time_s } => format!("{time_s:.2} s: tore the {organ}"),
            Mistake::Forbidden { time_s, zone } => {
                let name = match task {
                    Task::SafeNavigation { forbidden, .. } => forbidden
                        .get(zone)
                        .map_or_else(|| format!("zone {}", zone + 1), |s| spot_name(s, zone)),
                    _ => format!("zone {}", zone + 1),
                };
                format!("{time_s:.2} s: entered the forbidden {name}")
            }
        }
    }
}

/// The organ a task works on, for its mistakes' words ("organ" for navigation, on none).
pub fn task_organ(task: &Task) -> &str {
    task.organ().unwrap_or("organ")
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
            mistakes.note(Mistake::Tore { time_s: k as f64 });
        }
        assert_eq!(mistakes.listed.capacity(), room);
        assert_eq!(
            (mistakes.listed.len(), mistakes.unlisted),
            (MISTAKES_LISTED, 6)
        );
    }
}
