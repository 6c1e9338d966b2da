//! Scissors dividing a tube where their blades close, and what follows from the clips on it:
//! divided between two clips on the patient's side and one on the gallbladder's, as taught;
//! between fewer; with a stump left open, which bleeds or leaks bile ([`super::leak`]); or a
//! main bile duct divided, a bile duct injury whatever the clips.

use serde::Serialize;

use super::anatomy::{BiliaryTree, Part, Structure};
use super::clip::{Clip, crossing};
use super::geometry::Segment;
use super::leak::{FlowLaw, Fluid, Leak, Side};

/// Clips taught on each side of a division: two that stay with the patient, one with the
/// gallbladder.
pub const PATIENT_CLIPS: usize = 2;
pub const GALLBLADDER_CLIPS: usize = 1;

/// What a division is, by the clips around it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum DivisionOutcome {
    /// As taught: both sides closed by the clips taught.
    BetweenClips,
    /// Both sides closed, by fewer clips than taught.
    TooFewClips,
    /// A stump left open.
    Open,
    /// The common hepatic or common bile duct divided.
    BileDuctInjury,
}

/// One division.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Division {
    pub structure: Structure,
    pub part: Part,
    /// Along the tube from its patient end, at rest (m).
    pub arc_length_m: f64,
    /// Clips closing the lumen on each side of the cut.
    pub patient_clips: usize,
    pub gallbladder_clips: usize,
    pub outcome: DivisionOutcome,
}

impl Division {
    /// The division made by `blades` closing across a tube of `tree` among `clips`, with the
    /// stumps it leaves open (none, one or two: the patient's first); `None` where the blades
    /// close on no tube.
    pub fn cut(
        tree: &BiliaryTree,
        clips: &[Clip],
        blades: &Segment,
    ) -> Option<(Self, [Option<Leak>; 2])> {
        let crossing = crossing(tree, blades)?;
        let (structure, at_m) = (crossing.structure, crossing.arc_length_m);
        let part = tree.part_at(structure, at_m);
        let closing = || {
            clips
                .iter()
                .filter(move |c| c.structure == structure && c.closes_lumen())
        };
        let patient_clips = closing().filter(|c| c.arc_length_m < at_m).count();
        let gallbladder_clips = closing().filter(|c| c.arc_length_m > at_m).count();
        let outcome = if part.is_main_bile_duct() {
            DivisionOutcome::BileDuctInjury
        } else if patient_clips == 0 || gallbladder_clips == 0 {
            DivisionOutcome::Open
        } else if patient_clips < PATIENT_CLIPS || gallbladder_clips < GALLBLADDER_CLIPS {
            DivisionOutcome::TooFewClips
        } else {
            DivisionOutcome::BetweenClips
        };
        let division = Self {
            structure,
            part,
            arc_length_m: at_m,
            patient_clips,
            gallbladder_clips,
            outcome,
        };
        let leaks = division.open_stumps(tree);
        Some((division, leaks))
    }

    /// The stumps left open and what they let out: blood at arterial pressure from the
    /// artery's patient side and back from the gallbladder on its other side; bile from a
    /// duct's, what the liver secretes on the patient's side and the gallbladder's content on
    /// the other. The common duct's lower stump is held by the duodenum's sphincter and leaks
    /// nothing.
    fn open_stumps(&self, tree: &BiliaryTree) -> [Option<Leak>; 2] {
        let tube = tree.tube(self.structure);
        let lumen_m = tube.section.outer_radius_m - tube.section.wall_m;
        let sides = [
            (Side::Patient, self.patient_clips, self.arc_length_m),
            (
                Side::Gallbladder,
                self.gallbladder_clips,
                tube.length_m() - self.arc_length_m,
            ),
        ];
        sides.map(|(side, clips, from_source_m)| {
            let held = self.structure == Structure::CommonDuct && side == Side::Gallbladder;
            if clips > 0 || held {
                return None;
            }
            let (fluid, law) = match (self.structure, side) {
                (Structure::CysticArtery, Side::Patient) => (Fluid::Blood, FlowLaw::ARTERIAL),
                (Structure::CysticArtery, Side::Gallbladder) => {
                    (Fluid::Blood, FlowLaw::BACK_BLEEDING)
                }
                (_, Side::Patient) => (Fluid::Bile, FlowLaw::HEPATIC_BILE),
                (_, Side::Gallbladder) => (Fluid::Bile, FlowLaw::GALLBLADDER_BILE),
            };
            let at = (self.structure, side, self.arc_length_m);
            Some(Leak::new(at, fluid, &law, lumen_m, from_source_m))
        })
    }
}
