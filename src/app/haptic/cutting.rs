//! The scalpel inside the tick: the cut softens what the tool feels, and the blade's press
//! decides whether the tissue parts and where the cut goes. The cut state grows on a worker
//! thread per organ ([`CutWorker`]); the tick reads its latest view and never waits, except
//! on a simulated clock ([`SettleCuts`]), where each step is waited for so that a run is
//! deterministic.

use bevy::ecs::query::QueryData;
use bevy::prelude::*;
use nalgebra::{Matrix3, Point3, Unit, Vector3};

use super::components::{HandTouches, OrganBody, OrganDeformation, patch_nodes};
use super::hand::{HandIndex, Tool};
use crate::contact::{ToolContact, follow};
use crate::cutting::{BladeContact, CutWorker, Scalpel};
use crate::devices::Action;
use crate::pgd::{PatchLoad, Vademecum};

/// An organ a scalpel cuts: the blade on it, and its cut state on a worker thread (whose
/// latest view the tick reads; the worker frees the views it replaces, so that the tick never
/// frees one).
#[derive(Component)]
pub struct OrganCut {
    pub scalpel: Scalpel,
    pub worker: CutWorker,
    /// Scratch kept from tick to tick: the patch's nodes and shares, room for every load
    /// position.
    nodes: Vec<(usize, f64)>,
    /// Each hand's load on the organ as the cut stage settled it last tick, what the other
    /// hands' presses answer through the cut this tick.
    settled: Vec<PatchLoad>,
    /// The exercise's attempt the tissue was cut in (0 before the first).
    pub(super) attempt: u32,
}

impl OrganCut {
    /// `positions`: the organ's load positions, the most a patch holds; `hands`: how many
    /// hands load it.
    pub fn new(scalpel: Scalpel, worker: CutWorker, positions: usize, hands: usize) -> Self {
        Self {
            scalpel,
            worker,
            nodes: Vec::with_capacity(positions),
            settled: (0..hands).map(|_| PatchLoad::reserved(positions)).collect(),
            attempt: 0,
        }
    }
}

/// The loop runs on a simulated clock: each cut step is waited for.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct SettleCuts;

/// Reads each cut organ's latest cut, softens every hand's press on it and moves it by what
/// the cut lets the organ's other loads move its patch (one answer of the cut for both), and
/// hands the blade's step, if
/// any, to the organ's cut state: the blade is the first hand's whose instrument cuts, its
/// press on tissue the other hand may hold taut (that hand's load, a grasp's or a press's, is
/// among the organ's loads the press answers).
pub fn cut(
    tools: Query<(&HandIndex, &Tool)>,
    settle: Option<Res<SettleCuts>>,
    mut organs: Query<CutOrgan>,
) {
    let blade = tools.iter().find(|(_, tool)| tool.action() == Action::Cut);
    for organ in &mut organs {
        let (body, mut touches, mut deformation) = (organ.body, organ.touch, organ.deformation);
        let OrganCut {
            scalpel,
            worker,
            nodes,
            settled,
            ..
        } = organ.cut.into_inner();
        match settle {
            Some(_) => worker.settle(),
            None => worker.poll(),
        };
        let loads = &mut deformation.0.loads;
        for (slot, touch) in touches.0.iter_mut().enumerate() {
            let Some(contact) = touch.contact.as_mut() else {
                continue;
            };
            add_other_loads(&body.vademecum, worker, nodes, settled, slot);
            let cut = worker.patch_response(&touch.patch.blend);
            soften(contact, cut.added_m_per_n);
            let cuts = blade.is_some_and(|(hand, _)| hand.0 == slot);
            if let Some(parted_m) = scalpel.parted_depth_m().filter(|_| cuts) {
                give(contact, parted_m);
            }
            contact.force_n = contact.stiffness_n_per_m * contact.indentation_m;
            loads[slot].force_n = contact.force_n;
            follow(&mut touch.contact, &mut loads[slot], &cut.moved_m);
        }
        for (settled, load) in settled.iter_mut().zip(loads.iter()) {
            settled.clone_from(load);
        }
        // The cut organ answers any instrument softer, but only a blade parts it.
        let pressed = blade.and_then(|(hand, tool)| {
            let contact = touches.0[hand.0].contact.as_ref()?;
            let edge = tool
                .sample
                .map_or_else(Vector3::x, |s| s.orientation * Vector3::x());
            Some(blade_contact(contact, edge))
        });
        if let Some(step) = scalpel.tick(pressed.as_ref()) {
            worker.submit(step);
        }
    }
}

/// Has the cut organ's worker sum the loads of the hands other than `slot` as this stage
/// `settled` them last tick, for the press of `slot` to follow what the cut adds to its
/// patch's displacement under them (`Y_aᵀ Y_b f_b`; the vademecum moved the surface by the
/// uncut part already): the grasp that pulls the tissue across the cut, or the press on its
/// other lip, moves the tissue under the blade further than the uncut organ would. Taken as
/// settled last tick, as the press took their uncut part, so that hands held still settle on
/// the full cut organ's answer.
fn add_other_loads(
    vademecum: &Vademecum,
    worker: &mut CutWorker,
    nodes: &mut Vec<(usize, f64)>,
    settled: &[PatchLoad],
    slot: usize,
) {
    worker.clear_loads();
    let others = settled.iter().enumerate();
    for (_, load) in others.filter(|&(b, load)| b != slot && load.is_active()) {
        patch_nodes(&load.shares, vademecum, nodes);
        worker.add_load(nodes, &load.force_n);
    }
}

/// An organ a scalpel cuts, as the cut stage reads and feeds it.
#[derive(QueryData)]
#[query_data(mutable)]
pub struct CutOrgan {
    body: &'static OrganBody,
    touch: &'static mut HandTouches,
    deformation: &'static mut OrganDeformation,
    cut: &'static mut OrganCut,
}

/// The press's stiffness as the cut organ answers it: the patch compliance the cut `added`
/// ([`CutWorker::patch_response`]) on top of the vademecum's, inverted.
fn soften(contact: &mut ToolContact, added: Matrix3<f64>) {
    if added == Matrix3::zeros() {
        return;
    }
    let Some(stiffness) = contact
        .stiffness_n_per_m
        .try_inverse()
        .and_then(|uncut| (uncut + added).try_inverse())
    else {
        return;
    };
    contact.stiffness_n_per_m = stiffness;
}

/// The blade in its cut, the tissue parted `parted_m` deep: along the normal only the depth
/// beyond the cut's bottom presses the tissue; sideways it still holds the blade.
fn give(contact: &mut ToolContact, parted_m: f64) {
    let normal = contact.hit.normal;
    contact.indentation_m += normal * contact.depth_m.min(parted_m);
}

/// The blade where the tool presses: the point on the rest surface, into the tissue, the
/// blade's `edge` (from the device's orientation), how deep and how hard.
fn blade_contact(contact: &ToolContact, edge: Vector3<f64>) -> BladeContact {
    let inward = Unit::new_normalize(-contact.hit.normal);
    BladeContact {
        point_m: Point3::from(contact.hit.point_m),
        inward,
        edge,
        depth_m: contact.depth_m,
        pressing_n: contact.force_n.dot(&inward),
    }
}
