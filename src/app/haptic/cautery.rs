//! The electrocautery hook in the tick, after the organs' contact and beds: while a hand's
//! hook has its button down, its energy of the tick goes to the live ties within its reach
//! (shared among them), else to the wall of the organ it touches (a burn mark), else to
//! nothing. What it did is the hand's [`HookWork`], which scoring reads.

use bevy::prelude::*;

use super::components::{HandTouches, OrganBody, OrganIndex};
use super::hand::{HandIndex, Tool};
use super::resources::OrganBeds;
use crate::devices::{Action, TICK_S};
use crate::dissection::{BurnSite, Cautery, Wall, WallBurns};
use crate::scenario::{HookSample, HookTarget, WallSample};

/// The burns of the scene's organs' walls; present when an instrument is a hook.
#[derive(Resource, Clone)]
pub struct OrganBurns(pub WallBurns);

/// What a hand's hook did in the tick (nothing, for another instrument).
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct HookWork(pub HookSample);

/// The hook's energy of the tick, for each hand whose hook has its button down.
pub fn cauterize(
    mut beds: Option<ResMut<OrganBeds>>,
    mut burns: ResMut<OrganBurns>,
    mut hands: Query<(&HandIndex, &Tool, &mut HookWork)>,
    organs: Query<(&OrganIndex, &OrganBody, &HandTouches)>,
) {
    for (hand, tool, mut work) in &mut hands {
        work.0 = HookSample::default();
        let (Action::Cauterize(hook), Some(sample)) = (tool.action(), tool.sample) else {
            continue;
        };
        if sample.buttons & 1 == 0 {
            continue;
        }
        let energy_j = hook.energy_j(TICK_S);
        let reach_m = tool.probe.tip_radius_m + 0.5 * hook.mode.zone_width_m();
        let on_ties = (beds.iter_mut().flat_map(|b| b.0.iter_mut()))
            .map(|bed| bed.burn_near(&sample.tip_m, reach_m, energy_j, hook.mode))
            .fold((0, 0), |(h, d), o| (h + o.heated, d + o.divided));
        let on = match on_ties {
            (0, _) => burn_wall(hand.0, &hook, energy_j, &organs, &mut burns.0),
            (heated, divided) => HookTarget::Ties {
                heated: heated as u32,
                divided: divided as u32,
            },
        };
        work.0 = HookSample { energy_j, on };
    }
}

/// The energy burned into the wall of the first organ hand `slot`'s tool touches, or into
/// nothing.
fn burn_wall(
    slot: usize,
    hook: &Cautery,
    energy_j: f64,
    organs: &Query<(&OrganIndex, &OrganBody, &HandTouches)>,
    burns: &mut WallBurns,
) -> HookTarget {
    let touched =
        (organs.iter()).find_map(|(index, _, touch)| Some((index.0, touch.0[slot].contact?)));
    let Some((organ, contact)) = touched else {
        return HookTarget::Air;
    };
    let site = BurnSite {
        organ,
        at: contact.hit.at,
        at_rest_m: contact.hit.point_m,
    };
    let Some(burn) = burns.burn(&site, energy_j, hook.mode) else {
        return HookTarget::Air;
    };
    let mark = &burns.marks()[burn.mark];
    HookTarget::Wall(WallSample {
        organ,
        mark: burn.mark,
        new_mark: burn.new,
        area_m2: mark.area_m2,
        through_now: burn.through_now,
        hollow: matches!(burns.wall(organ), Some(Wall::Hollow { .. })),
    })
}

/// The ties of the scene's beds a grasper's pull tore in the last tick.
pub fn ties_torn(beds: Option<&OrganBeds>) -> u32 {
    let beds = beds.map_or(&[][..], |b| &b.0[..]);
    beds.iter().map(|b| b.wall_report().torn as u32).sum()
}

/// The share (0–1, by area) of the scene's beds released.
pub fn released_share(beds: Option<&OrganBeds>) -> f64 {
    let beds = beds.map_or(&[][..], |b| &b.0[..]);
    let area: f64 = beds.iter().map(|b| b.bed.area_m2()).sum();
    let released: f64 = (beds.iter())
        .map(|b| b.bed.released_share() * b.bed.area_m2())
        .sum();
    match area > 0.0 {
        true => released / area,
        false => 0.0,
    }
}
