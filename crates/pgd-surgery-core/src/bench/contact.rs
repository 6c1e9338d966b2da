//! The organ-contact stage benchmark: one pair's tick (the master's distance field probed by a
//! pointshell, the force solve, the loads on both organs) with the organs apart and with the
//! master pressed into the shell organ until at least 400 nodes push, against the brute-force
//! check of every pointshell node against the exact deformed master surface (parry3d), timed
//! in the same run.
//!
//! Pressed free, the master (the floppy gallbladder) swings out of the shell organ and few
//! nodes push. The `held` case presses a rigid copy of the master (its modes zeroed: held
//! still, as by an instrument), so that the shell organ alone gives way and as many nodes push
//! as its pointshell allows. Held still, a press settles and the forces stop changing; the
//! `sliding` case then moves the held master sideways, so that every tick's contact changes.

use std::fmt;
use std::sync::Arc;
use std::time::{Duration, Instant};

use nalgebra::{Point3, Vector3};
use parry3d::query::PointQuery;
use serde::Serialize;

use crate::contact::{
    ContactPair, ContactSurface, Coupling, CouplingSettings, DistanceField, OrganPose, PairOutput,
    PairReport, PairSide, Pointshell, ToolHold,
};
use crate::parry_interop::{to_parry, trimesh};
use crate::pgd::{PointLoad, RigidCarry, Vademecum};

/// Nodes in contact the pressed case asks for (the target's figure, `docs/physics.md`).
const PRESSED_NODES: usize = 400;

/// The most ticks a press is given to settle before its nodes in contact are counted or
/// timed, so that the depth search and the timed run see the same contact (fine pointshells
/// under a soft penalty first push with hundreds of nodes, then settle on far fewer, over
/// some hundreds of ticks).
const SETTLE_TICKS: usize = 1000;

/// Ticks in a row whose force solve took no product: the press has settled.
const SETTLED_TICKS: usize = 20;

/// How fast the `sliding` case moves the master sideways (m per tick: 10 mm/s at 1 kHz, a
/// slow sweep of an instrument), and how far to either side of where it settled.
const SLIDE_M_PER_TICK: f64 = 10e-6;
const SLIDE_REACH_M: f64 = 2e-3;

/// A scene's organ: its name and vademecum.
pub type Organ = (String, Arc<Vademecum>);

#[derive(Clone, Debug, Serialize)]
pub struct StageFigures {
    pub case: &'static str,
    /// How far the master is carried into the shell organ (m).
    pub pressed_m: f64,
    /// Nodes pushing, and nodes measured, median per tick.
    pub nodes_in_contact: usize,
    pub nodes_evaluated: usize,
    /// Products with the normal compliance the force solve took, median per tick.
    pub solve_products: usize,
    /// The contact stage per tick (µs).
    pub stage_p50_us: f64,
    pub stage_p99_us: f64,
    /// Every pointshell node against the exact deformed master surface: the surface's BVH
    /// rebuilt, then one closest-point query per node (µs per tick).
    pub brute_force_p50_us: f64,
    /// `brute_force_p50_us / stage_p50_us`.
    pub speedup: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct ContactBenchReport {
    pub master: String,
    pub shell: String,
    pub pointshell_nodes: usize,
    pub lattice_nodes: usize,
    pub ticks: usize,
    pub cases: Vec<StageFigures>,
    /// How many cases were asked for: fewer figures means a press never pushed.
    #[serde(skip)]
    cases_asked: usize,
}

/// The cases the benchmark can time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Case {
    /// The organs apart: culling alone.
    Apart,
    /// The master, free to deform, carried into the shell organ.
    Pressed,
    /// A rigid copy of the master carried in: the shell organ alone gives way.
    Held,
    /// The held master, once settled, slid sideways back and forth at 10 mm/s.
    Sliding,
}

impl Case {
    fn name(self) -> &'static str {
        match self {
            Case::Apart => "apart",
            Case::Pressed => "pressed",
            Case::Held => "held",
            Case::Sliding => "sliding",
        }
    }
}

