"""The 4OFF reader (rot4d_widget.geometry.offfile) reads one line at a time and trusts no size in the file:
garbage, binary files and absurd counts are refused at once, naming the file and the line."""

import io
import os
import time
import tracemalloc

import numpy as np
import pytest

from rot4d_widget.geometry.offfile import MAX_LINE_CHARS, read_off
from rot4d_widget.geometry.catalogue import polytope

MB = 1 << 20
TESSERACT = polytope("8-cell").to_off()


class CountingReader(io.RawIOBase):
    """A binary stream over a file that counts the bytes handed out (and has no size of its own)."""

    def __init__(self, path):
        self._fh = open(path, "rb", buffering=0)
        self.bytes_read = 0

    def readable(self):
        return True

    def readinto(self, b):
        n = self._fh.readinto(b)
        self.bytes_read += n or 0
        return n

    def close(self):
        self._fh.close()
        super().close()


class Pipe(io.RawIOBase):
    """A binary stream with no file number and no size (as a pipe)."""

    def __init__(self, data):
        self._data = io.BytesIO(data)

    def readable(self):
        return True

    def readinto(self, b):
        return self._data.readinto(b)


def _refused(source, match):
    """Read ``source`` expecting a ValueError matching ``match``: (seconds, peak traced bytes, error)."""
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(ValueError, match=match) as info:
            read_off(source)
        return time.perf_counter() - t0, tracemalloc.get_traced_memory()[1], info.value
    finally:
        tracemalloc.stop()


def test_100_mb_of_nul_bytes_after_the_header_is_refused_without_reading_it(tmp_path):
    path = tmp_path / "sparse.off"
    with open(path, "wb") as fh:  # a sparse file: 100 MB of NUL bytes after "4OFF"
        fh.write(b"4OFF\n")
        fh.truncate(100 * MB)
    seconds, peak, err = _refused(path, r"line 2: ")
    assert seconds < 5 and peak < 16 * MB, (seconds, peak)  # not 100 MB read into memory
    assert str(path) in str(err) and not isinstance(err, UnicodeDecodeError)


