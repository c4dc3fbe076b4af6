// The page's copy of the rotation state: rot4d_widget.core.state.RotationState.apply, step for
// step, with the bounds the kernel sends (`config.bounds`): a step that would leave its range is
// refused (false), never clamped.  A state is adopted whole from the kernel (`fromKernel`).

import { doubleRotation, matmul4, reorthonormalize, simpleRotation } from "./rotation.js";

const copyView = (v) => ({ ...v, sections: v.sections.slice(), levels: v.levels.slice() });

const finiteOr = (v, dflt) => (typeof v === "number" && Number.isFinite(v) ? v : dflt);

export class PageState {
  // `msg`: the kernel's state message (rot4d_widget.view.pagestate.state_message); `bounds`:
  // {theta0_min, theta0_max, alpha_max, theta0_factor, alpha_step_fraction}.
  constructor(msg, bounds) {
    this.bounds = bounds;
    this.set(msg);
  }

  set(msg) {
    this.matrix = Float64Array.from(msg.matrix);
    this.theta0 = msg.theta0;
    this.alpha = msg.alpha;
    this.c0 = msg.c0;
    this.c0Step = msg.c0_step;
    this.c0Limit = finiteOr(msg.c0_limit, Infinity);
    this.c0Origin = msg.c0_origin;
    const init = msg.initial;
    this.initial = { matrix: Float64Array.from(init.matrix), theta0: init.theta0, alpha: init.alpha, c0: init.c0 };
    // a field's view settings (rot4d_widget.view.fieldview.view_message), or null
    this.view = msg.view ? copyView(msg.view) : null;
    return this;
  }

  copy() {
    const c = Object.create(PageState.prototype);
    Object.assign(c, this, { matrix: Float64Array.from(this.matrix), initial: { ...this.initial },
                             view: this.view ? copyView(this.view) : null });
    return c;
  }

  get beta() {
    return this.theta0 - this.alpha;
  }

  stepMatrix(action, inverted) {
    const sign = inverted ? -1 : 1;
    if (action.planes.includes(",")) return doubleRotation(action.planes, sign * this.alpha, sign * this.beta);
    return simpleRotation(action.planes, sign * this.theta0);
  }

  // One step of `action` ({kind, planes, sign}); true if the state changed (RotationState.apply;
  // a field's view keys as rot4d_widget.view.fieldkeys steps them: `rule` for a source action the
  // page steps, {rule: "levels", sign}).
  apply(action, inverted = false, rule = null) {
    const b = this.bounds;
    switch (action.kind) {
      case "rotate":
        this.matrix = reorthonormalize(matmul4(this.stepMatrix(action, inverted), this.matrix));
        return true;
      case "alpha": {
        const next = this.alpha + action.sign * (this.theta0 * b.alpha_step_fraction);
        if (!(Math.abs(next) <= b.alpha_max && Math.abs(this.theta0 - next) <= b.alpha_max)) return false;
        this.alpha = next;
        return true;
      }
      case "c0": {
        const next = this.c0 + action.sign * this.c0Step;
        const o = this.c0Origin;
        if (Math.abs(next - o) > this.c0Limit && Math.abs(next - o) >= Math.abs(this.c0 - o)) return false;
        if (next + this.c0Step === next || next - this.c0Step === next) return false;  // a c0 its step cannot move
        this.c0 = next;
        return true;
      }
      case "theta0": {
        const next = action.sign > 0 ? this.theta0 * b.theta0_factor : this.theta0 / b.theta0_factor;
        const ratio = this.alpha / this.theta0;
        if (!(b.theta0_min <= next && next <= b.theta0_max && Math.abs(ratio * next) <= b.alpha_max &&
              Math.abs((1 - ratio) * next) <= b.alpha_max)) return false;
        this.alpha = this.alpha * (next / this.theta0);
        this.theta0 = next;
        return true;
      }
      case "reset":
        this.matrix = Float64Array.from(this.initial.matrix);
        this.theta0 = this.initial.theta0;
        this.alpha = this.initial.alpha;
        this.c0 = this.initial.c0;
        return true;
      case "rendering":
        return this.view !== null && this.stepRendering(action, inverted);
      case "section":
        return this.view !== null && this.stepSection(action, inverted);
      case "custom":
        return this.view !== null && !!rule && rule.rule === "levels" && this.stepLevels(rule.sign * (inverted ? -1 : 1));
      default:  // help, the view's other keys and the source's own: not the page's
        return false;
    }
  }

  // v / Shift+v: the next rendering in the kernel's order (rot4d_widget.view.renderings.Renderings.step)
  stepRendering(action, inverted) {
    const order = this.view.renderings;
    const direction = (inverted ? -1 : 1) * action.sign;
    const n = order.length;
    this.view.rendering = order[(((order.indexOf(this.view.rendering) + direction) % n) + n) % n];
    return true;
  }

  // a / s / d (Shift back): the section plane by one step, rounded to 1/1024, refused at 0 and 1
  stepSection(action, inverted) {
    const axis = "xyz".indexOf(action.name);
    const pos = this.view.sections;
    const direction = (inverted ? -1 : 1) * action.sign;
    const moved = Math.min(1, Math.max(0, roundHalfEven((pos[axis] + direction * this.view.section_step) * 1024) / 1024));
    if (moved === pos[axis]) return false;
    pos[axis] = moved;
    return true;
  }

  // o / i: every level by one step (FieldLevels.step_levels), refused beyond the range widened by one
  stepLevels(sign) {
    const v = this.view;
    if (!Number.isFinite(v.level_step)) return false;
    const step = v.level_step;
    const [lo, hi] = v.level_range;
    const next = v.levels.map((x) => x + (sign > 0 ? 1 : -1) * step);
    if (!next.every(Number.isFinite)) return false;
    if (Number.isFinite(lo) && Number.isFinite(hi)) {
      const outside = (x) => Math.max(lo - step - x, x - hi - step, 0.0);
      if (v.levels.some((u, i) => outside(next[i]) > 0 && outside(next[i]) >= outside(u))) return false;
    }
    v.levels = next;
    return true;
  }
}

// Python's round(): halves to the even neighbour.
function roundHalfEven(x) {
  const r = Math.round(x);
  return Math.abs(x % 1) === 0.5 && r % 2 !== 0 ? r - 1 : r;
}
