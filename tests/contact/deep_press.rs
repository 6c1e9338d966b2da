//! The free gallbladder carried 20 mm into the liver, as `pgd bench contact --case pressed`
//! presses it: far past where the normal compliance `A` predicts how the surfaces move (the
//! floppy master swings sideways under the forces). Taking each tick's whole change of the
//! forces, the contact flipped every tick (here: the force by 10 % of itself, nodes down to
//! 1.6 mm deep; the bench's settled 20 mm press, between nodes 0.3 mm and 6.5 mm deep), a
//! 500 Hz buzz in the tool. Relaxed (`contact::Relaxation`), it settles: within 300 ticks,
//! the force changes by at most 1 % of itself a tick, and no node is a lattice cell deep.

use pgd_surgery::bench::contact::free_press;

use crate::common::*;

#[test]
fn a_deep_free_press_settles_shallow_without_flipping() {
    let coupling = scene().coupling.as_deref().unwrap();
    let reports = free_press(&scene().organs, coupling, 0.020, 600).unwrap();
    let spacing_m = coupling.pairs[0].field().spacing_m();
    let settled = &reports[300..];
    let deepest_m = settled.iter().map(|r| r.deepest_m).fold(0.0, f64::max);
    let force_n = |r: &pgd_surgery::contact::PairReport| r.force_on_shell_n.norm();
    let largest_n = settled.iter().map(force_n).fold(0.0, f64::max);
    let largest_change_n = settled
        .windows(2)
        .map(|w| (w[1].force_on_shell_n - w[0].force_on_shell_n).norm())
        .fold(0.0, f64::max);
    eprintln!(
        "deepest {:.3} mm (cell {:.1} mm), force up to {largest_n:.4} N, changing by up to \
         {largest_change_n:.2e} N a tick",
        deepest_m * 1e3,
        spacing_m * 1e3
    );
    assert!(settled.iter().all(|r| r.nodes_in_contact > 0));
    assert!(deepest_m < spacing_m, "a node {deepest_m} m deep");
    assert!(
        largest_change_n <= 0.01 * largest_n,
        "the force changes by {largest_change_n} N a tick, of {largest_n} N"
    );
}
