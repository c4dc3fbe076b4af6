"""`Rot4DWidget.screenshot` and key p (issue 12), without a browser: the page's answer is fed in.

The page side (the companion reading the WebGL canvas after a render) is checked in the real
browser by tests/browser/test_screenshot_browser.py.
"""

from __future__ import annotations

import base64
import io

import pytest
from PIL import Image

from rot4d_widget.view.companion import _png_from_data_url
from test_widget import front_end_view_count

pytestmark = pytest.mark.usefixtures("recording_comms")


def _png(width=30, height=20, colour=(200, 30, 40)) -> bytes:
    buf = io.BytesIO()
    Image.new("RGB", (width, height), colour).save(buf, format="PNG")
    return buf.getvalue()


def _data_url(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode()


def _asked(log, w) -> list:
    """The screenshot requests the companion has sent to the page (custom messages)."""
    return [data["content"] for cid, data, _, _ in log
            if cid == w.companion.comm.comm_id and isinstance(data, dict) and data.get("method") == "custom"
            and isinstance(data.get("content"), dict) and data["content"].get("event") == "screenshot"]


def _answer(w, rid, **content):
    w.companion._handle_message(w.companion, {"event": "screenshot", "id": rid, **content})


def test_png_data_urls_are_checked():
    png = _png()
    assert _png_from_data_url(_data_url(png)) == png
    assert _png_from_data_url("data:image/png;base64,!!!") is None
    assert _png_from_data_url(_data_url(b"GIF89a not a png")) is None
    assert _png_from_data_url(None) is None


def test_no_view_no_screenshot_and_the_readout_says_so(make, recording_comms):
    w = make()
    with pytest.warns(UserWarning, match="no view is displayed"):
        assert w.screenshot() is None
    assert "no view is displayed" in w.readout.value
    assert w.last_screenshot is None
    assert len(_asked(recording_comms, w)) == 1  # asked anyway: a front end may not count views


def test_the_png_arrives_later_and_is_written_kept_and_handed_over(make, recording_comms, tmp_path):
    w = make()
    front_end_view_count(w, 1)
    got = []
    path = tmp_path / "view.png"
    rid = w.screenshot(path, callback=got.append)
    assert _asked(recording_comms, w)[-1] == {"event": "screenshot", "id": rid}
    assert not path.exists() and "asked" in w.readout.value  # returns at once
    png = _png(60, 50)
    _answer(w, rid, png=_data_url(png), width=60, height=50)
    assert path.read_bytes() == png and got == [png] and w.last_screenshot == png
    assert "60 \u00d7 50 px" in w.readout.value and "view.png" in w.readout.value
    _answer(w, rid, png=_data_url(_png(10, 10)))  # a second view answering the same request
    assert got == [png] and path.read_bytes() == png
    _answer(w, 999, png=_data_url(_png(10, 10)))  # never asked
    assert w.last_screenshot == png


def test_a_failed_or_empty_answer_is_reported(make):
    w = make()
    front_end_view_count(w, 1)
    rid = w.screenshot()
    _answer(w, rid, error="no canvas of this view is in the page")
    assert "screenshot failed: no canvas" in w.readout.value and w.last_screenshot is None
    rid = w.screenshot()
    _answer(w, rid, png="data:image/jpeg;base64,AAAA")
    assert "the page sent no PNG" in w.readout.value


def test_bad_arguments_and_bad_callbacks(make):
    w = make()
    front_end_view_count(w, 1)
    with pytest.raises(TypeError, match="path"):
        w.screenshot(5)
    with pytest.raises(TypeError, match="callback"):
        w.screenshot(callback="print")

    def boom(png):
        raise RuntimeError("callback broke")

    rid = w.screenshot(callback=boom)
    _answer(w, rid, png=_data_url(_png()))  # must not raise into the comm handler
    assert w.last_screenshot is not None
    assert "callback broke" in str(w.errors.outputs)


def test_key_p_saves_numbered_pngs_next_to_the_notebook(make, recording_comms, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "rot4d-001.png").write_bytes(b"taken before")
    w = make()
    front_end_view_count(w, 1)
    assert "<kbd>p</kbd>" in w.help_panel.value and "reserved" not in w.help_panel.value.split("<kbd>p</kbd>")[1][:30]
    w.press("p")
    w.press("p")  # a second picture before the first arrives: another name
    first, second = _asked(recording_comms, w)[-2:]
    png = _png()
    _answer(w, first["id"], png=_data_url(png))
    _answer(w, second["id"], png=_data_url(png))
    assert (tmp_path / "rot4d-001.png").read_bytes() == b"taken before"  # never overwritten
    assert (tmp_path / "rot4d-002.png").read_bytes() == png == (tmp_path / "rot4d-003.png").read_bytes()
    assert "saved rot4d-003.png" in w.readout.value


class FailingSend(Exception):
    """A comm send that fails (the kernel lost its connection for a moment)."""


def test_an_answer_whose_note_cannot_be_sent_never_raises_into_the_companion(make, monkeypatch):
    """Issue 33, item 6 (the soak): the note's readout send raised out of the companion's handler."""
    w = make()
    front_end_view_count(w, 1)
    rid = w.screenshot()

    def fail(*args, **kwargs):
        raise FailingSend("the comm is down")

    monkeypatch.setattr(w.readout.comm, "send", fail)
    _answer(w, rid, png=_data_url(_png()))  # must not raise
    assert w.last_screenshot is not None
    assert "the comm is down" in str(w.errors.outputs)


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="no FIFOs on this platform")
def test_a_fifo_at_the_target_name_is_refused_without_waiting(make, tmp_path):
    """Issue 33, item 7: opening a FIFO for writing waits for a reader -- under the pump's lock."""
    import os
    import threading

    fifo = tmp_path / "view.png"
    os.mkfifo(fifo)
    w = make()
    front_end_view_count(w, 1)
    rid = w.screenshot(fifo)
    done = threading.Event()

    def answer():
        _answer(w, rid, png=_data_url(_png()))
        done.set()

    threading.Thread(target=answer, daemon=True).start()
    assert done.wait(30), "the answer waited on the FIFO"
    assert "screenshot not saved" in w.readout.value and "not a regular file" in w.readout.value
