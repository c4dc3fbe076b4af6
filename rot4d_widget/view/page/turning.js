// The page turns (issue 34): the page steps its own copy of the state as keys are pressed and
// held over the view, by the same key table, bounds and schedule as the kernel, tells the kernel
// how far its clock has gone (a heartbeat with each frame that makes a step: the kernel applies
// exactly the page's steps as far as it has heard), and adopts the kernel's state and id as they
// arrive, its own later steps on top.  One prediction per widget, shared by all its views.
//
// The page steps only when ipyevents would forward the event: the pointer over the view (or the
// projection's canvas), not the browser's auto-repeat, not a modifier alone, no Ctrl/Alt/Meta;
// keys release on keyup, when the pointer leaves and when the page loses focus.
//
// Each key event the page steps also goes to the kernel with the heartbeats, until a state of the
// kernel that has it is adopted (`edges`): ipyevents forwards it on its own comm, which a busy
// kernel may hold up while it handles the companion's (JupyterLab 4.4+ sends widget messages on a
// subshell; ipykernel routes a comm's messages to the thread it last sent from), and the kernel
// must not hear the page's clock past an event it has not had (rot4d_widget.view.steplog).

import { keyId } from "./keymap.js";
import { Prediction } from "./predict.js";

const MODIFIERS = new Set(["Shift", "Control", "Alt", "Meta", "CapsLock", "AltGraph", "OS", "Fn"]);

// With keys held, no state from the kernel for this long (ms): it is not answering -- the page
// stops stepping (its keys released there) and says so, until the kernel's state comes again.
export const KERNEL_SILENT_MS = 3000;

// model -> {prediction, views, frame, listeners, edges}: one per widget (its companion model)
const shared = new WeakMap();

// The key events kept for the kernel until it has them (a state of its that has them adopted).
export const MAX_EDGES = 256;

// The widget's prediction (made on first use, remade when the key table changes, its held keys
// kept), and a way to
// be told when the predicted state changes: `subscribe(f)` -> unsubscribe.
export function turning(model) {
  let s = shared.get(model);
  if (!s) {
    s = { model, prediction: null, configSeen: null, listeners: new Set(), frame: null, lastBeat: -Infinity,
          lastKernel: performance.now(), silent: false, edges: [], beat: false };
    shared.set(model, s);
  }
  const config = model.get("config");
  if (config && config.keymap && s.configSeen !== config) {
    s.configSeen = config;
    s.prediction = new Prediction(config, model.get("kernel_state"), s.prediction);
  }
  return s;
}

function changed(s) {
  for (const f of [...s.listeners]) {
    try {
      f(s.prediction, s);
    } catch (e) {
      console.warn("rot4d_widget companion: a prediction listener failed", e);
    }
  }
}

// A key event the page stepped: to the kernel with the next heartbeat (sent at once).  `edge`:
// {kid, down, t} and for a press what finds its action (`key`, `code`, `shift`; `pad` for a button).
function noteEdge(s, edge) {
  s.edges.push(edge);
  if (s.edges.length > MAX_EDGES) s.edges.splice(0, s.edges.length - MAX_EDGES);
  s.beat = true;
}

function releaseEdges(s, kids, t) {
  for (const kid of kids) noteEdge(s, { kid, down: false, t });
}

// Step to `now`, tell the kernel, wake again while a key is held.
function frame(s, now) {
  s.frame = null;
  const p = s.prediction;
  if (!p) return;
  if (p.held.length && now - s.lastKernel > KERNEL_SILENT_MS) {  // the kernel is not answering
    releaseEdges(s, p.releaseAll(now), now);
    s.silent = true;
  }
  const moved = p.advance(now);
  if (s.beat || (p.held.length && now - s.lastBeat >= 1)) {
    s.lastBeat = now;
    s.beat = false;
    s.model.send({ event: "clock", t: now, edges: s.edges });
  }
  if (moved || s.silent) changed(s);
  if (p.held.length) schedule(s);
}

function schedule(s) {
  if (s.frame === null && typeof requestAnimationFrame === "function") {
    s.frame = requestAnimationFrame(() => frame(s, performance.now()));
  }
}

