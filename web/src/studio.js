// The page of `lsyc studio`: a CodeMirror editor, the drawing with pan and
// zoom, guide handles, sliders for constants, a step slider, save and reload.
// Every run happens on the server (POST /api/…, JSON); the page only draws
// what comes back, the latest request winning.
import { EditorView, basicSetup } from "codemirror";
import { keymap, hoverTooltip } from "@codemirror/view";
import { autocompletion } from "@codemirror/autocomplete";
import { setDiagnostics } from "@codemirror/lint";
import { lsy } from "./lsy.js";

const $ = (sel) => document.querySelector(sel);
const SVG_NS = "http://www.w3.org/2000/svg";

const ui = {
  file: $("[data-role=file]"),
  save: $("[data-role=save]"),
  seed: $("[data-role=seed]"),
  step: $("[data-role=step]"),
  stepValue: $("[data-role=step-value]"),
  showString: $("[data-role=show-string]"),
  exportSvg: $("[data-role=export-svg]"),
  exportPng: $("[data-role=export-png]"),
  exportObj: $("[data-role=export-obj]"),
  exportGlb: $("[data-role=export-glb]"),
  orbit: $("[data-role=orbit]"),
  viewAngle: $("[data-role=view-angle]"),
  resetView: $("[data-role=reset-view]"),
  exportLsy: $("[data-role=export-lsy]"),
  fit: $("[data-role=fit]"),
  banner: $("[data-role=disk-changed]"),
  diskMessage: $("[data-role=disk-message]"),
  reload: $("[data-role=reload]"),
  keep: $("[data-role=keep]"),
  editor: $("[data-role=editor]"),
  diagnostics: $("[data-role=diagnostics]"),
  view: $("[data-role=view]"),
  stage: $("[data-role=stage]"),
  drawing: $("[data-role=drawing]"),
  overlay: $("[data-role=overlay]"),
  consts: $("[data-role=consts]"),
  string: $("[data-role=string]"),
  status: $("[data-role=status]"),
};

const state = {
  seq: 0,
  /// Replies older than this are dropped.
  applied: 0,
  defines: {},
  seed: 0,
  /// The step shown, or null for the program's `derive`.
  step: null,
  maxStep: 0,
  svgText: null,
  /// A scene's layers on the page: guide → hash of its layer's SVG text.
  layers: {},
  guides: [],
  pins: new Set(),
  /// Stiff springs, as `A.vI=B.vJ`; `stiffFrom` is the first end chosen.
  stiff: [],
  stiffFrom: null,
  /// A 3D program's camera (azimuth, elevation in degrees), as `--view`.
  is3d: false,
  isScene: false,
  view: [30, 20],
  constants: [],
  /// Text and version of the file as last loaded or saved.
  savedText: "",
  diskVersion: null,
  ignoredVersion: null,
  /// World units → stage pixels, fixed once per file so that the drawing does
  /// not jump when its bounds change.
  unit: null,
  pan: { x: 0, y: 0, scale: 1 },
  drag: null,
  busy: 0,
  /// Round trips of runs and drags (request to drawing on the page), and
  /// the page's own part of a drag's redraw (parsing and patching the layers).
  timings: { edit: [], drag: [], page: [] },
};

// ---- the server ----

/// This page's session: the server keeps sequence numbers per session, so
/// that a reloaded page or a second tab starts its own.
const SESSION =
  globalThis.crypto && crypto.randomUUID
    ? crypto.randomUUID()
    : `${Date.now().toString(36)}-${Math.random().toString(36).slice(2)}`;

async function post(path, body) {
  const r = await fetch(path, {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ ...body, session: SESSION }),
  });
  return r.json();
}

/// One lane of requests (runs and drags share it): at most one in flight and
/// one waiting; a newer request replaces the waiting one. An edit's run is
/// sent at once when the one in flight is an edit's run too: the server
/// stops the older run between derivation steps and answers it `superseded`,
/// so typing never waits for a stale run to end.
const lane = { inFlight: 0, current: null, waiting: null };

function send(path, body, onReply, fresh = null) {
  const job = { path, body: { ...body, seq: ++state.seq }, onReply, fresh, sent: 0 };
  const preempt = path === "/api/run" && lane.current && lane.current.path === "/api/run" && !lane.waiting;
  if (lane.inFlight && !preempt) {
    lane.waiting = job;
    return;
  }
  start(job);
}

