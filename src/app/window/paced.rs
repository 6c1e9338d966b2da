//! The haptic loop ticked by the frames, where it has no thread of its own (a web page): at
//! the start of each frame, before the snapshot is read, the ticks real time has made due run
//! (see [`FramePaced`]).

use std::sync::Mutex;

use bevy::platform::time::Instant;
use bevy::prelude::*;

use crate::app::haptic::FramePaced;

/// The paced loop and the instant of the first frame.
struct Paced {
    paced: FramePaced,
    started: Option<Instant>,
}

/// The haptic loop ticked at the start of each frame, when it has no thread (`None` inside:
/// it has one). The loop moves into the app when the plugin is built.
pub(super) struct PacedPlugin(pub Mutex<Option<FramePaced>>);

impl Plugin for PacedPlugin {
    fn build(&self, app: &mut App) {
        let taken = self.0.lock().map(|mut paced| paced.take());
        let Ok(Some(paced)) = taken else {
            return;
        };
        app.insert_non_send(Paced {
            paced,
            started: None,
        })
        .add_systems(First, advance);
    }
}

fn advance(mut paced: NonSendMut<Paced>) {
    let started = *paced.started.get_or_insert_with(Instant::now);
    paced.paced.advance(started.elapsed());
}
