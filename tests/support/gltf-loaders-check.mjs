// Loads glTF files with three.js's GLTFLoader in headless Chromium and prints one JSON line per
// file of what three.js made of it; tests/gltf_loaders.rs asserts on it.
//
//   node gltf-loaders-check.mjs FILE.glb|FILE.gltf ...
//
// The npm package `three` is looked up in $THREE_DIR (an `npm install --prefix` directory),
// `playwright-core` in $VIEWER_BROWSER_DIR, each then through ordinary node_modules resolution;
// Chromium is $CHROMIUM_PATH or /usr/bin/chromium. The page, three.js and the files are served
// by the driver itself (request interception on an origin that never reaches the network), so
// `.gltf` files load their `.bin` and images by relative URI as on a web server. Exit codes:
// 0 = reports printed, 3 = a package or the browser missing (callers treat that as "skip"),
// 1 = a file could not be checked.
import { existsSync } from "node:fs";
import path from "node:path";

import { launchChromium, resolveIn } from "./headless-chromium.mjs";

const files = process.argv.slice(2).map((f) => path.resolve(f));
if (files.length === 0) {
  console.error("usage: gltf-loaders-check.mjs FILE...");
  process.exit(1);
}
// three's package.json exports map hides its folders: find the package root from its main.
const threeMain = resolveIn("THREE_DIR", "three");
const threeRoot = path.resolve(path.dirname(threeMain), "..");
if (!existsSync(path.join(threeRoot, "examples/jsm/loaders/GLTFLoader.js"))) {
  console.error(`no GLTFLoader under ${threeRoot}`);
  process.exit(3);
}
const ORIGIN = "http://fbakit.test";
const PAGE = `<!doctype html><meta charset="utf-8"><title>gltf loaders</title>
<script type="importmap">{"imports": {"three": "/three/build/three.module.js",
  "three/addons/": "/three/examples/jsm/"}}</script>
<script type="module">
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
window.THREE = THREE;
window.GLTFLoader = GLTFLoader;
window.loadersReady = true;
</script>`;

const browser = await launchChromium();

let failed = false;
try {
  const page = await browser.newPage();
  const log = { consoleErrors: [], consoleWarnings: [], pageErrors: [], foreignRequests: [] };
  page.on("console", (m) => {
    if (m.type() === "error") log.consoleErrors.push(m.text());
    if (m.type() === "warning") log.consoleWarnings.push(m.text());
  });
  page.on("pageerror", (e) => log.pageErrors.push(String(e && e.message ? e.message : e)));
  // Only the test origin is answered; anything else is refused and reported.
  await page.route("**/*", async (route) => {
    const url = new URL(route.request().url());
    if (url.origin !== ORIGIN) {
      log.foreignRequests.push(url.href);
      return route.abort();
    }
    const p = decodeURIComponent(url.pathname);
    if (p === "/") {
      return route.fulfill({ body: PAGE, contentType: "text/html" });
    }
    let file = null;
    if (p.startsWith("/three/")) {
      file = path.join(threeRoot, p.slice("/three/".length));
    } else {
      const m = /^\/f\/(\d+)\/(.*)$/.exec(p);
      if (m && files[Number(m[1])]) file = path.join(path.dirname(files[Number(m[1])]), m[2]);
    }
    if (!file || !existsSync(file)) {
      return route.fulfill({ status: 404, body: "not found" });
    }
    const contentType = file.endsWith(".js") ? "text/javascript" : undefined;
    return route.fulfill({ path: file, contentType });
  });
  await page.goto(`${ORIGIN}/`);
  await page.waitForFunction(() => window.loadersReady === true, null, { timeout: 60000 });

  for (let i = 0; i < files.length; i++) {
    const url = `${ORIGIN}/f/${i}/${encodeURIComponent(path.basename(files[i]))}`;
    for (const k of Object.keys(log)) log[k].length = 0;
    let report;
    try {
      report = await page.evaluate(inspect, url);
    } catch (e) {
      report = { loadError: String(e && e.message ? e.message : e) };
    }
    report.file = files[i];
    Object.assign(report, JSON.parse(JSON.stringify(log)));
    console.log(JSON.stringify(report));
  }
} catch (e) {
  console.error(String(e && e.stack ? e.stack : e));
  failed = true;
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);

// Runs in the page: what GLTFLoader made of the file at `url`.
async function inspect(url) {
  const THREE = window.THREE;
  const gltf = await new window.GLTFLoader().loadAsync(url);
  const assoc = gltf.parser.associations;
  const scene = gltf.scene;
  const nodes = [];
  const meshes = [];
  const skinned = [];
  let cameras = 0;
  scene.traverse((o) => {
    const a = assoc.get(o) || {};
    if (a.nodes !== undefined) nodes.push({ index: a.nodes, name: o.name, type: o.type });
    if (o.isCamera) cameras++;
    if (o.isMesh) {
      const g = o.geometry;
      const morphs = (g.morphAttributes && g.morphAttributes.position) || [];
      const dict = o.morphTargetDictionary || {};
      const names = [];
      for (const [k, v] of Object.entries(dict)) names[v] = k;
      const material = Array.isArray(o.material) ? o.material[0] : o.material;
      const map = material && material.map;
      meshes.push({
        name: o.name,
        mesh: a.meshes,
        primitive: a.primitives,
        type: o.type,
        vertices: g.attributes.position ? g.attributes.position.count : 0,
        morphTargets: morphs.length,
        morphTargetsRelative: g.morphTargetsRelative === true,
        // Largest offset of each target: a target three.js read as all zeros shows here.
        morphMax: morphs.map((m) => {
          let x = 0;
          for (let k = 0; k < m.array.length; k++) x = Math.max(x, Math.abs(m.array[k]));
          return x;
        }),
        names,
        influences: o.morphTargetInfluences ? Array.from(o.morphTargetInfluences) : [],
        bones: o.isSkinnedMesh && o.skeleton ? o.skeleton.bones.map((b) => b.name) : [],
        material: material ? material.name : null,
        textureImage: map && map.image ? [map.image.width, map.image.height] : null,
      });
      if (o.isSkinnedMesh) skinned.push(o.name);
    }
  });
  // Each clip played alone from rest: the morph influences at a quarter, half and three
  // quarters of it against their rest values.
  const rest = new Map();
  scene.traverse((o) => {
    if (o.morphTargetInfluences) rest.set(o, Array.from(o.morphTargetInfluences));
  });
  const animations = [];
  for (const clip of gltf.animations) {
    const mixer = new THREE.AnimationMixer(scene);
    const action = mixer.clipAction(clip);
    action.play();
    const samples = [];
    for (const f of [0.25, 0.5, 0.75]) {
      mixer.setTime(clip.duration * f);
      const changed = [];
      for (const [o, r] of rest) {
        const names = [];
        for (const [k, v] of Object.entries(o.morphTargetDictionary || {})) names[v] = k;
        o.morphTargetInfluences.forEach((w, k) => {
          if (Math.abs(w - r[k]) > 1e-6) changed.push({ mesh: o.name, target: names[k] ?? k, weight: w });
        });
      }
      samples.push({ at: f, changed });
    }
    action.stop();
    mixer.uncacheRoot(scene);
    for (const [o, r] of rest) o.morphTargetInfluences.splice(0, r.length, ...r);
    animations.push({
      name: clip.name,
      duration: clip.duration,
      tracks: clip.tracks.map((t) => t.name),
      samples,
    });
  }
  return { nodes, meshes, skinned, cameras, animations };
}
