// footfall view: draws the page's data (data.json, made by footfall.viz.view.payload) with
// WebGL2. One shader: flat-shaded meshes (normals from screen-space derivatives), unlit lines,
// round points. The recorded motion plays here, in the browser, at the display's rate (poses
// interpolated between the recorded frames); the page draws only when something changed.
// window.footfall is the page's state, read by the tests and the benchmark.
"use strict";
(() => {
  const $ = (id) => document.getElementById(id);
  const canvas = $("gl");
  const state = {
    ready: false, renders: 0, frame: 0, time: 0, frames: 0, playing: false, names: [],
    vertexCount, bodyPosition, setTime, error: "",
  };
  window.footfall = state;
  // multisampled edges where a GPU draws; none in a software renderer (SwiftShader, llvmpipe:
  // there it halves the frame rate). ?antialias=1 or =0 decides instead.
  const asked = new URLSearchParams(location.search).get("antialias");
  const smooth = asked === null ? !softwareWebGL() : asked !== "0";
  const gl = canvas.getContext("webgl2", { antialias: smooth, alpha: false });
  state.antialias = smooth;
  if (!gl) return fail("this browser has no WebGL2");

  function softwareWebGL() {
    const probe = document.createElement("canvas").getContext("webgl2");
    if (!probe) return false;
    const info = probe.getExtension("WEBGL_debug_renderer_info");
    const name = String(probe.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : probe.RENDERER));
    const lose = probe.getExtension("WEBGL_lose_context");
    if (lose) lose.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  }

  // ------------------------------------------------------------------ shader
  const VS = `#version 300 es
uniform mat4 u_proj, u_view, u_model; uniform float u_size;
in vec3 a_pos; in vec4 a_color; out vec3 v_world; out vec4 v_color;
void main() {
  vec4 w = u_model * vec4(a_pos, 1.0); v_world = w.xyz; v_color = a_color;
  vec4 e = u_view * w; gl_Position = u_proj * e;
  gl_PointSize = max(2.0, u_size / max(-e.z, 1e-3));
}`;
  const FS = `#version 300 es
precision highp float;
uniform vec4 u_color; uniform int u_mode; uniform vec3 u_light;
in vec3 v_world; in vec4 v_color; out vec4 o;
void main() {
  vec4 c = u_color * v_color;
  if (u_mode == 2) { vec2 p = gl_PointCoord - 0.5; if (dot(p, p) > 0.25) discard; }
  if (u_mode != 0) { o = c; return; }
  vec3 n = normalize(cross(dFdx(v_world), dFdy(v_world)));
  float k = 0.5 + 0.4 * abs(dot(n, u_light)) + 0.1 * abs(n.z);
  o = vec4(c.rgb * k, c.a);
}`;
  function compile(type, src) {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }
  const prog = gl.createProgram();
  gl.attachShader(prog, compile(gl.VERTEX_SHADER, VS));
  gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, FS));
  gl.bindAttribLocation(prog, 0, "a_pos");
  gl.bindAttribLocation(prog, 1, "a_color");
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) return fail(gl.getProgramInfoLog(prog));
  const U = {};
  for (const n of ["u_proj", "u_view", "u_model", "u_size", "u_color", "u_mode", "u_light"]) {
    U[n] = gl.getUniformLocation(prog, n);
  }
  const LIGHT = normalize([0.35, -0.55, 0.76]);

  // ------------------------------------------------------------------ 4x4 matrices (column-major)
  function normalize(v) { const l = Math.hypot(v[0], v[1], v[2]) || 1; return [v[0] / l, v[1] / l, v[2] / l]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function perspective(fov, aspect, near, far) {
    const f = 1 / Math.tan(fov / 2), nf = 1 / (near - far);
    return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
  }
  function lookAt(eye, target, up) {
    const z = normalize([eye[0] - target[0], eye[1] - target[1], eye[2] - target[2]]);
    const x = normalize(cross(up, z)), y = cross(z, x);
    return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
  }
  function pose(m, p, q) { // rotation of the unit quaternion q = (w, x, y, z), then p
    const [w, x, y, z] = q;
    m[0] = 1 - 2 * (y * y + z * z); m[1] = 2 * (x * y + w * z); m[2] = 2 * (x * z - w * y); m[3] = 0;
    m[4] = 2 * (x * y - w * z); m[5] = 1 - 2 * (x * x + z * z); m[6] = 2 * (y * z + w * x); m[7] = 0;
    m[8] = 2 * (x * z + w * y); m[9] = 2 * (y * z - w * x); m[10] = 1 - 2 * (x * x + y * y); m[11] = 0;
    m[12] = p[0]; m[13] = p[1]; m[14] = p[2]; m[15] = 1;
    return m;
  }
  const IDENTITY = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);

  // ------------------------------------------------------------------ data
  function array(s, Type) {
    const bin = atob(s), u8 = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) u8[i] = bin.charCodeAt(i);
    return new Type(u8.buffer);
  }
  let items = [];      // drawables: {name, group, mode, vao, count, indexed, color, body, marker, shown}
  let labels = [];     // {name, group, el, pos, shown}
  let robot = null;    // {bodies, t, pos, wxyz, mats}
  let markers = [];    // {name, pos (F*3)}
  let support = null;  // {vao, per}
  let camera = null, home = null, playStart = 0;

  function upload(positions, indices, colors) {
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const vb = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, vb);
    gl.bufferData(gl.ARRAY_BUFFER, positions, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    const buffers = [vb];
    if (colors) { // per-vertex colours of a batch (RGBA, 0..255)
      const cb = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, cb);
      gl.bufferData(gl.ARRAY_BUFFER, colors, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(1);
      gl.vertexAttribPointer(1, 4, gl.UNSIGNED_BYTE, true, 0, 0);
      buffers.push(cb);
    }
    if (indices) {
      const ib = gl.createBuffer();
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
      buffers.push(ib);
    }
    gl.bindVertexArray(null);
    return { vao, buffers };
  }
  function colour(rgb, opacity) { return [rgb[0] / 255, rgb[1] / 255, rgb[2] / 255, opacity]; }

  const counts = new Map(); // vertices per node name (batched nodes keep theirs)
  function addItems(list, group) {
    const batches = new Map(); // the still meshes of one opacity, drawn as one
    for (const m of list) {
      const positions = array(m.positions, Float32Array);
      const indices = m.indices ? array(m.indices, Uint32Array) : null;
      counts.set(m.name, (counts.get(m.name) || 0) + positions.length / 3);
      const body = m.body ?? -1, marker = m.marker ?? -1, shown = m.shown ?? null;
      if (indices && body < 0 && marker < 0 && !shown) {
        const op = m.opacity ?? 1;
        if (!batches.has(op)) batches.set(op, []);
        batches.get(op).push({ positions, indices, rgb: m.rgb, name: m.name });
        continue;
      }
      const { vao, buffers } = upload(positions, indices, null);
      const mode = m.kind === "points" ? 2 : m.kind === "lines" ? 1 : 0;
      items.push({
        name: m.name, group, mode, vao, buffers, vertices: positions.length / 3,
        count: indices ? indices.length : positions.length / 3, indexed: !!indices,
        color: colour(m.rgb, m.opacity ?? 1), body, marker, size: m.size ?? 0, shown,
      });
    }
    for (const [op, parts] of batches) {
      let nv = 0, ni = 0;
      for (const p of parts) { nv += p.positions.length / 3; ni += p.indices.length; }
      const pos = new Float32Array(3 * nv), idx = new Uint32Array(ni), col = new Uint8Array(4 * nv);
      let v = 0, i = 0;
      for (const p of parts) {
        pos.set(p.positions, 3 * v);
        for (let k = 0; k < p.indices.length; k++) idx[i + k] = p.indices[k] + v;
        const n = p.positions.length / 3;
        for (let k = 0; k < n; k++) col.set([p.rgb[0], p.rgb[1], p.rgb[2], 255], 4 * (v + k));
        v += n; i += p.indices.length;
      }
      const { vao, buffers } = upload(pos, idx, col);
      items.push({
        name: `${group}:batch`, group, mode: 0, vao, buffers, vertices: 0, count: ni, indexed: true,
        color: [1, 1, 1, op], body: -1, marker: -1, size: 0, shown: null, batch: parts.map((p) => p.name),
      });
    }
  }
  function addLabels(list, group) {
    const box = $("labels");
    for (const l of list) {
      const el = document.createElement("div");
      el.textContent = l.text;
      box.appendChild(el);
      labels.push({ name: l.name, group, el, pos: l.position, shown: l.shown ?? null });
    }
    placed = ""; // place them at the next drawing
  }
  function clearGroup(group) {
    for (const it of items.filter((i) => i.group === group)) {
      gl.deleteVertexArray(it.vao);
      for (const b of it.buffers) gl.deleteBuffer(b);
      for (const n of it.batch || [it.name]) counts.delete(n);
    }
    items = items.filter((i) => i.group !== group);
    for (const l of labels.filter((i) => i.group === group)) l.el.remove();
    labels = labels.filter((i) => i.group !== group);
  }
  function listNames() {
    const names = new Set(counts.keys());
    for (const l of labels) names.add(l.name);
    for (const m of markers) names.add(m.name);
    if (robot) for (const b of robot.bodies) names.add("/robot/" + b);
    if (support) names.add(support.name);
    state.names = [...names];
  }

  function vertexCount(name) {
    let n = 0;
    for (const [k, v] of counts) if (k === name || k.startsWith(name + "/")) n += v;
    return n;
  }
  function bodyPosition(name) {
    if (!robot) return null;
    const b = robot.bodies.indexOf(name);
    if (b < 0) return null;
    const m = robot.mats[b];
    return [m[12], m[13], m[14]];
  }

  // ------------------------------------------------------------------ the panel
  function inline(text) { // **bold**, _italic_, `code` of a line of footfall's own text
    const esc = text.replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
    return esc.replace(/\*\*(.+?)\*\*/g, "<b>$1</b>").replace(/`(.+?)`/g, "<code>$1</code>")
      .replace(/(^|\s)_(.+?)_(?=\s|$)/g, "$1<i>$2</i>");
  }
  function texts(d) {
    $("title").innerHTML = "<b>" + inline(d.title) + "</b>";
    const box = $("texts");
    box.innerHTML = "";
    for (const n of d.notes) box.insertAdjacentHTML("beforeend", `<p class="note">${inline(n)}</p>`);
    for (const s of d.summaries) box.insertAdjacentHTML("beforeend", `<p>${inline(s)}</p>`);
  }

  // ------------------------------------------------------------------ time
  function frameAt(t) { // the last frame at or before t
    const T = robot.t;
    let lo = 0, hi = T.length - 1;
    if (t >= T[hi]) return hi;
    while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (T[mid] <= t + 1e-9) lo = mid; else hi = mid; }
    return lo;
  }
  function setTime(t, fromSlider) {
    if (!robot) return;
    const T = robot.t, F = T.length, B = robot.bodies.length;
    t = Math.min(Math.max(t, 0), T[F - 1]);
    const f = frameAt(t), g = Math.min(f + 1, F - 1);
    const a = g > f ? Math.min(1, (t - T[f]) / (T[g] - T[f])) : 0;
    const P = robot.pos, Q = robot.wxyz;
    for (let b = 0; b < B; b++) {
      const i = f * B + b, j = g * B + b;
      const p = [0, 1, 2].map((k) => P[3 * i + k] + a * (P[3 * j + k] - P[3 * i + k]));
      let s = 0;
      for (let k = 0; k < 4; k++) s += Q[4 * i + k] * Q[4 * j + k];
      const sign = s < 0 ? -1 : 1; // the nearer of q and -q
      const q = [0, 1, 2, 3].map((k) => Q[4 * i + k] + a * (sign * Q[4 * j + k] - Q[4 * i + k]));
      const l = Math.hypot(q[0], q[1], q[2], q[3]) || 1;
      pose(robot.mats[b], p, q.map((v) => v / l));
    }
    state.time = t;
    state.frame = f;
    if (!fromSlider) $("time").value = t.toFixed(3);
    $("status").textContent = `frame ${f + 1} / ${F}, t = ${T[f].toFixed(2)} s`;
    requestDraw();
  }
  function shownAt(w) { return !w || (state.time >= w[0] && state.time <= w[1]); }

  // ------------------------------------------------------------------ camera
  function cameraFrom(c) {
    const d = [c.position[0] - c.target[0], c.position[1] - c.target[1], c.position[2] - c.target[2]];
    const dist = Math.hypot(d[0], d[1], d[2]) || 1;
    return { target: c.target.slice(), dist, az: Math.atan2(d[1], d[0]),
      el: Math.asin(Math.max(-1, Math.min(1, d[2] / dist))), fov: c.fov };
  }
  function eye() {
    const c = camera, ce = Math.cos(c.el);
    return [c.target[0] + c.dist * ce * Math.cos(c.az), c.target[1] + c.dist * ce * Math.sin(c.az),
      c.target[2] + c.dist * Math.sin(c.el)];
  }
  let drag = null;
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("pointerdown", (e) => {
    drag = { x: e.clientX, y: e.clientY, pan: e.button !== 0 || e.shiftKey };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener("pointerup", () => { drag = null; });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag || !camera) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      const e3 = eye(), f = normalize([camera.target[0] - e3[0], camera.target[1] - e3[1], camera.target[2] - e3[2]]);
      const r = normalize(cross(f, [0, 0, 1])), u = cross(r, f);
      const k = (2 * camera.dist * Math.tan(camera.fov / 2)) / canvas.clientHeight;
      for (let i = 0; i < 3; i++) camera.target[i] += k * (-dx * r[i] + dy * u[i]);
    } else {
      camera.az -= dx * 0.006;
      camera.el = Math.max(-1.5, Math.min(1.5, camera.el + dy * 0.006));
    }
    requestDraw();
  });
  canvas.addEventListener("wheel", (e) => {
    if (!camera) return;
    e.preventDefault();
    camera.dist *= Math.exp(e.deltaY * 0.001);
    requestDraw();
  }, { passive: false });
  canvas.addEventListener("dblclick", () => { if (home) { camera = cameraFrom(home); requestDraw(); } });
  canvas.addEventListener("keydown", (e) => { if (e.key === " ") { togglePlay(); e.preventDefault(); } });

  // ------------------------------------------------------------------ drawing
  let pending = false;
  function requestDraw() {
    if (!pending) { pending = true; requestAnimationFrame(frame); }
  }
  let last = 0;
  function frame(now) {
    pending = false;
    if (state.playing && robot) {
      const T = robot.t, end = T[T.length - 1];
      let t = state.time + (now - last) / 1000;
      if (t > end) t = 0;
      last = now;
      setTime(t);
    }
    draw();
    if (state.playing) requestDraw();
  }
  function draw() {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    gl.viewport(0, 0, w, h);
    gl.clearColor(0.957, 0.961, 0.969, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    if (!camera) return;
    const e3 = eye();
    const proj = perspective(camera.fov, w / h, camera.dist * 0.01, camera.dist * 50);
    const view = lookAt(e3, camera.target, [0, 0, 1]);
    gl.useProgram(prog);
    gl.vertexAttrib4f(1, 1, 1, 1, 1); // the colour of a node without colours of its own
    gl.uniformMatrix4fv(U.u_proj, false, proj);
    gl.uniformMatrix4fv(U.u_view, false, view);
    gl.uniform3fv(U.u_light, LIGHT);
    gl.enable(gl.DEPTH_TEST);
    const size = h / (2 * Math.tan(camera.fov / 2)); // pixels per metre at unit depth
    const model = new Float32Array(16);
    const opaque = items.filter((i) => i.color[3] >= 1), clear = items.filter((i) => i.color[3] < 1);
    gl.disable(gl.BLEND);
    gl.depthMask(true);
    for (const it of opaque) drawItem(it, model, size);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
    gl.depthMask(false);
    for (const it of clear) drawItem(it, model, size);
    gl.depthMask(true);
    gl.disable(gl.BLEND);
    if (support && robot) {
      gl.uniformMatrix4fv(U.u_model, false, IDENTITY);
      gl.uniform1i(U.u_mode, 1);
      gl.uniform4fv(U.u_color, support.color);
      gl.bindVertexArray(support.vao);
      gl.drawArrays(gl.LINES, state.frame * support.per, support.per);
    }
    gl.bindVertexArray(null);
    placeLabels(proj, view, w / dpr, h / dpr);
    state.renders++;
  }
  function drawItem(it, model, size) {
    if (!shownAt(it.shown)) return;
    let m = IDENTITY;
    if (it.body >= 0) {
      if (!robot) return;
      m = robot.mats[it.body];
    } else if (it.marker >= 0) {
      const P = markers[it.marker].pos, f = state.frame;
      const p = [P[3 * f], P[3 * f + 1], P[3 * f + 2]];
      if (!robot || !(Number.isFinite(p[0]) && Number.isFinite(p[1]) && Number.isFinite(p[2]))) return;
      m = pose(model, p, [1, 0, 0, 0]);
    }
    gl.uniformMatrix4fv(U.u_model, false, m);
    gl.uniform1i(U.u_mode, it.mode);
    gl.uniform4fv(U.u_color, it.color);
    gl.uniform1f(U.u_size, it.size * size);
    gl.bindVertexArray(it.vao);
    if (it.indexed) gl.drawElements(gl.TRIANGLES, it.count, gl.UNSIGNED_INT, 0);
    else gl.drawArrays(it.mode === 2 ? gl.POINTS : gl.LINES, 0, it.count);
  }
  let placed = "";
  function placeLabels(proj, view, w, h) {
    // the labels stand still in the world: moved only when the camera or the picture changed,
    // shown or hidden when the time passes their window
    const key = `${view.join()},${w},${h},${labels.length}`;
    const moved = key !== placed;
    placed = key;
    for (const l of labels) {
      if (!moved && !l.shown) continue;
      const p = l.pos, v = [0, 0, 0, 0];
      for (let r = 0; r < 4; r++) { // clip = proj * view * (p, 1)
        let s = 0;
        for (let k = 0; k < 4; k++) {
          let e = 0;
          for (let j = 0; j < 4; j++) e += view[j * 4 + k] * (j < 3 ? p[j] : 1);
          s += proj[k * 4 + r] * e;
        }
        v[r] = s;
      }
      const visible = v[3] > 0 && shownAt(l.shown);
      if (l.visible !== visible) { l.el.style.display = visible ? "" : "none"; l.visible = visible; }
      if (visible && moved) {
        const x = (v[0] / v[3] * 0.5 + 0.5) * w, y = (0.5 - v[1] / v[3] * 0.5) * h;
        l.el.style.transform = `translate(${x.toFixed(1)}px, ${y.toFixed(1)}px) translate(-50%, -100%)`;
      }
    }
  }
  new ResizeObserver(() => requestDraw()).observe(canvas);

  // ------------------------------------------------------------------ controls
  function togglePlay() {
    if (!robot || robot.t.length < 2) return;
    state.playing = !state.playing;
    last = performance.now();
    if (state.playing) requestDraw();
  }
  $("play").addEventListener("click", togglePlay);
  $("time").addEventListener("input", (e) => setTime(parseFloat(e.target.value), true));
  $("trial").addEventListener("change", (e) => showTrial(parseInt(e.target.value, 10)));
  $("rewalk").addEventListener("click", walkTrial);

  async function getJSON(url) {
    for (;;) {
      const r = await fetch(url, { cache: "no-store" });
      if (r.status === 503) { await new Promise((ok) => setTimeout(ok, 50)); continue; }
      const body = await r.json();
      if (!r.ok) throw new Error(body.error || r.statusText);
      return body;
    }
  }
  function drawScene(d, group) {
    addItems(d.meshes, group);
    addLabels(d.labels, group);
  }
  let trialShown = 0;
  async function showTrial(i) {
    $("outcome").textContent = "loading…";
    try {
      const d = await getJSON(`trial/${i}.json`);
      clearGroup("scene");
      setRobot(null);
      drawScene(d, "scene");
      trialShown = i;
      $("outcome").textContent = d.outcome;
      $("rewalk").disabled = false;
      listNames();
      requestDraw();
    } catch (err) { fail(String(err.message || err)); }
  }
  async function walkTrial() { // the server walks the trial again and records its replay
    const i = trialShown;
    $("rewalk").disabled = true;
    $("outcome").textContent = "walking the trial again…";
    try {
      const d = await getJSON(`trial/${i}/walk.json`);
      if (i !== trialShown) return; // another trial was picked meanwhile
      clearGroup("scene");
      drawScene(d, "scene");
      setRobot(d.robot, 0);
      $("outcome").textContent = d.summaries.join("; ");
      listNames();
      requestDraw();
    } catch (err) {
      $("outcome").textContent = String(err.message || err);
    }
  }
  function setRobot(r, start) { // the recorded motion shown (null: none)
    state.playing = false;
    clearGroup("robot");
    if (support) gl.deleteVertexArray(support.vao);
    robot = null; markers = []; support = null; state.frames = 0;
    $("timebox").hidden = true;
    $("status").textContent = "no recorded motion";
    if (!r) return;
    robot = { bodies: r.bodies, t: array(r.t, Float64Array), pos: array(r.pos, Float32Array),
      wxyz: array(r.wxyz, Float32Array), mats: r.bodies.map(() => new Float32Array(16)) };
    addItems(r.meshes, "robot");
    markers = r.markers.map((m) => ({ name: m.name, pos: array(m.positions, Float32Array) }));
    addItems(r.markers.map((m, k) => ({ ...m.mesh, name: m.name, marker: k })), "robot");
    if (r.support) {
      const { vao } = upload(array(r.support.positions, Float32Array), null);
      support = { name: r.support.name, vao, per: r.support.per, color: colour(r.support.rgb, 1) };
    }
    const F = robot.t.length;
    state.frames = F;
    if (F > 1) {
      $("timebox").hidden = false;
      $("time").max = robot.t[F - 1].toFixed(3);
    }
    setTime(start || 0);
  }

  async function main() {
    const d = await getJSON("data.json");
    texts(d);
    home = d.camera;
    camera = cameraFrom(home);
    drawScene(d, "scene");
    setRobot(d.robot, d.start);
    if (d.trials.length) {
      const sel = $("trial");
      d.trials.forEach((k, i) => sel.insertAdjacentHTML("beforeend", `<option value="${i}">${inline(k)}</option>`));
      $("trialbox").hidden = false;
      $("rewalk").hidden = !d.rewalk;
      $("outcome").textContent = d.outcome || "";
    }
    listNames();
    requestAnimationFrame(() => { draw(); state.ready = true; });
  }
  function fail(msg) {
    state.error = msg;
    const el = $("error");
    if (el) el.textContent = msg;
    return undefined;
  }
  main().catch((err) => fail(String(err.message || err)));
})();
