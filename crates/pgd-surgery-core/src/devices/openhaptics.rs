//! The OpenHaptics backend (Geomagic Touch, Touch X, Phantom): the vendor's HD library is
//! loaded at run time, so the build never needs the SDK and a machine without it gets a clear
//! message instead of a link error.
//!
//! The servo is the HD scheduler's own callback, not a thread of ours: the scheduler runs at
//! the device's servo rate with the priority the vendor's driver needs, and HD calls outside a
//! scheduler frame are not allowed for force output. Each frame the callback reads the position
//! (mm), the transform and the buttons, publishes them to the [`ServoLink`], renders the link's
//! force (zero once the haptic loop stops commanding: the watchdog), and reports any HD error.

use std::ffi::{CString, c_char, c_int, c_uint, c_ulong, c_ushort, c_void};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use libloading::Library;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::release::Release;
use super::servo::ServoLink;
use super::vendor::VendorLibrary;
use super::{DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice, held_to_ceiling};

/// The HD library, and what to install when it is missing.
pub const LIBRARY: VendorLibrary = VendorLibrary {
    backend: "openhaptics",
    file: "libHD.so",
    variable: "PGD_OPENHAPTICS_LIB",
    install: "OpenHaptics (the Geomagic Touch device drivers and the OpenHaptics Developer Edition for Linux)",
};

// Parameters, capabilities and return values of `hdDefines.h`.
const HD_CURRENT_BUTTONS: c_uint = 0x2000;
const HD_CURRENT_POSITION: c_uint = 0x2050;
const HD_CURRENT_TRANSFORM: c_uint = 0x2052;
const HD_DEVICE_MODEL_TYPE: c_uint = 0x2501;
const HD_USABLE_WORKSPACE_DIMENSIONS: c_uint = 0x2551;
const HD_NOMINAL_MAX_FORCE: c_uint = 0x2603;
const HD_NOMINAL_MAX_CONTINUOUS_FORCE: c_uint = 0x2604;
const HD_CURRENT_FORCE: c_uint = 0x2700;
const HD_FORCE_OUTPUT: c_uint = 0x4000;
const HD_INVALID_HANDLE: c_uint = 0xFFFF_FFFF;
const HD_CALLBACK_DONE: c_uint = 0;
const HD_CALLBACK_CONTINUE: c_uint = 1;
const HD_DEFAULT_SCHEDULER_PRIORITY: c_ushort = u16::MAX / 2;

/// `HDErrorInfo`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
struct ErrorInfo {
    code: c_uint,
    internal: c_int,
    handle: c_uint,
}

type Callback = extern "C" fn(*mut c_void) -> c_uint;

/// The HD functions the backend calls, resolved once from the library, which they keep open.
struct Hd {
    init_device: unsafe extern "C" fn(*const c_char) -> c_uint,
    disable_device: unsafe extern "C" fn(c_uint),
    make_current: unsafe extern "C" fn(c_uint),
    get_error: unsafe extern "C" fn() -> ErrorInfo,
    enable: unsafe extern "C" fn(c_uint),
    begin_frame: unsafe extern "C" fn(c_uint),
    end_frame: unsafe extern "C" fn(c_uint),
    get_doublev: unsafe extern "C" fn(c_uint, *mut f64),
    get_integerv: unsafe extern "C" fn(c_uint, *mut c_int),
    get_string: unsafe extern "C" fn(c_uint) -> *const c_char,
    set_doublev: unsafe extern "C" fn(c_uint, *const f64),
    start_scheduler: unsafe extern "C" fn(),
    stop_scheduler: unsafe extern "C" fn(),
    schedule_asynchronous: unsafe extern "C" fn(Callback, *mut c_void, c_ushort) -> c_ulong,
    unschedule: unsafe extern "C" fn(c_ulong),
    _library: Library,
}

