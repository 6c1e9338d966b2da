//! On a NaN from the device, a device error or a streak of overruns the force fades to zero
//! within the stated ticks and the fault is logged; the clamp holds under a deep press.

use nalgebra::Vector3;
use pgd_surgery::app::haptic::{FaultLog, TickClock};
use pgd_surgery::devices::{
    DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice, PressMotion, SafetySettings,
    Scripted,
};

use crate::common::{haptic, press, run, scripted, tick_at};

/// A scripted device that goes wrong from `from_s` on.
pub struct Faulty {
    inner: Box<dyn HapticDevice>,
    from_s: f64,
    kind: Kind,
    /// The time of the last read: the write that follows belongs to the same tick.
    now_s: f64,
}

impl Faulty {
    pub fn new(inner: Box<dyn HapticDevice>, from_s: f64, kind: Kind) -> Self {
        Self {
            inner,
            from_s,
            kind,
            now_s: 0.0,
        }
    }
}

#[derive(Clone, Copy)]
pub enum Kind {
    NanPosition,
    ReadError,
    WriteError,
}

impl HapticDevice for Faulty {
    fn name(&self) -> &str {
        "faulty"
    }

    fn limits(&self) -> DeviceLimits {
        self.inner.limits()
    }

    fn read(&mut self, time_s: f64) -> Result<DeviceSample, DeviceError> {
        self.now_s = time_s;
        let sample = self.inner.read(time_s)?;
        match self.kind {
            _ if time_s < self.from_s => Ok(sample),
            Kind::NanPosition => Ok(DeviceSample::at(Vector3::new(f64::NAN, 0.0, 0.0))),
            Kind::ReadError => Err(DeviceError::Disconnected {
                device: "faulty".into(),
            }),
            Kind::WriteError => Ok(sample),
        }
    }

    fn render(&mut self, force: EdgeForce) -> Result<(), DeviceError> {
        self.inner.write_force(force.newtons())?;
        if matches!(self.kind, Kind::WriteError) && self.now_s >= self.from_s {
            return Err(DeviceError::Failed {
                device: "faulty".into(),
                message: "motor amplifier over temperature".into(),
            });
        }
        Ok(())
    }
}

/// Ticks from the fault to zero force, and whether it stays zero to the end of the run.
fn fade(kind: Kind) -> (usize, bool, Vec<(u64, String)>) {
    let motion = PressMotion::default();
    let from_s = motion.approach_s + motion.press_s + 0.2;
    let device = Box::new(Faulty::new(scripted(press(&motion)), from_s, kind));
    let mut haptic = haptic(device, SafetySettings::default());
    let trace = run(&mut haptic, tick_at(from_s + 0.1));
    let start = tick_at(from_s) as usize;
    assert!(
        trace.sent_n[start - 1].norm() > 0.1,
        "the tool should press before the fault"
    );
    let zero = trace.sent_n[start..]
        .iter()
        .position(|f| *f == Vector3::zeros())
        .expect("the force never reached zero");
    let stays = trace.sent_n[start + zero..]
        .iter()
        .all(|f| *f == Vector3::zeros());
    let log = haptic.hand::<FaultLog>(0).unwrap();
    let faults = log.log.iter().map(|(t, f)| (*t, f.to_string())).collect();
    (zero, stays, faults)
}

/// The stated fade: zero within `fade_ticks` (5) of the fault, counting the tick it shows.
#[test]
fn a_nan_from_the_device_fades_the_force_to_zero() {
    let (ticks, stays, faults) = fade(Kind::NanPosition);
    let fade_ticks = SafetySettings::default().fade_ticks as usize;
    assert!(ticks < fade_ticks, "faded in {} ticks", ticks + 1);
    assert!(stays, "the force came back while the device sends NaN");
    assert_eq!(faults.len(), 1, "{faults:?}");
    assert!(faults[0].1.contains("non-finite"), "{faults:?}");
}

#[test]
fn a_device_error_fades_the_force_to_zero() {
    for kind in [Kind::ReadError, Kind::WriteError] {
        let (ticks, stays, faults) = fade(kind);
        // A failed write is seen on the tick after it.
        assert!(
            ticks <= SafetySettings::default().fade_ticks as usize,
            "{ticks}"
        );
        assert!(stays);
        assert!(
            faults.iter().any(|(_, f)| f.contains("faulty")),
            "{faults:?}"
        );
    }
}

#[test]
fn a_streak_of_overruns_fades_the_force() {
    let motion = PressMotion::default();
    let mut haptic = haptic(scripted(press(&motion)), SafetySettings::default());
    let pressed = tick_at(motion.approach_s + motion.press_s);
    run(&mut haptic, pressed);
    for (k, overruns) in (0..10).zip([0, 1, 2, 3, 4, 5, 6, 7, 8, 9]) {
        let tick = pressed + k;
        haptic.tick(TickClock {
            tick,
            time_s: tick as f64 * 1e-3,
            overruns_in_a_row: overruns,
        });
    }
    let log = haptic.hand::<FaultLog>(0).unwrap();
    assert_eq!(log.log.len(), 1, "{:?}", log.log);
    assert_eq!(
        log.log[0].0,
        pressed + 3,
        "the third overrun in a row is the fault"
    );
    let force = haptic.hand::<pgd_surgery::app::haptic::DeviceForce>(0);
    let sent = force.unwrap().sent_n;
    assert_eq!(sent, Vector3::zeros());
}

/// With a device that renders at most 0.05 N, a press that asks for several times that is
/// clamped on every tick, and reaches the limit.
#[test]
fn the_clamp_holds() {
    let limit = DeviceLimits::peak_only(0.05);
    let motion = PressMotion::default();
    let device = Box::new(Scripted::new("weak device", press(&motion)).with_limits(limit));
    let mut haptic = haptic(device, SafetySettings::default());
    let trace = run(&mut haptic, tick_at(press(&motion).duration_s()));
    let asked = trace.desired_n.iter().map(|f| f.norm()).fold(0.0, f64::max);
    let sent = trace.sent_n.iter().map(|f| f.norm()).fold(0.0, f64::max);
    assert!(asked > 3.0 * limit.peak_force_n, "asked only {asked} N");
    assert!(sent <= limit.peak_force_n * (1.0 + 1e-12), "sent {sent} N");
    assert!(sent > 0.99 * limit.peak_force_n, "sent {sent} N");
}
