// The haarshift viewer's page: draws the mesh with the per-vertex radiance the server computes
// for every view (WebGL2), and sends the view state on every change. Packets and requests are
// described in viewer/src/protocol.rs.
'use strict';

const PACKET = { scene: 1, environment: 2, frame: 3, reference: 4, picture: 5, positions: 6, glb: 7 };
const $ = (id) => document.getElementById(id);

// Everything tests and the frame-rate script read over the DevTools protocol.
const viewer = {
  framesReceived: 0,   // frame packets received
  framesDrawn: 0,      // frames drawn (a frame that arrives before the last is drawn is not)
  drawnSeq: null,      // the newest state number the frame drawn answers
  frame: null,         // { header, radiance: Float32Array (V x 3) } of the last frame
  reference: null,     // { header, radiance } of the last reference
  scene: null,         // the scene's description
  state: null,         // the view state last sent
  notices: [],         // error notices from the server, in order
  timings: [],         // per frame received: the server's milliseconds and the round trip
  ready: false,        // the scene and the environment have arrived
  positionsReceived: 0, // a dynamic scene's position packets (its objects moved)
  webgl2: false,
};
window.haarshiftViewer = viewer;

const canvas = $('view');
const gl = canvas.getContext('webgl2', { antialias: false });
viewer.webgl2 = gl !== null;

// ---- the view state, from the URL's hash --------------------------------------------------

const params = new URLSearchParams(location.hash.slice(1));
const num = (name, fallback) => (params.has(name) && isFinite(+params.get(name)) ? +params.get(name) : fallback);
const state = {
  seq: 0,
  yaw: num('yaw', NaN), pitch: num('pitch', NaN), roll: num('roll', NaN),
  basis: params.get('basis') || 'haar',
  brdf: params.get('brdf') || 'lambert',
  brdf_rotation: params.get('brdf_rotation') || 'haar',
  keep_light: params.has('keep_light') ? num('keep_light', null) : null,
  keep_visibility: params.has('keep_visibility') ? num('keep_visibility', null) : null,
  depth: params.has('depth') ? num('depth', null) : null,
  keep_brdf: params.has('keep_brdf') ? num('keep_brdf', null) : null,
  rotation_cache: params.has('rotation_cache') ? num('rotation_cache', null) : 64,
  light_rotation: params.get('light_rotation') || 'prefiltered',
  eye: null,
  format: params.get('format') === 'f16' ? 'f16' : 'f32',
  error: params.get('error') === '1',
  // A dynamic scene's motion path frame and its objects' translations (x,y,z;x,y,z in the URL).
  path_frame: params.has('path_frame') ? num('path_frame', null) : null,
  objects: translationsFromUrl(params.get('objects')),
};

function translationsFromUrl(text) {
  if (!text) return null;
  const t = text.split(';').map((o) => o.split(',').map(Number));
  return t.every((o) => o.length === 3 && o.every(isFinite)) ? t : null;
}
// The camera, orbiting the point looked at: azimuth and elevation in degrees, distance.
const orbit = { azimuth: num('azimuth', NaN), elevation: num('elevation', NaN), distance: num('distance', NaN), target: null, fov: num('fov', NaN) };
let exposure = num('exposure', 0);
// `panel=0` hides the controls and the figures (a clean picture: screenshots, tests).
if (params.get('panel') === '0') for (const id of ['panel', 'stats']) $(id).style.display = 'none';
const fixedSize = params.has('width') && params.has('height') ? [num('width', 640), num('height', 480)] : null;

// ---- the connection ---------------------------------------------------------------------

const socket = new WebSocket(`ws://${location.host}/ws`);
socket.binaryType = 'arraybuffer';
socket.onmessage = (event) => (typeof event.data === 'string' ? notice(JSON.parse(event.data)) : packet(event.data));
socket.onclose = () => showMessage('the server closed the connection: reload to reconnect');

function notice(n) {
  if (n.type === 'error') {
    viewer.notices.push(n.message);
    showMessage(n.message);
  } else if (n.type === 'unchanged') {
    // The frame shown answers this state too.
    if (viewer.frame && viewer.drawnSeq === viewer.frame.header.seq) viewer.drawnSeq = n.seq;
  } else if (n.type === 'progress') {
    referenceStatus = `reference ${n.total ? Math.floor((100 * n.done) / n.total) : 0}%`;
    updateStats();
  }
}

