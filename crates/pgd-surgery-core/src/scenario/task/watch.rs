//! Two measures several tasks take: a hold (something kept true for a while without a break)
//! and a force limit watched for presses over it.

/// Above a limit until the force falls below this share of it: one press is one error (and
/// inside a zone until this share of the way beyond its radius).
pub const HYSTERESIS: f64 = 0.9;

/// A hold: since when what a task asks has held, and the longest unbroken hold.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hold {
    since_s: Option<f64>,
    pub longest_s: f64,
}

impl Hold {
    /// Takes whether it holds at `time_s`; returns the longest hold (s).
    pub fn step(&mut self, holding: bool, time_s: f64) -> f64 {
        match holding {
            true => {
                let since = *self.since_s.get_or_insert(time_s);
                self.longest_s = self.longest_s.max(time_s - since);
            }
            false => self.since_s = None,
        }
        self.longest_s
    }
}

/// One force limit as a task watches it: the time spent above it, and a press above it seen
/// once (it ends when the force falls below nine tenths of the limit).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LimitWatch {
    over: bool,
}

impl LimitWatch {
    /// Adds `dt` to `time_over` while `force` is above `limit`; true on the tick it goes over.
    pub fn crossed(&mut self, force: f64, limit: f64, dt: f64, time_over: &mut f64) -> bool {
        if force > limit {
            *time_over += dt;
            let crossed = !self.over;
            self.over = true;
            crossed
        } else {
            if force < HYSTERESIS * limit {
                self.over = false;
            }
            false
        }
    }
}
