// Screenshots a baked glTF as three.js shows it (index.html, page.mjs) in headless Chromium:
//
//   node tools/bake-threejs/shoot.mjs MODEL.glb OUT.png [WIDTH HEIGHT]
//
// Serves this folder and the model (as /model.glb) on 127.0.0.1 at a port the system picks,
// drives Chromium ($CHROMIUM, else /usr/bin/chromium) through playwright-core, waits for the
// page's first frame and writes the PNG. Prints what the loader made of the file as JSON
// (material type, vertex colours, vertex count); exits 1 when the page failed.
import { createServer } from "node:http";
import { readFile, writeFile } from "node:fs/promises";
import { dirname, extname, join, normalize, sep } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

const [model, out, width = "640", height = "480"] = process.argv.slice(2);
if (!model || !out) {
  console.error("usage: node shoot.mjs MODEL.glb OUT.png [WIDTH HEIGHT]");
  process.exit(2);
}
const here = dirname(fileURLToPath(import.meta.url));
const TYPES = { ".html": "text/html", ".js": "text/javascript", ".mjs": "text/javascript",
  ".glb": "model/gltf-binary", ".gltf": "model/gltf+json" };

const server = createServer(async (request, response) => {
  const path = decodeURIComponent(new URL(request.url, "http://127.0.0.1").pathname);
  const file = path === "/model.glb" ? model : normalize(join(here, path === "/" ? "index.html" : path));
  if (file !== model && !file.startsWith(here + sep)) {
    response.writeHead(403).end();
    return;
  }
  try {
    const body = await readFile(file);
    response.writeHead(200, { "content-type": TYPES[extname(file)] ?? "application/octet-stream" });
    response.end(body);
  } catch {
    response.writeHead(404).end();
  }
});
await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
const port = server.address().port;

// The flags of viewer/src/browser.rs: as root no sandbox, SwiftShader's WebGL, nothing
// fetched from the network.
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--disable-background-networking", "--disable-component-update", "--no-first-run",
    "--disable-sync", "--disable-quic"],
});
let status = 0;
try {
  const page = await browser.newPage({ viewport: { width: Number(width), height: Number(height) } });
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  await page.goto(`http://127.0.0.1:${port}/index.html`);
  await page.waitForFunction(() => window.baked && window.baked.ready, null, { timeout: 60000 });
  const baked = await page.evaluate(() => window.baked);
  await writeFile(out, await page.screenshot({ type: "png" }));
  console.log(JSON.stringify({ ...baked, errors, screenshot: out }));
  status = baked.error || errors.length ? 1 : 0;
} finally {
  await browser.close();
  server.close();
}
process.exit(status);