function start(job) {
  lane.inFlight++;
  lane.current = job;
  state.busy++;
  job.sent = performance.now();
  // What depends on the page's drawing is read when the request leaves, after
  // the reply before it was drawn.
  if (job.fresh) job.body = { ...job.body, ...job.fresh() };
  post(job.path, job.body)
    .then((reply) => {
      if (!reply.superseded && reply.seq >= state.applied) {
        state.applied = reply.seq;
        job.onReply(reply, performance.now() - job.sent);
      }
    })
    .catch((e) => setStatus(`the studio's server did not answer: ${e}`, true))
    .finally(() => {
      state.busy--;
      lane.inFlight--;
      if (lane.current === job) lane.current = null;
      if (lane.inFlight > 0) return;
      const next = lane.waiting;
      lane.waiting = null;
      if (next) start(next);
    });
}

function program(extra = {}) {
  return {
    source: getSource(),
    defines: { ...state.defines },
    seed: state.seed,
    step: state.step,
    view: state.view,
    ...extra,
  };
}

// ---- the editor ----

let view;

function getSource() {
  return view.state.doc.toString();
}

function setSource(text) {
  view.dispatch({ changes: { from: 0, to: view.state.doc.length, insert: text } });
}

function createEditor(text) {
  view = new EditorView({
    doc: text,
    parent: ui.editor,
    extensions: [
      basicSetup,
      lsy,
      autocompletion({ override: [completions] }),
      hoverTooltip(hover, { hoverTime: 300 }),
      keymap.of([{ key: "Mod-s", preventDefault: true, run: () => (save(), true) }]),
      EditorView.updateListener.of((u) => {
        if (u.docChanged) {
          markDirty();
          run();
        }
      }),
    ],
  });
}

// ---- hover and completion: the language server's answers ----

/// Markdown as the language server writes it (fenced code, `code`, text) into DOM.
function markdown(text) {
  const dom = document.createElement("div");
  dom.className = "hover";
  text.split(/```[a-z]*\n?/).forEach((part, i) => {
    if (!part.trim()) return;
    if (i % 2 === 1) {
      const pre = document.createElement("pre");
      pre.textContent = part.replace(/\n$/, "");
      dom.append(pre);
      return;
    }
    for (const para of part.trim().split(/\n\n+/)) {
      const p = document.createElement("p");
      para.split(/(`[^`]*`)/).forEach((bit) => {
        if (bit.startsWith("`") && bit.endsWith("`") && bit.length > 1) {
          const c = document.createElement("code");
          c.textContent = bit.slice(1, -1);
          p.append(c);
        } else {
          p.append(bit.replace(/\*\*|__/g, ""));
        }
      });
      dom.append(p);
    }
  });
  return dom;
}

async function hover(view, pos) {
  const source = view.state.doc.toString();
  let reply;
  try {
    reply = await post("/api/hover", { source, at: pos });
  } catch {
    return null;
  }
  const h = reply.ok && reply.hover;
  if (!h || view.state.doc.toString() !== source) return null;
  return {
    pos: h.from,
    end: h.to,
    above: true,
    create: () => ({ dom: markdown(h.text) }),
  };
}

const KINDS = { function: "function", variable: "variable", constant: "constant", keyword: "keyword", module: "class", class: "class", property: "property", field: "property", snippet: "text", text: "text" };

async function completions(ctx) {
  const word = ctx.matchBefore(/[?\w]*/);
  if (!ctx.explicit && (!word || word.from === word.to)) return null;
  const source = ctx.state.doc.toString();
  const reply = await post("/api/complete", { source, at: ctx.pos });
  if (!reply.ok || !reply.items.length || ctx.aborted) return null;
  const from = Math.min(...reply.items.map((c) => c.from));
  return {
    from,
    to: ctx.pos,
    options: reply.items.map((c) => ({
      label: c.label,
      detail: c.detail || undefined,
      type: KINDS[c.kind] || "text",
      apply: c.insert,
      info: c.doc ? () => markdown(c.doc) : undefined,
    })),
    validFor: /^[?\w]*$/,
  };
}

function markDirty() {
  ui.file.classList.toggle("dirty", getSource() !== state.savedText);
}

// ---- running ----

