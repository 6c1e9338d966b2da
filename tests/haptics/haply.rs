//! The Haply backend against the fake Inverse Service (`haply_fake.rs`): our client's servo
//! thread exchanges with it over the loopback WebSocket as it would with Haply's service.

use std::time::{Duration, Instant};

use nalgebra::{UnitQuaternion, Vector3};
use pgd_surgery::app::haptic::{
    DeviceForce, FaultLog, HapticLoop, HapticThread, Scheduling, TickClock,
};
use pgd_surgery::devices::haply::{
    Condition, FULL_STATE_REQUEST, FrameKind, LOST_AFTER, REACH_CENTRE_M, ServiceView,
};
use pgd_surgery::devices::{Haply, HapticDevice, SafetySettings, TICK_S, TimerMode};
use tungstenite::Message;
use tungstenite::stream::MaybeTlsStream;

use crate::common::{TIP_RADIUS_M, scene, target};
use crate::fakes::pressing_tip_m;
use crate::haply_fake::{DEVICE_ID, FakeService};

fn open(fake: &FakeService) -> Haply {
    Haply::open(Some(&fake.url()), None).unwrap()
}

/// Where the fake's handle is for the tool at `scene_m`.
fn handle_at(scene_m: &Vector3<f64>) -> Vector3<f64> {
    scene_m + REACH_CENTRE_M
}

/// The fake as a client sees it on the wire: the snapshot first, with the devices' config;
/// exactly one frame for each message, `{}` included, without config; the snapshot again on
/// `force_render_full_state`; the position answering the force received.
#[test]
fn the_fake_speaks_as_the_service_is_documented() {
    let fake = FakeService::start("3.5.0");
    let (mut socket, _) = tungstenite::connect(fake.url()).unwrap();
    let mut view = ServiceView::default();
    let snapshot = socket.read().unwrap().into_text().unwrap();
    assert_eq!(view.merge(snapshot.as_str()), Ok(FrameKind::Snapshot));
    let mut exchange = |message: &str| {
        socket.send(Message::text(message)).unwrap();
        match socket.read().unwrap() {
            Message::Text(text) => view.merge(text.as_str()).unwrap(),
            other => panic!("{other:?}"),
        }
    };
    assert_eq!(exchange("{}"), FrameKind::Update);
    assert_eq!(exchange(FULL_STATE_REQUEST), FrameKind::Snapshot);
    let push = format!(
        r#"{{"inverse3":[{{"device_id":"{DEVICE_ID}","commands":{{"set_cursor_force":{{"vector":{{"x":0,"y":0,"z":1.0}}}}}}}}]}}"#
    );
    let (started, mut sent) = (Instant::now(), 2);
    while started.elapsed() < Duration::from_millis(300) {
        exchange(&push);
        sent += 1;
        std::thread::sleep(Duration::from_micros(500));
    }
    if let MaybeTlsStream::Plain(stream) = socket.get_ref() {
        stream
            .set_read_timeout(Some(Duration::from_millis(50)))
            .unwrap();
    }
    assert!(socket.read().is_err(), "a frame no message asked for");
    let state = fake.state();
    let counts = (
        state.messages,
        state.empty_messages,
        state.full_state_requests,
    );
    assert_eq!(counts, (sent, 1, 1));
    // 1 N on the 200 N/m hand: 5 mm up once settled.
    let lift_m = state.position_m.z - state.hand_m.z;
    assert!((lift_m - 0.005).abs() < 0.0005, "{lift_m}");
}

/// The handle 12 mm right and 5 mm up from the centre of reach is the tool there in the
/// scene; the grip's orientation (a quarter turn about z) and its button b (bit 1) come with
/// it; a force of (0.5, −0.2, 1) N reaches the service as it was sent (the axes are the
/// scene's), named `vector` for a 3.5 service, with the trainer's profile; the limit is the
/// product's 3.3 N default.
#[test]
fn the_servo_reads_the_handle_and_sends_the_force() {
    let fake = FakeService::start("3.5.0");
    fake.state()
        .place(handle_at(&Vector3::new(0.012, 0.0, 0.005)));
    fake.state().buttons = [false, true, false];
    let mut device = open(&fake);
    fake.wait_messages(3);
    let sample = device.read(0.0).unwrap();
    assert!(
        (sample.tip_m - Vector3::new(0.012, 0.0, 0.005)).norm() < 1e-12,
        "{sample:?}"
    );
    let quarter = UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2);
    assert!(sample.orientation.angle_to(&quarter) < 1e-9);
    assert_eq!(sample.buttons, 0b010);
    assert_eq!(device.limits().peak_force_n, 3.3);
    device.write_force(&Vector3::new(0.5, -0.2, 1.0)).unwrap();
    fake.wait_messages(3);
    let state = fake.state();
    assert_eq!(state.force_n, Vector3::new(0.5, -0.2, 1.0));
    assert_eq!(state.misnamed_forces, 0);
    assert_eq!(state.profile.as_deref(), Some("pgd-surgery trainer"));
    assert_eq!(device.condition(), Condition::Fine);
}

