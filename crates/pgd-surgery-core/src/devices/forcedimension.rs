//! The Force Dimension backend (omega, sigma, delta; the Novint Falcon through the same SDK):
//! the vendor's `dhd` library loaded at run time, as OpenHaptics' is.
//!
//! The dhd SDK has no scheduler of its own, so the servo is a thread of ours, paced at 1 kHz by
//! the same [`Metronome`] as the haptic loop: each frame it reads the end effector's position
//! (m), its orientation frame and the buttons, publishes them to the [`ServoLink`], and sends
//! the link's force (zero once the haptic loop stops commanding: the watchdog). SDK errors are
//! reported through the link; the haptic loop turns them into a fault and fades its force.

use std::ffi::{CStr, c_char, c_int, c_uint};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

use libloading::Library;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::release::Release;
use super::servo::{ServoLink, ServoThread};
use super::vendor::VendorLibrary;
use super::{
    DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice, Metronome, TICK_S, TimerMode,
    held_to_ceiling,
};

/// The dhd library, and what to install when it is missing.
pub const LIBRARY: VendorLibrary = VendorLibrary {
    backend: "forcedimension",
    file: "libdhd.so",
    variable: "PGD_FORCEDIMENSION_LIB",
    install: "the Force Dimension SDK for Linux (its lib/ folder on LD_LIBRARY_PATH)",
};

/// The dhd functions the backend calls, resolved once; the library stays open with them.
struct Dhd {
    open: unsafe extern "C" fn() -> c_int,
    open_id: unsafe extern "C" fn(c_char) -> c_int,
    get_device_count: unsafe extern "C" fn() -> c_int,
    close: unsafe extern "C" fn(c_char) -> c_int,
    enable_force: unsafe extern "C" fn(u8, c_char) -> c_int,
    get_position: unsafe extern "C" fn(*mut f64, *mut f64, *mut f64, c_char) -> c_int,
    get_orientation_frame: unsafe extern "C" fn(*mut [f64; 3], c_char) -> c_int,
    get_button_mask: unsafe extern "C" fn(c_char) -> c_uint,
    set_force: unsafe extern "C" fn(f64, f64, f64, c_char) -> c_int,
    get_max_force: unsafe extern "C" fn(c_char) -> f64,
    get_system_name: unsafe extern "C" fn(c_char) -> *const c_char,
    error_get_last: unsafe extern "C" fn() -> c_int,
    error_get_last_str: unsafe extern "C" fn() -> *const c_char,
    error_get_str: unsafe extern "C" fn(c_int) -> *const c_char,
    _library: Library,
}

impl Dhd {
    fn load(path: &Path) -> Result<Self, DeviceError> {
        let library = LIBRARY.load(path)?;
        macro_rules! resolve {
            ($name:literal) => {
                // SAFETY: the field's type is the one `dhdc.h` declares for the function.
                unsafe { LIBRARY.function(&library, path, $name)? }
            };
        }
        Ok(Self {
            open: resolve!("dhdOpen"),
            open_id: resolve!("dhdOpenID"),
            get_device_count: resolve!("dhdGetDeviceCount"),
            close: resolve!("dhdClose"),
            enable_force: resolve!("dhdEnableForce"),
            get_position: resolve!("dhdGetPosition"),
            get_orientation_frame: resolve!("dhdGetOrientationFrame"),
            get_button_mask: resolve!("dhdGetButtonMask"),
            set_force: resolve!("dhdSetForce"),
            get_max_force: resolve!("dhdGetMaxForce"),
            get_system_name: resolve!("dhdGetSystemName"),
            error_get_last: resolve!("dhdErrorGetLast"),
            error_get_last_str: resolve!("dhdErrorGetLastStr"),
            error_get_str: resolve!("dhdErrorGetStr"),
            _library: library,
        })
    }

    /// The SDK's last error: its code and its own words.
    fn last_error(&self) -> (u32, String) {
        // SAFETY: both take nothing; the string is static in the SDK, or null.
        let (code, text) = unsafe { ((self.error_get_last)(), (self.error_get_last_str)()) };
        (
            code as u32,
            c_text(text).unwrap_or_else(|| "unknown error".into()),
        )
    }

    /// The SDK's words for error `code`.
    fn error_text(&self, code: u32) -> String {
        // SAFETY: a plain value; the string is static in the SDK, or null.
        c_text(unsafe { (self.error_get_str)(code as c_int) })
            .unwrap_or_else(|| "unknown error".into())
    }
}