impl Hd {
    /// Loads the library at `path` (a bare name goes through the dynamic loader's search).
    fn load(path: &Path) -> Result<Self, DeviceError> {
        let library = LIBRARY.load(path)?;
        macro_rules! resolve {
            ($name:literal) => {
                // SAFETY: the field's type is the one `hd.h` declares for the function.
                unsafe { LIBRARY.function(&library, path, $name)? }
            };
        }
        Ok(Self {
            init_device: resolve!("hdInitDevice"),
            disable_device: resolve!("hdDisableDevice"),
            make_current: resolve!("hdMakeCurrentDevice"),
            get_error: resolve!("hdGetError"),
            enable: resolve!("hdEnable"),
            begin_frame: resolve!("hdBeginFrame"),
            end_frame: resolve!("hdEndFrame"),
            get_doublev: resolve!("hdGetDoublev"),
            get_integerv: resolve!("hdGetIntegerv"),
            get_string: resolve!("hdGetString"),
            set_doublev: resolve!("hdSetDoublev"),
            start_scheduler: resolve!("hdStartScheduler"),
            stop_scheduler: resolve!("hdStopScheduler"),
            schedule_asynchronous: resolve!("hdScheduleAsynchronous"),
            unschedule: resolve!("hdUnschedule"),
            _library: library,
        })
    }

    /// The pending HD error, if any, as `(code, vendor code)`.
    fn error(&self) -> Option<(u32, u32)> {
        // SAFETY: `hdGetError` takes no argument and returns the struct by value.
        let info = unsafe { (self.get_error)() };
        (info.code != 0).then_some((info.code, info.internal as u32))
    }

    fn doubles<const N: usize>(&self, parameter: c_uint) -> [f64; N] {
        let mut values = [0.0; N];
        // SAFETY: every parameter asked for here writes at most N doubles.
        unsafe { (self.get_doublev)(parameter, values.as_mut_ptr()) };
        values
    }
}

/// What an HD error code means, for the trainee and for whoever set the device up.
pub fn error_message(code: u32) -> &'static str {
    match code {
        0x0100 => "invalid enumerant (HD_INVALID_ENUM)",
        0x0101 => "invalid value (HD_INVALID_VALUE)",
        0x0102 => "operation not allowed now (HD_INVALID_OPERATION)",
        0x0103 => "wrong input type (HD_INVALID_INPUT_TYPE)",
        0x0104 => "bad device handle (HD_BAD_HANDLE)",
        0x0200 => "the motors are too warm: let the device cool down (HD_WARM_MOTORS)",
        0x0201 => "the force exceeded the device's maximum (HD_EXCEEDED_MAX_FORCE)",
        0x0202 => "the force changed faster than the device allows (HD_EXCEEDED_MAX_FORCE_IMPULSE)",
        0x0203 => "the stylus moved faster than the device allows (HD_EXCEEDED_MAX_VELOCITY)",
        0x0204 => "force error (HD_FORCE_ERROR)",
        0x0300 => "device fault: check its cable and power (HD_DEVICE_FAULT)",
        0x0301 => "the device is already initialized (HD_DEVICE_ALREADY_INITIATED)",
        0x0302 => {
            "communication error: check the cable and the device's permissions (HD_COMM_ERROR)"
        }
        0x0303 => {
            "communication configuration error: run the vendor's Touch Setup (HD_COMM_CONFIG_ERROR)"
        }
        0x0304 => "timer error (HD_TIMER_ERROR)",
        0x0400 => "a frame was begun twice (HD_ILLEGAL_BEGIN)",
        0x0401 => "a frame was ended without a begin (HD_ILLEGAL_END)",
        0x0402 => "frame error (HD_FRAME_ERROR)",
        0x0500 => "invalid scheduler priority (HD_INVALID_PRIORITY)",
        0x0501 => "the scheduler is full (HD_SCHEDULER_FULL)",
        0x0600 => "no valid OpenHaptics license (HD_INVALID_LICENSE)",
        _ => "unknown HD error",
    }
}

/// The device frame (x right, y up, z towards the user, mm) to the scene's (x right, y away
/// from the user, z up, m), with the device's centre at the scene's origin.
fn to_scene(device_mm: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(device_mm.x, -device_mm.z, device_mm.y) * 1e-3
}

/// A force in the scene's axes to the device's.
fn to_device_force(scene_n: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(scene_n.x, scene_n.z, -scene_n.y)
}

/// The device's frame change as a rotation: the orientation of the stylus in the scene.
fn frame() -> Matrix3<f64> {
    Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0)
}