/// Times the coupling's master against its largest pointshell over `ticks` ticks per case in
/// `cases` (every case where none is named); `organs` are the scene's, in the coupling's
/// order, and `settings` those the coupling was set up with.
pub fn run(
    organs: &[Organ],
    coupling: &Coupling,
    settings: &CouplingSettings,
    ticks: usize,
    cases: &[Case],
) -> Result<ContactBenchReport, String> {
    let (pair, master, shell) = largest_pair(organs, coupling)?;
    let cases = match cases {
        [] => &[Case::Apart, Case::Pressed, Case::Held, Case::Sliding],
        named => named,
    };
    let apart = cases
        .contains(&Case::Apart)
        .then(|| time_case(Case::Apart, pair, master, shell, 0.0, ticks));
    let pressed = cases
        .contains(&Case::Pressed)
        .then(|| press_depth(pair, master, shell))
        .flatten()
        .map(|depth| time_case(Case::Pressed, pair, master, shell, depth, ticks));
    let mut held_cases = vec![];
    if cases
        .iter()
        .any(|c| matches!(c, Case::Held | Case::Sliding))
    {
        let (held_pair, held_master) = held(pair, master, shell, settings)?;
        if let Some(depth) = press_depth(&held_pair, &held_master, shell) {
            for &case in cases
                .iter()
                .filter(|c| matches!(c, Case::Held | Case::Sliding))
            {
                held_cases.push(time_case(
                    case,
                    &held_pair,
                    &held_master,
                    shell,
                    depth,
                    ticks,
                ));
            }
        }
    }
    Ok(ContactBenchReport {
        master: master.0.clone(),
        shell: shell.0.clone(),
        pointshell_nodes: pair.pointshell().len(),
        lattice_nodes: pair.field().node_count(),
        ticks,
        cases: apart.into_iter().chain(pressed).chain(held_cases).collect(),
        cases_asked: cases.len(),
    })
}

/// The coupling's pair with the largest pointshell, its master and its shell organ.
fn largest_pair<'a>(
    organs: &'a [Organ],
    coupling: &'a Coupling,
) -> Result<(&'a ContactPair, &'a Organ, &'a Organ), String> {
    let pair = coupling
        .pairs
        .iter()
        .max_by_key(|p| p.pointshell().len())
        .ok_or("the scene's master meets no other organ")?;
    Ok((pair, &organs[pair.master], &organs[pair.shell]))
}

/// The pair of [`run`] with its master, free to deform, carried `depth_m` into the shell
/// organ: the pair's report of each of `ticks` ticks (the contact tests check that a deep
/// press settles).
pub fn free_press(
    organs: &[Organ],
    coupling: &Coupling,
    depth_m: f64,
    ticks: usize,
) -> Result<Vec<PairReport>, String> {
    let (pair, master, shell) = largest_pair(organs, coupling)?;
    let mut run = Run::new(pair, master, shell, carry_into(pair, depth_m));
    Ok((0..ticks)
        .map(|_| {
            run.tick();
            *run.pair.report()
        })
        .collect())
}

/// The pair again with a rigid copy of the master: its modes zeroed, so that neither its field
/// nor its part of the compliance moves.
fn held(
    pair: &ContactPair,
    master: &Organ,
    shell: &Organ,
    settings: &CouplingSettings,
) -> Result<(ContactPair, Organ), String> {
    let mut rigid = (*master.1).clone();
    for step in &mut rigid.steps {
        step.spatial.fill(0.0);
        step.local.correction.fill(0.0);
    }
    let surface = ContactSurface::new(&rigid).map_err(|e| e.to_string())?;
    let field = DistanceField::build(&rigid, &surface, &settings.distance);
    let nodes = Pointshell::new(&shell.1, &rigid, &surface, &field, settings.pointshell);
    let rigid = Arc::new(rigid);
    let pair = ContactPair::new(
        PairSide {
            organ: pair.master,
            vademecum: rigid.clone(),
        },
        PairSide {
            organ: pair.shell,
            vademecum: shell.1.clone(),
        },
        Arc::new(field),
        nodes,
        &settings.penalty,
    );
    Ok((pair, (master.0.clone(), rigid)))
}

/// The master carried `depth_m` into the shell organ, along the mean direction from it to the
/// pointshell's nodes.
fn carry_into(pair: &ContactPair, depth_m: f64) -> RigidCarry {
    let normals = &pair.pointshell().rest_normal;
    let direction = normals.iter().sum::<Vector3<f64>>().normalize();
    RigidCarry {
        translation_m: direction * depth_m,
        ..RigidCarry::default()
    }
}