function packet(buffer) {
  const words = new DataView(buffer);
  const kind = words.getUint32(0, true);
  const length = words.getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 8, length)));
  const start = Math.ceil((8 + length) / 4) * 4;
  if (kind === PACKET.scene) {
    sceneArrived(header, buffer, start);
  } else if (kind === PACKET.environment) {
    environmentArrived(header, new Float32Array(buffer, start));
  } else if (kind === PACKET.frame) {
    const radiance = header.format === 'f16' ? fromHalf(new Uint16Array(buffer, start)) : new Float32Array(buffer, start);
    const sent = sentAt.get(header.seq);
    for (const seq of sentAt.keys()) if (seq <= header.seq) sentAt.delete(seq);
    viewer.frame = { header, radiance, roundTripMs: sent === undefined ? undefined : performance.now() - sent };
    viewer.framesReceived += 1;
    if (playing && header.seq === state.seq) setTimeout(stepPath, PATH_FRAME_MS);
    viewer.timings.push({ encode: header.encode_ms, rotate: header.rotate_ms, shade: header.shade_ms, prepare: header.prepare_ms, roundTrip: viewer.frame.roundTripMs, at: performance.now() });
    if (viewer.timings.length > 10000) viewer.timings.shift();
    hideMessage();
    frameDirty = true;
  } else if (kind === PACKET.positions) {
    // A dynamic scene's objects moved: the frame that follows is shaded where they now are.
    gl.bindBuffer(gl.ARRAY_BUFFER, positionBuffer);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, new Float32Array(buffer, start, 3 * header.vertices));
    viewer.positionsReceived += 1;
  } else if (kind === PACKET.picture) {
    download(new Blob([new Uint8Array(buffer, start)], { type: 'image/x-exr' }), 'haarshift-view.exr');
  } else if (kind === PACKET.glb) {
    download(new Blob([new Uint8Array(buffer, start)], { type: 'model/gltf-binary' }), 'haarshift-view.glb');
  } else if (kind === PACKET.reference) {
    viewer.reference = { header, radiance: new Float32Array(buffer, start) };
    referenceStatus = `reference ready (${header.seconds.toFixed(1)} s)`;
    frameDirty = true;
  }
}

// IEEE half to float.
function fromHalf(h) {
  const out = new Float32Array(h.length);
  for (let i = 0; i < h.length; i++) {
    const s = h[i] & 0x8000 ? -1 : 1;
    const e = (h[i] >> 10) & 0x1f;
    const f = h[i] & 0x3ff;
    out[i] = e === 0 ? s * f * 2 ** -24 : e === 31 ? (f ? NaN : s * Infinity) : s * (1 + f / 1024) * 2 ** (e - 15);
  }
  return out;
}

let sendTimer = null;
const sentAt = new Map(); // a state's number to when it was sent
function send() {
  if (!viewer.ready || socket.readyState !== WebSocket.OPEN) return;
  state.seq += 1;
  state.eye = eyePosition();
  viewer.state = JSON.parse(JSON.stringify(state));
  sentAt.set(state.seq, performance.now());
  socket.send(JSON.stringify({ type: 'state', ...state }));
  if (sendTimer === null) sendTimer = setTimeout(() => { sendTimer = null; writeHash(); }, 250);
}

// ---- WebGL2 -------------------------------------------------------------------------------

const SRGB = `
vec3 srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}`;

const MESH_VS = `#version 300 es
in vec3 position;
in vec3 radiance;
uniform mat4 viewProjection;
out vec3 vRadiance;
void main() { gl_Position = viewProjection * vec4(position, 1.0); vRadiance = radiance; }`;

const MESH_FS = `#version 300 es
precision highp float;
in vec3 vRadiance;
uniform float exposure;
uniform bool display;
out vec4 colour;
${SRGB}
void main() { colour = vec4(display ? vRadiance : srgb(vRadiance * exposure), 1.0); }`;

const SKY_VS = `#version 300 es
out vec2 ndc;
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0;
  ndc = p;
  gl_Position = vec4(p, 0.999, 1.0);
}`;

