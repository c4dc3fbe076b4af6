// rot4d_widget companion (anywidget ES module, no build step).
//
// Jobs for one Scene, per displayed view of this invisible widget (job 1 also
// applies, as it arrives, what travels with each update: the rows each layer draws,
// `_rot4d_counts`, and a 3-D turn of the whole view, `_rot4d_turn`; and it stops the
// page from sending the row buffer's three.js `version` back after every update):
//  1. "drawn": after the pythreejs Scene has rendered a frame that contains
//     the latest assignment to the shared row buffer, send
//     {event: "drawn", seq, draw_ms} where seq is the buffer's `_rot4d_seq` (sent in
//     the same message as the array) and draw_ms the time since it arrived (the
//     kernel gives a slow page fewer updates in flight).  "Contains" is checked on the three.js
//     object itself (`buffer.obj`, a THREE.InterleavedBuffer): at the Scene's
//     `afterRender` (fired right after `renderer.render(...)`) its `array`
//     must be the array that arrived, and its `version` must have moved past
//     the one seen at the previous render (three.js uploads a buffer to the
//     GPU when its version moves).  The ack then leaves in the next
//     animation frame, once that frame has been presented.  An arrival that
//     is never rendered is never acknowledged; an id is acknowledged once.  A view
//     acknowledges the state it opens on once drawn (updates sent before it was shown).
//  2. focus loss: window blur or document hidden -> {event: "focus_lost", reason}.
//  3. Notebook 7 shortcut guard: a capture-phase key listener on `window`
//     calls preventDefault() while the pointer is over the canvas (the
//     element with CSS class `canvas_class`), so Notebook 7's command
//     shortcuts (m, x, c, y, z, j, k, ...) skip the event; ipyevents, which
//     listens on `document`, still receives and forwards it.  Ctrl/Meta/Alt
//     chords are left alone (they are not the widget's keys).
//  4. ipyevents leak guard: ipyevents adds a capture key listener on
//     `document` on mouseenter and removes it on mouseleave.  A canvas view
//     destroyed while hovered (cell re-run) never gets a mouseleave, and in
//     JupyterLab that listener then swallows every key on the page.  So each
//     canvas element of the scene gets a hidden <rot4d-leave-guard>
//     child whose disconnectedCallback (run as soon as the canvas leaves the
//     document, before ipyevents drops its element listeners) dispatches a
//     `mouseleave` on the canvas element: ipyevents' own handler then removes
//     its document listener.  The guard needs no companion view: it stays
//     with the canvas element and goes when the canvas goes.
//  6. rows drawn without instancing: just before each render the companion copies the rows
//     in use of the shared row buffer into one plain (non-instanced) geometry per layer
//     (a row becomes its template's 6 or 3 vertices, each carrying the row's columns) and
//     draws that instead of the instanced geometry.  Software WebGL (SwiftShader, what a
//     machine without a GPU runs) pays a fixed cost for every instance of an instanced draw
//     call; figures and command in docs/performance.md.  The shaders are unchanged: an attribute
//     reads the same columns, per vertex instead of per instance.  Filled in the scene's
//     `beforeRender` from the array three.js holds at that moment, so a frame draws one
//     whole update, and the drawn acknowledgement (job 1) stays exact.
//  7. the projection view (rot4d_widget/view/projection.py): from the skeleton (once per source)
//     and the state (the 4x4 matrix and hyperplane offsets) that travel in the row buffer's own
//     update message, the page rotates, projects, colours and finds the crossings
//     (projectSkeleton, exported for tests) and draws them with geometries of its own: no array
//     is sent to the projection, and both canvases change from the same message.
// All listeners are removed when the view is removed (and each layer gets its instanced
// geometry back).

import { GUARD_TAG, defineLeaveGuard, canvasHovered } from "./guards.js";
import { nextSurfaceVersion, CUBE, likeTexture } from "./uploads.js";
import { expansions, layerLayout, buildGeometry, makeExpansion, fillExpansion } from "./expand.js";
import { projections, decodeSkeleton, projectSkeleton } from "./projection.js";
import { modelId, dataOf, getModel } from "./models.js";
import { adoptKernel, attachKeys, attachPad, releaseKeys, turning } from "./turning.js";
import { askForTransfers, receiveChunk, transferStore, unpack } from "./transfer.js";
import { drawsOwn, forceOwn, ownHyperplanes, ownPicture, ownPictureReport, polytopeArrived } from "./pictures.js";
import { fieldArrived, freeField, noteContext, wantsTransfer } from "./field.js";
import { DEPTH_SCALE, FieldPicture, fieldDrawsOwn, forceOwnField, quickField } from "./fieldpicture.js";
import { drawLabels } from "./labels.js";

export { decodeSkeleton, projectSkeleton };

// A screenshot waits at most this long (ms) for page and kernel to agree on the state shown.
const SCREENSHOT_WAIT = 5000;

