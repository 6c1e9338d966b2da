//! The Haply Inverse3 through the Haply Inverse Service, the local service that owns the
//! device and speaks JSON over a WebSocket (its simulation channel, `ws://localhost:10001`).
//!
//! The client is ours, over `tungstenite`, on a servo thread of its own: Haply's `haply` crate
//! is an async client over tokio and reqwest (with OpenSSL), about 160 crates for what a
//! blocking loop on one thread does with a dozen. The service answers each message with one
//! frame, so the exchange is lock-step, paced no faster than [`MIN_EXCHANGE_PERIOD`].

mod channel;
mod servo;
mod wire;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

pub use channel::{DEFAULT_URL, ServiceUrl};
pub use servo::{
    Condition, LATE_AFTER, LOST_AFTER, MIN_EXCHANGE_PERIOD, REACH_CENTRE_M, RECONNECT_EVERY,
};
pub use wire::{
    CursorOrigin, FULL_STATE_REQUEST, FrameKind, GripView, Inverse3View, ServiceView, WireFormat,
    force_command,
};

use super::release::Release;
use super::servo::{ServoLink, ServoThread};
use super::{DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice};
use channel::{Channel, format_for};
use servo::{SNAPSHOT_WITHIN, Servo, Shared};

/// An open Inverse3 and its servo: what must be released, once, whichever way the program
/// leaves (see [`super::release`]).
struct Session {
    shared: Arc<Shared>,
    servo: ServoThread,
    released: AtomicBool,
}

impl Release for Session {
    /// Zero force at once (the link halted), then the servo stopped: its last exchange sends
    /// zero and closes the session.
    fn release(&self) {
        if self.released.swap(true, Ordering::AcqRel) {
            return;
        }
        self.shared.link.halt();
        self.shared.running.store(false, Ordering::Relaxed);
        self.servo.join();
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.release();
    }
}

/// A Haply Inverse3 (with its Verse Grip, when one is paired) served through the service.
pub struct Haply {
    name: String,
    device_id: String,
    url: String,
    session: Arc<Session>,
}

/// The Inverse3's limits: the service does not report them, and Haply's specification could
/// not be confirmed here, so the trainer holds it to the product's default for a device whose
/// limits are not reported (3.3 N peak), which an Inverse3 renders within its range.
fn inverse3_limits() -> DeviceLimits {
    DeviceLimits::default()
}

fn failed(url: &str, message: String) -> DeviceError {
    DeviceError::Failed {
        device: format!("Haply Inverse Service at {url}"),
        message,
    }
}

/// What to do when no service answers.
const INSTALL: &str = "install Haply's Inverse Service (with Haply Hub) and start it \
    (Linux: `systemctl start haply-inverse-service.service`), or name the service's address \
    (--device haply:ws://HOST:PORT, or PGD_HAPLY_URL)";

/// The variable that names the service's address when the command line does not.
pub const URL_VARIABLE: &str = "PGD_HAPLY_URL";

/// The service's address: `url`, else [`URL_VARIABLE`]'s, else [`DEFAULT_URL`].
pub fn service_url(url: Option<&str>) -> String {
    url.map(str::to_owned)
        .or_else(|| std::env::var(URL_VARIABLE).ok())
        .unwrap_or_else(|| DEFAULT_URL.to_owned())
}