/// A 3.4 service is sent `values` (and `execute`), which it reads; never `vector`.
#[test]
fn an_older_service_is_sent_the_older_name() {
    let fake = FakeService::start("3.4.1");
    let mut device = open(&fake);
    device.write_force(&Vector3::new(0.0, 0.3, 0.0)).unwrap();
    fake.wait_messages(3);
    let state = fake.state();
    assert_eq!(
        (state.force_n, state.misnamed_forces),
        (Vector3::new(0.0, 0.3, 0.0), 0)
    );
}

/// Frames that leave out the status and the grip keep what the snapshot said of them: the
/// device stays ready, the orientation and buttons stay; the position goes on updating.
#[test]
fn partial_frames_are_merged_into_what_is_known() {
    let fake = FakeService::start("3.5.0");
    fake.state().buttons = [true, false, false];
    let mut device = open(&fake);
    fake.state().partial = true;
    fake.state().buttons = [false, false, false];
    fake.state().place(handle_at(&Vector3::new(0.0, 0.02, 0.0)));
    fake.wait_messages(5);
    let sample = device.read(0.0).unwrap();
    assert!(
        (sample.tip_m - Vector3::new(0.0, 0.02, 0.0)).norm() < 1e-12,
        "{sample:?}"
    );
    assert_eq!(sample.buttons, 0b001, "kept from the snapshot");
    assert!(sample.orientation.angle() > 1.0, "kept from the snapshot");
    assert_eq!(device.condition(), Condition::Fine);
}

/// Malformed replies are ignored, each counted; the device goes on with the last good state.
#[test]
fn malformed_frames_are_counted_and_ignored() {
    let fake = FakeService::start("3.5.0");
    let mut device = open(&fake);
    let before = device.read(0.0).unwrap();
    fake.state().malformed_replies = 5;
    fake.wait_for("the malformed replies sent", |s| s.malformed_replies == 0);
    fake.wait_messages(2);
    assert_eq!(device.malformed_frames(), 5);
    assert_eq!(device.read(0.0).unwrap().tip_m, before.tip_m);
    assert_eq!(device.condition(), Condition::Fine);
}

