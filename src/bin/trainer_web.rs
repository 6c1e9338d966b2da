//! `trainer-web`: the trainer in a web page. `scripts/web-build.sh` builds it for
//! `wasm32-unknown-unknown` into `web/dist/`, and `scripts/web-serve.sh` serves the page.

#[cfg(target_arch = "wasm32")]
fn main() {
    pgd_surgery::app::web::start();
}

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    eprintln!(
        "trainer-web runs in a browser: build it with scripts/web-build.sh, then serve it with \
         scripts/web-serve.sh and open the address it prints (the desktop trainer is `trainer`)"
    );
    std::process::ExitCode::FAILURE
}
