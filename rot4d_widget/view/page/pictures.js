// The page's own pictures (issue 34): while it is ahead of the kernel -- keys held, steps of its
// own beyond the kernel's state, or the kernel's picture of that state not arrived -- the page
// cuts the polytope itself (slicer.js, from the tables sent once: transfer.js) at its predicted
// state and builds the scene's rows (rows.js, bit for bit the kernel's buffers.slice_rows), so a
// key's picture never waits for a round trip.  At rest, with the kernel's picture of the same
// state arrived, the layers draw the kernel's rows again (the same rows: the switch shows nothing).

import { decodePolytope, sliceData, sliceStarEdges } from "./slicer.js";
import { sliceRows } from "./rows.js";
import { transferStore, unpack } from "./transfer.js";

const cuts = new WeakMap();  // model -> {key, polytope, rows cache}
const forced = new WeakMap();  // model -> true: draw the page's own picture at rest too (tests compare the two)

export function forceOwn(model, on) {
  forced.set(model, !!on);
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
    c = { key: t.key, polytope: decodePolytope(msg), cacheKey: null, picture: null };
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
  if (prediction.held.length || prediction.pending || forced.get(model)) return true;
  const ks = model.get("kernel_state") || {};
  return ks.picture === "pending" || (Number.isInteger(ks.picture) && !(seq >= ks.picture));
}

// {rows (Float32Array, 20 a row), stride, counts: [balls, bars, triangles], version} of the
// predicted state seen from `eye` ([x, y, z] or null), made once per state and eye.
export function ownPicture(model, prediction, eye) {
  const c = cuts.get(model);
  const cfg = model.get("draw_config") || {};
  const key = `${prediction.version}|${eye ? eye.join(",") : ""}|${cfg.scale}|${cfg.single}|${cfg.palette.length}`;
  if (c.cacheKey === key && c.picture) return c.picture;
  // a polytope with star faces or non-convex cells: its balls and bars (the fills are the kernel's)
  const cut = c.polytope.star ? sliceStarEdges : sliceData;
  const data = cut(c.polytope, prediction.state.matrix, prediction.state.c0);
  const { rows, counts } = sliceRows(data, { scale: cfg.scale, palette: cfg.palette, eye,
                                             singleRgb: Number.isFinite(cfg.single) ? cfg.single : null });
  c.cacheKey = key;
  c.picture = { rows, stride: 20, counts, version: prediction.version };
  return c.picture;
}
