// What the browser checks share: finding an npm package in an `npm install --prefix`
// directory, and launching headless Chromium through playwright-core. A missing package or
// browser exits with code 3, which the Rust tests treat as "skip" (or fail where required).
import { createRequire } from "node:module";
import { existsSync } from "node:fs";
import path from "node:path";

// The entry point of npm package `request`, looked up in $envVar's prefix directory first,
// then through ordinary node_modules resolution; exits 3 when it is nowhere.
export function resolveIn(envVar, request) {
  const bases = [];
  if (process.env[envVar]) {
    bases.push(path.join(path.resolve(process.env[envVar]), "package.json"));
  }
  bases.push(import.meta.url);
  for (const base of bases) {
    try {
      return createRequire(base).resolve(request);
    } catch {
      // try the next place
    }
  }
  console.error(`${request} not found (set ${envVar})`);
  process.exit(3);
}

// Headless Chromium ($CHROMIUM_PATH or /usr/bin/chromium) with the network switched off;
// `webgl` adds software WebGL (ANGLE on SwiftShader), which pages that render need.
export async function launchChromium({ webgl = false } = {}) {
  const playwright = createRequire(import.meta.url)(resolveIn("VIEWER_BROWSER_DIR", "playwright-core"));
  const executablePath = process.env.CHROMIUM_PATH || "/usr/bin/chromium";
  if (!existsSync(executablePath)) {
    console.error(`no Chromium at ${executablePath} (set CHROMIUM_PATH)`);
    process.exit(3);
  }
  const args = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
  ];
  if (webgl) {
    args.push("--use-angle=swiftshader", "--enable-unsafe-swiftshader");
  }
  return playwright.chromium.launch({ executablePath, args });
}
