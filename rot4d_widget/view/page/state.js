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

  // One step of `action` ({kind, planes, sign}); true if the state changed (RotationState.apply).
  apply(action, inverted = false) {
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
      default:  // help, the view's and the source's keys: not the state's
        return false;
    }
  }
}