// The environment as relight render draws it: the direction d of each pixel shows f(R d).
const SKY_FS = `#version 300 es
precision highp float;
in vec2 ndc;
uniform mat4 inverseViewProjection;
uniform vec3 eye;
uniform mat3 rotation;
uniform sampler2D environment;
uniform float exposure;
out vec4 colour;
${SRGB}
void main() {
  vec4 far = inverseViewProjection * vec4(ndc, 1.0, 1.0);
  vec3 d = rotation * normalize(far.xyz / far.w - eye);
  float theta = acos(clamp(d.y, -1.0, 1.0));
  float phi = atan(d.x, d.z);
  if (phi < 0.0) phi += 6.283185307179586;
  vec3 f = texture(environment, vec2(phi / 6.283185307179586, theta / 3.141592653589793)).rgb;
  colour = vec4(srgb(f * exposure), 1.0);
}`;

function program(vs, fs) {
  const p = gl.createProgram();
  for (const [type, source] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const s = gl.createShader(type);
    gl.shaderSource(s, source);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    gl.attachShader(p, s);
  }
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}

let meshProgram, skyProgram, vao, positionBuffer, radianceBuffer, indexCount = 0, envTexture = null;
if (gl) {
  meshProgram = program(MESH_VS, MESH_FS);
  skyProgram = program(SKY_VS, SKY_FS);
} else {
  showMessage('this browser has no WebGL2');
}

function sceneArrived(header, buffer, start) {
  viewer.scene = header;
  const v = header.vertices;
  const positions = new Float32Array(buffer, start, 3 * v);
  const triangles = new Uint32Array(buffer, start + 12 * v, 3 * header.triangles);
  vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  positionBuffer = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, positionBuffer);
  gl.bufferData(gl.ARRAY_BUFFER, positions, header.dynamic ? gl.DYNAMIC_DRAW : gl.STATIC_DRAW);
  let loc = gl.getAttribLocation(meshProgram, 'position');
  gl.enableVertexAttribArray(loc);
  gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
  radianceBuffer = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, radianceBuffer);
  gl.bufferData(gl.ARRAY_BUFFER, 12 * v, gl.DYNAMIC_DRAW);
  loc = gl.getAttribLocation(meshProgram, 'radiance');
  gl.enableVertexAttribArray(loc);
  gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
  const indices = gl.createBuffer();
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, indices);
  gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, triangles, gl.STATIC_DRAW);
  indexCount = 3 * header.triangles;
  gl.bindVertexArray(null);

  // The camera starts where relight render's default is, unless the URL says otherwise.
  const c = header.camera;
  orbit.target = c.look_at;
  const offset = c.position.map((x, i) => x - c.look_at[i]);
  const r = Math.hypot(...offset);
  if (!isFinite(orbit.distance)) orbit.distance = r;
  if (!isFinite(orbit.azimuth)) orbit.azimuth = (Math.atan2(offset[0], offset[2]) * 180) / Math.PI;
  if (!isFinite(orbit.elevation)) orbit.elevation = (Math.asin(offset[1] / r) * 180) / Math.PI;
  if (!isFinite(orbit.fov)) orbit.fov = c.fov;
  if (!isFinite(state.yaw)) [state.yaw, state.pitch, state.roll] = header.angles;
  if (!isFinite(state.pitch)) state.pitch = header.angles[1];
  if (!isFinite(state.roll)) state.roll = header.angles[2];
  setupControls(header);
}

function environmentArrived(header, rgb) {
  const { width, height } = header;
  const rgba = new Float32Array(4 * width * height);
  for (let i = 0; i < width * height; i++) rgba.set(rgb.subarray(3 * i, 3 * i + 3), 4 * i);
  envTexture = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, envTexture);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA16F, width, height, 0, gl.RGBA, gl.FLOAT, rgba);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  viewer.ready = true;
  send();
}

// ---- the camera ---------------------------------------------------------------------------

function eyePosition() {
  const a = (orbit.azimuth * Math.PI) / 180, e = (orbit.elevation * Math.PI) / 180;
  const t = orbit.target;
  return [t[0] + orbit.distance * Math.cos(e) * Math.sin(a), t[1] + orbit.distance * Math.sin(e), t[2] + orbit.distance * Math.cos(e) * Math.cos(a)];
}

