//! A fake Haply Inverse Service on the loopback address, written from Haply's documentation of
//! the service's simulation channel: HTTP `GET /version` and the WebSocket on one port; on
//! connecting, the full snapshot before the client says anything; then exactly one frame for
//! every message (`{}` included), `state` and `status` without `config`, or the full snapshot
//! again when the message asks for it with `force_render_full_state`; the force read from
//! `set_cursor_force.vector` (3.5) or `.values` (3.1–3.4), by the version it announces.
//!
//! Its Inverse3 is a handle of 0.1 kg on a spring of 200 N/m to where the test's hand holds it
//! (damped critically), moved by the forces it receives: its position answers the force. The
//! test places the hand, and can delay or withhold replies, send malformed or partial frames,
//! close the connection, refuse new ones, and take calibration or readiness away.

use std::f64::consts::FRAC_1_SQRT_2;
use std::io::Write;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use nalgebra::Vector3;
use serde_json::{Value, json};
use tungstenite::{Message, WebSocket};

pub const DEVICE_ID: &str = "049D";
pub const GRIP_ID: &str = "0A1B";

/// The handle's mass (kg), the hand's spring (N/m) and damping (N s/m): critical, `2 √(k m)`.
const MASS_KG: f64 = 0.1;
const SPRING_N_PER_M: f64 = 200.0;
const DAMPING_N_S_PER_M: f64 = 8.944;

/// What the fake does and has seen; the test sets the first part and reads the second.
#[derive(Debug)]
pub struct FakeState {
    /// The version `GET /version` states.
    pub version: String,
    pub calibrated: bool,
    pub ready: bool,
    /// Where the trainee's hand holds the handle (m, the device's base frame).
    pub hand_m: Vector3<f64>,
    pub position_m: Vector3<f64>,
    pub velocity_m_s: Vector3<f64>,
    pub buttons: [bool; 3],
    /// Replies wait this long.
    pub delay: Duration,
    /// The next this many replies are malformed.
    pub malformed_replies: u32,
    /// Replies leave out the status and all but the cursor.
    pub partial: bool,
    /// New connections are refused (the service is down).
    pub refusing: bool,
    /// Set by the test to close the open connections.
    pub close_now: bool,
    // What was seen.
    pub messages: u64,
    pub empty_messages: u64,
    pub connections: u64,
    /// The last force received (N), and the force commands under the other version's name.
    pub force_n: Vector3<f64>,
    pub misnamed_forces: u64,
    pub full_state_requests: u64,
    pub closes_received: u64,
    pub profile: Option<String>,
    /// Messages with a force that came after a reply had said the device was not calibrated
    /// or not ready, while it still was not.
    pub forces_while_unready: u64,
    /// Whether the last reply said the device was not calibrated or not ready.
    said_unready: bool,
    /// When each message arrived, with the force it carried.
    pub log: Vec<(Instant, Vector3<f64>)>,
    last_step: Option<Instant>,
}

impl FakeState {
    fn new(version: &str) -> Self {
        let rest = Vector3::new(0.0, -0.10, 0.18);
        Self {
            version: version.into(),
            calibrated: true,
            ready: true,
            hand_m: rest,
            position_m: rest,
            velocity_m_s: Vector3::zeros(),
            buttons: [false; 3],
            delay: Duration::ZERO,
            malformed_replies: 0,
            partial: false,
            refusing: false,
            close_now: false,
            messages: 0,
            empty_messages: 0,
            connections: 0,
            force_n: Vector3::zeros(),
            misnamed_forces: 0,
            full_state_requests: 0,
            closes_received: 0,
            profile: None,
            forces_while_unready: 0,
            said_unready: false,
            log: Vec::new(),
            last_step: None,
        }
    }

    /// Places the handle where the hand holds it, at rest.
    pub fn place(&mut self, m: Vector3<f64>) {
        self.hand_m = m;
        self.position_m = m;
        self.velocity_m_s = Vector3::zeros();
    }

    /// The handle moved over the time since the last message by the last force and the hand.
    fn step(&mut self, now: Instant) {
        let dt = self
            .last_step
            .map_or(0.0, |t| (now - t).as_secs_f64().min(0.01));
        self.last_step = Some(now);
        // Semi-implicit Euler in steps of at most 0.1 ms: stable for the spring and damping.
        let steps = (dt / 1e-4).ceil() as usize;
        for _ in 0..steps {
            let h = dt / steps as f64;
            let pull = (self.hand_m - self.position_m) * SPRING_N_PER_M
                - self.velocity_m_s * DAMPING_N_S_PER_M;
            self.velocity_m_s += (self.force_n + pull) / MASS_KG * h;
            self.position_m += self.velocity_m_s * h;
        }
    }

