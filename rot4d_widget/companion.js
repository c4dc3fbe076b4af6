// rot4d_widget companion (anywidget ES module, no build step).
//
// Three jobs for one Scene, per displayed view of this invisible widget:
//  1. "drawn": after the pythreejs Scene has rendered a frame that contains
//     the latest assignment to the shared row buffer, send
//     {event: "drawn", seq} where seq is the buffer's `_rot4d_seq` (sent in
//     the same message as the array).  The Scene model fires `afterRender`
//     right after `renderer.render(...)`: the canvas then holds the new
//     pixels; the ack leaves in the next animation frame, once that frame has
//     been presented.  An arrival that is never rendered is never acknowledged.
//  2. focus loss: window blur or document hidden -> {event: "focus_lost", reason}.
//  3. Notebook 7 shortcut guard: a capture-phase key listener on `window`
//     calls preventDefault() while the pointer is over the canvas (the
//     element with CSS class `canvas_class`), so Notebook 7's command
//     shortcuts (m, x, c, y, z, j, k, ...) skip the event; ipyevents, which
//     listens on `document`, still receives and forwards it.  Ctrl/Meta/Alt
//     chords are left alone (they are not the widget's keys).
// All listeners are removed when the view is removed.

function modelId(ref) {
  return typeof ref === "string" && ref.startsWith("IPY_MODEL_") ? ref.slice(10) : ref;
}

function canvasHovered(cls) {
  if (!cls) return false;
  try {
    return document.querySelector("." + CSS.escape(cls) + ":hover") !== null;
  } catch (e) {
    return false;
  }
}

async function render({ model, el }) {
  el.style.display = "none";
  let alive = true;
  const cleanups = [];
  const send = (msg) => {
    if (alive) model.send(msg);
  };

  // 3. shortcut guard
  const guard = (event) => {
    if (event.ctrlKey || event.metaKey || event.altKey) return;
    if (canvasHovered(model.get("canvas_class"))) event.preventDefault();
  };
  for (const type of ["keydown", "keypress", "keyup"]) {
    window.addEventListener(type, guard, true);
    cleanups.push(() => window.removeEventListener(type, guard, true));
  }

  // 2. focus loss
  const onBlur = () => send({ event: "focus_lost", reason: "blur" });
  const onVisibility = () => {
    if (document.visibilityState === "hidden") send({ event: "focus_lost", reason: "hidden" });
  };
  window.addEventListener("blur", onBlur);
  document.addEventListener("visibilitychange", onVisibility);
  cleanups.push(() => window.removeEventListener("blur", onBlur));
  cleanups.push(() => document.removeEventListener("visibilitychange", onVisibility));

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

  // 1. drawn acknowledgement
  try {
    const manager = model.widget_manager;
    const [buffer, scene] = await Promise.all([
      manager.get_model(modelId(model.get("buffer_model_id"))),
      manager.get_model(modelId(model.get("scene_model_id"))),
    ]);
    if (alive) {
      let pending = null;
      const onArray = () => {
        pending = buffer.get("_rot4d_seq");
      };
      const onRendered = () => {
        if (pending === null) return;
        const seq = pending;
        pending = null;
        // The canvas holds the new pixels now; wait one more frame so that the
        // frame has been presented (and any rAF read-back has seen it).
        requestAnimationFrame(() => send({ event: "drawn", seq: seq }));
      };
      buffer.on("change:array", onArray);
      scene.on("afterRender", onRendered);
      cleanups.push(() => buffer.off("change:array", onArray));
      cleanups.push(() => scene.off("afterRender", onRendered));
    }
  } catch (e) {
    console.warn("rot4d_widget companion: scene models not found; no drawn acknowledgements", e);
  }
  return cleanup;
}

export default { render };