const sub = (a, b) => a.map((x, i) => x - b[i]);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const normalise = (a) => { const n = Math.hypot(...a); return a.map((x) => x / n); };

// Column-major view-projection of relight render's camera: +Y up, vertical field of view.
function viewProjection(eye, aspect) {
  const f = normalise(sub(orbit.target, eye));
  let r = cross(f, [0, 1, 0]);
  if (Math.hypot(...r) < 1e-9) r = cross(f, [0, 0, Math.sign(f[1])]);
  r = normalise(r);
  const u = cross(r, f);
  const b = viewer.scene.bounds;
  const radius = 0.5 * Math.hypot(...sub(b.max, b.min)) || 1;
  const centre = b.min.map((x, i) => 0.5 * (x + b.max[i]));
  const d = Math.hypot(...sub(centre, eye));
  const near = Math.max(d - 1.5 * radius, 1e-3 * radius), far = d + 1.5 * radius;
  const t = 1 / Math.tan((orbit.fov * Math.PI) / 360);
  const view = [r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0, -dot(r, eye), -dot(u, eye), dot(f, eye), 1];
  const proj = [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0, (2 * far * near) / (near - far), 0];
  return multiply(proj, view);
}

function multiply(a, b) {
  const out = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) out[4 * c + r] += a[4 * k + r] * b[4 * c + k];
  return out;
}

function invert(m) {
  // Gauss-Jordan on the 4 x 4 (column-major in, column-major out).
  const a = [0, 1, 2, 3].map((r) => [0, 1, 2, 3].map((c) => m[4 * c + r]).concat([0, 1, 2, 3].map((c) => (c === r ? 1 : 0))));
  for (let c = 0; c < 4; c++) {
    let p = c;
    for (let r = c + 1; r < 4; r++) if (Math.abs(a[r][c]) > Math.abs(a[p][c])) p = r;
    [a[c], a[p]] = [a[p], a[c]];
    const s = a[c][c];
    for (let k = 0; k < 8; k++) a[c][k] /= s;
    for (let r = 0; r < 4; r++) if (r !== c) { const q = a[r][c]; for (let k = 0; k < 8; k++) a[r][k] -= q * a[c][k]; }
  }
  const out = new Array(16);
  for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) out[4 * c + r] = a[r][4 + c];
  return out;
}

// ---- drawing ------------------------------------------------------------------------------

let frameDirty = false;
let referenceStatus = '';
let errorSummary = '';

function resize() {
  const [w, h] = fixedSize || [window.innerWidth, window.innerHeight];
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
    canvas.style.width = `${w}px`;
    canvas.style.height = `${h}px`;
    frameDirty = true;
  }
}

// The colours drawn per vertex: the radiance, or its error against the reference in false
// colour (black to red: 0 to 10% of the reference's RMS) when the error view is on and the
// reference is of the frame's lighting and material.
function vertexColours() {
  const frame = viewer.frame;
  errorSummary = '';
  if (!state.error) return { colours: frame.radiance, display: false };
  const ref = viewer.reference;
  const sent = frame.header.state;
  // (A dynamic scene's path frame adds its yaw; its objects must be where the frame has them.)
  const same = ref && sent && ref.header.yaw === sent.yaw + (frame.header.path_yaw ?? 0) && ref.header.pitch === sent.pitch && ref.header.roll === sent.roll && ref.header.brdf === sent.brdf &&
    (ref.header.eye === null || (sent.eye && ref.header.eye.every((x, i) => x === sent.eye[i]))) &&
    JSON.stringify(ref.header.translations) === JSON.stringify(frame.header.translations ?? []);
  if (!same) {
    if (!referenceStatus.startsWith('reference ') || referenceStatus.startsWith('reference ready')) referenceStatus = 'reference: waiting for this view';
    return { colours: frame.radiance, display: false };
  }
  const a = frame.radiance, b = ref.radiance;
  let sq = 0, ref2 = 0;
  for (let i = 0; i < a.length; i++) { sq += (a[i] - b[i]) ** 2; ref2 += b[i] ** 2; }
  const rms = Math.sqrt(ref2 / a.length) || 1;
  errorSummary = `error RMS ${(Math.sqrt(sq / a.length) / rms).toExponential(2)} of the reference's`;
  const colours = new Float32Array(a.length);
  const ramp = [[0, 0, 0], [0, 0, 1], [0, 1, 1], [0, 1, 0], [1, 1, 0], [1, 0, 0]];
  for (let v = 0; v < a.length / 3; v++) {
    const e = Math.hypot(a[3 * v] - b[3 * v], a[3 * v + 1] - b[3 * v + 1], a[3 * v + 2] - b[3 * v + 2]) / (0.1 * rms);
    const x = Math.min(Math.max(e, 0), 1) * (ramp.length - 1);
    const i = Math.min(Math.floor(x), ramp.length - 2), t = x - i;
    for (let c = 0; c < 3; c++) colours[3 * v + c] = ramp[i][c] * (1 - t) + ramp[i + 1][c] * t;
  }
  return { colours, display: true };
}

