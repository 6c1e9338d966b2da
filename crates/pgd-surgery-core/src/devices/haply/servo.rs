//! The servo thread of a Haply device: one exchange with the service after another, each the
//! tick's force out and the device's state back, published to the [`ServoLink`]; what keeps
//! the device from rendering (the connection lost, the service late, the device not
//! calibrated or not ready) is held as its [`Condition`] for the haptic loop to report, and a
//! lost connection is made again.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use nalgebra::{UnitQuaternion, Vector3};

use super::channel::{Channel, ExchangeError, ServiceUrl};
use super::wire::{CursorOrigin, Inverse3View, ServiceView, WireFormat, force_command};
use crate::devices::{DeviceSample, Metronome, ServoLink, TimerMode};

/// The shortest time between two exchanges: four a haptic tick, so that the sample a tick
/// reads is at most a quarter of a tick old. A service that answers slower sets the rate.
pub const MIN_EXCHANGE_PERIOD: Duration = Duration::from_micros(250);

/// A reply later than this is a fault: the service has stalled (the force fades).
pub const LATE_AFTER: Duration = Duration::from_millis(20);

/// A reply later than this: the connection is given up and made again.
pub const LOST_AFTER: Duration = Duration::from_millis(500);

/// How often a lost connection is tried again.
pub const RECONNECT_EVERY: Duration = Duration::from_millis(100);

/// How long a new connection may take to send its opening snapshot.
pub const SNAPSHOT_WITHIN: Duration = Duration::from_secs(1);

/// What keeps the device from rendering, if anything.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Condition {
    Fine = 0,
    /// The connection is gone; the servo is making it again.
    Lost = 1,
    /// The service has not answered within [`LATE_AFTER`].
    Late = 2,
    NotCalibrated = 3,
    NotReady = 4,
    /// The service, reconnected, no longer lists the device.
    Missing = 5,
}

impl Condition {
    fn from_code(code: u32) -> Self {
        [
            Self::Lost,
            Self::Late,
            Self::NotCalibrated,
            Self::NotReady,
            Self::Missing,
        ]
        .into_iter()
        .find(|c| *c as u32 == code)
        .unwrap_or(Self::Fine)
    }

    /// The condition of a device as the service reports it.
    pub fn of(device: &Inverse3View) -> Self {
        match (device.status.calibrated, device.status.ready) {
            (false, _) => Self::NotCalibrated,
            (true, false) => Self::NotReady,
            (true, true) if device.cursor_position_m.is_none() => Self::NotReady,
            (true, true) => Self::Fine,
        }
    }

    /// What the trainee is told, for the Inverse3 `id` served by `url`.
    pub fn describe(self, id: &str, url: &str) -> String {
        match self {
            Self::Fine => format!("Inverse3 {id} renders"),
            Self::Lost => format!(
                "the connection to the Haply Inverse Service at {url} is lost; reconnecting \
                 (is the service running?)"
            ),
            Self::Late => format!(
                "the Haply Inverse Service at {url} has not answered for {} ms",
                LATE_AFTER.as_millis()
            ),
            Self::NotCalibrated => format!(
                "the Inverse3 {id} is not calibrated: calibrate it as Haply's Hub shows \
                 (no force until it is)"
            ),
            Self::NotReady => format!(
                "the Inverse3 {id} is not ready: is it powered and its arm free? (no force \
                 until it is)"
            ),
            Self::Missing => format!(
                "the Haply Inverse Service at {url} no longer lists the Inverse3 {id}: is it \
                 plugged in?"
            ),
        }
    }
}

/// What the servo and the device share.
pub struct Shared {
    pub link: Arc<ServoLink>,
    condition: AtomicU32,
    /// The last condition other than [`Condition::Fine`] since the loop last read: one that
    /// came and went between two ticks (a connection dropped and made again at once) is
    /// still reported.
    latched: AtomicU32,
    pub running: AtomicBool,
    exchanges: AtomicU64,
    malformed: AtomicU64,
    connections: AtomicU64,
}

