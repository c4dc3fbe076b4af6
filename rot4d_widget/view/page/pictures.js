// The page's own pictures (issue 34): while it is ahead of the kernel -- keys held, steps of its
// own beyond the kernel's state, or the kernel's picture of that state not arrived -- the page
// cuts the polytope itself (slicer.js, from the tables sent once: transfer.js) at its predicted
// state and builds the scene's rows (rows.js, bit for bit the kernel's buffers.slice_rows), so a
// key's picture never waits for a round trip.  At rest, with the kernel's picture of the same
// state arrived, the layers draw the kernel's rows again (the same rows: the switch shows nothing).
// Parallel slices of the polytope (a stack: draw_config.stack) are cut and placed by stack.js.

import { decodePolytope, sliceData, sliceStarEdges } from "./slicer.js";
import { sliceRows } from "./rows.js";
import { decodeStack, stackData, stackHyperplanes } from "./stack.js";
import { transferStore, unpack } from "./transfer.js";

const cuts = new WeakMap();  // model -> {key, polytope, rows cache}
const forced = new WeakMap();  // model -> true: draw the page's own picture at rest too (tests compare the two)

export function forceOwn(model, on) {
  forced.set(model, !!on);
}

const stacks = new WeakMap();  // draw_config -> {stack (decoded) or null, text (what the cache keys on), bad}

// The stack of a draw_config (stack.js decodeStack; null for a single slice), decoded once per
// config; `bad` (the message, logged once) when it does not decode: then the page draws none.
function stackOf(cfg) {
  let s = stacks.get(cfg);
  if (!s) {
    s = { stack: null, text: "", bad: null };
    try {
      if (cfg.stack) s = { stack: decodeStack(cfg.stack), text: JSON.stringify(cfg.stack), bad: null };
    } catch (e) {
      s.bad = e.message;
      console.warn("rot4d_widget: the page does not draw this stack itself:", e.message);
    }
    stacks.set(cfg, s);
  }
  return s;
}

// The polytope the page holds for this widget, decoded once when its transfer is whole.
export function polytopeArrived(model) {
  const t = transferStore(model).done.get("polytope");
  if (!t) return null;
  let c = cuts.get(model);
  if (!c || c.key !== t.key) {
    const { arrays, scalars } = unpack(t.meta, t.bytes);
    const msg = { ...scalars };
    for (const [name, a] of Object.entries(arrays)) msg[name] = new DataView(a.buffer, a.byteOffset, a.byteLength);
    c = { key: t.key, polytope: decodePolytope(msg), cacheKey: null, picture: null, built: 0 };
    cuts.set(model, c);
    model.send({ event: "holds", name: "polytope", key: t.key });
  }
  return c;
}

// The page draws its own picture now: it holds the polytope the kernel offers, knows how to draw
// it, and is ahead of the kernel's picture.
export function drawsOwn(model, prediction, seq) {
  const c = cuts.get(model);
  const offered = (model.get("page_data") || {}).polytope;
  const cfg = model.get("draw_config") || {};
  if (!c || !prediction || !prediction.state || c.key !== offered || !Array.isArray(cfg.palette)) return false;
  if (stackOf(cfg).bad) return false;
  if (prediction.held.length || prediction.pending || forced.get(model)) return true;
  const ks = model.get("kernel_state") || {};
  return ks.picture === "pending" || (Number.isInteger(ks.picture) && !(seq >= ks.picture));
}

// {rows (Float32Array, 20 a row), stride, counts: [balls, bars, triangles], version} of the
// predicted state seen from `eye` ([x, y, z] or null), made once per state and eye.
export function ownPicture(model, prediction, eye) {
  const c = cuts.get(model);
  const cfg = model.get("draw_config") || {};
  const { stack, text } = stackOf(cfg);
  const key = `${prediction.version}|${eye ? eye.join(",") : ""}|${cfg.scale}|${cfg.single}|${cfg.palette.length}|${text}`;
  if (c.cacheKey === key && c.picture) return c.picture;
  const { matrix, c0 } = prediction.state;
  // a stack's parallel slices; a polytope with star faces or non-convex cells as its balls and bars
  // (the fills are the kernel's); any other polytope whole
  const data = stack ? stackData(c.polytope, matrix, c0, stack)
    : c.polytope.star ? sliceStarEdges(c.polytope, matrix, c0) : sliceData(c.polytope, matrix, c0);
  const { rows, counts } = sliceRows(data, { scale: cfg.scale, palette: cfg.palette, eye,
                                             singleRgb: Number.isFinite(cfg.single) ? cfg.single : null });
  c.cacheKey = key;
  c.picture = { rows, stride: 20, counts, version: prediction.version };
  c.built++;
  return c.picture;
}

// For tests (the canvas's rot4dPage() hook): how many pictures the page has built of its own
// states, the last one's state version and counts, and with `withRows` its rows (numbers); null
// before the page holds a polytope.
export function ownPictureReport(model, withRows = false) {
  const c = cuts.get(model);
  if (!c) return null;
  const p = c.picture;
  return { built: c.built, version: p ? p.version : null, counts: p ? p.counts : null,
           rows: withRows && p ? Array.from(p.rows) : null };
}

// What the projection marks for the page's state `state` ({matrix, c0}), as the kernel's
// projection.state_message: the matrix, the hyperplanes (c0; a stack's every cut) and the middle one.
export function ownHyperplanes(model, state) {
  const cfg = model.get("draw_config") || {};
  const stack = cfg.stack ? stackOf(cfg).stack : null;
  const { offsets, middle } = stack ? stackHyperplanes(stack, state.c0) : { offsets: [state.c0], middle: state.c0 };
  return { matrix: Array.from(state.matrix), offsets, middle };
}