impl Haply {
    /// Connects to the service at `url` (else [`service_url`]'s), picks the Inverse3 `device_id`
    /// (or the first listed) and its handle, and starts the servo.
    pub fn open(url: Option<&str>, device_id: Option<&str>) -> Result<Self, DeviceError> {
        let text = service_url(url);
        let url = ServiceUrl::parse(&text).map_err(|e| failed(&text, e))?;
        let ws = url.ws();
        let (format, warning) = format_for(url.version());
        let mut channel = Channel::open(&url)
            .map_err(|e| failed(&ws, format!("no service answers ({e}): {INSTALL}")))?;
        if let Some(warning) = warning {
            eprintln!("{warning}");
        }
        let mut skipped = 0;
        let snapshot = channel
            .receive(SNAPSHOT_WITHIN, &mut skipped)
            .map_err(|e| failed(&ws, format!("no opening snapshot from the service: {e:?}")))?;
        let mut view = ServiceView::default();
        view.merge(&snapshot)
            .map_err(|e| failed(&ws, e.to_string()))?;
        let device_id = pick(&view, device_id).map_err(|e| failed(&ws, e))?;
        let device = view.pick(Some(&device_id)).expect("just picked").0;
        let condition = Condition::of(device);
        let link = Arc::new(ServoLink::default());
        let limits = inverse3_limits();
        link.set_peak_force_n(limits.peak_force_n);
        let shared = Arc::new(Shared::new(link));
        let servo = Servo {
            url,
            device_id: device_id.clone(),
            format,
            channel: Some(channel),
            view,
            shared: shared.clone(),
            first: true,
        };
        let session = Arc::new(Session {
            shared: shared.clone(),
            servo: ServoThread::default(),
            released: AtomicBool::new(false),
        });
        super::register(&(session.clone() as Arc<dyn Release>));
        let thread = std::thread::Builder::new()
            .name("haply servo".into())
            .spawn(move || servo.run())
            .map_err(|e| failed(&ws, format!("cannot start the servo thread: {e}")))?;
        session.servo.set(thread);
        if condition != Condition::Fine {
            eprintln!("warning: {}", condition.describe(&device_id, &ws));
        }
        if !shared.link.await_first_sample() {
            let why = shared.condition().describe(&device_id, &ws);
            return Err(failed(&ws, format!("no position within a second: {why}")));
        }
        Ok(Self {
            name: format!("Haply Inverse3 {device_id}"),
            device_id,
            url: ws,
            session,
        })
    }

    /// Whether a service answers at `url` (else [`service_url`]'s): its address and
    /// version, or why not.
    pub fn probe(url: Option<&str>) -> Result<(String, String), DeviceError> {
        let text = service_url(url);
        let url = ServiceUrl::parse(&text).map_err(|e| failed(&text, e))?;
        let version = url.version();
        version
            .map(|version| (url.ws(), version))
            .map_err(|e| failed(&url.ws(), format!("no service answers ({e}): {INSTALL}")))
    }

    /// What the haptic loop and the servo share.
    pub fn link(&self) -> &Arc<ServoLink> {
        &self.session.shared.link
    }

    /// What keeps the device from rendering now, if anything.
    pub fn condition(&self) -> Condition {
        self.session.shared.condition()
    }

    /// Exchanges with the service so far.
    pub fn exchanges(&self) -> u64 {
        self.session.shared.exchanges()
    }

    /// Frames from the service that could not be read and were ignored.
    pub fn malformed_frames(&self) -> u64 {
        self.session.shared.malformed()
    }

    /// Connections made so far: one, plus one for each reconnection.
    pub fn connections(&self) -> u64 {
        self.session.shared.connections()
    }
}

/// The Inverse3 to serve: `wanted`, or the first listed; or why there is none.
fn pick(view: &ServiceView, wanted: Option<&str>) -> Result<String, String> {
    let listed: Vec<&str> = view.inverse3.iter().map(|d| d.device_id.as_str()).collect();
    match (view.pick(wanted), wanted) {
        (Some((device, _)), _) => Ok(device.device_id.clone()),
        (None, None) => Err(
            "the service lists no Inverse3: is it plugged in and powered? (Haply Hub shows \
             the devices the service sees)"
                .into(),
        ),
        (None, Some(id)) => Err(format!(
            "the service lists no Inverse3 `{id}`; it lists: {}",
            if listed.is_empty() {
                "none".into()
            } else {
                listed.join(", ")
            }
        )),
    }
}

impl HapticDevice for Haply {
    fn name(&self) -> &str {
        &self.name
    }

    fn limits(&self) -> DeviceLimits {
        inverse3_limits()
    }

    fn read(&mut self, _time_s: f64) -> Result<DeviceSample, DeviceError> {
        let shared = &self.session.shared;
        match shared.take_condition() {
            Condition::Fine => shared.link.latest().ok_or_else(|| DeviceError::Failed {
                device: self.name.clone(),
                message: "the servo has read no position yet".into(),
            }),
            condition => Err(DeviceError::Failed {
                device: self.name.clone(),
                message: condition.describe(&self.device_id, &self.url),
            }),
        }
    }

    fn render(&mut self, force: EdgeForce) -> Result<(), DeviceError> {
        self.session.shared.link.command(&force);
        Ok(())
    }
}
