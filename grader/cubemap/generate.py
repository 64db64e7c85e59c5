"""Write the generated environment maps into Cubemap/ (`python -m grader cubemap generate`).

The generators are the source of truth; the .hdr files are their committed
outputs. Deterministic: the same code gives the same bytes.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from .. import PROJECT_ROOT
from . import grid_room, interior, sky, test_map
from .convert import write_cross

CUBEMAP_DIR = PROJECT_ROOT / "Cubemap"

# file name -> generator of faces (6, N, N, 3)
GENERATED_MAPS: dict[str, Callable[[], np.ndarray]] = {
    "test_environment_map.hdr": test_map.generate,
    "sky_cross.hdr": sky.generate,
    "interior_cross.hdr": interior.generate,
    "grid_room_cross.hdr": grid_room.generate,
}


def generate_all(out_dir: Path = CUBEMAP_DIR, names: list[str] | None = None,
                 report: Callable[[str], None] = print) -> list[Path]:
    """Generate the named maps (all by default) into out_dir; the paths written."""
    written = []
    for name in names or list(GENERATED_MAPS):
        faces = GENERATED_MAPS[name]()
        path = Path(out_dir) / name
        write_cross(path, faces)
        report(f"{path}: face {faces.shape[2]}, {path.stat().st_size} bytes")
        written.append(path)
    return written