/// How many devices' servos the HD scheduler runs, by HD library (the tests load copies of
/// a fake, each with a scheduler of its own). The scheduler is one for the library: it
/// starts with the first device's servo and stops with the last one's, so that closing one
/// hand's device leaves the other's running.
static SCHEDULER_USERS: Mutex<Vec<(PathBuf, usize)>> = Mutex::new(Vec::new());

/// Runs `change` on the count of devices `library`'s scheduler serves, under its lock.
fn with_scheduler_users<T>(library: &Path, change: impl FnOnce(&mut usize) -> T) -> T {
    let mut all = SCHEDULER_USERS.lock().unwrap_or_else(|p| p.into_inner());
    let k = match all.iter().position(|(path, _)| path == library) {
        Some(k) => k,
        None => {
            all.push((library.to_owned(), 0));
            all.len() - 1
        }
    };
    change(&mut all[k].1)
}

/// How long a device closing while another's servo runs waits for its own servo's last frame,
/// at zero force, before unscheduling it without one.
const LAST_FRAME_WAIT: Duration = Duration::from_millis(100);

/// What the scheduler callback reaches: the functions, the device and the link.
struct Servo {
    hd: Arc<Hd>,
    handle: c_uint,
    link: Arc<ServoLink>,
    /// Set when the device closes while the scheduler runs on for another: the next frame
    /// renders zero and is the callback's last...
    leaving: AtomicBool,
    /// ...which it says here.
    left: AtomicBool,
}

/// One servo frame: read, publish, render, report.
extern "C" fn servo_frame(data: *mut c_void) -> c_uint {
    // SAFETY: `data` is the `Servo` the device keeps boxed until the callback is unscheduled.
    let servo = unsafe { &*(data as *const Servo) };
    let hd = &servo.hd;
    // SAFETY: HD calls inside a frame on the scheduler's thread, as the API requires.
    unsafe { (hd.begin_frame)(servo.handle) };
    let position: [f64; 3] = hd.doubles(HD_CURRENT_POSITION);
    let transform: [f64; 16] = hd.doubles(HD_CURRENT_TRANSFORM);
    let mut buttons: c_int = 0;
    // SAFETY: the buttons are one integer.
    unsafe { (hd.get_integerv)(HD_CURRENT_BUTTONS, &mut buttons) };
    let rotation = Matrix3::from_fn(|r, c| transform[4 * c + r]);
    let orientation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(
        &(frame() * rotation * frame().transpose()),
    ));
    servo.link.publish(&DeviceSample {
        tip_m: to_scene(&Vector3::from(position)),
        orientation,
        buttons: buttons as u32,
    });
    let leaving = servo.leaving.load(Ordering::Acquire);
    let force = match leaving {
        true => Vector3::zeros(),
        false => to_device_force(&servo.link.force_to_render()),
    };
    // SAFETY: the force is three doubles.
    unsafe {
        (hd.set_doublev)(HD_CURRENT_FORCE, force.as_ptr());
        (hd.end_frame)(servo.handle);
    }
    if let Some((code, internal)) = hd.error() {
        servo.link.report_error(code, internal);
    }
    if leaving {
        servo.left.store(true, Ordering::Release);
        return HD_CALLBACK_DONE;
    }
    HD_CALLBACK_CONTINUE
}

/// An initialized device and its scheduled servo: what must be released, once, whichever way
/// the program leaves (see [`super::release`]).
struct Session {
    hd: Arc<Hd>,
    /// The HD library's file: whose scheduler serves the device.
    library: PathBuf,
    handle: c_uint,
    /// The servo callback's handle once scheduled (with the scheduler started).
    scheduled: Option<c_ulong>,
    servo: Box<Servo>,
    released: AtomicBool,
}

impl Release for Session {
    /// Zero force at once (the link halted). The last device the scheduler serves: the
    /// scheduler stopped (no callback runs after it returns) and the callback unscheduled,
    /// zero written in a last frame. Another device still served: this one's servo renders
    /// zero in a last frame of its own and ends, the scheduler running on. Then the device is
    /// disabled.
    fn release(&self) {
        if self.released.swap(true, Ordering::AcqRel) {
            return;
        }
        self.servo.link.halt();
        let Some(scheduled) = self.scheduled else {
            // SAFETY: the handle is the one initialized; no callback of it was scheduled.
            unsafe { (self.hd.disable_device)(self.handle) };
            return;
        };
        with_scheduler_users(&self.library, |users| {
            *users = users.saturating_sub(1);
            match *users {
                0 => self.stop_last(scheduled),
                _ => self.leave_running(scheduled),
            }
        });
        // SAFETY: the handle is the one initialized; its callback no longer runs.
        unsafe { (self.hd.disable_device)(self.handle) };
    }
}

