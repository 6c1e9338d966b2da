//! The Inverse Service's simulation channel as JSON: the command frame the client sends each
//! exchange, and what it knows of the devices, merged from the frames the service answers with.
//!
//! The service opens with a full snapshot (every device's `config`, `state` and `status`) and
//! then answers every message with one frame of `state` and `status` only, which may leave out
//! fields (those at their defaults, or unchanged). So a frame is merged into what is known:
//! each field it holds replaces the known one, each it leaves out keeps its value. A frame is
//! checked whole before any of it is merged: a malformed one changes nothing.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde_json::{Map, Value, json};

/// How the service names a force command's vector: Haply renamed it in service 3.5.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WireFormat {
    /// `set_cursor_force.vector`: service 3.5 and later.
    Vector,
    /// `set_cursor_force.values`: services 3.1 to 3.4.
    Values,
}

impl WireFormat {
    /// The format a service of `version` ("3.5.0", "3.4.2.0", "v3.5") reads; `None` for a
    /// version that is no number, or older than 3.1 (the 3.0 format, on another port, is not
    /// spoken).
    pub fn of_version(version: &str) -> Option<Self> {
        let mut numbers = version.trim().trim_start_matches('v').split(['.', '-']);
        let major: u32 = numbers.next()?.parse().ok()?;
        let minor: u32 = numbers.next()?.parse().ok()?;
        match (major, minor) {
            (3, 1..=4) => Some(Self::Values),
            (3, 5..) | (4.., _) => Some(Self::Vector),
            _ => None,
        }
    }

    fn key(self) -> &'static str {
        match self {
            Self::Vector => "vector",
            Self::Values => "values",
        }
    }
}

/// The command of one exchange: the force (N, the service's axes) for the Inverse3
/// `device_id`; the first frame of a session also names the trainer as the session's profile.
pub fn force_command(
    device_id: &str,
    force_n: &Vector3<f64>,
    format: WireFormat,
    first: bool,
) -> String {
    let vector = json!({"x": force_n.x, "y": force_n.y, "z": force_n.z});
    let mut set_force = Map::new();
    set_force.insert(format.key().into(), vector);
    if format == WireFormat::Values {
        // The 3.1–3.4 command applies the force only when told to.
        set_force.insert("execute".into(), Value::Bool(true));
    }
    let mut frame = json!({
        "inverse3": [{"device_id": device_id, "commands": {"set_cursor_force": set_force}}]
    });
    if first {
        frame["session"] = json!({"configure": {"profile": {"name": "pgd-surgery trainer"}}});
    }
    frame.to_string()
}

/// The message that asks the service for a full snapshot again.
pub const FULL_STATE_REQUEST: &str = r#"{"session":{"force_render_full_state":{}}}"#;

/// An Inverse3's status flags, each as last reported.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Inverse3Status {
    pub calibrated: bool,
    pub ready: bool,
    pub started: bool,
    pub in_use: bool,
    pub power_supply: bool,
}

/// Where the service puts the cursor's origin (its `config.coordinate_origin`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CursorOrigin {
    /// On the device's mounting plate, near its centre: Haply's default.
    #[default]
    DeviceBase,
    /// At the centre of the device's reach.
    WorkspaceCenter,
}

/// What is known of one Inverse3.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Inverse3View {
    pub device_id: String,
    /// The cursor (m, the service's axes), once reported.
    pub cursor_position_m: Option<Vector3<f64>>,
    pub cursor_velocity_m_s: Option<Vector3<f64>>,
    /// The force the device applies now (N), as it reports it.
    pub current_cursor_force_n: Option<Vector3<f64>>,
    pub status: Inverse3Status,
    /// Whether a snapshot has given this device's `config`.
    pub configured: bool,
    pub origin: CursorOrigin,
}

/// What is known of one handle (a Verse Grip, wired or wireless).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GripView {
    pub device_id: String,
    pub orientation: Option<UnitQuaternion<f64>>,
    /// Buttons, one bit each: a wired grip's button is bit 0; a wireless grip's a, b, c are
    /// bits 0, 1, 2.
    pub buttons: u32,
}

/// Everything the client knows of the service's devices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ServiceView {
    pub session_id: Option<u64>,
    pub inverse3: Vec<Inverse3View>,
    pub grips: Vec<GripView>,
}