impl Shared {
    pub fn new(link: Arc<ServoLink>) -> Self {
        Self {
            link,
            condition: AtomicU32::new(Condition::Fine as u32),
            latched: AtomicU32::new(Condition::Fine as u32),
            running: AtomicBool::new(true),
            exchanges: AtomicU64::new(0),
            malformed: AtomicU64::new(0),
            connections: AtomicU64::new(1),
        }
    }

    pub fn condition(&self) -> Condition {
        Condition::from_code(self.condition.load(Ordering::Acquire))
    }

    /// What the loop reports at its read: the condition now, else the last other than fine
    /// since its previous read (cleared by this one).
    pub fn take_condition(&self) -> Condition {
        let latched = Condition::from_code(self.latched.swap(0, Ordering::AcqRel));
        match self.condition() {
            Condition::Fine => latched,
            now => now,
        }
    }

    fn set_condition(&self, condition: Condition) {
        self.condition.store(condition as u32, Ordering::Release);
        if condition != Condition::Fine {
            self.latched.store(condition as u32, Ordering::Release);
        }
    }

    /// Exchanges completed so far (a message sent and its reply merged).
    pub fn exchanges(&self) -> u64 {
        self.exchanges.load(Ordering::Relaxed)
    }

    /// Frames from the service that could not be read and were ignored.
    pub fn malformed(&self) -> u64 {
        self.malformed.load(Ordering::Relaxed)
    }

    /// Connections made so far, the first included.
    pub fn connections(&self) -> u64 {
        self.connections.load(Ordering::Relaxed)
    }
}

/// The centre of the Inverse3's reach in its base frame (m): where Haply's own examples
/// centre their scenes. The scene's origin is put there.
pub const REACH_CENTRE_M: Vector3<f64> = Vector3::new(0.0, -0.10, 0.18);

/// The cursor (the service's frame: x right, y away from the user, z up, m) as the tool in
/// the scene's (the same axes, about the centre of the device's reach).
pub fn to_scene(cursor_m: &Vector3<f64>, origin: CursorOrigin) -> Vector3<f64> {
    match origin {
        CursorOrigin::DeviceBase => cursor_m - REACH_CENTRE_M,
        CursorOrigin::WorkspaceCenter => *cursor_m,
    }
}

/// What the servo works with: the service, the device, what is known of it.
pub struct Servo {
    pub url: ServiceUrl,
    pub device_id: String,
    pub format: WireFormat,
    pub channel: Option<Channel>,
    pub view: ServiceView,
    pub shared: Arc<Shared>,
    /// Whether the next message is a session's first.
    pub first: bool,
}

impl Servo {
    /// Exchanges until told to stop, then sends a last zero force and closes the session.
    pub fn run(mut self) {
        let mut metronome = Metronome::new(MIN_EXCHANGE_PERIOD, TimerMode::Sleep);
        let mut last_try = Instant::now();
        while self.shared.running.load(Ordering::Relaxed) {
            metronome.wait();
            if self.channel.is_some() {
                self.exchange();
            } else if last_try.elapsed() >= RECONNECT_EVERY {
                last_try = Instant::now();
                self.reconnect();
            }
        }
        self.finish();
    }

    /// One exchange: the force out, the reply merged and published.
    fn exchange(&mut self) {
        let force = self.shared.link.force_to_render();
        let force = match self.shared.condition() {
            Condition::Fine => force,
            _ => Vector3::zeros(),
        };
        let message = force_command(&self.device_id, &force, self.format, self.first);
        self.first = false;
        match self.send_and_receive(message) {
            Ok(reply) => self.take(&reply),
            Err(why) => self.lose(&why),
        }
    }