function draw() {
  requestAnimationFrame(draw);
  resize();
  if (!frameDirty || !viewer.frame || !envTexture) return;
  frameDirty = false;
  render();
  viewer.framesDrawn += 1;
  viewer.drawnSeq = viewer.frame.header.seq;
  recordRate();
  updateStats();
}
if (gl) requestAnimationFrame(draw);

// Draws the last frame (the drawing buffer is not preserved: a picture of it is taken in the
// same task as the drawing).
function render() {
  const { colours, display } = vertexColours();
  gl.bindBuffer(gl.ARRAY_BUFFER, radianceBuffer);
  gl.bufferSubData(gl.ARRAY_BUFFER, 0, colours);
  gl.viewport(0, 0, canvas.width, canvas.height);
  const eye = eyePosition();
  const vp = viewProjection(eye, canvas.width / canvas.height);
  const scale = 2 ** exposure;
  const m = viewer.frame.header.rotation;
  gl.disable(gl.DEPTH_TEST);
  gl.useProgram(skyProgram);
  gl.uniformMatrix4fv(gl.getUniformLocation(skyProgram, 'inverseViewProjection'), false, invert(vp));
  gl.uniform3fv(gl.getUniformLocation(skyProgram, 'eye'), eye);
  // SphereRotation's rows, as GLSL's column-major mat3.
  gl.uniformMatrix3fv(gl.getUniformLocation(skyProgram, 'rotation'), false, [0, 1, 2].flatMap((c) => [0, 1, 2].map((r) => m[r][c])));
  gl.uniform1f(gl.getUniformLocation(skyProgram, 'exposure'), scale);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, envTexture);
  gl.uniform1i(gl.getUniformLocation(skyProgram, 'environment'), 0);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  gl.enable(gl.DEPTH_TEST);
  gl.clear(gl.DEPTH_BUFFER_BIT);
  gl.useProgram(meshProgram);
  gl.uniformMatrix4fv(gl.getUniformLocation(meshProgram, 'viewProjection'), false, vp);
  gl.uniform1f(gl.getUniformLocation(meshProgram, 'exposure'), scale);
  gl.uniform1i(gl.getUniformLocation(meshProgram, 'display'), display ? 1 : 0);
  gl.bindVertexArray(vao);
  gl.drawElements(gl.TRIANGLES, indexCount, gl.UNSIGNED_INT, 0);
  gl.bindVertexArray(null);
}

// Frames received and drawn per second over the last two seconds.
const drawTimes = [];
function recordRate() {
  const now = performance.now();
  drawTimes.push(now);
  while (drawTimes.length && now - drawTimes[0] > 2000) drawTimes.shift();
}

function updateStats() {
  const f = viewer.frame;
  if (!f) return;
  const h = f.header;
  const lines = [
    `${viewer.scene.vertices} vertices, ${viewer.scene.param} ${viewer.scene.resolution}`,
    `lighting rotation + encoding ${h.encode_ms.toFixed(1)} ms`,
    `BRDF rotations ${h.rotate_ms.toFixed(1)} ms`,
    `shading ${h.shade_ms.toFixed(1)} ms (rotations included)`,
    `round trip ${f.roundTripMs === undefined ? '-' : f.roundTripMs.toFixed(1)} ms (transfer: less the above)`,
    h.prepare_ms > 0 ? `shader prepared in ${h.prepare_ms.toFixed(0)} ms` : '',
    `lighting coefficients ${h.light_coefficients ?? '-'}`,
    `${(drawTimes.length / 2).toFixed(1)} frames drawn / s`,
    h.description,
    referenceStatus,
    errorSummary,
  ];
  $('stats').textContent = lines.filter((l) => l).join('\n');
}