impl Session {
    /// The scheduler's last device: the scheduler stopped, the callback unscheduled, zero
    /// written in a frame of this thread's.
    fn stop_last(&self, scheduled: c_ulong) {
        let zero = [0.0f64; 3];
        // SAFETY: the handle is the one initialized; the callback's data (`servo`) lives as
        // long as the session, past the scheduler's stop.
        unsafe {
            (self.hd.stop_scheduler)();
            (self.hd.unschedule)(scheduled);
            (self.hd.begin_frame)(self.handle);
            (self.hd.set_doublev)(HD_CURRENT_FORCE, zero.as_ptr());
            (self.hd.end_frame)(self.handle);
        }
    }

    /// Another device's servo runs on: this one's renders zero in its last frame and ends
    /// itself; if the scheduler runs no frame of it in time, it is unscheduled.
    fn leave_running(&self, scheduled: c_ulong) {
        self.servo.leaving.store(true, Ordering::Release);
        let asked = Instant::now();
        while !self.servo.left.load(Ordering::Acquire) {
            if asked.elapsed() > LAST_FRAME_WAIT {
                // SAFETY: the callback's handle, scheduled and not ended.
                unsafe { (self.hd.unschedule)(scheduled) };
                return;
            }
            std::thread::sleep(Duration::from_micros(200));
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.release();
    }
}

/// A Geomagic device served by the HD scheduler.
pub struct OpenHaptics {
    name: String,
    session: Arc<Session>,
    limits: DeviceLimits,
    /// The usable workspace's box (m, the scene's axes): its lower and upper corners.
    pub workspace_m: (Vector3<f64>, Vector3<f64>),
}

impl OpenHaptics {
    /// Opens the device named `device` (the vendor's default without one) through the HD
    /// library at `library` (or the one `LIBRARY` finds). On any error after the device was
    /// initialized, it is released before the error is returned.
    pub fn open(library: Option<&Path>, device: Option<&str>) -> Result<Self, DeviceError> {
        let path = library.map_or_else(|| LIBRARY.path(), Path::to_path_buf);
        let hd = Arc::new(Hd::load(&path)?);
        let name = device.unwrap_or("default device").to_owned();
        let failed = |what: &str, (code, internal): (u32, u32)| DeviceError::Failed {
            device: format!("OpenHaptics {name}"),
            message: format!(
                "{what}: {} (HD error {code:#06x}, vendor code {internal})",
                error_message(code)
            ),
        };
        let c_name = device
            .map(|d| CString::new(d).map_err(|_| failed("bad device name", (0x0101, 0))))
            .transpose()?;
        // SAFETY: a null name asks for the default device, as `hd.h` documents.
        let handle =
            unsafe { (hd.init_device)(c_name.as_ref().map_or(std::ptr::null(), |n| n.as_ptr())) };
        let init_error = hd.error();
        if handle == HD_INVALID_HANDLE {
            return Err(failed(
                "cannot initialize the device",
                init_error.unwrap_or((0x0104, 0)),
            ));
        }
        let mut session = Session {
            hd: hd.clone(),
            library: path.clone(),
            handle,
            scheduled: None,
            servo: Box::new(Servo {
                hd: hd.clone(),
                handle,
                link: Arc::new(ServoLink::default()),
                leaving: AtomicBool::new(false),
                left: AtomicBool::new(false),
            }),
            released: AtomicBool::new(false),
        };
        if let Some(error) = init_error {
            drop(session);
            return Err(failed("cannot initialize the device", error));
        }
        // SAFETY: the handle was just returned by `hdInitDevice`.
        unsafe { (hd.make_current)(handle) };
        let limits = held_to_ceiling(device_limits(&hd), &format!("OpenHaptics {name}"));
        session.servo.link.set_peak_force_n(limits.peak_force_n);
        let workspace: [f64; 6] = hd.doubles(HD_USABLE_WORKSPACE_DIMENSIONS);
        let corners = (
            to_scene(&Vector3::new(workspace[0], workspace[1], workspace[2])),
            to_scene(&Vector3::new(workspace[3], workspace[4], workspace[5])),
        );
        let workspace_m = (corners.0.inf(&corners.1), corners.0.sup(&corners.1));
        let model = model_name(&hd);
        // SAFETY: the callback's data outlives its scheduling (the session unschedules it
        // before the box is freed).
        unsafe {
            (hd.enable)(HD_FORCE_OUTPUT);
            let data = &*session.servo as *const Servo as *mut c_void;
            session.scheduled = Some((hd.schedule_asynchronous)(
                servo_frame,
                data,
                HD_DEFAULT_SCHEDULER_PRIORITY,
            ));
            // One scheduler for every device: started with the first one's servo.
            with_scheduler_users(&path, |users| {
                if *users == 0 {
                    (hd.start_scheduler)();
                }
                *users += 1;
            });
        }
        let session = Arc::new(session);
        super::register(&(session.clone() as Arc<dyn Release>));
        if let Some(error) = hd.error() {
            return Err(failed("cannot start the servo loop", error));
        }
        if !session.servo.link.await_first_sample() {
            return Err(failed(
                "the servo loop ran no frame within a second of starting",
                (0x0402, 0),
            ));
        }
        Ok(Self {
            name: format!("OpenHaptics {model} ({name})"),
            session,
            limits,
            workspace_m,
        })
    }

