//! Traction and counter-traction: while one hand does a task, the other keeps an organ held
//! (grasped, or pressed) with its force within a band, as the non-dominant hand holds tissue
//! taut for the dominant one to work on. A task asks for it with its shared `countertraction`
//! field; the exercise watches the other hand every tick. Fixed-size state: the real-time
//! thread allocates nothing.

use serde::{Deserialize, Serialize};

use super::{Hand, LimitWatch};
use crate::scenario::sample::HandSample;
use crate::scenario::units::Newtons;

/// `Countertraction(organ, min_force_n, max_force_n)`: the other hand keeps `organ` held —
/// in a grasper's jaws or under its tool — with the force it feels between the two, the whole
/// task.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Countertraction {
    pub organ: String,
    pub min_force_n: Newtons,
    pub max_force_n: Newtons,
}

impl Countertraction {
    /// The mistake `lapse`, in words, for a task done by `hand`.
    pub fn describe(&self, hand: Hand, lapse: Lapse) -> String {
        let other = hand.other().name();
        match lapse {
            Lapse::LetGo => format!("the {other} hand let go of the {}", self.organ),
            Lapse::TooHard => format!(
                "the {other} hand pulled the {} harder than {} N",
                self.organ, self.max_force_n
            ),
        }
    }
}

/// A break in the hold this long is letting go (s): a touch that flickers off for a few
/// ticks as the tool slides on the tissue is not.
pub const LET_GO_S: f64 = 0.1;

/// A break in the counter-traction, noted as a mistake.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lapse {
    /// The other hand held the organ, then no longer did for [`LET_GO_S`].
    LetGo,
    /// Its force went above the band (once per excursion, as a force limit is watched).
    TooHard,
}

/// What the other hand's counter-traction measured over the task (s and a count).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CountertractionMetrics {
    /// Held with the force within the band...
    pub in_band_s: f64,
    /// ...held, but slack: under the band...
    pub slack_s: f64,
    /// ...held, but harder than the band...
    pub over_s: f64,
    /// ...and not held at all.
    pub not_held_s: f64,
    /// How many times the hand let go.
    pub let_go: u32,
}

impl CountertractionMetrics {
    /// The share of the task's time the organ was held within the band (0 over no time).
    pub fn in_band_share(&self) -> f64 {
        let total = self.in_band_s + self.slack_s + self.over_s + self.not_held_s;
        match total > 0.0 {
            true => self.in_band_s / total,
            false => 0.0,
        }
    }
}

/// The running watch of one task's counter-traction.
#[derive(Clone, Debug)]
pub struct CountertractionWatch {
    /// The organ's place among the scenario's organs.
    organ: usize,
    min_force_n: f64,
    max_force_n: f64,
    /// Whether the hand has held the organ and not let go since...
    holding: bool,
    /// ...and for how long its hold has been broken (s).
    broken_s: f64,
    over: LimitWatch,
    metrics: CountertractionMetrics,
}

impl CountertractionWatch {
    /// The watch of `countertraction`, whose organ is the scenario's `organ`-th.
    pub fn new(countertraction: &Countertraction, organ: usize) -> Self {
        Self {
            organ,
            min_force_n: countertraction.min_force_n.0,
            max_force_n: countertraction.max_force_n.0,
            holding: false,
            broken_s: 0.0,
            over: LimitWatch::default(),
            metrics: CountertractionMetrics::default(),
        }
    }

    /// Takes one tick of the other hand; returns the lapse it made, if any.
    pub fn step(&mut self, other: &HandSample, dt: f64) -> Option<Lapse> {
        let held = other.holds(self.organ);
        let m = &mut self.metrics;
        if !held {
            m.not_held_s += dt;
            self.over = LimitWatch::default();
            self.broken_s += dt;
            let let_go = self.holding && self.broken_s >= LET_GO_S;
            if let_go {
                self.holding = false;
                m.let_go += 1;
            }
            return let_go.then_some(Lapse::LetGo);
        }
        self.holding = true;
        self.broken_s = 0.0;
        let force = other.force_n;
        let too_hard = self
            .over
            .crossed(force, self.max_force_n, dt, &mut m.over_s);
        if force < self.min_force_n {
            m.slack_s += dt;
        } else if force <= self.max_force_n {
            m.in_band_s += dt;
        }
        too_hard.then_some(Lapse::TooHard)
    }

    pub fn metrics(&self) -> CountertractionMetrics {
        self.metrics.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn band() -> CountertractionWatch {
        let countertraction = Countertraction {
            organ: "gallbladder".into(),
            min_force_n: Newtons(0.3),
            max_force_n: Newtons(1.0),
        };
        CountertractionWatch::new(&countertraction, 1)
    }

    /// Four seconds at 1 kHz of a left hand on the scenario's second organ: a second in the
    /// band, half a second slack, half a second too hard (one mistake), a second in the band
    /// again but for a 20 ms flicker off the organ (no mistake), then let go for a second
    /// (one mistake, once the break has lasted 0.1 s). Each time to a tick; a hold on another
    /// organ does not count.
    #[test]
    fn the_other_hands_hold_is_timed_in_and_out_of_its_band() {
        let mut watch = band();
        let mut lapses = Vec::new();
        for tick in 0..4000 {
            let t = tick as f64 * 1e-3;
            let force_n = match t {
                t if t < 1.0 => 0.6,
                t if t < 1.5 => 0.1,
                t if t < 2.0 => 1.4,
                _ => 0.6,
            };
            let flicker = (2.5..2.52).contains(&t);
            let hand = HandSample {
                grasping: if t < 3.0 && !flicker { 0b10 } else { 0b01 },
                force_n,
                ..HandSample::default()
            };
            lapses.extend(watch.step(&hand, 1e-3).map(|lapse| (tick, lapse)));
        }
        let m = watch.metrics();
        let close = |a: f64, b: f64| (a - b).abs() < 1.5e-3;
        assert!(close(m.in_band_s, 1.98), "{m:?}");
        assert!(close(m.slack_s, 0.5), "{m:?}");
        assert!(close(m.over_s, 0.5), "{m:?}");
        assert!(close(m.not_held_s, 1.02), "{m:?}");
        assert_eq!(m.let_go, 1);
        assert_eq!(lapses, [(1500, Lapse::TooHard), (3099, Lapse::LetGo)]);
        assert!((m.in_band_share() - 0.495).abs() < 1e-3);
    }
}