// ---- controls -----------------------------------------------------------------------------

function setupControls(scene) {
  for (const [id, max] of [['keep_light', scene.texels], ['keep_visibility', scene.texels], ['keep_brdf', scene.texels]]) {
    const el = $(id);
    el.max = max;
    el.value = state[id] ?? max;
    el.oninput = () => { state[id] = +el.value >= max ? null : Math.max(1, +el.value); send(); };
  }
  const depth = $('depth');
  depth.max = scene.levels;
  depth.value = state.depth ?? scene.levels;
  depth.oninput = () => { state.depth = +depth.value >= scene.levels ? null : +depth.value; send(); };
  $('basis').value = state.basis;
  $('basis').onchange = () => { state.basis = $('basis').value; send(); };
  // Measured BRDFs the server was given (--merl), by name.
  for (const m of scene.measured) $('material').add(new Option(`merl:${m.name}`, `merl:${m.name}`));
  const [kind, exponent] = state.brdf.split(':');
  if (kind === 'merl') $('material').value = state.brdf;
  else $('material').value = kind === 'blinn' ? 'blinn' : kind === 'phong' ? 'phong' : 'lambert';
  if (exponent && kind !== 'merl') $('exponent').value = exponent;
  const material = () => {
    const m = $('material').value;
    state.brdf = m === 'lambert' || m.startsWith('merl:') ? m : `${m}:${+$('exponent').value}`;
    send();
  };
  $('material').onchange = material;
  $('exponent').onchange = material;
  // A cache with bounced light baked its albedo and a Lambertian BRDF in: the menu is fixed
  // (the server refuses any other material too).
  if (scene.bounces) {
    for (const id of ['material', 'exponent']) {
      $(id).disabled = true;
      $(id).title = `fixed: the cache holds ${scene.bounces} bounces of light gathered with its albedo`;
    }
  }
  $('light_rotation').value = state.light_rotation;
  $('light_rotation').onchange = () => { state.light_rotation = $('light_rotation').value; send(); };
  $('brdf_rotation').value = state.brdf_rotation;
  $('brdf_rotation').onchange = () => { state.brdf_rotation = $('brdf_rotation').value; send(); };
  $('rotation_cache').value = state.rotation_cache ?? 0;
  $('rotation_cache').onchange = () => { const n = +$('rotation_cache').value; state.rotation_cache = n > 0 ? n : null; send(); };
  $('exposure').value = exposure;
  $('exposure').oninput = () => { exposure = +$('exposure').value; frameDirty = true; writeHash(); };
  $('format').value = state.format;
  $('format').onchange = () => { state.format = $('format').value; send(); };
  $('error').checked = state.error;
  $('error').onchange = () => { state.error = $('error').checked; $('legend').style.display = state.error ? 'block' : 'none'; frameDirty = true; send(); };
  $('legend').style.display = state.error ? 'block' : 'none';
  if (scene.dynamic) setupDynamic(scene.dynamic);
  $('copy').onclick = () => {
    const c = command();
    $('command').value = c;
    if (navigator.clipboard) navigator.clipboard.writeText(c).catch(() => {});
  };
  $('save').onclick = () => {
    if (viewer.frame && envTexture) render();
    canvas.toBlob((blob) => download(blob, 'haarshift-view.png'));
  };
  // The linear radiance, drawn by the server's rasteriser from the last frame.
  $('exr').onclick = () => socket.send(JSON.stringify({ type: 'picture', look_at: orbit.target, fov: orbit.fov, width: canvas.width, height: canvas.height }));
  // The mesh with the last frame's radiance as glTF colours (relight bake's file), at the
  // page's exposure.
  $('glb').onclick = () => socket.send(JSON.stringify({ type: 'glb', exposure }));
}

