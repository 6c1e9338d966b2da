//! Reach the targets in order, without entering a forbidden zone or pressing harder than the
//! limit.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::scenario::scene::Spot;
use crate::scenario::task::{
    HYSTERESIS, RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType, Tick,
};

/// `SafeNavigation(targets, forbidden, max_force_n, time_limit_s)`, among all the organs.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SafeNavigation {
    pub targets: Vec<Spot>,
    #[serde(default)]
    pub forbidden: Vec<Spot>,
}

/// The mistake of entering a forbidden zone (its number the amount).
const FORBIDDEN: u16 = 0;

impl TaskType for SafeNavigation {
    const NAME: &'static str = "SafeNavigation";
    const LABEL: &'static str = "safe navigation";
    const ON_AN_ORGAN: bool = false;
    type Run = SafeNavigationRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "reach {} in order, avoiding {}, under {} N",
            names(&self.targets),
            names(&self.forbidden),
            shared.max_force_n,
        )
    }

    fn check(&self, check: &mut TaskCheck<'_>) {
        if self.targets.is_empty() {
            check.problem(
                "targets",
                "there are no targets to reach",
                "add Spot(name: …, at_mm: (x, y, z), radius_mm: …) targets",
            );
        }
    }

    fn run(&self, _: &TaskShared, _: RunSetup) -> SafeNavigationRun {
        SafeNavigationRun {
            targets: self.targets.clone(),
            forbidden: self.forbidden.clone(),
            reached: 0,
            path_ratio: None,
            inside_zone: None,
        }
    }

    fn describe_mistake(&self, _: &TaskShared, code: u16, amount: f64) -> String {
        debug_assert_eq!(code, FORBIDDEN);
        let zone = amount as usize;
        let name = self
            .forbidden
            .get(zone)
            .map_or_else(|| format!("zone {}", zone + 1), |s| spot_name(s, zone));
        format!("entered the forbidden {name}")
    }
}

#[derive(Clone, Debug)]
pub struct SafeNavigationRun {
    targets: Vec<Spot>,
    forbidden: Vec<Spot>,
    reached: usize,
    path_ratio: Option<f64>,
    /// The forbidden zone the tip is in, if any.
    inside_zone: Option<usize>,
}

impl TaskRun for SafeNavigationRun {
    type Result = SafeNavigationResult;

    fn step(&mut self, tick: &mut Tick<'_>) {
        // The motion tracker has taken this tick's tip: its start and path are the task's.
        let (Some(tip), Some(first)) = (tick.sample.tip_m, tick.motion.start()) else {
            return;
        };
        if let Some(target) = self.targets.get(self.reached)
            && target.contains(&tip)
        {
            self.reached += 1;
            if self.reached == self.targets.len() {
                tick.metrics.completed = true;
                let straight_m = straight_length_m(first, &self.targets).max(1e-6);
                self.path_ratio = Some(tick.motion.path_length_m() / straight_m);
            }
        }
        self.watch_zones(tick, &tip);
    }

    fn progress(&self) -> Option<TaskProgress> {
        Some(TaskProgress {
            what: "targets reached:",
            done: self.reached as f64,
            of: self.targets.len() as f64,
            unit: "",
        })
    }

    fn result(&self) -> SafeNavigationResult {
        SafeNavigationResult {
            targets_reached: self.reached,
            targets: self.targets.len(),
            path_ratio: self.path_ratio,
        }
    }
}

impl SafeNavigationRun {
    /// Entering a forbidden zone is a mistake, once until the tip has left it.
    fn watch_zones(&mut self, tick: &mut Tick<'_>, tip: &Vector3<f64>) {
        match self.inside_zone {
            Some(k) => {
                let zone = &self.forbidden[k];
                if (tip - zone.centre_m()).norm() > zone.radius_mm.metres() / HYSTERESIS {
                    self.inside_zone = None;
                }
            }
            None => {
                if let Some(k) = self.forbidden.iter().position(|z| z.contains(tip)) {
                    self.inside_zone = Some(k);
                    tick.mistake(FORBIDDEN, k as f64);
                }
            }
        }
    }
}

/// Navigation's measures: targets reached, of how many, and the tip's path against the
/// straight lines between them (1 = straight).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SafeNavigationResult {
    pub targets_reached: usize,
    pub targets: usize,
    pub path_ratio: Option<f64>,
}

impl TaskResult for SafeNavigationResult {
    /// Never touching an organ is what navigation wants.
    fn untouched_force_share(&self) -> f64 {
        1.0
    }

    fn unfinished(&self) -> Option<String> {
        Some(format!(
            " ({} of {} targets reached)",
            self.targets_reached, self.targets
        ))
    }

    fn summary(&self) -> Vec<String> {
        let path = self.path_ratio.map_or(String::new(), |r| {
            format!(", path {r:.2}× the straight line")
        });
        vec![format!(
            "targets reached: {} of {}{path}",
            self.targets_reached, self.targets
        )]
    }
}

/// The straight path from `start` through the targets, in order (m).
fn straight_length_m(start: Vector3<f64>, targets: &[Spot]) -> f64 {
    let mut length = 0.0;
    let mut from = start;
    for target in targets {
        length += (target.centre_m() - from).norm();
        from = target.centre_m();
    }
    length
}

fn spot_name(spot: &Spot, k: usize) -> String {
    match spot.name.is_empty() {
        true => format!("zone {}", k + 1),
        false => spot.name.clone(),
    }
}

fn names(spots: &[Spot]) -> String {
    match spots.len() {
        0 => "nothing".into(),
        _ => spots
            .iter()
            .enumerate()
            .map(|(k, s)| spot_name(s, k))
            .collect::<Vec<_>>()
            .join(", "),
    }
}