function run() {
  const body = program();
  send("/api/run", body, (reply, ms) => {
    if (reply.ok) state.timings.edit.push(ms);
    applyRun(reply, ms, body);
  });
}

function applyRun(reply, ms, body) {
  showDiagnostics(reply.diagnostics || []);
  if (reply.ok) {
    const first = showDrawing(reply.svg, reply.previous_svg);
    state.layers = reply.layers || {};
    state.is3d = !!reply.is_3d;
    state.isScene = !!reply.is_scene;
    showView();
    state.guides = reply.guides || [];
    drawHandles();
    if (body.step === null && reply.stats) {
      state.maxStep = reply.stats.steps;
      ui.step.max = String(state.maxStep);
      ui.step.value = String(state.maxStep);
    }
    showStep();
    showConstants(reply.constants || []);
    // Fitted once the panels below the drawing have their size.
    if (first) fit();
    setStatus(statsLine(reply.stats, ms), false);
  } else {
    ui.drawing.classList.add("stale");
    const errors = (reply.diagnostics || []).filter((d) => d.severity === "error").length;
    setStatus(
      reply.error ||
        `${errors} error${errors === 1 ? "" : "s"}: the drawing is the last one that ran`,
      true,
    );
  }
}

function statsLine(s, ms) {
  if (!s) return "";
  const n = (v) => Number(v).toLocaleString("en");
  const head = s.scene !== undefined
    ? `scene ${s.scene}: ${n(s.systems)} systems, ${n(s.modules)} modules, ${n(s.segments)} segments, ${n(s.elements)} elements, ${n(s.queries)} queries, ${n(s.messages)} messages after ${s.steps} steps`
    : `${s.system}: ${n(s.modules)} modules, ${n(s.segments)} segments, ${n(s.elements)} elements, ${n(s.polygons)} polygons after ${s.steps} steps`;
  const t = [];
  if (s.check_ms !== undefined) t.push(`check ${s.check_ms.toFixed(1)} ms`);
  if (s.solve_ms !== undefined) t.push(`springs ${s.solve_ms.toFixed(1)} ms`);
  t.push(`derive ${s.derive_ms.toFixed(1)} ms`, `draw ${s.interpret_ms.toFixed(1)} ms`);
  t.push(`round trip ${ms.toFixed(0)} ms`);
  return `${head} · ${t.join(" · ")}`;
}

function setStatus(text, error) {
  ui.status.textContent = text;
  ui.status.classList.toggle("error", !!error);
}

// ---- diagnostics ----

function showDiagnostics(list) {
  const len = view.state.doc.length;
  const cm = list.map((d) => {
    const from = Math.min(d.from ?? 0, len);
    const to = Math.min(Math.max(d.to ?? from, from), len);
    return {
      from,
      to,
      severity: d.severity === "warning" ? "warning" : "error",
      source: d.code,
      message: d.help ? `${d.message}\nhelp: ${d.help}` : d.message,
    };
  });
  view.dispatch(setDiagnostics(view.state, cm));
  ui.diagnostics.replaceChildren(
    ...list.map((d, i) => {
      const li = document.createElement("li");
      li.dataset.code = d.code;
      li.className = d.severity;
      const where = document.createElement("span");
      where.className = "where";
      where.textContent = d.line ? `${d.line}:${d.column}` : "";
      const code = document.createElement("span");
      code.className = "code";
      code.textContent = `${d.severity}[${d.code}]`;
      li.append(where, code, ` ${d.message}`);
      li.addEventListener("click", () => {
        view.dispatch({ selection: { anchor: cm[i].from, head: cm[i].to }, scrollIntoView: true });
        view.focus();
      });
      return li;
    }),
  );
}

// ---- the drawing, pan and zoom ----

function parseSvg(text) {
  const doc = new DOMParser().parseFromString(text, "image/svg+xml");
  const svg = doc.documentElement;
  return svg.nodeName === "svg" ? document.importNode(svg, true) : null;
}

/// Places an SVG so that its user units map to `state.unit` stage pixels.
function place(svg, box) {
  const u = state.unit;
  svg.setAttribute("width", String(box.w * u));
  svg.setAttribute("height", String(box.h * u));
  svg.style.position = "absolute";
  svg.style.left = `${box.x * u}px`;
  svg.style.top = `${box.y * u}px`;
}

