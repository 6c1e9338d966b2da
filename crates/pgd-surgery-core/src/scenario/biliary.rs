//! The biliary tree a scenario puts in the scene, written `Biliary(…)`: the patient's
//! anatomy within its published ranges and what the critical view of safety asks; and what
//! a scenario with one, or with instruments that need one, must have.

use serde::Deserialize;

use super::problem::Problem;
use super::task::SceneFacts;
use crate::biliary::anatomy::RANGES;
use crate::biliary::{Anatomy, AnatomyError, BiliaryTree, CriticalViewRule};
use crate::mesh::organs::{Abdomen, Organ, OrganSettings};

/// The ducts and the artery of the hepatocystic triangle.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(rename = "Biliary", deny_unknown_fields)]
pub struct BiliaryEntry {
    /// `Anatomy(…)`: the sizes and the variant (the usual anatomy when left out).
    #[serde(default)]
    pub anatomy: Anatomy,
    /// `CriticalView(…)`: how much of each criterion of the critical view of safety is
    /// enough (0.9 of the triangle's fat cleared, 0.9 of the lower third released, half of
    /// each structure's last centimetre seen, when left out).
    #[serde(default)]
    pub critical_view: CriticalViewRule,
}

/// The organs the tree runs between: it is generated with them.
const BETWEEN: [Organ; 3] = [Organ::Liver, Organ::Gallbladder, Organ::Duodenum];

impl BiliaryEntry {
    /// The tree of this anatomy in the generated abdomen.
    pub fn tree(&self) -> Result<BiliaryTree, AnatomyError> {
        BiliaryTree::generate(&self.anatomy, &Abdomen::new(&OrganSettings::default()))
    }
}

/// What is wrong with the scenario's biliary tree `entry`, or with its instruments that need
/// one, in the scene `scene`.
pub(super) fn check(
    entry: Option<&BiliaryEntry>,
    scene: &SceneFacts<'_>,
    problems: &mut Vec<Problem>,
) {
    let Some(entry) = entry else {
        check_tools(scene, problems);
        return;
    };
    for organ in BETWEEN {
        let generated = (scene.organs.iter()).any(|o| o.name == organ.name() && o.mesh.is_none());
        if !generated {
            problems.push(Problem {
                field: "biliary".into(),
                anchors: vec!["biliary".into()],
                message: format!(
                    "the biliary tree runs from the liver to the gallbladder and the duodenum, \
                     and the scene has no generated {}",
                    organ.name()
                ),
                hint: "add \"liver\", \"gallbladder\" and \"duodenum\" to organs".into(),
            });
            return;
        }
    }
    match entry.anatomy.check().and_then(|()| entry.tree().map(drop)) {
        Err(AnatomyError::OutOfRange { range, value }) => problems.push(Problem {
            field: format!("biliary.anatomy.{}", range.field),
            anchors: vec!["biliary".into(), "anatomy".into(), range.field.into()],
            message: format!("{value} is out of its range ({})", range.source),
            hint: format!("from {} to {}", range.low, range.high),
        }),
        Err(e) => problems.push(Problem {
            field: "biliary.anatomy".into(),
            anchors: vec!["biliary".into(), "anatomy".into()],
            message: e.to_string(),
            hint: format!(
                "keep each size nearer its usual value: {}",
                (RANGES.iter())
                    .map(|r| format!("{} {}–{}", r.field, r.low, r.high))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }),
        Ok(()) => {}
    }
    check_rule(&entry.critical_view, problems);
}

/// Each share of the critical view's rule is more than 0 and at most 1.
fn check_rule(rule: &CriticalViewRule, problems: &mut Vec<Problem>) {
    let shares = [
        ("triangle_cleared", rule.triangle_cleared),
        ("lower_third_released", rule.lower_third_released),
        ("seen_share", rule.seen_share),
    ];
    for (field, share) in shares {
        if !(share.is_finite() && share > 0.0 && share <= 1.0) {
            problems.push(Problem {
                field: format!("biliary.critical_view.{field}"),
                anchors: vec!["biliary".into(), "critical_view".into(), field.into()],
                message: format!("{share} is not a share"),
                hint: "more than 0 and at most 1 (0.9: nine tenths)".into(),
            });
        }
    }
}

/// A clip applier or scissors in a scene without a tube to close on.
fn check_tools(scene: &SceneFacts<'_>, problems: &mut Vec<Problem>) {
    let tools = [
        (scene.clips, "ClipApplier", "a clip applier", "clip"),
        (scene.divides, "Scissors", "scissors", "divide"),
    ];
    for (held, variant, what, verb) in tools {
        if held {
            problems.push(Problem {
                field: "instruments".into(),
                anchors: vec![variant.into()],
                message: format!(
                    "{what} needs a duct or an artery to {verb}, and the scene has no biliary tree"
                ),
                hint: "add biliary: Biliary(), the usual anatomy, or take the instrument out"
                    .into(),
            });
        }
    }
}