/// A frame that could not be read, and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("malformed frame from the Haply Inverse Service: {0}")]
pub struct Malformed(pub String);

fn malformed<T>(what: impl Into<String>) -> Result<T, Malformed> {
    Err(Malformed(what.into()))
}

/// Whether a frame was a full snapshot (it carried the devices' `config`) or an update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameKind {
    Snapshot,
    Update,
}

/// The handle lists of a frame, in the order grips are kept.
const GRIP_LISTS: [&str; 3] = ["verse_grip", "wireless_verse_grip", "custom_verse_grip"];

impl ServiceView {
    /// Merges one text frame from the service; whether it was a snapshot. A malformed frame
    /// (not JSON, not an object, a device without its id, a field of the wrong shape)
    /// changes nothing.
    pub fn merge(&mut self, text: &str) -> Result<FrameKind, Malformed> {
        let frame: Value = serde_json::from_str(text).or_else(|e| malformed(e.to_string()))?;
        let Some(frame) = frame.as_object() else {
            return malformed("not a JSON object");
        };
        let mut merged = self.clone();
        let mut kind = FrameKind::Update;
        if let Some(id) = frame.get("session_id") {
            merged.session_id = Some(id.as_u64().map_or_else(|| malformed("session_id"), Ok)?);
        }
        for (id, entry) in entries(frame, "inverse3")? {
            let device = find_or_add(&mut merged.inverse3, id, |device_id| Inverse3View {
                device_id,
                ..Inverse3View::default()
            });
            if merge_inverse3(device, entry)? {
                kind = FrameKind::Snapshot;
            }
        }
        for list in GRIP_LISTS {
            for (id, entry) in entries(frame, list)? {
                let grip = find_or_add(&mut merged.grips, id, |device_id| GripView {
                    device_id,
                    ..GripView::default()
                });
                merge_grip(grip, entry)?;
            }
        }
        *self = merged;
        Ok(kind)
    }

    /// The Inverse3 `id`, or the first one; with the handle at the same place in the
    /// handles' list (the first handle with the first Inverse3), if there is one.
    pub fn pick(&self, id: Option<&str>) -> Option<(&Inverse3View, Option<&GripView>)> {
        let place = match id {
            Some(id) => self.inverse3.iter().position(|d| d.device_id == id)?,
            None if self.inverse3.is_empty() => return None,
            None => 0,
        };
        Some((&self.inverse3[place], self.grips.get(place)))
    }
}

/// One device's entry in a frame: its id and the entry.
type Entry<'a> = (&'a str, &'a Map<String, Value>);

/// The device entries of the list `name` in `frame`, each with its id; none when the frame
/// leaves the list out.
fn entries<'a>(frame: &'a Map<String, Value>, name: &str) -> Result<Vec<Entry<'a>>, Malformed> {
    let Some(list) = frame.get(name) else {
        return Ok(Vec::new());
    };
    let Some(list) = list.as_array() else {
        return malformed(format!("`{name}` is not a list"));
    };
    list.iter()
        .map(|entry| {
            let entry = entry.as_object();
            let id = entry
                .and_then(|e| e.get("device_id"))
                .and_then(Value::as_str);
            match (entry, id) {
                (Some(entry), Some(id)) => Ok((id, entry)),
                _ => malformed(format!("a `{name}` entry without a device_id")),
            }
        })
        .collect()
}

fn find_or_add<'a, T>(list: &'a mut Vec<T>, id: &str, new: impl FnOnce(String) -> T) -> &'a mut T
where
    T: HasDeviceId,
{
    match list.iter().position(|d| d.device_id() == id) {
        Some(k) => &mut list[k],
        None => {
            list.push(new(id.to_owned()));
            list.last_mut().expect("just pushed")
        }
    }
}

trait HasDeviceId {
    fn device_id(&self) -> &str;
}

impl HasDeviceId for Inverse3View {
    fn device_id(&self) -> &str {
        &self.device_id
    }
}

impl HasDeviceId for GripView {
    fn device_id(&self) -> &str {
        &self.device_id
    }
}