function viewBox(svg) {
  const [x, y, w, h] = (svg.getAttribute("viewBox") || "0 0 1 1").split(/[\s,]+/).map(Number);
  return { x, y, w: w || 1, h: h || 1 };
}

/// Shows a drawing; returns whether it is the first one.
function showDrawing(text, previousText) {
  const svg = parseSvg(text);
  if (!svg) return false;
  state.svgText = text;
  const box = viewBox(svg);
  const first = state.unit === null;
  if (first) state.unit = 800 / Math.max(box.w, box.h);
  place(svg, box);
  const layers = [svg];
  const previous = previousText ? parseSvg(previousText) : null;
  if (previous) {
    previous.classList.add("previous");
    previous.querySelectorAll("[id]").forEach((e) => e.setAttribute("id", `prev-${e.id}`));
    previous.querySelectorAll("use").forEach((e) => {
      const h = e.getAttribute("href");
      if (h) e.setAttribute("href", h.replace("#", "#prev-"));
      e.removeAttribute("xlink:href");
    });
    place(previous, viewBox(previous));
    layers.push(previous);
  }
  ui.drawing.replaceChildren(...layers);
  ui.drawing.classList.toggle("stepping", !!previous);
  ui.drawing.classList.remove("stale");
  place(ui.overlay, box);
  ui.overlay.setAttribute("viewBox", `${box.x} ${box.y} ${box.w} ${box.h}`);
  return first;
}

/// A 3D program's camera: re-drawn on the server as `--view AZ,EL` draws it.
function setView(v) {
  state.view = [Math.round(v[0] * 10) / 10, Math.round(v[1] * 10) / 10];
  showView();
  run();
}

function showView() {
  const on = state.is3d && !state.isScene;
  ui.orbit.hidden = !on;
  ui.viewAngle.value = `view ${state.view[0]}°, ${state.view[1]}°`;
}

function applyPan() {
  const p = state.pan;
  ui.stage.style.transform = `translate(${p.x}px, ${p.y}px) scale(${p.scale})`;
  sizeHandles();
}

function fit() {
  const svg = ui.drawing.querySelector("svg");
  if (!svg) return;
  const box = viewBox(svg);
  const u = state.unit;
  const r = ui.view.getBoundingClientRect();
  const scale = Math.min(r.width / (box.w * u), r.height / (box.h * u)) * 0.95 || 1;
  state.pan = {
    scale,
    x: (r.width - box.w * u * scale) / 2 - box.x * u * scale,
    y: (r.height - box.h * u * scale) / 2 - box.y * u * scale,
  };
  applyPan();
}

function setupPanZoom() {
  ui.view.addEventListener("wheel", (e) => {
    e.preventDefault();
    const r = ui.view.getBoundingClientRect();
    const mx = e.clientX - r.left;
    const my = e.clientY - r.top;
    const k = Math.exp(-e.deltaY * 0.0015);
    const p = state.pan;
    p.x = mx - (mx - p.x) * k;
    p.y = my - (my - p.y) * k;
    p.scale *= k;
    applyPan();
  }, { passive: false });
  let panning = null;
  ui.view.addEventListener("pointerdown", (e) => {
    if (e.target.closest(".handle") || e.button !== 0) return;
    const orbit = state.is3d && !state.isScene && !e.shiftKey;
    panning = { x: e.clientX, y: e.clientY, px: state.pan.x, py: state.pan.y, orbit, view: [...state.view] };
    ui.view.setPointerCapture(e.pointerId);
    ui.view.classList.add("panning");
  });
  ui.view.addEventListener("pointermove", (e) => {
    if (!panning) return;
    if (panning.orbit) {
      // Half a degree per pixel; the elevation stops short of the poles.
      const az = panning.view[0] - (e.clientX - panning.x) * 0.5;
      const el = Math.max(-89, Math.min(89, panning.view[1] + (e.clientY - panning.y) * 0.5));
      setView([((az % 360) + 360) % 360, el]);
      return;
    }
    state.pan.x = panning.px + e.clientX - panning.x;
    state.pan.y = panning.py + e.clientY - panning.y;
    applyPan();
  });
  const stop = () => {
    panning = null;
    ui.view.classList.remove("panning");
  };
  ui.view.addEventListener("pointerup", stop);
  ui.view.addEventListener("pointercancel", stop);
}

// ---- guide handles ----

function handleRadius() {
  return 5 / (state.unit * state.pan.scale);
}

