// mccs view: the page. Events from /events (server-sent), controls as POSTs, the patch
// in plain WebGL, the plots on a 2-D canvas. No library, no build step (docs/view.md).
'use strict';

const HISTORY_S = 10;
const ARROW_MM_PER_N = 8;
const CONE_MM = 6;

const state = {
  id: null, holder: null, connected: false, deviceError: null,
  hello: null, status: null, t: null, mesh: null,
  history: [], // {time, f: [x, y, z], fm, gain, flags}
  gaps: { telemetry: 0, mesh: 0 }, lastSeq: { t: null, mesh: null },
  pageDropped: 0, meshes: 0, samples: 0, paused: false,
};
// What the 3-D view last drew: its matrix and mesh.
const drawn = { matrix: null, mesh: null };
const $ = (id) => document.getElementById(id);

// ---- events -------------------------------------------------------------------------

function on(source, kind, fn) {
  source.addEventListener(kind, (e) => fn(JSON.parse(e.data)));
}

function connect() {
  const es = new EventSource('/events');
  es.onopen = () => { state.connected = true; showBanner(); };
  es.onerror = () => { state.connected = false; state.id = null; showBanner(); };
  on(es, 'welcome', (d) => { state.id = d.id; state.holder = d.holder; showRole(); });
  on(es, 'control', (d) => { state.holder = d.holder; showRole(); });
  on(es, 'hello', (d) => { state.hello = d; showFacts(); makePoseSliders(); resetCamera(); });
  on(es, 'status', (d) => { state.status = d; state.deviceError = null; showStatus(); showBanner(); });
  on(es, 'device', (d) => { state.deviceError = d.error; showBanner(); });
  on(es, 'page', (d) => { state.pageDropped = d.dropped; });
  on(es, 't', takeTelemetry);
  on(es, 'mesh', (m) => {
    countGap('mesh', m.seq);
    state.mesh = m; state.meshes += 1;
  });
}

function countGap(kind, seq) {
  const last = state.lastSeq[kind === 'mesh' ? 'mesh' : 't'];
  if (last !== null && seq > last + 1) state.gaps[kind] += seq - last - 1;
  state.lastSeq[kind === 'mesh' ? 'mesh' : 't'] = seq;
}

function takeTelemetry(t) {
  countGap('telemetry', t.seq);
  state.t = t; state.samples += 1;
  const f = t.force;
  state.history.push({ time: t.time_s, f, fm: Math.hypot(f[0], f[1], f[2]), gain: t.gain, flags: t.flags });
  const from = t.time_s - HISTORY_S;
  while (state.history.length && state.history[0].time < from) state.history.shift();
}

function flagBit(name) {
  const i = state.hello ? state.hello.flags.indexOf(name) : -1;
  return i < 0 ? 0 : 1 << i;
}
const has = (flags, name) => (flags & flagBit(name)) !== 0;

// ---- panels -------------------------------------------------------------------------

function showBanner() {
  const b = $('banner');
  let text = '';
  if (!state.connected) text = 'Connection to mccs view lost: it was stopped, or the network dropped. Retrying…';
  else if (state.deviceError) text = 'Device: ' + state.deviceError;
  b.textContent = text;
  b.classList.toggle('hidden', text === '');
}

function holds() { return state.id !== null && state.id === state.holder; }

function showRole() {
  $('role').textContent = holds() ? 'this page holds the controls'
    : 'watching: another page holds the controls';
  for (const el of document.querySelectorAll('#controls button, #controls input')) el.disabled = !holds();
}

function fill(dl, rows) {
  dl.replaceChildren(...rows.flatMap(([k, v]) => {
    const dt = document.createElement('dt'); dt.textContent = k;
    const dd = document.createElement('dd'); dd.textContent = v;
    return [dt, dd];
  }));
}

const n3 = (v, d = 1) => v.map((x) => x.toFixed(d)).join(', ');

