"""Checks on written image files: signature, size and that the picture is not blank."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
GIF_SIGNATURE = b"GIF8"


def pixels_std(path: Path) -> float:
    """Standard deviation of the RGB values (0-255) of an image's first frame."""
    with Image.open(path) as im:
        return float(np.asarray(im.convert("RGB"), dtype=float).std())


def assert_image(path: Path, signature: bytes, min_kb: float) -> None:
    """The file starts with ``signature``, is larger than ``min_kb`` KiB and is not (nearly) blank."""
    data = Path(path).read_bytes()
    assert data[: len(signature)] == signature
    assert len(data) > min_kb * 1024
    assert pixels_std(path) > 10.0, "image is (nearly) blank"
