//! The assistant's instrument (`Assistant`, in `format`), its script turned into the device
//! trajectory that moves it, and its checks. It is a grasper through a port of its own that
//! the scenario moves, key by key, as a surgical assistant holds the fundus up over the liver while the trainee
//! works with both hands. It is a third hand of the haptic world, on a scripted device; the
//! trainee's scores never read it. Its jaws stay shut and it holds the organ up by pushing:
//! an organ's dynamics hold one grasp at a time, and that grasp is the trainee's.

use super::format::{Assistant, Port};
use super::problem::Problem;
use super::scene::metres;
use crate::devices::{DeviceSample, MIN_OUTSIDE_M, Trajectory, TrajectoryRow};

impl Assistant {
    /// The device trajectory that moves the instrument's handle so that its tip follows the
    /// script through the port, the scene's frame one to one, no button pressed; `None` if a
    /// key's tip is out of the instrument's reach (what [`check`] refuses).
    pub fn trajectory(&self) -> Option<Trajectory> {
        let fulcrum = self.port.fulcrum();
        let rows = self.script.iter().map(|key| {
            let tip_m = metres(key.tip_mm);
            reaches(&self.port, &tip_m).then_some(())?;
            let sample = DeviceSample::at(fulcrum.handle_for(&tip_m)?);
            Some(TrajectoryRow::new(key.at_s, &sample))
        });
        Some(Trajectory {
            rows: rows.collect::<Option<_>>()?,
        })
    }
}

/// Whether the instrument through `port` reaches `tip_m`: beyond the port, and no farther
/// than its shaft less what the hand holds outside.
fn reaches(port: &Port, tip_m: &nalgebra::Vector3<f64>) -> bool {
    let fulcrum = port.fulcrum();
    let inside_m = (tip_m - fulcrum.port_m).norm();
    inside_m > 1e-3 && inside_m <= fulcrum.shaft_m - MIN_OUTSIDE_M
}

/// The assistant holds a grasper of the trainee's tip (`tip_m`), and its script has keys in
/// time order from 0 s, each within the instrument's reach.
pub(super) fn check(assistant: &Assistant, tip_m: f64, problems: &mut Vec<Problem>) {
    let problem = |field: String, anchors: Vec<String>, message: String, hint: &str| Problem {
        field,
        anchors,
        message,
        hint: hint.into(),
    };
    let at = |more: &[&str]| -> Vec<String> {
        let mut anchors = vec!["assistant".to_owned()];
        anchors.extend(more.iter().map(|s| (*s).to_owned()));
        anchors
    };
    if !assistant.tool.grasps() {
        problems.push(problem(
            "assistant.tool".into(),
            at(&["tool"]),
            "the assistant holds a grasper, and this is another instrument".into(),
            "give the assistant `tool: Grasper(tip_radius_mm: …)`",
        ));
    } else if (assistant.tool.tip_radius_m() - tip_m).abs() > 1e-9 {
        problems.push(problem(
            "assistant.tool.tip_radius_mm".into(),
            at(&["tip_radius_mm"]),
            format!(
                "its tip is {} mm, the right hand's {} mm: the organs are built for one tip",
                assistant.tool.tip_radius_m() * 1e3,
                tip_m * 1e3
            ),
            "give the assistant's grasper the right hand's first tip_radius_mm",
        ));
    }
    if assistant.script.is_empty() {
        problems.push(problem(
            "assistant.script".into(),
            at(&["script"]),
            "the assistant's script has no keys".into(),
            "add `Tip(at_s: 0.0, tip_mm: (…))` for where the grasper starts",
        ));
    }
    for (k, key) in assistant.script.iter().enumerate() {
        let earlier_s = k.checked_sub(1).map_or(0.0, |j| assistant.script[j].at_s);
        let message = if !(key.at_s.is_finite() && key.at_s >= earlier_s) {
            format!("the key at {} s comes before {earlier_s} s", key.at_s)
        } else if !reaches(&assistant.port, &metres(key.tip_mm)) {
            format!(
                "the tip at ({}, {}, {}) mm is out of reach of a {} mm instrument through its port",
                key.tip_mm.0, key.tip_mm.1, key.tip_mm.2, assistant.port.shaft_mm.0
            )
        } else {
            continue;
        };
        let mut anchors = at(&["script", "Tip"]);
        anchors.extend(std::iter::repeat_n("Tip".to_owned(), k));
        problems.push(problem(
            format!("assistant.script[{k}]"),
            anchors,
            message,
            "keys in time order from 0 s, each tip beyond the port and within the shaft's reach",
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::format::{TipKey, Tool};
    use crate::scenario::units::Millimetres;

    fn assistant(tips_mm: &[(f64, (f64, f64, f64))]) -> Assistant {
        Assistant {
            tool: Tool::Grasper {
                tip_radius_mm: Millimetres(6.0),
            },
            port: Port {
                at_mm: (140.0, 90.0, -130.0),
                shaft_mm: Millimetres(350.0),
            },
            script: (tips_mm.iter())
                .map(|&(at_s, tip_mm)| TipKey { at_s, tip_mm })
                .collect(),
        }
    }

    /// Each key's handle, taken back through the port, puts the tip where the key says, at
    /// the key's time, no button pressed.
    #[test]
    fn the_handle_puts_the_tip_on_each_key() {
        let keys = [(0.0, (50.0, 35.0, -90.0)), (2.0, (50.0, 40.0, -65.0))];
        let assistant = assistant(&keys);
        let trajectory = assistant.trajectory().unwrap();
        let fulcrum = assistant.port.fulcrum();
        for (row, (at_s, tip_mm)) in trajectory.rows.iter().zip(keys) {
            let sample = trajectory.sample(at_s);
            let tip = fulcrum.pose(&sample.tip_m).unwrap().tip_m;
            assert!((tip - metres(tip_mm)).norm() < 1e-9, "{tip:?}");
            assert_eq!((row.time_s, row.buttons), (at_s, 0));
        }
    }

    /// A key beyond the shaft's reach, or back in time, is refused at its index; a tool other
    /// than a grasper is refused.
    #[test]
    fn keys_out_of_reach_or_order_are_refused() {
        let far = assistant(&[(0.0, (50.0, 35.0, -90.0)), (1.0, (50.0, 35.0, 400.0))]);
        assert!(far.trajectory().is_none());
        let mut problems = Vec::new();
        check(&far, 6e-3, &mut problems);
        assert_eq!(problems.len(), 1);
        assert_eq!(problems[0].field, "assistant.script[1]");
        let back = assistant(&[(1.0, (50.0, 35.0, -90.0)), (0.5, (50.0, 35.0, -80.0))]);
        let mut problems = Vec::new();
        check(&back, 6e-3, &mut problems);
        assert!(
            problems[0].message.contains("comes before"),
            "{}",
            problems[0].message
        );
        let mut hook = assistant(&[(0.0, (50.0, 35.0, -90.0))]);
        hook.tool = Tool::Probe {
            tip_radius_mm: Millimetres(6.0),
        };
        let mut problems = Vec::new();
        check(&hook, 6e-3, &mut problems);
        assert_eq!(problems[0].field, "assistant.tool");
    }
}