/// The smallest depth (1 mm steps, up to 30 mm) at which at least 400 nodes push, or, where
/// the pointshell never gets there, the depth with the most nodes pushing; `None` when none
/// ever does.
fn press_depth(pair: &ContactPair, master: &Organ, shell: &Organ) -> Option<f64> {
    let mut most = (0, None);
    for depth in (1..=30).map(|mm| mm as f64 * 1e-3) {
        let mut run = Run::new(pair, master, shell, carry_into(pair, depth));
        run.settle();
        let in_contact = run.pair.report().nodes_in_contact;
        if in_contact >= PRESSED_NODES {
            return Some(depth);
        }
        if in_contact > most.0 {
            most = (in_contact, Some(depth));
        }
    }
    most.1
}

/// A pair ticking on its own, the contact's coefficients fed back as each organ's only ones.
struct Run {
    pair: ContactPair,
    carry: RigidCarry,
    still: RigidCarry,
    coefficients: [Vec<f64>; 2],
    alpha: [Vec<f32>; 2],
    /// The contact's point loads, master then shell (unused: the field is not formed).
    points: [Vec<PointLoad>; 2],
}

impl Run {
    fn new(pair: &ContactPair, master: &Organ, shell: &Organ, carry: RigidCarry) -> Self {
        let modes = [master.1.total_modes(), shell.1.total_modes()];
        Self {
            pair: pair.clone(),
            carry,
            still: RigidCarry::default(),
            coefficients: modes.map(|m| vec![0.0; m]),
            alpha: modes.map(|m| vec![0.0; m]),
            points: [Vec::new(), Vec::new()],
        }
    }

    /// Ticks until [`SETTLED_TICKS`] in a row take no product, or [`SETTLE_TICKS`] in all.
    fn settle(&mut self) {
        let mut still = 0;
        for _ in 0..SETTLE_TICKS {
            self.tick();
            still = match self.pair.report().products {
                0 => still + 1,
                _ => 0,
            };
            if still == SETTLED_TICKS {
                return;
            }
        }
    }

    fn tick(&mut self) {
        for (alpha, c) in self.alpha.iter_mut().zip(&self.coefficients) {
            alpha.iter_mut().zip(c).for_each(|(a, &c)| *a = c as f32);
        }
        let [master_c, shell_c] = &mut self.coefficients;
        master_c.fill(0.0);
        shell_c.fill(0.0);
        let (mut master_hold, mut shell_hold) = (ToolHold::default(), ToolHold::default());
        let [master_points, shell_points] = &mut self.points;
        master_points.clear();
        shell_points.clear();
        self.pair.tick(
            OrganPose {
                alpha: &self.alpha[0],
                carry: &self.carry,
            },
            OrganPose {
                alpha: &self.alpha[1],
                carry: &self.still,
            },
            None,
            PairOutput {
                master: master_c,
                shell: shell_c,
                master_points,
                shell_points,
                master_hold: &mut master_hold,
                shell_hold: &mut shell_hold,
            },
        );
    }
}

/// Settles the master carried `depth_m` into the shell organ, then times `ticks` ticks of
/// `case` (the master still, or sliding).
fn time_case(
    case: Case,
    pair: &ContactPair,
    master: &Organ,
    shell: &Organ,
    depth_m: f64,
    ticks: usize,
) -> StageFigures {
    let mut run = Run::new(pair, master, shell, carry_into(pair, depth_m));
    run.settle();
    let (settled, sideways) = (run.carry.translation_m, sideways(&run.carry.translation_m));
    let mut products = Vec::with_capacity(ticks);
    let mut in_contact = Vec::with_capacity(ticks);
    let mut evaluated = Vec::with_capacity(ticks);
    let mut times: Vec<Duration> = (0..ticks)
        .map(|tick| {
            if case == Case::Sliding {
                run.carry.translation_m = settled + sideways * slide_m(tick);
            }
            let start = Instant::now();
            run.tick();
            let elapsed = start.elapsed();
            products.push(run.pair.report().products);
            in_contact.push(run.pair.report().nodes_in_contact);
            evaluated.push(run.pair.report().nodes_evaluated);
            elapsed
        })
        .collect();
    times.sort();
    products.sort();
    in_contact.sort();
    evaluated.sort();
    let brute = brute_force_us(pair, &master.1, &run.carry, ticks.min(200));
    let p50 = micros(times[times.len() / 2]);
    StageFigures {
        case: case.name(),
        pressed_m: depth_m,
        nodes_in_contact: in_contact[in_contact.len() / 2],
        nodes_evaluated: evaluated[evaluated.len() / 2],
        solve_products: products[products.len() / 2],
        stage_p50_us: p50,
        stage_p99_us: micros(times[times.len() * 99 / 100]),
        brute_force_p50_us: brute,
        speedup: brute / p50,
    }
}

