// Held keys by the page's clock (rot4d_widget.view.steplog, the same schedule in the same
// operations): a key pressed at page time `down` (ms, the event's timeStamp) steps then, and held,
// its k-th repeat is due at down + hold + (k - 1) * period; released at `up`, its steps are those
// due at or before `up`.  Steps of several keys go in page-time order, a tie in press order.

export function stepTime(down, k, holdMs, periodMs) {
  return k === 0 ? down : down + holdMs + (k - 1) * periodMs;
}

export class KeyLog {
  constructor(holdDelay, tickRate) {
    this.holdMs = holdDelay * 1000.0;
    this.periodMs = 1000.0 / tickRate;
    this.keys = new Map();  // kid -> {kid, action, inverted, down, up, order, repeats, after}
    this.order = 0;
  }

  // false while the key is held already (a keydown without a keyup between: a repeat)
  press(kid, action, inverted, t, repeats) {
    const held = this.keys.get(kid);
    if (held && held.up === null) return false;
    if (held) {
      this.keys.delete(kid);
      this.keys.set(`${kid}#${held.order}`, held);
    }
    this.order += 1;
    this.keys.set(kid, { kid, action, inverted: !!inverted, down: t, up: null, order: this.order,
                         repeats: !!repeats, after: -Infinity });
    return true;
  }

  release(kid, t) {
    const key = this.keys.get(kid);
    if (!key || key.up !== null) return false;
    key.up = Math.max(t, key.down);
    return true;
  }

  releaseAll(t) {
    const out = [];
    for (const kid of [...this.keys.keys()]) if (this.release(kid, t)) out.push(kid);
    return out;
  }

  get held() {
    return [...this.keys.values()].filter((k) => k.up === null).sort((a, b) => a.order - b.order).map((k) => k.kid);
  }

  // every step after the checkpoint due at or before `upto`, in order
  steps(upto) {
    const out = [];
    for (const key of this.keys.values()) {
      const end = key.up === null ? upto : Math.min(upto, key.up);
      for (let k = 0; ; k++) {
        const t = stepTime(key.down, k, this.holdMs, this.periodMs);
        if (t > end || (k > 0 && !key.repeats)) break;
        if (t > key.after) out.push({ t, order: key.order, kid: key.kid, k, action: key.action, inverted: key.inverted });
      }
    }
    out.sort((a, b) => a.t - b.t || a.order - b.order);
    return out;
  }

  // every step at or before `t` is in the state taken from the kernel: keys released by then go
  checkpoint(t) {
    for (const [kid, key] of [...this.keys.entries()]) {
      if (key.up !== null && key.up <= t) this.keys.delete(kid);
      else key.after = Math.max(key.after, t);
    }
  }

  // the next step's page time of a held key (to wake the page then), or Infinity
  nextDue(now) {
    let next = Infinity;
    for (const key of this.keys.values()) {
      if (key.up !== null || !key.repeats) continue;
      let k = Math.max(1, Math.floor((now - key.down - this.holdMs) / this.periodMs));
      let t;
      for (;; k++) {
        t = stepTime(key.down, k, this.holdMs, this.periodMs);
        if (t > now) break;
      }
      next = Math.min(next, t);
    }
    return next;
  }
}
