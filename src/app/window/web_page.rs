//! What the window tells the web page around it: the stage the trainee is at and, on each
//! debrief, the scorecard and the frame times so far as JSON (`window.trainer.stage`,
//! `.scorecard`, `.frames`), for the page's scripts and the browser test, through
//! [`publish`].

use bevy::prelude::*;
use wasm_bindgen::JsValue;

use super::frames::FrameLog;
use super::lesson::{Debriefed, Stage, show_debrief};

/// What the web page around the window reads: the stage, and the scorecard at the debrief.
pub(super) struct WebPagePlugin;

impl Plugin for WebPagePlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(Update, publish_stage.run_if(state_changed::<Stage>))
            .add_systems(
                OnEnter(Stage::Debrief),
                publish_scorecard.after(show_debrief),
            );
    }
}

fn publish_stage(stage: Res<State<Stage>>) {
    publish("stage", &JsValue::from_str(&format!("{:?}", stage.get())));
}

fn publish_scorecard(card: Option<Res<Debriefed>>, frames: Res<FrameLog>) {
    if let Some(report) = frames.report() {
        publish_json("frames", &report);
    }
    if let Some(card) = card {
        publish_json("scorecard", &card.0);
    }
}

fn publish_json(key: &str, value: &impl serde::Serialize) {
    match serde_json::to_string(value) {
        Ok(json) => publish(key, &JsValue::from_str(&json)),
        Err(e) => bevy::log::error!("{key} could not be written as JSON: {e}"),
    }
}

/// Sets `window.trainer[key]` (creating `window.trainer`): what a script driving the page
/// reads (`stage`; `scorecard` and `frames` as JSON; `error`).
pub fn publish(key: &str, value: &JsValue) {
    let Some(window) = web_sys::window() else {
        return;
    };
    let trainer = js_sys::Reflect::get(&window, &JsValue::from_str("trainer"))
        .ok()
        .filter(JsValue::is_object)
        .unwrap_or_else(|| {
            let object = js_sys::Object::new().into();
            let _ = js_sys::Reflect::set(&window, &JsValue::from_str("trainer"), &object);
            object
        });
    let _ = js_sys::Reflect::set(&trainer, &JsValue::from_str(key), value);
}
