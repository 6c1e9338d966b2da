//! Blunt dissection: a grasper's pull carried by the freed organ's wall to the ties near its
//! jaws, which it tears.
//!
//! The organs are solids of their bulk's stiffness: the gallbladder's 1.15 kPa is what it
//! gives under a pressing tool. Its wall is far stiffer in tension (porcine gallbladder wall:
//! 9.03 MPa in uniaxial tension; `docs/dissection.md`): over the wall's reach of 15 mm, a
//! strip of 2 mm wall is 16 times stiffer in tension (`E h / ℓ`) than the ties under it
//! (`K ℓ`) at the bed's law. The bulk alone cannot carry a
//! pull to the bed: a full FEM solve of the coarse gallbladder tied in its bed, drawn 30 mm by
//! a point 12 mm from the nearest tie, pulls back 0.075 N and opens that tie by 0.26 mm, where
//! it tears at 20 mm.
//!
//! So the wall is taken as inextensible and slack in compression: when the jaws close on the
//! freed organ, each live tie whose end on it lies within [`WALL_REACH_M`] of the jaws hangs
//! from them by a strand of wall as long as it is from the jaws to the tie's end on the base.
//! Drawing the jaws further than that opens the tie by the difference, along the strand; the
//! tie carries its law's traction there, tears past its failure separation, and pulls the jaws
//! back along the strand. Nearer ties go taut first and tear first: the plane opens from the
//! jaws outwards, as a peel. Within a tick the strands are springs of the ties' secant
//! stiffness along their directions as the last tick left them ([`Tether`]), so that the
//! grasp solves them with its coupling and the hand feels them at once. The ties the wall
//! holds are left out of the organs' fields' solve while it holds them: the wall carries them.

use nalgebra::{Matrix3, Vector3};

use super::bed::{Bed, TieEnds};
use crate::dynamics::Tether;

/// How far from the jaws (m) the wall carries their pull to the bed: the jaws' own length
/// (10–15 mm for a laparoscopic grasper); beyond it the pull spreads into the bulk. An
/// assumption: a surgeon dissecting bluntly grasps within a jaw's length of the plane.
pub const WALL_REACH_M: f64 = 0.015;

/// A tie hanging from the jaws by a strand of wall.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Strand {
    tie: usize,
    length_m: f64,
    /// How far the strand has drawn the tie's end from its end on the base (m).
    opened_m: Vector3<f64>,
}

/// What the wall did in one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallPullReport {
    /// Ties hanging from the jaws.
    pub strands: usize,
    /// Of those, the ties drawn taut.
    pub taut: usize,
    /// Ties torn in this tick.
    pub torn: usize,
    /// The strands' pull on the jaws (N).
    pub force_on_jaws_n: Vector3<f64>,
}

/// The strands of wall from the jaws to the ties near them, while the jaws hold the freed
/// organ. Nothing is allocated once set up.
#[derive(Clone, Debug)]
pub struct WallPull {
    strands: Vec<Strand>,
    /// Where the jaws were in the last tick (m): the strands' directions.
    jaws_m: Vector3<f64>,
    /// Per tie, whether the wall carries it.
    carried: Vec<bool>,
}

impl WallPull {
    /// Room for every tie of a bed of `ties`.
    pub fn with_room(ties: usize) -> Self {
        Self {
            strands: Vec::with_capacity(ties),
            jaws_m: Vector3::zeros(),
            carried: vec![false; ties],
        }
    }

    /// The jaws close at `jaws_m` on the freed organ: every live tie of `bed` whose end on
    /// it (`ends`, as the last tick left them) lies within `reach_m` hangs from them by a
    /// strand as long as from the jaws to its end on the base.
    pub fn grip(&mut self, bed: &Bed, ends: &[TieEnds], jaws_m: &Vector3<f64>, reach_m: f64) {
        self.let_go();
        self.jaws_m = *jaws_m;
        for (tie, (t, end)) in bed.ties.iter().zip(ends).enumerate() {
            if t.state.failed(&bed.law) || (end.freed_m - jaws_m).norm() > reach_m {
                continue;
            }
            self.strands.push(Strand {
                tie,
                length_m: (jaws_m - end.base_m).norm(),
                opened_m: Vector3::zeros(),
            });
            self.carried[tie] = true;
        }
    }

    /// The jaws let go: the ties go back to the organs' fields. Called every tick the jaws
    /// hold nothing, so it costs nothing then (a tie is carried only while a strand holds it).
    pub fn let_go(&mut self) {
        if self.strands.is_empty() {
            return;
        }
        self.strands.clear();
        self.carried.fill(false);
    }