def test_100_mb_of_garbage_lines_after_the_header_is_refused_at_line_2(tmp_path):
    path = tmp_path / "garbage.off"
    block = b"%x y\n" * (MB // 5)
    with open(path, "wb") as fh:
        fh.write(b"4OFF\n")
        for _ in range(100):
            fh.write(block)
    seconds, peak, err = _refused(path, r"line 2: expected four counts V F E C, got '%x y'")
    assert str(path) in str(err) and seconds < 5 and peak < 16 * MB, (seconds, peak)
    counting = CountingReader(path)
    with io.BufferedReader(counting) as fh:
        with pytest.raises(ValueError, match="line 2: expected four counts"):
            read_off(fh)
        assert counting.bytes_read < MB  # a few buffers, not the file
        assert not fh.closed  # the caller's file is left open


def test_an_over_long_line_is_refused_when_that_much_is_read(tmp_path):
    path = tmp_path / "long.off"
    path.write_bytes(b"4OFF\n16 24 32 8\n" + b"1 " * (40 * MB) + b"\n")
    counting = CountingReader(path)
    with io.BufferedReader(counting) as fh:
        with pytest.raises(ValueError, match=rf"line 3: longer than {MAX_LINE_CHARS} characters"):
            read_off(fh)
        assert counting.bytes_read < MAX_LINE_CHARS + MB
    with pytest.raises(ValueError, match=rf"{path.name}.*line 3: longer than"):
        read_off(path)


NUL_IN_A_VERTEX = TESSERACT.replace("\n\n# vertices\n", "\n\n# vertices\n1 \x00", 1).encode()


@pytest.mark.parametrize("content, bad, match", [
    (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", b"\x89", r"not UTF-8 text \(byte 0x89 at column 1\)"),
    (TESSERACT.encode()[:40] + b"\xff\xfe\x00\x01 garbage\n", b"\xff", r"not UTF-8 text \(byte 0xff at column \d+\)"),
    (NUL_IN_A_VERTEX, b"\x00", r"a NUL byte at column 3: a binary file"),
], ids=["png", "bytes-after-text", "nul"])
def test_a_binary_file_is_a_value_error_naming_the_file_and_line(tmp_path, content, bad, match):
    path = tmp_path / "picture.off"
    path.write_bytes(content)
    with pytest.raises(ValueError, match=match) as info:
        read_off(path)
    text = str(info.value)
    assert not isinstance(info.value, UnicodeDecodeError)
    assert str(path) in text
    line = content[: content.index(bad)].count(b"\n") + 1
    assert f"line {line}:" in text
    with pytest.raises(ValueError, match=rf"line {line}: .*{match}"):
        read_off(content)  # the same bytes given in memory


@pytest.mark.parametrize("counts", ["1000000000 1 0 1", "16 1000000000 0 1", "16 24 0 1000000000"])
def test_counts_the_file_cannot_hold_are_refused_before_allocating(tmp_path, counts):
    path = tmp_path / "big.off"
    path.write_text(TESSERACT.replace("16 24 32 8", counts))
    seconds, peak, err = _refused(path, r"line 4: the counts .* declare .* which take at least \d+ more bytes, "
                                        r"but the file has \d+ left")
    assert str(path) in str(err) and seconds < 5 and peak < 4 * MB
    with pytest.raises(ValueError, match="take at least"):
        read_off(TESSERACT.replace("16 24 32 8", counts))  # the text: its length bounds it too
    # a stream of unknown size: bounded by MAX_COUNT, and nothing allocated for what is declared
    huge = TESSERACT.replace("16 24 32 8", "1000000000000 24 32 8").encode()
    with pytest.raises(ValueError, match="line 4: counts '1000000000000 24 32 8' above 100,000,000"):
        read_off(io.BufferedReader(Pipe(huge)))
    below = TESSERACT.replace("16 24 32 8", counts.replace("1000000000", "50000000")).encode()
    seconds, peak, _ = _refused(io.BufferedReader(Pipe(below)), r"line \d+: ")  # where the file stops fitting
    assert peak < 4 * MB  # 50 million declared: what was read is allocated, not what was declared


def test_every_way_to_give_a_file_reads_the_same(tmp_path):
    want = read_off(TESSERACT)
    path = tmp_path / "t.off"
    path.write_text(TESSERACT)
    crlf = TESSERACT.replace("\n", "\r\n").encode()
    cr = TESSERACT.replace("\n", "\r").encode()
    with open(path, "rb") as binary, open(path, encoding="utf-8") as text:
        got = [read_off(path), read_off(str(path)), read_off(binary), read_off(text), read_off(crlf),
               read_off(cr), read_off(b"\xef\xbb\xbf" + crlf)]
    for g in got:
        np.testing.assert_array_equal(g.vertices, want.vertices)
        assert g.faces == want.faces and g.cells == want.cells and g.cell_lines == want.cell_lines
    # exact counts fit exactly: the shortest lines, no newline at the end
    assert read_off("4OFF\n1 1 0 1\n0 0 0 0\n1 0\n1 0").vertices.shape == (1, 4)


def test_a_stream_of_unknown_size_still_reads_many_vertices():
    n = 70_000  # more than the first buffer of vertices
    rows = np.random.default_rng(1).integers(-9, 9, (n, 4))
    text = "4OFF\n%d 1 0 1\n" % n + "\n".join(" ".join(map(str, r)) for r in rows.tolist()) + "\n3 0 1 2\n1 0\n"
    got = read_off(io.BufferedReader(Pipe(text.encode())))  # no size to ask
    np.testing.assert_array_equal(got.vertices, rows)


def test_a_missing_file_is_still_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_off(os.fspath(tmp_path / "missing.off"))
