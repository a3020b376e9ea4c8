// Loads an fbakit viewer page in headless Chromium and prints one JSON report of what the page
// did; tests/viewer_browser.rs asserts on it.
//
//   node viewer-check.mjs PAGE.html [SCREENSHOT.png]
//
// The npm package `playwright-core` is looked up in $VIEWER_BROWSER_DIR (an
// `npm install --prefix` directory) first, then through ordinary node_modules resolution;
// Chromium is $CHROMIUM_PATH or /usr/bin/chromium. Exit codes: 0 = report printed, 3 = driver or
// browser missing (callers treat that as "skip"), 1 = the page could not be checked.
import path from "node:path";
import { pathToFileURL } from "node:url";

import { launchChromium } from "./headless-chromium.mjs";

const [pagePath, screenshot] = process.argv.slice(2);
if (!pagePath) {
  console.error("usage: viewer-check.mjs PAGE.html [SCREENSHOT.png]");
  process.exit(1);
}
const pageUrl = pathToFileURL(path.resolve(pagePath)).href;
const browser = await launchChromium({ webgl: true });

const report = { consoleErrors: [], pageErrors: [], foreignRequests: [] };
try {
  const page = await browser.newPage({ viewport: { width: 1000, height: 640 } });
  page.on("console", (m) => {
    if (m.type() === "error") report.consoleErrors.push(m.text());
  });
  page.on("pageerror", (e) => report.pageErrors.push(String(e && e.message ? e.message : e)));
  page.on("request", (r) => {
    const u = r.url();
    if (u !== pageUrl && !u.startsWith("data:") && !u.startsWith("blob:")) {
      report.foreignRequests.push(u);
    }
  });
  await page.goto(pageUrl);
  report.ready = await page.evaluate(() => window.fbakitViewer.ready);

  // Opens ready to watch: playing, in animation mode, and time moves; the pause button stops
  // the clock. (A page without a stream has no transport and starts in pose mode.)
  report.stateOnLoad = await page.evaluate(() => window.fbakitViewer.state());
  const animated = report.ready.frames > 0;
  if (animated) {
    report.timeAdvanced = await page
      .waitForFunction(() => window.fbakitViewer.state().time > 0.05, null, { timeout: 20000 })
      .then(() => true, () => false);
    await page.click("#play");
    report.stateAfterPauseClick = await page.evaluate(() => window.fbakitViewer.state());
  }

  // A frame far from the first for the mouth: where the values of the mouth's FAPs (groups 1,
  // 2 and 8: visemes, expressions, jaw and lips) differ most from frame 0.
  const pick = await page.evaluate(() => {
    const m = window.fbakitViewer.model;
    const ranges = {};
    for (const g of m.groups) {
      if (![1, 2, 8].includes(g.number)) continue;
      for (const k of g.keys) ranges[k.key] = k.max - k.min || 1;
    }
    let best = 0;
    let bestScore = -1;
    const n = m.stream ? m.stream.frames : 0;
    for (let i = 0; i < n; i++) {
      let s = 0;
      for (const t of m.tracks) {
        if (ranges[t.key]) s += Math.abs(t.values[i] - t.values[0]) / ranges[t.key];
      }
      if (s > bestScore) {
        bestScore = s;
        best = i;
      }
    }
    return { frame: best, time: m.stream ? best / m.stream.fps : 0, frames: n };
  });
  report.pickedFrame = pick;

  // The mouth region on screen, from the lip feature points (inner lip 2.2-2.9, outer lip 8.x).
  const region = await page.evaluate(() => {
    const v = window.fbakitViewer;
    v.seek(0);
    const pts = v.projectFeaturePoints().filter((p) => /^(2\.[2-9]|8\.\d+)$/.test(p.id));
    const c = document.getElementById("view");
    if (pts.length < 2) {
      return { x: c.clientWidth * 0.3, y: c.clientHeight * 0.55, w: c.clientWidth * 0.4, h: c.clientHeight * 0.3, points: pts.length };
    }
    const xs = pts.map((p) => p.x);
    const ys = pts.map((p) => p.y);
    const x0 = Math.min(...xs), x1 = Math.max(...xs), y0 = Math.min(...ys), y1 = Math.max(...ys);
    const px = (x1 - x0) * 0.2 + 4, py = (y1 - y0) * 0.4 + 4;
    const x = Math.max(0, x0 - px), y = Math.max(0, y0 - py);
    return {
      x, y,
      w: Math.min(c.clientWidth, x1 + px) - x,
      h: Math.min(c.clientHeight, y1 + py) - y,
      points: pts.length,
    };
  });
  report.mouthRegion = region;

  // Reads the rendered canvas (device pixels) inside `region` as RGBA bytes.
  const readRegion = () =>
    page.evaluate((r) => {
      const v = window.fbakitViewer;
      v.renderNow();
      const c = document.getElementById("view");
      const sx = c.width / c.clientWidth;
      const sy = c.height / c.clientHeight;
      const w = Math.max(1, Math.round(r.w * sx));
      const h = Math.max(1, Math.round(r.h * sy));
      const tmp = document.createElement("canvas");
      tmp.width = w;
      tmp.height = h;
      const g = tmp.getContext("2d");
      g.drawImage(c, Math.round(r.x * sx), Math.round(r.y * sy), w, h, 0, 0, w, h);
      return Array.from(g.getImageData(0, 0, w, h).data);
    }, region);

  const compare = (a, b) => {
    let sum = 0;
    let changed = 0;
    let opaque = 0;
    const n = Math.min(a.length, b.length) / 4;
    for (let i = 0; i < n; i++) {
      let d = 0;
      for (let k = 0; k < 4; k++) d += Math.abs(a[i * 4 + k] - b[i * 4 + k]);
      sum += d / 4;
      if (d / 4 > 16) changed++;
      if (a[i * 4 + 3] > 0) opaque++;
    }
    return { meanAbsDiff: sum / n, changedFraction: changed / n, opaqueFraction: opaque / n, pixels: n };
  };

  if (animated) {
    // Two times of the animation.
    await page.evaluate(() => window.fbakitViewer.seek(0));
    const atStart = await readRegion();
    await page.evaluate((t) => window.fbakitViewer.seek(t), pick.time);
    const atPick = await readRegion();
    report.timeChange = compare(atStart, atPick);
    report.stateAfterSeek = await page.evaluate(() => window.fbakitViewer.state());

    // Scrubbing through the time slider moves the clock too.
    await page.locator("#scrub").fill(String(pick.time / 2));
    report.stateAfterScrub = await page.evaluate(() => window.fbakitViewer.state());
  }

  // One FAP slider: neutral first, then the jaw (or the first mouth FAP) to its maximum.
  await page.click("#reset-pose");
  const neutralPixels = await readRegion();
  const slider = await page.evaluate(() => {
    const m = window.fbakitViewer.model;
    const keys = m.groups.flatMap((g) => g.keys);
    const k = keys.find((k) => k.key === "open_jaw") || keys.find((k) => /_lip|jaw/.test(k.key)) || keys[0];
    return k ? { key: k.key, value: k.max } : null;
  });
  report.slider = slider;
  if (slider) {
    await page.locator(`input[data-key="${slider.key}"]`).fill(String(slider.value));
    const posed = await readRegion();
    report.sliderChange = compare(neutralPixels, posed);
    report.stateAfterSlider = await page.evaluate(() => window.fbakitViewer.state());
    report.sliderOutput = await page.locator(`#fap-${slider.key} + output`).textContent();
  }

  // The neutral face at the default camera: where the pupils, the skin and the chin land, and
  // how dark the pixels inside the pupils are (eyes must show an iris and a pupil, and the
  // whole face must sit above the transport bar).
  await page.click("#reset-pose");
  await page.click("#reset-camera");
  report.neutralView = await page.evaluate(() => {
    const v = window.fbakitViewer;
    v.renderNow();
    const c = document.getElementById("view");
    const cr = c.getBoundingClientRect();
    const tr = document.getElementById("transport");
    const barTop = tr.hidden ? cr.height : tr.getBoundingClientRect().top - cr.top;
    const pts = v.projectFeaturePoints();
    const get = (id) => pts.find((p) => p.id === id);
    const sx = c.width / c.clientWidth;
    const sy = c.height / c.clientHeight;
    const tmp = document.createElement("canvas");
    tmp.width = c.width;
    tmp.height = c.height;
    const g = tmp.getContext("2d");
    g.drawImage(c, 0, 0);
    // Mean luminance (0-255) of the drawn pixels in a 3x3 box of device pixels around `p`.
    const lum = (p) => {
      const x = Math.round(p.x * sx);
      const y = Math.round(p.y * sy);
      const d = g.getImageData(x - 1, y - 1, 3, 3).data;
      let s = 0;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (d[i + 3] === 0) continue;
        s += 0.2126 * d[i] + 0.7152 * d[i + 1] + 0.0722 * d[i + 2];
        n++;
      }
      return n ? s / n : null;
    };
    const at = (ids) => ids.map(get).filter(Boolean).map((p) => ({ id: p.id, x: p.x, y: p.y, luminance: lum(p) }));
    const ys = pts.map((p) => p.y);
    return {
      barTop,
      canvasHeight: cr.height,
      chin: get("2.1") || null,
      pupils: at(["3.5", "3.6"]),
      skin: at(["9.3", "5.3", "5.4"]),
      lowestPoint: Math.max(...ys),
      highestPoint: Math.min(...ys),
      eyes: (v.model.eyes || []).length,
    };
  });
  if (screenshot) await page.screenshot({ path: screenshot.replace(/\.png$/, "") + "-neutral.png" });

  if (screenshot) {
    if (animated) await page.evaluate((t) => window.fbakitViewer.seek(t), pick.time);
    await page.screenshot({ path: screenshot });
  }
  console.log(JSON.stringify(report));
} catch (e) {
  console.error(String(e && e.stack ? e.stack : e));
  process.exitCode = 1;
} finally {
  await browser.close();
}
