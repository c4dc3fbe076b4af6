// Key events to actions in the page, by the same rules as rot4d_widget.core.keymap.Keymap.lookup,
// from the table the kernel sends (`PageKeymap(config.keymap)`): digits by their physical key
// (Digit4 and Numpad4), other characters by the character typed, longer names as a
// KeyboardEvent.code; Ctrl / Alt / Meta chords are not the widget's; Shift inverts only the kinds
// the kernel says (`config.shift_kinds`).

const DIGIT_CODE = /^(?:Digit|Numpad)([0-9])$/;

// An action as the kernel sends it: {kind, planes, sign, name} (rot4d_widget.view.pagestate).
function action(data) {
  if (!data || typeof data.kind !== "string") throw new Error("an action needs a kind");
  return { kind: data.kind, planes: String(data.planes || ""), sign: Number(data.sign) || 0,
           name: String(data.name || "") };
}

export class PageKeymap {
  constructor(bindings, shiftKinds) {
    this.bindings = new Map(Object.entries(bindings || {}).map(([k, a]) => [k, action(a)]));
    this.shiftKinds = new Set(shiftKinds || []);
  }

  // {action, inverted} for a browser KeyboardEvent (or the dict ipyevents sends), or null.
  lookup(event) {
    if (!event || event.ctrlKey || event.altKey || event.metaKey) return null;
    const code = typeof event.code === "string" ? event.code : "";
    const key = typeof event.key === "string" ? event.key : "";
    const shift = event.shiftKey === true;
    let found;
    const m = DIGIT_CODE.exec(code);
    if (m) found = this.bindings.get(m[1]);
    if (found === undefined && code.length > 1 && !m) found = this.bindings.get(code);
    if (found === undefined && key.length === 1) found = this.bindings.get(key.toLowerCase());
    if (found === undefined) return null;
    return { action: found, inverted: shift && this.shiftKinds.has(found.kind) };
  }

  // Scripting and key pad lookup: ("C") or ("c", true), as Keymap.resolve.
  resolve(key, shift = false) {
    let found;
    if (key.length === 1) {
      const lower = key.toLowerCase();
      if (lower !== key) shift = true;
      found = this.bindings.get(lower);
    } else {
      const m = DIGIT_CODE.exec(key);
      found = this.bindings.get(m ? m[1] : key);
    }
    if (found === undefined) return null;
    return { action: found, inverted: !!shift && this.shiftKinds.has(found.kind) };
  }
}

// The key's identity while held: its code, else its lower-cased key (rot4d_widget.view.keys.key_id).
export function keyId(event) {
  if (typeof event.code === "string" && event.code) return event.code;
  if (typeof event.key === "string" && event.key) return "key:" + event.key.toLowerCase();
  return null;
}
