"""Bad video input gets a clear error naming the file (and the byte offset for cine)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from cageless.errors import VideoError
from cageless.tracking.io import open_video, write_cine


@pytest.fixture()
def good_cine(tmp_path):
    data = np.arange(5 * 8 * 8, dtype=np.uint16).reshape(5, 8, 8)
    return write_cine(tmp_path / "good.cine", data, fps=1000, fmt="16", real_bpp=12), data


def test_truncated_cine(tmp_path, good_cine):
    path, data = good_cine
    raw = path.read_bytes()
    cut = tmp_path / "cut.cine"
    cut.write_bytes(raw[: len(raw) - 50])
    with pytest.raises(VideoError, match=r"cut.cine: is truncated: frame 4 of 5.*byte offset \d+") as err:
        open_video(cut)
    assert err.value.offset is not None and err.value.offset < len(raw)
    from cageless.tracking.io.cine import CineReader

    with CineReader(cut, allow_truncated=True) as video:
        assert len(video) == 4
        np.testing.assert_array_equal(video[:], data[:4])
        assert "truncated" in video.metadata.notes[0]


def test_header_cut_short(tmp_path, good_cine):
    path, _ = good_cine
    short = tmp_path / "short.cine"
    short.write_bytes(path.read_bytes()[:300])
    with pytest.raises(VideoError, match=r"short.cine: is truncated or corrupt: SETUP .*byte offset 84"):
        open_video(short)
    tiny = tmp_path / "tiny.cine"
    tiny.write_bytes(b"CI\x2c")
    with pytest.raises(VideoError, match="too short"):
        open_video(tiny)


def test_wrong_magic(tmp_path, good_cine):
    path, _ = good_cine
    bad = tmp_path / "magic.cine"
    bad.write_bytes(b"XX" + path.read_bytes()[2:])
    with pytest.raises(VideoError, match=r"wrong magic bytes b'XX'.*byte offset 0"):
        open_video(bad)


def test_zero_frames(tmp_path, good_cine):
    path, _ = good_cine
    raw = bytearray(path.read_bytes())
    raw[20:24] = (0).to_bytes(4, "little")  # ImageCount
    zero = tmp_path / "zero.cine"
    zero.write_bytes(bytes(raw))
    with pytest.raises(VideoError, match="zero.cine: has zero frames"):
        open_video(zero)


def test_colour_cine_is_refused(tmp_path, good_cine):
    path, _ = good_cine
    raw = bytearray(path.read_bytes())
    raw[84 + 808: 84 + 812] = (3).to_bytes(4, "little")  # SETUP.CFA = Bayer
    colour = tmp_path / "colour.cine"
    colour.write_bytes(bytes(raw))
    with pytest.raises(VideoError, match="colour cine.*monochrome"):
        open_video(colour)


def test_corrupt_image_size(tmp_path, good_cine):
    path, _ = good_cine
    from cageless.tracking.io.cine import CineReader

    with CineReader(path) as video:
        first = int(video._data_start[0])
    raw = bytearray(path.read_bytes())
    raw[first - 4: first] = (12345).to_bytes(4, "little")
    bad = tmp_path / "size.cine"
    bad.write_bytes(bytes(raw))
    with pytest.raises(VideoError, match="frame 0 declares 12345 bytes"):
        open_video(bad)


def test_unreadable_video(tmp_path):
    junk = tmp_path / "junk.avi"
    junk.write_bytes(b"\x00" * 1000)
    with pytest.raises(VideoError, match="junk.avi: OpenCV cannot open"):
        open_video(junk)


def test_unknown_suffix_missing_and_empty_folder(tmp_path):
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(VideoError, match="not a video cageless reads"):
        open_video(tmp_path / "notes.txt")
    with pytest.raises(VideoError, match="no such file"):
        open_video(tmp_path / "missing.cine")
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(VideoError, match="empty: holds no numbered"):
        open_video(empty)


def test_image_sequence_without_timing(tmp_path):
    from cageless.tracking.io import write_image_sequence

    folder = write_image_sequence(tmp_path / "seq", np.zeros((2, 4, 4), np.uint8))
    with open_video(folder) as video:
        with pytest.raises(VideoError, match="has no frame timing.*--fps"):
            _ = video.times


def test_damaged_image_in_sequence(tmp_path):
    from cageless.tracking.io import write_image_sequence

    folder = write_image_sequence(tmp_path / "seq", np.zeros((3, 4, 4), np.uint8), suffix=".png")
    (folder / "frame_000001.png").write_bytes(b"not a png")
    with open_video(folder, fps=10) as video:
        with pytest.raises(VideoError, match="frame_000001.png: cannot be read"):
            video[1]


def test_shared_files_untouched(shared_dir, tmp_path):
    """Reading never writes: a copy of a real file hashes the same after reading."""
    src = shared_dir / "reference" / "cine" / "cine_781.cine"
    copy = tmp_path / "c.cine"
    shutil.copy(src, copy)
    before = copy.read_bytes()
    with open_video(copy) as video:
        video[3]
    assert copy.read_bytes() == before
