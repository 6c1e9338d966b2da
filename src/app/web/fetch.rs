//! Files over HTTP from the page's own site. The browser's HTTP cache keeps them: a second
//! visit revalidates rather than downloads again.

use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_futures::JsFuture;

/// The bytes at `url` (relative to the page); `None` if the site has no such file (404).
pub async fn bytes(url: &str) -> Result<Option<Vec<u8>>, String> {
    let window = web_sys::window().ok_or("no browser window")?;
    let failed = |e: JsValue| format!("{url}: {}", describe(&e));
    let response = JsFuture::from(window.fetch_with_str(url))
        .await
        .map_err(failed)?;
    let response: web_sys::Response = response.dyn_into().map_err(failed)?;
    if response.status() == 404 {
        return Ok(None);
    }
    if !response.ok() {
        return Err(format!("{url}: HTTP {}", response.status()));
    }
    let body = JsFuture::from(response.array_buffer().map_err(failed)?)
        .await
        .map_err(failed)?;
    Ok(Some(js_sys::Uint8Array::new(&body).to_vec()))
}

/// The text at `url`, which must exist.
pub async fn text(url: &str) -> Result<String, String> {
    let bytes = bytes(url)
        .await?
        .ok_or_else(|| format!("{url}: not found"))?;
    String::from_utf8(bytes).map_err(|e| format!("{url}: {e}"))
}

fn describe(e: &JsValue) -> String {
    e.as_string()
        .or_else(|| {
            e.dyn_ref::<js_sys::Error>()
                .map(|e| String::from(e.message()))
        })
        .unwrap_or_else(|| format!("{e:?}"))
}