/// A unit direction square to `pressed`.
fn sideways(pressed: &Vector3<f64>) -> Vector3<f64> {
    let across = match pressed.x.abs() < 0.9 * pressed.norm() {
        true => Vector3::x(),
        false => Vector3::y(),
    };
    pressed
        .cross(&across)
        .try_normalize(1e-12)
        .unwrap_or(across)
}

/// How far the sliding master is to one side at `tick` (m): out to [`SLIDE_REACH_M`], back
/// through the start to the other side, and back, at [`SLIDE_M_PER_TICK`].
fn slide_m(tick: usize) -> f64 {
    let quarter = (SLIDE_REACH_M / SLIDE_M_PER_TICK).round() as usize;
    let phase = tick % (4 * quarter);
    let steps = match phase {
        p if p < quarter => p as f64,
        p if p < 3 * quarter => (2 * quarter) as f64 - p as f64,
        p => p as f64 - (4 * quarter) as f64,
    };
    steps * SLIDE_M_PER_TICK
}

/// The median over `ticks` of the brute-force check (µs).
fn brute_force_us(pair: &ContactPair, master: &Vademecum, carry: &RigidCarry, ticks: usize) -> f64 {
    let positions: Vec<[f32; 3]> = master
        .position_coords_m
        .iter()
        .map(|p| {
            let moved = Vector3::from(p.map(f64::from));
            let moved = moved + carry.at(&moved);
            [0, 1, 2].map(|c| moved[c] as f32)
        })
        .collect();
    let nodes = &pair.pointshell().rest_m;
    let mut times: Vec<Duration> = (0..ticks.max(1))
        .map(|_| {
            let start = Instant::now();
            let mesh = trimesh(&positions, &master.triangles).expect("the master's surface");
            let inside = nodes
                .iter()
                .filter(|p| {
                    let p = Point3::from(p.map(f64::from));
                    mesh.project_local_point(to_parry(&p), false).is_inside
                })
                .count();
            std::hint::black_box(inside);
            start.elapsed()
        })
        .collect();
    times.sort();
    micros(times[times.len() / 2])
}

fn micros(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

impl fmt::Display for ContactBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        writeln!(
            f,
            "Organ contact: {} (distance field, {} lattice nodes) against {} ({} pointshell nodes), {} ticks per case",
            self.master, self.lattice_nodes, self.shell, self.pointshell_nodes, self.ticks
        )?;
        writeln!(
            f,
            "{:<8} {:>8} {:>9} {:>9} {:>8} {:>10} {:>10} {:>12} {:>8}",
            "case",
            "depth mm",
            "in contact",
            "evaluated",
            "products",
            "p50 µs",
            "p99 µs",
            "parry p50 µs",
            "speedup"
        )?;
        for c in &self.cases {
            writeln!(
                f,
                "{:<8} {:>8.1} {:>9} {:>9} {:>8} {:>10.1} {:>10.1} {:>12.1} {:>7.1}×",
                c.case,
                c.pressed_m * 1e3,
                c.nodes_in_contact,
                c.nodes_evaluated,
                c.solve_products,
                c.stage_p50_us,
                c.stage_p99_us,
                c.brute_force_p50_us,
                c.speedup
            )?;
        }
        if self.cases.len() < self.cases_asked {
            writeln!(
                f,
                "(no depth up to 30 mm puts {PRESSED_NODES} nodes in contact)"
            )?;
        }
        Ok(())
    }
}
