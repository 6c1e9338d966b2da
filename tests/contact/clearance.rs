//! Nodes measured clear of the master are skipped while nothing has moved far enough since to
//! close the gap (`contact::Clearance`). That must change no force: the same pushes run on
//! the scene that measures every node within reach every tick give, tick by tick, exactly the
//! same contact, with fewer nodes measured.

use nalgebra::Vector3;

use crate::common::*;

fn assert_same_contact(skipping: &[Tick], every: &[Tick]) {
    let (mut measured_skipping, mut measured_every) = (0, 0);
    for (tick, (a, b)) in skipping.iter().zip(every).enumerate() {
        for (organ, (da, db)) in a.organs.iter().zip(&b.organs).enumerate() {
            assert_eq!(da.coupling, db.coupling, "tick {tick}, organ {organ}");
            assert_eq!(
                da.coefficients, db.coefficients,
                "tick {tick}, organ {organ}"
            );
        }
        for ((_, _, ra), (_, _, rb)) in a.pairs.iter().zip(&b.pairs) {
            assert_eq!(ra.force_on_shell_n, rb.force_on_shell_n, "tick {tick}");
            assert_eq!(ra.nodes_in_contact, rb.nodes_in_contact, "tick {tick}");
            measured_skipping += ra.nodes_evaluated;
            measured_every += rb.nodes_evaluated;
        }
    }
    eprintln!(
        "nodes measured: {measured_skipping} skipping those known clear, {measured_every} not"
    );
    assert!(
        2 * measured_skipping < measured_every,
        "the skip should at least halve the nodes measured: {measured_skipping} against {measured_every}"
    );
}

#[test]
fn skipping_nodes_known_clear_changes_no_force() {
    let ticks = 2500;
    for target in [
        facing("gallbladder", -Vector3::z()),
        facing_clear_of("gallbladder", -Vector3::z(), "duodenum"),
    ] {
        let trajectory = push(&target, 0.012, 2.0, 0.5);
        let skipping = run(trajectory.clone(), ticks).1;
        let every = run_on(measuring_every_node_scene(), trajectory, ticks).1;
        assert!(
            skipping
                .iter()
                .any(|t| t.pairs.iter().any(|p| p.2.nodes_in_contact > 0))
        );
        assert_same_contact(&skipping, &every);
    }
}