function sizeHandles() {
  const r = String(handleRadius());
  ui.overlay.querySelectorAll(".handle").forEach((h) => h.setAttribute("r", r));
}

function drawHandles() {
  const active = state.drag ? state.drag.vertex : null;
  const circles = [];
  for (const g of state.guides) {
    g.points.forEach(([x, y], i) => {
      const name = `${g.name}.v${i}`;
      const c = document.createElementNS(SVG_NS, "circle");
      c.setAttribute("class", "handle");
      c.dataset.vertex = name;
      c.setAttribute("cx", String(x));
      c.setAttribute("cy", String(-y));
      c.setAttribute("r", String(handleRadius()));
      if (state.pins.has(name)) c.classList.add("pinned");
      if (state.stiffFrom === name) c.classList.add("stiff-from");
      c.dataset.pinned = state.pins.has(name) ? "true" : "false";
      if (name === active) {
        c.classList.add("active");
        c.setAttribute("cx", String(state.drag.x));
        c.setAttribute("cy", String(-state.drag.y));
      }
      const title = document.createElementNS(SVG_NS, "title");
      title.textContent = `${name} (${x}, ${y}) — drag to move, shift-click to pin, alt-click two vertices for a stiff spring`;
      c.append(title);
      circles.push(c);
    });
  }
  const at = (v) => {
    const [guide, index] = v.split(/\.v(?=\d+$)/);
    return state.guides.find((g) => g.name === guide)?.points[Number(index)];
  };
  const springs = [];
  for (const pair of state.stiff) {
    const [a, b] = pair.split("=").map(at);
    if (!a || !b) continue;
    const l = document.createElementNS(SVG_NS, "line");
    l.setAttribute("class", "stiff");
    l.dataset.stiff = pair;
    l.setAttribute("x1", String(a[0]));
    l.setAttribute("y1", String(-a[1]));
    l.setAttribute("x2", String(b[0]));
    l.setAttribute("y2", String(-b[1]));
    springs.push(l);
  }
  ui.overlay.replaceChildren(...springs, ...circles);
}

/// `--pin GUIDE.vN` on or off.
function togglePin(vertex) {
  if (state.pins.has(vertex)) state.pins.delete(vertex);
  else state.pins.add(vertex);
  drawHandles();
}

/// `--stiff A.vI=B.vJ`: the first vertex chosen, then the second adds the
/// spring (or removes it if it was there); choosing the first again cancels.
function chooseStiff(vertex) {
  const a = state.stiffFrom;
  if (a === null) {
    state.stiffFrom = vertex;
  } else if (a === vertex) {
    state.stiffFrom = null;
  } else {
    const pair = `${a}=${vertex}`;
    const back = `${vertex}=${a}`;
    const had = state.stiff.filter((p) => p === pair || p === back);
    state.stiff = state.stiff.filter((p) => p !== pair && p !== back);
    if (!had.length) state.stiff.push(pair);
    state.stiffFrom = null;
  }
  drawHandles();
}

function worldPoint(e) {
  const m = ui.overlay.getScreenCTM();
  if (!m) return null;
  const p = new DOMPoint(e.clientX, e.clientY).matrixTransform(m.inverse());
  return { x: p.x, y: -p.y };
}

function setupHandles() {
  ui.overlay.addEventListener("pointerdown", (e) => {
    const h = e.target.closest(".handle");
    if (!h || e.button !== 0) return;
    e.preventDefault();
    e.stopPropagation();
    const vertex = h.dataset.vertex;
    if (e.shiftKey) {
      togglePin(vertex);
      return;
    }
    if (e.altKey) {
      chooseStiff(vertex);
      return;
    }
    const [guide, index] = vertex.split(/\.v(?=\d+$)/);
    const at = state.guides.find((g) => g.name === guide)?.points[Number(index)];
    if (!at) return;
    h.setPointerCapture(e.pointerId);
    state.drag = { vertex, x: at[0], y: at[1], base: program(), moved: false, pointer: e.pointerId };
    h.classList.add("active");
    // Starts the server's drag session (a full run) before the pointer moves,
    // so that every move is an incremental one.
    sendDrag(false);
  });
  ui.overlay.addEventListener("pointermove", (e) => {
    const d = state.drag;
    if (!d || e.pointerId !== d.pointer) return;
    const p = worldPoint(e);
    if (!p) return;
    d.x = p.x;
    d.y = p.y;
    d.moved = true;
    const h = ui.overlay.querySelector(`[data-vertex="${CSS.escape(d.vertex)}"].active`);
    if (h) {
      h.setAttribute("cx", String(p.x));
      h.setAttribute("cy", String(-p.y));
    }
    sendDrag(false);
  });
  const release = (e) => {
    const d = state.drag;
    if (!d || e.pointerId !== d.pointer) return;
    if (d.moved) sendDrag(true);
    else state.drag = null;
  };
  ui.overlay.addEventListener("pointerup", release);
  ui.overlay.addEventListener("pointercancel", release);
}

