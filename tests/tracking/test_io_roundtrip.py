"""Writer -> reader round trips are bit-exact for every format we write (cine 8/16/P10/P12, FFV1, images)."""

from __future__ import annotations

import numpy as np
import pytest

from cageless.tracking.io import open_video, write_cine, write_ffv1, write_image_sequence
from cageless.tracking.io.packing import pack10, pack12, unpack10, unpack12


def frames(n: int, h: int, w: int, bits: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    dtype = np.uint8 if bits <= 8 else np.uint16
    a = rng.integers(0, 1 << bits, size=(n, h, w), dtype=np.int64).astype(dtype)
    a[:, 0, 0] = (1 << bits) - 1  # the extremes survive
    a[:, -1, -1] = 0
    return a


@pytest.mark.parametrize(
    ("fmt", "bits", "real_bpp"), [("8", 8, 8), ("16", 16, 16), ("16", 12, 12), ("p10", 10, 10), ("p12", 12, 12)]
)
def test_cine_round_trip(tmp_path, fmt, bits, real_bpp):
    data = frames(7, 12, 20, bits)
    # Frames 3 and 4 were dropped: the time stamps show the gap.
    times = np.array([0, 1, 2, 5, 6, 7, 8]) * 1e-4
    path = write_cine(tmp_path / f"x_{fmt}.cine", data, fps=10000, fmt=fmt, real_bpp=real_bpp,
                      timestamps_s=times, exposure_s=10e-6, serial=1234)
    with open_video(path) as video:
        assert video.shape == data.shape
        assert video.metadata.bit_depth == real_bpp
        np.testing.assert_array_equal(video[0:7], data)
        np.testing.assert_array_equal(video[5], data[5])
        # TIME64 keeps 2**-32 s: the times come back to well under a nanosecond.
        np.testing.assert_allclose(video.times, times, atol=1e-9, rtol=0)
        assert video.metadata.header_fps == 10000
        assert video.metadata.exposure_s == pytest.approx(10e-6)
        assert "serial 1234" in video.metadata.camera


def test_cine_streams_from_an_iterator(tmp_path):
    data = frames(5, 8, 8, 12)
    path = write_cine(tmp_path / "it.cine", iter(data), n_frames=5, fps=500, fmt="p12")
    with open_video(path) as video:
        np.testing.assert_array_equal(video[:], data)
        np.testing.assert_allclose(video.times, np.arange(5) / 500, atol=1e-9)


def test_cine_writer_refuses_bad_frames(tmp_path):
    from cageless.errors import ParameterError

    with pytest.raises(ParameterError, match=r"below 2\*\*12"):
        write_cine(tmp_path / "a.cine", np.full((2, 4, 4), 4096, np.uint16), fps=10, fmt="16", real_bpp=12)
    with pytest.raises(ParameterError, match="all frames must be"):
        write_cine(tmp_path / "b.cine", [np.zeros((4, 4), np.uint16), np.zeros((4, 5), np.uint16)], fps=10)
    with pytest.raises(ParameterError, match="must be one of"):
        write_cine(tmp_path / "c.cine", np.zeros((1, 4, 4), np.uint16), fps=10, fmt="14")
    assert not any(tmp_path.iterdir())  # nothing half-written


@pytest.mark.parametrize("bits", [10, 12])
def test_packing_is_the_inverse_of_unpacking(bits):
    pixels = frames(1, 4, 24, bits, seed=3).reshape(-1)
    pack, unpack = (pack10, unpack10) if bits == 10 else (pack12, unpack12)
    packed = pack(pixels)
    assert packed.size == pixels.size * bits // 8
    np.testing.assert_array_equal(unpack(packed, pixels.size), pixels)
    # Bit order, by hand: the 12-bit pair (0xABC, 0x123) packs to bytes AB C1 23.
    if bits == 12:
        assert pack12([0xABC, 0x123]).tolist() == [0xAB, 0xC1, 0x23]
    else:  # 10-bit quad (0x3FF, 0, 0x155, 1) -> 11111111 11000000 00000101 01010100 00000001
        assert pack10([0x3FF, 0, 0x155, 1]).tolist() == [0xFF, 0xC0, 0x05, 0x54, 0x01]


@pytest.mark.parametrize("suffix", [".avi", ".mkv"])
def test_ffv1_round_trip(tmp_path, suffix):
    data = frames(6, 24, 32, 8)
    path = write_ffv1(tmp_path / f"v{suffix}", data, fps=25)
    with open_video(path, fps=10000) as video:
        assert video.shape == data.shape
        np.testing.assert_array_equal(video[:], data)
        np.testing.assert_array_equal(video[4], data[4])  # random access, forward
        np.testing.assert_array_equal(video[1], data[1])  # and back
        assert video.metadata.time_source == "fps override"
        np.testing.assert_allclose(video.times, np.arange(6) / 10000)


@pytest.mark.parametrize(("suffix", "bits"), [(".tif", 16), (".png", 16), (".png", 8), (".tif", 8)])
def test_image_sequence_round_trip(tmp_path, suffix, bits):
    data = frames(4, 10, 14, bits)
    times = np.array([0.0, 1e-4, 3e-4, 4e-4])
    folder = write_image_sequence(tmp_path / "seq", data, times_s=times, suffix=suffix)
    with open_video(folder) as video:
        np.testing.assert_array_equal(video[:], data)
        assert video.metadata.bit_depth == bits
        np.testing.assert_array_equal(video.times, times)
    with open_video(folder, fps=50) as video:
        np.testing.assert_allclose(video.times, np.arange(4) / 50)


def test_ffv1_avi_at_camera_rate_keeps_every_frame(tmp_path):
    """OpenCV's AVI muxer drops frames above 1000 fps; the writer caps the container rate and verifies."""
    data = frames(40, 16, 16, 8)
    path = write_ffv1(tmp_path / "fast.avi", data, fps=10000)
    with open_video(path) as video:
        assert len(video) == 40
        np.testing.assert_array_equal(video[:], data)
        assert video.metadata.header_fps == 1000
    mkv = write_ffv1(tmp_path / "fast.mkv", data, fps=10000)
    with open_video(mkv) as video:
        assert video.metadata.header_fps == 10000 and len(video) == 40


@pytest.mark.parametrize("fmt", ["8", "16", "p10", "p12"])
@pytest.mark.parametrize("width", [20, 22])  # 22 px rows are not whole 10-bit groups: the slow path
def test_chunked_reads_equal_frame_by_frame_reads(tmp_path, fmt, width):
    bits = {"8": 8, "16": 16, "p10": 10, "p12": 12}[fmt]
    data = frames(9, 6, width, bits, seed=5)
    if (6 * width) % (4 if bits == 10 else 2):
        pytest.skip("frame cannot be packed")
    with open_video(write_cine(tmp_path / "c.cine", data, fps=100, fmt=fmt)) as video:
        chunks = [c for _, c in video.iter_chunks(4)]
        np.testing.assert_array_equal(np.concatenate(chunks), data)
        np.testing.assert_array_equal(video[2:7], data[2:7])
        np.testing.assert_array_equal(video[1:8:3], data[1:8:3])
        assert all(np.array_equal(video[i], data[i]) for i in range(9))
        assert all(np.array_equal(video.frame_view(i), data[i]) for i in range(-9, 9))
        stack = video.frame_stack()
        if bits in (10, 12):
            assert stack is None  # packed frames have no view: they are unpacked
        else:
            np.testing.assert_array_equal(stack, data)  # the written cine is bottom-up: rows come back upright
            assert not stack.flags.writeable


@pytest.mark.parametrize("suffix", [".avi", ".mkv"])
def test_opencv_reader_decodes_a_reread_frame_once(tmp_path, suffix, monkeypatch):
    """The tracker's set-up reads the same spread frames several times; a kept frame is not decoded again
    (a 200-frame corpus AVI was decoded 944 times in one ``cageless track`` before), and it reads the same."""
    from cageless.tracking.io import opencv

    data = frames(40 + opencv.FRAME_CACHE, 16, 24, 8)
    path = write_ffv1(tmp_path / f"x{suffix}", data, fps=1000)
    with open_video(path) as video:
        decodes = []
        inner = video._seek_and_decode
        monkeypatch.setattr(video, "_seek_and_decode", lambda i: decodes.append(i) or inner(i))
        order = [5, 30, 5, 30, 12, 5]
        got = [video[i] for i in order]
        assert decodes == [5, 30, 12]
        for i, g in zip(order, got, strict=True):
            np.testing.assert_array_equal(g, data[i])
        got[0][:] = 0  # a returned frame is the caller's own: changing it leaves the kept one alone
        np.testing.assert_array_equal(video[5], data[5])
        for i in range(40, 40 + opencv.FRAME_CACHE):  # frames kept longest leave once the cache is full
            video[i]
        decodes.clear()
        video[30]
        assert decodes == [30]


def test_an_mkv_is_counted_once_and_read_in_order(tmp_path, monkeypatch):
    """MKV/MP4 hold no exact frame count, so opening one decodes it all; the tracker's segments each open the
    file again, and the same file is counted once. Going back in it means decoding again from the start, so
    it says it is not seekable (AVI seeks exactly: it is)."""
    import cv2

    from cageless.tracking.io import opencv

    data = frames(40, 16, 24, 8)
    mkv = write_ffv1(tmp_path / "x.mkv", data, fps=1000)
    grabs = []
    real = cv2.VideoCapture

    class Counting:
        def __init__(self, *args):
            self._cap = real(*args)

        def grab(self):
            grabs.append(1)
            return self._cap.grab()

        def __getattr__(self, name):
            return getattr(self._cap, name)

    monkeypatch.setattr(opencv.cv2, "VideoCapture", Counting)
    monkeypatch.setattr(opencv, "_COUNTED", {})
    with open_video(mkv) as video:
        assert len(video) == 40 and not video.seekable
    assert len(grabs) == 40  # frame 0 is decoded to read the size; 39 grabs count the rest, one finds the end
    with open_video(mkv) as again:
        assert len(again) == 40
        np.testing.assert_array_equal(again[39], data[39])
    assert len(grabs) == 40 + 38  # not counted again, and not opened again: frame 39 is 38 grabs from frame 1
    assert open_video(write_ffv1(tmp_path / "x.avi", data, fps=1000)).seekable


def test_prefetch_decodes_spread_frames_in_one_pass(tmp_path, monkeypatch):
    """Spread frames asked for after a prefetch are decoded once, in order, in one pass over an MKV; an AVI
    (seekable) ignores the hint and reads them when asked."""
    data = frames(40, 16, 24, 8)
    with open_video(write_ffv1(tmp_path / "x.mkv", data, fps=1000)) as video:
        opened, decodes = [], []
        for name, log in (("_open", opened), ("_seek_and_decode", decodes)):
            inner = getattr(video, name)
            monkeypatch.setattr(video, name, lambda *a, inner=inner, log=log: log.append(a) or inner(*a))
        video.prefetch([30, 0, 13, 39, 13])
        assert decodes == [(0,), (13,), (30,), (39,)] and not opened  # counted, then opened again at frame 0
        for i in (39, 0, 30, 13):
            np.testing.assert_array_equal(video[i], data[i])
        assert len(decodes) == 4 and not opened
    with open_video(write_ffv1(tmp_path / "x.avi", data, fps=1000)) as avi:
        avi.prefetch([30, 0])
        assert not avi._decoded
