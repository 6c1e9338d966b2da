//! `trainer-web`: the trainer in a web page. `scripts/web-build.sh` builds it for
//! `wasm32-unknown-unknown` into `web/dist/`, and `scripts/web-serve.sh` serves the page.
//! It is built once per renderer, with the feature `webgl2` or `webgpu`.

#[cfg(all(
    target_arch = "wasm32",
    not(any(feature = "webgl2", feature = "webgpu"))
))]
compile_error!(
    "the web page needs a renderer: build it with `--features webgl2` or `--features webgpu` \
     (scripts/web-build.sh builds both)"
);

#[cfg(all(target_arch = "wasm32", feature = "webgl2", feature = "webgpu"))]
compile_error!(
    "build the web page with one renderer, `webgl2` or `webgpu`: Bevy compiles its shaders \
     for one of them"
);

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