function sendDrag(final) {
  const d = state.drag;
  const body = {
    ...d.base,
    vertex: d.vertex,
    x: d.x,
    y: d.y,
    pins: [...state.pins].filter((p) => p !== d.vertex),
    stiff: [...state.stiff],
  };
  send("/api/drag", body, (reply, ms) => {
    if (!reply.ok) {
      setStatus(reply.error || "the drag failed", true);
      if (final) state.drag = null;
      return;
    }
    const t0 = performance.now();
    if (reply.patch) {
      if (!applyPatch(reply.patch)) {
        // The page's drawing is not the one the patch was made for.
        state.layers = {};
        if (final) state.drag = null;
        run();
        return;
      }
    } else {
      showDrawing(reply.svg, null);
    }
    state.layers = reply.layers || {};
    const own = performance.now() - t0;
    ms += own;
    state.timings.drag.push(ms);
    state.timings.page.push(own);
    state.guides = reply.guides;
    if (final) {
      state.drag = null;
      setSource(reply.formatted);
    } else {
      drawHandles();
    }
    const again = reply.recomputed ? ` · recomputed ${reply.recomputed.length} of ${reply.guides.length} guides` : "";
    const sent = reply.patch ? ` · sent ${reply.patch.layers.filter(([, t]) => t !== null).length} of ${reply.patch.layers.length} layers` : "";
    setStatus(statsLine(reply.stats, ms) + again + sent, false);
  }, () => ({ have: { ...state.layers } }));
}

/// Applies a drag's patch to the drawing on the page: the new head's view box
/// and styles, the layers sent in place of theirs, the new outlines and
/// links. The result is the drawing the whole SVG would give. Returns false
/// if the drawing on the page does not have the patch's layers.
function applyPatch(patch) {
  const svg = ui.drawing.querySelector(":scope > svg:not(.previous)");
  const top = svg && svg.querySelector(":scope > g");
  if (!top || ui.drawing.querySelector(":scope > svg.previous")) return false;
  const old = [...top.querySelectorAll(":scope > g.guide-content")];
  if (old.length === 0 || old.length !== patch.layers.length) return false;
  // The head and tail are small: parsed as a document of their own. The
  // layers, which are most of the bytes, are parsed once, straight into this
  // document (as markup inside an SVG element), not parsed and then copied.
  const fresh = parseSvg(patch.head + patch.tail);
  const freshTop = fresh && fresh.querySelector(":scope > g");
  if (!freshTop) return false;
  const holder = document.createElementNS(SVG_NS, "g");
  holder.innerHTML = patch.layers.map(([, text]) => text || "").join("");
  const freshLayers = [...holder.children];
  if (freshLayers.length !== patch.layers.filter(([, t]) => t !== null).length) return false;
  // The tail: everything after the defs (outlines, links).
  const tail = [];
  const defsEnd = freshTop.querySelector(":scope > defs");
  for (let n = defsEnd ? defsEnd.nextSibling : freshTop.firstChild; n; n = n.nextSibling) tail.push(n);
  let k = 0;
  patch.layers.forEach(([, text], i) => {
    if (text !== null) old[i].replaceWith(freshLayers[k++]);
  });
  svg.setAttribute("viewBox", fresh.getAttribute("viewBox"));
  for (const a of freshTop.attributes) top.setAttribute(a.name, a.value);
  const defs = freshTop.querySelector(":scope > defs");
  const oldDefs = top.querySelector(":scope > defs");
  if (defs && oldDefs) oldDefs.replaceWith(defs);
  const lastLayer = old.length ? top.querySelectorAll(":scope > g.guide-content")[old.length - 1] : null;
  while (lastLayer && lastLayer.nextSibling) lastLayer.nextSibling.remove();
  top.append(...tail);
  state.svgText = null;
  const box = viewBox(svg);
  place(svg, box);
  place(ui.overlay, box);
  ui.overlay.setAttribute("viewBox", `${box.x} ${box.y} ${box.w} ${box.h}`);
  ui.drawing.classList.remove("stale");
  return true;
}

