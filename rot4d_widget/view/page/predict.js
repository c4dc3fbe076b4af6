// The page's prediction: the kernel's latest state (adopted whole, with its id) and the page's
// own steps after it.  The kernel's state for id (epoch, upto) holds every page step due at or
// before page time `upto`; the page applies its steps after `upto` on top -- client-side
// prediction with server reconciliation.  Steps already applied are kept while they are still
// what the keys make; otherwise the state is rebuilt from the kernel's (a late keyup).

import { KeyLog } from "./keys.js";
import { PageKeymap } from "./keymap.js";
import { PageState } from "./state.js";

// Two predicted states the same (every number a picture is made from).
export function sameState(a, b) {
  if (!a || !b || a.theta0 !== b.theta0 || a.alpha !== b.alpha || a.c0 !== b.c0) return false;
  for (let i = 0; i < 16; i++) if (a.matrix[i] !== b.matrix[i]) return false;
  return JSON.stringify(a.view) === JSON.stringify(b.view);
}

// Two page times of one key event as the kernel heard it (through seconds) and the page made it
// (rot4d_widget.view.steplog.SAME_MS).
export const SAME_MS = 1e-6;

export class Prediction {
  // `config`: rot4d_widget.view.pagestate.page_config; `kernel`: {epoch, upto, state} or null;
  // `previous`: the prediction this one replaces when the key table changes (a field's keys become
  // the page's once it holds its copy) -- the keys held then stay held, with the actions they were
  // pressed with, if the hold's schedule is the same
  constructor(config, kernel, previous = null) {
    this.config = config;
    this.keymap = new PageKeymap(config.keymap, config.shift_kinds);
    this.predicted = new Set(config.predicted_kinds || []);
    // a source's own actions the page steps too (a field's levels): name -> {rule, sign, repeat}
    this.actions = new Map(Object.entries(config.predicted_actions || {}));
    this.repeating = new Set(config.repeating_kinds || []);
    const log = new KeyLog(config.hold_delay, config.tick_rate);
    const same = previous && previous.log.holdMs === log.holdMs && previous.log.periodMs === log.periodMs;
    this.log = same ? previous.log : log;
    this.kernel = null;
    this.state = null;
    this.applied = [];
    this.version = 0;  // counts changes of the predicted state (a picture's cache key)
    if (kernel) this.adopt(kernel);
  }

  // The kernel's state for its id: the page's steps up to `upto` are in it.  False (not adopted)
  // when the page's own key events say otherwise (`agrees`).  The version moves only if the state
  // predicted is another once the page's later steps are on it again (`advance`): adopting the
  // kernel's state of what the page already shows draws nothing again.
  adopt(kernel) {
    if (!kernel || !kernel.state || !this.agrees(kernel)) return false;
    this.kernel = kernel;
    this.log.checkpoint(kernel.upto === null ? -Infinity : kernel.upto);
    this.adopted = { state: this.state, version: this.version };
    this.base = new PageState(kernel.state, this.config.bounds);
    this.state = this.base.copy();
    this.applied = [];
    this.version += 1;
    return true;
  }

  // Whether the kernel's state can be what the page's keys make by its `upto`: the keys it holds
  // as held (`keys`: [kid, page time pressed]) are those the page held then.  It is not when the
  // kernel holds a key the page released by then (it has not heard the release, and went on by
  // its estimate of a page it did not hear from) or lacks one the page pressed by then (it went
  // past the press by that estimate): the page's own steps stay until the kernel's state agrees.
  agrees(kernel) {
    if (!Array.isArray(kernel.keys) || typeof kernel.upto !== "number") return true;
    const upto = kernel.upto;
    const same = (a, b) => Math.abs(a - b) <= SAME_MS;
    const mine = [...this.log.keys.values()];
    const theirs = kernel.keys.filter((k) => Array.isArray(k) && typeof k[0] === "string" && typeof k[1] === "number");
    for (const [kid, down] of theirs) {
      const key = mine.find((k) => k.kid === kid && same(k.down, down));
      if (key && key.up !== null && key.up <= upto + SAME_MS) return false;
    }
    for (const key of mine) {
      const heldThen = key.down <= upto + SAME_MS && (key.up === null || key.up > upto + SAME_MS);
      if (heldThen && !theirs.some(([kid, down]) => kid === key.kid && same(key.down, down))) return false;
    }
    return true;
  }

  // True for an action the page steps itself (the state's kinds, a field's view kinds and levels).
  steps(action) {
    return this.predicted.has(action.kind) || (action.kind === "custom" && this.actions.has(action.name));
  }

  // A key event the page steps itself: {action, inverted, kid} or null (not ours: the kernel's).
  ours(event, kid) {
    const found = this.keymap.lookup(event);
    if (!found || !kid || !this.steps(found.action)) return null;
    return { ...found, kid };
  }

  press(kid, action, inverted, t) {
    const repeats = action.kind === "custom" ? !!this.actions.get(action.name).repeat : this.repeating.has(action.kind);
    return this.log.press(kid, action, inverted, t, repeats);
  }

  release(kid, t) {
    return this.log.release(kid, t);
  }

  releaseAll(t) {
    return this.log.releaseAll(t);
  }

  get held() {
    return this.log.held;
  }

  // Apply the steps due by page time `now`; true if the predicted state changed.
  advance(now) {
    if (!this.base) return false;
    const steps = this.log.steps(now);
    const done = this.applied;
    let same = done.length <= steps.length;
    for (let i = 0; same && i < done.length; i++) {
      same = done[i].t === steps[i].t && done[i].order === steps[i].order;
    }
    let todo = steps.slice(done.length);
    if (!same) {
      this.state = this.base.copy();
      this.applied = [];
      todo = steps;
    }
    let changed = !same;
    for (const s of todo) {
      changed = this.state.apply(s.action, s.inverted, this.actions.get(s.action.name)) || changed;
      this.applied.push(s);
    }
    if (changed) this.version += 1;
    const before = this.adopted;
    this.adopted = null;
    if (before && sameState(before.state, this.state)) {
      this.version = before.version;  // the kernel's state with the page's steps on it: what was shown
      return false;
    }
    return changed;
  }

  // Steps the page has made that the kernel's state does not hold yet.
  get pending() {
    return this.applied.length;
  }
}
