//! What the window tells the web page around it: the stage the trainee is at and, on each
//! debrief, the scorecard as JSON (`window.trainer.stage`, `window.trainer.scorecard`), for
//! the page's scripts and the browser test.

use bevy::prelude::*;
use wasm_bindgen::JsValue;

use super::lesson::{Stage, show_debrief};
use crate::app::web::publish;
use crate::scenario::Scorecard;

/// The scorecard the debrief shows.
#[derive(Resource, Clone, Debug)]
pub(super) struct Debriefed(pub Scorecard);

pub(super) fn setup(app: &mut App) {
    app.add_systems(Update, publish_stage.run_if(state_changed::<Stage>))
        .add_systems(
            OnEnter(Stage::Debrief),
            publish_scorecard.after(show_debrief),
        );
}

fn publish_stage(stage: Res<State<Stage>>) {
    publish("stage", &JsValue::from_str(&format!("{:?}", stage.get())));
}

fn publish_scorecard(card: Option<Res<Debriefed>>) {
    let Some(card) = card else {
        return;
    };
    match serde_json::to_string(&card.0) {
        Ok(json) => publish("scorecard", &JsValue::from_str(&json)),
        Err(e) => bevy::log::error!("the scorecard could not be written as JSON: {e}"),
    }
}
