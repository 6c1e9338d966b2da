//! The haptic loop ticked by the frames, where it has no thread of its own (a web page): at
//! the start of each frame, before the snapshot is read, the ticks real time has made due run
//! (see [`FramePaced`]).

use bevy::platform::time::Instant;
use bevy::prelude::*;

use crate::app::haptic::FramePaced;

/// The paced loop and the instant of the first frame.
struct Paced {
    paced: FramePaced,
    started: Option<Instant>,
}

pub(super) fn setup(app: &mut App, paced: Option<FramePaced>) {
    let Some(paced) = paced else {
        return;
    };
    app.insert_non_send(Paced {
        paced,
        started: None,
    })
    .add_systems(First, advance);
}

fn advance(mut paced: NonSendMut<Paced>) {
    let started = *paced.started.get_or_insert_with(Instant::now);
    paced.paced.advance(started.elapsed());
}