/// The object `name` of `entry`, if there is one.
fn section<'a>(
    entry: &'a Map<String, Value>,
    name: &str,
) -> Result<Option<&'a Map<String, Value>>, Malformed> {
    match entry.get(name) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::Object(section)) => Ok(Some(section)),
        Some(_) => malformed(format!("`{name}` is not an object")),
    }
}

/// Merges one Inverse3 entry; whether it carried the device's `config`.
fn merge_inverse3(
    device: &mut Inverse3View,
    entry: &Map<String, Value>,
) -> Result<bool, Malformed> {
    if let Some(state) = section(entry, "state")? {
        merge_vec3(&mut device.cursor_position_m, state, "cursor_position")?;
        merge_vec3(&mut device.cursor_velocity_m_s, state, "cursor_velocity")?;
        merge_vec3(
            &mut device.current_cursor_force_n,
            state,
            "current_cursor_force",
        )?;
    }
    if let Some(status) = section(entry, "status")? {
        let flags = &mut device.status;
        merge_flag(&mut flags.calibrated, status, "calibrated")?;
        merge_flag(&mut flags.ready, status, "ready")?;
        merge_flag(&mut flags.started, status, "started")?;
        merge_flag(&mut flags.in_use, status, "in_use")?;
        merge_flag(&mut flags.power_supply, status, "power_supply")?;
    }
    let Some(config) = section(entry, "config")? else {
        return Ok(false);
    };
    device.configured = true;
    device.origin = match config.get("coordinate_origin").and_then(Value::as_str) {
        Some("workspace_center") => CursorOrigin::WorkspaceCenter,
        _ => CursorOrigin::DeviceBase,
    };
    Ok(true)
}

/// Merges one handle's entry.
fn merge_grip(grip: &mut GripView, entry: &Map<String, Value>) -> Result<(), Malformed> {
    let Some(state) = section(entry, "state")? else {
        return Ok(());
    };
    if let Some(q) = state.get("orientation") {
        grip.orientation = Some(quaternion(q).ok_or_else(|| Malformed("orientation".into()))?);
    }
    if let Some(button) = state.get("button") {
        let pressed = button.as_bool().ok_or_else(|| Malformed("button".into()))?;
        grip.buttons = (grip.buttons & !1) | u32::from(pressed);
    }
    if let Some(buttons) = section(state, "buttons")? {
        for (bit, name) in ["a", "b", "c"].into_iter().enumerate() {
            let mut pressed = grip.buttons & (1 << bit) != 0;
            merge_flag(&mut pressed, buttons, name)?;
            grip.buttons = (grip.buttons & !(1 << bit)) | (u32::from(pressed) << bit);
        }
    }
    Ok(())
}

fn merge_flag(flag: &mut bool, section: &Map<String, Value>, name: &str) -> Result<(), Malformed> {
    match section.get(name) {
        None => Ok(()),
        Some(Value::Bool(value)) => {
            *flag = *value;
            Ok(())
        }
        Some(_) => malformed(format!("`{name}` is not true or false")),
    }
}

fn merge_vec3(
    known: &mut Option<Vector3<f64>>,
    section: &Map<String, Value>,
    name: &str,
) -> Result<(), Malformed> {
    let Some(value) = section.get(name) else {
        return Ok(());
    };
    *known = Some(vec3(value).ok_or_else(|| Malformed(format!("`{name}` is not {{x, y, z}}")))?);
    Ok(())
}

fn number(object: &Map<String, Value>, name: &str) -> Option<f64> {
    object.get(name)?.as_f64()
}

/// `{x, y, z}`.
fn vec3(value: &Value) -> Option<Vector3<f64>> {
    let v = value.as_object()?;
    Some(Vector3::new(
        number(v, "x")?,
        number(v, "y")?,
        number(v, "z")?,
    ))
}