/// A C string the SDK owns, copied; `None` for null.
fn c_text(text: *const c_char) -> Option<String> {
    // SAFETY: non-null strings from the SDK are NUL-terminated.
    (!text.is_null()).then(|| {
        unsafe { CStr::from_ptr(text) }
            .to_string_lossy()
            .into_owned()
    })
}

/// The device frame (x towards the user, y right, z up, m, centred on the workspace) to the
/// scene's (x right, y away from the user, z up).
fn to_scene(device_m: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(device_m.y, -device_m.x, device_m.z)
}

/// A force in the scene's axes to the device's.
fn to_device_force(scene_n: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(-scene_n.y, scene_n.x, scene_n.z)
}

/// The device axes in the scene's, as a rotation.
fn frame() -> Matrix3<f64> {
    Matrix3::new(0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
}

/// One servo frame: read, publish, send, report.
fn servo_frame(dhd: &Dhd, id: c_char, link: &ServoLink) {
    let (mut x, mut y, mut z) = (0.0, 0.0, 0.0);
    let mut rotation = [[0.0; 3]; 3];
    // SAFETY: out-pointers to three doubles and to a 3 × 3 array, as `dhdc.h` declares.
    let (read, oriented, buttons) = unsafe {
        (
            (dhd.get_position)(&mut x, &mut y, &mut z, id),
            (dhd.get_orientation_frame)(rotation.as_mut_ptr(), id),
            (dhd.get_button_mask)(id),
        )
    };
    let orientation = match oriented >= 0 {
        true => {
            let device = Matrix3::from_fn(|r, c| rotation[r][c]);
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(
                &(frame() * device * frame().transpose()),
            ))
        }
        // A device without a wrist reports no orientation.
        false => UnitQuaternion::identity(),
    };
    if read >= 0 {
        link.publish(&DeviceSample {
            tip_m: to_scene(&Vector3::new(x, y, z)),
            orientation,
            buttons,
        });
    }
    let force = to_device_force(&link.force_to_render());
    // SAFETY: plain values.
    let sent = unsafe { (dhd.set_force)(force.x, force.y, force.z, id) };
    if read < 0 || sent < 0 {
        let (code, _) = dhd.last_error();
        link.report_error(code.max(1), 0);
    }
}

/// An open device and its servo thread: what must be released, once, whichever way the program
/// leaves (see [`super::release`]).
struct Session {
    dhd: Arc<Dhd>,
    id: c_char,
    link: Arc<ServoLink>,
    running: Arc<AtomicBool>,
    servo: ServoThread,
    released: AtomicBool,
}

impl Release for Session {
    /// Zero force at once (the link halted), the servo stopped (not waited for from its own
    /// thread), zero sent, the device closed.
    fn release(&self) {
        if self.released.swap(true, Ordering::AcqRel) {
            return;
        }
        self.link.halt();
        self.running.store(false, Ordering::Relaxed);
        self.servo.join();
        // SAFETY: the servo has stopped; the ID is the one opened.
        unsafe {
            (self.dhd.set_force)(0.0, 0.0, 0.0, self.id);
            (self.dhd.close)(self.id);
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.release();
    }
}

/// A Force Dimension device served by a servo thread of ours.
pub struct ForceDimension {
    name: String,
    session: Arc<Session>,
    limits: DeviceLimits,
}

impl ForceDimension {
    /// Opens a device through the dhd library at `library` (or the one `LIBRARY` finds): the
    /// one at `index` in the SDK's list of connected devices (two hands, two devices), or the
    /// first available; and starts its servo thread. On any error after the device was
    /// opened, it is closed before the error is returned.
    pub fn open(library: Option<&Path>, index: Option<u8>) -> Result<Self, DeviceError> {
        let path = library.map_or_else(|| LIBRARY.path(), Path::to_path_buf);
        let dhd = Arc::new(Dhd::load(&path)?);
        let failed = |what: &str, (code, text): (u32, String)| DeviceError::Failed {
            device: match index {
                Some(index) => format!("Force Dimension device {index}"),
                None => "Force Dimension".into(),
            },
            message: format!("{what}: {text} (dhd error {code})"),
        };
        let id = open_device(&dhd, index).map_err(|(what, error)| failed(&what, error))?;
        let session = Arc::new(Session {
            dhd: dhd.clone(),
            id,
            link: Arc::new(ServoLink::default()),
            running: Arc::new(AtomicBool::new(true)),
            servo: ServoThread::default(),
            released: AtomicBool::new(false),
        });
        super::register(&(session.clone() as Arc<dyn Release>));
        // SAFETY: the ID was just returned by `dhdOpen` or `dhdOpenID`.
        let (model, max_force) = unsafe {
            (
                c_text((dhd.get_system_name)(session.id)),
                (dhd.get_max_force)(session.id),
            )
        };
        let limits = held_to_ceiling(device_limits(max_force), "Force Dimension");
        session.link.set_peak_force_n(limits.peak_force_n);
        // SAFETY: the ID is open.
        if unsafe { (dhd.enable_force)(1, session.id) } < 0 {
            return Err(failed("cannot enable force output", dhd.last_error()));
        }
        let servo = spawn_servo(&session)
            .map_err(|e| failed("cannot start the servo thread", (0, e.to_string())))?;
        session.servo.set(servo);
        let model = model.unwrap_or_else(|| "device".into());
        let name = match index {
            Some(index) => format!("Force Dimension {model} ({index})"),
            None => format!("Force Dimension {model}"),
        };
        if !session.link.await_first_sample() {
            let (code, text) = dhd.last_error();
            return Err(DeviceError::Failed {
                device: name,
                message: format!(
                    "the servo read no position within a second: {text} (dhd error {code})"
                ),
            });
        }
        Ok(Self {
            name,
            session,
            limits,
        })
    }

