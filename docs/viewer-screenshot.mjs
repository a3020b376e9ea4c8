// Takes a screenshot of an fbakit viewer page in headless Chromium (the README's pictures).
//
//   node docs/viewer-screenshot.mjs PAGE.html OUT.png [--size 1100x620] [--time 1.8]
//        [--points] [--wireframe] [--fap open_jaw=600 ...] [--open GROUP ...]
//
// playwright-core comes from $VIEWER_BROWSER_DIR (as for tests/support/viewer-check.mjs), Chromium
// from $CHROMIUM_PATH or /usr/bin/chromium. The README pictures were made with:
//   fbakit view alma samples/speech.fap -o alma.html
//   node docs/viewer-screenshot.mjs alma.html docs/viewer.png --time 1.8
//   fbakit view bruno samples/speech.fap -o bruno.html
//   node docs/viewer-screenshot.mjs bruno.html docs/viewer-overlays.png --time 0.4 --points \
//        --wireframe --open 2 --open 8
// each then made small with `pngquant --quality 70-90` (Debian package pngquant).
import { createRequire } from "node:module";
import path from "node:path";
import { pathToFileURL } from "node:url";

const args = process.argv.slice(2);
const [pagePath, out] = args;
const opt = { size: "1100x620", time: null, points: false, wireframe: false, faps: [], open: [] };
for (let i = 2; i < args.length; i++) {
  const a = args[i];
  if (a === "--size") opt.size = args[++i];
  else if (a === "--time") opt.time = Number(args[++i]);
  else if (a === "--points") opt.points = true;
  else if (a === "--wireframe") opt.wireframe = true;
  else if (a === "--fap") opt.faps.push(args[++i].split("="));
  else if (a === "--open") opt.open.push(Number(args[++i]));
  else throw new Error(`unknown option ${a}`);
}
const base = process.env.VIEWER_BROWSER_DIR
  ? path.join(path.resolve(process.env.VIEWER_BROWSER_DIR), "package.json")
  : import.meta.url;
const { chromium } = createRequire(base)("playwright-core");
const [width, height] = opt.size.split("x").map(Number);
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM_PATH || "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--hide-scrollbars"],
});
try {
  const page = await browser.newPage({ viewport: { width, height } });
  page.on("pageerror", (e) => console.error("page error:", e.message));
  await page.goto(pathToFileURL(path.resolve(pagePath)).href);
  await page.evaluate(() => window.fbakitViewer.ready);
  await page.evaluate((o) => {
    const v = window.fbakitViewer;
    if (o.time !== null) {
      v.seek(o.time);
      v.pause();
    }
    for (const [k, val] of o.faps) v.setValue(k, Number(val));
    if (o.points) document.getElementById("toggle-points").click();
    if (o.wireframe) document.getElementById("toggle-wireframe").click();
    if (o.open.length) {
      document.querySelectorAll("details.group").forEach((d, i) => {
        d.open = o.open.includes(v.model.groups[i].number);
      });
    }
    v.renderNow();
  }, opt);
  await page.waitForTimeout(200);
  await page.screenshot({ path: out });
} finally {
  await browser.close();
}
