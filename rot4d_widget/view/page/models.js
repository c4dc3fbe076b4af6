// The widget manager's models: ids, data unions, and models found while a page restores them.

export function modelId(ref) {
  return typeof ref === "string" && ref.startsWith("IPY_MODEL_") ? ref.slice(10) : ref;
}

// The typed array three.js gets for a data-union value (an ndarray's `.data`).
export function dataOf(value) {
  return value && value.data !== undefined ? value.data : value;
}

// widget_manager.get_model rejects while a model is not registered yet (e.g.
// while a reloaded page restores widgets from the kernel): retry, 50 ms first,
// then up to 1 s apart, for about a minute, while this view lives.
export async function getModel(manager, id, isAlive) {
  for (let i = 0, wait = 50; ; i++, wait = Math.min(2 * wait, 1000)) {
    try {
      return await manager.get_model(id);
    } catch (e) {
      if (i >= 65 || !isAlive()) throw e;
      await new Promise((resolve) => setTimeout(resolve, wait));
    }
  }
}

