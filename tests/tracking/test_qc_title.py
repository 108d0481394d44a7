"""The text of the QC images: its black outline sits on its letters (a new user's trial saw a failed clip's
selection image with its title written twice, the second copy shifted, where it crossed a bright ring face)."""

from __future__ import annotations

import numpy as np

from cageless.tracking.qc import _write_title

TITLE = ("found 14 balls moving together along one circle, but 12 are expected (the bearing's ball count, or "
         "--n-balls). (frame 12: the candidates that start there, of 6 bursts; all in clip.candidates.csv)")


def test_the_outline_ends_where_the_letters_end_on_a_bright_frame():
    img = np.full((200, 960, 3), 128, np.uint8)  # a uniform grey frame: outline and letters both show
    _write_title(img, TITLE, [("selected: 12", (0, 255, 0))])
    grey = img[..., 0].astype(int)
    for row in (slice(8, 26), slice(26, 44)):  # the title's two wrapped lines (18 px pitch, from y = 22)
        dark = np.flatnonzero((grey[row] < 40).any(axis=0))
        bright = np.flatnonzero((grey[row] > 220).any(axis=0))
        assert bright.size and dark.size
        # the outline is the letters moved by 1 px each way (anti-aliased: 2 px); a 3 px stroke ran 24-37 px ahead
        assert dark.max() - bright.max() <= 2
        assert bright.min() - dark.min() <= 2


def test_lines_do_not_touch():
    """An outline does not reach the line above: 18 px between baselines, text 13 px high with its outline."""
    img = np.full((200, 960, 3), 128, np.uint8)
    last = _write_title(img, TITLE, [("selected: 12", (0, 255, 0)), ("breaks spacing: 2", (0, 200, 255))])
    assert last == 4 + 18 * 4
    touched = (img != 128).any(axis=(1, 2))
    assert touched[: last + 6].sum() < last + 6  # some untouched rows between the lines