    /// Per tie of the bed, whether the wall carries it.
    pub fn carried(&self) -> &[bool] {
        &self.carried
    }

    /// The taut strands as springs on the jaws for the next tick: each its tie's secant
    /// stiffness times its area along its direction from the tie's end on the base (`ends`),
    /// from the point where it is just taut. None when no strand is taut.
    pub fn tether(&self, bed: &Bed, ends: &[TieEnds]) -> Option<Tether> {
        let mut tether = Tether {
            stiffness_n_per_m: Matrix3::zeros(),
            force_at_origin_n: Vector3::zeros(),
        };
        let mut taut = false;
        for strand in &self.strands {
            let base = ends[strand.tie].base_m;
            let reach = self.jaws_m - base;
            let span = reach.norm();
            if span <= strand.length_m {
                continue;
            }
            let tie = &bed.ties[strand.tie];
            let k = tie.state.secant_pa_per_m(&bed.law) * tie.area_m2;
            let along = reach / span;
            let spring = along * along.transpose() * k;
            tether.stiffness_n_per_m += spring;
            tether.force_at_origin_n += spring * (base + along * strand.length_m);
            taut = true;
        }
        taut.then_some(tether)
    }

    /// The jaws are at `jaws_m` after the tick: each strand opens its tie by how far they
    /// draw it past its length, the tie's damage grows with that, and a tie torn (or divided
    /// meanwhile) drops from the jaws.
    pub fn pull(
        &mut self,
        bed: &mut Bed,
        ends: &[TieEnds],
        jaws_m: &Vector3<f64>,
    ) -> WallPullReport {
        self.jaws_m = *jaws_m;
        let law = bed.law;
        let mut report = WallPullReport::default();
        for strand in &mut self.strands {
            let reach = jaws_m - ends[strand.tie].base_m;
            let span = reach.norm();
            let opening = (span - strand.length_m).max(0.0);
            let along = reach / span.max(f64::MIN_POSITIVE);
            let tie = &mut bed.ties[strand.tie];
            let whole = !tie.state.failed(&law);
            let traction_pa = tie.state.open(&law, opening);
            strand.opened_m = along * opening;
            report.force_on_jaws_n -= along * (traction_pa * tie.area_m2);
            report.taut += usize::from(opening > 0.0);
            report.torn += usize::from(whole && tie.state.failed(&law));
        }
        let carried = &mut self.carried;
        self.strands.retain(|strand| {
            let holds = !bed.ties[strand.tie].state.failed(&law);
            carried[strand.tie] = holds;
            holds
        });
        report.strands = self.strands.len();
        report
    }

    /// Draws each taut strand's tie from its end on the base towards the jaws: where the
    /// wall holds it.
    pub fn draw_open(&self, ends: &mut [TieEnds]) {
        for strand in self
            .strands
            .iter()
            .filter(|s| s.opened_m != Vector3::zeros())
        {
            let end = &mut ends[strand.tie];
            end.freed_m = end.base_m + strand.opened_m;
        }
    }
}

#[cfg(test)]
mod tests {

    use super::*;
    use crate::dissection::CohesiveLaw;
    use crate::dissection::bed::tie_over_plane;

    /// Ties of 1 cm² on the plane z = 0 at `xs` (m) along x, their ends on the base there.
    fn bed_along(xs: &[f64]) -> (Bed, Vec<TieEnds>) {
        let bed = Bed {
            law: CohesiveLaw::gallbladder_bed(),
            ties: (0..xs.len()).map(|p| tie_over_plane(p, 1e-4)).collect(),
        };
        let ends = (xs.iter())
            .map(|&x| TieEnds {
                freed_m: Vector3::new(x, 0.0, 0.001),
                base_m: Vector3::new(x, 0.0, 0.0),
            })
            .collect();
        (bed, ends)
    }