    /// The dhd library this machine would load, or why there is none (what to install).
    pub fn find_library() -> Result<PathBuf, DeviceError> {
        let path = LIBRARY.path();
        Dhd::load(&path).map(|_| path)
    }

    /// What the haptic loop and the servo share.
    pub fn link(&self) -> &Arc<ServoLink> {
        &self.session.link
    }
}

/// Opens the device at `index` in the SDK's list, or the first available; its ID, or what
/// failed and the SDK's error.
fn open_device(dhd: &Dhd, index: Option<u8>) -> Result<c_char, (String, (u32, String))> {
    let unopened = || "no device could be opened (is it plugged in, powered and calibrated?)";
    let Some(index) = index else {
        // SAFETY: takes nothing; returns the device's ID, or −1.
        let id = unsafe { (dhd.open)() };
        return match id < 0 {
            true => Err((unopened().into(), dhd.last_error())),
            false => Ok(id as c_char),
        };
    };
    // SAFETY: takes nothing; returns how many devices are connected, or −1.
    let count = unsafe { (dhd.get_device_count)() };
    if count >= 0 && i32::from(index) >= count {
        let what = format!("there is no device {index}: the SDK finds {count} (0 is the first)");
        return Err((what, dhd.last_error()));
    }
    // SAFETY: a plain value; returns the device's ID, or −1.
    let id = unsafe { (dhd.open_id)(index as c_char) };
    match id < 0 {
        true => Err((unopened().into(), dhd.last_error())),
        false => Ok(id as c_char),
    }
}

/// The servo thread, paced at 1 kHz, until the session stops it.
fn spawn_servo(session: &Session) -> std::io::Result<JoinHandle<()>> {
    let (dhd, link, running) = (
        session.dhd.clone(),
        session.link.clone(),
        session.running.clone(),
    );
    let id = session.id;
    std::thread::Builder::new()
        .name("force dimension servo".into())
        .spawn(move || {
            let mut metronome =
                Metronome::new(Duration::from_secs_f64(TICK_S), TimerMode::default());
            while running.load(Ordering::Relaxed) {
                metronome.wait();
                servo_frame(&dhd, id, &link);
            }
        })
}

/// The SDK states one force limit, the one it enforces (`dhdGetMaxForce`; negative when none
/// is set), and no continuous rating: the peak is that limit, and so is the continuous one.
/// Without a limit set, the Touch-class default holds, well inside any Force Dimension device.
fn device_limits(max_force_n: f64) -> DeviceLimits {
    match max_force_n.is_finite() && max_force_n > 0.0 {
        true => DeviceLimits::peak_only(max_force_n),
        false => DeviceLimits::default(),
    }
}

impl HapticDevice for ForceDimension {
    fn name(&self) -> &str {
        &self.name
    }

    fn limits(&self) -> DeviceLimits {
        self.limits
    }

    fn read(&mut self, _time_s: f64) -> Result<DeviceSample, DeviceError> {
        let session = &self.session;
        if let Some((code, _)) = session.link.take_error() {
            return Err(DeviceError::Failed {
                device: self.name.clone(),
                message: format!("{} (dhd error {code})", session.dhd.error_text(code)),
            });
        }
        session.link.latest().ok_or_else(|| DeviceError::Failed {
            device: self.name.clone(),
            message: "the servo has read no position yet".into(),
        })
    }

    fn render(&mut self, force: EdgeForce) -> Result<(), DeviceError> {
        self.session.link.command(&force);
        Ok(())
    }
}
