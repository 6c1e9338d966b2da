//! The page around the trainer: what its address asks for, the status line under the canvas,
//! and what it tells a script driving it (a browser test reads `window.trainer`).

use wasm_bindgen::JsValue;

use crate::app::scene::Detail;
use crate::app::window::publish;

/// What the page's address asks for: `?scenario=STEM&script=URL&detail=full`.
pub struct Query {
    /// The shipped scenario to open (`scenarios/STEM.scenario.ron`); the default one if absent.
    pub scenario: Option<String>,
    /// A trajectory CSV to drive the tool instead of the mouse (the exercise begins at once).
    pub script: Option<String>,
    pub detail: Detail,
}

impl Query {
    pub fn read() -> Self {
        let search = web_sys::window()
            .and_then(|w| w.location().search().ok())
            .unwrap_or_default();
        let params = web_sys::UrlSearchParams::new_with_str(&search).ok();
        let get = |key: &str| params.as_ref().and_then(|p| p.get(key));
        Self {
            scenario: get("scenario"),
            script: get("script"),
            detail: match get("detail").as_deref() {
                Some("full") => Detail::Full,
                _ => Detail::Coarse,
            },
        }
    }
}

/// Shows `text` in the page's status line (and the console).
pub fn status(text: &str) {
    web_sys::console::log_1(&JsValue::from_str(text));
    if let Some(line) = element("status") {
        line.set_text_content(Some(text));
    }
}

/// The page could not start the trainer: says why on the page and as a console error.
pub fn fail(why: &str) {
    web_sys::console::error_1(&JsValue::from_str(why));
    if let Some(line) = element("status") {
        line.set_text_content(Some(&format!("The trainer could not start: {why}")));
    }
    publish("error", &JsValue::from_str(why));
}

fn element(id: &str) -> Option<web_sys::Element> {
    web_sys::window()?.document()?.get_element_by_id(id)
}