// ---- constants ----

function range(v) {
  if (v > 0) return [0, 2 * v];
  if (v < 0) return [2 * v, 0];
  return [-1, 1];
}

function stepOf(v, lo, hi) {
  return Number.isInteger(v) && Math.abs(v) >= 2 ? 1 : (hi - lo) / 1000;
}

function showConstants(list) {
  const names = list.map((c) => c.name).join(",");
  if (names === state.constants.map((c) => c.name).join(",")) {
    // Same constants: follow the source's values unless a slider is held.
    for (const c of list) {
      const s = ui.consts.querySelector(`input[data-role=const][data-name="${CSS.escape(c.name)}"]`);
      if (s && !(c.name in state.defines) && document.activeElement !== s) {
        const lo = Number(s.min);
        const hi = Number(s.max);
        if (c.value < lo || c.value > hi) {
          const [a, b] = range(c.value);
          s.min = String(a);
          s.max = String(b);
        }
        s.value = String(c.value);
        s.nextElementSibling.value = String(c.value);
      }
    }
    state.constants = list;
    return;
  }
  state.constants = list;
  const cells = [];
  for (const c of list) {
    const [lo, hi] = range(c.value);
    const label = document.createElement("span");
    label.className = "name";
    label.textContent = c.name;
    label.title = c.literal ? "" : "written as an expression: releasing the slider writes the number";
    const min = document.createElement("input");
    min.type = "number";
    min.value = String(lo);
    min.title = "lowest value";
    const slider = document.createElement("input");
    slider.type = "range";
    slider.dataset.role = "const";
    slider.dataset.name = c.name;
    slider.min = String(lo);
    slider.max = String(hi);
    slider.step = String(stepOf(c.value, lo, hi));
    slider.value = String(c.value);
    const max = document.createElement("input");
    max.type = "number";
    max.value = String(hi);
    max.title = "highest value";
    const out = document.createElement("output");
    out.value = String(c.value);
    min.addEventListener("change", () => {
      slider.min = min.value;
      slider.step = String(stepOf(c.value, Number(min.value), Number(slider.max)));
    });
    max.addEventListener("change", () => {
      slider.max = max.value;
      slider.step = String(stepOf(c.value, Number(slider.min), Number(max.value)));
    });
    slider.addEventListener("input", () => {
      const v = Number(slider.value);
      out.value = String(v);
      state.defines[c.name] = v;
      run();
    });
    slider.addEventListener("change", () => writeConstant(c.name, Number(slider.value)));
    // The value follows its slider (`showConstants` finds it there).
    cells.push(label, min, slider, out, max);
  }
  ui.consts.replaceChildren(...cells);
}

async function writeConstant(name, value) {
  const reply = await post("/api/const", { source: getSource(), name, value });
  delete state.defines[name];
  if (reply.ok) setSource(reply.source);
  else {
    setStatus(reply.error, true);
    run();
  }
}

// ---- steps ----

function showStep() {
  ui.stepValue.value = state.step === null ? `${state.maxStep} (derive)` : `${state.step} / ${state.maxStep}`;
}

function setupStep() {
  ui.step.addEventListener("input", () => {
    const k = Number(ui.step.value);
    state.step = k >= state.maxStep ? null : k;
    showStep();
    run();
    if (!ui.string.hidden) showString();
  });
  ui.showString.addEventListener("click", () => {
    if (!ui.string.hidden) {
      ui.string.hidden = true;
      return;
    }
    showString();
  });
}

async function showString() {
  const reply = await post("/api/string", program({ seq: 0 }));
  ui.string.hidden = false;
  ui.string.textContent = reply.ok
    ? reply.text + (reply.cut ? "\n… (cut)" : "")
    : "the program has errors";
}

// ---- files ----