async function render({ model, el }) {
  el.style.display = "none";
  let alive = true;
  const cleanups = [];
  const send = (msg) => {
    if (alive) model.send(msg);
  };
  const listen = (target, type, f, capture = false) => {
    target.addEventListener(type, f, capture);
    cleanups.push(() => target.removeEventListener(type, f, capture));
  };

  // 3. shortcut guard
  const guard = (event) => {
    if (event.ctrlKey || event.metaKey || event.altKey) return;
    if (canvasHovered(model.get("canvas_class")) || canvasHovered(model.get("projection_class"))) event.preventDefault();
  };
  for (const type of ["keydown", "keypress", "keyup"]) listen(window, type, guard, true);

  // 4. leak guard: one guard in each canvas element of this scene.  Placed on
  // render (and a few times soon after, as the canvas view may come later),
  // after a scene render (at most twice a second), and on mouseover: a new canvas
  // can appear under a pointer that does not move.
  try {
    defineLeaveGuard();
  } catch (e) {
    console.warn("rot4d_widget companion: leave guard unavailable", e);
  }
  const ensureGuards = () => {
    if (!alive || typeof customElements === "undefined" || !customElements.get(GUARD_TAG)) return;
    for (const cls of [model.get("canvas_class"), model.get("projection_class")]) {
      if (!cls) continue;
      // a live collection, cheap; a canvas element has only a few children
      for (const host of document.getElementsByClassName(cls)) {
        if (!Array.from(host.children).some((c) => c.localName === GUARD_TAG)) {
          host.appendChild(document.createElement(GUARD_TAG));
        }
      }
    }
  };
  listen(document, "mouseover", ensureGuards, true);
  for (const ms of [0, 100, 500, 2000]) {
    const t = setTimeout(ensureGuards, ms);
    cleanups.push(() => clearTimeout(t));
  }

  // 2. focus loss (with the page's time: held keys are released then on both sides, one time)
  const focusLost = (reason) => {
    const t = performance.now();
    send({ event: "focus_lost", reason, t });
    releaseKeys(model, t);
  };
  listen(window, "blur", () => focusLost("blur"));
  listen(document, "visibilitychange", () => {
    if (document.visibilityState === "hidden") focusLost("hidden");
  });

  // 8. the page turns: its own copy of the state, stepped by the keys over this widget's canvases
  // (turning.js); the kernel's state adopted as it arrives
  const canvasClasses = () => [model.get("canvas_class"), model.get("projection_class")].filter((c) => c);
  const canvases = () => {
    const out = [];
    for (const cls of canvasClasses()) {
      for (const host of document.getElementsByClassName(cls)) out.push(host);
    }
    return out;
  };
  turning(model);
  attachKeys(model, { listen, hovered: () => canvasClasses().some(canvasHovered), canvases });
  attachPad(model, { listen, canvasClass: () => model.get("canvas_class") });
  const onKernelState = () => adoptKernel(model);
  const onConfig = () => turning(model);
  if (typeof model.on === "function") {
    model.on("change:kernel_state", onKernelState);
    model.on("change:config", onConfig);
    cleanups.push(() => {
      model.off("change:kernel_state", onKernelState);
      model.off("change:config", onConfig);
    });
  }
  // the readout is the kernel's: while the page is ahead of it (its own steps, keys held) the side
  // panel says so; and when the kernel does not answer
  const sideMark = (p, sh) => {
    const ahead = !!p && (p.pending > 0 || p.held.length > 0);
    for (const cls of canvasClasses()) {
      for (const side of document.getElementsByClassName(cls + "-side")) {
        side.classList.toggle("rot4d-behind", ahead && !sh.silent);
        side.classList.toggle("rot4d-silent", !!sh.silent);
      }
    }
  };
  const shared0 = turning(model);
  shared0.listeners.add(sideMark);
  cleanups.push(() => shared0.listeners.delete(sideMark));

  // 9. one-time transfers (transfer.js): asked for when offered and not held, put together here
  const onPageData = () => askForTransfers(model, (name) => wantsTransfer(model, name));
  const onTransfer = (msg, buffers) => {
    if (!receiveChunk(model, msg, buffers && buffers[0])) return;
    if (msg.name === "polytope") polytopeArrived(model);
    if (msg.name === "field" || msg.name === "field_box") fieldArrived(model);
  };
  const onClose = () => freeField(model);  // the widget closed: its field's copy goes
  if (typeof model.on === "function") {
    model.on("change:page_data", onPageData);
    model.on("change:field_config", onPageData);
    model.on("msg:custom", onTransfer);
    model.on("destroy", onClose);
    cleanups.push(() => {
      model.off("change:page_data", onPageData);
      model.off("change:field_config", onPageData);
      model.off("msg:custom", onTransfer);
      model.off("destroy", onClose);
    });
  }
  onPageData();
  // the test hook: the page's state, the kernel's id it rests on, the page's steps beyond it, the
  // pictures it made itself (`rows`: with the last one's rows)
  const pageHook = (rows = false) => {
    const p = turning(model).prediction;
    if (!p || !p.state) return null;
    const k = p.kernel || {};
    return { matrix: Array.from(p.state.matrix), theta0: p.state.theta0, alpha: p.state.alpha, c0: p.state.c0,
             epoch: k.epoch, upto: k.upto, pending: p.pending, held: p.held, version: p.version,
             own: ownPictureReport(model, rows) };
  };
  const hookPage = () => {
    for (const host of canvases()) host.rot4dPage = pageHook;
  };
  listen(document, "mouseover", hookPage, true);
  for (const ms of [0, 100, 500, 2000]) {
    const t = setTimeout(hookPage, ms);
    cleanups.push(() => clearTimeout(t));
  }

  const cleanup = () => {
    alive = false;
    for (const f of cleanups.splice(0)) {
      try {
        f();
      } catch (e) {
        console.warn("rot4d_widget companion: cleanup failed", e);
      }
    }
  };

  // 1. drawn acknowledgement, drawn counts, 3-D turn
  // Where this stands, on the (hidden) element for whoever inspects the page: the scene's
  // models still awaited (their ids), "attached", or why not.
  const waiting = new Set();
  const status = (text) => {
    if (el && el.dataset) el.dataset.rot4dCompanion = text;
  };
  const awaited = (manager, id, isAlive) => {
    waiting.add(id);
    status("waiting for models " + [...waiting].join(" "));
    return getModel(manager, id, isAlive).then((m) => {
      waiting.delete(id);
      status(waiting.size ? "waiting for models " + [...waiting].join(" ") : "models found");
      return m;
    });
  };
  try {
    const manager = model.widget_manager;
    const isAlive = () => alive;
    const ids = (name) => (model.get(name) || []).map(modelId);
    const [buffer, scene, geometries, meshes, textures] = await Promise.all([
      awaited(manager, modelId(model.get("buffer_model_id")), isAlive),
      awaited(manager, modelId(model.get("scene_model_id")), isAlive),
      Promise.all(ids("geometry_model_ids").map((id) => awaited(manager, id, isAlive))),
      Promise.all(ids("mesh_model_ids").map((id) => awaited(manager, id, isAlive))),
      Promise.all(ids("texture_model_ids").map((id) => awaited(manager, id, isAlive))),
    ]);
    status(alive ? "attached" : "removed");
    if (alive) {
      // The kernel owns the row buffer's state.  pythreejs would send the three.js buffer's
      // `version` back after every update (syncToModel -> save_changes): one more message
      // each way per update, and a kernel busy/idle status pair that JupyterLab redraws.
      const saveChanges = buffer.save_changes;
      buffer.save_changes = () => {};
      cleanups.push(() => {
        buffer.save_changes = saveChanges;
      });
      const version = () => (buffer.obj ? buffer.obj.version : undefined);
      // Draw only the rows in use: set in the same event that applied the array, so a
      // frame never draws a count with another update's rows.  Never more than the rows held.
      const applyCounts = () => {
        const counts = buffer.get("_rot4d_counts") || [];
        const obj = buffer.obj;
        const rows = obj && obj.array ? obj.array.length / obj.stride : 0;
        geometries.forEach((g, i) => {
          if (g.obj && Number.isInteger(counts[i])) g.obj.maxInstancedCount = Math.max(0, Math.min(counts[i], rows));
        });
      };
      // The whole view turned in 3-D (keys that leave w alone): one rotation for every mesh.
      let own = false; // the layers draw the page's own picture (pictures.js), not the kernel's rows
      let fieldOwn = false; // ... of a field (fieldpicture.js): its ray-cast mesh in place of the kernel's
      let drawnVersion = null; // the prediction's version the page's own picture last drawn shows
      let drawnCounts = []; // the rows each layer drew last (balls, bars, faces): for the test hook
      const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
      const applyTurn = () => {
        const m = own ? IDENTITY : buffer.get("_rot4d_turn");  // the page's rows are in the final frame
        if (!Array.isArray(m) || m.length !== 16) return;
        for (const mesh of meshes) {
          const obj = mesh.obj;
          if (!obj) continue;
          const e = obj.matrix.elements;
          for (let i = 0; i < 16; i++) e[i] = m[i];
          obj.quaternion.setFromRotationMatrix(obj.matrix);
        }
      };
      // A smooth surface (a field's isosurfaces): quantised arrays that travel with the rows
      // in the same message; uploaded into the surface mesh's geometry (placeholder arrays of
      // the same types) and its box into the material, so it is drawn with those rows.
      const copy = (dv, T) =>
        dv && dv.byteLength !== undefined ? new T(dv.buffer.slice(dv.byteOffset, dv.byteOffset + dv.byteLength)) : new T(0);
      let surfaceArrays = null; // what applySurface put into the surface geometry last
      // pythreejs may (re)build the surface geometry's three.js object from its placeholder
      // arrays after the companion filled it (the first view): true if it holds ours no more
      const surfaceLost = () => {
        const s = buffer.get("_rot4d_surface") || {};
        if (!s.n_vertices || !s.n_indices) return false;
        const mesh = meshes.find((m) => m.obj && m.obj.name === "surface");
        const g = mesh && mesh.obj.geometry;
        return !!g && !!g.attributes && !!g.attributes.position &&
          (surfaceArrays === null || surfaceArrays.geometry !== g || g.attributes.position.array !== surfaceArrays.position);
      };
      const applySurface = () => {
        const mesh = meshes.find((m) => m.obj && m.obj.name === "surface");
        const s = buffer.get("_rot4d_surface") || {};
        if (!mesh) return;
        const g = mesh.obj.geometry;
        const u = mesh.obj.material && mesh.obj.material.uniforms;
        const n = Number.isInteger(s.n_vertices) ? s.n_vertices : 0;
        const k = Number.isInteger(s.n_indices) ? s.n_indices : 0;
        if (!g || !g.attributes || !g.attributes.position || !g.index) return;
        if (!n || !k) {
          g.setDrawRange(0, 0);
          return;
        }
        const put = (attr, array) => {
          attr.setArray(array);
          attr.version = nextSurfaceVersion();
        };
        surfaceArrays = { position: copy(s.position, Uint16Array), geometry: g };
        put(g.attributes.position, surfaceArrays.position);
        put(g.attributes.normal, copy(s.normal, Int8Array));
        put(g.attributes.a_rgb, copy(s.rgb, Uint8Array));
        put(g.index, copy(s.index, Uint32Array));
        g.setDrawRange(0, k);
        if (u) {
          if (u.u_lo) u.u_lo.value = s.lo;
          if (u.u_span) u.u_span.value = s.span;
          if (u.u_opacity) u.u_opacity.value = s.opacity;
        }
        // one opaque surface writes depth; nested translucent ones (sorted back to front) do not
        if (mesh.obj.material) mesh.obj.material.depthWrite = !(s.opacity < 1);
      };
      // A field's cut ray-cast ("volume", "mip", "sections"; rot4d_widget/view/volume_layer.py):
      // the atlas and colour table go into the mesh's textures, one box of 36 vertices per cut
      // into its geometry, the mode and its numbers into uniforms; all from the same message.
      let ownTextures = null; // [atlas, colour table]: see applyVolume
      let volumeApplied = null; // {geometry, position, atlas, data}: what applyVolume put in last
      // pythreejs may (re)build the geometry or a texture after the companion filled them, or the
      // textures may not have been resolved yet when the message came: true if ours is not drawn
      const volumeLost = () => {
        const v = buffer.get("_rot4d_volume") || {};
        if (!(v.n_boxes > 0)) return false;
        const mesh = meshes.find((m) => m.obj && m.obj.name === "volume");
        if (!mesh) return false;
        const obj = mesh.obj;
        const u = obj.material && obj.material.uniforms;
        const atlas = u && u.u_atlas && u.u_atlas.value;
        const a = volumeApplied;
        return !a || !obj.visible || a.geometry !== obj.geometry || !obj.geometry.attributes.position ||
          obj.geometry.attributes.position.array !== a.position || atlas !== a.atlas || !atlas || atlas.image !== a.image;
      };
      const applyVolume = () => {
        const mesh = meshes.find((m) => m.obj && m.obj.name === "volume");
        volumeApplied = null;
        if (!mesh) return;
        const obj = mesh.obj;
        const v = buffer.get("_rot4d_volume") || {};
        const n = Number.isInteger(v.n_boxes) ? v.n_boxes : 0;
        const g = obj.geometry;
        const u = obj.material && obj.material.uniforms;
        const size = v.atlas_size || [0, 0];
        // Textures of the companion's own, made once like the pythreejs placeholders (their
        // class, format, type and filters): pythreejs writes its model's data back into its own
        // texture whenever the model is synced (and refuses other dimensions), so ours are not
        // its objects.  A texture set as a new uniform value needs the material set up again.
        if (u && !ownTextures && textures.length >= 2 && textures[0].obj && textures[1].obj) {
          ownTextures = textures.slice(0, 2).map((m) => likeTexture(m.obj));
          cleanups.push(() => ownTextures.forEach((t) => t.dispose && t.dispose()));
        }
        if (u && ownTextures && (!u.u_atlas || u.u_atlas.value !== ownTextures[0] || !u.u_lut || u.u_lut.value !== ownTextures[1])) {
          u.u_atlas = { value: ownTextures[0] };
          u.u_lut = { value: ownTextures[1] };
          obj.material.needsUpdate = true;
        }
        if (!n || !g || !g.attributes || !g.attributes.position || !u || !u.u_atlas || !u.u_atlas.value || !u.u_lut ||
            !u.u_lut.value || !(size[0] > 0 && size[1] > 0)) {
          obj.visible = false;
          return;
        }
        const boxes = copy(v.boxes, Float32Array);
        if (boxes.length < n * 12) {
          obj.visible = false;
          return;
        }
        const V = CUBE.length / 3;
        const arrays = { position: new Float32Array(n * V * 3) };
        for (const name of ["a_lo", "a_span", "a_shape", "a_tile"]) arrays[name] = new Float32Array(n * V * 3);
        for (let b = 0; b < n; b++) {
          for (let k = 0; k < V; k++) {
            const o = (b * V + k) * 3;
            for (let j = 0; j < 3; j++) {
              arrays.position[o + j] = CUBE[k * 3 + j];
              arrays.a_lo[o + j] = boxes[b * 12 + j];
              arrays.a_span[o + j] = boxes[b * 12 + 3 + j];
              arrays.a_shape[o + j] = boxes[b * 12 + 6 + j];
              arrays.a_tile[o + j] = boxes[b * 12 + 9 + j];
            }
          }
        }
        for (const [name, array] of Object.entries(arrays)) {
          const attr = g.attributes[name];
          if (!attr) continue;
          attr.setArray(array);
          attr.version = nextSurfaceVersion();
        }
        g.setDrawRange(0, n * V);
        const atlas = u.u_atlas.value;
        atlas.image = { data: copy(v.atlas, Uint8Array), width: size[0], height: size[1] };
        atlas.needsUpdate = true;
        const lut = u.u_lut.value;
        lut.image = { data: copy(v.lut, Uint8Array), width: 256, height: 1 };
        lut.needsUpdate = true;
        const set = (name, value) => {
          if (!u[name]) return;
          const cur = u[name].value;
          if (cur && typeof cur.fromArray === "function" && Array.isArray(value)) cur.fromArray(value);
          else u[name].value = value;
        };
        set("u_atlas_size", [size[0], size[1]]);
        set("u_mode", Number(v.mode) || 0);
        set("u_sections", v.sections || [0.5, 0.5, 0.5]);
        set("u_density", Number(v.density) || 0);
        set("u_step", Number(v.step) || 0.5);
        obj.material.uniformsNeedUpdate = true;
        obj.visible = true;  // hidden again before each frame while the page draws its own (beforeRender)
        volumeApplied = { geometry: g, position: arrays.position, atlas, image: atlas.image };
      };
      // 6. rows drawn without instancing: geometries[i] is meshes[i]'s (balls, bars, faces)
      const layers = geometries.slice(0, 3).map((model, i) => ({ model, mesh: meshes[i], e: null }));
      const release = (layer) => {
        const e = layer.e;
        layer.e = null;
        if (!e) return;
        const mesh = layer.mesh && layer.mesh.obj;
        if (mesh && mesh.geometry === e.geometry) mesh.geometry = e.inst;
        if (--e.users > 0) return;
        expansions.delete(e.inst);
        if (e.geometry.dispose) e.geometry.dispose();
      };
      cleanups.push(() => layers.forEach(release));
      const expand = (picture) => {
        const obj = picture ? { array: picture.rows, stride: picture.stride, version: picture.version } : buffer.obj;
        if (!obj || !obj.array || !(obj.stride > 0)) return;
        const held = Math.floor(obj.array.length / obj.stride);
        const counts = picture ? picture.counts : buffer.get("_rot4d_counts") || [];
        drawnCounts = Array.from(counts);
        layers.forEach((layer, i) => {
          const inst = layer.model.obj;
          const mesh = layer.mesh && layer.mesh.obj;
          if (!inst || !mesh) return;
          if (layer.e && layer.e.inst !== inst) release(layer); // pythreejs rebuilt the geometry
          if (!layer.e) {
            let shared = expansions.get(inst);
            if (!shared) {
              const layout = layerLayout(inst);
              if (!layout) return; // not a layer this module knows: it stays instanced
              shared = makeExpansion(inst, layout, Math.max(held, 1));
              expansions.set(inst, shared);
            }
            shared.users++;
            layer.e = shared;
          }
          const e = layer.e;
          if (e.capacity < held) {
            // the capacity grew: a new geometry (a GL buffer cannot take a longer array in place)
            const old = e.geometry;
            Object.assign(e, buildGeometry(inst, e.layout, held));
            if (old.dispose) old.dispose();
          }
          const count = Number.isInteger(counts[i]) ? counts[i] : held;
          if (e.rows !== obj.array || e.version !== obj.version || e.count !== count) {
            fillExpansion(e, obj.array, obj.stride, count);
            e.rows = obj.array;
            e.version = obj.version;
            e.count = count;
          }
          if (mesh.geometry !== e.geometry) mesh.geometry = e.geometry;
        });
      };
      if (geometries.length) applyCounts();
      if (meshes.length) applyTurn();
      if (meshes.length) applySurface();
      if (meshes.length) applyVolume();
      // 7. the projection: the kernel names its meshes and scene (`projection_model_ids`) when it
      // is first shown; each update's skeleton and state are projected here (projectSkeleton)
      // into geometries of the companion's own, shared by every view of this companion (keyed by
      // the edges mesh's three.js object), which the two meshes draw in place of their
      // placeholders.  Computed in the projection scene's `beforeRender` from the buffer's values
      // at that moment; an arriving state asks that scene to render.
      let proj = null; // {lines, points, scene} models
      let projCleanup = null;
      const projectionShared = (lo) => {
        let g = projections.get(lo);
        if (g) return g;
        const G = lo.geometry && lo.geometry.constructor;
        const A = lo.geometry && lo.geometry.attributes && lo.geometry.attributes.position &&
          lo.geometry.attributes.position.constructor;
        if (typeof G !== "function" || typeof A !== "function" || !A.prototype.setArray) return null;
        const attr = (n) => new A(new Float32Array(3 * n), 3);
        const lines = new G();
        const points = new G();
        const add = (geometry, name, a) => (geometry.addAttribute ? geometry.addAttribute(name, a) : geometry.setAttribute(name, a));
        add(lines, "position", attr(1));
        add(lines, "color", attr(1));
        lines.setIndex(new A(new Uint32Array(0), 1));
        add(points, "position", attr(1));
        g = { lines, points, sk: undefined, decoded: null, st: undefined, result: null };
        projections.set(lo, g);
        return g;
      };
      let ownProj = null; // the state message of the page's own state, made once per state
      const ownProjection = (p) => {
        if (!ownProj || ownProj.version !== p.version) {
          ownProj = { version: p.version, msg: ownHyperplanes(model, p.state) };
        }
        return ownProj.msg;
      };
      const projectionBefore = () => {
        const lo = proj && proj.lines.obj, po = proj && proj.points.obj;
        if (!lo || !po) return;
        const g = projectionShared(lo);
        if (!g) return;
        const sk = buffer.get("_rot4d_skeleton");
        // the page's own state while it draws its own picture (c0, or a stack's every cut)
        const mine = own && turning(model).prediction;
        const st = mine && mine.state ? ownProjection(mine) : buffer.get("_rot4d_project");
        if (g.sk !== sk) {
          g.sk = sk;
          g.decoded = decodeSkeleton(sk);
          g.st = undefined;
        }
        if (g.st !== st) {
          g.st = st;
          const out = g.decoded ? projectSkeleton(g.decoded, st) : null;
          g.result = out;
          const set = (a, array) => {
            if (a.array === array) return;
            a.setArray(array);
            a.needsUpdate = true;
          };
          if (out) {
            set(g.lines.attributes.position, out.positions);
            set(g.lines.attributes.color, out.rgb);
            set(g.lines.index, out.index);
            set(g.points.attributes.position, out.points);
          }
        }
        // every frame: an object pythreejs rebuilt from its model comes back with its placeholder
        const out = g.result;
        lo.visible = !!out && out.index.length > 0;
        po.visible = !!out && out.points.length > 0;
        if (lo.geometry !== g.lines) lo.geometry = g.lines;
        if (po.geometry !== g.points) po.geometry = g.points;
      };
      // the test hook: the arrays last computed, on the projection canvas's element
      let hookAt = -Infinity;
      const projectionAfter = () => {
        const now = performance.now();
        const cls = model.get("projection_class");
        if (now - hookAt < 500 || !cls || !proj) return;
        hookAt = now;
        const lo = proj.lines.obj;
        const hook = () => {
          const g = lo && projections.get(lo);
          const o = g && g.result;
          return o ? { positions: Array.from(o.positions), rgb: Array.from(o.rgb), index: Array.from(o.index),
                       points: Array.from(o.points), state: g.st } : null;
        };
        for (const host of document.getElementsByClassName(cls)) host.rot4dProjection = hook;
      };
      const projectionRerender = () => {
        if (proj && proj.scene) proj.scene.trigger("rerender", proj.scene, {});
      };
      const attachProjection = async () => {
        const pids = ids("projection_model_ids");
        if (projCleanup) projCleanup();
        projCleanup = null;
        proj = null;
        if (pids.length !== 3) return;
        const [lines, points, pscene] = await Promise.all(pids.map((id) => getModel(manager, id, isAlive)));
        if (!alive || ids("projection_model_ids").join() !== pids.join()) return;
        proj = { lines, points, scene: pscene };
        pscene.on("beforeRender", projectionBefore);
        pscene.on("afterRender", projectionAfter);
        projCleanup = () => {
          pscene.off("beforeRender", projectionBefore);
          pscene.off("afterRender", projectionAfter);
        };
        hookAt = -Infinity;
        projectionRerender();
      };
      const onProjectionIds = () => attachProjection().catch((e) => console.warn("rot4d_widget companion: projection not found", e));
      if (typeof model.on === "function") model.on("change:projection_model_ids", onProjectionIds);
      cleanups.push(() => {
        if (typeof model.off === "function") model.off("change:projection_model_ids", onProjectionIds);
        if (projCleanup) projCleanup();
      });
      onProjectionIds();
      // what became of each rendered frame, on the hidden element for whoever inspects the page
      const acks = {};
      if (el) el.rot4dAcks = acks;
      const why = (k) => {
        acks[k] = (acks[k] || 0) + 1;
      };
      let pending = null; // {seq, data, after}: the latest update not yet acknowledged
      let lastSent = null;
      let renderedVersion = version(); // three.js buffer version at the previous render
      // The state this view opens on (updates the kernel sent before any view was shown, e.g.
      // keys pressed from code in the displaying cell): acknowledged once drawn, or the kernel
      // would await them until a newer update leaves.
      const seq0 = buffer.get("_rot4d_seq");
      if (Number.isInteger(seq0) && seq0 > 0) pending = { seq: seq0, data: null, after: undefined };
      // The attributes of one message arrive as one synchronous burst of change:<name>
      // events (pythreejs applies the array in its own); collect them and act once,
      // in a microtask, or at the next render if that comes first.
      let batch = null;
      const settle = () => {
        const b = batch;
        batch = null;
        if (b === null) return;
        if (b.counts || b.array) applyCounts();
        if (b.surface) applySurface();
        if (b.volume) applyVolume();
        if (b.project) projectionRerender();
        if (b.turn) {
          applyTurn();
          scene.trigger("rerender", scene, {}); // a turn alone changes no three.js buffer
        }
        const data = b.array ? dataOf(buffer.get("array")) : null;
        if (b.seq) {
          // `after`: the version before this array can have been uploaded; a turn alone
          // (data null) is in the next frame drawn.
          pending = { seq: buffer.get("_rot4d_seq"), data, after: renderedVersion, at: performance.now() };
        } else if (b.array && pending !== null && pending.data !== null) {
          pending = { seq: pending.seq, data, after: renderedVersion, at: pending.at }; // a growth step re-sent the rows
        }
      };
      const note = (what) => () => {
        if (batch === null) {
          batch = {};
          queueMicrotask(settle);
        }
        batch[what] = true;
      };
      const watched = { array: note("array"), _rot4d_seq: note("seq"), _rot4d_counts: note("counts"), _rot4d_turn: note("turn"),
                        _rot4d_surface: note("surface"), _rot4d_volume: note("volume"),
                        _rot4d_labels: note("labels"), _rot4d_label_extent: note("labels"), _rot4d_project: note("project"),
                        _rot4d_skeleton: note("project") };
      let guardsAt = -Infinity;
      // Labels pinned to points of the view (`_rot4d_labels`: a field's box corners with their data
      // coordinates, a stack's slices with their w): an overlay over each canvas of this scene, each
      // text placed from where its point projects through the camera of the frame just drawn, turned
      // with the meshes, clear of where the data's extent (`_rot4d_label_extent`) projects
      // (labels.js).  Rewritten only when a position or a text changed.
      const overlays = new Map(); // canvas host element -> {div, key}
      cleanups.push(() => overlays.forEach((o) => o.div.remove()));
      const placeLabels = (camera) => {
        const labels = fieldOwn ? [] : buffer.get("_rot4d_labels") || [];  // the kernel's: not while the page draws
        const extent = labels.length ? buffer.get("_rot4d_label_extent") || [] : [];
        const cls = model.get("canvas_class");
        if (!cls || !camera || !camera.projectionMatrix) return;
        const turn = meshes.length && meshes[0].obj ? meshes[0].obj.matrixWorld : null;
        const V = camera.position.constructor;
        for (const host of document.getElementsByClassName(cls)) {
          const canvas = host.localName === "canvas" ? host : host.querySelector("canvas");
          if (!canvas || !canvas.isConnected) continue;
          const w = canvas.clientWidth, h = canvas.clientHeight;
          const at = (p) => {
            const v = new V(p[0], p[1], p[2]);
            if (turn) v.applyMatrix4(turn);
            v.project(camera);
            return { x: Math.round(((v.x + 1) / 2) * w), y: Math.round(((1 - v.y) / 2) * h) };
          };
          const spots = labels.map((l) => ({ ...at(l.p), text: String(l.text || ""), kind: String(l.kind || "edge") }));
          const box = extent.map(at);
          const key = JSON.stringify([spots, box, w, h]);
          let o = overlays.get(host);
          if (o && o.key === key && o.div.isConnected) continue;
          if (!o || !o.div.isConnected) {
            const div = document.createElement("div");
            div.className = "rot4d-labels";
            div.style.cssText = "position:absolute;left:0;top:0;width:0;height:0;pointer-events:none;z-index:1";
            if (getComputedStyle(host).position === "static") host.style.position = "relative";
            host.appendChild(div);
            o = { div, key: null };
            overlays.set(host, o);
          }
          o.key = key;
          drawLabels(o.div, spots, box, w, h);
        }
      };
      const onRendered = (_scene, _renderer, camera) => {
        settle();
        try {
          placeLabels(camera);
        } catch (e) {
          console.warn("rot4d_widget companion: labels not placed", e);
        }
        if (!fieldOwn && surfaceLost()) {
          applySurface();
          scene.trigger("rerender", scene, {});
        }
        if (!fieldOwn && volumeLost()) {
          applyVolume();
          if (volumeApplied) scene.trigger("rerender", scene, {});
        }
        // A scan of the document for canvases (a live class collection walks the whole page
        // after any DOM change): at most twice a second, not on every frame.
        const now = performance.now();
        if (now - guardsAt > 500) {
          guardsAt = now;
          ensureGuards();
        }
        const obj = buffer.obj;
        const p = pending;
        renderedVersion = version();
        why("renders");
        if (p === null || !obj) return why(p === null ? "nothing pending" : "no buffer object");
        // not in this frame unless three.js holds the new array and re-uploaded it
        if (p.data !== null && obj.array !== p.data) return why("another array");
        if (p.data !== null && p.after !== undefined && !(obj.version > p.after)) return why("not re-uploaded");
        pending = null;
        if (p.seq === lastSent) return why("sent already");
        lastSent = p.seq;
        acks.last = p.seq;
        // The canvas holds the new pixels now; wait one more frame so that the
        // frame has been presented (and any rAF read-back has seen it).
        // With it, the time since the update arrived: the kernel gives a slow page fewer in flight.
        requestAnimationFrame(() => {
          const msg = { event: "drawn", seq: p.seq };
          if (Number.isFinite(p.at)) msg.draw_ms = Math.max(0, performance.now() - p.at);
          send(msg);
        });
      };
      for (const [name, f] of Object.entries(watched)) {
        buffer.on("change:" + name, f);
        cleanups.push(() => buffer.off("change:" + name, f));
      }
      scene.on("afterRender", onRendered);
      cleanups.push(() => scene.off("afterRender", onRendered));
      // the frame about to be drawn takes the update's counts and turn, and its rows unpacked
      // While keys are held a ray-cast picture is drawn at half the renderer's pixel ratio (a
      // quarter of the rays; the browser scales the canvas up), at rest at its own again.
      let baseRatio = null;
      let ratioRenderer = null;
      const applyRatio = (renderer) => {
        if (!renderer || typeof renderer.setPixelRatio !== "function") return;
        const v = buffer.get("_rot4d_volume") || {};
        if (renderer !== ratioRenderer) {
          if (ratioRenderer && baseRatio !== null) ratioRenderer.setPixelRatio(baseRatio);
          ratioRenderer = renderer;
          baseRatio = renderer.getPixelRatio();
        }
        const half = (v.n_boxes > 0 && v.held) || (fieldOwn && quickField(model));
        const want = half ? baseRatio / 2 : baseRatio;
        if (renderer.getPixelRatio() !== want) renderer.setPixelRatio(want);
      };
      cleanups.push(() => {
        if (ratioRenderer && baseRatio !== null && ratioRenderer.getPixelRatio() !== baseRatio) {
          ratioRenderer.setPixelRatio(baseRatio);
        }
      });
      // 10. the page's own picture of a field (fieldpicture.js): its mesh "field" in place of the
      // kernel's surface and volume meshes while the page draws, given back after
      const fieldMesh = meshes.find((m) => m.obj && m.obj.name === "field");
      const fieldPic = fieldMesh && textures.length >= 3 && textures[2].obj && textures[1].obj
        ? new FieldPicture(fieldMesh, textures[2].obj.constructor, textures[1].obj) : null;
      const kernelMeshes = () => meshes.filter((m) => m.obj && (m.obj.name === "surface" || m.obj.name === "volume"));
      const setFieldOwn = (on) => {
        fieldOwn = on;
        if (on) {
          for (const m of kernelMeshes()) m.obj.visible = false;
          return;
        }
        fieldPic.hide();
        for (const m of kernelMeshes()) if (m.obj.name === "surface") m.obj.visible = !!m.get("visible");
        applySurface();
        applyVolume();
      };
      const beforeRender = (_scene, renderer, camera) => {
        settle();
        if (noteContext(renderer)) onPageData();  // now the page knows whether it can hold a field
        const p = turning(model).prediction;
        const seq = buffer.get("_rot4d_seq");
        const mine = polytopeArrived(model) !== null && drawsOwn(model, p, seq);
        const mineField = !mine && fieldPic !== null && fieldDrawsOwn(model, p, seq);
        const fieldRows = mineField ? fieldPic.draw(model, p) : null;
        if (!!fieldRows !== fieldOwn) setFieldOwn(!!fieldRows);
        // a kernel's picture that arrives while the page draws its own (sent before the page took
        // over: keys held from before the page had its copy) must not show beside it: two ray
        // casts a frame, the kernel's of an older state
        if (fieldOwn) for (const m of kernelMeshes()) m.obj.visible = false;
        if ((mine || !!fieldRows) !== own) {
          own = mine || !!fieldRows;
          applyTurn();
        }
        const eye = camera && camera.position ? [camera.position.x, camera.position.y, camera.position.z] : null;
        expand(mine ? ownPicture(model, p, eye) : fieldRows);
        drawnVersion = own && p ? p.version : null;
        applyRatio(renderer);
      };
      // the page's own picture changes with its state: draw again (not for a state already drawn:
      // the kernel's state of what the page shows, adopted, keeps its version)
      const redraw = () => {
        const p = turning(model).prediction;
        const seq = buffer.get("_rot4d_seq");
        const want = drawsOwn(model, p, seq) || (fieldPic !== null && fieldDrawsOwn(model, p, seq));
        if (want !== own || (want && (!p || p.version !== drawnVersion))) {
          scene.trigger("rerender", scene, {});
          projectionRerender();
        }
      };
      const sharedTurn = turning(model);
      sharedTurn.listeners.add(redraw);
      cleanups.push(() => sharedTurn.listeners.delete(redraw));
      // the test hook: draw the page's own picture at rest too (to compare it with the kernel's), and
      // say which is drawn
      const hookDraw = () => {
        for (const cls of canvasClasses()) {
          for (const host of document.getElementsByClassName(cls)) {
            host.rot4dForceOwn = (on) => {
              forceOwn(model, on);
              forceOwnField(model, on);
              scene.trigger("rerender", scene, {});
            };
            host.rot4dDrawsOwn = () => own;
            // which of the kernel's field meshes (surface, volume) are drawn, and whether the page
            // draws its own field picture now
            host.rot4dFieldMeshes = () => ({ own: fieldOwn, kernel: kernelMeshes().filter((m) => m.obj.visible).map((m) => m.obj.name) });
            // the page's field picture as each pixel's first surface hit's distance (field.frag
            // u_output), with the camera it was drawn with: read the canvas after a frame
            host.rot4dFieldDepth = (on) => {
              if (!fieldPic) return null;
              fieldPic.setOutput(on);
              scene.trigger("rerender", scene, {});
              const cam = scene.obj && scene.obj.children.find((c) => c.isCamera);
              return cam ? { world: Array.from(cam.matrixWorld.elements), projection: Array.from(cam.projectionMatrix.elements),
                             scale: DEPTH_SCALE } : { scale: DEPTH_SCALE };
            };
            host.rot4dCounts = () => drawnCounts.slice();
          }
        }
      };
      listen(document, "mouseover", hookDraw, true);
      hookDraw();
      scene.on("beforeRender", beforeRender);
      cleanups.push(() => scene.off("beforeRender", beforeRender));

      // 5. screenshot: {event: "screenshot", id} from the kernel -> the canvas as a PNG data URL.
      // Read in the task that rendered (after a render asked for here): only then is the
      // WebGL drawing buffer sure to hold the picture.  A frozen view that does not render is
      // read after a second, as it stands.
      const findCanvas = () => {
        const cls = model.get("canvas_class");
        if (!cls) return null;
        for (const host of document.getElementsByClassName(cls)) {
          const c = host.localName === "canvas" ? host : host.querySelector("canvas");
          if (c && c.isConnected && c.width > 0 && c.height > 0) return c;
        }
        return null;
      };
      const onMessage = (msg) => {
        if (!msg || msg.event !== "screenshot") return;
        const id = msg.id;
        const canvas = findCanvas();
        if (!canvas) {
          send({ event: "screenshot", id, error: "no canvas of this view is in the page" });
          return;
        }
        let done = false;
        const grab = () => {
          if (done) return;
          done = true;
          scene.off("afterRender", grab);
          try {
            send({ event: "screenshot", id, png: canvas.toDataURL("image/png"), width: canvas.width, height: canvas.height });
          } catch (e) {
            send({ event: "screenshot", id, error: String(e) });
          }
        };
        // The picture of the state page and kernel agree on: no key held, no step of the page's
        // beyond the kernel's state, and the kernel's picture of that state arrived.  Waited for
        // (at most SCREENSHOT_WAIT), then read at the next render (a frozen view: a second later).
        const settled = () => {
          const p = turning(model).prediction;
          if (p && (p.held.length || p.pending)) return false;
          const ks = model.get("kernel_state") || {};
          const seq = buffer.get("_rot4d_seq");
          return ks.picture !== "pending" && (!Number.isInteger(ks.picture) || seq >= ks.picture);
        };
        let waited = 0;
        const whenSettled = () => {
          if (done) return;
          if (!settled() && waited < SCREENSHOT_WAIT) {
            waited += 50;
            timers.push(setTimeout(whenSettled, 50));
            return;
          }
          scene.on("afterRender", grab);
          timers.push(setTimeout(grab, 1000));
          scene.trigger("rerender", scene, {});
        };
        const timers = [];
        cleanups.push(() => {
          timers.forEach(clearTimeout);
          scene.off("afterRender", grab);
        });
        whenSettled();
      };
      model.on("msg:custom", onMessage);
      cleanups.push(() => model.off("msg:custom", onMessage));
    }
  } catch (e) {
    status("failed: " + String(e));
    console.warn("rot4d_widget companion: scene models not found; no drawn acknowledgements", e);
  }
  return cleanup;
}

export default { render };