function showFacts() {
  const h = state.hello;
  $('addr').textContent = h.addr + (h.demo ? ' (the demo\u2019s soft device)' : '');
  fill($('facts'), [
    ['device', h.device + (h.simulated ? ' (simulated plant)' : '')],
    ['contact', h.contact], ['tick', h.tick_hz + ' Hz'],
    ['patch', h.grid + ' \u00d7 ' + h.grid + ' nodes'],
    ['tissue', h.tissue[0] + ' \u00d7 ' + h.tissue[1] + ' nodes, ' + h.spacing_mm + ' mm apart'],
    ['friction', '\u03bcs ' + h.friction[0].toFixed(3) + ', \u03bck ' + h.friction[1].toFixed(3)],
    ['force clamp', h.force_clamp_n + ' N'],
  ]);
}

function showStatus() {
  const s = state.status;
  fill($('status'), [
    ['armed', s.armed ? 'yes' : 'no'], ['fault', s.fault], ['gain', s.gain.toFixed(3)],
    ['ticks', s.ticks], ['overruns', s.overruns], ['bad frames (device)', s.bad_frames],
    ['bad frames (here)', s.bad_frames_in], ['dropped telemetry', s.dropped_telemetry],
    ['dropped meshes', s.dropped_mesh], ['rx dropped', s.rx_dropped],
    ['checking a tissue', s.checking ? 'yes' : 'no'],
    ['pose', n3(s.pose) + ' mm; ' + n3(s.rotation_deg) + '\u00b0'], ['pages watching', s.pages],
  ]);
  const lost = s.dropped_telemetry + s.dropped_mesh + s.rx_dropped + s.stream_drops
    + state.gaps.telemetry + state.gaps.mesh + state.pageDropped;
  const d = $('drops');
  d.textContent = 'Frames dropped: telemetry ' + (s.dropped_telemetry + state.gaps.telemetry)
    + ', meshes ' + (s.dropped_mesh + state.gaps.mesh) + ', to the device ' + s.rx_dropped
    + ', in this view ' + (s.stream_drops + state.pageDropped)
    + ' (the page follows at the link\u2019s rates and skips what it misses).';
  d.classList.toggle('hidden', lost === 0);
}

// ---- controls -----------------------------------------------------------------------

async function post(path, body) {
  $('answer').textContent = path.slice(1) + '\u2026';
  try {
    const r = await fetch(path, { method: 'POST', body: body || '', headers: { 'X-Mccs-Page': String(state.id) } });
    const a = await r.json();
    $('answer').textContent = (a.ok ? '' : 'refused: ') + a.message;
    return a;
  } catch (e) {
    $('answer').textContent = 'failed: ' + e;
    return { ok: false, message: String(e) };
  }
}

const POSE = [['x', 'mm'], ['y', 'mm'], ['z', 'mm'], ['rx', '\u00b0'], ['ry', '\u00b0'], ['rz', '\u00b0']];

function makePoseSliders() {
  const box = $('pose');
  if (box.childElementCount) return;
  const [lo, hi] = state.hello.workspace_mm;
  const s = state.status;
  POSE.forEach(([name, unit], i) => {
    const label = document.createElement('label');
    const input = document.createElement('input');
    input.type = 'range'; input.id = 'pose-' + name;
    if (i < 3) { input.min = lo[i]; input.max = hi[i]; input.step = 0.5; input.value = s ? s.pose[i] : (lo[i] + hi[i]) / 2; }
    else { input.min = -180; input.max = 180; input.step = 1; input.value = s ? s.rotation_deg[i - 3] : 0; }
    const out = document.createElement('output');
    const show = () => { out.textContent = Number(input.value).toFixed(1) + ' ' + unit; };
    input.oninput = show; show();
    input.onchange = () => post('/pose', POSE.map(([n]) => $('pose-' + n).value).join(','));
    label.append(name + ' ', input, out);
    box.append(label);
  });
  showRole();
}

$('arm').onclick = () => post('/arm');
$('disarm').onclick = () => post('/disarm');
$('tissue-file').onchange = async (e) => {
  const file = e.target.files[0];
  if (!file) return;
  $('answer').textContent = 'loading ' + file.name + ' (the device checks it first)\u2026';
  await post('/load', await file.text());
};

// ---- 3-D ----------------------------------------------------------------------------

const canvas = $('scene');
const gl = canvas.getContext('webgl', { preserveDrawingBuffer: true, antialias: true });
const camera = { yaw: -2.2, pitch: 0.7, dist: 100, target: [0, 0, 0] };