async function save() {
  const text = getSource();
  // The version the text started from: the server refuses to write over a
  // file that changed on disk since.
  const reply = await post("/api/save", { text, base: state.diskVersion });
  if (reply.ok) {
    state.savedText = text;
    state.diskVersion = reply.version;
    ui.banner.hidden = true;
    markDirty();
    setStatus(`saved ${ui.file.textContent}`, false);
  } else if (reply.conflict && reply.disk && reply.disk.ok) {
    askAboutDisk(reply.disk, "Not saved: the file changed on disk since it was loaded.");
    setStatus(reply.error, true);
  } else {
    setStatus(reply.error, true);
  }
}

/// Shows the bar that asks whether to load the file as it is on disk or
/// keep the page's text (a later save then writes over that version).
function askAboutDisk(f, message) {
  ui.diskMessage.textContent = message;
  ui.banner.hidden = false;
  state.pendingDisk = f;
}

async function load() {
  const r = await fetch("/api/file");
  return r.json();
}

async function pollDisk() {
  try {
    const f = await load();
    if (!f.ok || f.version === state.diskVersion || f.version === state.ignoredVersion) return;
    if (f.text === getSource()) {
      state.savedText = f.text;
      state.diskVersion = f.version;
      markDirty();
    } else if (getSource() === state.savedText) {
      state.savedText = f.text;
      state.diskVersion = f.version;
      setSource(f.text);
      setStatus("reloaded: the file changed on disk", false);
    } else {
      // Unsaved edits here and a change there: ask, never drop either silently.
      askAboutDisk(f, "The file changed on disk.");
    }
  } catch {
    // The server is gone; the page keeps what was typed.
  }
}

/// The drawing as `lsyc run -o NAME.EXT` writes it, made on the server.
async function exportAs(ext) {
  const r = await fetch("/api/export", {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ ...program(), format: ext, session: SESSION }),
  });
  if (!r.ok) {
    const e = await r.json().catch(() => ({}));
    setStatus(e.error || `cannot export .${ext}`, true);
    return;
  }
  const blob = await r.blob();
  download(`${baseName()}.${ext}`, blob.type, blob);
  setStatus(`exported ${baseName()}.${ext} (${blob.size.toLocaleString("en")} bytes)`, false);
}

function download(name, type, data) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(data instanceof Blob ? data : new Blob([data], { type }));
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

function baseName() {
  return (ui.file.textContent.split("/").pop() || "program.lsy").replace(/\.lsy$/, "");
}

async function main() {
  const f = await load();
  ui.file.textContent = f.name || "";
  state.savedText = f.ok ? f.text : "";
  state.diskVersion = f.ok ? f.version : null;
  createEditor(state.savedText);
  setupPanZoom();
  setupHandles();
  setupStep();
  ui.save.addEventListener("click", save);
  ui.fit.addEventListener("click", fit);
  ui.seed.addEventListener("change", () => {
    state.seed = Math.max(0, Math.floor(Number(ui.seed.value) || 0));
    run();
  });
  for (const [button, ext] of [[ui.exportSvg, "svg"], [ui.exportPng, "png"], [ui.exportObj, "obj"], [ui.exportGlb, "glb"]]) {
    button.addEventListener("click", () => exportAs(ext));
  }
  ui.resetView.addEventListener("click", () => setView([30, 20]));
  ui.exportLsy.addEventListener("click", () => download(`${baseName()}.lsy`, "text/plain", getSource()));
  ui.reload.addEventListener("click", () => {
    const d = state.pendingDisk;
    if (!d) return;
    state.savedText = d.text;
    state.diskVersion = d.version;
    ui.banner.hidden = true;
    setSource(d.text);
  });
  ui.keep.addEventListener("click", () => {
    const d = state.pendingDisk;
    if (d) {
      // The page's text now stands against that version: the next save
      // writes over it, knowingly.
      state.ignoredVersion = d.version;
      state.diskVersion = d.version;
    }
    ui.banner.hidden = true;
  });
  window.addEventListener("beforeunload", (e) => {
    if (getSource() !== state.savedText) e.preventDefault();
  });
  setInterval(pollDisk, 1000);
  run();
}

window.lsycStudio = {
  getSource,
  setSource,
  /// Resolves when no request is in flight or waiting.
  idle() {
    return new Promise((resolve) => {
      const check = () => (state.busy === 0 && !lane.waiting ? resolve() : setTimeout(check, 20));
      check();
    });
  },
  timings: state.timings,
  state,
  togglePin,
  chooseStiff,
};

main();