// A dynamic scene: its objects are dragged (the one chosen) and its motion path played; the
// controls of what it does not offer (other bases, the page's materials) are hidden.
let dragTarget = -1;
let playing = false;
const PATH_FRAME_MS = 40; // at most 25 path frames a second, at most one ahead of the server
function setupDynamic(dynamic) {
  for (const id of ['basis', 'material', 'exponent', 'brdf_rotation', 'keep_brdf', 'rotation_cache', 'depth']) $(id).parentElement.style.display = 'none';
  $('dynamic').style.display = 'block';
  dynamic.objects.forEach((o, k) => $('drag_target').add(new Option(o.name ?? `object ${k}`, k)));
  $('drag_target').onchange = () => { dragTarget = +$('drag_target').value; };
  const frames = dynamic.path_frames;
  if (!frames) {
    for (const id of ['path_frame', 'play']) ($(id).parentElement.tagName === 'LABEL' ? $(id).parentElement : $(id)).style.display = 'none';
    return;
  }
  $('path_frame').max = frames - 1;
  $('path_frame').value = state.path_frame ?? 0;
  $('path_frame').oninput = () => { state.path_frame = +$('path_frame').value; state.objects = null; send(); };
  $('play').onclick = () => {
    playing = !playing;
    $('play').textContent = playing ? 'stop' : 'play the path';
    if (playing) stepPath();
  };
}

function stepPath() {
  if (!playing) return;
  const frames = viewer.scene.dynamic.path_frames;
  state.path_frame = ((state.path_frame ?? -1) + 1) % frames;
  state.objects = null;
  $('path_frame').value = state.path_frame;
  send();
}

// The translations drawn now: the last frame's (a path frame's placements), else the scene's.
function translations() {
  const t = state.objects ?? viewer.frame?.header.translations ?? viewer.scene.dynamic.objects.map((o) => o.translate);
  return t.map((x) => x.slice());
}

function download(blob, name) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
}

// Dragging: the lighting (left button), the camera (shift or right button); the wheel zooms.
let drag = null;
canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('pointerdown', (e) => {
  drag = { x: e.clientX, y: e.clientY, camera: e.shiftKey || e.button === 2 };
  canvas.setPointerCapture(e.pointerId);
});
canvas.addEventListener('pointerup', () => { drag = null; });
canvas.addEventListener('pointermove', (e) => {
  if (!drag || !viewer.ready) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX;
  drag.y = e.clientY;
  if (drag.camera) {
    orbit.azimuth -= 0.4 * dx;
    orbit.elevation = Math.min(89, Math.max(-89, orbit.elevation + 0.4 * dy));
    frameDirty = true;
  } else if (dragTarget >= 0) {
    // The object slides on the ground: right with the camera's right, up the screen away from
    // the eye, a pixel the size of one at the point looked at.
    const a = (orbit.azimuth * Math.PI) / 180;
    const perPixel = (2 * orbit.distance * Math.tan((orbit.fov * Math.PI) / 360)) / canvas.height;
    const t = translations();
    t[dragTarget][0] += perPixel * (dx * Math.cos(a) + dy * Math.sin(a));
    t[dragTarget][2] += perPixel * (-dx * Math.sin(a) + dy * Math.cos(a));
    state.objects = t;
    state.path_frame = null;
  } else {
    state.yaw = (state.yaw + 0.5 * dx) % 360;
    state.pitch = Math.min(90, Math.max(-90, state.pitch + 0.5 * dy));
  }
  send();
});
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  orbit.distance *= e.deltaY > 0 ? 1.1 : 1 / 1.1;
  frameDirty = true;
  send();
}, { passive: false });

// ---- sharing ------------------------------------------------------------------------------

const round = (x) => +x.toFixed(6);

