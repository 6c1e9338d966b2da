//! What a task type checks of its fields once the whole scenario is read, and how it says
//! what is wrong: the field, the problem and a hint, located in the text by the field's name.

use crate::scenario::attachment::AttachmentEntry;
use crate::scenario::problem::Problem;
use crate::scenario::scene::{Nodule, OrganEntry};

use super::TaskShared;

/// What of the scenario a task's fields are checked against.
#[derive(Clone, Copy)]
pub struct SceneFacts<'a> {
    pub organs: &'a [OrganEntry],
    pub nodules: &'a [Nodule],
    /// Whether an instrument in the trainee's hand is a scalpel...
    pub blade: bool,
    /// ...or a grasper...
    pub grasps: bool,
    /// ...or an electrocautery hook...
    pub hook: bool,
    /// ...or a clip applier...
    pub clips: bool,
    /// ...or scissors.
    pub divides: bool,
    /// Whether the scene has a biliary tree (`Biliary(…)`).
    pub biliary: bool,
    /// The organs bound to others by connective tissue.
    pub attachments: &'a [AttachmentEntry],
    /// The most the scenario's device may push (N).
    pub device_max_force_n: f64,
}

/// One end of a force band as [`TaskCheck::force_band`] checks it: its field's path (after
/// `tasks[k].`), the words that find it in the file, and its value (N).
pub struct BandEnd<'a> {
    pub field: &'a str,
    pub anchors: &'a [&'a str],
    pub value_n: f64,
}

/// The scene as a task's check sees it, and the problems noted so far.
pub struct TaskCheck<'a> {
    pub scene: SceneFacts<'a>,
    pub shared: &'a TaskShared,
    /// The task's place in the scenario's list, and its type's name.
    index: usize,
    name: &'static str,
    pub(in crate::scenario) problems: Vec<Problem>,
}

impl<'a> TaskCheck<'a> {
    pub(in crate::scenario) fn new(
        scene: SceneFacts<'a>,
        shared: &'a TaskShared,
        index: usize,
        name: &'static str,
    ) -> Self {
        Self {
            scene,
            shared,
            index,
            name,
            problems: Vec::new(),
        }
    }

    /// The field's path in the scenario: `tasks[2].hold_s`.
    pub fn field(&self, name: &str) -> String {
        format!("tasks[{}].{name}", self.index)
    }

    /// The task's name in the file (`Incision`).
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The task's organ in the scene, if it names one the scene has.
    pub fn organ(&self) -> Option<&'a OrganEntry> {
        let name = self.shared.organ.as_deref()?;
        self.scene.organs.iter().find(|o| o.name == name)
    }

    /// The task's organ's name ("organ" for a task on none).
    pub fn organ_name(&self) -> &'a str {
        self.shared.organ.as_deref().unwrap_or("organ")
    }

    /// Notes a problem with the field `name`, the cursor put on its first use after `tasks`.
    pub fn problem(&mut self, name: &str, message: impl Into<String>, hint: impl Into<String>) {
        self.problem_at(name, &["tasks", name], message, hint);
    }

    /// Notes a problem with the field `name`, the cursor put on each of `anchors` in turn.
    pub fn problem_at(
        &mut self,
        name: &str,
        anchors: &[&str],
        message: impl Into<String>,
        hint: impl Into<String>,
    ) {
        self.problems.push(Problem {
            field: self.field(name),
            anchors: anchors.iter().map(|a| (*a).to_owned()).collect(),
            message: message.into(),
            hint: hint.into(),
        });
    }

    /// The task's force limit must be one the device can send.
    pub fn within_device(&mut self) {
        let (max_force_n, device_n) = (self.shared.max_force_n.0, self.scene.device_max_force_n);
        if max_force_n > device_n {
            self.problem(
                "max_force_n",
                format!("{max_force_n} N is above the device's limit of {device_n} N"),
                "lower it, or raise device.max_force_n",
            );
        }
    }

    /// A force band, `min` to `max` (each its field's path and the anchors that find it, and
    /// its value in N), must not be empty, and its top must be a force the device can send.
    pub fn force_band(&mut self, min: BandEnd<'_>, max: BandEnd<'_>) {
        let (min_n, max_n) = (min.value_n, max.value_n);
        if min_n >= max_n {
            self.problem_at(
                min.field,
                min.anchors,
                format!("the band is empty: {min_n} N is not below {max_n} N"),
                "make min_force_n smaller than max_force_n",
            );
        }
        let device_n = self.scene.device_max_force_n;
        if max_n > device_n {
            self.problem_at(
                max.field,
                max.anchors,
                format!(
                    "{max_n} N is above the device's limit of {device_n} N: the band cannot be reached"
                ),
                "lower it, or raise device.max_force_n",
            );
        }
    }

    /// Holding for `hold_s` must fit in the task's time limit.
    pub fn hold_fits(&mut self, hold_s: f64) {
        let time_limit_s = self.shared.time_limit_s.0;
        if hold_s >= time_limit_s {
            self.problem(
                "hold_s",
                format!("holding {hold_s} s cannot fit in the time limit of {time_limit_s} s"),
                "make time_limit_s longer than hold_s",
            );
        }
    }
}