/// No service at the address: one message, naming the address and what to install and start;
/// the trainer exits non-zero with it and no panic. `trainer devices` lists Haply as unusable
/// with the same reason, and as usable, with the service's version, when the fake answers.
#[test]
fn a_missing_service_is_named_and_a_present_one_listed() {
    let free = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let nowhere = format!("ws://{}", free.local_addr().unwrap());
    drop(free);
    let error = Haply::open(Some(&nowhere), None).err().unwrap().to_string();
    assert!(
        error.contains(&nowhere) && error.contains("no service answers"),
        "{error}"
    );
    assert!(
        error.contains("systemctl start haply-inverse-service"),
        "{error}"
    );
    let trainer = env!("CARGO_BIN_EXE_trainer");
    let run = |url: &str, args: &[&str]| {
        std::process::Command::new(trainer)
            .args(args)
            .env("PGD_HAPLY_URL", url)
            .output()
            .unwrap()
    };
    let out = run(
        &nowhere,
        &[
            "--headless",
            "--realtime",
            "--ticks",
            "10",
            "--device",
            "haply",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("no service answers") && !stderr.contains("panicked"),
        "{stderr}"
    );
    let listed = |url: &str| {
        let out = run(url, &["devices"]);
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        stdout
            .lines()
            .find(|l| l.starts_with("haply"))
            .unwrap()
            .to_owned()
    };
    let absent = listed(&nowhere);
    assert!(
        absent.contains(" no ") && absent.contains("no service answers"),
        "{absent}"
    );
    let fake = FakeService::start("3.5.2");
    let present = listed(&fake.url());
    eprintln!("{absent}\n{present}");
    assert!(
        present.contains(" yes ") && present.contains("3.5.2"),
        "{present}"
    );
}

/// An Inverse3 asked for by an id the service does not list: refused, naming those it lists.
#[test]
fn a_device_id_not_listed_is_refused() {
    let fake = FakeService::start("3.5.0");
    let error = Haply::open(Some(&fake.url()), Some("FFFF"))
        .err()
        .unwrap()
        .to_string();
    assert!(
        error.contains("no Inverse3 `FFFF`") && error.contains(DEVICE_ID),
        "{error}"
    );
    assert!(Haply::open(Some(&fake.url()), Some(DEVICE_ID)).is_ok());
}

/// Closing sends a zero force last and closes the WebSocket.
#[test]
fn closing_leaves_zero_force_and_closes_the_session() {
    let fake = FakeService::start("3.5.0");
    let mut device = open(&fake);
    device.write_force(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
    fake.wait_for("the force", |s| s.force_n.z == 1.0);
    drop(device);
    let state = fake.state();
    assert_eq!(state.log.last().unwrap().1, Vector3::zeros());
    assert_eq!(state.closes_received, 1);
}

/// The edge guard: a NaN is sent as zero, 100 N as the 3.3 N peak, each refused.
#[test]
fn the_last_guard_keeps_nan_and_excess_from_the_service() {
    let fake = FakeService::start("3.5.0");
    let mut device = open(&fake);
    assert!(
        device
            .write_force(&Vector3::new(f64::NAN, 0.0, 1.0))
            .is_err()
    );
    fake.wait_messages(3);
    assert_eq!(fake.state().force_n, Vector3::zeros());
    assert!(device.write_force(&Vector3::new(0.0, 0.0, 100.0)).is_err());
    fake.wait_messages(3);
    assert!((fake.state().force_n.norm() - 3.3).abs() < 1e-12);
    let largest = fake
        .state()
        .log
        .iter()
        .map(|(_, f)| f.norm())
        .fold(0.0, f64::max);
    assert!(largest <= 3.3 * (1.0 + 1e-12), "{largest}");
}

/// What a run of the haptic loop over the fake sent, tick by tick, and its faults.
struct Run {
    sent: Vec<Vector3<f64>>,
    faults: Vec<(u64, String)>,
}

impl Run {
    /// The force along the liver's outward normal at each tick.
    fn pushing(&self) -> Vec<f64> {
        let n = target().normal;
        self.sent.iter().map(|f| f.dot(&n)).collect()
    }

    /// The first tick with a fault saying `says`.
    fn first_fault(&self, says: &str) -> u64 {
        let found = self.faults.iter().find(|(_, f)| f.contains(says));
        found
            .unwrap_or_else(|| panic!("no fault says `{says}`: {:?}", self.faults))
            .0
    }
}

/// The haptic loop over a Haply device pressing the liver 4 mm deep, ticked about every
/// millisecond for `ticks`, `fault` done at tick 400 and `mend` at `mend_at`.
fn press_through_fault(
    fake: &FakeService,
    ticks: u64,
    fault: impl FnOnce(),
    mend_at: u64,
    mend: impl FnOnce(),
) -> Run {
    fake.state().place(handle_at(&pressing_tip_m()));
    let device = Box::new(open(fake));
    let mut haptic = HapticLoop::new(&scene(SafetySettings::default()), device).unwrap();
    let (mut fault, mut mend) = (Some(fault), Some(mend));
    let mut sent = Vec::new();
    for n in 0..ticks {
        if n == 400 {
            fault.take().unwrap()();
        }
        if n == mend_at {
            mend.take().unwrap()();
        }
        haptic.tick(TickClock {
            tick: n,
            time_s: n as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
        sent.push(haptic.hand::<DeviceForce>(0).unwrap().sent_n);
        std::thread::sleep(Duration::from_micros(900));
    }
    let faults = haptic.hand::<FaultLog>(0).unwrap().log.iter();
    Run {
        faults: faults.map(|(t, f)| (*t, f.to_string())).collect(),
        sent,
    }
}

/// The force pushed back before the fault; it was zero within the filter's fade from the
/// first tick the fault was reported, stayed zero while it lasted, and came back after it
/// ramped by the filter's rate limit to what it was.
fn assert_faded_and_recovered(run: &Run, says: &str, mended_by: u64) {
    let push = run.pushing();
    let settings = SafetySettings::default();
    let before = push[399];
    assert!(before > 0.05, "{before}");
    let faulted = run.first_fault(says) as usize;
    assert!(faulted >= 400, "{:?}", run.faults);
    let faded = faulted + settings.fade_ticks as usize;
    assert!(
        push[faded..mended_by as usize].iter().all(|f| *f == 0.0),
        "{:?}",
        &push[faded..faded + 20]
    );
    let last = *push.last().unwrap();
    assert!(
        (last - before).abs() < 0.1 * before,
        "back to {last} N of {before} N"
    );
    let steps = run.sent.windows(2).map(|w| (w[1] - w[0]).norm());
    let largest = steps.skip(faded).fold(0.0, f64::max);
    assert!(
        largest <= settings.max_change_n_per_tick * (1.0 + 1e-9),
        "a {largest} N step"
    );
    eprintln!(
        "pressing {before:.3} N; fault at tick {faulted} ({says}); back to {last:.3} N; faults {:?}",
        &run.faults[..run.faults.len().min(3)]
    );
}

/// The service closes the connection mid-press: the force fades, the loss is reported, the
/// servo connects again and the force ramps back.
#[test]
fn a_dropped_connection_fades_reconnects_and_ramps_back() {
    let fake = FakeService::start("3.5.0");
    let run = press_through_fault(&fake, 1300, || fake.state().close_now = true, 400, || {});
    assert_eq!(fake.state().connections, 2);
    assert_faded_and_recovered(&run, "connection", 420);
}

/// The service stalls (each reply 60 ms late) for 300 ms: late replies are a fault, the force
/// fades and stays at zero; once it answers promptly again the force ramps back.
#[test]
fn a_stalled_service_fades_the_force_until_it_answers() {
    let fake = FakeService::start("3.5.0");
    let run = press_through_fault(
        &fake,
        1300,
        || fake.state().delay = Duration::from_millis(60),
        700,
        || fake.state().delay = Duration::ZERO,
    );
    assert_faded_and_recovered(&run, "has not answered", 700);
    assert_eq!(fake.state().connections, 1);
}

/// A stall longer than the servo waits: it gives the connection up and makes a new one.
#[test]
fn a_service_silent_too_long_is_reconnected() {
    let fake = FakeService::start("3.5.0");
    let _device = open(&fake);
    fake.state().delay = LOST_AFTER + Duration::from_millis(300);
    fake.wait_messages(1);
    std::thread::sleep(Duration::from_millis(50));
    fake.state().delay = Duration::ZERO;
    fake.wait_for("a second connection", |s| s.connections == 2);
}

/// The device loses its calibration mid-press: said, the force fades, zero is sent to the
/// service; calibrated again, the force ramps back.
#[test]
fn a_device_not_calibrated_gets_no_force() {
    let fake = FakeService::start("3.5.0");
    let run = press_through_fault(
        &fake,
        1200,
        || fake.state().calibrated = false,
        600,
        || fake.state().calibrated = true,
    );
    assert_faded_and_recovered(&run, "not calibrated", 600);
    assert_eq!(
        fake.state().forces_while_unready,
        0,
        "force sent while not calibrated"
    );
}

/// The round trip through the real schedule: the haptic loop on its 1 kHz thread, our servo
/// on its own, the fake service on the loopback. The handle steps from 5 mm above the liver
/// to 4 mm into it, 40 times; each time, the time until the fake receives a force is the
/// latency from a position to the force. Printed as p50 and p99 with the exchange rate; the
/// test holds only that every step is answered, within a liveness bound of 200 ms.
#[test]
fn the_force_answers_the_handle_through_the_real_schedule() {
    let fake = FakeService::start("3.5.0");
    let target = target();
    let handle =
        |depth_m: f64| handle_at(&(target.point_m + target.normal * (TIP_RADIUS_M - depth_m)));
    fake.state().place(handle(-0.005));
    let device = Box::new(open(&fake));
    let haptic = HapticLoop::new(&scene(SafetySettings::default()), device).unwrap();
    let thread = HapticThread::spawn(haptic, TimerMode::default(), Scheduling::RealTime).unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let (started, messages_before) = (Instant::now(), fake.state().messages);
    let mut latencies_ms = Vec::new();
    for _ in 0..40 {
        fake.state().place(handle(-0.005));
        fake.wait_for("zero force above the liver", |s| {
            s.force_n == Vector3::zeros()
        });
        std::thread::sleep(Duration::from_millis(20));
        let stepped = Instant::now();
        fake.state().place(handle(0.004));
        while fake.state().force_n == Vector3::zeros()
            && stepped.elapsed() < Duration::from_millis(200)
        {
            std::thread::sleep(Duration::from_micros(50));
        }
        latencies_ms.push(stepped.elapsed().as_secs_f64() * 1e3);
    }
    let rate_hz =
        (fake.state().messages - messages_before) as f64 / started.elapsed().as_secs_f64();
    let (report, haptic) = thread.stop();
    latencies_ms.sort_by(f64::total_cmp);
    let quantile = |q: f64| latencies_ms[((latencies_ms.len() - 1) as f64 * q).round() as usize];
    eprintln!(
        "handle to force: p50 {:.2} ms, p99 {:.2} ms, largest {:.2} ms over {} steps; \
         {rate_hz:.0} exchanges/s; tick compute p99 {:.0} µs",
        quantile(0.5),
        quantile(0.99),
        latencies_ms.last().unwrap(),
        latencies_ms.len(),
        report.compute.p99_us
    );
    let faults: Vec<String> = (haptic.hand::<FaultLog>(0).unwrap().log.iter())
        .map(|(tick, fault)| format!("tick {tick}: {fault}"))
        .collect();
    assert!(
        latencies_ms.iter().all(|&l| l < 200.0),
        "{latencies_ms:?}\nfaults: {faults:?}"
    );
}