    /// Whether the version announced is 3.5 or later (`vector`) or older (`values`).
    fn speaks_vector(&self) -> bool {
        let mut parts = self.version.split('.');
        let major: u32 = parts.next().and_then(|p| p.parse().ok()).unwrap_or(0);
        let minor: u32 = parts.next().and_then(|p| p.parse().ok()).unwrap_or(0);
        (major, minor) >= (3, 5)
    }

    /// The frame for the devices: with their `config` in a snapshot.
    fn frame(&self, snapshot: bool) -> Value {
        let v3 = |v: &Vector3<f64>| json!({"x": v.x, "y": v.y, "z": v.z});
        let mut state = json!({
            "cursor_position": v3(&self.position_m),
            "cursor_velocity": v3(&self.velocity_m_s),
        });
        if self.partial && !snapshot {
            return json!({"inverse3": [{"device_id": DEVICE_ID, "state": state}]});
        }
        state["current_cursor_force"] = v3(&self.force_n);
        state["body_orientation"] = json!({"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0});
        state["angular_position"] = json!({"a0": 0.0, "a1": 10.0, "a2": 20.0});
        state["mode"] = json!("idle");
        let mut inverse3 = json!({
            "device_id": DEVICE_ID,
            "state": state,
            "status": {"calibrated": self.calibrated, "ready": self.ready, "started": true,
                       "in_use": true, "power_supply": true},
        });
        let [a, b, c] = self.buttons;
        let mut grip = json!({
            "device_id": GRIP_ID,
            "state": {"orientation": {"w": FRAC_1_SQRT_2, "x": 0.0, "y": 0.0, "z": FRAC_1_SQRT_2},
                      "buttons": {"a": a, "b": b, "c": c}, "battery_level": 0.9},
            "status": {"ready": true, "connected": true, "awake": true},
        });
        if snapshot {
            inverse3["config"] = json!({
                "type": "inverse3", "port": "/dev/ttyACM0", "handedness": "right",
                "device_info": {"id": DEVICE_ID, "major_version": 3, "minor_version": 5,
                                "device_type": "inverse3", "uuid": "00000000"},
                "gravity_compensation": {"enabled": true, "scaling_factor": 1.0},
            });
            grip["config"] = json!({"type": "wireless_verse_grip", "port": "radio"});
        }
        json!({"session_id": 1, "inverse3": [inverse3], "wireless_verse_grip": [grip]})
    }

    /// Takes one message from the client: its force, its session requests.
    fn take(&mut self, text: &str) -> bool {
        self.messages += 1;
        let Ok(message) = serde_json::from_str::<Value>(text) else {
            return false;
        };
        if message.as_object().is_some_and(|m| m.is_empty()) {
            self.empty_messages += 1;
        }
        if let Some(name) = message["session"]["configure"]["profile"]["name"].as_str() {
            self.profile = Some(name.to_owned());
        }
        let full = message["session"].get("force_render_full_state").is_some();
        self.full_state_requests += u64::from(full);
        let (key, other) = match self.speaks_vector() {
            true => ("vector", "values"),
            false => ("values", "vector"),
        };
        let mut force = Vector3::zeros();
        for command in message["inverse3"].as_array().into_iter().flatten() {
            if command["device_id"] != DEVICE_ID {
                continue;
            }
            let set = &command["commands"]["set_cursor_force"];
            let v = &set[key];
            if let (Some(x), Some(y), Some(z)) = (v["x"].as_f64(), v["y"].as_f64(), v["z"].as_f64())
            {
                force = Vector3::new(x, y, z);
            }
            self.misnamed_forces += u64::from(set.get(other).is_some());
        }
        // A command holds for one exchange only: a message without one is zero force.
        self.force_n = force;
        let unready = !(self.calibrated && self.ready);
        self.forces_while_unready += u64::from(unready && self.said_unready && force.norm() > 0.0);
        self.said_unready = unready;
        self.log.push((Instant::now(), force));
        full
    }
}

/// The fake service, listening on 127.0.0.1 at a port of its own.
pub struct FakeService {
    pub addr: SocketAddr,
    state: Arc<Mutex<FakeState>>,
    stop: Arc<AtomicBool>,
}

impl FakeService {
    /// A fake announcing service `version` ("3.5.0", "3.4.1"...).
    pub fn start(version: &str) -> Self {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let state = Arc::new(Mutex::new(FakeState::new(version)));
        let stop = Arc::new(AtomicBool::new(false));
        let (s, halt) = (state.clone(), stop.clone());
        std::thread::spawn(move || {
            for stream in listener.incoming() {
                if halt.load(Ordering::Relaxed) {
                    break;
                }
                let Ok(stream) = stream else { continue };
                let (s, halt) = (s.clone(), halt.clone());
                std::thread::spawn(move || serve(stream, &s, &halt));
            }
        });
        Self { addr, state, stop }
    }

    /// The address a client is given.
    pub fn url(&self) -> String {
        format!("ws://{}", self.addr)
    }

    pub fn state(&self) -> MutexGuard<'_, FakeState> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Waits until `done` holds of the state (polled every 0.2 ms), up to 5 s.
    pub fn wait_for(&self, what: &str, done: impl Fn(&FakeState) -> bool) {
        let give_up = Instant::now() + Duration::from_secs(5);
        while !done(&self.state()) {
            assert!(Instant::now() < give_up, "the fake waited 5 s for {what}");
            std::thread::sleep(Duration::from_micros(200));
        }
    }

    /// Waits for `n` more messages from the client.
    pub fn wait_messages(&self, n: u64) {
        let from = self.state().messages;
        self.wait_for("messages", |s| s.messages >= from + n);
    }
}

impl Drop for FakeService {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        self.state().close_now = true;
        let _ = TcpStream::connect(self.addr);
    }
}

/// One connection: the version over HTTP, or a WebSocket session.
fn serve(stream: TcpStream, state: &Mutex<FakeState>, stop: &AtomicBool) {
    if state.lock().unwrap_or_else(|p| p.into_inner()).refusing || stop.load(Ordering::Relaxed) {
        return;
    }
    let _ = stream.set_nodelay(true);
    if !is_upgrade(&stream) {
        answer_version(stream, state);
        return;
    }
    let Ok(mut socket) = tungstenite::accept(stream) else {
        return;
    };
    {
        let mut s = state.lock().unwrap_or_else(|p| p.into_inner());
        s.connections += 1;
        s.close_now = false;
        s.last_step = None;
    }
    let snapshot = state
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .frame(true)
        .to_string();
    if socket.send(Message::text(snapshot)).is_err() {
        return;
    }
    let _ = socket
        .get_ref()
        .set_read_timeout(Some(Duration::from_millis(5)));
    session(&mut socket, state);
}

/// Whether the request on `stream` asks for a WebSocket (its headers peeked, not read).
fn is_upgrade(stream: &TcpStream) -> bool {
    let mut buffer = [0u8; 2048];
    let give_up = Instant::now() + Duration::from_secs(1);
    while Instant::now() < give_up {
        let Ok(n) = stream.peek(&mut buffer) else {
            return false;
        };
        let head = String::from_utf8_lossy(&buffer[..n]).to_ascii_lowercase();
        if head.contains("\r\n\r\n") {
            return head.contains("upgrade: websocket");
        }
        std::thread::sleep(Duration::from_micros(200));
    }
    false
}

fn answer_version(mut stream: TcpStream, state: &Mutex<FakeState>) {
    let mut request = [0u8; 2048];
    let _ = std::io::Read::read(&mut stream, &mut request);
    let version = state
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .version
        .clone();
    let body = json!({"build_time": "2026-05-01T00:00:00Z", "git_branch": "main",
        "git_describe": version, "git_hash": "0", "git_tag": version,
        "project_name": "haply-inverse-service", "project_version": format!("{version}.0")})
    .to_string();
    let reply = format!(
        "HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\
         Connection: close\r\n\r\n{body}",
        body.len()
    );
    let _ = stream.write_all(reply.as_bytes());
}

/// Answers every message with one frame until the client closes or the test closes it.
fn session(socket: &mut WebSocket<TcpStream>, state: &Mutex<FakeState>) {
    loop {
        if state.lock().unwrap_or_else(|p| p.into_inner()).close_now {
            let _ = socket.get_mut().shutdown(std::net::Shutdown::Both);
            return;
        }
        let text = match socket.read() {
            Ok(Message::Text(text)) => text,
            Ok(Message::Close(_)) => {
                state
                    .lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .closes_received += 1;
                let _ = socket.flush();
                return;
            }
            Ok(_) => continue,
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                continue;
            }
            Err(_) => return,
        };
        let (reply, delay) = {
            let mut s = state.lock().unwrap_or_else(|p| p.into_inner());
            s.step(Instant::now());
            let full = s.take(&text);
            let reply = match s.malformed_replies {
                0 => s.frame(full).to_string(),
                n => {
                    s.malformed_replies = n - 1;
                    // Cut short: not JSON.
                    s.frame(false).to_string()[..40].to_owned()
                }
            };
            (reply, s.delay)
        };
        if !delay.is_zero() {
            std::thread::sleep(delay);
        }
        if socket.send(Message::text(reply)).is_err() {
            return;
        }
    }
}