// The relight render command that computes this view's frame and picture (relight scene for a
// dynamic scene: objects the page moved are said in a comment, the scene file holds where).
function command() {
  const s = viewer.scene;
  const eye = eyePosition().map(round);
  if (s.dynamic) {
    const yaw = round(state.yaw + (viewer.frame?.header.path_yaw ?? 0));
    // The page's visibility budget replaces the build's.
    const build = s.dynamic.build_flags.filter((f) => !(state.keep_visibility && f.startsWith('--keep-visibility ')));
    const parts = ['haarshift relight scene', quote(s.cache), '--env', quote(s.env), `--yaw ${yaw}`, `--pitch ${round(state.pitch)}`, `--roll ${round(state.roll)}`, ...build];
    if (state.light_rotation !== 'source') parts.push(`--light-rotation ${state.light_rotation}`);
    if (state.keep_light) parts.push(`--keep-light ${state.keep_light}`);
    if (state.keep_visibility) parts.push(`--keep-visibility ${state.keep_visibility}`);
    parts.push(`--camera ${eye.join(',')}`, `--look-at ${orbit.target.map(round).join(',')}`, `--fov ${round(orbit.fov)}`);
    parts.push(`--width ${canvas.width} --height ${canvas.height}`);
    if (exposure) parts.push(`--exposure ${exposure}`);
    parts.push('-o view.png --vertices view.npy');
    const moved = viewer.frame?.header.translations?.map((t, k) => [t, s.dynamic.objects[k]]).filter(([t, o]) => t.some((x, i) => x !== o.translate[i]));
    if (moved?.length) parts.push(`  # with ${moved.map(([t, o]) => `${o.name ?? 'an object'} translated to ${t.map(round).join(',')}`).join(', ')} in the scene file`);
    return parts.join(' ');
  }
  const parts = ['haarshift relight render', quote(s.cache), '--env', quote(s.env), `--yaw ${round(state.yaw)}`, `--pitch ${round(state.pitch)}`, `--roll ${round(state.roll)}`];
  if (state.basis !== 'haar') parts.push(`--basis ${state.basis}`);
  if (state.light_rotation !== 'source' && state.basis !== 'ambient') parts.push(`--light-rotation ${state.light_rotation}`);
  if (state.brdf !== 'lambert') {
    const measured = s.measured.find((m) => `merl:${m.name}` === state.brdf);
    parts.push(`--brdf ${measured ? quote(`merl:${measured.path}`) : state.brdf}`);
    if (state.brdf_rotation !== 'haar') parts.push(`--brdf-rotation ${state.brdf_rotation}`);
    if (state.rotation_cache) parts.push(`--rotation-cache ${state.rotation_cache}`);
    if (state.keep_brdf) parts.push(`--keep-brdf ${state.keep_brdf}`);
  }
  if (state.keep_light) parts.push(`--keep-light ${state.keep_light}`);
  if (state.keep_visibility) parts.push(`--keep-visibility ${state.keep_visibility}`);
  if (state.depth !== null) parts.push(`--depth ${state.depth}`);
  parts.push(`--camera ${eye.join(',')}`, `--look-at ${orbit.target.map(round).join(',')}`, `--fov ${round(orbit.fov)}`);
  parts.push(`--width ${canvas.width} --height ${canvas.height}`);
  if (exposure) parts.push(`--exposure ${exposure}`);
  parts.push('-o view.png --vertices view.npy');
  return parts.join(' ');
}
viewer.command = command;

function quote(path) {
  return /^[\w./-]+$/.test(path) ? path : `'${String(path).replace(/'/g, "'\\''")}'`;
}

function writeHash() {
  const p = new URLSearchParams();
  for (const k of ['yaw', 'pitch', 'roll']) p.set(k, round(state[k]));
  for (const k of ['basis', 'brdf', 'brdf_rotation', 'light_rotation', 'format']) p.set(k, state[k]);
  for (const k of ['keep_light', 'keep_visibility', 'depth', 'keep_brdf', 'rotation_cache']) if (state[k] !== null) p.set(k, state[k]);
  if (state.error) p.set('error', '1');
  if (state.path_frame !== null) p.set('path_frame', state.path_frame);
  if (state.objects) p.set('objects', state.objects.map((t) => t.map(round).join(',')).join(';'));
  for (const k of ['azimuth', 'elevation', 'distance', 'fov']) p.set(k, round(orbit[k]));
  if (exposure) p.set('exposure', exposure);
  if (fixedSize) { p.set('width', fixedSize[0]); p.set('height', fixedSize[1]); }
  if (params.get('panel') === '0') p.set('panel', '0');
  history.replaceState(null, '', `#${p}`);
}

// Sets part of the state, as the controls would (the tests' and scripts' entry point).
viewer.setState = (changes) => {
  Object.assign(state, changes);
  send();
};

function showMessage(text) {
  const el = $('message');
  el.textContent = text;
  el.style.display = 'block';
}

function hideMessage() {
  $('message').style.display = 'none';
}
