// Labels pinned to points of the view, placed where they cover no data (issue 37).
//
// `placeLabels` is the rule, in pixels of the canvas (y down): a box label ("corner", "edge") goes
// outside `keep`, the rectangle the data's extent projects into, on the side nearest its point
// (beside it: level with the point on the left or right, above or below it otherwise), moved along
// that side (left and right: a line's height at a time, up and down alternately) or outward (above
// and below: a row at a time) until it overlaps no label placed before it, inside the canvas; the
// next side is tried when none of 9 places is free.  A "slice" label (a stack's slice) is centred
// under its point, moved down a row at a time past labels placed before it.  When no place is
// free the first is taken, clamped into the canvas.  keep/framing.py `place_labels` is the same
// rule for the static pictures (tests/view/test_labels.py runs both on the same cases).
// `drawLabels` builds the overlay: a span per label (its text as text, never markup), a dot at
// each point and a thin line from it to its label when the label was moved away from it.

const STEPS = [0, 1, -1, 2, -2, 3, -3, 4, -4];
const OUTWARD = [0, 1, 2, 3, 4, 5, 6, 7, 8];
export const LABEL_GAP = 4;

function overlaps(a, b) {
  return a.left < b.left + b.w && b.left < a.left + a.w && a.top < b.top + b.h && b.top < a.top + a.h;
}

function clamp(v, lo, hi) {
  return Math.max(lo, Math.min(hi, v));
}

// The places tried for one label, in order: [{left, top}] (the first is the fallback).
function candidates(it, keep, width, height, gap) {
  const out = [];
  if (it.kind === "slice" || !keep) {
    for (const k of OUTWARD) out.push({ left: clamp(it.x - it.w / 2, 0, width - it.w), top: it.y + gap + k * (it.h + 1) });
    return out;
  }
  const dist = { left: it.x - keep.x0, right: keep.x1 - it.x, top: it.y - keep.y0, bottom: keep.y1 - it.y };
  const sides = ["left", "right", "top", "bottom"].map((s, i) => [s, i]);
  sides.sort((a, b) => dist[a[0]] - dist[b[0]] || a[1] - b[1]);
  for (const [side] of sides) {
    if (side === "left" || side === "right") {
      const left = side === "left" ? Math.min(keep.x0, it.x) - gap - it.w : Math.max(keep.x1, it.x) + gap;
      for (const k of STEPS) out.push({ left, top: clamp(it.y - it.h / 2 + k * (it.h + 1), 0, height - it.h) });
    } else {
      const left = clamp(it.x - it.w / 2, 0, width - it.w);
      for (const k of OUTWARD) {
        const top = side === "top" ? Math.min(keep.y0, it.y) - gap - it.h - k * (it.h + 1)
          : Math.max(keep.y1, it.y) + gap + k * (it.h + 1);
        out.push({ left, top });
      }
    }
  }
  return out;
}

// items: [{x, y, w, h, kind}] (a label's point and its box's size, px), in the order they are
// placed; keep: {x0, y0, x1, y1} or null; returns [{left, top, w, h, free}] (free: no overlap).
export function placeLabels(items, keep, width, height, gap = LABEL_GAP) {
  const placed = [];
  return items.map((it) => {
    const tries = candidates(it, keep, width, height, gap);
    let found = null;
    for (const c of tries) {
      const box = { left: c.left, top: c.top, w: it.w, h: it.h };
      if (box.left < 0 || box.top < 0 || box.left + box.w > width || box.top + box.h > height) continue;
      if (keep && it.kind !== "slice" && overlaps(box, { left: keep.x0, top: keep.y0, w: keep.x1 - keep.x0, h: keep.y1 - keep.y0 })) continue;
      if (placed.some((p) => overlaps(box, p))) continue;
      found = { ...box, free: true };
      break;
    }
    if (found === null) {
      const c = tries[0];
      found = { left: clamp(c.left, 0, width - it.w), top: clamp(c.top, 0, height - it.h), w: it.w, h: it.h, free: false };
    }
    placed.push(found);
    return found;
  });
}

// The rectangle {x0, y0, x1, y1} holding the points [{x, y}], or null for none.
export function extentRect(points) {
  if (!points.length) return null;
  const xs = points.map((p) => p.x), ys = points.map((p) => p.y);
  return { x0: Math.min(...xs), y0: Math.min(...ys), x1: Math.max(...xs), y1: Math.max(...ys) };
}

// Fill `div` (the overlay over one canvas, width x height px) with `spots` ([{x, y, text, kind}],
// projected) placed clear of the rectangle of `extent` ([{x, y}], projected).
export function drawLabels(div, spots, extent, width, height) {
  const doc = div.ownerDocument;
  const shown = spots.filter((s) => s.text);
  const spans = shown.map((s) => {
    const span = doc.createElement("span");
    span.className = "rot4d-label";
    span.dataset.kind = s.kind || "edge";
    span.textContent = s.text;
    span.style.cssText = "position:absolute;left:0;top:0;font:10px sans-serif;color:#333;" +
      "background:rgba(255,255,255,0.72);padding:0 2px;white-space:nowrap;visibility:hidden";
    return span;
  });
  const svg = doc.createElementNS("http://www.w3.org/2000/svg", "svg");
  svg.setAttribute("width", String(width));
  svg.setAttribute("height", String(height));
  svg.style.cssText = "position:absolute;left:0;top:0;overflow:visible";
  div.replaceChildren(svg, ...spans);
  const items = shown.map((s, i) => ({ x: s.x, y: s.y, w: spans[i].offsetWidth, h: spans[i].offsetHeight, kind: s.kind }));
  const boxes = placeLabels(items, extentRect(extent), width, height);
  const line = (tag, attrs) => {
    const el = doc.createElementNS("http://www.w3.org/2000/svg", tag);
    for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, String(v));
    svg.appendChild(el);
  };
  boxes.forEach((b, i) => {
    const s = shown[i];
    spans[i].style.left = `${b.left}px`;
    spans[i].style.top = `${b.top}px`;
    spans[i].style.visibility = "visible";
    const nx = clamp(s.x, b.left, b.left + b.w), ny = clamp(s.y, b.top, b.top + b.h);
    if (Math.hypot(nx - s.x, ny - s.y) > 3) {
      line("line", { x1: s.x, y1: s.y, x2: nx, y2: ny, stroke: "#777", "stroke-width": 0.7, "stroke-dasharray": "2 2" });
    }
    if (s.kind !== "slice") line("circle", { cx: s.x, cy: s.y, r: 2, fill: "#333" });
  });
}
