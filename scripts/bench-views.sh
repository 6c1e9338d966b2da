#!/usr/bin/env bash
# Frame time of the laparoscopic view against the free camera, on the same scene and the
# same held probe, the two runs alternating so that both see the same machine:
#   scripts/bench-views.sh [SECONDS_PER_RUN] [ROUNDS]
# Each run draws scenarios/liver-laparoscopic-press (time limit lifted, so no debrief covers
# the view) on the coarse organs for SECONDS_PER_RUN (default 60) and prints the window's
# frame time (p50, p95). Without $DISPLAY it starts its own Xvfb (1280×800).
set -euo pipefail
seconds=${1:-60}
rounds=${2:-2}
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"; [ -n "${xvfb:-}" ] && kill "$xvfb" 2>/dev/null || true' EXIT
if [ -z "${DISPLAY:-}" ]; then
  Xvfb :93 -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
  xvfb=$!
  export DISPLAY=:93
  sleep 1
fi
cargo build --release --bin trainer --manifest-path "$root/Cargo.toml" >&2
trainer="${CARGO_TARGET_DIR:-$root/target}/release/trainer"
sed 's/time_limit_s: 20.0/time_limit_s: 3600.0/' \
  "$root/scenarios/liver-laparoscopic-press.scenario.ron" >"$work/view.scenario.ron"
# The probe held 30 mm above the liver's front, its handle through the scenario's port.
printf 'time_s,x_m,y_m,z_m,buttons\n0,%s\n3600,%s\n' "0.0912,0.1975,-0.2761,0" "0.0912,0.1975,-0.2761,0" >"$work/hold.csv"
for round in $(seq "$rounds"); do
  for view in laparoscope free; do
    flag=()
    [ "$view" = free ] && flag=(--free-camera)
    line=$("$trainer" run "$work/view.scenario.ron" --coarse --vademecums "$root/vademecums" \
      --device "scripted:$work/hold.csv" --exit-after-s "$seconds" "${flag[@]}" \
      --history "$work/history.sqlite" --report-dir "$work" 2>/dev/null | grep '^window:' || true)
    echo "round $round, $view: ${line:-no frames}"
  done
done
