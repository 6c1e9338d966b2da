#!/usr/bin/env bash
# Builds the trainer as a static web page in web/dist/: the trainer compiled for
# wasm32-unknown-unknown twice, drawn by WebGPU and by WebGL2 (the page loads the first where
# the browser offers a WebGPU adapter), bound to JavaScript by wasm-bindgen-cli (the version
# Cargo.lock pins, installed from the crate registry when missing), the page, and the web
# forms of the vademecums every shipped scenario needs (built natively first when missing).
#   scripts/web-build.sh                   coarse organs (the page's default), both renderers
#   WEB_DETAIL=full scripts/web-build.sh   the papers' meshes too (open the page with ?detail=full)
#   WEB_RENDERERS=webgl2 scripts/web-build.sh   one renderer only (webgl2 or webgpu)
#   WEB_TRAINER_PROFILE=dev scripts/web-build.sh  the vademecums made by the dev build of the
#                                   trainer (what `cargo test` builds; CI), not the release one
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/pgd-surgery/target}"
tools="${PGD_TOOLS:-$HOME/.cache/pgd-surgery/tools}"
dist=web/dist
detail="${WEB_DETAIL:-coarse}"
trainer_profile="${WEB_TRAINER_PROFILE:-release}"
case "$trainer_profile" in
  release) trainer_dir=release ;;
  dev) trainer_dir=debug ;;
  *) echo "web-build: WEB_TRAINER_PROFILE is \`$trainer_profile\`; it is release or dev" >&2; exit 2 ;;
esac
read -r -a renderers <<<"${WEB_RENDERERS:-webgpu webgl2}"
for renderer in "${renderers[@]}"; do
  case "$renderer" in
    webgl2 | webgpu) ;;
    *) echo "web-build: WEB_RENDERERS names \`$renderer\`; the renderers are webgl2 and webgpu" >&2
       exit 2 ;;
  esac
done

bindgen_version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print }' Cargo.lock)
if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
  echo "web-build: adding the wasm32-unknown-unknown target"
  rustup target add wasm32-unknown-unknown
fi
if [ "$("$tools/bin/wasm-bindgen" --version 2>/dev/null)" != "wasm-bindgen $bindgen_version" ]; then
  echo "web-build: installing wasm-bindgen-cli $bindgen_version into $tools"
  CARGO_TARGET_DIR="$HOME/.cache/pgd-surgery/tools-build" \
    cargo install wasm-bindgen-cli --version "=$bindgen_version" --root "$tools" --force
fi

rm -rf "$dist"
mkdir -p "$dist/vademecums" "$dist/scenarios"
for renderer in "${renderers[@]}"; do
  echo "web-build: compiling the trainer for the browser, drawn by $renderer"
  cargo build --release --target wasm32-unknown-unknown -p pgd-surgery --bin trainer-web \
    --features "$renderer"
  "$tools/bin/wasm-bindgen" --target web --no-typescript --remove-name-section \
    --remove-producers-section --out-dir "$dist" --out-name "trainer_$renderer" \
    "$CARGO_TARGET_DIR/wasm32-unknown-unknown/release/trainer-web.wasm"
  # Compressed twins, which scripts/web_serve.py (as any static host) sends to browsers.
  gzip -9 --keep --force "$dist/trainer_${renderer}_bg.wasm" "$dist/trainer_$renderer.js"
done
cp web/index.html "$dist/"
# The scripted runs, for the browser test and for replaying an exercise in the page.
cp -r scenarios/runs "$dist/scenarios/"

echo "web-build: the vademecums of every shipped scenario ($detail organs)"
detail_flag=()
[ "$detail" = coarse ] && detail_flag=(--coarse)
cargo build --profile "$trainer_profile" --bin trainer
"$CARGO_TARGET_DIR/$trainer_dir/trainer" prepare "${detail_flag[@]}" --web "$dist/vademecums" \
  scenarios/*.scenario.ron
du -sh "$dist"/trainer_*_bg.wasm* "$dist/vademecums"
echo "web-build: done; serve it with scripts/web-serve.sh"