// The key listeners of one view (capture phase on `window`, like the shortcut guard); `hovered()`
// says whether the pointer is over a canvas of this widget.  Returns the cleanup.
export function attachKeys(model, { listen, hovered, canvases }) {
  const onDown = (event) => {
    const s = turning(model);
    const p = s.prediction;
    if (!p || event.repeat || MODIFIERS.has(event.key) || !hovered() || s.silent) return;
    const mine = p.ours(event, keyId(event));
    if (!mine) return;
    if (!p.held.length) s.lastKernel = Math.max(s.lastKernel, event.timeStamp);  // silence counts from here
    if (!p.press(mine.kid, mine.action, mine.inverted, event.timeStamp)) return;
    noteEdge(s, { kid: mine.kid, down: true, t: event.timeStamp, key: event.key, code: event.code,
                  shift: event.shiftKey === true });
    frame(s, event.timeStamp);
    schedule(s);
  };
  const onUp = (event) => {
    const s = turning(model);
    const p = s.prediction;
    if (!p || !p.release(keyId(event), event.timeStamp)) return;
    releaseEdges(s, [keyId(event)], event.timeStamp);
    frame(s, event.timeStamp);
  };
  listen(window, "keydown", onDown, true);
  listen(window, "keyup", onUp, true);
  // ipyevents forwards the canvas's mouseleave (its timeStamp) and the kernel releases then: the
  // same listener on each canvas element of this widget, added as they appear (a pointer over one)
  const watched = new WeakSet();
  const onLeave = (event) => releaseKeys(model, event.timeStamp);
  const watchCanvases = () => {
    for (const c of canvases()) {
      if (watched.has(c)) continue;
      watched.add(c);
      listen(c, "mouseleave", onLeave);
    }
  };
  listen(document, "mouseover", watchCanvases, true);
  watchCanvases();
}

// The key pad's buttons (rot4d_widget.view.keypad): ipyevents forwards a button's mousedown and
// touchstart (a press, its timeStamp) and mouseup, mouseleave, touchend, touchcancel (a release);
// the page steps them as the kernel does, as the key "pad:<key>[+shift]" the button stands for
// (its classes: `<canvas class>-pad`, `rot4d-pad-key-<code point, hex>[-shift]`).
const PAD_KEY = /^rot4d-pad-key-([0-9a-f]+)(-shift)?$/;

export function attachPad(model, { listen, canvasClass }) {
  const button = (event) => {
    const el = event.target && event.target.closest ? event.target.closest(".rot4d-pad-button") : null;
    if (!el || !el.classList.contains(canvasClass() + "-pad")) return null;
    for (const c of el.classList) {
      const m = PAD_KEY.exec(c);
      if (m) return { key: String.fromCodePoint(parseInt(m[1], 16)), shift: !!m[2] };
    }
    return null;
  };
  const press = (event) => {
    const b = button(event);
    const s = turning(model);
    const p = s.prediction;
    if (!b || !p || s.silent || (event.type === "mousedown" && event.button !== 0)) return;
    const found = p.keymap.resolve(b.key, b.shift);
    if (!found || !p.steps(found.action)) return;
    if (!p.held.length) s.lastKernel = Math.max(s.lastKernel, event.timeStamp);
    const kid = `pad:${b.key}${b.shift ? "+shift" : ""}`;
    if (!p.press(kid, found.action, found.inverted, event.timeStamp)) return;
    noteEdge(s, { kid, down: true, t: event.timeStamp, key: b.key, shift: b.shift, pad: true });
    frame(s, event.timeStamp);
    schedule(s);
  };
  const release = (event) => {
    const b = button(event);
    const s = turning(model);
    const kid = b && `pad:${b.key}${b.shift ? "+shift" : ""}`;
    if (b && s.prediction && s.prediction.release(kid, event.timeStamp)) {
      releaseEdges(s, [kid], event.timeStamp);
      frame(s, event.timeStamp);
    }
  };
  for (const type of ["mousedown", "touchstart"]) listen(document, type, press, true);
  for (const type of ["mouseup", "touchend", "touchcancel"]) listen(document, type, release, true);
  listen(document, "mouseout", (event) => {  // leaving the button (ipyevents' mouseleave)
    const b = button(event);
    if (b && !(event.relatedTarget && event.target.closest(".rot4d-pad-button").contains(event.relatedTarget))) {
      release(event);
    }
  }, true);
}

// Every key of the widget up at page time `t` (the page lost focus, the pointer left the canvas):
// the same time the kernel is told.
export function releaseKeys(model, t) {
  const s = turning(model);
  if (!s.prediction) return;
  const kids = s.prediction.releaseAll(t);
  if (kids.length) {
    releaseEdges(s, kids, t);
    frame(s, t);
  }
}

// The kernel's state arrived (`kernel_state`): adopted, the page's later steps on top -- unless the
// page's key events say it is not what they make (`Prediction.agrees`: the kernel has not heard one
// yet); the events it has are no longer sent.
export function adoptKernel(model) {
  const s = turning(model);
  s.lastKernel = performance.now();
  s.silent = false;
  if (!s.prediction) return;
  const kernel = model.get("kernel_state");
  if (s.prediction.adopt(kernel) && kernel && typeof kernel.upto === "number") {
    s.edges = s.edges.filter((e) => e.t > kernel.upto);
  }
  s.prediction.advance(performance.now());
  changed(s);
}
