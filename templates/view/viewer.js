"use strict";
// implc's live viewer, written once for two hosts. The page (viewer.html.j2) runs this file
// as its script: the block at the end mounts the viewer on the page's own document. The
// notebook widget (implc/api/widget.py) sends this file with widget.mjs after it as one ES
// module, which mounts the viewer in a shadow root per view. `root` is a Document or a
// ShadowRoot holding viewer-body.html.j2's markup; `DATA` is implc/view.py's viewer_data;
// `options`: size (a fixed square canvas in pixels, 0: fill the stage), backend ("webgpu"
// to start on WebGPU), onParams(params) after a slider moved, onError(message).
function implcMount(root, DATA, options) {
  const fixedSize = options.size ? Math.max(8, Math.min(4096, options.size)) : 0;
  const $ = (id) => root.getElementById(id);
  const stage = $("stage"), glCanvas = $("gl-canvas"), gpuCanvas = $("gpu-canvas");

  // What tests (and the curious) can read: the page's window.implcViewer, the widget's
  // element's implcViewer.
  const viewer = {
    frames: 0, backend: "webgl2", error: "", lastFrameMs: NaN, webgpu: "unavailable",
    params: {}, ready: false,
  };

  // --- small vector helpers -------------------------------------------------------
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const len = (a) => Math.sqrt(dot(a, a));
  const norm = (a) => { const l = len(a); return l > 0 ? mul(a, 1 / l) : a; };
  // Rodrigues: v turned by `angle` radians about the unit axis k.
  const rotate = (v, k, angle) => {
    const c = Math.cos(angle), s = Math.sin(angle);
    return add(add(mul(v, c), mul(cross(k, v), s)), mul(k, dot(k, v) * (1 - c)));
  };

  // --- state: camera (first frame = the surface's [view]) and parameters ---------------
  const home = () => ({ eye: DATA.view.eye.slice(), target: DATA.view.target.slice(),
                        up: DATA.view.up.slice(), fov_y: DATA.view.fov_y });
  let camera = home();
  const params = {};
  for (const p of DATA.params) params[p.name] = p.value;
  viewer.params = params;
  let quality = 1;

  // --- page text --------------------------------------------------------------------
  $("name").textContent = DATA.surface.name;
  $("equation").textContent = DATA.surface.equation;
  $("method").textContent = DATA.method.name + (DATA.method.uses_taylor2 ? " (Eq. 4: " + DATA.method.taylor2 + ")" : "");
  $("method").title = DATA.method.summary;
  $("step").textContent = DATA.method.step === null ? DATA.method.unmarched : "b = " + DATA.method.step;
  if (fixedSize) stage.classList.add("fixed");

  function showError(message) {
    viewer.error = message;
    const box = $("error");
    box.textContent = message;
    box.style.display = "block";
    if (options.onError) options.onError(message);
  }

  // --- parameter sliders --------------------------------------------------------------
  if (!DATA.params.length) $("no-params").hidden = false;
  const sliders = {};
  for (const p of DATA.params) {
    const row = document.createElement("div");
    row.className = "row";
    const label = document.createElement("label");
    const input = document.createElement("input");
    const out = document.createElement("output");
    input.type = "range";
    input.id = "param-" + p.name;
    label.htmlFor = input.id;
    label.textContent = p.name;
    input.min = String(p.low);
    input.max = String(p.high);
    input.step = String(p.step);
    input.value = String(p.value);
    input.dataset.param = p.name;
    out.textContent = Number(p.value).toPrecision(4);
    input.addEventListener("input", () => {
      params[p.name] = parseFloat(input.value);
      out.textContent = params[p.name].toPrecision(4);
      requestFrame();
      if (options.onParams) options.onParams(Object.assign({}, params));
    });
    row.append(label, input, out);
    $("params").append(row);
    sliders[p.name] = { input, out };
  }
  // Parameter values from outside (the widget's Python side): the picture and the sliders.
  viewer.setParams = (values) => {
    let changed = false;
    for (const [name, value] of Object.entries(values || {})) {
      const s = sliders[name];
      if (!s || typeof value !== "number" || !isFinite(value) || params[name] === value) continue;
      params[name] = value;
      s.input.value = String(value);
      s.out.textContent = value.toPrecision(4);
      changed = true;
    }
    if (changed) requestFrame();
  };

  // --- canvas size -------------------------------------------------------------------
  function activeCanvas() { return viewer.backend === "webgpu" ? gpuCanvas : glCanvas; }
  function resize() {
    let w, h;
    if (fixedSize) {
      w = h = fixedSize;
      for (const c of [glCanvas, gpuCanvas]) { c.style.width = fixedSize + "px"; c.style.height = fixedSize + "px"; }
    } else {
      const dpr = window.devicePixelRatio || 1;
      w = Math.max(1, Math.round(stage.clientWidth * dpr * quality));
      h = Math.max(1, Math.round(stage.clientHeight * dpr * quality));
    }
    for (const c of [glCanvas, gpuCanvas]) {
      if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
    }
    stage.classList.toggle("low", quality < 1);
  }

  // --- WebGL2: the es300 program over a full-screen triangle ---------------------------
  const gl = glCanvas.getContext("webgl2", { antialias: false, alpha: false, depth: false,
                                              preserveDrawingBuffer: true });
  let glProgram = null, glUniforms = {};
  function compile(type, source) {
    const shader = gl.createShader(type);
    gl.shaderSource(shader, source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
      throw new Error("WebGL2 shader compile failed:\n" + gl.getShaderInfoLog(shader));
    }
    return shader;
  }
  function initWebGL2() {
    if (!gl) throw new Error("this browser has no WebGL2");
    const program = gl.createProgram();
    gl.attachShader(program, compile(gl.VERTEX_SHADER, DATA.glsl.vertex));
    gl.attachShader(program, compile(gl.FRAGMENT_SHADER, DATA.glsl.fragment));
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) {
      throw new Error("WebGL2 program link failed:\n" + gl.getProgramInfoLog(program));
    }
    glProgram = program;
    const names = ["u_resolution", "u_eye", "u_target", "u_up", "u_fov_y", "u_clip_center",
                   "u_clip_radius"].concat(DATA.params.map((p) => p.uniform));
    for (const name of names) glUniforms[name] = gl.getUniformLocation(program, name);
    gl.bindVertexArray(gl.createVertexArray());
  }
  function frameWebGL2() {
    const w = glCanvas.width, h = glCanvas.height;
    gl.viewport(0, 0, w, h);
    gl.useProgram(glProgram);
    const u = glUniforms;
    gl.uniform2f(u.u_resolution, w, h);
    gl.uniform3fv(u.u_eye, camera.eye);
    gl.uniform3fv(u.u_target, camera.target);
    gl.uniform3fv(u.u_up, camera.up);
    gl.uniform1f(u.u_fov_y, camera.fov_y);
    gl.uniform3fv(u.u_clip_center, DATA.view.clip_center);
    gl.uniform1f(u.u_clip_radius, DATA.view.clip_radius);
    for (const p of DATA.params) if (u[p.uniform]) gl.uniform1f(u[p.uniform], params[p.name]);
    const start = performance.now();
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    const pixel = new Uint8Array(4);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);  // waits for the frame
    return performance.now() - start;
  }

  // --- WebGPU: the WGSL compute program into a storage texture, blitted to the canvas --
  const gpu = { adapter: null, device: null, context: null, compute: null, blit: null, format: null,
                size: [0, 0], texture: null, aux: null, uniforms: null, computeGroup: null, blitGroup: null };
  // The uniform block: 20 floats of camera and clip sphere (docs/reference/drop-ins.md,
  // "Drop-in contract (WGSL)"), the parameters' f32s from float 19 on (`--params uniform`), 16-byte rounded.
  const uniformFloats = Math.max(20, ...DATA.params.map((p) => p.wgsl_index + 1));
  const uniformBytes = Math.ceil(uniformFloats * 4 / 16) * 16;
  async function initWebGPU() {
    if (!DATA.wgsl.program) { viewer.webgpu = "not in this page (implc view --no-webgpu)"; return; }
    if (!navigator.gpu) { viewer.webgpu = "this browser has no WebGPU"; return; }
    const adapter = await navigator.gpu.requestAdapter();
    if (!adapter) { viewer.webgpu = "no WebGPU adapter"; return; }
    gpu.adapter = adapter;  // keep it: Chromium rejects pending work once it is collected
    const device = await adapter.requestDevice({ requiredLimits: {
      maxStorageBufferBindingSize: adapter.limits.maxStorageBufferBindingSize,
      maxBufferSize: adapter.limits.maxBufferSize } });
    device.pushErrorScope("validation");
    const program = device.createShaderModule({ code: DATA.wgsl.program, label: "implc.wgsl" });
    const blit = device.createShaderModule({ code: DATA.wgsl.blit, label: "implc blit" });
    const messages = [];
    for (const [name, module] of [["program", program], ["blit", blit]]) {
      const info = await module.getCompilationInfo();
      for (const m of info.messages) {
        if (m.type === "error") messages.push(name + ":" + m.lineNum + ":" + m.linePos + ": " + m.message);
      }
    }
    if (messages.length) throw new Error("WebGPU rejected the WGSL:\n" + messages.join("\n"));
    const format = navigator.gpu.getPreferredCanvasFormat();
    gpu.compute = await device.createComputePipelineAsync({ layout: "auto",
                                                             compute: { module: program, entryPoint: "main" } });
    gpu.blit = await device.createRenderPipelineAsync({ layout: "auto",
      vertex: { module: blit, entryPoint: "vs" },
      fragment: { module: blit, entryPoint: "fs", targets: [{ format }] },
      primitive: { topology: "triangle-list" } });
    const failure = await device.popErrorScope();
    if (failure) throw new Error("WebGPU: " + failure.message);
    gpu.context = gpuCanvas.getContext("webgpu");
    gpu.context.configure({ device, format, alphaMode: "opaque" });
    gpu.device = device;
    gpu.format = format;
    gpu.uniforms = device.createBuffer({ size: uniformBytes,
                                         usage: GPUBufferUsage.UNIFORM | GPUBufferUsage.COPY_DST });
    device.lost.then((info) => { if (info.reason !== "destroyed") showError("WebGPU device lost: " + info.message); });
    viewer.webgpu = "available";
    const button = $("use-webgpu");
    button.disabled = false;
  }
  function gpuTargets(w, h) {
    if (gpu.size[0] === w && gpu.size[1] === h) return;
    if (gpu.texture) { gpu.texture.destroy(); gpu.aux.destroy(); }
    const d = gpu.device;
    gpu.texture = d.createTexture({ size: [w, h], format: "rgba32float",
                                    usage: GPUTextureUsage.STORAGE_BINDING | GPUTextureUsage.TEXTURE_BINDING });
    gpu.aux = d.createBuffer({ size: w * h * 16, usage: GPUBufferUsage.STORAGE });
    gpu.computeGroup = d.createBindGroup({ layout: gpu.compute.getBindGroupLayout(0), entries: [
      { binding: 0, resource: { buffer: gpu.uniforms } },
      { binding: 1, resource: gpu.texture.createView() },
      { binding: 2, resource: { buffer: gpu.aux } }] });
    gpu.blitGroup = d.createBindGroup({ layout: gpu.blit.getBindGroupLayout(0), entries: [
      { binding: 0, resource: gpu.texture.createView() }] });
    gpu.size = [w, h];
  }
  async function frameWebGPU() {
    const w = gpuCanvas.width, h = gpuCanvas.height, d = gpu.device;
    gpuTargets(w, h);
    const data = new Float32Array(uniformBytes / 4);
    data.set([w, h, camera.fov_y, DATA.view.clip_radius], 0);
    data.set(camera.eye, 4);
    data.set(camera.target, 8);
    data.set(camera.up, 12);
    data.set(DATA.view.clip_center, 16);
    for (const p of DATA.params) data[p.wgsl_index] = params[p.name];
    d.queue.writeBuffer(gpu.uniforms, 0, data);
    const start = performance.now();
    const encoder = d.createCommandEncoder();
    const pass = encoder.beginComputePass();
    pass.setPipeline(gpu.compute);
    pass.setBindGroup(0, gpu.computeGroup);
    pass.dispatchWorkgroups(Math.ceil(w / 8), Math.ceil(h / 8), 1);
    pass.end();
    const draw = encoder.beginRenderPass({ colorAttachments: [{
      view: gpu.context.getCurrentTexture().createView(), loadOp: "clear", storeOp: "store",
      clearValue: { r: 0, g: 0, b: 0, a: 1 } }] });
    draw.setPipeline(gpu.blit);
    draw.setBindGroup(0, gpu.blitGroup);
    draw.draw(3);
    draw.end();
    d.queue.submit([encoder.finish()]);
    await d.queue.onSubmittedWorkDone();
    return performance.now() - start;
  }

  // --- frames on demand ---------------------------------------------------------------
  let wanted = false, busy = false;
  function requestFrame() {
    wanted = true;
    if (!busy) requestAnimationFrame(runFrame);
  }
  let disposed = false;
  async function runFrame() {
    if (!wanted || busy || viewer.error || disposed) return;
    wanted = false;
    busy = true;
    try {
      resize();
      const ms = viewer.backend === "webgpu" ? await frameWebGPU() : frameWebGL2();
      const c = activeCanvas();
      viewer.lastFrameMs = ms;
      viewer.frames += 1;
      $("frame-time").textContent = ms.toFixed(1) + " ms (" + (1000 / Math.max(ms, 1e-3)).toFixed(1) + " fps)";
      $("frame-size").textContent = c.width + " × " + c.height;
    } catch (err) {
      showError(String(err && err.message || err));
    } finally {
      busy = false;
    }
    if (wanted) requestAnimationFrame(runFrame);
  }

  function setBackend(name) {
    if (name === "webgpu" && !gpu.device) return false;
    viewer.backend = name;
    glCanvas.hidden = name !== "webgl2";
    gpuCanvas.hidden = name !== "webgpu";
    $("use-webgl2").setAttribute("aria-pressed", String(name === "webgl2"));
    $("use-webgpu").setAttribute("aria-pressed", String(name === "webgpu"));
    $("source").textContent = currentShader();
    requestFrame();
    return true;
  }
  function currentShader() { return viewer.backend === "webgpu" ? DATA.wgsl.program : DATA.glsl.fragment; }
  viewer.setBackend = setBackend;
  $("use-webgl2").addEventListener("click", () => setBackend("webgl2"));
  $("use-webgpu").addEventListener("click", () => setBackend("webgpu"));
  $("quality").addEventListener("change", (e) => { quality = parseFloat(e.target.value); requestFrame(); });

  // --- copy the shader ----------------------------------------------------------------
  $("copy").addEventListener("click", async () => {
    const text = currentShader();
    let ok = false;
    try { await navigator.clipboard.writeText(text); ok = true; } catch (err) { ok = false; }
    if (!ok) {  // older browsers, or no clipboard permission
      const area = document.createElement("textarea");
      area.value = text;
      document.body.append(area);
      area.select();
      try { ok = document.execCommand("copy"); } catch (err) { ok = false; }
      area.remove();
    }
    $("copy-status").textContent = ok ? "copied " + (viewer.backend === "webgpu" ? "WGSL" : "GLSL ES 3.00")
                                      : "copy failed: open “Shader source”";
  });

  // --- orbit, pan and zoom: mouse, pen and touch through pointer events -------------
  const ORBIT_RADIANS_PER_PX = 0.008;
  function basis() {
    const forward = norm(sub(camera.target, camera.eye));
    const right = norm(cross(forward, camera.up));
    return { forward, right, up: cross(right, forward) };
  }
  function orbit(dx, dy) {
    const axis = norm(camera.up);
    let offset = sub(camera.eye, camera.target);
    offset = rotate(offset, axis, -dx * ORBIT_RADIANS_PER_PX);
    const right = norm(cross(mul(offset, -1), axis));
    const tilted = rotate(offset, right, -dy * ORBIT_RADIANS_PER_PX);
    const cos = dot(norm(tilted), axis);
    if (Math.abs(cos) < 0.995) offset = tilted;  // stop short of the up axis
    camera.eye = add(camera.target, offset);
  }
  function pan(dx, dy) {
    const b = basis();
    const distance = len(sub(camera.eye, camera.target));
    const canvas = activeCanvas();  // fov_y spans the canvas's shorter side
    const perPx = 2 * distance * Math.tan(camera.fov_y * Math.PI / 360) /
      Math.max(Math.min(canvas.clientWidth, canvas.clientHeight), 1);
    const move = add(mul(b.right, -dx * perPx), mul(b.up, dy * perPx));
    camera.eye = add(camera.eye, move);
    camera.target = add(camera.target, move);
  }
  function zoom(factor) {
    const offset = sub(camera.eye, camera.target);
    const distance = len(offset);
    const r = DATA.view.clip_radius;
    const next = Math.min(Math.max(distance * factor, 0.02 * r), 200 * r);
    camera.eye = add(camera.target, mul(offset, next / distance));
  }
  const pointers = new Map();
  let pinch = null;
  function pinchState() {
    const [a, b] = [...pointers.values()];
    return { distance: Math.hypot(a.x - b.x, a.y - b.y), x: (a.x + b.x) / 2, y: (a.y + b.y) / 2 };
  }
  stage.addEventListener("pointerdown", (e) => {
    try { stage.setPointerCapture(e.pointerId); } catch (err) { /* not an active pointer */ }
    pointers.set(e.pointerId, { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.button === 1 || e.shiftKey });
    pinch = pointers.size === 2 ? pinchState() : null;
    stage.classList.add("dragging");
  });
  stage.addEventListener("pointermove", (e) => {
    const p = pointers.get(e.pointerId);
    if (!p) return;
    const dx = e.clientX - p.x, dy = e.clientY - p.y;
    p.x = e.clientX;
    p.y = e.clientY;
    if (pointers.size === 1) {
      if (p.pan || e.shiftKey) pan(dx, dy); else orbit(dx, dy);
    } else if (pointers.size === 2 && pinch) {
      const now = pinchState();
      if (now.distance > 0) zoom(pinch.distance / now.distance);
      pan(now.x - pinch.x, now.y - pinch.y);
      pinch = now;
    }
    requestFrame();
  });
  const release = (e) => {
    pointers.delete(e.pointerId);
    pinch = pointers.size === 2 ? pinchState() : null;
    if (!pointers.size) stage.classList.remove("dragging");
  };
  stage.addEventListener("pointerup", release);
  stage.addEventListener("pointercancel", release);
  stage.addEventListener("contextmenu", (e) => e.preventDefault());
  stage.addEventListener("wheel", (e) => {
    e.preventDefault();
    const lines = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
    zoom(Math.exp(e.deltaY * lines * 0.0015));
    requestFrame();
  }, { passive: false });
  function resetView() { camera = home(); requestFrame(); }
  stage.addEventListener("dblclick", resetView);
  $("reset").addEventListener("click", resetView);
  viewer.resetView = resetView;
  Object.defineProperty(viewer, "camera", { get: () => camera, enumerable: true });
  // idle: no frame running or waiting (a test reads the canvas only then)
  Object.defineProperty(viewer, "idle", { get: () => !busy && !wanted, enumerable: true });
  const observer = new ResizeObserver(() => requestFrame());
  observer.observe(stage);

  // --- start: WebGL2 first (its first frame is the surface's [view]), WebGPU alongside --
  $("source").textContent = currentShader();
  try {
    initWebGL2();
  } catch (err) {
    showError(String(err.message || err));
  }
  requestFrame();
  initWebGPU().then(() => {
    if (options.backend === "webgpu" && !setBackend("webgpu")) showError("WebGPU: " + viewer.webgpu);
  }).catch((err) => {
    viewer.webgpu = "failed: " + String(err.message || err);
    if (options.backend === "webgpu") showError(viewer.webgpu);
  }).finally(() => {
    viewer.ready = true;
    $("use-webgpu").title = viewer.webgpu;
  });

  // The host removes the view (a notebook cell cleared): stop drawing, free the GPU.
  viewer.dispose = () => {
    disposed = true;
    observer.disconnect();
    if (gpu.device) gpu.device.destroy();
    const lose = gl && gl.getExtension("WEBGL_lose_context");
    if (lose) lose.loseContext();
  };
  return viewer;
}

// The page: its data in #implc-data, its options in the address (?size=256&backend=webgpu).
if (typeof document !== "undefined" && document.getElementById("implc-data")) {
  const query = new URLSearchParams(location.search);
  window.implcViewer = implcMount(document, JSON.parse(document.getElementById("implc-data").textContent), {
    size: query.has("size") ? parseInt(query.get("size"), 10) || 256 : 0,
    backend: query.get("backend"),
  });
}