    /// One tie drawn straight away from the jaws in steps of 0.01 mm until it tears: the
    /// strand pulls the jaws back with the law's traction times the tie's area at every step
    /// (to 1e-12), the tie tears on the step its opening passes the failure separation, and
    /// the work the jaws did against it (trapezoid rule) is the fracture energy of its area,
    /// to 1e-4.
    #[test]
    fn a_strand_pulls_with_the_law_and_tears_its_tie_at_its_fracture_energy() {
        let (mut bed, ends) = bed_along(&[0.0]);
        let law = bed.law;
        let start = Vector3::new(-0.01, 0.0, 0.0);
        let mut wall = WallPull::with_room(1);
        wall.grip(&bed, &ends, &start, WALL_REACH_M);
        let step = 1e-5;
        let (mut work, mut last) = (0.0, 0.0);
        let mut torn_at = None;
        for i in 1..=3000 {
            let jaws = start - Vector3::x() * (step * i as f64);
            let opening = step * i as f64;
            let report = wall.pull(&mut bed, &ends, &jaws);
            let expected = law.stiffness_pa_per_m * (1.0 - law.damage(opening)) * opening * 1e-4;
            let pull = report.force_on_jaws_n.x;
            work += 0.5 * (pull + last) * step;
            last = pull;
            if torn_at.is_none() {
                assert!(
                    (pull - expected).abs() <= 1e-12,
                    "{pull} against {expected}"
                );
            }
            if report.torn == 1 {
                torn_at = Some(opening);
            }
        }
        let torn_at = torn_at.expect("the tie tore");
        let failure = law.failure_separation_m();
        let energy = law.fracture_energy_j_per_m2 * 1e-4;
        let error = (work - energy).abs() / energy;
        eprintln!(
            "torn at {:.3} mm; work {work:.4e} J against {energy:.4e} J",
            torn_at * 1e3
        );
        assert!(torn_at >= failure && torn_at < failure + step);
        assert!(error < 1e-4, "{error}");
        assert!(wall.carried().iter().all(|c| !c));
    }

    /// Ties 2, 6 and 12 mm from the jaws along the bed, the jaws drawn straight up from it:
    /// the nearest goes taut and tears first, then the next; one beyond the wall's reach
    /// (20 mm) and one already torn hang from nothing.
    #[test]
    fn the_plane_opens_from_the_jaws_outwards() {
        let (mut bed, ends) = bed_along(&[0.002, 0.006, 0.012, 0.020, 0.004]);
        bed.ties[4].state.sever(&bed.law);
        let mut wall = WallPull::with_room(5);
        wall.grip(&bed, &ends, &Vector3::zeros(), WALL_REACH_M);
        assert_eq!(wall.carried(), &[true, true, true, false, false]);
        let mut order = Vec::new();
        for i in 1..=6000 {
            let jaws = Vector3::z() * (1e-5 * i as f64);
            wall.pull(&mut bed, &ends, &jaws);
            for (tie, t) in bed.ties.iter().enumerate().take(3) {
                if t.state.failed(&bed.law) && !order.contains(&tie) {
                    order.push(tie);
                }
            }
        }
        assert_eq!(order, [0, 1, 2]);
    }

    /// Jaws that let go before their ties tear hand them back to the fields with the damage
    /// they took, and pull on nothing more.
    #[test]
    fn ties_let_go_keep_their_damage() {
        let (mut bed, ends) = bed_along(&[0.002]);
        let mut wall = WallPull::with_room(1);
        wall.grip(&bed, &ends, &Vector3::zeros(), WALL_REACH_M);
        wall.pull(&mut bed, &ends, &Vector3::new(0.0, 0.0, 0.01));
        let damage = bed.ties[0].state.damage(&bed.law);
        assert!(damage > 0.0 && damage < 1.0, "{damage}");
        wall.let_go();
        assert_eq!(wall.carried(), &[false]);
        assert!(wall.tether(&bed, &ends).is_none());
        let report = wall.pull(&mut bed, &ends, &Vector3::new(0.0, 0.0, 0.02));
        assert_eq!(
            (report.strands, report.force_on_jaws_n),
            (0, Vector3::zeros())
        );
        assert_eq!(bed.ties[0].state.damage(&bed.law), damage);
    }

    /// The tether a taut wall gives the grasp pulls the jaws, where it was made, as the
    /// strands do (to 1e-12 N); a slack wall gives none.
    #[test]
    fn the_tether_is_the_strands_where_it_is_made() {
        let (mut bed, ends) = bed_along(&[0.002, 0.006]);
        let mut wall = WallPull::with_room(2);
        wall.grip(&bed, &ends, &Vector3::zeros(), WALL_REACH_M);
        assert!(wall.tether(&bed, &ends).is_none());
        let jaws = Vector3::new(-0.001, 0.0005, 0.003);
        wall.pull(&mut bed, &ends, &jaws);
        let report = wall.pull(&mut bed, &ends, &jaws);
        let tether = wall.tether(&bed, &ends).expect("taut");
        let miss = (tether.force_n(&jaws) - report.force_on_jaws_n).norm();
        assert!(miss < 1e-12, "{miss} N");
        assert_eq!(report.taut, 2);
    }
}