    /// The HD library this machine would load, or why there is none (what to install).
    pub fn find_library() -> Result<PathBuf, DeviceError> {
        let path = LIBRARY.path();
        Hd::load(&path).map(|_| path)
    }

    /// What the haptic loop and the servo share (for its figures: samples, expired frames).
    pub fn link(&self) -> &Arc<ServoLink> {
        &self.session.servo.link
    }
}

/// The device's model, as the library names it.
fn model_name(hd: &Hd) -> String {
    // SAFETY: a model string is static in the library, or null.
    let model = unsafe { (hd.get_string)(HD_DEVICE_MODEL_TYPE) };
    match model.is_null() {
        true => "Geomagic device".to_owned(),
        // SAFETY: non-null strings from `hdGetString` are NUL-terminated.
        false => unsafe { std::ffi::CStr::from_ptr(model) }
            .to_string_lossy()
            .into_owned(),
    }
}

/// The device's own limits: its nominal peak and continuous forces.
fn device_limits(hd: &Hd) -> DeviceLimits {
    let [peak]: [f64; 1] = hd.doubles(HD_NOMINAL_MAX_FORCE);
    let [continuous]: [f64; 1] = hd.doubles(HD_NOMINAL_MAX_CONTINUOUS_FORCE);
    // A value the device does not give (zero, negative, not a number) is the Touch's.
    let touch = DeviceLimits::touch();
    let given = |f: f64, otherwise: f64| {
        if f.is_finite() && f > 0.0 {
            f
        } else {
            otherwise
        }
    };
    let peak_force_n = given(peak, touch.peak_force_n);
    DeviceLimits {
        peak_force_n,
        continuous_force_n: given(continuous, touch.continuous_force_n).min(peak_force_n),
        thermal_window_s: touch.thermal_window_s,
    }
}

impl HapticDevice for OpenHaptics {
    fn name(&self) -> &str {
        &self.name
    }

    fn limits(&self) -> DeviceLimits {
        self.limits
    }

    fn read(&mut self, _time_s: f64) -> Result<DeviceSample, DeviceError> {
        let link = &self.session.servo.link;
        if let Some((code, internal)) = link.take_error() {
            return Err(DeviceError::Failed {
                device: self.name.clone(),
                message: format!(
                    "{} (HD error {code:#06x}, vendor code {internal})",
                    error_message(code)
                ),
            });
        }
        link.latest().ok_or_else(|| DeviceError::Failed {
            device: self.name.clone(),
            message: "the servo loop has not run yet".into(),
        })
    }

    fn render(&mut self, force: EdgeForce) -> Result<(), DeviceError> {
        self.session.servo.link.command(&force);
        Ok(())
    }
}
