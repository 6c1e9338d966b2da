// The trainer's web page in headless Chromium, once per renderer (WebGL2 and WebGPU, both on
// SwiftShader, the CPU's software GPU): it loads, runs a shipped scenario from a scripted
// trajectory (the page's `script` parameter), and scores it; then M opens the menu and the
// next scenario loads to its briefing; then the liver incision, cut by the scalpel, is scored
// as well. Fails on any console error (Bevy's logged errors among them) or uncaught
// exception, on a page that loads another renderer than asked, on a scorecard that does not
// pass, on a canvas that shows nearly one colour, and on a menu that does not load the
// scenario chosen.
//   node tests/web/browser.mjs http://127.0.0.1:8080/ [SCREENSHOT_DIR] [RENDERERS]
// RENDERERS: "webgl2 webgpu" when left out; each canvas lands in SCREENSHOT_DIR/shot-<renderer>.png.
import { writeFileSync } from "node:fs";
import { createRequire } from "node:module";

const require = createRequire(new URL("../../web/package.json", import.meta.url));
const { chromium } = require("playwright-core");

const base = process.argv[2] ?? "http://127.0.0.1:8080/";
const screenshotDir = process.argv[3];
const renderers = (process.argv[4] ?? "webgl2 webgpu").split(/\s+/).filter(Boolean);
const scenario = "liver-steady-press";
// A scenario whose scalpel cuts: the cut state grows where the page hands it each step.
const cutting = "liver-capsule-incision";
// Software WebGL renders a frame in about a second, so the physics, paced by the frames, runs
// slower than real time: the 5.5 s script takes minutes.
const timeoutMs = 8 * 60 * 1000;

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: [
    "--no-sandbox",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--ignore-gpu-blocklist",
    // WebGPU on SwiftShader's Vulkan: without the first, Chromium offers no software adapter;
    // without the others, the device it gives is lost at once.
    "--enable-unsafe-webgpu",
    "--enable-features=Vulkan",
    "--use-vulkan=swiftshader",
    "--use-webgpu-adapter=swiftshader",
  ],
});
const problems = [];

// The whole run on one renderer, in a page of its own; what goes wrong lands in `problems`.
async function testRenderer(renderer) {
  const page = await browser.newPage({ viewport: { width: 960, height: 600 } });
  const problem = (text) => problems.push(`${renderer}: ${text}`);
  page.on("console", (message) => {
    const text = message.text();
    console.log(`[${renderer} page ${message.type()}] ${text}`);
    // Bevy logs its errors through console.log, styled and marked ERROR.
    const bevyError = text.startsWith("%cERROR");
    if (message.type() === "error" || bevyError) problem(`console error: ${text}`);
  });
  page.on("pageerror", (error) => {
    // Bevy hands the event loop to the browser by throwing; that is not a failure.
    if (!String(error).includes("Using exceptions for control flow")) {
      problem(`uncaught: ${error}`);
    }
  });
  // Loads `name` with its competent script and requires the scorecard to pass.
  const scoredRun = async (name) => {
    const started = Date.now();
    const script = `scenarios/runs/${name}.competent.csv`;
    await page.goto(`${base}?renderer=${renderer}&scenario=${name}&script=${script}`);
    await page.waitForFunction(
      () => window.trainer?.scorecard !== undefined || window.trainer?.error !== undefined,
      null,
      { timeout: timeoutMs, polling: 500 },
    );
    const { scorecard, error, frames, loaded } = await page.evaluate(() => ({
      scorecard: window.trainer.scorecard,
      error: window.trainer.error,
      frames: window.trainer.frames,
      loaded: window.trainerRenderer,
    }));
    if (error !== undefined) throw new Error(`the page failed on ${name}: ${error}`);
    if (loaded !== renderer) problem(`the page loaded the ${loaded} build`);
    const card = JSON.parse(scorecard);
    console.log(
      `${renderer}, ${name}: scored ${card.score.toFixed(1)} (pass mark ${card.pass_mark}, ` +
        `passed ${card.passed}) after ${((Date.now() - started) / 1000).toFixed(0)} s`,
    );
    if (!card.passed) problem(`the competent run of ${name} did not pass: ${scorecard}`);
    if (frames !== undefined) console.log(`${renderer} frames: ${frames}`);
  };
  try {
    await scoredRun(scenario);
    await checkCanvas(page, renderer, problem);

    const until = (wanted) =>
      page.waitForFunction((s) => window.trainer.stage === s, wanted, { timeout: timeoutMs });
    await page.focus("#trainer");
    await page.keyboard.press("KeyM");
    await until("Menu");
    await page.keyboard.press("ArrowDown");
    await page.keyboard.press("Enter");
    await page.waitForFunction(() => window.trainer.stage !== "Menu", null, {
      timeout: timeoutMs,
    });
    await until("Briefing");
    console.log(`${renderer}: the menu loaded the next scenario to its briefing`);

    await scoredRun(cutting);
  } catch (e) {
    problem(String(e));
  } finally {
    await page.close();
  }
}

// The canvas, saved as SCREENSHOT_DIR/shot-<renderer>.png, must show more than a few colours.
async function checkCanvas(page, renderer, problem) {
  const shot = await page.locator("#trainer").screenshot();
  if (screenshotDir) writeFileSync(`${screenshotDir}/shot-${renderer}.png`, shot);
  const colours = await page.evaluate(async (png) => {
    const image = new Image();
    image.src = `data:image/png;base64,${png}`;
    await image.decode();
    const canvas = document.createElement("canvas");
    canvas.width = image.width;
    canvas.height = image.height;
    const context = canvas.getContext("2d");
    context.drawImage(image, 0, 0);
    const pixels = context.getImageData(0, 0, image.width, image.height).data;
    const seen = new Set();
    for (let k = 0; k < pixels.length; k += 4 * 7) {
      seen.add((pixels[k] << 16) | (pixels[k + 1] << 8) | pixels[k + 2]);
    }
    return seen.size;
  }, shot.toString("base64"));
  console.log(`${renderer}: the canvas shows ${colours} colours`);
  if (colours < 50) problem(`the canvas is nearly one colour (${colours} colours)`);
}

try {
  for (const renderer of renderers) await testRenderer(renderer);
} finally {
  await browser.close();
}
for (const problem of problems) console.error(`browser test: ${problem}`);
const failed = problems.length > 0;
console.log(failed ? "browser test: FAILED" : "browser test: passed");
process.exit(failed ? 1 : 0);