    /// Sends `message` and waits for its reply: past [`LATE_AFTER`] the device is marked
    /// late (the loop fades its force) while the wait goes on, up to [`LOST_AFTER`].
    fn send_and_receive(&mut self, message: String) -> Result<String, String> {
        let channel = self
            .channel
            .as_mut()
            .expect("exchanges run on a connection");
        let mut skipped = 0;
        let lost = |e: ExchangeError| match e {
            ExchangeError::Lost(why) => why,
            ExchangeError::Late => format!("no reply for {} ms", LOST_AFTER.as_millis()),
        };
        channel.send(message).map_err(lost)?;
        let started = Instant::now();
        let reply = loop {
            match channel.receive(LATE_AFTER, &mut skipped) {
                Ok(reply) => break reply,
                Err(ExchangeError::Late)
                    if started.elapsed() < LOST_AFTER
                        && self.shared.running.load(Ordering::Relaxed) =>
                {
                    self.shared.set_condition(Condition::Late);
                }
                Err(e) => return Err(lost(e)),
            }
        };
        self.shared.malformed.fetch_add(skipped, Ordering::Relaxed);
        Ok(reply)
    }

    /// A reply: merged (a malformed one counted and ignored), the condition set from the
    /// device's status, the sample published.
    fn take(&mut self, reply: &str) {
        self.shared.exchanges.fetch_add(1, Ordering::Relaxed);
        if self.view.merge(reply).is_err() {
            self.shared.malformed.fetch_add(1, Ordering::Relaxed);
        }
        let Some((device, grip)) = self.view.pick(Some(&self.device_id)) else {
            self.shared.set_condition(Condition::Missing);
            return;
        };
        self.shared.set_condition(Condition::of(device));
        if let Some(cursor_m) = device.cursor_position_m {
            self.shared.link.publish(&DeviceSample {
                tip_m: to_scene(&cursor_m, device.origin),
                orientation: grip
                    .and_then(|g| g.orientation)
                    .unwrap_or_else(UnitQuaternion::identity),
                buttons: grip.map_or(0, |g| g.buttons),
            });
        }
    }

    /// The connection is gone: said, dropped, to be made again.
    fn lose(&mut self, why: &str) {
        if self.shared.condition() != Condition::Lost {
            eprintln!("Haply Inverse3 {}: {why}; reconnecting", self.device_id);
        }
        self.shared.set_condition(Condition::Lost);
        self.channel = None;
    }

    /// Tries to connect again: the opening snapshot read, the device found in it.
    fn reconnect(&mut self) {
        let Ok(mut channel) = Channel::open(&self.url) else {
            return;
        };
        let mut skipped = 0;
        let Ok(snapshot) = channel.receive(SNAPSHOT_WITHIN, &mut skipped) else {
            return;
        };
        let mut view = ServiceView::default();
        if view.merge(&snapshot).is_err() {
            self.shared.malformed.fetch_add(1, Ordering::Relaxed);
            return;
        }
        self.shared.connections.fetch_add(1, Ordering::Relaxed);
        match view.pick(Some(&self.device_id)) {
            Some((device, _)) => self.shared.set_condition(Condition::of(device)),
            None => {
                self.shared.set_condition(Condition::Missing);
                return;
            }
        }
        self.view = view;
        self.channel = Some(channel);
        self.first = true;
    }

    /// The last exchange at zero force, then the session closed.
    fn finish(mut self) {
        if self.channel.is_none() {
            return;
        }
        let zero = force_command(&self.device_id, &Vector3::zeros(), self.format, false);
        let _ = self.send_and_receive(zero);
        if let Some(channel) = self.channel.take() {
            channel.close();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::devices::haply::wire::Inverse3Status;

    /// Calibration first, then readiness, then a position to render from.
    #[test]
    fn a_device_renders_only_calibrated_ready_and_placed() {
        let status = |calibrated, ready| Inverse3Status {
            calibrated,
            ready,
            ..Inverse3Status::default()
        };
        let device = |status, placed: bool| Inverse3View {
            status,
            cursor_position_m: placed.then(Vector3::zeros),
            ..Inverse3View::default()
        };
        let cases = [
            (device(status(false, true), true), Condition::NotCalibrated),
            (device(status(false, false), true), Condition::NotCalibrated),
            (device(status(true, false), true), Condition::NotReady),
            (device(status(true, true), false), Condition::NotReady),
            (device(status(true, true), true), Condition::Fine),
        ];
        for (device, condition) in cases {
            assert_eq!(Condition::of(&device), condition, "{:?}", device.status);
            assert_eq!(Condition::from_code(condition as u32), condition);
        }
    }
}