/// `{w, x, y, z}`, normalized; `None` for one of no length.
fn quaternion(value: &Value) -> Option<UnitQuaternion<f64>> {
    let q = value.as_object()?;
    let q = Quaternion::new(
        number(q, "w")?,
        number(q, "x")?,
        number(q, "y")?,
        number(q, "z")?,
    );
    (q.norm() > 1e-9).then(|| UnitQuaternion::from_quaternion(q))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SNAPSHOT: &str = r#"{"session_id": 7,
        "inverse3": [{"device_id": "049D",
            "config": {"type": "inverse3", "handedness": "right"},
            "state": {"cursor_position": {"x": 0.01, "y": -0.1, "z": 0.2},
                      "cursor_velocity": {"x": 0, "y": 0, "z": 0}, "mode": "idle"},
            "status": {"calibrated": true, "ready": true, "started": true,
                       "in_use": false, "power_supply": true}}],
        "wireless_verse_grip": [{"device_id": "G1",
            "state": {"orientation": {"w": 1, "x": 0, "y": 0, "z": 0},
                      "buttons": {"a": false, "b": true, "c": false}},
            "status": {"ready": true}}]}"#;

    #[test]
    fn a_partial_frame_keeps_what_it_leaves_out() {
        let mut view = ServiceView::default();
        assert_eq!(view.merge(SNAPSHOT), Ok(FrameKind::Snapshot));
        let update = r#"{"inverse3": [{"device_id": "049D",
            "state": {"cursor_velocity": {"x": 0.5, "y": 0, "z": 0}},
            "status": {"ready": false}}]}"#;
        assert_eq!(view.merge(update), Ok(FrameKind::Update));
        let (device, grip) = view.pick(None).unwrap();
        assert_eq!(
            device.cursor_position_m,
            Some(Vector3::new(0.01, -0.1, 0.2))
        );
        assert_eq!(
            device.cursor_velocity_m_s,
            Some(Vector3::new(0.5, 0.0, 0.0))
        );
        assert!(device.status.calibrated && !device.status.ready);
        assert!(device.configured);
        assert_eq!(grip.unwrap().buttons, 0b010);
    }

    #[test]
    fn a_malformed_frame_changes_nothing() {
        let mut view = ServiceView::default();
        view.merge(SNAPSHOT).unwrap();
        let known = view.clone();
        for bad in [
            "not json",
            "[1, 2]",
            r#"{"inverse3": {"device_id": "049D"}}"#,
            r#"{"inverse3": [{"state": {}}]}"#,
            r#"{"inverse3": [{"device_id": "049D", "state": {"cursor_position": {"x": 1}}}]}"#,
            r#"{"inverse3": [{"device_id": "049D", "status": {"ready": "yes"}}]}"#,
            r#"{"inverse3": [{"device_id": "049D", "state": {"cursor_position": {"x": 9, "y": 9, "z": 9}}}], "verse_grip": [{"device_id": "V", "state": {"button": 1}}]}"#,
        ] {
            assert!(view.merge(bad).is_err(), "{bad}");
            assert_eq!(view, known, "{bad}");
        }
    }

    #[test]
    fn the_force_is_named_by_the_services_version() {
        assert_eq!(WireFormat::of_version("3.5.0.0"), Some(WireFormat::Vector));
        assert_eq!(WireFormat::of_version("v3.6"), Some(WireFormat::Vector));
        assert_eq!(WireFormat::of_version("3.4.2"), Some(WireFormat::Values));
        assert_eq!(WireFormat::of_version("3.1.0"), Some(WireFormat::Values));
        assert_eq!(WireFormat::of_version("3.0.7"), None);
        assert_eq!(WireFormat::of_version("dev"), None);
        let force = Vector3::new(1.0, -2.0, 0.5);
        let new: Value =
            serde_json::from_str(&force_command("A1", &force, WireFormat::Vector, true)).unwrap();
        let command = &new["inverse3"][0]["commands"]["set_cursor_force"];
        assert_eq!(new["inverse3"][0]["device_id"], "A1");
        assert_eq!(
            (command["vector"]["y"].as_f64(), command.get("values")),
            (Some(-2.0), None)
        );
        assert!(new["session"]["configure"]["profile"]["name"].is_string());
        let old: Value =
            serde_json::from_str(&force_command("A1", &force, WireFormat::Values, false)).unwrap();
        let command = &old["inverse3"][0]["commands"]["set_cursor_force"];
        assert_eq!(
            (command["values"]["z"].as_f64(), command.get("vector")),
            (Some(0.5), None)
        );
        assert_eq!(command["execute"], true);
        assert!(old.get("session").is_none());
    }
}