function shader(type, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src); gl.compileShader(s);
  return s;
}
const program = gl.createProgram();
gl.attachShader(program, shader(gl.VERTEX_SHADER,
  'attribute vec3 p; attribute vec3 c; uniform mat4 m; varying vec3 v;'
  + 'void main() { gl_Position = m * vec4(p, 1.0); v = c; }'));
gl.attachShader(program, shader(gl.FRAGMENT_SHADER,
  'precision mediump float; varying vec3 v; void main() { gl_FragColor = vec4(v, 1.0); }'));
gl.linkProgram(program);
const loc = { p: gl.getAttribLocation(program, 'p'), c: gl.getAttribLocation(program, 'c'), m: gl.getUniformLocation(program, 'm') };
const buffer = gl.createBuffer();

// Column-major 4×4 matrices, as WebGL takes them.
function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
}
function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
function unit(a) { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }
function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
function lookAt(eye, target, up) {
  const z = unit(sub(eye, target)), x = unit(cross(up, z)), y = cross(z, x);
  return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
}
function mul(a, b) {
  const o = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) o[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return o;
}
function apply(m, p) {
  const v = [0, 0, 0, 0];
  for (let r = 0; r < 4; r++) v[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
  return v;
}

function extentMm() {
  const h = state.hello;
  return h ? [(h.tissue[0] - 1) * h.spacing_mm, (h.tissue[1] - 1) * h.spacing_mm] : [40, 40];
}

// The camera follows the window (the tissue frame's origin is the tissue's centre).
function resetCamera() {
  const h = state.hello;
  camera.dist = h ? 2.4 * (h.grid - 1) * h.spacing_mm : 60;
}

// The camera eases onto the window in time, not in frames (a tenth of the way a frame
// lagged seconds behind a window that jumped, where the browser drew few frames): 63 %
// of the way in FOLLOW_S.
const FOLLOW_S = 0.15;
let followedAt = null;
function follow(now) {
  if (!state.t) return;
  const dt = followedAt === null ? 1 : Math.min(1, (now - followedAt) / 1000);
  followedAt = now;
  const k = 1 - Math.exp(-dt / FOLLOW_S);
  const [wx, wy] = state.t.window, c = camera.target;
  c[0] += k * (wx - c[0]); c[1] += k * (wy - c[1]); c[2] = -1;
}

function matrix() {
  const c = Math.cos(camera.pitch);
  const eye = [camera.target[0] + camera.dist * c * Math.cos(camera.yaw),
    camera.target[1] + camera.dist * c * Math.sin(camera.yaw),
    camera.target[2] + camera.dist * Math.sin(camera.pitch)];
  return mul(perspective(0.8, canvas.width / canvas.height, 1, 2000), lookAt(eye, camera.target, [0, 0, 1]));
}

let dragging = null;
canvas.onmousedown = (e) => { dragging = [e.clientX, e.clientY]; };
window.onmouseup = () => { dragging = null; };
window.onmousemove = (e) => {
  if (!dragging) return;
  camera.yaw -= (e.clientX - dragging[0]) * 0.01;
  camera.pitch = Math.max(-1.5, Math.min(1.5, camera.pitch + (e.clientY - dragging[1]) * 0.01));
  dragging = [e.clientX, e.clientY];
};
canvas.onwheel = (e) => { e.preventDefault(); camera.dist = Math.max(5, Math.min(1500, camera.dist * Math.exp(e.deltaY * 0.001))); };

// Depth (mm into the tissue) to colour: pale tissue at the surface, dark red deep down.
function depthColour(z, deepest) {
  const t = Math.max(0, Math.min(1, -z / deepest));
  return [0.95 - 0.45 * t, 0.66 - 0.6 * t, 0.62 - 0.5 * t];
}

// The device's frame to the tissue's: the pose's rotation (Rz Ry Rx) transposed.
function toTissue(v) {
  const r = state.status ? state.status.rotation_deg.map((a) => a * Math.PI / 180) : [0, 0, 0];
  const [cx, cy, cz] = r.map(Math.cos), [sx, sy, sz] = r.map(Math.sin);
  const R = [[cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
    [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
    [-sy, cy * sx, cy * cx]];
  return [0, 1, 2].map((j) => R[0][j] * v[0] + R[1][j] * v[1] + R[2][j] * v[2]);
}

function drawScene() {
  const tris = [], lines = [];
  const line = (a, b, c) => { lines.push(...a, ...c, ...b, ...c); };
  const [w, d] = extentMm().map((e) => e / 2);
  const grey = [0.55, 0.55, 0.55];
  line([-w, -d, 0], [w, -d, 0], grey); line([w, -d, 0], [w, d, 0], grey);
  line([w, d, 0], [-w, d, 0], grey); line([-w, d, 0], [-w, -d, 0], grey);
  const m = state.mesh, t = state.t, h = state.hello;
  if (m) {
    const deepest = Math.max(0.5, ...m.nodes.map((n) => -n[4]));
    for (const tri of m.triangles) {
      for (const k of tri) { const n = m.nodes[k]; tris.push(n[2], n[3], n[4], ...depthColour(n[4], deepest)); }
      const [a, b, c] = tri.map((k) => m.nodes[k].slice(2));
      const edge = [0.45, 0.25, 0.25];
      line(a, b, edge); line(b, c, edge); line(c, a, edge);
    }
  }
  if (t && h) {
    // The window: the patch's outer ring, (grid − 1) spacings across, about its centre.
    const e = (h.grid - 1) * h.spacing_mm / 2, [wx, wy] = t.window, blue = [0.08, 0.4, 0.75];
    line([wx - e, wy - e, 0], [wx + e, wy - e, 0], blue); line([wx + e, wy - e, 0], [wx + e, wy + e, 0], blue);
    line([wx + e, wy + e, 0], [wx - e, wy + e, 0], blue); line([wx - e, wy + e, 0], [wx - e, wy - e, 0], blue);
    const crossAt = (p, c, s) => {
      line([p[0] - s, p[1], p[2]], [p[0] + s, p[1], p[2]], c);
      line([p[0], p[1] - s, p[2]], [p[0], p[1] + s, p[2]], c);
      line([p[0], p[1], p[2] - s], [p[0], p[1], p[2] + s], c);
    };
    crossAt(t.probe, [0.1, 0.54, 0.23], 2);
    if (has(t.flags, 'contact')) {
      crossAt(t.proxy, [0.88, 0.66, 0], 1.5);
      const slip = has(t.flags, 'slipping'), c = slip ? [0.85, 0.1, 0.1] : [0, 0.51, 0.56];
      const r = CONE_MM * Math.min(2, h.friction[0]);
      let prev = null;
      for (let k = 0; k <= 16; k++) {
        const a = (k / 16) * 2 * Math.PI;
        const rim = [t.proxy[0] + r * Math.cos(a), t.proxy[1] + r * Math.sin(a), t.proxy[2] + CONE_MM];
        if (k % 4 === 0) line(t.proxy, rim, c);
        if (prev) line(prev, rim, c);
        prev = rim;
      }
    }
    const f = toTissue(t.force), tip = t.probe.map((p, i) => p + f[i] * ARROW_MM_PER_N);
    const purple = [0.48, 0.12, 0.64];
    if (Math.hypot(...f) > 1e-3) {
      line(t.probe, tip, purple);
      const back = unit(sub(t.probe, tip)), side = unit(cross(back, [0, 0, 1]).map((x, i) => x || (i === 0 ? 1 : 0)));
      for (const s of [1, -1]) line(tip, tip.map((p, i) => p + 2 * back[i] + s * 1.2 * side[i]), purple);
    }
  }
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(0.984, 0.984, 0.98, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  gl.useProgram(program);
  drawn.matrix = matrix(); drawn.mesh = m;
  gl.uniformMatrix4fv(loc.m, false, new Float32Array(drawn.matrix));
  gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
  gl.enableVertexAttribArray(loc.p); gl.enableVertexAttribArray(loc.c);
  for (const [data, mode] of [[tris, gl.TRIANGLES], [lines, gl.LINES]]) {
    if (!data.length) continue;
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(data), gl.DYNAMIC_DRAW);
    gl.vertexAttribPointer(loc.p, 3, gl.FLOAT, false, 24, 0);
    gl.vertexAttribPointer(loc.c, 3, gl.FLOAT, false, 24, 12);
    gl.drawArrays(mode, 0, data.length / 6);
  }
}

// ---- plots --------------------------------------------------------------------------

const plots = $('plots').getContext('2d');

function drawPlots() {
  const cv = $('plots'), W = cv.width, H = cv.height, L = 70, R = 10;
  plots.clearRect(0, 0, W, H);
  plots.font = '11px system-ui, sans-serif';
  const hist = state.history, now = hist.length ? hist[hist.length - 1].time : 0;
  const x = (time) => L + (W - L - R) * (1 - (now - time) / HISTORY_S);
  const panel = (top, height, title, lo, hi, series) => {
    plots.strokeStyle = '#ddd'; plots.strokeRect(L, top, W - L - R, height);
    plots.fillStyle = '#333'; plots.fillText(title, 4, top + 12);
    plots.fillStyle = '#888'; plots.fillText(hi.toFixed(2), 4, top + 26); plots.fillText(lo.toFixed(2), 4, top + height - 2);
    const y = (v) => top + height - (height * (v - lo)) / (hi - lo);
    for (const [colour, get] of series) {
      plots.strokeStyle = colour; plots.beginPath();
      hist.forEach((s, i) => (i ? plots.lineTo(x(s.time), y(get(s))) : plots.moveTo(x(s.time), y(get(s)))));
      plots.stroke();
    }
  };
  const big = Math.max(0.5, ...hist.map((s) => s.fm));
  panel(4, 140, 'force, N', -big, big, [['#d32f2f', (s) => s.f[0]], ['#388e3c', (s) => s.f[1]], ['#1976d2', (s) => s.f[2]], ['#000', (s) => s.fm]]);
  plots.fillStyle = '#555'; plots.fillText('x y z |F|', 4, 60);
  panel(150, 60, 'gain', 0, 1, [['#6a1b9a', (s) => s.gain]]);
  ['contact', 'slipping', 'clamped', 'armed'].forEach((name, k) => {
    const top = 216 + k * 18;
    plots.fillStyle = '#333'; plots.fillText(name, 4, top + 11);
    plots.fillStyle = ['#00838f', '#d32f2f', '#ef6c00', '#2e7d32'][k];
    hist.forEach((s, i) => {
      if (i && has(s.flags, name)) { const x0 = x(hist[i - 1].time); plots.fillRect(x0, top, Math.max(1, x(s.time) - x0), 14); }
    });
  });
  plots.fillStyle = '#888'; plots.fillText('\u2212' + HISTORY_S + ' s', L, H - 2); plots.fillText('now', W - R - 20, H - 2);
}

function frame(now) {
  // Animation frames seen, paused or not (the browser test waits on them: a frame
  // drawn before a pause is on the screen once a few more have passed).
  state.frames = (state.frames || 0) + 1;
  if (!state.paused) {
    follow(now);
    drawScene();
    drawPlots();
  }
  requestAnimationFrame(frame);
}

// Pause: the picture holds still (the events still come; the plots catch up after).
$('pause').onclick = () => {
  state.paused = !state.paused;
  $('pause').textContent = state.paused ? 'Resume' : 'Pause';
};

// For the browser tests: where the nodes of the mesh last drawn are on the page (CSS
// pixels), and its triangles' centroids.
function onScreen(p) {
  const v = apply(drawn.matrix, p), rect = canvas.getBoundingClientRect();
  return [rect.left + (v[0] / v[3] * 0.5 + 0.5) * rect.width, rect.top + (0.5 - v[1] / v[3] * 0.5) * rect.height];
}
window.mccsView = {
  state,
  // The camera within 3 mm of the window it follows (the patch is 17.5 mm across).
  settled() {
    if (!state.t) return false;
    const [wx, wy] = state.t.window, c = camera.target;
    return Math.hypot(wx - c[0], wy - c[1]) < 3;
  },
  nodesOnScreen() {
    return drawn.mesh ? drawn.mesh.nodes.map((n) => onScreen(n.slice(2))) : [];
  },
  centroidsOnScreen() {
    if (!drawn.mesh) return [];
    const at = (k) => drawn.mesh.nodes[k].slice(2);
    return drawn.mesh.triangles.map((t) => onScreen([0, 1, 2].map((i) => (at(t[0])[i] + at(t[1])[i] + at(t[2])[i]) / 3)));
  },
};

showRole();
connect();
requestAnimationFrame(frame);
