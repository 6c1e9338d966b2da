// The trainer's web page in headless Chromium: it loads, runs a shipped scenario from a
// scripted trajectory (the page's `script` parameter), and scores it; then M opens the menu
// and the next scenario loads to its briefing; then the liver incision, cut by the scalpel,
// is scored as well. Fails on any console error or uncaught exception, on a scorecard that
// does not pass, on a canvas that shows nearly one colour, and on a menu that does not load
// the scenario chosen.
//   node tests/web/browser.mjs http://127.0.0.1:8080/ [SCREENSHOT.png]
import { writeFileSync } from "node:fs";
import { createRequire } from "node:module";

const require = createRequire(new URL("../../web/package.json", import.meta.url));
const { chromium } = require("playwright-core");

const base = process.argv[2] ?? "http://127.0.0.1:8080/";
const screenshotPath = process.argv[3];
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
  ],
});
const problems = [];
let failed = false;
try {
  const page = await browser.newPage({ viewport: { width: 960, height: 600 } });
  page.on("console", (message) => {
    const text = message.text();
    console.log(`[page ${message.type()}] ${text}`);
    if (message.type() === "error") problems.push(`console error: ${text}`);
  });
  page.on("pageerror", (error) => {
    // Bevy hands the event loop to the browser by throwing; that is not a failure.
    if (!String(error).includes("Using exceptions for control flow")) {
      problems.push(`uncaught: ${error}`);
    }
  });
  // Loads `name` with its competent script and requires the scorecard to pass.
  const scoredRun = async (name) => {
    const started = Date.now();
    await page.goto(`${base}?scenario=${name}&script=tests/scenarios/${name}.competent.csv`);
    await page.waitForFunction(
      () => window.trainer?.scorecard !== undefined || window.trainer?.error !== undefined,
      null,
      { timeout: timeoutMs, polling: 500 },
    );
    const { scorecard, error, frames } = await page.evaluate(() => ({
      scorecard: window.trainer.scorecard,
      error: window.trainer.error,
      frames: window.trainer.frames,
    }));
    if (error !== undefined) throw new Error(`the page failed on ${name}: ${error}`);
    const card = JSON.parse(scorecard);
    console.log(
      `${name}: scored ${card.score.toFixed(1)} (pass mark ${card.pass_mark}, passed ` +
        `${card.passed}) after ${((Date.now() - started) / 1000).toFixed(0)} s`,
    );
    if (!card.passed) problems.push(`the competent run of ${name} did not pass: ${scorecard}`);
    if (frames !== undefined) console.log(`frames: ${frames}`);
  };
  await scoredRun(scenario);

  const shot = await page.locator("#trainer").screenshot();
  if (screenshotPath) writeFileSync(screenshotPath, shot);
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
  console.log(`the canvas shows ${colours} colours`);
  if (colours < 50) problems.push(`the canvas is nearly one colour (${colours} colours)`);

  const stage = () => page.evaluate(() => window.trainer.stage);
  const until = (wanted) =>
    page.waitForFunction((s) => window.trainer.stage === s, wanted, { timeout: timeoutMs });
  await page.focus("#trainer");
  await page.keyboard.press("KeyM");
  await until("Menu");
  await page.keyboard.press("ArrowDown");
  await page.keyboard.press("Enter");
  await page.waitForFunction(() => window.trainer.stage !== "Menu", null, { timeout: timeoutMs });
  await until("Briefing");
  console.log(`the menu loaded the next scenario: ${await stage()}`);

  await scoredRun(cutting);
} catch (e) {
  problems.push(String(e));
} finally {
  await browser.close();
}
for (const problem of problems) console.error(`browser test: ${problem}`);
failed = problems.length > 0;
console.log(failed ? "browser test: FAILED" : "browser test: passed");
process.exit(failed ? 1 : 0);
