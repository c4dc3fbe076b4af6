// Key guards (jobs 3 and 4 of companion.js): Notebook 7's shortcuts stopped while the pointer is
// over a canvas, and ipyevents' document listener removed when a hovered canvas leaves the page.

export const GUARD_TAG = "rot4d-leave-guard";

// Defined once per page (this module may be evaluated several times).
export function defineLeaveGuard() {
  if (typeof customElements === "undefined" || customElements.get(GUARD_TAG)) return;
  customElements.define(
    GUARD_TAG,
    class extends HTMLElement {
      connectedCallback() {
        this.style.display = "none";
        this._host = this.parentElement; // the canvas element (ipyevents' source view)
      }
      disconnectedCallback() {
        const host = this._host;
        // only when the canvas itself left the document (not if just this guard was removed)
        if (host && !host.isConnected) host.dispatchEvent(new MouseEvent("mouseleave"));
      }
    }
  );
}

export function canvasHovered(cls) {
  if (!cls) return false;
  try {
    return document.querySelector("." + CSS.escape(cls) + ":hover") !== null;
  } catch (e) {
    return false;
  }
}

